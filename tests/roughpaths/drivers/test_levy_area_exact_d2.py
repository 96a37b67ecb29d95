r"""Exact sampling of the d = 2 Lévy area given the increment (``levy_area="exact"``).

Claim: for planar Brownian motion over a step of size ``h`` with increment ``w``, the Lévy area
``A = ½∫(W¹dW² − W²dW¹)`` has the conditional characteristic function

.. math:: E[e^{i\lambda A}\mid w] = \frac{\lambda h/2}{\sinh(\lambda h/2)}
          \exp\Bigl(-\frac{|w|^2}{2h}\bigl(\tfrac{\lambda h}{2}\coth\tfrac{\lambda h}{2} - 1\bigr)\Bigr),

and the sampler draws from this law: the driver's table sampler (``_levy_table``) and its fallback,
the series sampler, each. Tested by Kolmogorov–Smirnov tests (10⁵ samples) against
the CDF computed from the characteristic function by Gil-Pelaez inversion (numerical
quadrature, checked here against the closed form for ``w = 0``, the logistic law), conditionally
on given increments, and unconditionally against :math:`(2/\pi)\arctan(e^{\pi x/h})`; the same
statistics reject the law of another ``|w|`` and Davie's ``m = 1`` law at small ``|w|``.
"""

import numpy as np
import pytest
from scipy import integrate, stats

from roughpaths import BrownianDriver
from roughpaths.drivers._area_kernels import _exact_areas_d2
from roughpaths.drivers._random import PathStreams
from roughpaths.drivers._levy_table import TABLE_STEP, load_table
from roughpaths.drivers.areas import _EXACT_T1, _EXACT_T2, _EXACT_TERMS

_SERIES_ONLY = np.empty((2, 0, 0))


def _cf(lam, h, w2):
    x = lam * h / 2
    return x / np.sinh(x) * np.exp(-w2 / (2 * h) * (x / np.tanh(x) - 1))


def _cdf_grid(h, w2, xs):
    """Gil-Pelaez: F(x) = 1/2 + (1/π) ∫_0^∞ sin(λx) φ(λ)/λ dλ (φ real and even)."""
    top = 80.0 / h
    return np.array([0.5 + integrate.quad(lambda l: np.sin(l * x) * _cf(l, h, w2) / l, 1e-12, top,
                                          limit=400, epsabs=1e-11)[0] / np.pi for x in xs])


def _sample_given(w, h, n, seed=0, series=False):
    dW = np.broadcast_to(np.asarray(w, float), (n, 1, 2)).copy()
    keys = np.stack([np.arange(n), np.ones(n, dtype=np.int64)], axis=1)
    st = PathStreams(np.random.SeedSequence(seed), keys).states
    out = np.empty((n, 1, 2, 2))
    table = _SERIES_ONLY if series else load_table()
    _exact_areas_d2(dW, np.array([h]), st, table, TABLE_STEP, _EXACT_TERMS, _EXACT_T1, _EXACT_T2, False, out)
    return 0.5 * (out[:, 0, 0, 1] - out[:, 0, 1, 0])


def test_gil_pelaez_oracle_reproduces_the_closed_forms():
    h = 0.7
    xs = np.linspace(-1.0, 1.0, 9)
    np.testing.assert_allclose(_cdf_grid(h, 0.0, xs), 1 / (1 + np.exp(-2 * np.pi * xs / h)), atol=1e-8)


@pytest.mark.parametrize("series", [False, True], ids=["table", "series"])
@pytest.mark.parametrize("w", [(0.0, 0.0), (0.3, -0.4), (2.0, 1.0)])
def test_conditional_law_kolmogorov_smirnov(w, series):
    h, n = 0.5, 100_000
    w2 = float(np.dot(w, w))
    a = _sample_given(w, h, n, series=series)
    sd = np.sqrt(h * h / 12 + h * w2 / 12)
    xs = np.linspace(-8 * sd, 8 * sd, 321)
    F = _cdf_grid(h, w2, xs)
    cdf = lambda x: np.interp(x, xs, F)                     # noqa: E731
    assert stats.kstest(a, cdf).pvalue > 1e-3
    assert abs(np.var(a) - sd ** 2) < 5 * sd ** 2 * np.sqrt(4.0 / n)
    # the law of another increment is rejected
    F_other = _cdf_grid(h, w2 + 4 * h, xs)
    assert stats.kstest(a, lambda x: np.interp(x, xs, F_other)).pvalue < 1e-6


def test_davie_law_is_rejected_where_it_differs():
    """Davie's m = 1 area given w is Gaussian with the right variance; at small |w| the exact law
    (nearly logistic) is far from Gaussian, and the same test rejects Davie's samples."""
    h, n, w = 0.5, 100_000, np.array([0.3, 0.0])
    w2 = float(w @ w)
    sd = np.sqrt(h * h / 12 + h * w2 / 12)
    xs = np.linspace(-8 * sd, 8 * sd, 321)
    F = _cdf_grid(h, w2, xs)
    rng = np.random.default_rng(1)
    H = rng.standard_normal((n, 2)) * np.sqrt(h / 12)
    davie = H[:, 0] * w[1] - H[:, 1] * w[0] + rng.standard_normal(n) * h / np.sqrt(12)
    assert stats.kstest(davie, lambda x: np.interp(x, xs, F)).pvalue < 1e-6
    assert stats.kstest(_sample_given(w, h, n, seed=3), lambda x: np.interp(x, xs, F)).pvalue > 1e-3


def test_unconditional_law_through_the_driver():
    h, n = 1.3, 100_000
    X = BrownianDriver(2, seed=77, dt=h, n_steps=1, batch_shape=(n,), levy_area="exact").rough_path()
    a = X.step_levy_areas[:, 0, 0, 1]
    cdf = lambda x: (2 / np.pi) * np.arctan(np.exp(np.pi * x / h))   # noqa: E731
    assert stats.kstest(a, cdf).pvalue > 1e-3
    assert stats.kstest(2 * a, cdf).pvalue < 1e-6                    # the area without the ½ fails
    W = X.increments[:, 0]
    prod = a ** 2 * W[:, 0] ** 2
    assert abs(prod.mean() - 5 * h ** 3 / 12) < 5 * prod.std() / np.sqrt(n)


def test_exact_is_refused_where_it_does_not_exist():
    with pytest.raises(ValueError, match="dim <= 2 only"):
        BrownianDriver(3, seed=0, dt=0.1, n_steps=2, levy_area="exact")
    with pytest.raises(ValueError, match="substeps"):
        BrownianDriver(2, seed=0, dt=0.1, n_steps=2, levy_area="exact", substeps=4)
