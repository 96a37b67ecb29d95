r"""Claim: the excess kurtosis of a sampled Lévy area is the value derived in :mod:`roughpaths.drivers.brownian`.

For ``levy_area="davie"`` with ``m`` substeps the docstring derives :math:`\kappa_4 = h^4/8 - h^4/(24 m^3)`
with :math:`\kappa_2 = h^2/4`, i.e. excess kurtosis :math:`2 - 2/(3m^3)` (**4/3** at the default
``m = 1``, formerly stated as "1.36 (measured)"; 23/12 at ``m = 2``), and for ``levy_area="foster"``
the same :math:`\kappa_4` over :math:`\kappa_2 = h^2/4 - h^2/(12m)`, i.e.
:math:`(2 - 2/(3m^3))(3m/(3m-1))^2` (3 at ``m = 1``); the true Lévy area (``"exact"``) has 2.

The tests

* check the derivation's algebra with an independent numerical trace (the bilinear-form matrix ``K``
  built entry by entry from the Chen sum, :math:`\kappa_4 = 6\,\mathrm{tr}((KK^T)^2)`), and the
  stated sixth-cumulant error (4/9 at ``m = 1``, falling like :math:`m^{-4}`);
* estimate the excess kurtosis of :math:`A_{12}` from the sampler and accept it within 4 standard
  errors, the standard error computed from the same sample by the delta method (influence function
  of :math:`m_4/m_2^2`), and check that the test can tell 4/3 from the exact law's 2;
* check that the docstring states the derived value, not the measured 1.36.

Peers: LevyArea.jl's ``runtests.jl`` checks the structure of its iterated integrals (diagonal
:math:`\tfrac12 W^2 - \tfrac12 h`), not their law; no peer suite checks a fourth moment. These tests extend
the second-moment checks of ``test_brownian_law.py`` / ``test_brownian_driver_law.py`` to the fourth
cumulant. Default runs use 10⁶ samples per case (about a second each); ``-m slow`` uses 8·10⁶.
"""

import numpy as np
import pytest

import roughpaths.drivers.brownian as brownian
from roughpaths import brownian_increments_and_areas

H = 0.5


def _davie_excess(m):
    return 2.0 - 2.0 / (3.0 * m ** 3)


def _expected(method, m):
    if method == "davie":
        return _davie_excess(m)
    return _davie_excess(m) * (3.0 * m / (3.0 * m - 1.0)) ** 2


def _excess_kurtosis(a):
    """Sample excess kurtosis and its delta-method standard error (from the same sample)."""
    a = a - a.mean()
    a2 = a * a
    m2, m4 = a2.mean(), (a2 * a2).mean()
    influence = (a2 * a2 - m4) / m2 ** 2 - 2.0 * m4 * (a2 - m2) / m2 ** 3
    return m4 / m2 ** 2 - 3.0, float(influence.std() / np.sqrt(a.size))


def _levy_area_samples(method, m, n, seed):
    _, XX = brownian_increments_and_areas(np.random.default_rng(seed), 1, H, 2, batch_shape=(n,),
                                          levy_area=method, substeps=m)
    return 0.5 * (XX[:, 0, 0, 1] - XX[:, 0, 1, 0])


# ------------------------------------------------------------------ the algebra of the derivation
@pytest.mark.parametrize("m", [1, 2, 3, 5, 8])
def test_fourth_cumulant_formula(m):
    delta = H / m
    c = 1.0 / np.sqrt(12.0)
    n = 2 * m                                   # u = (w^1_k, √12 H^1_k)/√δ, v likewise for component 2
    K = np.zeros((n, n))
    for k in range(m):
        K[m + k, k] += c                        # H^1_k w^2_k
        K[k, m + k] -= c                        # -w^1_k H^2_k
        for l in range(k + 1, m):               # ½ (w^1_k w^2_l - w^2_k w^1_l), k < l
            K[k, l] += 0.5
            K[l, k] -= 0.5
    G = K @ K.T
    kappa2 = delta ** 2 * np.sum(K * K) + H ** 2 / (12.0 * m)
    kappa4 = 6.0 * delta ** 4 * np.trace(G @ G)
    assert kappa2 == pytest.approx(H ** 2 / 4, rel=1e-12)
    assert kappa4 == pytest.approx(H ** 4 / 8 - H ** 4 / (24.0 * m ** 3), rel=1e-12)
    assert kappa4 / kappa2 ** 2 == pytest.approx(_davie_excess(m), rel=1e-12)
    trB4 = np.trace(np.linalg.matrix_power(K[:m, :m], 4))
    assert trB4 == pytest.approx(m * (m - 1) * (m * m + m - 3) / 48.0, abs=1e-12)
    foster2 = kappa2 - H ** 2 / (12.0 * m)
    assert kappa4 / foster2 ** 2 == pytest.approx(_expected("foster", m), rel=1e-12)


def _sixth_cumulant_relative_error(m):
    delta, c = H / m, 1.0 / np.sqrt(12.0)
    K = np.zeros((2 * m, 2 * m))
    for k in range(m):
        K[m + k, k], K[k, m + k] = c, -c
        K[k, k + 1:m], K[k + 1:m, k] = 0.5, -0.5
    G = K @ K.T
    kappa6 = 120.0 * delta ** 6 * np.trace(G @ G @ G)
    return (H ** 6 / 4 - kappa6) / (H ** 6 / 4)               # true Lévy area: κ6 = h⁶/4 (log cosh)


def test_sixth_cumulant_error_as_stated():
    assert _sixth_cumulant_relative_error(1) == pytest.approx(4.0 / 9.0, rel=1e-12)
    ratio = _sixth_cumulant_relative_error(32) / _sixth_cumulant_relative_error(64)
    assert ratio == pytest.approx(16.0, rel=0.03)               # falls like m^-4


# ------------------------------------------------------------------ the sampler
def _check(method, m, n, seed):
    g, se = _excess_kurtosis(_levy_area_samples(method, m, n, seed))
    target = _expected(method, m)
    assert abs(g - target) <= 4.0 * se, (method, m, g, se, target)
    return g, se


@pytest.mark.parametrize("method,m,seed", [("davie", 1, 101), ("davie", 2, 102), ("foster", 1, 103)])
def test_excess_kurtosis_at_the_derived_value(method, m, seed):
    _check(method, m, 1_000_000, seed)


def test_the_default_is_told_apart_from_the_exact_law():
    g, se = _check("davie", 1, 1_000_000, 104)
    assert abs(g - 2.0) > 10.0 * se


@pytest.mark.slow
@pytest.mark.parametrize("method,m,seed", [("davie", 1, 201), ("davie", 2, 202), ("davie", 3, 203),
                                           ("foster", 2, 204)])
def test_excess_kurtosis_at_the_derived_value_large(method, m, seed):
    _check(method, m, 8_000_000, seed)


def test_docstring_states_the_derived_value():
    doc = brownian.__doc__
    assert "4/3" in doc and "2 - 2/(3m^3)" in doc
    assert "1.36" not in doc
