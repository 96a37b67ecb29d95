r"""Streaming ensemble statistics: running moments, the moment observable, a chunk-invariant reducer.

:class:`RunningMoments` is a Welford/Chan summary that merges exactly in exact arithmetic; in
floating point its result depends on how the data were split. :class:`LeafReducer` makes the
statistics of an ensemble independent of the split: it reduces per-path values in fixed leaves of
``LEAF`` consecutive paths (one numpy two-pass over exactly those rows) and merges the leaves in path
order, so the numbers are the same, bit for bit, whatever chunks the values arrive in.
"""

from __future__ import annotations

import numba
import numpy as np

from roughpaths.validation import arrays_equal, as_float_array, check_memory, check_positive_int

__all__ = ["RunningMoments", "moment_observable", "split_moment_features", "LeafReducer", "LEAF", "moments_problem"]

#: Paths per leaf of :class:`LeafReducer` (part of the definition of the ensemble's statistics).
LEAF = 64
#: Arrays smaller than this are allocated without asking :func:`roughpaths.validation.check_memory`.
_SMALL_BYTES = 1 << 20


# ------------------------------------------------------------------------------ running moments
class RunningMoments:
    r"""Streaming count, mean and covariance of vectors in ``R^p`` (Welford / Chan et al. merging).

    ``update(x)`` adds a batch ``x`` of shape ``(k, p)`` (its mean and scatter are computed in two
    passes, then merged); ``merge(other)`` combines two summaries exactly:
    :math:`\bar x = \bar x_a + \delta\,n_b/n`,
    :math:`M = M_a + M_b + \delta\delta^T n_a n_b/n` with :math:`\delta = \bar x_b - \bar x_a`.

    Examples
    --------
    >>> x = np.arange(12.0).reshape(6, 2) ** 1.5
    >>> a = RunningMoments(2).update(x[:2]).merge(RunningMoments(2).update(x[2:]))
    >>> bool(np.allclose(a.mean, x.mean(0)) and np.allclose(a.covariance, np.cov(x.T)))
    True
    """

    __slots__ = ("dim", "count", "mean", "scatter")

    def __init__(self, dim: int):
        self.dim = check_positive_int(dim, "dim")
        nbytes = 8.0 * self.dim * (self.dim + 1)
        if nbytes > _SMALL_BYTES:            # the budget reads /proc: not for every leaf's few hundred bytes
            check_memory(nbytes, f"the mean and scatter matrix (dim={self.dim})", "use fewer observables")
        self.count = 0
        self.mean = np.zeros(self.dim)
        self.scatter = np.zeros((self.dim, self.dim))

    def update(self, x) -> "RunningMoments":
        """Add the rows of ``x`` (shape ``(k, p)`` or ``(p,)``); returns ``self``."""
        x = as_float_array(x, "x")
        if x.ndim == 1:
            x = x[None]
        if x.ndim != 2 or x.shape[1] != self.dim:
            raise ValueError(f"x must have shape (k, {self.dim}), got {x.shape}.")
        k = x.shape[0]
        if k == 0:
            return self
        other = RunningMoments(self.dim)
        other.count = k
        other.mean = x.mean(axis=0)
        d = x - other.mean
        other.scatter = d.T @ d
        return self.merge(other)

    def merge(self, other: "RunningMoments") -> "RunningMoments":
        """Merge ``other`` into ``self`` (Chan et al.); returns ``self``."""
        if not isinstance(other, RunningMoments):
            raise TypeError(f"other must be a RunningMoments, got {type(other).__name__}.")
        if other.dim != self.dim:
            raise ValueError(f"other has dimension {other.dim}; can only merge a RunningMoments of "
                             f"dimension {self.dim}.")
        if other.count == 0:
            return self
        if self.count == 0:
            self.count, self.mean, self.scatter = other.count, other.mean.copy(), other.scatter.copy()
            return self
        n = self.count + other.count
        delta = other.mean - self.mean
        self.mean = self.mean + delta * (other.count / n)
        self.scatter = self.scatter + other.scatter + np.outer(delta, delta) * (self.count * other.count / n)
        self.count = n
        return self

    @property
    def covariance(self) -> np.ndarray:
        """Unbiased sample covariance ``(p, p)`` (NaN-free: zeros if ``count < 2``)."""
        if self.count < 2:
            return np.zeros((self.dim, self.dim))
        return self.scatter / (self.count - 1)

    @property
    def standard_error(self) -> np.ndarray:
        """Standard error of each component of the mean, ``sqrt(var / count)``, shape ``(p,)``."""
        if self.count < 2:
            return np.full(self.dim, np.inf)
        return np.sqrt(np.diag(self.covariance) / self.count)

    def copy(self) -> "RunningMoments":
        out = RunningMoments(self.dim)
        out.count, out.mean, out.scatter = self.count, self.mean.copy(), self.scatter.copy()
        return out

    def __eq__(self, other) -> bool:
        if not isinstance(other, RunningMoments):
            return NotImplemented
        return (self.dim == other.dim and self.count == other.count and arrays_equal(self.mean, other.mean)
                and arrays_equal(self.scatter, other.scatter))

    __hash__ = None

    def __repr__(self) -> str:
        return f"RunningMoments(dim={self.dim}, count={self.count})"


# ------------------------------------------------------------------------------ observables
def moment_observable(x) -> np.ndarray:
    """``(x, x_i x_j for i ≤ j)``: first and second moments; ``(..., n)`` → ``(..., n + n(n+1)/2)``."""
    x = np.asarray(x, dtype=np.float64)
    if x.ndim == 0:
        raise ValueError(f"moment_observable takes states of shape (..., n), got the scalar {float(x)!r}; pass "
                         f"np.atleast_1d(x).")
    n = x.shape[-1]
    i, j = np.triu_indices(n)
    out = np.empty(x.shape[:-1] + (n + len(i),))
    out[..., :n] = x
    np.multiply(x[..., i], x[..., j], out=out[..., n:])
    return out


def split_moment_features(values, n: int):
    """Unpack :func:`moment_observable` features: ``(..., n + n(n+1)/2)`` → mean ``(..., n)``, second
    moment ``(..., n, n)`` (symmetric)."""
    v = np.asarray(values, dtype=np.float64)
    iu = np.triu_indices(n)
    m2 = np.zeros(v.shape[:-1] + (n, n))
    m2[..., iu[0], iu[1]] = v[..., n:]
    m2[..., iu[1], iu[0]] = v[..., n:]
    return v[..., :n], m2


class LeafReducer:
    """Streaming reduction of per-path value rows ``(k, p)``, arriving in path order, into a
    :class:`RunningMoments` that does not depend on how the rows were chunked.

    Examples
    --------
    >>> x = np.random.default_rng(0).standard_normal((300, 2))
    >>> a, b = LeafReducer(2), LeafReducer(2)
    >>> for part in np.split(x, [7, 150, 151]):
    ...     _ = a.add(part)
    >>> for part in np.split(x, [100, 299]):
    ...     _ = b.add(part)
    >>> ra, rb = a.result(), b.result()
    >>> bool(np.array_equal(ra.mean, rb.mean) and np.array_equal(ra.scatter, rb.scatter))
    True
    """

    def __init__(self, dim: int):
        self.moments = RunningMoments(dim)
        self._pending = np.empty((0, dim))

    def add(self, rows) -> "LeafReducer":
        """Append the next rows (``(k, p)``, in path order)."""
        rows = np.asarray(rows, dtype=np.float64)
        pend = np.concatenate([self._pending, rows]) if self._pending.size else rows
        full = (pend.shape[0] // LEAF) * LEAF
        for a in range(0, full, LEAF):
            self.moments.merge(RunningMoments(self.moments.dim).update(np.ascontiguousarray(pend[a:a + LEAF])))
        self._pending = np.array(pend[full:])
        return self

    def result(self) -> RunningMoments:
        """The moments of all rows added (the last, partial leaf included)."""
        out = self.moments.copy()
        if self._pending.shape[0]:
            out.merge(RunningMoments(out.dim).update(np.ascontiguousarray(self._pending)))
        return out


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def accumulate(acc, values):
    """``acc[c] += values[c, t]`` for ``t`` in order (sequential in time: the sum of a path does not
    depend on how its steps were split into blocks). ``acc (C, p)``, ``values (C, T, p)``."""
    for c in range(values.shape[0]):
        for t in range(values.shape[1]):
            for j in range(values.shape[2]):
                acc[c, j] += values[c, t, j]


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def accumulate_moments(acc, states):
    """``acc[c] += moment_observable(states[c, t])`` for ``t`` in order, without the temporary.
    ``acc (C, n + n(n+1)/2)``, ``states (C, T, n)``."""
    n = states.shape[2]
    if n == 3:                       # so(3)*: nine running sums in registers (the same additions, in the same order)
        for c in range(states.shape[0]):
            a0, a1, a2, a3, a4, a5, a6, a7, a8 = (acc[c, 0], acc[c, 1], acc[c, 2], acc[c, 3], acc[c, 4], acc[c, 5],
                                                  acc[c, 6], acc[c, 7], acc[c, 8])
            for t in range(states.shape[1]):
                x0, x1, x2 = states[c, t, 0], states[c, t, 1], states[c, t, 2]
                a0 += x0
                a1 += x1
                a2 += x2
                a3 += x0 * x0
                a4 += x0 * x1
                a5 += x0 * x2
                a6 += x1 * x1
                a7 += x1 * x2
                a8 += x2 * x2
            acc[c, 0], acc[c, 1], acc[c, 2], acc[c, 3], acc[c, 4] = a0, a1, a2, a3, a4
            acc[c, 5], acc[c, 6], acc[c, 7], acc[c, 8] = a5, a6, a7, a8
        return
    for c in range(states.shape[0]):
        for t in range(states.shape[1]):
            for i in range(n):
                acc[c, i] += states[c, t, i]
            r = n
            for i in range(n):
                xi = states[c, t, i]
                for j in range(i, n):
                    acc[c, r] += xi * states[c, t, j]
                    r += 1


def moments_problem(name: str, count, mean, scatter, *, max_count=None):
    """What is wrong with stored statistics ``(count, mean, scatter)`` read from a file, or ``None``: the one check
    of checkpoints and saved :class:`~mechanics.ensemble.result.EnsembleResult` files (untrusted input).

    Finite means and scatter, a scatter matrix symmetric (to 1e-9 of its largest diagonal entry) with a
    non-negative diagonal, a count that is a whole number from 0 to ``max_count``, and zero statistics where the
    count is zero.
    """
    if not isinstance(count, (int, np.integer)) or count < 0 or (max_count is not None and count > max_count):
        return f"{name + '_count'!r} is {count!r}, not a number of paths from 0 to {max_count}"
    for label, a in ((name + "_mean", mean), (name + "_scatter", scatter)):
        if not np.all(np.isfinite(a)):
            return f"{label!r} holds non-finite values"
    diag = np.diag(scatter)
    scale = float(np.max(diag, initial=0.0))
    if np.any(diag < 0) or float(np.max(np.abs(scatter - scatter.T), initial=0.0)) > 1e-9 * scale:
        return f"{name + '_scatter'!r} is not a scatter matrix (symmetric with a non-negative diagonal)"
    if count == 0 and (np.any(mean != 0) or np.any(scatter != 0)):
        return f"{name!r} holds no paths but a non-zero mean or scatter"
    return None
