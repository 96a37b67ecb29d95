"""Proposition 3.1 beyond the rigid body: on su(3), so(5) (and su(4), slow) the uniform law on a coadjoint orbit
is invariant without dissipation, with the Lévy-area correction.

Claim: for spanning noise ``ξ_i = σ e_i`` and ``θ = 0`` the Lie–Poisson equation
``dμ = ad*_{∇h + ℓ} μ dt + Σ_i ad*_{ξ_i} μ ∘ dW^i``, ``ℓ = ½ Σ s^{ij}[ξ_i, ξ_j] ≠ 0``, leaves the uniform (Ad-invariant)
law ν on the orbit of μ₀ invariant, whatever s (the correction only adds a coadjoint drift).

Test: draw ``P`` exact samples of ν (``U M₀ U⁻¹``, Haar ``U``: ``MatrixLieAlgebra.sample_orbit``), evolve each by
the SDE for a time ``T`` (Lie–Heun through ``mechanics.run_ensemble``, one independent path per sample), and
compare the law at ``T`` with ``P`` fresh exact samples of ν:

* the means of the linear and quadratic functions ``μ_a``, ``μ_a μ_b`` (the moment features) by a two-sample z
  statistic ``(m₁ − m₂)/√(se₁² + se₂²)``; threshold fixed before running: every |z| < 4 (44 features on su(3),
  65 on so(5): a false alarm has probability ≈ 0.3 %);
* the law of the non-linear energy ``h(μ)`` by the two-sample Kolmogorov–Smirnov test; threshold p > 1e-4;
* the fresh samples against the closed form of ν's moments, ``E[μ] = 0``, ``E[μμᵀ] = |μ₀|²/n · I`` (Schur: the
  adjoint representation of a simple algebra is irreducible), so the reference itself is checked.

Power (the test can fail): the same statistics reject (every threshold crossed by far) the law at ``T`` of the
dissipative system (θ > 0, whose invariant law is Gibbs, not ν), and the evolution is not trivial (the start and
end states of a path are decorrelated: ``E[μ_0 · μ_T] ≤ 0.3 |μ₀|²``).
"""

import numpy as np
import pytest
from scipy.stats import ks_2samp

import mechanics

CASES = {
    "su3": (lambda: mechanics.su(3), lambda g: g.matrix_to_dual(1j * np.diag([1.0, 0.3, -1.3]))),
    "so5": (lambda: mechanics.so(5), lambda g: g.matrix_to_dual(_blocks(5, [1.0, 0.4]))),
    "su4": (lambda: mechanics.su(4), lambda g: g.matrix_to_dual(1j * np.diag([1.1, 0.5, -0.4, -1.2]))),
}


def _blocks(N, angles):
    M = np.zeros((N, N))
    for k, a in enumerate(angles):
        M[2 * k, 2 * k + 1], M[2 * k + 1, 2 * k] = a, -a
    return M


def _system(g, sigma, theta):
    n = g.dim
    s = np.zeros((n, n))
    s[0, 1], s[1, 3], s[2, n - 1] = 2.0, -1.5, 1.0
    s = s - s.T
    return mechanics.LiePoissonSystem(g, np.linspace(0.6, 2.0, n), sigma * np.eye(n), s=s, theta=theta)


def _evolve(system, start, *, T, dt, seed):
    return mechanics.run_ensemble(system, start, dt=dt, n_steps=int(round(T / dt)), n_paths=start.shape[0], seed=seed,
                                  keep_final=True, chunk_size=min(start.shape[0], 2000))


def _compare(system, final, fresh):
    """Two-sample statistics of the final states against fresh uniform samples: max |z|, KS p-value of h."""
    a, b = mechanics.moment_observable(final), mechanics.moment_observable(fresh)
    se = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
    z = (a.mean(axis=0) - b.mean(axis=0)) / se
    p = ks_2samp(system.energy(final), system.energy(fresh)).pvalue
    return float(np.max(np.abs(z))), float(p)


def _run_case(name, *, P, T, dt, sigma=0.6):
    make, point = CASES[name]
    g = make()
    mu0 = point(g)
    n = g.dim
    start = g.sample_orbit(mu0, P, np.random.default_rng(101))
    fresh = g.sample_orbit(mu0, P, np.random.default_rng(202))
    # the reference against the closed form of ν's moments
    feats = mechanics.moment_observable(fresh)
    exact = mechanics.moment_observable(np.zeros(n))
    iu = np.triu_indices(n)
    exact[n:] = (float(mu0 @ mu0) / n * np.eye(n))[iu]
    z_ref = np.max(np.abs(feats.mean(axis=0) - exact) / (feats.std(axis=0, ddof=1) / np.sqrt(P)))
    assert z_ref < 4.0, z_ref
    system = _system(g, sigma, 0.0)
    assert np.linalg.norm(system.levy_velocity) > 0.5           # a large correction, and still uniform
    res = _evolve(system, start, T=T, dt=dt, seed=7)
    final = res.final_states
    drift = np.abs(g.casimirs(final) - g.casimirs(mu0)) / g.casimir_scale(g.dual_to_matrix(mu0))
    assert np.max(drift) <= 1e-12                                   # every path stayed on the orbit
    zmax, p = _compare(system, final, fresh)
    corr = float(np.mean(np.sum(start * final, axis=-1)) / (mu0 @ mu0))
    print(f"{name}: max |z| = {zmax:.2f} over {len(exact)} features, KS p(h) = {p:.3g}, E[μ0·μT]/|μ|² = {corr:.3f}, "
          f"reference vs closed form max |z| = {z_ref:.2f}")
    assert zmax < 4.0 and p > 1e-4
    assert corr < 0.3                                                # the paths moved
    # power: the dissipative system from the same start ends far from uniform
    diss = _evolve(_system(g, sigma, 1.5), start, T=T, dt=dt, seed=7).final_states
    zmax_d, p_d = _compare(system, diss, fresh)
    print(f"{name}, θ = 1.5 (Gibbs, not uniform): max |z| = {zmax_d:.1f}, KS p(h) = {p_d:.2g}")
    assert zmax_d > 10.0 and p_d < 1e-8


@pytest.mark.parametrize("name", ["su3", "so5"])
def test_uniform_orbit_law_is_invariant(name):
    _run_case(name, P=1000, T=1.5, dt=0.025)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["su3", "so5", "su4"])
def test_uniform_orbit_law_is_invariant_large(name):
    _run_case(name, P=20_000, T=4.0, dt=0.01)
