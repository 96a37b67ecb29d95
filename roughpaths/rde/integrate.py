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

import numbers
import time as _time

import numpy as np

from ..validation import as_float_array, check_memory, check_positive_int, check_same_batch
from ..drivers.base import Driver
from ..progress import progress_reporter
from ..paths.rough_path import RoughPath
from ..paths.rough_path_n import RoughPathN
from ._grid import _GridSteps
from .adaptive import _TreeSteps, _step_doubling
from .base import Solver
from .solution import NonFiniteStateError, Solution, _failure_message
from ._split import _solve_split
from .step_control import FixedSteps
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
    control = _check_control(step_control, driver, solver)
    if shared_steps is not None and not isinstance(shared_steps, (bool, np.bool_)):   # bool("no") is True
        raise TypeError(f"shared_steps must be True, False or None (the solver's choice), got {shared_steps!r}; "
                        f"pass shared_steps=True for one step size for the whole batch, False for steps per member.")
    if executor is not None:
        if control is not None:
            raise ValueError("executor= splits a batch solved on a fixed grid; with a step controller solve serially "
                             "(the members' steps are their own: a member's result is the same in any batch).")
        return _solve_split(solve, fields, driver, y0, solver, executor, chunks, progress, drift=drift, save_at=save_at,
                            on_failure=on_failure, block_steps=block_steps)
    if not isinstance(driver, (RoughPath, RoughPathN, Driver)):
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


def _check_control(control, driver, solver):
    """The step controller of a solve (``None``: the driver's own grid), checked against driver and solver."""
    any_times = getattr(driver, "any_times", False)
    if control is None:
        if any_times:
            raise ValueError(f"a {type(driver).__name__} driver needs a step controller: pass "
                             f"step_control=PIController(rtol, atol) (or FixedSteps(dt)), or solve on a grid with "
                             f"driver=tree.rough_path(times).")
        return None
    if not all(hasattr(control, k) for k in ("adaptive", "init", "adapt", "dt_min", "dt_max", "max_steps")):
        raise TypeError(f"step_control must follow the StepController contract (roughpaths.PIController, FixedSteps "
                        f"or a StepController subclass), got {type(control).__name__}; e.g. "
                        f"step_control=PIController(rtol=1e-3, atol=1e-6).")
    if not any_times:
        if isinstance(control, FixedSteps) and control.dt is None:
            return None
        raise ValueError(f"step_control needs a driver that answers on any interval, a roughpaths.BrownianTree; "
                         f"got a {type(driver).__name__}, whose grid is fixed. Build BrownianTree(dim, seed=...) "
                         f"or drop step_control.")
    name = type(control).__name__
    if isinstance(control.max_steps, (bool, np.bool_)) or not isinstance(control.max_steps, numbers.Integral) \
            or control.max_steps < 1:
        raise ValueError(f"{name}.max_steps must be an integer >= 1 (the most attempts of a lane, contract item 5), "
                         f"got {control.max_steps!r}; e.g. max_steps = 100_000 (StepController's default).")
    q = solver.error_order if solver.error_order is not None else solver.order
    if control.adaptive and (solver.error_estimate != "step_doubling" or not q > 0):
        raise ValueError(f"adaptive steps need the solver's declared error estimate (Solver.error_estimate, step "
                         f"doubling for an order-1 scheme that uses the area), got {solver!r} (error_estimate="
                         f"{solver.error_estimate!r}, order {solver.order}); use Davie(), LogODE() or a coadjoint "
                         f"LieHeun(), or FixedSteps(dt) for this solver.")
    return control


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


def _unmet_message(members, batch, r, t, h, control, dt_min=None, resolution=None):
    """The message of a step at ``dt_min`` whose error exceeds the tolerance (``on_failure="raise"``); a step held
    above ``dt_min`` by the driver's grid (two cells of a coarse tree) names the tree's ``resolution`` instead."""
    first = tuple(int(v) for v in np.unravel_index(int(members[0]), batch))
    by_grid = dt_min is not None and resolution is not None and h > dt_min * (1 + 1e-9)
    at = (f"the shortest step of the tree's grid (2 cells of (t1 - t0)·2^-{resolution}; dt_min = {dt_min:.3g})"
          if by_grid else f"dt_min = {h:.3g}")
    lower = (f"build the BrownianTree with a higher resolution (now {resolution}, at most 62)" if by_grid else
             "lower dt_min (PIController(dt_min=...))")
    return (f"the error tolerance cannot be met: the step [{t:.6g}, {t + h:.6g}] at {at} still has "
            f"{r:.3g} times the error {control!r} allows, for {len(members)} batch member(s) (first {first}); "
            f"loosen rtol/atol, {lower}, or pass on_failure='mask' to mark these "
            f"members failed (Solution.failed) and finish the others.")


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
