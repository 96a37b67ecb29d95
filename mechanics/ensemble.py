r"""Ensembles of stochastic Lie–Poisson paths: reproducible streams, running statistics, executors.

:func:`run_ensemble` simulates ``n_paths`` independent paths of a
:class:`~mechanics.lie_poisson.LiePoissonSystem` driven by Stratonovich Brownian motion and returns
streaming statistics (memory independent of ``n_paths`` and ``n_steps``):

* ``final``: count, mean and covariance across paths of ``observable(μ_T)``;
* ``time_average``: the same for each path's time average of ``observable(μ_t)`` over
  ``burn_in < t ≤ T`` (the paths are independent, so the standard error of the ensemble mean of
  time averages is honest whatever the autocorrelation within a path);
* ``snapshots``: optional statistics at every ``record_every``-th step.

Reproducibility. Path ``i`` owns the random stream
``Generator(PCG64(SeedSequence(seed, spawn_key=(i,))))`` (the ``i``-th child of
``SeedSequence(seed).spawn``), consumed sequentially in time blocks of ``block_steps`` steps. A
path's noise therefore depends only on ``(seed, i, block_steps, levy_area)``: the same seed gives
the same paths whatever ``chunk_size`` (paths per task) or ``executor``, and the statistics agree
to round-off (they are merged in chunk order with Chan's formula). With ``levy_area=None`` the
stream is also independent of ``block_steps`` (``standard_normal`` draws concatenate).

Vectorisation. The time stepping is vectorised over the paths of a chunk (one call of
:func:`mechanics.integrators.simulate` per block, the numba so(3) kernel where it applies). The
only per-path Python work is one RNG call per path per time block (``O(n_paths · n_steps /
block_steps)`` calls, each drawing ``block_steps × m`` normals), negligible for
``block_steps ≳ 100``.

Executors. ``executor=`` accepts any :class:`concurrent.futures.Executor` (thread or process pool,
or a cluster client with the same ``submit`` interface). Tasks are ``(spec, first_path, last_path)``
with a picklable spec: the system, observable and method must be picklable for process pools (a
module-level function, not a lambda, as ``observable``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from roughpaths.validation import as_float_array, check_positive_int

__all__ = ["RunningMoments", "EnsembleResult", "moment_observable", "split_moment_features",
           "path_generator", "run_ensemble"]


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
        self.count = 0
        self.mean = np.zeros(self.dim)
        self.scatter = np.zeros((self.dim, self.dim))

    def update(self, x) -> "RunningMoments":
        """Add the rows of ``x`` (shape ``(k, p)`` or ``(p,)``); returns ``self``."""
        x = np.asarray(x, dtype=np.float64)
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
        if not isinstance(other, RunningMoments) or other.dim != self.dim:
            raise ValueError(f"can only merge a RunningMoments of dimension {self.dim}.")
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

    def __repr__(self) -> str:
        return f"RunningMoments(dim={self.dim}, count={self.count})"


# ------------------------------------------------------------------------------ observables
def moment_observable(x) -> np.ndarray:
    """``(x, x_i x_j for i ≤ j)``: first and second moments; ``(..., n)`` → ``(..., n + n(n+1)/2)``."""
    x = np.asarray(x, dtype=np.float64)
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


def path_generator(seed: int, index: int) -> np.random.Generator:
    """The generator of path ``index``: ``PCG64(SeedSequence(seed, spawn_key=(index,)))``.

    Identical to ``default_rng(SeedSequence(seed).spawn(n)[index])`` for any ``n > index``, but
    O(1) to build.
    """
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=(int(index),))))


# ------------------------------------------------------------------------------ results
@dataclass
class EnsembleResult:
    """Output of :func:`run_ensemble`.

    Attributes
    ----------
    final : RunningMoments
        Across-path statistics of ``observable(μ_T)``.
    time_average : RunningMoments or None
        Across-path statistics of the per-path time averages over ``burn_in < n ≤ n_steps``
        (every ``average_every``-th step); None if that window is empty.
    snapshot_times : ndarray (S,)
    snapshots : list of RunningMoments
        Statistics of ``observable(μ_t)`` at ``snapshot_times``.
    final_states : ndarray (n_paths, n) or None
        Only with ``keep_final=True`` (memory ``O(n_paths)``).
    n_paths, n_steps, dt, seed
    """

    final: RunningMoments
    time_average: RunningMoments | None
    snapshot_times: np.ndarray
    snapshots: list
    final_states: np.ndarray | None
    n_paths: int
    n_steps: int
    dt: float
    seed: int
    state_dim: int = 0

    def moments(self, which: str = "time_average"):
        """For the default observable: ``(mean (n,), second_moment (n, n), se_mean (n,), se_second (n, n))``
        of ``which`` in {"time_average", "final"}."""
        rm = self.time_average if which == "time_average" else self.final if which == "final" else None
        if rm is None:
            raise ValueError(f"which must be 'time_average' or 'final' (and that statistic must exist), got {which!r}.")
        n = self.state_dim
        if rm.dim != n + n * (n + 1) // 2:
            raise ValueError("moments() needs the default observable (moment_observable).")
        mean, m2 = split_moment_features(rm.mean, n)
        se_mean, se_m2 = split_moment_features(rm.standard_error, n)
        return mean, m2, se_mean, se_m2


@dataclass(frozen=True)
class _Spec:
    system: object
    mu0: np.ndarray
    dt: float
    n_steps: int
    seed: int
    method: object
    levy_area: str | None
    block_steps: int
    burn_in: int
    average_every: int
    record_every: int | None
    observable: Callable
    keep_final: bool


def _draw_block(gens, k, dt, m, levy_area):
    """Increments (c, k, m) and Stratonovich areas (c, k, m, m) (``None`` without Lévy area: level-1
    driving), one generator call per path."""
    c = len(gens)
    dW = np.empty((c, k, m))
    if levy_area is None:
        sq = math.sqrt(dt)
        for p, g in enumerate(gens):
            dW[p] = g.standard_normal((k, m)) * sq
        return dW, None
    from roughpaths.brownian import brownian_increments_and_areas
    areas = np.empty((c, k, m, m))
    for p, g in enumerate(gens):
        dW[p], areas[p] = brownian_increments_and_areas(g, k, dt, m, levy_area=levy_area)
    return dW, areas


def _observable_sum(observable, window):
    """``Σ_t observable(window[:, t])`` per path, ``(c, T, n) → (c, p)``; BLAS fast path for the moments."""
    if observable is moment_observable:
        n = window.shape[-1]
        i, j = np.triu_indices(n)
        second = np.matmul(np.swapaxes(window, 1, 2), window)        # (c, n, n) = Σ_t x xᵀ
        return np.concatenate([window.sum(axis=1), second[:, i, j]], axis=-1)
    return np.asarray(observable(window)).sum(axis=1)


def _run_chunk(spec: _Spec, first: int, last: int):
    """Simulate paths ``first .. last-1``; return their statistics (picklable)."""
    from roughpaths import RoughPath, solve

    system = spec.system
    c = last - first
    n, m = system.dim, system.n_noise
    gens = [path_generator(spec.seed, i) for i in range(first, last)]
    mu0 = spec.mu0 if spec.mu0.ndim == 1 else spec.mu0[first:last]
    mu = np.array(np.broadcast_to(mu0, (c, n)), dtype=np.float64)
    obs0 = np.asarray(spec.observable(mu[:1]))
    p = obs0.shape[-1]
    acc = np.zeros((c, p))
    n_avg = 0
    snaps = []
    snap_steps = []
    if spec.record_every is not None:
        rm = RunningMoments(p).update(np.asarray(spec.observable(mu)))
        snaps.append(rm)
        snap_steps.append(0)
    step = 0
    while step < spec.n_steps:
        k = min(spec.block_steps, spec.n_steps - step)
        dW, areas = _draw_block(gens, k, spec.dt, m, spec.levy_area)
        times = (step + np.arange(k + 1)) * spec.dt
        if areas is None:                                            # level 1: zero step Lévy area
            X = RoughPath.from_increments(dW, None, times=times)
            states = solve(system, X, mu, spec.method).states        # (c, k+1, n)
        else:
            X = RoughPath(dW, areas, times=times, kind="geometric", check=False)
            states = solve(system, X, mu, spec.method).states        # (c, k+1, n)
        idx = step + np.arange(1, k + 1)                             # global step numbers of states[:, 1:]
        # averaged steps: idx > burn_in and idx % average_every == 0, as a strided slice (no copy)
        first_ok = max(spec.burn_in + 1, step + 1)
        first_ok += (-first_ok) % spec.average_every
        if first_ok <= step + k:
            window = states[:, 1 + first_ok - step - 1::spec.average_every]
            acc += _observable_sum(spec.observable, window)
            n_avg += window.shape[1]
        if spec.record_every is not None:
            for j in np.nonzero(idx % spec.record_every == 0)[0]:
                snaps.append(RunningMoments(p).update(np.asarray(spec.observable(states[:, j + 1]))))
                snap_steps.append(int(idx[j]))
        mu = np.ascontiguousarray(states[:, -1])
        step += k
    final = RunningMoments(p).update(np.asarray(spec.observable(mu)))
    tavg = RunningMoments(p).update(acc / n_avg) if n_avg else None
    return final, tavg, snaps, snap_steps, (mu if spec.keep_final else None)


def run_ensemble(system, mu0, *, dt, n_steps, n_paths, seed, method=None, levy_area=None,
                 observable=moment_observable, burn_in=0, average_every=1, record_every=None,
                 chunk_size=256, block_steps=500, executor=None, keep_final=False) -> EnsembleResult:
    r"""Simulate ``n_paths`` independent Brownian-driven paths and return streaming statistics.

    Parameters
    ----------
    system : LiePoissonSystem
    mu0 : array_like, shape ``(n,)`` or ``(n_paths, n)``
        Common initial state, or one per path (e.g. samples of a known law, to skip a burn-in).
    dt : float
        Step size.
    n_steps : int
        Steps per path (horizon ``T = n_steps · dt``).
    n_paths : int
    seed : int
        Master seed; path ``i`` uses :func:`path_generator` ``(seed, i)``.
    method : integrator method, optional
        ``mechanics.integrators.LieHeun()`` by default.
    levy_area : {None, "davie", "foster"}
        ``None`` (default): zero step Lévy area (weak order 1, enough for laws and invariant
        measures). ``"davie"``/``"foster"``: sample it (strong order 1; slower).
    observable : callable
        ``(..., n) → (..., p)``; default :func:`moment_observable` (first and second moments).
    burn_in : int
        Steps excluded from the time averages.
    average_every : int
        Use every ``average_every``-th step in the time averages.
    record_every : int, optional
        Also keep across-path statistics at steps ``0, record_every, 2·record_every, …``.
    chunk_size : int
        Paths per task (memory ``O(chunk_size · block_steps · m²)``).
    block_steps : int
        Steps per random-number block (part of the stream definition when ``levy_area`` is set).
    executor : concurrent.futures.Executor, optional
        Runs the chunks (default: serially in this process).
    keep_final : bool
        Also return every path's final state.

    Returns
    -------
    EnsembleResult

    Examples
    --------
    >>> from mechanics.lie_algebra import so3
    >>> from mechanics.lie_poisson import LiePoissonSystem
    >>> rb = LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.5 * np.eye(3), theta=1.0)
    >>> a = run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=50, n_paths=6, seed=1, chunk_size=4,
    ...                  keep_final=True)
    >>> b = run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=50, n_paths=6, seed=1, chunk_size=5,
    ...                  keep_final=True)
    >>> bool(np.array_equal(a.final_states, b.final_states))
    True
    """
    from .integrators import CoadjointSolver, LieHeun

    if method is None:
        method = LieHeun()
    if not isinstance(method, CoadjointSolver):
        raise TypeError(f"method must be a coadjoint solver instance (LieEuler(), LieHeun(), ImplicitMidpoint()), "
                        f"got {method!r}" + (f"; did you mean {method.__name__}()?" if isinstance(method, type)
                                             else "."))
    if method.levy_area != (levy_area is not None):                 # the driving level follows levy_area
        import copy
        method = copy.copy(method)
        method.levy_area = levy_area is not None
    for attr in ("dim", "n_noise"):
        if not hasattr(system, attr):
            raise TypeError(f"system must be a LiePoissonSystem (needs .{attr}), got {type(system).__name__}.")
    n = system.dim
    mu0 = as_float_array(mu0, "mu0", last_dims=(n,))
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating)) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive finite number, got {dt!r}.")
    n_steps = check_positive_int(n_steps, "n_steps")
    n_paths = check_positive_int(n_paths, "n_paths")
    if mu0.ndim not in (1, 2) or (mu0.ndim == 2 and mu0.shape[0] != n_paths):
        raise ValueError(f"mu0 must have shape ({n},) or (n_paths, {n}) = ({n_paths}, {n}), got {mu0.shape}.")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be a non-negative integer, got {seed!r}.")
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer (SeedSequence entropy), got {seed!r}.")
    if levy_area not in (None, "davie", "foster"):
        raise ValueError(f"levy_area must be None, 'davie' or 'foster', got {levy_area!r}.")
    if not callable(observable):
        raise TypeError(f"observable must be callable (..., n) -> (..., p), got {observable!r}.")
    burn_in = check_positive_int(burn_in, "burn_in", minimum=0)
    average_every = check_positive_int(average_every, "average_every")
    if record_every is not None:
        record_every = check_positive_int(record_every, "record_every")
    chunk_size = check_positive_int(chunk_size, "chunk_size")
    block_steps = check_positive_int(block_steps, "block_steps")
    if executor is not None and not hasattr(executor, "submit"):
        raise TypeError(f"executor must be a concurrent.futures.Executor (with .submit), got {executor!r}.")

    spec = _Spec(system=system, mu0=mu0, dt=float(dt), n_steps=n_steps, seed=int(seed), method=method,
                 levy_area=levy_area, block_steps=block_steps, burn_in=burn_in,
                 average_every=average_every, record_every=record_every, observable=observable,
                 keep_final=bool(keep_final))
    bounds = [(a, min(a + chunk_size, n_paths)) for a in range(0, n_paths, chunk_size)]
    if executor is None:
        parts = (_run_chunk(spec, a, b) for a, b in bounds)
    else:
        futures = [executor.submit(_run_chunk, spec, a, b) for a, b in bounds]
        parts = (f.result() for f in futures)

    final = tavg = None
    snaps: list = []
    snap_steps: list = []
    finals = []
    for fin, ta, sn, st, fs in parts:               # merged in chunk order: deterministic
        final = fin if final is None else final.merge(fin)
        if ta is not None:
            tavg = ta if tavg is None else tavg.merge(ta)
        if not snaps:
            snaps, snap_steps = sn, st
        else:
            for a, b in zip(snaps, sn):
                a.merge(b)
        if fs is not None:
            finals.append(fs)
    return EnsembleResult(final=final, time_average=tavg,
                          snapshot_times=np.asarray(snap_steps, dtype=np.float64) * float(dt),
                          snapshots=snaps, final_states=np.concatenate(finals) if finals else None,
                          n_paths=n_paths, n_steps=n_steps, dt=float(dt), seed=int(seed), state_dim=n)
