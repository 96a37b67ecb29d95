r"""Ensembles of stochastic Lie–Poisson paths: one entry point, :func:`run_ensemble`, on top of :func:`roughpaths.solve`.

:func:`run_ensemble` simulates ``n_paths`` independent paths of a
:class:`~mechanics.systems.lie_poisson.LiePoissonSystem` driven by a :class:`roughpaths.BrownianDriver`
(Stratonovich Brownian motion, with a sampled Lévy area or level-1 driving) and returns streaming
statistics (memory independent of ``n_steps``; ``O(chunk_size)`` in the paths):

* ``final``: count, mean and covariance across paths of ``observable(μ_T)``;
* ``time_average``: the same for each path's time average of ``observable(μ_t)`` over
  ``burn_in < t ≤ T`` (the paths are independent, so the standard error of the ensemble mean of
  time averages is honest whatever the autocorrelation within a path);
* ``snapshots``: optional statistics at every ``record_every``-th step.

It is the same computation as ``roughpaths.solve(system, BrownianDriver(m, seed=seed, dt=dt,
n_steps=n_steps, batch_shape=(n_paths,), levy_area=levy_area), mu0, method)``: paths are split into
chunks of ``chunk_size`` (``driver.select``), each chunk is solved block by block in time
(``block_steps``) and reduced to statistics on the fly.

Reproducibility. A path's noise depends only on ``(seed, path index, levy_area)`` (the driver's
stream); the coadjoint step of a member does not depend on the rest of the batch; time sums are
accumulated step by step; the across-path statistics are reduced in fixed leaves of
:data:`~mechanics.ensemble.statistics.LEAF` paths merged in path order
(:class:`~mechanics.ensemble.statistics.LeafReducer`). So the results — final states and every statistic —
are bitwise the same whatever ``chunk_size``, ``block_steps`` or ``executor``.

Executors. ``executor=`` accepts any :class:`concurrent.futures.Executor` (thread or process pool)
or anything with the same ``submit`` interface, e.g. a ``dask.distributed`` cluster through
``client.get_executor()`` (optional extra ``mechanics[dask]``). Tasks are ``(spec, first_path,
last_path)`` with a picklable spec: the system and the observable must be picklable for process
pools and clusters (a module-level function, not a lambda, as ``observable``).

Threads. Within a process, the driver's sampling and the coadjoint kernels split each chunk's paths over
numba's threads (``numba.set_num_threads(k)``, ``NUMBA_NUM_THREADS``), as in :func:`roughpaths.solve`; the
results are bitwise the same for every thread count.
"""

from __future__ import annotations

import os

from dataclasses import dataclass
from typing import Callable

import numpy as np

from roughpaths import BrownianDriver, progress_reporter, solve
from roughpaths.validation import as_float_array, check_memory, check_positive_int, check_positive_real, check_work

from ..integrators import CoadjointSolver, LieHeun
from ..systems.lie_poisson import LiePoissonSystem
from .checkpoint import fingerprint as _fingerprint
from .checkpoint import load_checkpoint as _load_checkpoint
from .checkpoint import save_checkpoint as _save_checkpoint
from .result import EnsembleResult
from .statistics import LeafReducer, accumulate, accumulate_moments, moment_observable

__all__ = ["run_ensemble"]

#: Fewest steps per time block when ``block_steps`` is not given (measured, 1000 paths x 1000 steps of the
#: rigid body with Davie's area, CPU time: chunks of 256 paths in the driver's cache-sized blocks cost
#: 1.37x a direct solve, chunks of 1024 in blocks of 250 steps 0.9-1.0x).
MIN_BLOCK_STEPS = 256


@dataclass(frozen=True)
class _Spec:
    system: object
    mu0: np.ndarray
    driver: BrownianDriver
    method: object
    block_steps: int | None
    burn_in: int
    average_every: int
    record_every: int | None
    observable: Callable
    keep_final: bool


def _observe(observable, x):
    return np.asarray(observable(x), dtype=np.float64)


def _check_observable(observable, mu0, n):
    """Evaluate ``observable`` on the initial state (shapes ``(1, n)`` and ``(1, 1, n)``) before any
    work starts: it must return finite arrays of shape ``(1, p)`` and ``(1, 1, p)``; returns ``p``."""
    x = np.array(np.broadcast_to(mu0, (1, n)), dtype=np.float64)
    outs = []
    for probe in (x, x[:, None]):
        try:
            v = np.asarray(observable(probe.copy()))
        except Exception as exc:
            raise ValueError(f"observable raised {type(exc).__name__}: {exc} when called on the initial state "
                             f"of shape {probe.shape}; it must map (..., {n}) -> (..., p).") from exc
        if v.dtype.kind not in "biuf":
            raise TypeError(f"observable must return real numbers, got an array of dtype {v.dtype} for input "
                            f"of shape {probe.shape}.")
        if v.ndim != probe.ndim or v.shape[:-1] != probe.shape[:-1] or v.shape[-1] < 1:
            raise ValueError(f"observable must map (..., {n}) -> (..., p) keeping the leading axes, but for "
                             f"input of shape {probe.shape} it returned shape {v.shape}; e.g. return "
                             f"x[..., :1] rather than a scalar.")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"observable returned non-finite values on the initial state {x[0]!r}.")
        outs.append(v.shape[-1])
    if outs[0] != outs[1]:
        raise ValueError(f"observable returned {outs[0]} values per state for input (1, {n}) but {outs[1]} for "
                         f"(1, 1, {n}); it must act on the last axis only.")
    return outs[0]


def _check_picklable(spec, executor):
    """A process or cluster executor pickles each task: refuse an unpicklable one (e.g. a lambda
    observable with a ProcessPoolExecutor) before any work is submitted."""
    import pickle
    from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

    if isinstance(executor, ThreadPoolExecutor):
        return
    try:
        pickle.dumps(spec)
        return
    except Exception as exc:
        error = exc
    if not isinstance(executor, ProcessPoolExecutor):
        try:                                   # cluster executors (dask) pickle with cloudpickle
            import cloudpickle

            cloudpickle.dumps(spec)
            return
        except ImportError:
            pass
        except Exception as exc:
            error = exc
    raise TypeError(f"executor {type(executor).__name__} must pickle each task, but the system or observable "
                    f"cannot be pickled ({type(error).__name__}: {error}); use a module-level function "
                    f"(not a lambda or a local function) as observable, or executor=None / a ThreadPoolExecutor.")


def _run_chunk(spec: _Spec, first: int, last: int):
    """Solve paths ``first .. last-1`` block by block; return their per-path values (picklable)."""
    system = spec.system
    c = last - first
    n = system.dim
    mu0 = spec.mu0 if spec.mu0.ndim == 1 else spec.mu0[first:last]
    mu = np.array(np.broadcast_to(mu0, (c, n)), dtype=np.float64)
    p = _observe(spec.observable, mu[:1]).shape[-1]
    acc = np.zeros((c, p))
    n_avg = 0
    snaps = []
    if spec.record_every is not None:
        snaps.append(_observe(spec.observable, mu))
    fast_moments = spec.observable is moment_observable
    step = 0
    driver = spec.driver.select(range(first, last))
    block_steps = spec.block_steps
    if block_steps is None:
        block_steps = max(driver.default_block_steps(), MIN_BLOCK_STEPS)
    # The blocks go straight to the method's ``integrate`` (what ``solve`` calls per block), checked once per
    # chunk: no per-block output array, copy or memory check, and only the steps used are saved. A failed
    # block is solved again through ``solve``, which raises its error (the same numbers: a pure function).
    method = spec.method
    method.check_driver(driver)
    with_area = min(method.increment_level, driver.level) >= 2
    for block in driver.blocks(block_steps):
        k = block.n_steps
        steps = np.arange(step + 1, step + k + 1)
        averaged = (steps > spec.burn_in) & (steps % spec.average_every == 0)
        recorded = (np.zeros(k, dtype=bool) if spec.record_every is None else steps % spec.record_every == 0)
        save = averaged | recorded
        new_mu, saved, first_bad = method.integrate(system, mu, block.times, block.increments,
                                                    block.areas if with_area else None, save,
                                                    stop_on_failure=True)      # saved: (c, save.sum(), n)
        if np.any(first_bad >= 0):
            solve(system, block, mu, method)                                   # raises NonFiniteStateError
            raise RuntimeError("a block failed in the compiled kernel but not in solve; please report this.")
        if averaged.any():
            window = saved if not recorded.any() else saved[:, averaged[save]]
            if fast_moments:
                accumulate_moments(acc, window)
            else:
                accumulate(acc, np.ascontiguousarray(_observe(spec.observable, window)))
            n_avg += window.shape[1]
        for j in np.flatnonzero(recorded[save]):
            snaps.append(_observe(spec.observable, saved[:, j]))
        mu = np.ascontiguousarray(new_mu, dtype=np.float64)
        step += k
    final = _observe(spec.observable, mu)
    return final, (acc / n_avg if n_avg else None), snaps, (mu if spec.keep_final else None)


def _check_working_memory(driver, system, block_steps, chunk_size, n_paths, n_steps, p, keep_final) -> None:
    """Refuse, before any path is solved, a chunk's working arrays above the memory budget.

    A chunk of ``c = min(chunk_size, n_paths)`` paths, in blocks of ``K`` steps (``block_steps``, else the
    chunk driver's default but at least ``MIN_BLOCK_STEPS``, at most ``n_steps``), with ``n`` state, ``m``
    noise and ``p`` observed dimensions, holds: two driver blocks (one if a block covers the run,
    ``driver.block_nbytes``); the states a block saves (``c K n``) and the observable on them with its
    contiguous copy (``2 c K p``); the state, its update, the time-average accumulator and the final values
    (``3 c n + 2 c p``); one step's temporaries per path (the noise's square, its products with the state,
    the Jacobian-sized ``m n²`` and up to ``16 n² + 8 n`` for the coadjoint maps), 8 bytes each. With
    ``keep_final`` the finals are concatenated at the end (a second ``n_paths x n``). With ``executor``,
    each concurrent chunk holds as much again.
    """
    n, m = system.dim, system.n_noise
    c = min(chunk_size, n_paths)
    chunk = driver.select(range(c))
    K = block_steps if block_steps is not None else max(chunk.default_block_steps(), MIN_BLOCK_STEPS)
    K = min(K, n_steps)
    blocks = (2 if K < n_steps else 1) * chunk.block_nbytes(K)
    step = float(m) ** 2 + 2.0 * n * m + float(m) * n * n + 16.0 * n * n + 8.0 * n
    need = blocks + 8.0 * c * (K * (n + 2 * p) + 3 * n + 2 * p + step) + 4096.0
    if keep_final:
        need += 8.0 * n_paths * n
    check_memory(need, f"the working arrays of a chunk of {c} paths ({K}-step blocks of the driver, the saved "
                       f"states and observables, one step's temporaries)",
                 "pass a smaller chunk_size or block_steps")


def run_ensemble(system, mu0, *, dt, n_steps, n_paths, seed, method=None, levy_area=None, levy_area_error=None,
                 observable=moment_observable, burn_in=0, average_every=1, record_every=None,
                 chunk_size=1024, block_steps=None, executor=None, keep_final=False,
                 checkpoint=None, keep_checkpoint=False, code_version=None, progress=None) -> EnsembleResult:
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
        Seed of the ``roughpaths.BrownianDriver``; path ``i`` is the driver's path ``i``.
    method : CoadjointSolver instance, optional
        ``LieHeun()`` by default. It drives with what the driver has: increments alone for
        ``levy_area=None``, increments and Lévy areas otherwise.
    levy_area : None or str
        The driver's Lévy-area method, any name :class:`roughpaths.BrownianDriver` accepts
        (:data:`roughpaths.LEVY_AREA_METHODS`). ``None`` (the default here): level-1 driving, zero step
        Lévy area. The default differs from the driver's on purpose: an ensemble estimates laws and time
        averages, for which the coadjoint schemes have weak order 1 with or without the area (the area has
        mean zero and enters at second order), and a level-1 driver draws no area, so each path-step is
        cheaper. Pass a method when the statistics are of pathwise quantities that need strong order 1.
    levy_area_error : float, optional
        The per-step L² error of the error-controlled methods, as for :class:`roughpaths.BrownianDriver`.
    observable : callable
        ``(..., n) → (..., p)``, evaluated state by state; default :func:`moment_observable` (first
        and second moments).
    burn_in : int
        Steps excluded from the time averages.
    average_every : int
        Use every ``average_every``-th step in the time averages.
    record_every : int, optional
        Also keep across-path statistics at steps ``0, record_every, 2·record_every, …``.
    chunk_size : int
        Paths per task (default 1024: the compiled kernels already run a task's paths on numba's
        threads, and each task pays a driver start-up). Changes memory use and parallelism, never the
        numbers.
    block_steps : int, optional
        Steps per time block (default: the driver's cache-sized blocks, at least
        256 steps (``MIN_BLOCK_STEPS``): each block is one call of the method's compiled kernel, whose fixed
        cost a longer block spreads over more steps). Changes memory use and speed, never the numbers.
    executor : concurrent.futures.Executor, optional
        Runs the chunks (default: serially in this process); e.g. ``dask.distributed``'s
        ``client.get_executor()``. Never changes the numbers.
    keep_final : bool
        Also return every path's final state.
    checkpoint : str or os.PathLike, optional
        A ``.npz`` file where the statistics merged so far are saved, atomically, after every chunk
        (with a fingerprint of the run's arguments). If the file exists when the run starts, the
        finished chunks are taken from it and only the rest is simulated: a run killed at any moment
        and started again with the same arguments returns bitwise the result of an uninterrupted run.
        The file is removed when the run completes, unless ``keep_checkpoint``.

        A checkpoint resumes only the run it belongs to, and it never takes identity on trust. Its
        fingerprint holds the numerical arguments, the pickled ``system``, ``method`` and ``observable``
        (their data, and the functions and classes they refer to, by name), the versions of
        roughpaths-mechanics and numpy, and ``code_version``; a checkpoint of another run is refused.
        A name identifies the library's own code (``roughpaths``, ``mechanics``, numpy: fixed by the
        version) but not yours: a function of yours can compute something else under the same name
        (an edited body, a global or a helper it reads). So with ``checkpoint``, a ``system``,
        ``method`` or ``observable`` that refers to code outside the library (your own observable, a
        Hamiltonian or force of yours, a solver subclass) is refused unless you pass
        ``code_version``; a lambda or a closure, which does not pickle, is refused (define it at
        module level). The file itself is untrusted input (:func:`roughpaths.io.open_npz`): a pipe,
        a folder or a device is refused, every array's size is checked before it is read, and every
        count, shape and statistic is checked against the run; a damaged or tampered file is
        refused with a message that names it and says to delete it.
    keep_checkpoint : bool
        Leave the checkpoint file in place after a completed run (default False).
    code_version : str, optional
        With ``checkpoint``: the version of your own code that the run calls (see ``checkpoint``), any
        non-empty string, e.g. ``"energy-observable-3"``. Change it whenever that code, or anything it
        reads, changes: a checkpoint written under another ``code_version`` is refused, one written under
        the same is resumed on your word. Required when the run refers to code outside the library,
        refused without ``checkpoint`` (it would have no effect).
    progress : None, bool or callable
        Report progress and the time left (:mod:`roughpaths.progress`): ``None``/``False`` silent (default),
        ``True`` a bar on standard error (``tqdm`` if importable, else a plain line), a callable is called
        with a :class:`roughpaths.ProgressRecord` ``(done, total, elapsed, eta)``. ``done`` counts paths of
        ``total = n_paths`` and advances once per chunk, as the chunks are merged in path order (with an
        executor, a slow first chunk holds back the report of later ones). A resumed run starts at the paths
        of its checkpoint and estimates the time left from this run's rate. Never changes the numbers.

    Returns
    -------
    EnsembleResult

    Examples
    --------
    >>> from mechanics.systems.lie_algebra import so3
    >>> from mechanics.systems.lie_poisson import LiePoissonSystem
    >>> rb = LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.5 * np.eye(3), theta=1.0)
    >>> a = run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=50, n_paths=6, seed=1, chunk_size=4,
    ...                  keep_final=True)
    >>> b = run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=50, n_paths=6, seed=1, chunk_size=5,
    ...                  block_steps=7, keep_final=True)
    >>> bool(np.array_equal(a.final_states, b.final_states) and np.array_equal(a.final.mean, b.final.mean))
    True
    """
    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a LiePoissonSystem (e.g. mechanics.rigid_body(...)), got "
                        f"{type(system).__name__}.")
    if method is None:
        method = LieHeun()
    if not isinstance(method, CoadjointSolver):
        raise TypeError(f"method must be a coadjoint solver instance (LieEuler(), LieHeun(), ImplicitMidpoint()), "
                        f"got {method!r}" + (f"; did you mean {method.__name__}()?" if isinstance(method, type)
                                             else "."))
    n = system.dim
    mu0 = as_float_array(mu0, "mu0", last_dims=(n,))
    dt = check_positive_real(dt, "dt")
    n_steps = check_positive_int(n_steps, "n_steps")
    n_paths = check_positive_int(n_paths, "n_paths")
    check_work(float(n_paths) * float(n_steps), f"run_ensemble with n_paths={n_paths} and n_steps={n_steps}",
               "use fewer paths or steps (or raise ROUGHPATHS_MAX_WORK)")
    if mu0.ndim not in (1, 2) or (mu0.ndim == 2 and mu0.shape[0] != n_paths):
        raise ValueError(f"mu0 must have shape ({n},) or (n_paths, {n}) = ({n_paths}, {n}), got {mu0.shape}.")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise TypeError(f"seed must be a non-negative integer, got {seed!r}.")
    if seed < 0:
        raise ValueError(f"seed must be a non-negative integer (SeedSequence entropy), got {seed!r}.")
    if not callable(observable):
        raise TypeError(f"observable must be callable (..., n) -> (..., p), got {observable!r}.")
    burn_in = check_positive_int(burn_in, "burn_in", minimum=0)
    average_every = check_positive_int(average_every, "average_every")
    if record_every is not None:
        record_every = check_positive_int(record_every, "record_every")
    chunk_size = check_positive_int(chunk_size, "chunk_size")
    if block_steps is not None:
        block_steps = check_positive_int(block_steps, "block_steps")
    if executor is not None and not hasattr(executor, "submit"):
        raise TypeError(f"executor must be a concurrent.futures.Executor (with .submit), got {executor!r}.")
    p = _check_observable(observable, mu0[:1] if mu0.ndim == 2 else mu0, n)
    if record_every is not None:
        n_snap = n_steps // record_every + 1
        check_memory(8.0 * n_snap * (p + p * p) * 3, f"the snapshot statistics ({n_snap} snapshots of {p} "
                     f"observables)", "record fewer snapshots (a larger record_every)")
    if keep_final:
        check_memory(8.0 * n_paths * n, f"the final states ({n_paths} paths x {n})",
                     "use keep_final=False or fewer paths")
    driver = BrownianDriver(system.n_noise, seed=int(seed), dt=float(dt), n_steps=n_steps, batch_shape=(n_paths,),
                            levy_area=levy_area, levy_area_error=levy_area_error)   # checks both
    spec = _Spec(system=system, mu0=mu0, driver=driver, method=method, block_steps=block_steps, burn_in=burn_in,
                 average_every=average_every, record_every=record_every, observable=observable,
                 keep_final=bool(keep_final))
    if executor is not None:
        _check_picklable(spec, executor)
    bounds = [(a, min(a + chunk_size, n_paths)) for a in range(0, n_paths, chunk_size)]
    final = tavg = None
    snaps: list = []
    finals = []
    start = 0
    if code_version is not None and checkpoint is None:
        raise ValueError(f"code_version={code_version!r} identifies your code in a checkpoint, and there is no "
                         f"checkpoint; pass checkpoint=... or leave code_version unset.")
    if checkpoint is not None:
        fingerprint = _fingerprint(system, mu0, dt, n_steps, n_paths, seed, method, (levy_area, levy_area_error),
                                   burn_in, average_every, record_every, chunk_size, keep_final, observable,
                                   code_version)
        n_avg = n_steps // average_every - min(burn_in, n_steps) // average_every     # steps in the time average
        state = _load_checkpoint(checkpoint, fingerprint, bounds=bounds, dim=p, state_dim=n,
                                 time_average=n_avg > 0, keep_final=bool(keep_final),
                                 n_snapshots=0 if record_every is None else n_steps // record_every + 1)
        if state is not None:
            start, final, tavg, snaps, finals = state
    todo = bounds[start:]
    # after the checkpoint (its own sizes are checked as it is read), before any path is solved
    _check_working_memory(driver, system, block_steps, chunk_size, n_paths, n_steps, p, keep_final)
    report = progress_reporter(progress, n_paths, desc="run_ensemble", unit="paths",
                               initial=bounds[start - 1][1] if start else 0)
    if executor is None:
        parts = (_run_chunk(spec, a, b) for a, b in todo)
    else:
        futures = [executor.submit(_run_chunk, spec, a, b) for a, b in todo]
        parts = (f.result() for f in futures)
    try:
        for done, (fin, ta, sn, fs) in enumerate(parts, start + 1):   # in path order: fixed leaves, bitwise
            if final is None:
                p = fin.shape[-1]
                final = LeafReducer(p)
                tavg = LeafReducer(p) if ta is not None else None
                snaps = [LeafReducer(p) for _ in sn]
            final.add(fin)
            if tavg is not None:
                tavg.add(ta)
            for red, values in zip(snaps, sn):
                red.add(values)
            if fs is not None:
                finals.append(fs)
            if checkpoint is not None:
                _save_checkpoint(checkpoint, fingerprint, done, final, tavg, snaps, finals)
            if report is not None:
                report.update(bounds[done - 1][1])
    finally:
        if report is not None:
            report.close()
    if checkpoint is not None and not keep_checkpoint:
        try:
            os.unlink(checkpoint)
        except FileNotFoundError:          # nothing was written (no chunk ran)
            pass
    snap_steps = [] if record_every is None else list(range(0, n_steps + 1, record_every))
    return EnsembleResult(final=final.result(), time_average=None if tavg is None else tavg.result(),
                          snapshot_times=np.asarray(snap_steps, dtype=np.float64) * float(dt),
                          snapshots=[r.result() for r in snaps],
                          final_states=np.concatenate(finals) if finals else None,
                          n_paths=n_paths, n_steps=n_steps, dt=float(dt), seed=int(seed), state_dim=n)
