r"""The entry point :func:`solve` for rough differential equations, and its one time loop.

Solves :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i` with a one-step solver that follows the contract of
:class:`roughpaths.Solver`. One loop serves every driver: the steps are proposed (a grid driver's blocks in
:mod:`roughpaths.rde._grid`; a step controller's attempts on a driver that answers on any times, e.g. a
:class:`~roughpaths.BrownianTree`, in :mod:`roughpaths.rde.adaptive`), the driver answers their increments
and areas, the solver integrates them (with the declared error estimate for an adaptive controller), the
controller accepts or rejects, and the states are saved or the failures marked; the failures, the memory
check of the saved states and the statistics exist once (:class:`_Run`). Every step is vectorised over the
batch, so no Python loop runs per path on a grid. Batch members never affect each other: a member that
becomes non-finite is reported by its index and step, and with ``on_failure="mask"`` the healthy members'
results are returned unchanged.
"""

from __future__ import annotations

import time as _time

import numpy as np

from ..validation import as_float_array, check_memory, check_positive_int, check_same_batch
from ..progress import progress_reporter
from ._arguments import SOLVERS, _check_control, _check_options, _check_save_at, _resolve_solver
from ._grid import _GridSteps
from .adaptive import _TreeSteps, _step_doubling
from .solution import NonFiniteStateError, Solution, _failure_message, _unmet_message
from ._split import _solve_split

__all__ = ["solve", "Solution", "NonFiniteStateError", "SOLVERS"]


def solve(fields, driver, y0, solver=None, *, drift=None, save_at="all", on_failure="raise",
          block_steps=None, executor=None, chunks=None, step_control=None, shared_steps=None,
          progress=None) -> Solution:
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
        solved on ``[tree.t0, tree.t1]`` with the steps of ``step_control``. Level 2 for level-2
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
        Which states to keep (default all ``N + 1``; with a step controller every accepted step, or the
        given times in ``[t0, t1]``, which the steps then hit). Times are given in increasing order, as
        ``Solution.times`` returns them: unsorted times are refused, never reordered (a repeated time
        is saved once).
    on_failure : "raise" or "mask"
        What to do when batch members become non-finite: raise :class:`NonFiniteStateError` naming every
        failed member and its step (default), or finish the healthy members and return them, with
        ``Solution.failed_step`` marking the failed ones (their states are NaN from the failure on; with steps
        per member a failed member takes no more steps, its states NaN at the save times left). Either way a
        healthy member's result is the one it has when solved alone (with ``shared_steps=True`` the steps, and
        so the results, depend on the whole batch by design).
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
    step_control : StepController, optional
        The step controller (:mod:`roughpaths.rde.step_control`). ``None``: the driver's grid (a ``RoughPath``,
        a ``Driver``). A :class:`~roughpaths.BrownianTree` needs one: :class:`~roughpaths.PIController` for
        adaptive steps (step doubling on the same tree, ``docs/adaptive-steps.md``; the solver must declare an
        error estimate, ``Solver.error_estimate``: ``Davie``, ``LogODE``, a coadjoint ``LieHeun``),
        :class:`~roughpaths.FixedSteps` ``(dt)``, or any object following the :class:`~roughpaths.StepController`
        contract. ``Solution.stats`` then holds ``accepted``, ``rejected`` and ``at_dt_min``.
    shared_steps : bool, optional
        With a step controller: ``False`` gives every batch member steps of its own (its result is bitwise the
        same alone or in any batch; the stats are arrays over the batch; with ``save_at="all"``,
        ``Solution.times`` has the batch's axes, shorter rows repeating their last time and state); ``True``
        makes the batch take the same steps (the error ratio is the maximum over its members). ``None``
        (default): steps per member where the solver steps members on their own times in one call
        (``Solver.member_times``: ``Davie``, ``LogODE``, ``Heun``, ``Euler`` on autonomous fields or fields
        declared ``batched_time``, and the coadjoint solvers of :mod:`mechanics`), shared steps otherwise, where
        per-member steps cost one call per member per attempt. ``Solution.stats["shared_steps"]`` says which
        ran.
    progress : None, bool or callable
        Report progress and the time left (:mod:`roughpaths.progress`): ``None``/``False`` silent (default),
        ``True`` a bar on standard error (``tqdm`` if importable, else a plain line), a callable is called
        with a :class:`~roughpaths.ProgressRecord` ``(done, total, elapsed, eta)``. On a grid, ``done`` counts
        steps of every member (``total = N × members``) and advances once per block of steps: per block of
        a :class:`~roughpaths.Driver` (``block_steps``), per finished group with ``executor`` (in group
        order), once at the end for a ``RoughPath`` (a single block). With a step controller, ``done`` is the
        time every member has reached, ``t - t0`` of ``total = t1 - t0``, reported when it grows (with shared
        steps once per accepted step). Never changes the numbers.

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
    control = _check_control(step_control, driver, solver, shared_steps)
    if executor is not None:
        if control is not None:
            raise ValueError("executor= splits a batch solved on a fixed grid; with a step controller solve serially "
                             "(the members' steps are their own: a member's result is the same in any batch).")
        return _solve_split(solve, fields, driver, y0, solver, executor, chunks, progress, drift=drift, save_at=save_at,
                            on_failure=on_failure, block_steps=block_steps)
    _check_options(driver, fields, on_failure)
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
    run = _Run(y, batch, on_failure, getattr(driver, "any_times", False))
    steps = (_TreeSteps(run, driver, control, solver, save_at, shared_steps, fields) if run.flat else
             _GridSteps(run, driver, save_at, block_steps, level,
                        solver.step_nbytes(fields) if hasattr(solver, "step_nbytes") else None))
    total, desc, unit = steps.progress_total
    report = run.report = progress_reporter(progress, total, desc=desc, unit=unit)
    t_start = _time.perf_counter()
    try:      # the one loop: propose, ask the driver (in propose), integrate, adapt, save or mark failures
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            while attempts := steps.propose():
                for a in attempts:
                    y_start = run.y[a.members]
                    if a.h is None:
                        y_new, saved, first_bad = solver.integrate(fields, y_start, a.times, a.dX, a.dXX, a.save,
                                                                   stop_on_failure=a.stop)
                        err = None
                    else:                               # the declared estimate: step doubling
                        (y_new, y_one), saved, first_bad = _step_doubling(solver, fields, y_start, a), None, None
                        err = control.error_ratio(y_start, y_new, y_new - y_one, a.h, steps.span)
                    steps.judge(a, y_new, saved, first_bad, err)
                steps.adapt(attempts)
    finally:
        if report is not None:
            report.close()
    times, states, stats = steps.finish()
    stats.update(solver=repr(solver), batch_shape=batch, wall_time=_time.perf_counter() - t_start)
    return Solution(times=times, states=states, failed_step=run.failed.reshape(batch), stats=stats)


class _Run:
    """What the loop keeps once for every proposer: the state, the failures, the saved states' memory check."""

    def __init__(self, y, batch, on_failure, flat):
        self.batch, self.e, self.on_failure, self.flat = batch, y.shape[-1], on_failure, flat
        self.members = int(np.prod(batch, dtype=np.int64))
        self.y = y.reshape(self.members, self.e) if flat else y
        self.failed = np.full(self.members, -1, dtype=np.int64)
        self.healthy = np.ones(self.members, dtype=bool)
        self.report, self._checked = None, 1

    def fail(self, members, steps, times=None, unmet=None):
        """Members (flat indices) failed at ``steps``: raise (``on_failure="raise"``) or mark them."""
        self.failed[members] = steps
        if self.on_failure == "raise":
            if unmet is not None:
                raise ValueError(_unmet_message(members, self.batch, *unmet))
            at = times if not callable(times) else (lambda m: times(int(np.ravel_multi_index(m, self.batch)) if m else 0))
            msg, mem, st = _failure_message(self.failed.reshape(self.batch), at, self.batch)
            raise NonFiniteStateError(msg, mem, st)
        self.healthy[members] = False

    def check_saves(self, n_times, growing=False):
        """Refuse saved states past the memory budget (a growing count is checked at every doubling)."""
        if growing and n_times < 2 * self._checked:
            return
        self._checked = n_times
        check_memory((16.0 if growing else 8.0) * self.members * n_times * self.e,
                     f"the saved states ({self.members} member(s) x {n_times} time(s){' so far' if growing else ''} "
                     f"x {self.e})", "save fewer times (save_at='end' or a coarser array of times) or solve the batch "
                     "in parts")

    def progress(self, done):
        if self.report is not None:
            self.report.update(done)