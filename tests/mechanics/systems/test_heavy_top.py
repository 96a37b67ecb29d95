"""The stochastic heavy top on se(3)*.

Claims: the vector field is dΠ = Π×W + Γ×χ, dΓ = Γ×W (W = I⁻¹Π + c), i.e. the Lie–Poisson flow of
h = ½Π·I⁻¹Π + χ·Γ (docs/conventions.md: Γ × χ, not the paper's + χ × γ); the Casimirs |Γ|² and Π·Γ are
conserved to round-off by the coadjoint schemes, with noise and Lévy torque; without noise the
energy h is conserved to (at least) second order in dt by Lie–Heun (fitted slope ≈ 3), exactly (to
round-off) by the chord-solved implicit midpoint, to first order only by Lie–Euler, and the paper's printed gravity sign does not conserve h at all.
"""

import numpy as np
import pytest

from mechanics.systems.heavy_top import heavy_top
from mechanics.integrators import ImplicitMidpoint, LieEuler, LieHeun
from roughpaths import BrownianDriver, RoughPath, solve

I3 = np.array([1.0, 2.0, 3.0])
CHI = np.array([0.2, -0.1, 1.0])
S = np.array([[0.0, 2.0, -1.0], [-2.0, 0.0, 3.0], [1.0, -3.0, 0.0]])
MU0 = np.array([0.4, -0.3, 1.1, 0.3, 0.5, 0.81])


def test_vector_field_independent_formula(rng):
    top = heavy_top(I3, CHI, sigma=0.3, s=S)
    c = 0.5 * sum(S[i, j] * np.cross(0.3 * np.eye(3)[i], 0.3 * np.eye(3)[j]) for i in range(3) for j in range(3))
    for mu in rng.standard_normal((5, 6)):
        pi, gam = mu[:3], mu[3:]
        w = pi / I3 + c
        np.testing.assert_allclose(top.drift(mu), np.r_[np.cross(pi, w) + np.cross(gam, CHI), np.cross(gam, w)],
                                   atol=1e-14)
        noise = top.noise(mu)
        for i in range(3):
            xi = 0.3 * np.eye(3)[i]
            np.testing.assert_allclose(noise[:, i], np.r_[np.cross(pi, xi), np.cross(gam, xi)], atol=1e-15)
    paper = heavy_top(I3, CHI, sigma=0.3, s=S, convention="paper")
    mu = MU0
    w = mu[:3] / I3 - c
    np.testing.assert_allclose(paper.drift(mu), np.r_[np.cross(mu[:3], w) + np.cross(CHI, mu[3:]),
                                                      np.cross(mu[3:], w)], atol=1e-14)


@pytest.mark.parametrize("method", [LieEuler(), LieHeun(), ImplicitMidpoint()], ids=lambda m: type(m).__name__)
def test_casimirs_exact(method, rng):
    top = heavy_top(I3, CHI, sigma=0.3, s=S, theta=0.2)
    mu0 = np.stack([MU0, rng.standard_normal(6)])
    X = BrownianDriver(3, seed=3, dt=1e-2, n_steps=1000, batch_shape=(2,))
    mu = solve(top, X, mu0, method, save_at=X.times[::100]).states
    c0 = top.casimirs(mu0)[:, None, :]
    assert np.max(np.abs(top.casimirs(mu) - c0)) <= 1e-12 * np.max(np.abs(c0))


def _energy_errors(top, method, ns, T=2.0):
    errs = []
    for n in ns:
        X = RoughPath.from_path(np.zeros((n + 1, 3)), times=np.linspace(0.0, T, n + 1))
        mu = solve(top, X, MU0, method).states
        errs.append(np.max(np.abs(top.energy(mu) - top.energy(MU0))))
    return np.polyfit(np.log(T / np.array(ns)), np.log(errs), 1)[0], errs


NS = [20, 40, 80, 160]


def test_energy_at_least_second_order_lie_heun():
    top = heavy_top(I3, CHI)                     # sigma = 0, theta = 0
    slope, errs = _energy_errors(top, LieHeun(), NS)
    assert slope >= 1.8, (slope, errs)           # measured ≈ 3.0 (the energy error is superconvergent)
    assert errs[-1] < 1e-5


def test_energy_implicit_midpoint_exact():
    """The chord-solved midpoint conserves this quadratic(+linear) h to round-off (the paper's
    'energyconserve' scheme), so its error cannot even be fitted: assert it is ≤ 1e-13."""
    top = heavy_top(I3, CHI)
    _, errs = _energy_errors(top, ImplicitMidpoint(), NS)
    assert max(errs) <= 1e-13, errs


def test_energy_first_order_for_lie_euler():
    slope, errs = _energy_errors(heavy_top(I3, CHI), LieEuler(), NS)
    assert 0.8 <= slope <= 1.2, (slope, errs)


def test_paper_gravity_sign_does_not_conserve_energy():
    paper = heavy_top(I3, CHI, convention="paper")
    _, errs = _energy_errors(paper, LieHeun(), NS)
    assert min(errs) > 1e-2                      # no convergence to conservation: a wrong model
    np.testing.assert_allclose(paper.casimirs(MU0), heavy_top(I3, CHI).casimirs(MU0))


def test_dissipation_decreases_modified_energy(rng):
    top = heavy_top(I3, CHI, sigma=0.0, s=S, theta=0.5)
    X = RoughPath.from_path(np.zeros((401, 3)), times=np.linspace(0.0, 4.0, 401))
    mu = solve(top, X, MU0, LieHeun()).states
    e = top.modified_energy(mu)
    assert np.all(np.diff(e) <= 1e-12) and e[-1] < e[0] - 1e-3


@pytest.mark.parametrize("method", [LieEuler(), LieHeun()], ids=lambda m: type(m).__name__)
def test_perturbed_driver_equals_conservative_torque_with_dissipation(method, rng):
    """Proposition 2.1 for the dissipative heavy top: the s-free top driven by ``X.perturb(S)`` equals, path by
    path, the top with ``s = S`` and ``levy_in_dissipation=False`` driven by ``X``; the default model (torque in
    the double bracket too) differs when θ > 0."""
    n, h = 200, 0.01
    dW = np.sqrt(h) * rng.standard_normal((4, n, 3))
    A = 0.5 * h * rng.standard_normal((4, n, 3, 3))
    X = RoughPath(dW, 0.5 * (A - np.swapaxes(A, -1, -2)) + 0.5 * dW[..., :, None] * dW[..., None, :],
                  times=np.linspace(0.0, n * h, n + 1))
    plain = heavy_top(I3, CHI, sigma=0.3, theta=0.5)
    conservative = heavy_top(I3, CHI, sigma=0.3, s=S, theta=0.5, levy_in_dissipation=False)
    default = heavy_top(I3, CHI, sigma=0.3, s=S, theta=0.5)
    a = solve(plain, X.perturb(S), MU0, method).states
    b = solve(conservative, X, MU0, method).states
    c = solve(default, X, MU0, method).states
    assert np.max(np.abs(a - b)) <= 1e-12
    assert np.max(np.abs(a - c)) > 1e-3


@pytest.mark.parametrize("theta, metric, lid", [(0.7, None, False), (0.0, None, True),
                                                 (0.4, np.diag([1.0, 2.0, 0.5, 1.5, 1.0, 3.0]), True)],
                         ids=["dissipative", "conservative", "metric"])
@pytest.mark.parametrize("levy", [True, False])
@pytest.mark.parametrize("cls", [LieEuler, LieHeun, ImplicitMidpoint], ids=lambda c: c.__name__)
def test_se3_kernel_equals_numpy_scheme(cls, levy, theta, metric, lid):
    """The compiled se(3) path (chosen by the SE3Algebra type) computes the numpy path's scheme, also
    the implicit midpoint's chord iteration: same system on se(3) built from its structure constants
    (no compiled path), same driver; Casimirs kept to 1e-12."""
    from mechanics.systems.lie_algebra import LieAlgebra, se3, se3_ad_star_exp
    from mechanics.systems.lie_poisson import LiePoissonSystem

    S3 = np.array([[0, 1.0, -2.0], [-1.0, 0, 0.5], [2.0, -0.5, 0]])
    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.4, s=S3, theta=theta, metric=metric,
                    levy_in_dissipation=lid)
    generic = LiePoissonSystem(LieAlgebra(se3().structure_constants, ad_star_exp=se3_ad_star_exp), top.hamiltonian,
                               top.xi, s=S3, theta=theta, metric=metric, levy_in_dissipation=lid)
    X = BrownianDriver(3, seed=4, dt=0.05, n_steps=40, batch_shape=(5,), levy_area="davie" if levy else None)
    X = X.rough_path()
    mu0 = MU0 * np.array([[1.0], [0.1], [2.0], [-1.5], [0.5]])
    a = solve(top, X, mu0, cls()).states
    b = solve(generic, X, mu0, cls()).states
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    c0 = top.casimirs(mu0)
    assert np.max(np.abs(top.casimirs(a[:, -1]) - c0) / np.maximum(1.0, np.abs(c0))) <= 1e-12


def test_se3_kernel_chord_failure_is_per_member():
    """A member whose chord iteration cannot converge (huge momentum, large step) fails alone in the
    compiled se(3) path: ChordConvergenceError names it; with on_failure="mask" it is marked and the
    others equal their solo solves bit for bit."""
    from mechanics.integrators import ChordConvergenceError

    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.3, theta=0.5)
    X = BrownianDriver(3, seed=2, dt=0.05, n_steps=10, batch_shape=(4,)).rough_path()
    mu0 = np.tile(MU0, (4, 1))
    mu0[1] *= 1e4                                                      # Δt|Ω| ≫ 1: the chord map does not contract
    with pytest.raises(ChordConvergenceError, match=r"member\(s\) \(1,\)"):
        solve(top, X, mu0, ImplicitMidpoint(max_iter=20))
    sol = solve(top, X, mu0, ImplicitMidpoint(max_iter=20), on_failure="mask")
    assert sol.failed.tolist() == [False, True, False, False] and sol.failed_step[1] == 0
    for i in (0, 2, 3):
        alone = solve(top, RoughPath(X.increments[i], X.areas[i], times=X.times, kind="geometric"), mu0[i],
                      ImplicitMidpoint(max_iter=20))
        np.testing.assert_array_equal(sol.states[i], alone.states)
