r"""The entry point :func:`solve` for rough differential equations.

Solves :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i` on the grid of a :class:`~roughpaths.RoughPath`
(or of a :class:`~roughpaths.Driver`, consumed block by block) with a one-step solver that
follows the contract of :class:`roughpaths.Solver`. The time loop runs over steps in Python
(or inside a solver's compiled block kernel); every step is vectorised over the batch (the driver's
batch axes broadcast against those of ``y0``), so no Python loop runs per path. Batch members never
affect each other: a member that becomes non-finite is reported by its index and step, and with
``on_failure="mask"`` the healthy members' results are returned unchanged.
"""

from __future__ import annotations

import time as _time

import numpy as np

from ..validation import as_float_array, check_memory, check_positive_int, check_same_batch
from ..drivers.base import Driver
from ..drivers.tree import BrownianTree
from ..progress import progress_reporter
from ..paths.rough_path import RoughPath
from ..paths.rough_path_n import RoughPathN
from .adaptive import solve_adaptive
from .base import Solver
from .solution import NonFiniteStateError, Solution, _failure_message
from .davie import Davie
from .euler import Euler, Heun
from .logode import LogODE

__all__ = ["solve", "Solution", "NonFiniteStateError"]


#: Solver names accepted by :func:`~roughpaths.solve` as strings (default instances).
SOLVERS = {"euler": Euler, "heun": Heun, "davie": Davie, "logode": LogODE}


def _resolve_solver(solver) -> Solver:
    if solver is None:
        return Davie()
    if isinstance(solver, str):
        key = solver.lower().replace("-", "").replace("_", "")
        if key not in SOLVERS:
            raise ValueError(f"unknown solver name {solver!r}; valid names are {sorted(SOLVERS)} "
                             f"(or pass an instance, e.g. solver=Davie()).")
        return SOLVERS[key]()
    if isinstance(solver, type):
        if issubclass(solver, Solver):
            raise TypeError(f"solver must be an instance, got the class {solver.__name__}; "
                            f"did you mean {solver.__name__}()?")
        raise TypeError(f"solver must be a Solver instance, got the class {solver.__name__}.")
    if not isinstance(solver, Solver):
        raise TypeError(f"solver must be a Solver instance (Euler(), Heun(), Davie(), LogODE(), or a "
                        f"coadjoint solver from mechanics) or one of the names {sorted(SOLVERS)}, got "
                        f"{type(solver).__name__}.")
    return solver


def solve(fields, driver, y0, solver=None, *, drift=None, save_at="all", on_failure="raise",
          block_steps=None, executor=None, chunks=None, step_control=None, progress=None) -> Solution:
    r"""Solve the RDE :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i`, :math:`Y_{t_0} = y_0`, on the driver's grid.

    Parameters
    ----------
    fields : VectorFields or another object the solver accepts
        The family :math:`(V_0; V_1..V_d)` (:class:`~roughpaths.LinearVectorFields` or
        :class:`~roughpaths.VectorFields`); coadjoint solvers of :mod:`mechanics`
        accept a ``LiePoissonSystem``. Driving field ``i`` of the API (``0``-based) is
        :math:`V_{i+1}` of the maths; the maths' :math:`V_0` is the drift. The object must have
        ``dim_state`` (``e``) and ``dim_noise`` (``d``).
    driver : RoughPath, RoughPathN, Driver or BrownianTree
        Batch shape ``B_X``, dimension ``d``, ``N`` steps; a :class:`~roughpaths.Driver` is
        consumed block by block (memory for one block). A :class:`~roughpaths.BrownianTree` is
        solved on ``[tree.t0, tree.t1]`` with adaptive steps (``step_control``). Level 2 for level-2
        solvers, a :class:`~roughpaths.RoughPathN` of level >= 3 for level-3 solvers (``LogODE3``, ``Davie3``).
        Convention: area :math:`\mathbb{X}^{ij} = \int (X^i - X^i_s)\,dX^j`.
    y0 : array_like, shape ``(..., e)``
        Initial condition(s); the batch ``B_y`` broadcasts against ``B_X``.
    solver : Solver instance or str, optional
        ``Davie()`` (default), ``LogODE()``, ``Heun()``, ``Euler()``, or one of the names
        ``"davie", "logode", "heun", "euler"``; any object following the :class:`~roughpaths.Solver`
        contract.
    drift : callable, matrix ``(e, e)`` or LinearDrift, optional
        Extra drift added to :math:`V_0`, e.g. ``fields.friz_oberhauser_drift(s)`` (vector fields only).
    save_at : "all", "end" or array_like of grid times
        Which states to keep (default all ``N + 1``; with adaptive steps every accepted step, or the
        given times in ``[t0, t1]``, which the steps then hit). Times are given in increasing order, as
        ``Solution.times`` returns them: unsorted times are refused, never reordered (a repeated time
        is saved once).
    on_failure : "raise" or "mask"
        What to do when batch members become non-finite: raise :class:`NonFiniteStateError` naming every
        failed member and its step (default), or finish the healthy members and return them, with
        ``Solution.failed_step`` marking the failed ones (their states are NaN from the failure on).
        Either way a healthy member's result is the one it has when solved alone.
    block_steps : int, optional
        Steps per block requested from a :class:`~roughpaths.Driver` (its default if ``None``);
        it changes memory use, never the numbers.
    executor : concurrent.futures.Executor, optional
        Split the (flattened) batch into ``chunks`` contiguous groups of members and solve each on
        the executor (a thread or process pool, or a Dask cluster's ``client.get_executor()``). Since
        members never affect each other, the result is bitwise that of the serial call. With a process
        pool or a cluster, the fields, driver and solver must pickle (vector fields built from
        module-level functions do). A lazy driver must offer ``select(paths)``.
    chunks : int, optional
        Number of groups for ``executor`` (default ``min(members, 4 × CPU count)``).
    step_control : PIController, optional
        Adaptive steps, for a :class:`~roughpaths.BrownianTree` driver and an order-1 solver (``Davie``,
        ``LogODE``, a coadjoint ``LieHeun``): step doubling on the same tree, the steps shared by the
        batch (:mod:`roughpaths.rde.adaptive`; ``docs/adaptive-steps.md``). ``Solution.stats`` then holds
        ``accepted``, ``rejected`` and ``at_dt_min``. Fixed steps (``None``) need a grid: a
        ``RoughPath``, a ``Driver``, or ``tree.rough_path(times)``.
    progress : None, bool or callable
        Report progress and the time left (:mod:`roughpaths.progress`): ``None``/``False`` silent (default),
        ``True`` a bar on standard error (``tqdm`` if importable, else a plain line), a callable is called
        with a :class:`~roughpaths.ProgressRecord` ``(done, total, elapsed, eta)``. On a grid, ``done`` counts
        steps of every member (``total = N × members``) and advances once per block of steps: per block of
        a :class:`~roughpaths.Driver` (``block_steps``), per finished group with ``executor`` (in group
        order), once at the end for a ``RoughPath`` (a single block). With adaptive steps, ``done`` is the
        time reached, ``t - t0`` of ``total = t1 - t0``, once per accepted step. Never changes the numbers.

    Returns
    -------
    Solution
        ``times (K,)``, ``states (broadcast(B_X, B_y), K, e)``, ``failed_step``, ``stats``.

    Raises
    ------
    ValueError
        Mismatched dimensions; a level-2 solver with a level-1 driver; an unknown solver name.
    NonFiniteStateError
        (a ``ValueError``) members became non-finite, with ``on_failure="raise"``.
    TypeError
        A solver class instead of an instance ("did you mean Davie()?"), wrong argument types.

    Notes
    -----
    Threads: the compiled parts of a solve (a Brownian driver's sampling, the coadjoint solvers of
    :mod:`mechanics`) split the paths over numba's threads, the calling thread included; set their number
    with ``numba.set_num_threads(k)`` (per calling thread) or the ``NUMBA_NUM_THREADS`` environment
    variable. Every member's result is bitwise the same for every thread count (each member is computed
    by the same instructions, from its own random streams). ``executor`` adds parallelism over groups of
    members on top (processes, or a cluster).

    Examples
    --------
    Friz–Oberhauser: a perturbed area equals an extra drift (exactly, step by step, for ``LogODE`` on
    linear fields):

    >>> import numpy as np
    >>> from roughpaths import LinearVectorFields, LogODE, RoughPath, solve
    >>> rng = np.random.default_rng(0)
    >>> V = LinearVectorFields(0.5 * rng.standard_normal((2, 3, 3)))
    >>> X = RoughPath.from_path(np.cumsum(0.1 * rng.standard_normal((8, 65, 2)), axis=-2))
    >>> s = np.array([[0.0, 0.7], [-0.7, 0.0]])
    >>> a = solve(V, X.perturb(s), np.ones(3), LogODE()).final
    >>> b = solve(V, X, np.ones(3), LogODE(), drift=V.friz_oberhauser_drift(s)).final
    >>> a.shape, bool(np.allclose(a, b, atol=1e-12))
    ((8, 3), True)
    """
    solver = _resolve_solver(solver)
    fields = solver.check_fields(fields)
    _check_save_at(save_at)
    if block_steps is not None:
        block_steps = check_positive_int(block_steps, "block_steps")
    if isinstance(driver, BrownianTree):
        if step_control is None:
            raise ValueError("a BrownianTree driver needs adaptive steps: pass step_control=PIController(rtol, "
                             "atol), or solve on a grid with driver=tree.rough_path(times).")
        if executor is not None:
            raise ValueError("executor= splits a batch solved on a fixed grid; adaptive steps are shared by the "
                             "batch, so solve the tree serially (or one tree per process).")
    elif step_control is not None:
        raise ValueError(f"step_control needs a driver that answers on any interval, a roughpaths.BrownianTree; "
                         f"got a {type(driver).__name__}, whose grid is fixed. Build BrownianTree(dim, seed=...) "
                         f"or drop step_control.")
    if executor is not None:
        return _solve_split(fields, driver, y0, solver, executor, chunks, progress, drift=drift, save_at=save_at,
                            on_failure=on_failure, block_steps=block_steps)
    if not isinstance(driver, (RoughPath, RoughPathN, Driver, BrownianTree)):
        raise TypeError(f"driver must be a RoughPath, a RoughPathN, a Driver (e.g. roughpaths.BrownianDriver) or a "
                        f"BrownianTree, got {type(driver).__name__}; build a path with "
                        f"RoughPath.from_path(values, times=...) or RoughPath(increments, areas, times=...).")
    if on_failure not in ("raise", "mask"):
        raise ValueError(f"on_failure must be 'raise' or 'mask', got {on_failure!r}.")
    if driver.dim != fields.dim_noise:
        raise ValueError(f"the driver has dimension d={driver.dim} but the vector fields have "
                         f"dim_noise={fields.dim_noise}; one field per driving component is needed.")
    solver.check_driver(driver)
    # what a step receives: the solver's level, or the driver's if lower and the solver accepted it
    # (a coadjoint solver on a level-1 driver: increments alone, zero step area)
    level = min(solver.increment_level, driver.level)
    e = fields.dim_state
    y = as_float_array(y0, "y0", min_ndim=1)
    if y.shape[-1] != e:
        raise ValueError(f"y0 has last dimension {y.shape[-1]} but the vector fields act on R^{e} "
                         f"(dim_state={e}); y0 must have shape (..., {e}).")
    batch = check_same_batch(y.shape[:-1], driver.batch_shape, "y0", "driver")
    y = np.array(np.broadcast_to(y, batch + (e,)))
    if drift is not None:
        if not hasattr(fields, "with_drift"):
            raise TypeError(f"drift= is for vector fields; {type(fields).__name__} takes its drift from "
                            f"its own definition.")
        fields = fields.with_drift(drift)
    if step_control is not None:
        return solve_adaptive(fields, driver, y, solver, step_control, save_at, on_failure, batch, progress)

    times = np.asarray(driver.times)
    n = driver.n_steps
    if isinstance(save_at, str):
        if save_at == "all":
            idx = np.arange(n + 1)
        elif save_at == "end":
            idx = np.array([n])
        else:
            raise ValueError(f"save_at must be 'all', 'end' or an array of grid times, got {save_at!r}.")
    else:
        idx = np.unique(_index_of(driver, save_at).ravel())
    save_mask = np.zeros(n + 1, dtype=bool)
    save_mask[idx] = True
    members = float(np.prod(batch, dtype=np.float64))
    check_memory(8.0 * members * idx.size * e, f"the saved states ({members:.0f} member(s) x {idx.size} "
                 f"time(s) x {e})", "save fewer times (save_at='end' or a coarser array of grid times) or "
                 "solve the batch in parts")
    work, blocks_what = _working_bytes(driver, block_steps, members, e, level, int(idx.size),
                                       solver.step_nbytes(fields) if hasattr(solver, "step_nbytes") else None)
    check_memory(work, f"the solver's working arrays ({members:.0f} member(s): {blocks_what}, the states saved "
                       f"per block and one step's temporaries)",
                 "pass a smaller block_steps, or solve the batch in parts (driver.select(...), or executor=...)")
    out = np.empty(batch + (idx.size, e))
    slot = 0
    if save_mask[0]:
        out[..., 0, :] = y
        slot = 1

    failed_step = np.full(batch, -1, dtype=np.int64)
    blocks = driver.blocks(block_steps) if isinstance(driver, Driver) else (driver,)
    k0 = 0
    n_blocks = 0
    report = progress_reporter(progress, n * members, desc="solve", unit="member-steps")
    t_start = _time.perf_counter()
    try:
        for block in blocks:
            kb = block.n_steps
            save = save_mask[k0 + 1:k0 + kb + 1]
            y, saved, first_bad = solver.integrate(fields, y, block.times, block.increments,
                                                   _higher_levels(block, level), save,
                                                   stop_on_failure=(on_failure == "raise"))
            new_bad = (first_bad >= 0) & (failed_step < 0)
            if new_bad.any():
                failed_step[new_bad] = first_bad[new_bad] + k0
                if on_failure == "raise":
                    msg, members, steps = _failure_message(failed_step, times, batch)
                    raise NonFiniteStateError(msg, members, steps)
                y[failed_step >= 0] = np.nan
            nsave = saved.shape[-2]
            out[..., slot:slot + nsave, :] = saved
            slot += nsave
            k0 += kb
            n_blocks += 1
            if report is not None:
                report.update(k0 * members)
    finally:
        if report is not None:
            report.close()
    if k0 != n:
        raise RuntimeError(f"the driver's blocks covered {k0} of its {n} steps; its blocks() is broken.")
    if on_failure == "mask" and (failed_step >= 0).any():
        mark = (failed_step[..., None] >= 0) & (idx > failed_step[..., None])
        out[mark] = np.nan
    stats = {"solver": repr(solver), "n_steps": n, "n_blocks": n_blocks, "batch_shape": batch,
             "wall_time": _time.perf_counter() - t_start}
    return Solution(times=times[idx].copy(), states=out, failed_step=failed_step, stats=stats)


def _working_bytes(driver, block_steps, members: float, e: int, level: int, n_saved: int, step_bytes=None):
    """Bytes a fixed-step :func:`solve` holds besides its saved states, and what holds them (for the message).

    With ``M`` members, ``N`` steps, blocks of ``K`` steps, ``d`` noise and ``e`` state dimensions:

    * a lazy driver's blocks: two of ``driver.block_nbytes(K)`` (the generator makes the next block while
      the loop still holds the last; one if a block covers the grid); a ``RoughPath`` is read in place;
    * the states a block saves before they are copied out, ``8 M min(K, saved) e``;
    * the state, its copy and the failure indices, ``8 M (2 e + 1)``;
    * one step's temporaries, per member: the slice of the area (d²) and of level 3 (d³) the step is given,
      the fields' values and their product with the area (2 e d), their Jacobians (d e²), the linear
      generators (2 e²) with a log-ODE step's matrix exponential (up to 14 e², scaling and squaring) and up to
      eight state-sized sums (8 e), 8 bytes each; or, besides the areas, what the solver states
      (``step_bytes``, contract item 9 of :class:`~roughpaths.Solver`).
    """
    N, d = driver.n_steps, driver.dim
    if isinstance(driver, Driver):
        K = block_steps if block_steps is not None else getattr(driver, "default_block_steps", lambda: N)()
        K = min(K, N)
        nb = 2 if K < N else 1
        # a driver without block_nbytes (one of the caller's own) states nothing of its blocks
        per_block = driver.block_nbytes(K) if hasattr(driver, "block_nbytes") else 0.0
        blocks, what = nb * per_block, f"{nb} driver block(s) of {K} steps"
    else:
        K, blocks, what = N, 0.0, "the path read in place"
    d3 = float(d) ** 3 if level >= 3 else 0.0
    step = float(d) ** 2 + d3 + 2.0 * e * d + float(d) * e * e + 16.0 * e * e + 8.0 * e
    if step_bytes is not None:
        step = float(d) ** 2 + d3 + float(step_bytes) / 8.0
    return (blocks + 8.0 * members * (min(K, n_saved) * e + 2 * e + 1 + step) + 4096.0), what


def _check_save_at(save_at) -> None:
    """Refuse an array ``save_at`` that is not 1-D (or a scalar) or not in increasing order (every route of
    :func:`solve` keeps times in order; sorting them silently would pair the caller's times with other states)."""
    if isinstance(save_at, str):
        return
    t = as_float_array(save_at, "save_at")
    if t.ndim > 1:
        raise ValueError(f"save_at must be a 1-D array of times, got shape {t.shape}; pass np.ravel(save_at) "
                         f"if you meant its entries in that order.")
    if t.ndim == 1 and np.any(t[1:] < t[:-1]):
        k = int(np.argmax(t[1:] < t[:-1]))
        shown = repr(save_at) if len(repr(save_at)) <= 80 else repr(save_at)[:77] + "..."
        raise ValueError(f"save_at must be in increasing order (Solution.times and states follow it), but "
                         f"save_at[{k}]={float(t[k])!r} > save_at[{k + 1}]={float(t[k + 1])!r} in "
                         f"save_at={shown}; sort it (np.sort(save_at)) and read the states in that order.")


def _higher_levels(block, increment_level):
    """The ``dXX`` argument of contract item 8: None, the areas, or ``(areas, level-3 components)``."""
    if increment_level < 2:
        return None
    if increment_level == 2:
        return block.areas
    return block.areas, block.step_level(3)


def _index_of(driver, save_at):
    if isinstance(driver, (RoughPath, RoughPathN)):
        return driver.index_of(save_at, "save_at")
    return RoughPath(np.zeros((driver.n_steps, driver.dim)), times=driver.times, check=False).index_of(
        save_at, "save_at")


def _chunk_of(driver, batch, lo, hi):
    """Members ``lo:hi`` of the flattened batch of ``driver`` (broadcast to ``batch``)."""
    if isinstance(driver, RoughPath):
        n, d = driver.n_steps, driver.dim
        inc = np.broadcast_to(driver.increments, batch + (n, d)).reshape((-1, n, d))[lo:hi]
        areas = None
        if driver.areas is not None:
            areas = np.broadcast_to(driver.areas, batch + (n, d, d)).reshape((-1, n, d, d))[lo:hi]
        x0 = np.broadcast_to(driver.x0, batch + (d,)).reshape((-1, d))[lo:hi]
        return RoughPath(inc, areas, times=driver.times, x0=x0, kind=driver.kind, check=False)
    if driver.batch_shape != batch:
        raise ValueError(f"with executor=, a lazy driver's batch shape {driver.batch_shape} must be the "
                         f"batch shape of the solve {batch}; give y0 without extra batch axes.")
    if not hasattr(driver, "select"):
        raise TypeError(f"executor= needs to split the driver's batch, but {type(driver).__name__} has no "
                        f"select(paths) method; materialise it with driver.rough_path() or solve serially.")
    return driver.select(np.arange(lo, hi))


def _solve_split(fields, driver, y0, solver, executor, chunks, progress, **kw):
    import os

    from ..validation import check_positive_int

    if not hasattr(executor, "submit"):
        raise TypeError(f"executor must be a concurrent.futures.Executor (e.g. ProcessPoolExecutor(), or a "
                        f"Dask client's get_executor()), got {type(executor).__name__}.")
    if not isinstance(driver, (RoughPath, Driver)):
        raise TypeError(f"driver must be a RoughPath or a Driver, got {type(driver).__name__}.")
    y = as_float_array(y0, "y0", min_ndim=1)
    batch = check_same_batch(y.shape[:-1], driver.batch_shape, "y0", "driver")
    members = int(np.prod(batch, dtype=np.int64))
    if kw["drift"] is not None:
        fields = fields.with_drift(kw["drift"])
    kw["drift"] = None
    if members == 0:
        return solve(fields, driver, y0, solver, progress=progress, **kw)
    n_chunks = min(members, 4 * (os.cpu_count() or 1)) if chunks is None else check_positive_int(chunks, "chunks")
    bounds = np.linspace(0, members, min(n_chunks, members) + 1).round().astype(int)
    yflat = np.broadcast_to(y, batch + y.shape[-1:]).reshape((-1, y.shape[-1]))
    mode, kw["on_failure"] = kw["on_failure"], "mask"
    report = progress_reporter(progress, driver.n_steps * members, desc="solve", unit="member-steps")
    futures = [executor.submit(solve, fields, _chunk_of(driver, batch, lo, hi), yflat[lo:hi], solver, **kw)
               for lo, hi in zip(bounds[:-1], bounds[1:])]
    parts = []
    try:
        for hi, f in zip(bounds[1:], futures):       # in group order: each finished group reports its members
            parts.append(f.result())
            if report is not None:
                report.update(driver.n_steps * int(hi))
    finally:
        if report is not None:
            report.close()
    states = np.concatenate([s.states for s in parts], axis=0).reshape(batch + parts[0].states.shape[-2:])
    failed = np.concatenate([s.failed_step for s in parts]).reshape(batch)
    if mode == "raise" and (failed >= 0).any():
        msg, mem, steps = _failure_message(failed, np.asarray(driver.times), batch)
        raise NonFiniteStateError(msg, mem, steps)
    stats = {"solver": repr(solver), "n_steps": driver.n_steps, "n_blocks": sum(s.stats["n_blocks"] for s in parts),
             "batch_shape": batch, "chunks": len(parts),
             "wall_time": max(s.stats["wall_time"] for s in parts)}
    return Solution(times=parts[0].times, states=states, failed_step=failed, stats=stats)
