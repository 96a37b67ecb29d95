"""Claim (Wong–Zakai anomaly): the rigid body driven by coloured noise with no added drift (srbcoloured)
converges, as ε → 0, to the white-noise system with noise vectors σ·(A⁻¹D)[:, k] and the Lévy
torque Π × c, c = ½ Σ N^{ij} (σe_i)×(σe_j) = σ²(N23, −N13, N12), in the conservative part only —
not to the same system without the torque, and not to the paper's (srblevy), whose dissipation
also carries c.

Coupled through the same Brownian motion B (the coloured noise is sampled jointly with B), the
pathwise RMS difference to the limit shrinks like ε, and the ensemble means agree within standard
errors, while the torque-free system differs by many standard errors.

Parameters: A = kI + Λ (Λ13 = 1), k = 0.5, D = I, σ = 0.5 (larger than the paper's 0.05 so that the
torque c = (0, −0.2, 0) moves E[Π1(T)] by ≈ 0.1 ≫ the standard error), θ = 1, I = diag(1, 2, 3),
Π(0) = e3, T = 1. The rotation by π about e3 is a symmetry of the torque-free limit (σ²MMᵀ is
diagonal), so there E[Π1] = 0; the torque breaks it.
"""

import numpy as np
import pytest

from roughpaths import paper_coloured_noise_matrices, sample_coloured_noise, solve
from mechanics.integrators import LieHeun
from mechanics.systems.lie_poisson import levy_velocity
from mechanics.systems.rigid_body import rigid_body
from mechanics.limits.wong_zakai import rigid_body_wong_zakai_limit, simulate_wong_zakai_rigid_body

A, D = paper_coloured_noise_matrices(k=0.5)
SIGMA = 0.5


def test_torque_mapping():
    wz = rigid_body_wong_zakai_limit(A, D, SIGMA)
    N = wz.limit.N
    assert np.allclose(wz.torque, SIGMA ** 2 * np.array([N[1, 2], -N[0, 2], N[0, 1]]))
    assert np.allclose(wz.torque, [0.0, -SIGMA ** 2 / (2 * 0.5 * 1.25), 0.0])
    assert np.allclose(levy_velocity(wz.perturbation_B, wz.limit_xi), wz.torque)          # B coordinates
    assert np.allclose(wz.limit_xi, SIGMA * wz.limit.M.T)
    # the paper's 2N would double it
    assert np.allclose(levy_velocity(wz.limit.unnormalised_area_rate, wz.coloured_xi), 2 * wz.torque)
    try:
        from mechanics.systems.rigid_body import rigid_body
    except ImportError:  # pragma: no cover - the mechanics core is built in parallel
        return
    rb = rigid_body([1.0, 2.0, 3.0], xi=wz.limit_xi, s=wz.perturbation_B, theta=1.0)
    assert np.allclose(rb.levy_velocity, wz.torque)


def test_limit_in_both_coordinates_agree(rng):
    """Friz–Oberhauser: ξ = σe_i driven by (MB, M BB Mᵀ + N dt) == ξ' = σM[:, k] driven by B plus Π×c."""
    wz = rigid_body_wong_zakai_limit(A, D, SIGMA)
    s = sample_coloured_noise(A, D, 0.05, np.linspace(0, 1, 2001), rng=rng, batch_shape=(20,))
    e3 = [0.0, 0.0, 1.0]
    torque_body = rigid_body([1, 2, 3], xi=wz.limit_xi, s=wz.perturbation_B, theta=1.0, levy_in_dissipation=False)
    assert np.allclose(torque_body.levy_velocity, wz.torque)                 # Π×c in the conservative term only
    P1 = solve(rigid_body([1, 2, 3], xi=wz.coloured_xi, theta=1.0), s.limit_path(), e3, LieHeun()).states
    P2 = solve(torque_body, s.brownian, e3, LieHeun()).states
    P0 = solve(rigid_body([1, 2, 3], xi=wz.limit_xi, theta=1.0), s.brownian, e3, LieHeun()).states
    d = np.max(np.abs(P1 - P2))
    assert d < 1e-3 and np.max(np.abs(P1 - P0)) > 100 * d
    assert np.max(np.abs(np.linalg.norm(P1, axis=-1) - 1)) < 1e-12


def _strang_naive(X, Pi0, inertia, xi, theta, c, cd):
    """Independent scheme (numpy, written here): Strang splitting, half drift step (explicit midpoint on
    the drift velocity), the exact noise rotation by the step's log-signature η = ξ_i X^i + ½ L^{ij} ξ_i×ξ_j,
    half drift step; rotations by the Rodrigues formula written with np.cross."""
    def rot(v, p):                                   # exp(ad*_v) Π = exp(-hat v) Π: Rodrigues, batched
        t = np.linalg.norm(v, axis=-1, keepdims=True)
        vxp = np.cross(v, p)
        return p - np.sin(t) / t * vxp + (1 - np.cos(t)) / t ** 2 * np.cross(v, vxp)

    def vel(p):                                      # Π×(Ω + c) + θΠ×(Π×(Ω + cd)) = Π × vel
        om = p / inertia
        return om + c + theta * np.cross(p, om + cd)

    inc, lev = X.increments, X.step_levy_areas       # (P, N, m), (P, N, m, m)
    eta = inc @ xi + 0.5 * np.einsum("pnij,ijk->pnk", lev, np.cross(xi[:, None], xi[None, :]))
    P = np.tile(np.asarray(Pi0, float), (inc.shape[0], 1))
    for n, dt in enumerate(X.dt):
        for half in range(2):
            if half:
                P = rot(eta[:, n], P)
            P = rot(0.5 * dt * vel(rot(0.25 * dt * vel(P), P)), P)
    return P


def test_shared_integrator_agrees_with_a_naive_strang_splitting(rng):
    """The shared coadjoint Lie–Heun (``roughpaths.solve`` on ``rigid_body(..., s)``) vs an independent Strang
    scheme on coloured paths, for the exact limit's torque placement (c in the conservative term only:
    ``levy_in_dissipation=False``) and for (srblevy) (c in the dissipation too: ``levy_in_dissipation=True``)."""
    s = sample_coloured_noise(A, D, 0.1, np.linspace(0, 0.5, 1001), rng=rng, batch_shape=(5,))
    c = np.array([0.1, -0.2, 0.05])
    sc = np.zeros((3, 3))                             # c = σ² (s23, −s13, s12) for ξ_i = σ e_i
    sc[1, 2], sc[0, 2], sc[0, 1] = c[0] / SIGMA ** 2, -c[1] / SIGMA ** 2, c[2] / SIGMA ** 2
    sc -= sc.T
    for cd in (np.zeros(3), c):
        body = rigid_body([1, 2, 3], xi=SIGMA * np.eye(3), s=sc, theta=1.0, levy_in_dissipation=bool(np.any(cd)))
        assert np.allclose(body.levy_velocity, c)
        ours = solve(body, s.path, [0.0, 0.6, 0.8], LieHeun(), save_at=s.path.times[::1000]).states
        ref = _strang_naive(s.path, [0.0, 0.6, 0.8], np.array([1.0, 2.0, 3.0]), SIGMA * np.eye(3), 1.0, c, cd)
        assert np.max(np.abs(ours[:, -1] - ref)) < 1e-4
        other = _strang_naive(s.path, [0.0, 0.6, 0.8], np.array([1.0, 2.0, 3.0]), SIGMA * np.eye(3), 1.0, c,
                              c - cd)                  # the other dissipation placement is far off
        assert np.max(np.abs(ours[:, -1] - other)) > 1e-3


def _run(eps, P, seed, T=1.0):
    r = simulate_wong_zakai_rigid_body(A, D, eps, SIGMA, T=T, n_paths=P, rng=np.random.default_rng(seed),
                                       save_every=10 ** 9, systems=("coloured", "limit", "no_torque", "srblevy"))
    return {k: sol.final for k, sol in r.items()}


def _paired(fin, other):
    d = fin["coloured"] - fin[other]
    return d.mean(0), d.std(0, ddof=1) / np.sqrt(len(d)), np.sqrt(np.mean(np.sum(d ** 2, axis=-1)))


def _check_anomaly(eps_list, P, seed):
    rms = []
    for eps in eps_list:
        fin = _run(eps, P, seed)
        for k, v in fin.items():
            assert np.max(np.abs(np.linalg.norm(v, axis=-1) - 1)) < 1e-12, k          # Casimir |Π|
        m_lim, se_lim, r_lim = _paired(fin, "limit")
        m_no, se_no, _ = _paired(fin, "no_torque")
        m_lev, se_lev, _ = _paired(fin, "srblevy")
        rms.append(r_lim)
        assert abs(m_no[0]) > 10 * se_no[0]                 # the torque moves E[Π1] by many SE
        assert np.max(np.abs(m_lev) / se_lev) > 10          # (srblevy) dissipation is not the limit
    assert np.all(np.abs(m_lim) < 4 * se_lim + 0.1 * abs(m_no[0])), (m_lim, se_lim)
    slope = np.polyfit(np.log(eps_list), np.log(rms), 1)[0]
    assert slope > 0.7 and rms[-1] < 0.5 * rms[0], (slope, rms)


def test_anomaly_reduced():
    _check_anomaly((0.2, 0.1, 0.05), 600, 11)


@pytest.mark.slow
def test_anomaly_full():
    _check_anomaly((0.2, 0.1, 0.05, 0.025), 8000, 12)


def test_saved_times_include_T_and_match_unsaved_runs():
    """Each system comes back as a Solution whose times are every save_every-th grid time and T; the saved
    states do not depend on save_every (same draws), and .final is the state at T."""
    kw = dict(T=0.3, n_paths=3, systems=("coloured", "limit"))
    a = simulate_wong_zakai_rigid_body(A, D, 0.2, SIGMA, rng=np.random.default_rng(4), save_every=7, **kw)
    b = simulate_wong_zakai_rigid_body(A, D, 0.2, SIGMA, rng=np.random.default_rng(4), save_every=1, **kw)
    n = b["coloured"].stats["n_steps"]
    assert n % 7 != 0
    for k in kw["systems"]:
        assert a[k].times[-1] == b[k].times[-1] and abs(b[k].times[-1] - 0.3) < 1e-12
        idx = np.r_[np.arange(0, n + 1, 7), n]
        np.testing.assert_allclose(a[k].times, b[k].times[idx], rtol=0, atol=1e-15)
        np.testing.assert_array_equal(a[k].states, b[k].states[:, idx])
        np.testing.assert_array_equal(a[k].final, b[k].final)
