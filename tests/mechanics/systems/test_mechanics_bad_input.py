"""Bad input to the mechanics layer raises a clear error (never a silent wrong answer, NaN or hang).

Covers: non-symmetric / non-positive inertia, wrong ξ shapes, s not antisymmetric or of the wrong size,
θ < 0 (and non-finite, non-numeric), unknown convention, states off the orbit for a Casimir-preserving
run (``check_on_orbit``), a chord iteration that fails to converge (the message names the step), level-3
or non-geometric drivers, dimension mismatches, bad seed / dt / n_steps / save_at.
"""

import numpy as np
import pytest

from mechanics.systems.heavy_top import heavy_top
from mechanics.integrators import ChordConvergenceError, ImplicitMidpoint, LieHeun, check_on_orbit
from mechanics.systems.lie_algebra import so3
from mechanics.systems.lie_poisson import LiePoissonSystem
from mechanics.systems.rigid_body import rigid_body
from roughpaths import BrownianDriver, RoughPath, RoughPathN, solve

I3 = [1.0, 2.0, 3.0]


@pytest.mark.parametrize("inertia, match", [
    ([[1.0, 0.5, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]], "symmetric"),
    ([1.0, -2.0, 3.0], "positive definite"),
    ([1.0, 0.0, 3.0], "positive definite"),
    (np.eye(2), "3x3"),
    ([1.0, np.nan, 3.0], "non-finite"),
])
def test_bad_inertia(inertia, match):
    with pytest.raises(ValueError, match=match):
        rigid_body(inertia, sigma=0.1)


@pytest.mark.parametrize("xi", [np.ones(3), np.ones((3, 4)), np.ones((0, 3)), np.ones((2, 3, 3))])
def test_bad_xi_shape(xi):
    with pytest.raises(ValueError, match="xi must have shape"):
        rigid_body(I3, xi=xi)
    with pytest.raises(ValueError, match="xi must have shape"):
        LiePoissonSystem(so3(), np.diag(I3), xi)


def test_heavy_top_bad_xi_and_chi():
    with pytest.raises(ValueError, match=r"\(m, 3\).*\(m, 6\)"):
        heavy_top(I3, [0, 0, 1.0], xi=np.ones((2, 4)))
    with pytest.raises(ValueError, match="chi"):
        heavy_top(I3, [0, 1.0], sigma=0.1)


def test_bad_s():
    with pytest.raises(ValueError, match="antisymmetric"):
        rigid_body(I3, sigma=0.1, s=np.ones((3, 3)))
    with pytest.raises(ValueError, match="3x3"):
        rigid_body(I3, sigma=0.1, s=[[0.0, 1.0], [-1.0, 0.0]])


@pytest.mark.parametrize("theta, exc", [(-0.1, ValueError), (np.inf, ValueError), (float("nan"), ValueError),
                                        ("1", TypeError), (True, TypeError)])
def test_bad_theta(theta, exc):
    with pytest.raises(exc, match="theta"):
        rigid_body(I3, sigma=0.1, theta=theta)


def test_bad_convention_sigma_and_both_noise_args():
    with pytest.raises(ValueError, match="convention"):
        rigid_body(I3, sigma=0.1, convention="Paper")
    with pytest.raises(ValueError, match="not both"):
        rigid_body(I3, xi=np.eye(3), sigma=0.1)
    with pytest.raises(ValueError, match="sigma"):
        rigid_body(I3, sigma=-0.1)


@pytest.mark.parametrize("value", ["False", 0, None, np.array([True])])
def test_bad_levy_in_dissipation(value):
    with pytest.raises(TypeError, match="levy_in_dissipation"):
        rigid_body(I3, sigma=0.1, theta=1.0, levy_in_dissipation=value)


def test_bad_hamiltonian_and_algebra():
    with pytest.raises(TypeError, match="hamiltonian_gradient"):
        LiePoissonSystem(so3(), lambda mu: mu @ mu, np.eye(3))
    with pytest.raises(TypeError, match="LieAlgebra"):
        LiePoissonSystem("so3", np.diag(I3), np.eye(3))


def test_off_orbit_states_rejected(rng):
    rb = rigid_body(I3, sigma=0.1, theta=1.0)
    X = RoughPath.from_path(np.zeros((11, 3)))
    with pytest.raises(ValueError, match=r"off the coadjoint orbit: \|mu\|\^2 = 4.0"):
        check_on_orbit(rb, [0.0, 0.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="batch index \\(1,\\)"):
        check_on_orbit(rb, [[0.0, 0.0, 1.0], [0.0, 0.0, 1.1]], 1.0)
    top = heavy_top(I3, [0, 0, 1.0], sigma=0.1)
    with pytest.raises(ValueError, match="Pi.Gamma"):
        check_on_orbit(top, [1.0, 0, 0, 1.0, 0, 0], [1.0, 0.0])
    check_on_orbit(top, [0.0, 1.0, 0, 1.0, 0, 0], [1.0, 0.0])        # on the orbit: accepted
    assert solve(top, X, [0.0, 1.0, 0, 1.0, 0, 0], LieHeun()).states.shape == (11, 6)


def test_chord_non_convergence_names_the_step(rng):
    rb = rigid_body(I3, sigma=0.5, theta=50.0)
    with pytest.raises(ChordConvergenceError, match=r"did not converge at step 0 .*max_iter = 1"):
        solve(rb, BrownianDriver(3, seed=5, dt=0.05, n_steps=5), [0.0, 0.6, 0.8],
              ImplicitMidpoint(tol=1e-15, max_iter=1))
    X = RoughPath.from_path(np.cumsum(rng.standard_normal((3, 21, 3)) * 0.1, axis=1), times=np.linspace(0, 1, 21))
    with pytest.raises(ChordConvergenceError, match="step 0"):
        solve(rb, X, [0.0, 0.6, 0.8], ImplicitMidpoint(tol=1e-15, max_iter=1))
    # the numpy path (a generic system): at rest on the equilibrium e3 until the first kick at step 7
    generic = LiePoissonSystem(so3(), lambda m: 0.5 * np.sum(m * m / I3, -1), 0.5 * np.eye(3), theta=50.0,
                               hamiltonian_gradient=lambda m: m / np.asarray(I3))
    kick = np.zeros((11, 3))
    kick[8:] = [0.1, -0.2, 0.05]
    with pytest.raises(ChordConvergenceError, match=r"step 7 of the block from t = 0 \(step from t = 0.35"):
        solve(generic, RoughPath.from_path(kick, times=np.linspace(0.0, 0.5, 11)), [0.0, 0.0, 1.0],
              ImplicitMidpoint(tol=1e-15, max_iter=1))
    with pytest.raises(ValueError, match="tol"):
        ImplicitMidpoint(tol=-1.0)
    with pytest.raises(ValueError, match="max_iter"):
        ImplicitMidpoint(max_iter=0)


def test_bad_drivers_and_shapes(rng):
    rb = rigid_body(I3, sigma=0.1)
    vals = np.cumsum(rng.standard_normal((11, 3)), axis=0)
    X = RoughPath.from_path(vals)
    with pytest.raises(ValueError, match="level-3"):
        solve(rb, RoughPathN.from_rough_path(X, 3), [0, 0, 1.0], LieHeun())
    ito = RoughPath(X.increments, X.areas - 0.05 * np.eye(3), times=X.times, kind="ito")
    with pytest.raises(ValueError, match="geometric"):
        solve(rb, ito, [0, 0, 1.0], LieHeun())
    with pytest.raises(ValueError, match="dimension d=2"):
        solve(rb, RoughPath.from_path(vals[:, :2]), [0, 0, 1.0], LieHeun())
    with pytest.raises(ValueError, match=r"y0 must have shape \(\.\.\., 3\)"):
        solve(rb, X, [0, 1.0], LieHeun())
    with pytest.raises(TypeError, match="RoughPath"):
        solve(rb, vals, [0, 0, 1.0], LieHeun())
    with pytest.raises(TypeError, match="coadjoint solver"):
        solve(rb, X, [0, 0, 1.0], "heun")
    with pytest.raises(ValueError, match="save_at"):
        solve(rb, X, [0, 0, 1.0], LieHeun(), save_at=X.times[:2] + 0.05)
    with pytest.raises(TypeError, match="Generator"):
        BrownianDriver(3, seed=rng, dt=0.01, n_steps=10)
    with pytest.raises(ValueError, match="dt"):
        BrownianDriver(3, seed=0, dt=-0.01, n_steps=10)
    with pytest.raises(ValueError, match="n_steps"):
        BrownianDriver(3, seed=0, dt=0.01, n_steps=0)
    with pytest.raises(ValueError, match="levy_area"):
        BrownianDriver(3, seed=0, dt=0.01, n_steps=10, levy_area="exact")
    with pytest.raises(ValueError, match="non-finite"):
        solve(rb, BrownianDriver(3, seed=0, dt=0.01, n_steps=10), [0, np.nan, 1.0], LieHeun())
    with pytest.raises(ValueError, match="broadcast"):
        solve(rb, RoughPath.from_path(np.stack([vals, vals, vals])), np.ones((4, 3)), LieHeun())


def test_solver_contract_of_the_coadjoint_schemes():
    """The coadjoint schemes are roughpaths.Solver instances with declared levels and orders; classes
    are refused everywhere; wrong fields or drivers are refused with the fix in the message."""
    from roughpaths import BrownianDriver, Davie, LinearVectorFields, Solver, solve

    from mechanics.ensemble import run_ensemble
    from mechanics.integrators import LieEuler

    for cls in (LieEuler, LieHeun, ImplicitMidpoint):
        s = cls()
        assert isinstance(s, Solver) and s.preserves == ("casimirs",) and s.calculus == "stratonovich"
        assert (s.increment_level, s.order) == (2, 1.0)
    assert (LieEuler.smooth_order, LieHeun.smooth_order, ImplicitMidpoint.smooth_order) == (1.0, 2.0, 2.0)
    rb = rigid_body(I3, sigma=0.1)
    X = BrownianDriver(3, seed=0, dt=0.01, n_steps=5)
    with pytest.raises(TypeError, match=r"did you mean LieHeun\(\)"):
        solve(rb, X, [0, 0, 1.0], LieHeun)
    with pytest.raises(TypeError, match=r"did you mean LieHeun\(\)"):
        run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=5, n_paths=2, seed=0, method=LieHeun)
    with pytest.raises(TypeError, match="LiePoissonSystem"):
        solve(LinearVectorFields(np.zeros((3, 3, 3))), X, np.ones(3), LieHeun())
    with pytest.raises(TypeError, match="coadjoint solver"):
        solve(rb, X, [0, 0, 1.0], Davie())
    with pytest.raises(TypeError, match="takes no arguments"):   # the level is the driver's, never a flag
        LieHeun(levy_area=False)
    with pytest.raises(ValueError, match="levy_area"):
        run_ensemble(rb, [0, 0, 1.0], dt=0.01, n_steps=5, n_paths=2, seed=0, levy_area="davy")
