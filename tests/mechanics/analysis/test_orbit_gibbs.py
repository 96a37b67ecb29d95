"""The orbit Gibbs oracle (``mechanics.OrbitGibbsMeasure``) against independent oracles, and its input checks.

Claims:

* on so(3) (matrix algebra) its estimates of the Gibbs moments of ``h̃ = ½ μ·𝕀⁻¹μ + ℓ·μ`` on the sphere
  ``|μ| = r`` agree with the rigid body's quadrature (``mechanics.GibbsMeasure``, relative accuracy 1e-10) within
  4 of its own standard errors, and ``orbit_gibbs_beta`` of the so(3) system is the rigid body's ``gibbs_beta``
  (the general derivation reduces to the rigid body's);
* on su(2) (orbits are round spheres) with a linear energy ``a·μ`` the mean is the Langevin closed form
  ``E[μ·â] = −r (coth κ − 1/κ)``, ``κ = β r |a|``;
* its standard errors are honest: over 40 independent estimates the spread of ``(estimate − exact)/SE`` has
  standard deviation within [0.7, 1.35] (the delta-method error of a self-normalised estimator);
* with ``β = 0`` it is the uniform law, whose second moment on su(3) is ``|μ|²/8 · I`` exactly (Schur);
* bad input (non-compact algebra, non-orthonormal use, non-isotropic noise, the h-dissipated model, a
  structure-constant algebra, negative β, a wrong-shaped energy) raises a clear error naming the fix.
"""

import numpy as np
import pytest

import mechanics
from mechanics.systems.lie_algebra import so3

IU = np.triu_indices(3)


def test_so3_matches_rigid_body_quadrature():
    g = mechanics.so(3)
    inertia = np.array([1.0, 2.0, 3.0])
    sigma, theta = 0.8, 1.0
    s = np.array([[0.0, 1.0, -0.5], [-1.0, 0.0, 0.8], [0.5, -0.8, 0.0]])
    system = mechanics.LiePoissonSystem(g, inertia, sigma * np.eye(3), s=s, theta=theta)
    beta = mechanics.orbit_gibbs_beta(system)
    assert beta == mechanics.gibbs_beta(sigma, theta)
    r = 1.3
    mu0 = np.array([0.0, 0.0, r])
    gm = mechanics.OrbitGibbsMeasure.from_system(system, mu0, n_samples=80_000, rng=np.random.default_rng(3))
    est = gm.expectation()
    # the same density exp(-β h̃) on the same sphere, in the same coordinates, by quadrature
    quad = mechanics.GibbsMeasure(inertia, system.levy_velocity, beta=beta, radius=r)
    exact = np.concatenate([quad.mean, quad.second_moment[IU]])
    z = (est.mean - exact) / est.standard_error
    print(f"so(3): IS {np.round(est.mean, 4)}\n  quadrature {np.round(exact, 4)}\n  z {np.round(z, 2)}, "
          f"ESS {est.effective_sample_size:.0f}")
    assert np.max(np.abs(z)) < 4.0
    assert np.max(np.abs(quad.mean)) > 0.2              # a tilted law, not the uniform one
    # the orbit samples lie on the sphere
    np.testing.assert_allclose(np.linalg.norm(gm.samples, axis=-1), r, rtol=1e-13)


def _langevin(beta, r, a):
    k = beta * r * np.linalg.norm(a)
    return -r * (1.0 / np.tanh(k) - 1.0 / k)


def test_su2_linear_energy_langevin_closed_form_and_honest_standard_errors():
    g = mechanics.su(2)
    a = np.array([0.3, -0.4, 1.2])
    r, beta = 0.9, 1.7
    exact = _langevin(beta, r, a)
    unit = a / np.linalg.norm(a)
    zs = []
    rng = np.random.default_rng(11)
    for _ in range(40):
        gm = mechanics.OrbitGibbsMeasure(g, [r, 0.0, 0.0], lambda m: m @ a, beta=beta, n_samples=4000, rng=rng)
        est = gm.expectation(lambda m: m @ unit)
        zs.append((float(est.mean) - exact) / float(est.standard_error))
    zs = np.array(zs)
    print(f"su(2) Langevin: exact {exact:.5f}; z over 40 runs: mean {zs.mean():.2f}, sd {zs.std(ddof=1):.2f}")
    assert abs(zs.mean()) < 4.0 / np.sqrt(40) * 1.35
    assert 0.7 <= zs.std(ddof=1) <= 1.35
    big = mechanics.OrbitGibbsMeasure(g, [r, 0.0, 0.0], lambda m: m @ a, beta=beta, n_samples=200_000,
                                      rng=np.random.default_rng(12)).expectation(lambda m: m @ unit)
    assert abs(float(big.mean) - exact) < 4 * float(big.standard_error)
    assert float(big.standard_error) < 2e-3


def test_beta_zero_is_the_uniform_law():
    g = mechanics.su(3)
    mu0 = g.matrix_to_dual(1j * np.diag([1.0, 0.3, -1.3]))
    system = mechanics.LiePoissonSystem(g, np.linspace(0.6, 2.0, 8), np.eye(8), theta=0.5)
    gm = mechanics.OrbitGibbsMeasure.from_system(system, mu0, n_samples=50_000, rng=np.random.default_rng(1))
    u = gm.reweighted(beta=0.0)
    assert u.effective_sample_size == pytest.approx(50_000, rel=1e-12)
    est = u.expectation(lambda m: np.einsum("ka,kb->kab", m, m).reshape(len(m), -1))
    exact = (mu0 @ mu0 / 8 * np.eye(8)).ravel()
    assert np.max(np.abs(est.mean - exact) / est.standard_error) < 4.5
    # the samples are shared: reweighting changes only the weights
    assert u.samples is gm.samples and gm.beta == 1.0 and gm.effective_sample_size < u.effective_sample_size


def test_bad_input_is_refused():
    g = mechanics.su(3)
    mu0 = g.matrix_to_dual(1j * np.diag([1.0, 0.3, -1.3]))
    inertia = np.linspace(0.6, 2.0, 8)
    s = np.zeros((8, 8))
    s[0, 1], s[1, 0] = 1.0, -1.0
    with pytest.raises(ValueError, match="isotropic"):
        mechanics.orbit_gibbs_beta(mechanics.LiePoissonSystem(g, inertia, np.diag(np.linspace(1, 2, 8)), theta=1.0))
    with pytest.raises(ValueError, match="levy_in_dissipation"):
        mechanics.orbit_gibbs_beta(mechanics.LiePoissonSystem(g, inertia, np.eye(8), s=s, theta=1.0,
                                                              levy_in_dissipation=False))
    with pytest.raises(ValueError, match="not compact"):
        mechanics.orbit_gibbs_beta(mechanics.LiePoissonSystem(mechanics.sl(3), inertia, np.eye(8), theta=1.0))
    with pytest.raises(TypeError, match="GibbsMeasure"):
        mechanics.orbit_gibbs_beta(mechanics.LiePoissonSystem(so3(), [1.0, 2.0, 3.0], np.eye(3), theta=1.0))
    with pytest.raises(ValueError, match="metric"):
        mechanics.orbit_gibbs_beta(mechanics.LiePoissonSystem(g, inertia, np.eye(8), theta=1.0, metric=2 * np.eye(8)))
    with pytest.raises(TypeError, match="LiePoissonSystem"):
        mechanics.orbit_gibbs_beta(g)
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="beta must be >= 0"):
        mechanics.OrbitGibbsMeasure(g, mu0, lambda m: m[..., 0], beta=-1.0, n_samples=10, rng=rng)
    with pytest.raises(ValueError, match="energy must map"):
        mechanics.OrbitGibbsMeasure(g, mu0, lambda m: m, beta=1.0, n_samples=10, rng=rng)
    with pytest.raises(TypeError, match="callable"):
        mechanics.OrbitGibbsMeasure(g, mu0, 3.0, beta=1.0, n_samples=10, rng=rng)
    with pytest.raises(TypeError, match="Generator"):
        mechanics.OrbitGibbsMeasure(g, mu0, lambda m: m[..., 0], beta=1.0, n_samples=10, rng=3)
    with pytest.raises(ValueError, match="trailing shape"):
        mechanics.OrbitGibbsMeasure(g, mu0[:3], lambda m: m[..., 0], beta=1.0, n_samples=10, rng=rng)
    gm = mechanics.OrbitGibbsMeasure(g, mu0, lambda m: m[..., 0], beta=1.0, n_samples=10, rng=rng)
    with pytest.raises(ValueError, match="f must map"):
        gm.expectation(lambda m: m[0])


def test_chunked_expectation_equals_the_direct_formula():
    """Over several chunks of samples, the one-pass sums give Σ w f and (Σ w² (f − f̂)²)^½ of the normalised weights."""
    g = mechanics.so(4)
    mu0 = g.matrix_to_dual(np.array([[0, 1.0, 0, 0], [-1.0, 0, 0, 0], [0, 0, 0, 0.3], [0, 0, -0.3, 0]]))
    gm = mechanics.OrbitGibbsMeasure(g, mu0, lambda m: m @ np.arange(6.0) + 50.0, beta=0.7, n_samples=45_000,
                                     rng=np.random.default_rng(2))
    est = gm.expectation()
    f = mechanics.moment_observable(gm.samples)
    w = gm.weights
    mean = w @ f
    se = np.sqrt((w ** 2) @ (f - mean) ** 2)
    np.testing.assert_allclose(est.mean, mean, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(est.standard_error, se, rtol=1e-9)
    assert est.effective_sample_size == pytest.approx(1.0 / np.sum(w ** 2), rel=1e-12)
