r"""Deprecated entry points, kept as thin wrappers over :func:`roughpaths.solve`.

=====================================  =========================================================
deprecated                             use instead
=====================================  =========================================================
``simulate(system, mu0, X, method)``   ``roughpaths.solve(system, X, mu0, LieHeun())``
``simulate(..., levy_area=False)``     ``roughpaths.solve(system, X1, mu0, LieHeun(levy_area=False))``
``simulate_brownian(...)``             ``roughpaths.solve(system, BrownianDriver(...), mu0, LieHeun())``
``coadjoint_step(...)``                ``solver.step(system, mu, t, dt, dX, dXX)``
=====================================  =========================================================
"""

from __future__ import annotations

import copy
import warnings

import numpy as np

from roughpaths import BrownianDriver, NonFiniteStateError, RoughPath, solve
from roughpaths.validation import as_float_array, check_memory, check_positive_int, check_rng, check_work

from ..lie_poisson import LiePoissonSystem
from .base import ChordConvergenceError, CoadjointSolver, LieHeun, check_on_orbit

__all__ = ["simulate", "simulate_brownian", "coadjoint_step"]


def _warn(old, new):
    warnings.warn(f"mechanics.{old} is deprecated; use {new} (returns a roughpaths.Solution).",
                  DeprecationWarning, stacklevel=3)


def _solver(method, levy_area):
    if isinstance(method, type):
        raise TypeError(f"method must be a solver instance, got the class {method.__name__}; did you mean "
                        f"{method.__name__}()?")
    if not isinstance(method, CoadjointSolver):
        raise TypeError(f"method must be LieEuler(), LieHeun() or ImplicitMidpoint(...), got {method!r}.")
    if method.levy_area != bool(levy_area):
        method = copy.copy(method)
        method.levy_area = bool(levy_area)
    return method


def _prepare(system, mu0, orbit):
    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a LiePoissonSystem (e.g. mechanics.rigid_body.rigid_body(...)), "
                        f"got {type(system).__name__}.")
    mu0 = as_float_array(mu0, "mu0", last_dims=(system.dim,))
    if orbit is not None:
        check_on_orbit(system, mu0, orbit)
    return mu0


def _run(system, driver, mu0, solver, save_at):
    try:
        sol = solve(system, driver, mu0, solver, save_at=save_at)
    except NonFiniteStateError as exc:
        raise FloatingPointError(f"{exc} (the Hamiltonian or its gradient may have returned NaN/inf)") from exc
    return sol.times, sol.states


def simulate(system: LiePoissonSystem, mu0, driver: RoughPath, method=LieHeun(), save_every: int = 1, *,
             orbit=None, levy_area: bool = True):
    r"""Deprecated: ``roughpaths.solve(system, driver, mu0, method)``; returns ``(times, states)``.

    ``levy_area=False`` is ``type(method)(levy_area=False)`` (a level-1 driver is required);
    ``save_every`` keeps ``driver.times[::save_every]``; ``orbit`` checks the initial Casimirs
    (:func:`~mechanics.integrators.check_on_orbit`).

    Examples
    --------
    >>> import warnings
    >>> import numpy as np
    >>> from roughpaths import RoughPath, solve
    >>> from mechanics import rigid_body, LieHeun
    >>> rb = rigid_body([1.0, 2.0, 3.0], sigma=0.1, theta=1.0)
    >>> X = RoughPath.from_path(np.cumsum(np.random.default_rng(0).normal(0, 0.03, (101, 3)), axis=0),
    ...                         times=np.linspace(0, 1, 101))
    >>> sol = solve(rb, X, [0.0, 0.6, 0.8], LieHeun())
    >>> sol.states.shape, bool(abs(np.linalg.norm(sol.final) - 1.0) < 1e-14)
    ((101, 3), True)
    """
    _warn("simulate", "roughpaths.solve(system, X, mu0, LieHeun())")
    if not isinstance(levy_area, (bool, np.bool_)):
        raise TypeError(f"levy_area must be True (use the driver's Lévy areas) or False (level-1 driving, "
                        f"zero area), got {levy_area!r}.")
    solver = _solver(method, levy_area)
    if not isinstance(driver, RoughPath):
        raise TypeError(f"driver must be a roughpaths.RoughPath, got {type(driver).__name__}.")
    save_every = check_positive_int(save_every, "save_every")
    mu0 = _prepare(system, mu0, orbit)
    return _run(system, driver, mu0, solver, driver.times[::save_every])


def simulate_brownian(system: LiePoissonSystem, mu0, dt: float, n_steps: int, rng, *, n_paths=None,
                      method=LieHeun(), levy_area=True, area_substeps: int = 1, save_every: int = 1,
                      chunk_steps=None, orbit=None):
    r"""Deprecated: ``roughpaths.solve(system, BrownianDriver(...), mu0, method)``; returns ``(times (K,), states (P, K, n))``.

    The driver is ``roughpaths.BrownianDriver(m, seed=int(rng.integers(2**63)), dt=dt, n_steps=n_steps,
    batch_shape=(n_paths,), levy_area=..., substeps=area_substeps)`` (``levy_area`` ``True`` means
    ``"davie"``, ``False`` level-1 driving); its stream depends only on that seed, the path index and
    the area method, never on ``chunk_steps`` (the block size handed to :func:`roughpaths.solve`).
    """
    _warn("simulate_brownian", "roughpaths.solve(system, roughpaths.BrownianDriver(...), mu0, LieHeun())")
    rng = check_rng(rng)
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating)) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive finite number, got {dt!r}.")
    dt = float(dt)
    n_steps = check_positive_int(n_steps, "n_steps")
    save_every = check_positive_int(save_every, "save_every")
    if not (isinstance(levy_area, (bool, np.bool_)) or levy_area in ("davie", "foster")):
        raise ValueError(f"levy_area must be True, False, 'davie' or 'foster', got {levy_area!r}.")
    area_substeps = check_positive_int(area_substeps, "area_substeps")
    solver = _solver(method, levy_area is not False)
    mu0 = _prepare(system, mu0, None)
    if mu0.ndim > 2:
        raise ValueError(f"mu0 must have shape (n,) or (n_paths, n), got {mu0.shape}.")
    if n_paths is None:
        n_paths = mu0.shape[0] if mu0.ndim == 2 else 1
    n_paths = check_positive_int(n_paths, "n_paths")
    n_saved = n_steps // save_every + 1
    check_memory(8.0 * n_paths * (n_saved + 2) * system.dim, f"the saved states (n_paths={n_paths} x (n_steps/save_every + 1) "
                 f"= {n_saved} times x {system.dim})", "save fewer times (a larger save_every) or use fewer paths")
    check_work(float(n_paths) * n_steps * area_substeps, f"simulate_brownian with n_paths={n_paths}, "
               f"n_steps={n_steps} and area_substeps={area_substeps}", "use fewer paths, steps or sub-steps")
    mu0 = np.array(np.broadcast_to(mu0, (n_paths, system.dim)))
    if orbit is not None:
        check_on_orbit(system, mu0, orbit)
    if chunk_steps is not None:
        chunk_steps = check_positive_int(chunk_steps, "chunk_steps")
    method_name = None if levy_area is False else ("davie" if levy_area is True else levy_area)
    driver = BrownianDriver(system.n_noise, seed=int(rng.integers(2 ** 63)), dt=dt, n_steps=n_steps,
                            batch_shape=(n_paths,), levy_area=method_name, substeps=area_substeps)
    try:
        sol = solve(system, driver, mu0, solver, save_at=driver.times[::save_every], block_steps=chunk_steps)
    except NonFiniteStateError as exc:
        raise FloatingPointError(f"{exc} (the Hamiltonian or its gradient may have returned NaN/inf)") from exc
    return sol.times, sol.states


def coadjoint_step(system: LiePoissonSystem, mu, dt: float, eta, method=LieHeun(), *, step_index: int = 0,
                   t: float = 0.0) -> np.ndarray:
    r"""Deprecated: one coadjoint step :math:`\mu\mapsto\exp(\mathrm{ad}^*_{\sigma})\mu` from a stochastic
    velocity ``eta`` (``(..., n)``); use ``solver.step(system, mu, t, dt, dX, dXX)``."""
    _warn("coadjoint_step", "solver.step(system, mu, t, dt, dX, dXX)")
    solver = _solver(method, method.levy_area if isinstance(method, CoadjointSolver) else True)
    mu = _prepare(system, mu, None)
    dt = float(as_float_array(dt, "dt", ndim=0))
    eta = as_float_array(eta, "eta", last_dims=(system.dim,))
    new, ok, conv = solver._advance(system, mu, dt, eta)
    if conv is not None and not np.all(conv):
        raise ChordConvergenceError(
            f"implicit midpoint: the chord iteration did not converge at step {step_index} (t = {t:.6g}, "
            f"dt = {dt:.3g}) for batch member(s) {[tuple(int(i) for i in m) for m in np.argwhere(~conv)][:8]} "
            f"after max_iter = {solver.max_iter} iterations. Reduce dt (or use LieHeun), or raise max_iter / tol.")
    return new
