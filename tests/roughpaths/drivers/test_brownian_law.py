r"""Law of the Brownian rough path sampler (``roughpaths.drivers.brownian``).

Claims tested:

* increments are independent :math:`N(0, h I)` on any (non-uniform) grid;
* Lévy areas (with the ½): :math:`E[A_{ij}] = 0`, :math:`\mathrm{Var}(A_{12}) = h^2/4`, components
  uncorrelated with each other and with the increments, and the conditional variance
  :math:`\mathrm{Var}(A_{12}\mid W) = h^2/12 + h(W_1^2 + W_2^2)/12`, checked through
  :math:`E[A_{12}^2 W_1^2] = 5h^3/12`;
* d = 2: the Lévy area :math:`A = \tfrac12\int(x\,dy - y\,dx)` over ``[0, t]`` has characteristic
  function :math:`1/\cosh(\lambda t/2)`, density :math:`\mathrm{sech}(\pi x/t)/t`, CDF
  :math:`(2/\pi)\arctan(e^{\pi x/t})` (formulas verified here by quadrature), and the sampler passes
  a Kolmogorov–Smirnov test against it, while the area without the ½ fails;
* seeds reproduce exactly, and bad input raises ``TypeError``/``ValueError`` naming the argument.
"""

import numpy as np
import pytest
from scipy import integrate, stats

from roughpaths import brownian_increments_and_areas, brownian_rough_path


def _levy(XX):
    return 0.5 * (XX - np.swapaxes(XX, -1, -2))


def _within(est, target, se, k=5.0):
    return abs(est - target) <= k * se


# ----------------------------------------------------------------------------- increments
def test_increments_mean_and_covariance_on_nonuniform_grid():
    times = np.array([0.0, 0.05, 0.3, 0.31, 1.0])
    X = brownian_rough_path(times, 3, np.random.default_rng(11), batch_shape=(40000,), levy_area=None)
    assert X.level == 1
    inc = X.increments                                   # (n, 4, 3)
    n = inc.shape[0]
    h = np.diff(times)
    for k in range(4):
        z = inc[:, k, :]
        assert np.all(np.abs(z.mean(0)) <= 5 * np.sqrt(h[k] / n))
        cov = z.T @ z / n
        se = h[k] * np.sqrt(2.0 / n)
        assert np.all(np.abs(np.diag(cov) - h[k]) <= 5 * se)
        off = cov[~np.eye(3, dtype=bool)]
        assert np.all(np.abs(off) <= 5 * h[k] / np.sqrt(n))
        # the wrong variant "variance h^2" is rejected by the same test
        assert not np.all(np.abs(np.diag(cov) - h[k] ** 2) <= 5 * se)
    # independence across steps
    c01 = np.mean(inc[:, 0, 0] * inc[:, 1, 0])
    assert abs(c01) <= 5 * np.sqrt(h[0] * h[1] / n)


# ----------------------------------------------------------------------------- Lévy area moments
@pytest.mark.parametrize("d", [2, 4])
def test_levy_area_second_moments(d):
    h, n = 0.5, 100000
    dW, XX = brownian_increments_and_areas(np.random.default_rng(5), 1, h, d, batch_shape=(n,))
    A, W = _levy(XX)[:, 0], dW[:, 0]
    a12 = A[:, 0, 1]
    assert _within(a12.mean(), 0.0, a12.std() / np.sqrt(n))
    se_var = np.std(a12 ** 2) / np.sqrt(n)
    assert _within(np.mean(a12 ** 2), h * h / 4, se_var)
    # wrong variants fail: the paper's area without the ½ (variance h²), or the variance h²/2
    assert not _within(np.mean((2 * a12) ** 2), h * h / 4, 4 * se_var)
    assert not _within(np.mean(a12 ** 2), h * h / 2, se_var)
    # conditional variance given W: E[A12² W1²] = E[(h²/12 + h(W1²+W2²)/12) W1²] = 5h³/12
    prod = a12 ** 2 * W[:, 0] ** 2
    assert _within(prod.mean(), 5 * h ** 3 / 12, prod.std() / np.sqrt(n))
    # uncorrelated with the increments at second and third order
    for f in (a12 * W[:, 0], a12 * W[:, 0] * W[:, 1]):
        assert _within(f.mean(), 0.0, f.std() / np.sqrt(n))
    if d > 2:
        for f in (a12 * A[:, 0, 2], a12 * A[:, 2, 3], A[:, 1, 3] * A[:, 2, 3]):
            assert _within(f.mean(), 0.0, f.std() / np.sqrt(n))
        assert _within(np.mean(A[:, 2, 3] ** 2), h * h / 4, se_var * 1.5)


def test_areas_are_geometric_and_antisymmetric_part_has_zero_diagonal():
    dW, XX = brownian_increments_and_areas(np.random.default_rng(1), 7, 0.1, 3, batch_shape=(2, 5))
    assert dW.shape == (2, 5, 7, 3) and XX.shape == (2, 5, 7, 3, 3)
    sym = 0.5 * (XX + np.swapaxes(XX, -1, -2))
    np.testing.assert_allclose(sym, 0.5 * dW[..., :, None] * dW[..., None, :], atol=1e-15)


# ----------------------------------------------------------------------------- d = 2 law
def _levy_cdf(x, t):
    return (2 / np.pi) * np.arctan(np.exp(np.pi * x / t))


def _levy_pdf(x, t):
    e = np.exp(-np.abs(np.pi * np.asarray(x) / t))
    return 2 * e / (1 + e * e) / t                      # sech(πx/t)/t without overflow


def test_levy_law_formulas_are_consistent():
    t = 0.7
    mass = integrate.quad(_levy_pdf, -np.inf, np.inf, args=(t,))[0]
    var = integrate.quad(lambda x: x * x * _levy_pdf(x, t), -np.inf, np.inf)[0]
    assert abs(mass - 1) < 1e-9 and abs(var - t * t / 4) < 1e-9
    for lam in (0.5, 2.0, 7.0):       # characteristic function 1 / cosh(λ t / 2)
        cf = integrate.quad(lambda x: np.cos(lam * x) * _levy_pdf(x, t), -np.inf, np.inf, limit=200)[0]
        assert abs(cf - 1 / np.cosh(lam * t / 2)) < 1e-7
    x = np.linspace(-2, 2, 9)
    eps = 1e-6
    np.testing.assert_allclose((_levy_cdf(x + eps, t) - _levy_cdf(x - eps, t)) / (2 * eps), _levy_pdf(x, t), rtol=1e-6)
    assert abs(_levy_cdf(0.0, t) - 0.5) < 1e-15


def test_kolmogorov_smirnov_d2_levy_area():
    t, n = 0.7, 40000
    X = brownian_rough_path([0.0, 0.2, t], 2, np.random.default_rng(2024), batch_shape=(n,))
    a = X.levy_area(0.0, t)[:, 0, 1]             # Chen over two steps: tests the grid law too
    assert stats.kstest(a, _levy_cdf, args=(t,)).pvalue > 1e-3
    assert stats.kstest(-a, _levy_cdf, args=(t,)).pvalue > 1e-3
    # wrong variants fail: no ½, or a Gaussian with the right variance
    assert stats.kstest(2 * a, _levy_cdf, args=(t,)).pvalue < 1e-6
    g = np.random.default_rng(3).standard_normal(n) * t / 2
    assert stats.kstest(g, _levy_cdf, args=(t,)).pvalue < 1e-6


@pytest.mark.slow
def test_kolmogorov_smirnov_d2_levy_area_large():
    """At 4e5 samples the exact d = 2 sampler passes, and Davie's one-step area (exact second moments
    only, the documented default) is rejected: the test has the power to see the approximation."""
    t, n = 1.3, 400000
    dW, XX = brownian_increments_and_areas(np.random.default_rng(77), 1, t, 2, batch_shape=(n,),
                                           levy_area="exact")
    a = _levy(XX)[:, 0, 0, 1]
    assert stats.kstest(a, _levy_cdf, args=(t,)).pvalue > 1e-3
    dW, XX = brownian_increments_and_areas(np.random.default_rng(77), 1, t, 2, batch_shape=(n,),
                                           levy_area="davie")
    assert stats.kstest(_levy(XX)[:, 0, 0, 1], _levy_cdf, args=(t,)).pvalue < 1e-6


# ----------------------------------------------------------------------------- reproducibility
def test_seeds_reproduce_exactly_and_increments_do_not_depend_on_area_options():
    kw = dict(batch_shape=(3,))
    a = brownian_increments_and_areas(np.random.default_rng(9), 6, 0.2, 3, **kw)
    b = brownian_increments_and_areas(np.random.default_rng(9), 6, 0.2, 3, **kw)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    c = brownian_increments_and_areas(np.random.default_rng(10), 6, 0.2, 3, **kw)
    assert not np.array_equal(a[0], c[0])
    for opts in (dict(levy_area=None), dict(levy_area="foster", substeps=3), dict(kind="ito")):
        d = brownian_increments_and_areas(np.random.default_rng(9), 6, 0.2, 3, **kw, **opts)
        assert np.array_equal(a[0], d[0])
    X = brownian_rough_path(np.linspace(0, 1.2, 7), 3, np.random.default_rng(9), **kw)
    np.testing.assert_allclose(X.increments, a[0], rtol=1e-14)   # linspace steps differ from 0.2 by ulps
    np.testing.assert_allclose(X.areas, a[1], rtol=1e-12, atol=1e-15)


def test_array_dt_matches_scalar_dt():
    a = brownian_increments_and_areas(np.random.default_rng(4), 3, 0.25, 2)
    b = brownian_increments_and_areas(np.random.default_rng(4), 3, [0.25, 0.25, 0.25], 2)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_small_blocks_sample_the_same_law():
    from roughpaths import BrownianDriver
    h, n = 0.3, 30000
    drv = BrownianDriver(2, seed=6, dt=h, n_steps=2, batch_shape=(n // 2,), block_bytes=1000)   # many blocks
    a = np.concatenate([_levy(b.areas)[..., 0, 1] for b in drv.blocks()], axis=-1).ravel()
    assert _within(np.mean(a * a), h * h / 4, np.std(a * a) / np.sqrt(n))


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, exc, word", [
    (lambda: brownian_increments_and_areas(np.random.RandomState(0), 2, 0.1, 2), TypeError, "rng"),
    (lambda: brownian_increments_and_areas(None, 2, 0.1, 2), TypeError, "rng"),
    (lambda: brownian_increments_and_areas(0.5, 2, 0.1, 2), TypeError, "rng"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.0, 2), ValueError, "dt"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, -1.0, 2), ValueError, "dt"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, [0.1, 0.1, 0.1], 2), ValueError, "dt"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, np.nan, 2), ValueError, "dt"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 0, 0.1, 2), ValueError, "n_steps"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 0), ValueError, "dim"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 2.0), TypeError, "dim"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 2, substeps=0), ValueError, "substeps"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 2, levy_area="nonsense"), ValueError, "levy_area"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 2, kind="strat"), ValueError, "kind"),
    (lambda: brownian_increments_and_areas(np.random.default_rng(), 2, 0.1, 2, batch_shape=(-1,)), ValueError, "batch_shape"),
    (lambda: brownian_rough_path([0.0, 0.5, 0.5], 2, np.random.default_rng()), ValueError, "times"),
    (lambda: brownian_rough_path([0.0, 1.0, 0.5], 2, np.random.default_rng()), ValueError, "times"),
    (lambda: brownian_rough_path([0.0, 1.0], 0, np.random.default_rng()), ValueError, "dim"),
    (lambda: brownian_rough_path([0.0, 1.0], 2, None), TypeError, "rng"),
    (lambda: brownian_rough_path([0.0, 1.0], 2, np.random.default_rng(), x0=[1.0, 2.0, 3.0]), ValueError, "x0"),
])
def test_bad_input_names_the_argument(call, exc, word):
    with pytest.raises(exc, match=word):
        call()
