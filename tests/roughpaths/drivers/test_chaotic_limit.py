"""Green–Kubo estimates, the exact cat-map correlations and the perturbed limit (roughpaths.drivers.chaotic_limit).

Claims: ``SineObservable.correlations`` equals a grid quadrature of ``∫ v ⊗ v∘T^m`` (an independent oracle);
``green_kubo`` recovers the closed-form ``C(m)``, ``E`` and ``Σ`` of a moving-average process and of the cat-map
example within its standard errors, and those standard errors are calibrated; ``chaotic_limit_path`` is
``(M B, M BB Mᵀ + Alt(E) dt)``; bad input is refused, naming the argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from roughpaths import (SineObservable, brownian_rough_path, cat_map, chaotic_limit, chaotic_limit_path, green_kubo,
                        observable_orbits)

A = np.array([[2, 1], [1, 1]])
K, Q = np.array([1, 0]), np.array([0, 1])
# v¹ = sin 2πk·y + ½ sin 2πA²q·y,  v² = sin 2πAk·y + sin 2πq·y:  C²¹(1) = ½, C¹²(2) = ¼
EXAMPLE = SineObservable([[K, A @ A @ Q], [A @ K, Q]], [[1.0, 0.5], [1.0, 1.0]])


def _grid_average(f, g, m, N=256):
    """∫ f(y) g(A^m y mod 1) dy by the average over the N×N grid (A maps the grid onto itself)."""
    t = np.arange(N) / N
    y = np.stack(np.meshgrid(t, t, indexing="ij"), axis=-1).reshape(-1, 2)
    z = y.copy()
    for _ in range(m):
        z = (z @ A.T) % 1.0
    return np.einsum("pa,pb->ab", f(y), g(z)) / y.shape[0]


def test_sine_correlations_against_quadrature():
    C = EXAMPLE.correlations(6)
    for m in range(5):                     # frequencies up to |(Aᵀ)^4 (3, 2)| = 144 < 256: no aliasing
        np.testing.assert_allclose(C[m], _grid_average(EXAMPLE, EXAMPLE, m), atol=1e-12)
    assert np.all(C[3:] == 0.0)
    np.testing.assert_array_equal(C[0], np.diag([0.625, 1.0]))
    np.testing.assert_array_equal(C[1], [[0.0, 0.0], [0.5, 0.0]])
    np.testing.assert_array_equal(C[2], [[0.0, 0.25], [0.0, 0.0]])
    # a minus sign: v = sin 2π(−Ak)·y is −(v¹∘T)'s first term, C(1) = −½ for that pair
    w = SineObservable([[K], [-(A @ K)]], [[1.0], [1.0]])
    np.testing.assert_allclose(w.correlations(2)[1], _grid_average(w, w, 1), atol=1e-12)
    assert w.correlations(2)[1][1, 0] == -0.5


def test_green_kubo_moving_average_closed_form_and_calibrated_errors():
    # v_j = g_j + Φ g_{j−1}: C(0) = I + ΦΦᵀ, C(1) = Φᵀ... as E[v_0 v_1ᵀ] = E[(g_0 + Φ g_{−1}) (g_1 + Φ g_0)ᵀ] = Φᵀ
    Phi = np.array([[0.3, 0.8], [-0.4, 0.1]])
    E_true = Phi.T
    S_true = np.eye(2) + Phi @ Phi.T + Phi + Phi.T
    rng = np.random.default_rng(5)
    z = []
    for _ in range(30):
        g = rng.standard_normal((40, 801, 2))
        v = g[:, 1:] + g[:, :-1] @ Phi.T
        est = green_kubo(v, 4)
        z.append(np.concatenate([((est.E - E_true) / est.E_se).ravel(), ((est.Sigma - S_true) / est.Sigma_se).ravel()]))
        np.testing.assert_allclose(est.correlations[2:], 0.0, atol=6 * est.correlations_se[2:].max())
    z = np.array(z)
    assert np.all(np.abs(z) < 5)
    # the standard errors are honest: the standardised errors have spread ~1 (30 repetitions x 8 entries)
    assert 0.75 < z.std() < 1.3, z.std()


def test_centring_check_is_calibrated_for_few_orbits():
    """A centred observable is never refused, whatever the number of orbits: with 2 orbits the mean over its
    standard error is Student-t with 1 degree of freedom (beyond 6 about 10 % of the time; a fixed 6-SE rule
    refused the Lorenz groups of the main job's tiny run)."""
    rng = np.random.default_rng(9)
    ratios = []
    for _ in range(300):
        v = rng.standard_normal((2, 200, 1))
        m = v.mean(axis=1)[:, 0]
        ratios.append(abs(m.mean()) / (m.std(ddof=1) / math.sqrt(2)))
        green_kubo(v, 3)                                              # never refused
    assert np.mean(np.array(ratios) > 6) > 0.03                       # the old rule would have refused these


def test_green_kubo_on_the_cat_map_matches_the_closed_form():
    C = EXAMPLE.correlations(8)
    E, S = C[1:].sum(axis=0), C[0] + 2 * 0.0 + C[1:].sum(axis=0) + C[1:].sum(axis=0).T
    vals = observable_orbits(cat_map(), EXAMPLE, 4000, seed=3, batch_shape=(64,))
    est = green_kubo(vals, 8)
    assert np.all(np.abs(est.E - E) < 4 * est.E_se), (est.E, E, est.E_se)
    assert np.all(np.abs(est.Sigma - S) < 4 * est.Sigma_se)
    assert np.all(np.abs(est.correlations - C) < 5 * est.correlations_se)
    assert np.all(np.abs(est.tail) < 5 * est.tail_se)              # lags 5..8 carry nothing here
    assert abs(est.E[1, 0] - est.E[0, 1]) > 10 * max(est.E_se[1, 0], est.E_se[0, 1])   # Alt(E) ≠ 0
    lim = est.limit()
    np.testing.assert_allclose(lim.levy_perturbation, [[0, -0.125], [0.125, 0]], atol=4 * est.E_se.max())


def test_limit_and_limit_path():
    Sigma = np.array([[0.625, 0.75], [0.75, 1.0]])
    E = np.array([[0.0, 0.25], [0.5, 0.0]])
    lim = chaotic_limit(Sigma, E)
    np.testing.assert_allclose(lim.scaling @ lim.scaling.T, Sigma, atol=1e-14)
    np.testing.assert_allclose(lim.levy_perturbation, [[0.0, -0.125], [0.125, 0.0]], atol=0)
    np.testing.assert_allclose(lim.area_rate, 0.5 * Sigma + lim.levy_perturbation)
    B = brownian_rough_path(np.linspace(0, 2, 41), 2, np.random.default_rng(1), batch_shape=(6,))
    X = chaotic_limit_path(lim, B)
    M = lim.scaling
    np.testing.assert_allclose(X.increments, B.increments @ M.T, atol=1e-14)
    want = np.einsum("ia,pkab,jb->pkij", M, B.areas, M) + lim.levy_perturbation * 0.05
    np.testing.assert_allclose(X.areas, want, atol=1e-14)
    assert X.kind == "geometric"
    # a singular Σ (a coboundary direction) is a valid limit: one Brownian direction, the area drift stays
    sing = chaotic_limit(np.ones((2, 2)), E)
    np.testing.assert_allclose(sing.scaling @ sing.scaling, np.ones((2, 2)), atol=1e-14)


def test_bad_input_is_refused_with_the_fix():
    E = np.zeros((2, 2))
    with pytest.raises(ValueError, match="positive semi-definite"):
        chaotic_limit(np.diag([1.0, -0.1]), E)
    with pytest.raises(ValueError, match="symmetric"):
        chaotic_limit(np.array([[1.0, 0.5], [0.0, 1.0]]), E)
    with pytest.raises(ValueError, match="E must have the shape of Sigma"):
        chaotic_limit(np.eye(2), np.zeros((3, 3)))
    lim = chaotic_limit(np.eye(2), E)
    B = brownian_rough_path(np.linspace(0, 1, 5), 2, np.random.default_rng(0))
    with pytest.raises(ValueError, match="geometric"):
        chaotic_limit_path(lim, brownian_rough_path(np.linspace(0, 1, 5), 2, np.random.default_rng(0), kind="ito"))
    with pytest.raises(ValueError, match="dimension 3"):
        chaotic_limit_path(lim, brownian_rough_path(np.linspace(0, 1, 5), 3, np.random.default_rng(0)))
    with pytest.raises(TypeError, match="ChaoticLimit"):
        chaotic_limit_path((np.eye(2), E), B)
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="at least 2 independent orbits"):
        green_kubo(rng.standard_normal((1, 100, 2)), 3)
    with pytest.raises(ValueError, match="max_lag must be smaller"):
        green_kubo(rng.standard_normal((4, 10, 2)), 10)
    with pytest.raises(ValueError, match="not centred"):
        green_kubo(1.0 + rng.standard_normal((8, 500, 2)), 3)
    with pytest.raises(ValueError, match="non-zero vectors"):
        SineObservable([[[0, 0]]], [[1.0]])
    with pytest.raises(ValueError, match="coefficients must have shape"):
        SineObservable([[[1, 0]]], [[1.0, 2.0]])
    assert math.isfinite(green_kubo(rng.standard_normal((4, 50, 1)), 2).E[0, 0])


def test_empty_dimensions_wrong_coordinates_and_unestimated_sizes_are_refused(monkeypatch):
    # were bare numpy errors: a (0, 0) Sigma ('zero-size array to reduction operation maximum'), values with no
    # component ('cannot reshape array of size 0'), coordinates without the last axis of length 2 (matmul)
    with pytest.raises(ValueError, match="Sigma must be .* d >= 1"):
        chaotic_limit(np.zeros((0, 0)), np.zeros((0, 0)))
    with pytest.raises(ValueError, match=r"values must have at least one component"):
        green_kubo(np.zeros((3, 10, 0)), 2)
    with pytest.raises(ValueError, match=r"y must have shape \(\.\.\., 2\)"):
        EXAMPLE(np.zeros((5, 3)))
    with pytest.raises(ValueError, match=r"y must have shape \(\.\.\., 2\)"):
        EXAMPLE(0.5)
    # the correlations C (P, M + 1, d, d) of green_kubo, d times the values, and the (M + 1, d, d) of the exact
    # correlations were allocated without an estimate
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(5 * 10**6))
    v = np.random.default_rng(0).standard_normal((2000, 100, 2))     # 3.2 MB; C alone is 6.4 MB
    with pytest.raises(ValueError, match="correlations .* memory budget"):
        green_kubo(v, 99)
    wide = SineObservable(np.ones((200, 1, 2), dtype=np.int64), np.ones((200, 1)))
    with pytest.raises(ValueError, match="correlations .* memory budget"):
        wide.correlations(100)
