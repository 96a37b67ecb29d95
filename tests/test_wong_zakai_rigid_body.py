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

from roughpaths.coloured_noise import paper_coloured_noise_matrices, sample_coloured_noise
from mechanics.wong_zakai import (integrate_rigid_body, levy_torque, rigid_body_wong_zakai_limit,
                                  simulate_wong_zakai_rigid_body)

A, D = paper_coloured_noise_matrices(k=0.5)
SIGMA = 0.5


def test_torque_mapping():
    wz = rigid_body_wong_zakai_limit(A, D, SIGMA)
    N = wz.limit.N
    assert np.allclose(wz.torque, SIGMA ** 2 * np.array([N[1, 2], -N[0, 2], N[0, 1]]))
    assert np.allclose(wz.torque, [0.0, -SIGMA ** 2 / (2 * 0.5 * 1.25), 0.0])
    assert np.allclose(levy_torque(wz.perturbation_B, wz.limit_xi), wz.torque)          # B coordinates
    assert np.allclose(wz.limit_xi, SIGMA * wz.limit.M.T)
    # the paper's 2N would double it
    assert np.allclose(levy_torque(wz.limit.unnormalised_area_rate, wz.coloured_xi), 2 * wz.torque)
    try:
        from mechanics.rigid_body import rigid_body
    except ImportError:  # pragma: no cover - the mechanics core is built in parallel
        return
    rb = rigid_body([1.0, 2.0, 3.0], xi=wz.limit_xi, s=wz.perturbation_B, theta=1.0)
    assert np.allclose(rb.levy_torque_vector, wz.torque)


def test_limit_in_both_coordinates_agree(rng):
    """Friz–Oberhauser: ξ = σe_i driven by (MB, M BB Mᵀ + N dt) == ξ' = σM[:, k] driven by B plus Π×c."""
    wz = rigid_body_wong_zakai_limit(A, D, SIGMA)
    s = sample_coloured_noise(A, D, 0.05, np.linspace(0, 1, 2001), rng=rng, batch_shape=(20,))
    _, P1 = integrate_rigid_body(s.limit_path(), [0.0, 0.0, 1.0], [1, 2, 3], wz.coloured_xi, 1.0)
    _, P2 = integrate_rigid_body(s.brownian, [0.0, 0.0, 1.0], [1, 2, 3], wz.limit_xi, 1.0, torque=wz.torque)
    _, P0 = integrate_rigid_body(s.brownian, [0.0, 0.0, 1.0], [1, 2, 3], wz.limit_xi, 1.0)
    d = np.max(np.abs(P1 - P2))
    assert d < 1e-3 and np.max(np.abs(P1 - P0)) > 100 * d
    assert np.max(np.abs(np.linalg.norm(P1, axis=-1) - 1)) < 1e-12


def test_kernel_agrees_with_mechanics_integrators(rng):
    """Our Strang kernel vs the project's coadjoint Lie–Heun (mechanics.integrators) on one coloured path."""
    integrators = pytest.importorskip("mechanics.integrators")
    from mechanics.rigid_body import rigid_body
    s = sample_coloured_noise(A, D, 0.1, np.linspace(0, 0.5, 4001), rng=rng, batch_shape=(5,))
    _, ours = integrate_rigid_body(s.path, [0.0, 0.6, 0.8], [1, 2, 3], SIGMA * np.eye(3), 1.0)
    rb = rigid_body([1.0, 2.0, 3.0], sigma=SIGMA, theta=1.0)
    _, theirs = integrators.simulate(rb, [0.0, 0.6, 0.8], s.path, integrators.LieHeun())
    assert np.max(np.abs(ours - theirs)) < 1e-4


def _run(eps, P, seed, T=1.0):
    r = simulate_wong_zakai_rigid_body(A, D, eps, SIGMA, T=T, n_paths=P, rng=np.random.default_rng(seed),
                                       save_every=10 ** 9, systems=("coloured", "limit", "no_torque", "srblevy"))
    return r["final"]


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
