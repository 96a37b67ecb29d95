"""The arguments of :func:`~roughpaths.solve`, checked before its loop runs; every refusal names the fix.

The solver (an instance, or a name of :data:`SOLVERS`), the step controller against the driver and the solver
(:mod:`roughpaths.rde.step_control`, contract items 1 and 5), ``save_at``, ``shared_steps``, ``on_failure`` and the
driver's type and dimension. The answers a controller gives during the loop are checked where the loop reads them
(:mod:`roughpaths.rde.adaptive`).
"""

from __future__ import annotations

import numbers

import numpy as np

from ..drivers.base import Driver
from ..paths.rough_path import RoughPath
from ..paths.rough_path_n import RoughPathN
from ..validation import as_float_array
from .base import Solver
from .davie import Davie
from .euler import Euler, Heun
from .logode import LogODE
from .step_control import FixedSteps

__all__ = ["SOLVERS"]


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


def _check_control(control, driver, solver, shared_steps):
    """The step controller of a solve (``None``: the driver's own grid), checked against driver and solver, and
    ``shared_steps``."""
    if shared_steps is not None and not isinstance(shared_steps, (bool, np.bool_)):   # bool("no") is True
        raise TypeError(f"shared_steps must be True, False or None (the solver's choice), got {shared_steps!r}; "
                        f"pass shared_steps=True for one step size for the whole batch, False for steps per member.")
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



def _check_options(driver, fields, on_failure) -> None:
    """Refuse an unknown ``on_failure``, a driver of another type or of another dimension than the fields' noise."""
    if not isinstance(driver, (RoughPath, RoughPathN, Driver)):
        raise TypeError(f"driver must be a RoughPath, a RoughPathN, a Driver (e.g. roughpaths.BrownianDriver) or a "
                        f"BrownianTree, got {type(driver).__name__}; build a path with "
                        f"RoughPath.from_path(values, times=...) or RoughPath(increments, areas, times=...).")
    if on_failure not in ("raise", "mask"):
        raise ValueError(f"on_failure must be 'raise' or 'mask', got {on_failure!r}.")
    if driver.dim != fields.dim_noise:
        raise ValueError(f"the driver has dimension d={driver.dim} but the vector fields have "
                         f"dim_noise={fields.dim_noise}; one field per driving component is needed.")
