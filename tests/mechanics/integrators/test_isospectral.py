"""The coadjoint schemes on matrix states (systems on a MatrixLieAlgebra).

The oracle is the structure-constant path: the same system on ``LieAlgebra(g.structure_constants)`` (its own
compiled kernels, coordinates, Rodrigues-free generic exponential) must give the same solution to round-off,
since both integrate the same scheme; Casimirs are checked against the eigenvalues of the initial matrix.
"""

import numpy as np
import pytest

import roughpaths as rp
from mechanics import ImplicitMidpoint, LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, so, sp, su

SCHEMES = [LieEuler(), LieHeun(), ImplicitMidpoint()]


def _pair(g, theta, levy_in_dissipation=True, m=3, seed=0):
    rng = np.random.default_rng(seed)
    n = g.dim
    xi = 0.5 * rng.standard_normal((m, n))
    moments = 1.0 + rng.random(n)
    s = np.zeros((m, m))
    s[0, 1], s[1, 0] = 0.8, -0.8
    kw = dict(s=s, theta=theta, levy_in_dissipation=levy_in_dissipation)
    matrix = LiePoissonSystem(g, moments, xi, **kw)
    consts = LiePoissonSystem(LieAlgebra(g.structure_constants, name="constants"), np.diag(moments), xi, **kw)
    return matrix, consts, rng.standard_normal(n)


@pytest.mark.parametrize("g", [so(4), su(3)], ids=["so4", "su3"])
@pytest.mark.parametrize("theta,lid", [(0.0, True), (0.4, True), (0.4, False)])
@pytest.mark.parametrize("scheme", SCHEMES, ids=lambda s: type(s).__name__)
def test_matrix_path_equals_the_structure_constant_path(g, theta, lid, scheme):
    matrix, consts, mu0 = _pair(g, theta, lid)
    X = rp.brownian_rough_path(np.linspace(0.0, 0.5, 101), dim=3, rng=np.random.default_rng(4), batch_shape=(3,))
    a = rp.solve(matrix, X, mu0, scheme, save_at=np.array([0.25, 0.5]))
    b = rp.solve(consts, X, mu0, scheme, save_at=np.array([0.25, 0.5]))
    tol = 5e-12 if isinstance(scheme, ImplicitMidpoint) else 1e-12      # the midpoint: two iterations' tolerance
    np.testing.assert_allclose(a.states, b.states, rtol=0, atol=tol * max(1.0, float(np.max(np.abs(b.states)))))


@pytest.mark.parametrize("g", [su(6), so(7), sp(2)], ids=["su6", "so7", "sp4"])
def test_casimirs_kept_over_many_steps(g):
    """tr((iM)^k) (tr(M^k) on sp) relative to sum |lambda|^k: drift at round-off level over 2000 steps (10^4 in the
    slow run of tests/mechanics/integrators/test_isospectral_strong_order.py's companion)."""
    rng = np.random.default_rng(1)
    n, m = g.dim, 4
    system = LiePoissonSystem(g, 1.0 + rng.random(n), 0.4 * rng.standard_normal((m, n)), theta=0.2)
    mu0 = 0.5 * rng.standard_normal(n)
    driver = rp.BrownianDriver(m, batch_shape=(2,), seed=3, dt=1e-3, n_steps=2000)
    final = rp.solve(system, driver, mu0, LieHeun()).final
    M0 = g.dual_to_matrix(mu0)
    drift = np.abs(g.casimirs(final) - g.casimirs(mu0)) / g.casimir_scale(M0)
    assert np.max(drift) < 1e-12, drift
    assert np.max(np.abs(final - mu0)) > 0.1                         # it moved


def test_batch_members_are_bitwise_independent():
    g = su(4)
    rng = np.random.default_rng(5)
    system = LiePoissonSystem(g, 1.0 + rng.random(g.dim), 0.3 * rng.standard_normal((3, g.dim)), theta=0.3)
    mu0 = rng.standard_normal((5, g.dim))
    X = rp.brownian_rough_path(np.linspace(0.0, 0.2, 41), dim=3, rng=np.random.default_rng(6), batch_shape=(5,))
    for scheme in SCHEMES:
        batch = rp.solve(system, X, mu0, scheme).final
        for i in (0, 3):
            alone = rp.solve(system, X[i], mu0[i], scheme).final
            np.testing.assert_array_equal(batch[i], alone)


def test_a_failed_member_fails_alone():
    g = su(3)
    rng = np.random.default_rng(2)
    system = LiePoissonSystem(g, 1.0 + rng.random(8), 0.3 * rng.standard_normal((2, 8)))
    mu0 = rng.standard_normal((3, 8))
    mu0[1] *= 1e250                                                   # overflows in its first step
    X = rp.brownian_rough_path(np.linspace(0.0, 0.1, 21), dim=2, rng=np.random.default_rng(3), batch_shape=(3,))
    sol = rp.solve(system, X, mu0, LieHeun(), on_failure="mask")
    assert np.all(np.isnan(sol.final[1])) and np.all(np.isfinite(sol.final[[0, 2]]))
    np.testing.assert_array_equal(sol.final[2], rp.solve(system, X[2], mu0[2], LieHeun()).final)


def test_unconverged_midpoint_is_reported():
    g = su(3)
    rng = np.random.default_rng(8)
    system = LiePoissonSystem(g, 0.05 + rng.random(8), 0.3 * rng.standard_normal((2, 8)), theta=2.0)
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 3), dim=2, rng=np.random.default_rng(3))
    from mechanics import ChordConvergenceError
    with pytest.raises(ChordConvergenceError, match="did not converge"):
        rp.solve(system, X, 20.0 * rng.standard_normal(8), ImplicitMidpoint(max_iter=3))


def test_level1_driver_gives_zero_area():
    """A level-1 driver drives with the increments alone: the same as a RoughPath whose areas are zero."""
    g = so(5)
    rng = np.random.default_rng(9)
    system = LiePoissonSystem(g, 1.0 + rng.random(g.dim), 0.4 * rng.standard_normal((3, g.dim)))
    X = rp.brownian_rough_path(np.linspace(0.0, 0.3, 31), dim=3, rng=np.random.default_rng(1))
    mu0 = rng.standard_normal(g.dim)
    a = rp.solve(system, X.to_level1(), mu0, LieEuler()).final
    consts = LiePoissonSystem(LieAlgebra(g.structure_constants), np.diag(1.0 / system.hamiltonian.q_diagonal),
                              system.xi)
    b = rp.solve(consts, X.to_level1(), mu0, LieEuler()).final
    np.testing.assert_allclose(a, b, atol=1e-12)
    with_area = rp.solve(system, X, mu0, LieEuler()).final
    assert np.max(np.abs(with_area - a)) > 1e-4


def test_a_hamiltonian_given_on_matrices():
    """h(M) = a/2 B(M, M) + B(M, C) given on matrices (MatrixHamiltonian: the solver calls gradient_matrix) against
    the same h in coordinates (a diagonal QuadraticHamiltonian with the linear term C's coordinates)."""
    from mechanics import MatrixHamiltonian, QuadraticHamiltonian

    g = su(4)
    rng = np.random.default_rng(12)
    a, c = 0.7, rng.standard_normal(g.dim)
    C = g.to_matrix(c)
    h_matrix = MatrixHamiltonian(g, lambda M: 0.5 * a * g.pairing(M, M) + g.pairing(M, C), lambda M: a * M + C)
    h_coords = QuadraticHamiltonian(np.full(g.dim, a), linear=c)
    xi = 0.4 * rng.standard_normal((3, g.dim))
    s = np.zeros((3, 3))
    s[1, 2], s[2, 1] = 0.5, -0.5
    mu0 = rng.standard_normal((2, g.dim))
    np.testing.assert_allclose(h_matrix.value(mu0), h_coords.value(mu0), atol=1e-12)
    np.testing.assert_allclose(h_matrix.gradient(mu0), h_coords.gradient(mu0), atol=1e-12)
    X = rp.brownian_rough_path(np.linspace(0.0, 0.5, 101), dim=3, rng=np.random.default_rng(1), batch_shape=(2,))
    for theta in (0.0, 0.3):
        one = LiePoissonSystem(g, h_matrix, xi, s=s, theta=theta)
        two = LiePoissonSystem(g, h_coords, xi, s=s, theta=theta)
        np.testing.assert_allclose(rp.solve(one, X, mu0, LieHeun()).final, rp.solve(two, X, mu0, LieHeun()).final,
                                   atol=1e-12)
