r"""The entry point :func:`solve` for rough differential equations, and its result :class:`Solution`.

Solves :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i` on the grid of a :class:`~roughpaths.RoughPath`
with a one-step solver from :mod:`roughpaths.solvers`. The time loop runs over steps in Python; every
step is vectorised over the batch (the driver's batch axes broadcast against those of ``y0``), so no
Python loop runs per path.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field

import numpy as np

from ._validation import as_float_array, check_same_batch
from .rough_path import RoughPath
from .solvers import SOLVERS, Davie, Solver
from .vector_fields import VectorFields

__all__ = ["solve", "Solution"]


@dataclass(frozen=True)
class Solution:
    """Result of :func:`solve`.

    Attributes
    ----------
    times : ndarray, shape ``(K,)``
        The saved times (all grid times by default).
    states : ndarray, shape ``(..., K, e)``
        The solution at ``times``; leading axes are the broadcast batch of driver and ``y0``.
    stats : dict
        ``solver``, ``n_steps``, ``batch_shape``, ``wall_time`` (seconds).
    """

    times: np.ndarray
    states: np.ndarray
    stats: dict = field(default_factory=dict)

    @property
    def final(self) -> np.ndarray:
        """The state at the last saved time, shape ``(..., e)``."""
        return self.states[..., -1, :]

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
    if not (hasattr(solver, "step") and hasattr(solver, "increment_level")):
        raise TypeError(f"solver must be a Solver instance (Euler(), Heun(), Davie(), LogODE()) or one "
                        f"of the names {sorted(SOLVERS)}, got {type(solver).__name__}.")
    return solver


def solve(fields, driver, y0, solver=None, *, drift=None, save_at="all") -> Solution:
    r"""Solve the RDE :math:`dY = V_0(Y)\,dt + V_i(Y)\,d\mathbf{X}^i`, :math:`Y_{t_0} = y_0`, on the driver's grid.

    Parameters
    ----------
    fields : VectorFields
        The family :math:`(V_0; V_1..V_d)` (:class:`~roughpaths.vector_fields.LinearVectorFields` or
        :class:`~roughpaths.vector_fields.VectorFields`).
    driver : RoughPath
        Batch shape ``B_X``, dimension ``d``, ``N`` steps. Level 2 for level-2 solvers. Convention:
        area :math:`\mathbb{X}^{ij} = \int (X^i - X^i_s)\,dX^j`.
    y0 : array_like, shape ``(..., e)``
        Initial condition(s); the batch ``B_y`` broadcasts against ``B_X``.
    solver : Solver instance or str, optional
        ``Davie()`` (default), ``LogODE()``, ``Heun()``, ``Euler()``, or one of the names
        ``"davie", "logode", "heun", "euler"``.
    drift : callable, matrix ``(e, e)`` or LinearDrift, optional
        Extra drift added to :math:`V_0`, e.g. ``fields.friz_oberhauser_drift(s)``.
    save_at : "all", "end" or array_like of grid times
        Which states to keep (default all ``N + 1``).

    Returns
    -------
    Solution
        ``times (K,)``, ``states (broadcast(B_X, B_y), K, e)``, ``stats``.

    Raises
    ------
    ValueError
        Mismatched dimensions; a level-2 solver with a level-1 driver; a non-finite state during the
        solve (the message gives the step index and time); unknown solver name.
    TypeError
        A solver class instead of an instance ("did you mean Davie()?"), wrong argument types.

    Examples
    --------
    Friz–Oberhauser: a perturbed area equals an extra drift (exactly, step by step, for ``LogODE`` on
    linear fields):

    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> from roughpaths.solve import solve
    >>> from roughpaths.solvers import LogODE
    >>> from roughpaths.vector_fields import LinearVectorFields
    >>> rng = np.random.default_rng(0)
    >>> V = LinearVectorFields(0.5 * rng.standard_normal((2, 3, 3)))
    >>> X = RoughPath.from_path(np.cumsum(0.1 * rng.standard_normal((8, 65, 2)), axis=-2))
    >>> s = np.array([[0.0, 0.7], [-0.7, 0.0]])
    >>> a = solve(V, X.perturb(s), np.ones(3), LogODE()).final
    >>> b = solve(V, X, np.ones(3), LogODE(), drift=V.friz_oberhauser_drift(s)).final
    >>> a.shape, bool(np.allclose(a, b, atol=1e-12))
    ((8, 3), True)
    """
    if not isinstance(fields, VectorFields):
        raise TypeError(f"fields must be a VectorFields object (LinearVectorFields(M) or "
                        f"VectorFields(callables, ...)), got {type(fields).__name__}.")
    if not isinstance(driver, RoughPath):
        raise TypeError(f"driver must be a RoughPath, got {type(driver).__name__}; build one with "
                        f"RoughPath.from_path(values, times=...) or RoughPath(increments, areas, times=...).")
    solver = _resolve_solver(solver)
    if driver.dim != fields.dim_noise:
        raise ValueError(f"the driver has dimension d={driver.dim} but the vector fields have "
                         f"dim_noise={fields.dim_noise}; one field per driving component is needed.")
    if solver.increment_level == 2 and driver.level < 2:
        raise ValueError(f"{solver!r} is a level-2 solver and needs the driver's area, but the driver is "
                         f"level 1 (no area); pass a level-2 RoughPath (e.g. a Brownian rough path with "
                         f"its Lévy area), or choose a level-1 solver (Heun(), Euler()) if dropping the "
                         f"area is intended.")
    e = fields.dim_state
    y = as_float_array(y0, "y0", min_ndim=1)
    if y.shape[-1] != e:
        raise ValueError(f"y0 has last dimension {y.shape[-1]} but the vector fields act on R^{e} "
                         f"(dim_state={e}); y0 must have shape (..., {e}).")
    batch = check_same_batch(y.shape[:-1], driver.batch_shape, "y0", "driver")
    y = np.array(np.broadcast_to(y, batch + (e,)))
    if drift is not None:
        fields = fields.with_drift(drift)

    times = driver.times
    n = driver.n_steps
    if isinstance(save_at, str):
        if save_at == "all":
            idx = np.arange(n + 1)
        elif save_at == "end":
            idx = np.array([n])
        else:
            raise ValueError(f"save_at must be 'all', 'end' or an array of grid times, got {save_at!r}.")
    else:
        idx = np.unique(driver.index_of(save_at, "save_at").ravel())
    save_mask = np.zeros(n + 1, dtype=bool)
    save_mask[idx] = True
    out = np.empty(batch + (idx.size, e))
    slot = 0
    if save_mask[0]:
        out[..., 0, :] = y
        slot = 1

    inc, areas = driver.increments, driver.areas
    use_area = solver.increment_level == 2
    dts = np.diff(times)
    t_start = _time.perf_counter()
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k in range(n):
            dXX = areas[..., k, :, :] if use_area else None
            y = solver.step(fields, y, times[k], dts[k], inc[..., k, :], dXX)
            if not np.all(np.isfinite(y)):
                bad = np.argwhere(~np.all(np.isfinite(y), axis=-1))
                where = f" (first bad batch index {tuple(int(i) for i in bad[0])})" if bad.size else ""
                raise ValueError(f"the solution became non-finite at step {k} (t = {float(times[k + 1]):.6g}, "
                                 f"step from t = {float(times[k]):.6g}){where}; the vector fields may blow up "
                                 f"there, or the step is too large: refine the driver's grid.")
            if save_mask[k + 1]:
                out[..., slot, :] = y
                slot += 1
    stats = {"solver": repr(solver), "n_steps": n, "batch_shape": batch,
             "wall_time": _time.perf_counter() - t_start}
    return Solution(times=times[idx].copy(), states=out, stats=stats)
