"""Claim (paper eq. 2dexample): the planar system driven by coloured noise with A = αI + γJ, D = √δ I
converges, as ε → 0, to dX = (Q + N12 S)X dt + √(δ/(α²+γ²)) P(X)∘dW, where N12 = Alt(ΣA⁻ᵀ)_{12}
equals the paper's δγ/(2α(α²+γ²)), S = diag(1, −1) = [V_1, V_2], and A⁻¹D = √(δ/(α²+γ²)) R with R
a rotation (so the paper's scaling is right, W = RB).

Monte Carlo: E[X_T] of the coloured system approaches the limit's closed form
(e^{(λ+N12)T} x1, e^{(μ−N12)T} x2) — derived here by hand — and not the torque-free
(e^{λT} x1, e^{μT} x2); E|X_T|² matches the limit's second-moment ODE. The coloured system is
solved through the public path, ``roughpaths.solve(ex.vector_fields(), ex.driver(...), x0, LogODE())``,
which agrees with an independent Strang splitting written here
(e^{Qh/2} · exp(X^1E_1 + X^2E_2 + A^{12}S) · e^{Qh/2} per step, on the same driver) up to the
splitting's third-order local error.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from mechanics.limits.planar import planar_example, planar_limit_moments
from roughpaths import BrownianDriver, LogODE, Solution, solve

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
    fields = ex.vector_fields()
    for k, eps in enumerate(eps_list):
        sol = solve(fields, ex.driver(eps, T, seed=seed + 1000 * k, batch_shape=(P,)), X0, LogODE(), save_at="end")
        assert isinstance(sol, Solution) and sol.times.tolist() == [T]
        X = sol.final
        m, se = X.mean(0), X.std(0, ddof=1) / np.sqrt(P)
        sq = np.sum(X ** 2, axis=-1)
        assert np.all(np.abs(m - mean_lim) < 4 * se + 0.02), (eps, m, mean_lim, se)
        assert np.all(np.abs(m - mean_no) > 8 * se), (eps, m, mean_no, se)
        assert abs(sq.mean() - sq_lim) < 4 * sq.std(ddof=1) / np.sqrt(P) + 0.1


def _strang(ex, X, x0):
    """Naive Strang splitting on the increments and areas of a level-2 path (scipy's expm per member)."""
    E1, E2 = ex.noise_matrices
    S = np.diag([1.0, -1.0])
    x = np.tile(x0, (X.increments.shape[0], 1))
    for k, h in enumerate(np.diff(X.times)):
        half = np.exp(np.array([ex.lam, ex.mu]) * h / 2)
        for p in range(x.shape[0]):
            dx, a = X.increments[p, k], X.areas[p, k]
            G = dx[0] * E1 + dx[1] * E2 + 0.5 * (a[0, 1] - a[1, 0]) * S
            x[p] = half * (sla.expm(G) @ (half * x[p]))
    return x


def test_solve_agrees_with_strang_splitting():
    ex = planar_example(**PARAMS)
    gaps = []
    for eps in (0.2, 0.1):
        drv = ex.driver(eps, 0.5, seed=7, batch_shape=(8,))
        got = solve(ex.vector_fields(), drv, X0, LogODE(), save_at="end").final
        ref = _strang(ex, drv.rough_path(), X0)
        gaps.append(np.max(np.abs(got - ref)) / np.max(np.abs(ref)))
    assert gaps[0] < 2e-3 and gaps[1] < gaps[0] / 4, gaps     # third-order local error: gap ~ h^(3/2..2)


def test_driver_grid_and_limit_fields():
    ex = planar_example(**PARAMS)
    drv = ex.driver(0.1, 1.0, seed=0, batch_shape=(3,))
    h = 0.1 ** 2 / (2 * np.linalg.norm(ex.A, 2))
    assert drv.times[-1] == 1.0 and np.isclose(drv.times[1], 1.0 / round(1.0 / h)) and drv.dim == 2
    M = np.linalg.solve(ex.A, ex.D)                                   # A⁻¹D, by hand
    V1 = np.array([[0.0, 0.0], [1.0, 0.0]])                           # V_1(x) = (0, x_1)
    V2 = np.array([[0.0, 1.0], [0.0, 0.0]])                           # V_2(x) = (x_2, 0)
    lim_fields = ex.limit_vector_fields()
    for k in range(2):
        np.testing.assert_allclose(lim_fields.matrices[k], M[0, k] * V1 + M[1, k] * V2, atol=1e-14)
    n12 = PARAMS["delta"] * PARAMS["gamma"] / (2 * PARAMS["alpha"] * (PARAMS["alpha"] ** 2 + PARAMS["gamma"] ** 2))
    np.testing.assert_allclose(lim_fields.drift_matrix, np.diag([PARAMS["lam"] + n12, PARAMS["mu"] - n12]),
                               atol=1e-14)
    np.testing.assert_array_equal(ex.limit_vector_fields(torque=False).drift_matrix,
                                  np.diag([PARAMS["lam"], PARAMS["mu"]]))
    np.testing.assert_array_equal(ex.vector_fields().matrices, [V1, V2])
    # the limit is driven by B: E[X_T] of the limit's solve matches the closed form (coarse Monte Carlo)
    lim = solve(ex.limit_vector_fields(), BrownianDriver(2, seed=1, dt=1 / 64, n_steps=64, batch_shape=(4000,)),
                X0, LogODE(), save_at="end").final
    mean, _ = _hand_limit(ex)
    se = lim.std(0, ddof=1) / np.sqrt(lim.shape[0])
    assert np.all(np.abs(lim.mean(0) - mean) < 4 * se + 0.01), (lim.mean(0), mean, se)
    with pytest.raises(ValueError, match="eps"):
        ex.driver(-0.1, 1.0, seed=0)
    with pytest.raises(TypeError, match="seed"):
        ex.driver(0.1, 1.0, seed=np.random.default_rng(0))
    with pytest.raises(ValueError, match="T"):
        ex.driver(0.1, -1.0, seed=0)
    with pytest.raises(TypeError, match="torque"):
        planar_limit_moments(ex, X0, T, torque="yes")


def test_planar_reduced():
    _check((0.2, 0.1), 2000, 3)


@pytest.mark.slow
def test_planar_full():
    _check((0.2, 0.1, 0.05, 0.025), 20000, 4)
