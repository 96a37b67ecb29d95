r"""The entry point :func:`solve` for rough differential equations, and its result :class:`Solution`.

Solves :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i` on the grid of a :class:`~roughpaths.RoughPath`
(or of a :class:`~roughpaths.driver.Driver`, consumed block by block) with a one-step solver that
follows the contract of :class:`roughpaths.solvers.Solver`. The time loop runs over steps in Python
(or inside a solver's compiled block kernel); every step is vectorised over the batch (the driver's
batch axes broadcast against those of ``y0``), so no Python loop runs per path. Batch members never
affect each other: a member that becomes non-finite is reported by its index and step, and with
``on_failure="mask"`` the healthy members' results are returned unchanged.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field

import numpy as np

from .validation import as_float_array, check_same_batch
from .driver import Driver
from .rough_path import RoughPath
from .solvers import SOLVERS, Davie, Solver

__all__ = ["solve", "Solution", "NonFiniteStateError"]


class NonFiniteStateError(ValueError):
    """Batch members of a :func:`solve` became non-finite.

    Attributes
    ----------
    members : tuple of tuple of int
        The batch indices of the failed members (all of them, in C order).
    steps : tuple of int
        For each failed member, the index ``k`` of the step ``[t_k, t_{k+1}]`` after which it was
        first non-finite.
    """

    def __init__(self, message, members=(), steps=()):
        super().__init__(message)
        self.members = tuple(members)
        self.steps = tuple(steps)


@dataclass(frozen=True)
class Solution:
    """Result of :func:`solve`.

    Attributes
    ----------
    times : ndarray, shape ``(K,)``
        The saved times (all grid times by default).
    states : ndarray, shape ``(..., K, e)``
        The solution at ``times``; leading axes are the broadcast batch of driver and ``y0``.
    failed_step : ndarray of int, shape ``(...)``
        Per batch member, the index of the step after which it first became non-finite, ``-1`` for
        a healthy member (all ``-1`` unless ``on_failure="mask"`` kept a batch with failures). The
        states of a failed member are NaN from that step on.
    stats : dict
        ``solver``, ``n_steps``, ``n_blocks``, ``batch_shape``, ``wall_time`` (seconds).
    """

    times: np.ndarray
    states: np.ndarray
    failed_step: np.ndarray = None
    stats: dict = field(default_factory=dict)

    @property
    def final(self) -> np.ndarray:
        """The state at the last saved time, shape ``(..., e)``."""
        return self.states[..., -1, :]

    @property
    def failed(self) -> np.ndarray:
        """Boolean mask ``(...)`` of the batch members that became non-finite."""
        return self.failed_step >= 0

    def __repr__(self) -> str:
        return (f"Solution(times: {self.times.shape}, states: {self.states.shape}, "
                f"solver={self.stats.get('solver')!r})")


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


def _failure_message(failed_step, times, batch) -> tuple:
    members = [tuple(int(i) for i in idx) for idx in np.argwhere(failed_step >= 0)]
    steps = [int(failed_step[m]) for m in members]
    first = int(np.argmin(steps))
    k, m = steps[first], members[first]
    msg = (f"the solution became non-finite at step {k} (t = {float(times[k + 1]):.6g}, step from "
           f"t = {float(times[k]):.6g}) for batch member {m}")
    if len(members) > 1:
        shown = ", ".join(f"{mm} at step {kk}" for mm, kk in zip(members[:8], steps[:8]))
        more = f" and {len(members) - 8} more" if len(members) > 8 else ""
        msg += (f"; {len(members)} of {int(np.prod(batch, dtype=np.int64))} members failed: "
                f"{shown}{more}")
    msg += ("; the vector fields may blow up there, or the step is too large: refine the driver's "
            "grid. Pass on_failure='mask' to keep the healthy members' results (Solution.failed marks "
            "the others).")
    return msg, members, steps


def solve(fields, driver, y0, solver=None, *, drift=None, save_at="all", on_failure="raise",
          block_steps=None) -> Solution:
    r"""Solve the RDE :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i`, :math:`Y_{t_0} = y_0`, on the driver's grid.

    Parameters
    ----------
    fields : VectorFields or another object the solver accepts
        The family :math:`(V_0; V_1..V_d)` (:class:`~roughpaths.vector_fields.LinearVectorFields` or
        :class:`~roughpaths.vector_fields.VectorFields`); coadjoint solvers of :mod:`mechanics`
        accept a ``LiePoissonSystem``. Driving field ``i`` of the API (``0``-based) is
        :math:`V_{i+1}` of the maths; the maths' :math:`V_0` is the drift. The object must have
        ``dim_state`` (``e``) and ``dim_noise`` (``d``).
    driver : RoughPath or Driver
        Batch shape ``B_X``, dimension ``d``, ``N`` steps; a :class:`~roughpaths.driver.Driver` is
        consumed block by block (memory for one block). Level 2 for level-2 solvers. Convention:
        area :math:`\mathbb{X}^{ij} = \int (X^i - X^i_s)\,dX^j`.
    y0 : array_like, shape ``(..., e)``
        Initial condition(s); the batch ``B_y`` broadcasts against ``B_X``.
    solver : Solver instance or str, optional
        ``Davie()`` (default), ``LogODE()``, ``Heun()``, ``Euler()``, or one of the names
        ``"davie", "logode", "heun", "euler"``; any object following the :class:`~roughpaths.solvers.Solver`
        contract.
    drift : callable, matrix ``(e, e)`` or LinearDrift, optional
        Extra drift added to :math:`V_0`, e.g. ``fields.friz_oberhauser_drift(s)`` (vector fields only).
    save_at : "all", "end" or array_like of grid times
        Which states to keep (default all ``N + 1``).
    on_failure : "raise" or "mask"
        What to do when batch members become non-finite: raise :class:`NonFiniteStateError` naming every
        failed member and its step (default), or finish the healthy members and return them, with
        ``Solution.failed_step`` marking the failed ones (their states are NaN from the failure on).
        Either way a healthy member's result is the one it has when solved alone.
    block_steps : int, optional
        Steps per block requested from a :class:`~roughpaths.driver.Driver` (its default if ``None``);
        it changes memory use, never the numbers.

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
    if not isinstance(driver, (RoughPath, Driver)):
        raise TypeError(f"driver must be a RoughPath or a Driver (e.g. roughpaths.BrownianDriver), got "
                        f"{type(driver).__name__}; build a path with RoughPath.from_path(values, times=...) "
                        f"or RoughPath(increments, areas, times=...).")
    if on_failure not in ("raise", "mask"):
        raise ValueError(f"on_failure must be 'raise' or 'mask', got {on_failure!r}.")
    if driver.dim != fields.dim_noise:
        raise ValueError(f"the driver has dimension d={driver.dim} but the vector fields have "
                         f"dim_noise={fields.dim_noise}; one field per driving component is needed.")
    solver.check_driver(driver)
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
    out = np.empty(batch + (idx.size, e))
    slot = 0
    if save_mask[0]:
        out[..., 0, :] = y
        slot = 1

    use_area = solver.increment_level >= 2
    failed_step = np.full(batch, -1, dtype=np.int64)
    blocks = (driver,) if isinstance(driver, RoughPath) else driver.blocks(block_steps)
    k0 = 0
    n_blocks = 0
    t_start = _time.perf_counter()
    for block in blocks:
        kb = block.n_steps
        save = save_mask[k0 + 1:k0 + kb + 1]
        y, saved, first_bad = solver.integrate(fields, y, block.times, block.increments,
                                               block.areas if use_area else None, save,
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
    if k0 != n:
        raise RuntimeError(f"the driver's blocks covered {k0} of its {n} steps; its blocks() is broken.")
    if on_failure == "mask" and (failed_step >= 0).any():
        mark = (failed_step[..., None] >= 0) & (idx > failed_step[..., None])      # batch + (K,)
        out[mark] = np.nan
    stats = {"solver": repr(solver), "n_steps": n, "n_blocks": n_blocks, "batch_shape": batch,
             "wall_time": _time.perf_counter() - t_start}
    return Solution(times=times[idx].copy(), states=out, failed_step=failed_step, stats=stats)


def _index_of(driver, save_at):
    if isinstance(driver, RoughPath):
        return driver.index_of(save_at, "save_at")
    return RoughPath(np.zeros((driver.n_steps, driver.dim)), times=driver.times, check=False).index_of(
        save_at, "save_at")
