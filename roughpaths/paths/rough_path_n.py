r"""Geometric rough paths of any level ``N`` on a time grid: :class:`RoughPathN`.

A :class:`RoughPathN` stores, on a grid :math:`t_0 < \dots < t_K` shared by every path of a batch,
the **step signatures** :math:`\mathbf{X}_{t_k, t_{k+1}} \in T^{(N)}(\mathbb{R}^d)`, truncated at
level ``N``, in the flat layout of :mod:`roughpaths.algebra.tensor` (levels ``1..N`` concatenated,
row-major words, implicit scalar 1: the layout of ``iisignature.sig``). Every two-parameter
quantity over grid times ``s < t`` follows by Chen's identity
:math:`\mathbf{X}_{s,t} = \mathbf{X}_{s,u}\otimes\mathbf{X}_{u,t}`, so the object is Chen-consistent
by construction. It is the level-``N`` sibling of the level-2 :class:`~roughpaths.RoughPath` (the fast
special case, which it converts to and from).

Conventions (``docs/conventions.md``)
-------------------------------------
* level ``k`` entry of word :math:`(i_1, \dots, i_k)` is
  :math:`\int_{s<u_1<\dots<u_k<t} dX^{i_1}_{u_1}\cdots dX^{i_k}_{u_k}`; level 2 ``[i, j]`` is the area
  :math:`\int (X^i - X^i_s)\,dX^j` of :class:`~roughpaths.RoughPath`;
* geometric: every step signature is group-like (its logarithm is a Lie element);
* perturbation by an antisymmetric ``s``: the log-signature of each step gains
  :math:`\mathsf{s}\,(t_{k+1} - t_k)` at level 2 (:meth:`RoughPathN.perturb`).

Shapes: step signatures ``(..., K, sigdim(d, N))``, ``times`` ``(K + 1,)``, ``x0`` ``(..., d)``;
the leading ``...`` are batch axes.
"""

from __future__ import annotations

import numpy as np

from .rough_path import RoughPath, grid_index
from ..algebra.tensor import (from_lyndon_coordinates, lyndon_coordinates, sigdim, tensor_exp,
                             tensor_inverse, tensor_log, tensor_product)
from ..validation import as_float_array, check_antisymmetric, check_memory, check_positive_int, check_times

__all__ = ["RoughPathN"]

#: Largest grid (points) on which the all-pairs norms run by default (memory ``O(points**2)`` per path).
_DEFAULT_MAX_POINTS = 1025


def _level_slices(d: int, level: int) -> list:
    out, start = [], 0
    for k in range(1, level + 1):
        out.append(slice(start, start + d ** k))
        start += d ** k
    return out


def _lie_defect(sig: np.ndarray, d: int) -> np.ndarray:
    """``max |log g - P(log g)|`` per element, ``P`` the projection onto the free Lie algebra."""
    z = tensor_log(sig, d)
    back = from_lyndon_coordinates(lyndon_coordinates(z, d), d, _depth(sig.shape[-1], d))
    return np.max(np.abs(z - back), axis=-1) if z.size else np.zeros(z.shape[:-1])


def _depth(length: int, d: int) -> int:
    total, k = 0, 0
    while total < length:
        k += 1
        total += d ** k
    return k


class RoughPathN:
    r"""A batch of level-``N`` geometric rough paths on a common time grid (``N >= 1``).

    Parameters
    ----------
    step_signatures : array_like, shape ``(..., K, sigdim(d, N))``
        Per-step truncated signatures :math:`\mathbf{X}_{t_k, t_{k+1}}` (flat, implicit scalar 1).
    dim : int
        Dimension ``d`` of the trace (the level ``N`` is read from the last axis).
    times : array_like, shape ``(K + 1,)``, optional
        Strictly increasing grid; default ``linspace(0, 1, K + 1)``.
    x0 : array_like, shape ``(..., d)``, optional
        Starting point of the trace (default 0).
    check : bool
        Validate shapes, finiteness and that every step is group-like (geometric), to
        ``1e-9`` relative to the step's size (default True).

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPathN, signature
    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> X = RoughPathN.from_path(pts, level=3, times=[0.0, 1.0, 2.0, 3.0])
    >>> X.level, X.dim, X.n_steps
    (3, 2, 3)
    >>> bool(np.allclose(X.signature(0.0, 3.0), signature(pts, 3)))    # Chen over the whole grid
    True
    >>> float(X.to_rough_path().levy_area(0.0, 2.0)[0, 1])            # the L-shaped path's Lévy area
    0.5
    """

    __slots__ = ("_sig", "_dim", "_level", "_times", "_x0", "_cache")

    def __init__(self, step_signatures, dim, *, times=None, x0=None, check=True):
        d = check_positive_int(dim, "dim")
        if check:
            sig = as_float_array(step_signatures, "step_signatures", min_ndim=2)
        else:
            sig = np.asarray(step_signatures, dtype=np.float64)
        level = _depth(sig.shape[-1], d)
        if sigdim(d, max(level, 1)) != sig.shape[-1] or level < 1:
            valid = ", ".join(str(sigdim(d, m)) for m in range(1, 5))
            raise ValueError(f"step_signatures has last axis {sig.shape[-1]}, which is not d + d**2 + ... + "
                             f"d**N for d={d} (valid: {valid}, ...); pass the flat layout of iisignature.sig.")
        n = sig.shape[-2]
        if check and n < 1:
            raise ValueError(f"step_signatures needs at least one step (axis -2), got shape {sig.shape}.")
        if times is None:
            t = np.linspace(0.0, 1.0, n + 1)
        else:
            t = check_times(times, "times", n=n + 1) if check else np.asarray(times, dtype=np.float64)
        batch = sig.shape[:-2]
        if x0 is None:
            z = np.zeros(batch + (d,))
        else:
            z = as_float_array(x0, "x0", last_dims=(d,)) if check else np.asarray(x0, dtype=np.float64)
            try:
                z = np.broadcast_to(z, batch + (d,))
            except ValueError:
                raise ValueError(f"x0 has shape {z.shape}, which does not broadcast to {batch + (d,)}; "
                                 f"give x0 shape (d,) or the batch axes of step_signatures.") from None
        if check and level >= 2 and sig.size:
            defect = _lie_defect(sig, d)
            scale = 1.0 + np.max(np.abs(sig), axis=-1)
            bad = defect > 1e-9 * scale ** level
            if np.any(bad):
                k = int(np.argmax(bad.reshape(-1)))
                raise ValueError(f"step_signatures are not group-like (geometric): the logarithm of flat step "
                                 f"{k} is off the free Lie algebra by {float(defect.reshape(-1)[k]):.3g}; build "
                                 f"steps with tensor_exp of a Lie element, RoughPathN.from_path or "
                                 f"RoughPathN.from_rough_path, or pass check=False if this is intended.")
        self._sig, self._dim, self._level, self._times, self._x0 = sig, d, level, t, z
        self._cache = {}

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_path(cls, values, level: int, *, times=None) -> "RoughPathN":
        r"""Piecewise-linear lift of sampled data, at level ``level``.

        Each step is the straight line between samples, with signature :math:`\exp(\Delta X_k)`.

        Parameters
        ----------
        values : array_like, shape ``(..., K + 1, d)``
        level : int
        times : array_like, shape ``(K + 1,)``, optional
        """
        level = check_positive_int(level, "level")
        v = as_float_array(values, "values", min_ndim=2)
        if v.shape[-2] < 2:
            raise ValueError(f"values needs at least 2 samples along axis -2, got shape {v.shape}.")
        d = v.shape[-1]
        # held at the peak, for M = prod(v.shape[:-1]) samples and S = sigdim(d, level) entries each: the
        # exponent z, the running sum of exp's series and its update, the tensor power and its successor
        # (5 M S), one level-sized product temporary (M d^level) and the increments (M d), 8 bytes each
        M = float(np.prod(v.shape[:-1], dtype=float))
        check_memory(8.0 * M * (5.0 * float(sigdim(d, level)) + float(d) ** level + d) + 4096.0,
                     f"the level-{level} lift of {v.shape[:-1]} samples in d={d}", "lower level or lift fewer samples")
        inc = np.diff(v, axis=-2)
        z = np.zeros(inc.shape[:-1] + (sigdim(d, level),))
        z[..., :d] = inc
        return cls(tensor_exp(z, d), d, times=times, x0=v[..., 0, :], check=False)

    @classmethod
    def from_rough_path(cls, X: RoughPath, level: int) -> "RoughPathN":
        r"""Extend a geometric level-2 :class:`~roughpaths.RoughPath` to level ``level`` step by step.

        Each step becomes the geodesic :math:`\exp(X_k + A_k)`, ``A_k`` its Lévy area (the extension
        :func:`~roughpaths.rough_path_signature` uses). Levels 1 and 2 are exactly those of ``X``; the
        higher levels are the minimal extension of the grid data, **not** the iterated integrals of a
        path between grid points (for those, lift a fine sample: :func:`roughpaths.piecewise_linear_lift`).
        """
        if not isinstance(X, RoughPath):
            raise TypeError(f"X must be a RoughPath, got {type(X).__name__}.")
        level = check_positive_int(level, "level")
        if X.level != 2 or X.kind != "geometric":
            raise ValueError(f"X must be a geometric level-2 RoughPath (got level {X.level}, kind "
                             f"{X.kind!r}); convert an Itô lift first (XX + ½(t - s) I).")
        d = X.dim
        z = np.zeros(X.increments.shape[:-1] + (sigdim(d, level),))
        z[..., :d] = X.increments
        if level >= 2:
            z[..., d:d + d * d] = X.step_levy_areas.reshape(X.increments.shape[:-1] + (d * d,))
        return cls(tensor_exp(z, d), d, times=X.times, x0=X.x0, check=False)

    # ------------------------------------------------------------------ attributes
    @property
    def step_signatures(self) -> np.ndarray:
        """Per-step signatures, shape ``(..., K, sigdim(d, N))`` (flat, implicit scalar 1)."""
        return self._sig

    @property
    def level(self) -> int:
        """Truncation level ``N``."""
        return self._level

    @property
    def kind(self) -> str:
        """Always ``"geometric"`` (steps are group-like)."""
        return "geometric"

    @property
    def dim(self) -> int:
        """Dimension ``d`` of the trace."""
        return self._dim

    @property
    def times(self) -> np.ndarray:
        """Grid times, shape ``(K + 1,)``."""
        return self._times

    @property
    def n_steps(self) -> int:
        """Number of grid steps ``K``."""
        return self._sig.shape[-2]

    @property
    def batch_shape(self) -> tuple:
        """Leading batch axes ``...``."""
        return self._sig.shape[:-2]

    @property
    def dt(self) -> np.ndarray:
        """Step sizes, shape ``(K,)``."""
        return np.diff(self._times)

    @property
    def x0(self) -> np.ndarray:
        """Starting point of the trace, shape ``(..., d)``."""
        return self._x0

    def step_level(self, k: int) -> np.ndarray:
        r"""Level ``k`` of every step signature, shape ``(..., K) + (d,) * k``."""
        k = check_positive_int(k, "k")
        if k > self._level:
            raise ValueError(f"k={k} exceeds the level N={self._level} of this path.")
        d = self._dim
        return self._sig[..., _level_slices(d, self._level)[k - 1]].reshape(self._sig.shape[:-1] + (d,) * k)

    @property
    def increments(self) -> np.ndarray:
        """Per-step increments (level 1), shape ``(..., K, d)``."""
        return self._sig[..., :self._dim]

    @property
    def areas(self) -> np.ndarray | None:
        """Per-step areas (level 2, ``iisignature`` ordering), shape ``(..., K, d, d)``; None if ``N = 1``."""
        return self.step_level(2) if self._level >= 2 else None

    @property
    def path(self) -> np.ndarray:
        """The trace on the grid, shape ``(..., K + 1, d)``."""
        inc = self.increments
        rel = np.concatenate([np.zeros(inc.shape[:-2] + (1, self._dim)), np.cumsum(inc, axis=-2)], axis=-2)
        return rel + self._x0[..., None, :]

    # ------------------------------------------------------------------ queries
    def index_of(self, t, name: str = "t") -> np.ndarray:
        """Grid indices of the times ``t`` (each must be a grid point)."""
        return grid_index(self._times, t, name)

    def _prefix(self) -> np.ndarray:
        """:math:`\\mathbf{X}_{t_0, t_k}` for every ``k``, shape ``(..., K + 1, D)`` (cached)."""
        p = self._cache.get("prefix")
        if p is None:
            sig, d = self._sig, self._dim
            p = np.zeros(sig.shape[:-2] + (sig.shape[-2] + 1, sig.shape[-1]))
            acc = np.zeros(sig.shape[:-2] + (sig.shape[-1],))
            for k in range(sig.shape[-2]):
                acc = tensor_product(acc, sig[..., k, :], d)
                p[..., k + 1, :] = acc
            self._cache["prefix"] = p
        return p

    def _products(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Chen products of the steps ``i[q] .. j[q] - 1`` in time order, shape ``(..., nq, D)``."""
        d, sig = self._dim, self._sig
        lengths = j - i
        acc = np.zeros(sig.shape[:-2] + (i.size, sig.shape[-1]))
        for step in range(int(lengths.max(initial=0))):
            live = step < lengths
            cols = np.where(live, i + step, 0)
            acc = np.where(live[:, None], tensor_product(acc, sig[..., cols, :], d), acc)
        return acc

    def signature(self, s, t) -> np.ndarray:
        r"""The signature :math:`\mathbf{X}_{s,t}` over grid times ``s <= t`` (Chen), shape ``(..., *q, D)``.

        The product of the steps between ``s`` and ``t`` in time order (no prefix inverses, so no
        cancellation error; ``O(max steps)`` vectorised products).
        """
        i, j = self.index_of(s, "s"), self.index_of(t, "t")
        if np.any(i > j):
            raise ValueError("s must not exceed t (s <= t); for the reversed direction use path.reverse().")
        q = np.broadcast_shapes(i.shape, j.shape)
        i, j = np.broadcast_to(i, q).ravel(), np.broadcast_to(j, q).ravel()
        out = self._products(i, j)
        return out.reshape(self.batch_shape + q + (self._sig.shape[-1],))

    def increment(self, s, t) -> np.ndarray:
        """Increment :math:`X_{s,t}`, shape ``(..., *q, d)``."""
        return self.signature(s, t)[..., :self._dim]

    def area(self, s, t) -> np.ndarray:
        r"""Area :math:`\mathbb{X}_{s,t}` (level 2), shape ``(..., *q, d, d)``."""
        if self._level < 2:
            raise ValueError("area needs level >= 2; this path is level 1.")
        d = self._dim
        g = self.signature(s, t)
        return g[..., d:d + d * d].reshape(g.shape[:-1] + (d, d))

    # ------------------------------------------------------------------ transformations
    def restrict(self, times) -> "RoughPathN":
        """The same rough path on a coarser grid (a subset of :attr:`times`), by Chen products.

        Each coarse step is the product of its fine steps in time order. The new ``x0`` is the trace at
        ``times[0]``.
        """
        tt = check_times(times, "times")
        idx = self.index_of(tt, "times")
        if np.any(np.diff(idx) <= 0):
            raise ValueError("times contains the same grid point twice (to the grid tolerance); drop one.")
        d = self._dim
        acc = self._products(idx[:-1], idx[1:])
        return RoughPathN(acc, d, times=self._times[idx], x0=self.path[..., idx[0], :], check=False)

    def concatenate(self, other: "RoughPathN") -> "RoughPathN":
        """Append ``other`` after this path (its grid shifted to start at ``self.times[-1]``; trace continued)."""
        if not isinstance(other, RoughPathN):
            raise TypeError(f"other must be a RoughPathN, got {type(other).__name__}.")
        if (other.dim, other.level, other.batch_shape) != (self.dim, self.level, self.batch_shape):
            raise ValueError(f"cannot concatenate a path with (d, N, batch) = {(other.dim, other.level, other.batch_shape)} "
                             f"after one with {(self.dim, self.level, self.batch_shape)}; they must match.")
        t = np.concatenate([self._times, other._times[1:] - other._times[0] + self._times[-1]])
        return RoughPathN(np.concatenate([self._sig, other._sig], axis=-2), self._dim, times=t, x0=self._x0,
                          check=False)

    def reverse(self) -> "RoughPathN":
        r"""Time reversal :math:`u \mapsto X_{t_0 + t_K - u}`: each step becomes its group inverse, in reversed order."""
        t = self._times[0] + self._times[-1] - self._times[::-1]
        sig = tensor_inverse(self._sig[..., ::-1, :], self._dim)
        return RoughPathN(sig, self._dim, times=t, x0=self.path[..., -1, :], check=False)

    def perturb(self, s) -> "RoughPathN":
        r"""The path whose step log-signatures gain :math:`\mathsf{s}\,(t_{k+1} - t_k)` at level 2.

        Each step becomes :math:`\exp(\log\mathbf{X}_k + \mathsf{s}\,h_k)`, a group-like element, so the
        path stays geometric. Level 2 is exactly that of :meth:`roughpaths.RoughPath.perturb`
        (:math:`\mathbb{X}_k + \mathsf{s}h_k`); level 3 gains :math:`\tfrac12(X_k\otimes \mathsf{s}h_k +
        \mathsf{s}h_k\otimes X_k)` per step, and the Chen products supply the cross integrals of
        :math:`X` and :math:`\mathsf{s}t` between steps. This equals the translation of the rough path by
        :math:`t\mapsto\mathsf{s}t` up to per-step terms whose Chen sum is bounded by
        :math:`\max_k h_k \cdot \sum_k |X_k|` at level 3, so the two agree as the mesh shrinks
        (they are exactly equal at levels 1 and 2).

        Parameters
        ----------
        s : array_like, shape ``(d, d)`` or ``(..., d, d)`` broadcasting against the batch
            Antisymmetric.
        """
        if self._level < 2:
            raise ValueError("perturb needs level >= 2; this path is level 1.")
        s = check_antisymmetric(s, "s", dim=self._dim)
        d = self._dim
        try:
            batch = np.broadcast_shapes(s.shape[:-2], self.batch_shape)
        except ValueError:
            raise ValueError(f"s has batch shape {s.shape[:-2]}, which does not broadcast against the path's "
                             f"batch shape {self.batch_shape}.") from None
        z = np.array(np.broadcast_to(tensor_log(self._sig, d), batch + self._sig.shape[-2:]))
        z[..., d:d + d * d] += s.reshape(s.shape[:-2] + (1, d * d)) * self.dt[:, None]
        return RoughPathN(tensor_exp(z, d), d, times=self._times,
                          x0=np.broadcast_to(self._x0, batch + (d,)), check=False)

    def truncate(self, level: int) -> "RoughPathN":
        """The same path truncated at a lower level (a group morphism)."""
        level = check_positive_int(level, "level")
        if level > self._level:
            raise ValueError(f"level={level} exceeds this path's level {self._level}; extend a level-2 path "
                             f"with RoughPathN.from_rough_path instead.")
        return RoughPathN(self._sig[..., :sigdim(self._dim, level)], self._dim, times=self._times,
                          x0=self._x0, check=False)

    def to_rough_path(self) -> RoughPath:
        """Levels 1 and 2 as a (geometric) :class:`~roughpaths.RoughPath` (level 1 if ``N = 1``)."""
        return RoughPath(self.increments, self.areas, times=self._times, x0=self._x0,
                         kind=None if self._level < 2 else "geometric", check=False)

    def __getitem__(self, index) -> "RoughPathN":
        """Index the batch axes only, e.g. ``X[0]`` or ``X[:10]``."""
        if not self.batch_shape:
            raise IndexError("this rough path has no batch axes to index.")
        np.empty(self.batch_shape, dtype=bool)[index]
        idx = index if isinstance(index, tuple) else (index,)
        return RoughPathN(self._sig[idx + (slice(None),) * 2], self._dim, times=self._times,
                          x0=self._x0[idx + (slice(None),)], check=False)

    # ------------------------------------------------------------------ norms
    def _pair_norms(self, max_points):
        """Per-level Euclidean norms ``|X^{(k)}_{t_i, t_j}|`` for all ``i < j``: ``(..., N, P, P)``.

        Uses ``X_{t_0,t_i}^{-1} ⊗ X_{t_0,t_j}`` from the prefix products (absolute error about
        ``1e-16`` times the size of the prefixes, ample for norms).
        """
        P = self.n_steps + 1
        if max_points is not None and P > max_points:
            raise ValueError(f"the all-pairs rough-path norms need O(points**2) memory; this grid has {P} "
                             f"points > max_points={max_points}. Restrict the path to a coarser grid "
                             f"(path.restrict(times)) or raise max_points.")
        d, sl = self._dim, _level_slices(self._dim, self._level)
        pre = self._prefix()
        out = np.zeros(self.batch_shape + (self._level, P, P))
        for i in range(P - 1):
            g = tensor_product(tensor_inverse(pre[..., i, :], d)[..., None, :], pre[..., i + 1:, :], d)
            for k in range(self._level):
                out[..., k, i, i + 1:] = np.sqrt(np.sum(g[..., sl[k]] ** 2, axis=-1))
        return out

    def holder_norm(self, alpha: float, *, max_points=_DEFAULT_MAX_POINTS) -> np.ndarray:
        r"""Homogeneous :math:`\alpha`-Hölder rough-path norm on the grid, shape ``(...)``.

        :math:`\max_{k\le N}\ \max_{i<j} |\mathbf{X}^{(k)}_{t_i,t_j}|^{1/k} / (t_j - t_i)^{\alpha}`, with the
        Euclidean (Frobenius) norm on :math:`(\mathbb{R}^d)^{\otimes k}`. Exact over grid pairs,
        ``O(points**2)`` work and memory.
        """
        alpha = float(alpha)
        if not 0.0 < alpha <= 1.0:
            raise ValueError(f"alpha must be in (0, 1], got {alpha!r}.")
        norms = self._pair_norms(max_points)
        t = self._times
        lag = np.abs(t[None, :] - t[:, None])
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(lag > 0, 1.0 / np.where(lag > 0, lag, 1.0) ** alpha, 0.0)
        k = np.arange(1, self._level + 1).reshape((self._level, 1, 1))
        return np.max(norms ** (1.0 / k) * w, axis=(-3, -2, -1))

    def p_variation(self, p: float, *, max_points=_DEFAULT_MAX_POINTS) -> np.ndarray:
        r"""Homogeneous ``p``-variation of the rough path over grid partitions, shape ``(...)``.

        :math:`\big(\max_{\mathcal P}\sum_{[t_i,t_j]\in\mathcal P}\|\mathbf{X}_{t_i,t_j}\|^p\big)^{1/p}` with
        :math:`\|g\| = \max_{k\le N}|g^{(k)}|^{1/k}` (Euclidean norms per level), maximised exactly over
        all partitions by grid points (dynamic programming, ``O(points**2)``).
        """
        p = float(p)
        if not p >= 1.0 or not np.isfinite(p):
            raise ValueError(f"p must be a finite number >= 1, got {p!r}.")
        norms = self._pair_norms(max_points)
        k = np.arange(1, self._level + 1).reshape((self._level, 1, 1))
        w = np.max(norms ** (1.0 / k), axis=-3) ** p                     # (..., P, P)
        P = w.shape[-1]
        best = np.zeros(self.batch_shape + (P,))
        for j in range(1, P):
            best[..., j] = np.max(best[..., :j] + w[..., :j, j], axis=-1)
        return best[..., -1] ** (1.0 / p)

    def __repr__(self) -> str:
        return (f"RoughPathN(level={self._level}, d={self._dim}, n_steps={self.n_steps}, "
                f"batch_shape={self.batch_shape}, t=[{self._times[0]:g}, {self._times[-1]:g}])")
