"""Claim: the lift of B^ε = ∫ y/ε dt converges to (A⁻¹D B, A⁻¹D BB^{Strat} (A⁻¹D)ᵀ + N(t−s)).

* ``E[XX^ε_{t,t+w}]/w → ΣA⁻ᵀ`` (Monte Carlo against the exact finite-ε value
  ``ΣA⁻ᵀ − (ε²/w)ΣA⁻ᵀA⁻ᵀ(I − e^{−Aᵀw/ε²})``); its antisymmetric part tends to
  ``N = Alt(ΣA⁻ᵀ)`` and **not** to the paper's ``2N`` (nor to ``−N``); its symmetric part is ``½MMᵀ``.
* The trace: ``sup_t |B^ε_t − A⁻¹D B_t| → 0`` at rate ε when coupled through the same ``B``, both
  for the library's sampler and for a naive Euler–Maruyama simulation written here.
* The paper's example ``A = kI + Λ`` (``Λ13 = 1 = −Λ31``), ``D = I``: ``Σ = I/(2k)``, the printed
  ``A⁻¹D``, ``N13 = 1/(2k(1+k²))`` and the paper's "s13 ≈ 19.95" = ``2N13`` at ``k = 0.05``.
* The lift's own bias (sub-step area) is below 10⁻³ of ``N`` at the default resolution.
"""

import numpy as np
import pytest
import scipy.linalg as sla

from roughpaths import (coloured_noise_limit, coloured_noise_limit_path, lift_area_rate,
                                       paper_coloured_noise_matrices, sample_coloured_noise)

A2 = np.array([[1.0, 2.0], [-0.5, 1.5]])
D2 = np.array([[1.0, 0.0], [0.3, 0.8]])


def _exact_window_rate(A, D, eps, w):
    """Independent closed form: Σ from the Kronecker form (I⊗A + A⊗I) vec Σ = vec DDᵀ, then the window formula."""
    n = len(A)
    Sigma = np.linalg.solve(np.kron(np.eye(n), A) + np.kron(A, np.eye(n)), (D @ D.T).reshape(-1)).reshape(n, n)
    AiT = np.linalg.inv(A).T
    return Sigma @ AiT - (eps ** 2 / w) * Sigma @ AiT @ AiT @ (np.eye(len(A)) - sla.expm(-A.T * w / eps ** 2))


def test_paper_example_closed_forms():
    k = 0.05
    A, D = paper_coloured_noise_matrices(k)
    assert A[0, 2] == 1.0 and A[2, 0] == -1.0
    lim = coloured_noise_limit(A, D)
    assert np.allclose(lim.Sigma, np.eye(3) / (2 * k), rtol=1e-10)
    printed = np.array([[k / (k * k + 1), 0, -1 / (k * k + 1)], [0, 1 / k, 0], [1 / (k * k + 1), 0, k / (k * k + 1)]])
    assert np.allclose(lim.scaling, printed, rtol=1e-12)
    N13 = 1 / (2 * k * (1 + k * k))
    assert np.isclose(lim.N[0, 2], N13) and np.isclose(lim.N[2, 0], -N13)
    assert abs(lim.N[0, 1]) < 1e-12 and abs(lim.N[1, 2]) < 1e-12
    assert np.isclose(lim.unnormalised_area_rate[0, 2], 19.95, atol=5e-3)     # the paper's "s13"
    assert np.allclose(lim.N, -(1 / k) * 0.5 * (np.linalg.inv(A) - np.linalg.inv(A).T) / 2)


@pytest.mark.parametrize("seed", range(4))
def test_symmetric_part_is_half_MMt(seed):
    g = np.random.default_rng(seed)
    A = g.normal(size=(3, 3)) + 3 * np.eye(3)
    D = g.normal(size=(3, 2))
    D = np.concatenate([D, g.normal(size=(3, 1))], axis=1)
    lim = coloured_noise_limit(A, D)
    R = lim.area_rate
    assert np.allclose(0.5 * (R + R.T), 0.5 * lim.M @ lim.M.T, atol=1e-12)
    assert np.allclose(lim.N, 0.5 * (lim.Sigma @ np.linalg.inv(A).T - np.linalg.inv(A) @ lim.Sigma), atol=1e-12)
    assert np.allclose(A @ lim.Sigma + lim.Sigma @ A.T, D @ D.T, atol=1e-12)


def test_lift_bias_small_at_default_resolution():
    for A, D in [(A2, D2), paper_coloured_noise_matrices(0.05)]:
        lim = coloured_noise_limit(A, D)
        delta = 0.5 / np.linalg.norm(A, 2)
        for herm, tol in [(True, 1e-3), (False, 5e-2)]:
            r = lift_area_rate(A, D, delta, hermite=herm)
            rel = np.max(np.abs(0.5 * (r - r.T) - lim.N)) / np.max(np.abs(lim.N))
            assert rel < tol
        r = lift_area_rate(A, D, delta, hermite=False)
        assert np.max(np.abs(0.5 * (r - r.T) - lim.N)) / np.max(np.abs(lim.N)) > 1e-3   # the chord is worse


def _area_rate_mc(A, D, eps, h, T, P, rng):
    s = sample_coloured_noise(A, D, eps, np.linspace(0, T, int(round(T / h)) + 1), rng=rng, batch_shape=(P,))
    per_path = s.path.areas.mean(axis=1) / h                       # time-averaged area per path
    return per_path.mean(0), per_path.std(0, ddof=1) / np.sqrt(P)


def test_area_rate_monte_carlo(rng):
    h, T, P = 0.1, 1.0, 2000
    lim = coloured_noise_limit(A2, D2)
    N = lim.N
    devs = []
    for eps in (0.2, 0.1, 0.05):
        est, se = _area_rate_mc(A2, D2, eps, h, T, P, rng)
        exact = _exact_window_rate(A2, D2, eps, h)
        z = np.abs(est - exact) / se
        assert np.max(z) < 4.5, (eps, est, exact, se)
        lev = 0.5 * (est[0, 1] - est[1, 0])
        se_lev = 0.5 * np.hypot(se[0, 1], se[1, 0])        # conservative
        devs.append((eps, lev, se_lev))
    eps, lev, se_lev = devs[-1]
    bias = abs(0.5 * (_exact_window_rate(A2, D2, eps, h) - _exact_window_rate(A2, D2, eps, h).T)[0, 1] - N[0, 1])
    assert abs(lev - N[0, 1]) < 4 * se_lev + bias
    for wrong in (2 * N[0, 1], -N[0, 1], 0.0):                     # the paper's 2N, the sign flip, no anomaly
        assert abs(lev - wrong) > 8 * se_lev
    # the finite-eps deficit shrinks towards N as eps -> 0
    assert abs(devs[0][1] - N[0, 1]) > abs(devs[-1][1] - N[0, 1])


def test_trace_coupled_sampler(rng):
    lim = coloured_noise_limit(A2, D2)
    errs = []
    eps_list = (0.1, 0.05, 0.025)
    for eps in eps_list:
        s = sample_coloured_noise(A2, D2, eps, np.linspace(0, 1.0, 101), rng=rng, batch_shape=(200,))
        d = s.path.path - s.brownian.path @ lim.M.T
        errs.append(np.mean(np.max(np.abs(d), axis=(-1, -2))))
    slope = np.polyfit(np.log(eps_list), np.log(errs), 1)[0]
    assert 0.8 < slope < 1.2, (slope, errs)


def test_trace_naive_euler_maruyama(rng):
    """Independent oracle: y by Euler–Maruyama on a grid dt = ε²/40, B^ε by the trapezoid rule."""
    M = np.linalg.solve(A2, D2)
    errs = []
    eps_list = (0.2, 0.1, 0.05)
    for eps in eps_list:
        dt = eps ** 2 / 40
        n = int(round(0.5 / dt))
        P = 100
        y = np.zeros((P, 2))
        Be = np.zeros((P, 2))
        B = np.zeros((P, 2))
        worst = np.zeros(P)
        for _ in range(n):
            dB = rng.normal(scale=np.sqrt(dt), size=(P, 2))
            y_new = y - dt / eps ** 2 * y @ A2.T + dB @ D2.T / eps
            Be += 0.5 * dt * (y + y_new) / eps
            B += dB
            y = y_new
            worst = np.maximum(worst, np.max(np.abs(Be - B @ M.T), axis=-1))
        errs.append(worst.mean())
    slope = np.polyfit(np.log(eps_list), np.log(errs), 1)[0]
    assert 0.7 < slope < 1.3, (slope, errs)


def test_limit_path_is_scaled_brownian_plus_N(rng):
    s = sample_coloured_noise(A2, D2, 0.1, np.linspace(0, 1, 11), rng=rng, batch_shape=(3,))
    L = s.limit_path()
    lim = s.limit
    assert L.kind == "geometric" and L.dim == 2
    assert np.allclose(L.increments, s.brownian.increments @ lim.M.T)
    base = lim.M @ s.brownian.areas @ lim.M.T
    assert np.allclose(L.areas - base, lim.N * 0.1)
    with pytest.raises(ValueError, match="dimension"):
        coloured_noise_limit_path(lim, s.path.to_level1().__class__(np.zeros((1, 3)), np.zeros((1, 3, 3))))
