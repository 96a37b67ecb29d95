"""Claim (paper eq. 2dexample): the planar system driven by coloured noise with A = αI + γJ, D = √δ I
converges, as ε → 0, to dX = (Q + N12 S)X dt + √(δ/(α²+γ²)) P(X)∘dW, where N12 = Alt(ΣA⁻ᵀ)_{12}
equals the paper's δγ/(2α(α²+γ²)), S = diag(1, −1) = [V_1, V_2], and A⁻¹D = √(δ/(α²+γ²)) R with R
a rotation (so the paper's scaling is right, W = RB).

Monte Carlo: E[X_T] of the coloured system approaches the limit's closed form
(e^{(λ+N12)T} x1, e^{(μ−N12)T} x2) — derived here by hand — and not the torque-free
(e^{λT} x1, e^{μT} x2); E|X_T|² matches the limit's second-moment ODE.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from mechanics.wong_zakai import planar_example, planar_limit_moments, simulate_planar_coloured

PARAMS = dict(alpha=1.0, gamma=1.0, delta=2.0, lam=-0.2, mu=0.0)
X0 = np.array([1.0, 1.0])
T = 1.0


@pytest.mark.parametrize("alpha, gamma, delta", [(1.0, 1.0, 2.0), (0.5, 2.0, 1.0), (2.0, -0.7, 3.0)])
def test_constant_and_scaling(alpha, gamma, delta):
    ex = planar_example(alpha, gamma, delta)
    const = delta * gamma / (2 * alpha * (alpha ** 2 + gamma ** 2))
    assert np.isclose(ex.N12, const, rtol=1e-12) and np.isclose(ex.paper_constant, const)
    M = ex.limit.scaling
    c = np.sqrt(delta / (alpha ** 2 + gamma ** 2))
    assert np.isclose(ex.limit_scale, c)
    R = M / c
    assert np.allclose(R @ R.T, np.eye(2), atol=1e-12) and np.isclose(np.linalg.det(R), 1.0)
    # [V1, V2] = DV2·V1 − DV1·V2 with V1 = (0, x1), V2 = (x2, 0): S = diag(1, −1)
    E1, E2 = ex.noise_matrices
    assert np.allclose(E2 @ E1 - E1 @ E2, np.diag([1.0, -1.0]))


def _hand_limit(ex, torque=True):
    n12 = ex.N12 if torque else 0.0
    mean = np.array([np.exp((ex.lam + n12) * T) * X0[0], np.exp((ex.mu - n12) * T) * X0[1]])
    c2 = ex.limit_scale ** 2
    # d/dt (P11, P22) = [[2(λ+N12), c²], [c², 2(μ−N12)]] (P11, P22)   (Itô, G1²=G2²=0)
    L = np.array([[2 * (ex.lam + n12), c2], [c2, 2 * (ex.mu - n12)]])
    P = sla.expm(L * T) @ (X0 ** 2)
    return mean, P.sum()


def test_library_limit_moments_match_hand_formula():
    ex = planar_example(**PARAMS)
    for torque in (True, False):
        m, P = planar_limit_moments(ex, X0, T, torque=torque)
        mh, sh = _hand_limit(ex, torque)
        assert np.allclose(m, mh, rtol=1e-12) and np.isclose(np.trace(P), sh, rtol=1e-12)


def _check(eps_list, P, seed):
    ex = planar_example(**PARAMS)
    mean_lim, sq_lim = _hand_limit(ex)
    mean_no, _ = _hand_limit(ex, torque=False)
    rng = np.random.default_rng(seed)
    for eps in eps_list:
        X = simulate_planar_coloured(ex, eps, X0, T, n_paths=P, rng=rng)
        m, se = X.mean(0), X.std(0, ddof=1) / np.sqrt(P)
        sq = np.sum(X ** 2, axis=-1)
        assert np.all(np.abs(m - mean_lim) < 4 * se + 0.02), (eps, m, mean_lim, se)
        assert np.all(np.abs(m - mean_no) > 8 * se), (eps, m, mean_no, se)
        assert abs(sq.mean() - sq_lim) < 4 * sq.std(ddof=1) / np.sqrt(P) + 0.1


def test_planar_reduced():
    _check((0.2, 0.1), 2000, 3)


@pytest.mark.slow
def test_planar_full():
    _check((0.2, 0.1, 0.05, 0.025), 20000, 4)
