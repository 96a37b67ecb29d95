r"""Exact fBM sampling: the grid values have covariance ``½(s^{2H} + t^{2H} − |t − s|^{2H})``.

Claim: :func:`roughpaths.fbm` (Davies–Harte circulant embedding, and Cholesky) samples fractional Brownian
motion exactly on the grid, for every ``H ∈ (0, 1)``: the covariance of the values at grid times ``s, t``
is the closed form above (components independent), reproducibly from a seed.

Oracle: the closed-form covariance, written here; the empirical covariance of many samples must match it
within 5 standard errors (``sqrt((C_ss C_tt + C_st²)/n)`` for Gaussian samples) at every pair of a few
grid times; the circulant eigenvalues are checked non-negative independently (numpy's FFT).
"""

import numpy as np
import pytest

from roughpaths import fbm, fbm_rough_path, fgn_autocovariance


def _cov(H, s, t):
    return 0.5 * (s ** (2 * H) + t ** (2 * H) - np.abs(t - s) ** (2 * H))


@pytest.mark.parametrize("method", ["davies-harte", "cholesky"])
@pytest.mark.parametrize("H", [0.1, 0.3, 0.5, 0.75, 0.95])
def test_grid_covariance(H, method):
    n, K, T = 8000, 64, 2.0
    B = fbm(K, H, rng=np.random.default_rng(17), T=T, dim=2, batch_shape=(n // 2,), method=method)
    x = B.reshape(-1, K + 1, 2).transpose(0, 2, 1).reshape(-1, K + 1)      # n independent series
    idx = np.array([1, 7, 20, 40, 64])
    t = idx * T / K
    emp = x[:, idx].T @ x[:, idx] / x.shape[0]
    C = _cov(H, t[:, None], t[None, :])
    se = np.sqrt((np.diag(C)[:, None] * np.diag(C)[None, :] + C ** 2) / x.shape[0])
    assert np.all(np.abs(emp - C) < 5 * se), np.max(np.abs(emp - C) / se)
    # independent components
    assert abs(np.mean(B[..., -1, 0] * B[..., -1, 1])) < 5 * T ** (2 * H) / np.sqrt(n // 2)


@pytest.mark.parametrize("H", [0.05, 0.25, 0.5, 0.8, 0.99])
def test_circulant_embedding_nonnegative(H):
    K = 1000
    g = fgn_autocovariance(H, K + 1)
    row = np.concatenate([g, g[K - 1:0:-1]])
    lam = np.fft.fft(row).real
    assert lam.min() > -1e-10 * lam.max()
    k = np.arange(4.0)
    np.testing.assert_allclose(g[:4], 0.5 * (np.abs(k + 1) ** (2 * H) - 2 * k ** (2 * H) + np.abs(k - 1) ** (2 * H)))


def test_seeded_and_reproducible():
    a = fbm(100, 0.3, rng=5, dim=2, batch_shape=(3,))
    b = fbm(100, 0.3, rng=np.random.default_rng(5), dim=2, batch_shape=(3,))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, fbm(100, 0.3, rng=6, dim=2, batch_shape=(3,)))
    assert a.shape == (3, 101, 2) and np.all(a[..., 0, :] == 0)


def test_bad_input():
    with pytest.raises(ValueError, match="hurst"):
        fbm(10, 1.0, rng=0)
    with pytest.raises(TypeError, match="hurst"):
        fbm(10, "0.3", rng=0)
    with pytest.raises(TypeError, match="rng"):
        fbm(10, 0.3, rng=None)
    with pytest.raises(ValueError, match="max_bytes"):
        fbm(10 ** 6, 0.3, rng=0, batch_shape=(10 ** 4,))
    with pytest.raises(ValueError, match="method"):
        fbm(10, 0.3, rng=0, method="fft")
    with pytest.raises(ValueError, match="1/4"):
        fbm_rough_path(10, 0.25, rng=0, level=3)
    with pytest.raises(ValueError, match="level >= 3"):
        fbm_rough_path(10, 0.3, rng=0, level=2)
