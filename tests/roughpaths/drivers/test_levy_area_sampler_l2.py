r"""Strong L² error of the Lévy-area sampler (``roughpaths.drivers.brownian``).

Claims tested:

* the vectorised reference used below (Chen sum of the substep conditional means
  :math:`H_k\otimes w_k - w_k\otimes H_k` plus :math:`\mathrm{Alt}\sum_{k<l} w_k\otimes w_l`) equals a
  naive loop;
* that conditional mean is the Lévy area of the polynomial :math:`u\mapsto u w + 6u(1-u)H`
  (checked with ``iisignature`` on a fine polygon);
* coupled to a much finer sample of the same Brownian path (``M`` substeps), the ``m``-substep
  approximation has per-component L² error :math:`h\sqrt{(1/m - 1/M)/12}` (i.e. ``h/sqrt(12 m)``
  against the true area), fitted order ``-1/2`` in ``m``; dropping the cross term fails;
* the public sampler's variances: ``foster`` gives :math:`h^2/4 - h^2/(12m)`, ``davie`` :math:`h^2/4`.
(The draw order and the kernel against a naive per-step reimplementation:
``tests/roughpaths/drivers/test_brownian_driver_stream.py``.)
"""

import iisignature
import numpy as np
import pytest

from roughpaths import brownian_increments_and_areas


def _levy_area_from_substeps(w, H):
    """Chen-summed conditional-mean Lévy area ``(..., d, d)`` of one step from its substeps ``w, H (..., m, d)``."""
    s_excl = np.cumsum(w, axis=-2) - w
    g = np.matmul(np.swapaxes(H + 0.5 * s_excl, -1, -2), w)
    return g - np.swapaxes(g, -1, -2)


def _naive(w, H):
    m, d = w.shape
    A, pos = np.zeros((d, d)), np.zeros(d)
    for k in range(m):
        A += np.outer(H[k], w[k]) - np.outer(w[k], H[k]) + 0.5 * (np.outer(pos, w[k]) - np.outer(w[k], pos))
        pos = pos + w[k]
    return A


def test_kernel_matches_naive_chen_sum():
    rng = np.random.default_rng(0)
    w, H = rng.standard_normal((5, 7, 3)), rng.standard_normal((5, 7, 3))
    A = _levy_area_from_substeps(w, H)
    for i in range(5):
        np.testing.assert_allclose(A[i], _naive(w[i], H[i]), atol=1e-13)


def test_conditional_mean_is_area_of_polynomial_path():
    w, H = np.array([0.7, -0.3]), np.array([0.2, 0.5])
    u = np.linspace(0, 1, 4001)[:, None]
    path = u * w + 6 * u * (1 - u) * H
    s = iisignature.sig(path, 2)[2:].reshape(2, 2)
    levy = 0.5 * (s - s.T)
    np.testing.assert_allclose(levy, _levy_area_from_substeps(w[None], H[None]), atol=1e-6)


def _aggregate(w, H, k):
    """Merge groups of k substeps: increments add; H from the time integral I = δ(H + w/2) by Chen."""
    n, M, d = w.shape
    wg, Hg = w.reshape(n, M // k, k, d), H.reshape(n, M // k, k, d)
    delta = 1.0 / M
    pos = np.cumsum(wg, axis=2) - wg
    integral = (delta * (Hg + 0.5 * wg) + delta * pos).sum(axis=2)     # ∫ (W_r - W_start) dr
    W = wg.sum(axis=2)
    return W, integral / (k * delta) - 0.5 * W


def test_coupled_strong_error_rate_and_constant():
    n, M, d, h = 4000, 256, 2, 1.0
    rng = np.random.default_rng(1)
    w = rng.standard_normal((n, M, d)) * np.sqrt(h / M)
    H = rng.standard_normal((n, M, d)) * np.sqrt(h / M / 12)
    ref = _levy_area_from_substeps(w, H)[:, 0, 1]
    ms, errs = [1, 2, 4, 8, 16, 32], []
    for m in ms:
        W, Hm = _aggregate(w, H, M // m)
        err = np.sqrt(np.mean((_levy_area_from_substeps(W, Hm)[:, 0, 1] - ref) ** 2))
        errs.append(err)
        assert abs(err / (h * np.sqrt((1 / m - 1 / M) / 12)) - 1) < 0.06
    slope = np.polyfit(np.log(ms), np.log(np.array(errs) ** 2 + h * h / (12 * M)), 1)[0] / 2
    assert abs(slope + 0.5) < 0.05
    # wrong variant: no Chen cross term between substeps -> error does not decrease like this
    W, Hm = _aggregate(w, H, M // 8)
    no_cross = (Hm[:, :, 0] * W[:, :, 1] - W[:, :, 0] * Hm[:, :, 1]).sum(axis=1)
    err = np.sqrt(np.mean((no_cross - ref) ** 2))
    assert err > 3 * h * np.sqrt(1 / 8 / 12)


@pytest.mark.parametrize("m", [1, 4])
def test_public_sampler_variances(m):
    h, n = 0.6, 80000
    out = {}
    for method in ("foster", "davie"):
        _, XX = brownian_increments_and_areas(np.random.default_rng(2), 1, h, 2, batch_shape=(n,),
                                              levy_area=method, substeps=m)
        a = 0.5 * (XX - np.swapaxes(XX, -1, -2))[:, 0, 0, 1]
        out[method] = (np.mean(a * a), np.std(a * a) / np.sqrt(n))
    v, se = out["foster"]
    assert abs(v - (h * h / 4 - h * h / (12 * m))) < 5 * se
    v, se = out["davie"]
    assert abs(v - h * h / 4) < 5 * se
