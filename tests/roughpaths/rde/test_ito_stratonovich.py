r"""Itô / Stratonovich relation of the Brownian lift.

Claim: path by path, :math:`\mathbb{X}^{\text{Itô}}_{s,t} = \mathbb{X}^{\text{Strat}}_{s,t} - \tfrac12 (t-s) I`
(same seed, same Lévy area), the symmetric parts are :math:`\tfrac12 W\otimes W` and
:math:`\tfrac12 W\otimes W - \tfrac12 (t-s) I`, and over any interval of the grid (Chen sums)
:math:`E[\mathbb{X}^{\text{Itô}}_{s,t}] = 0` while :math:`E[\mathbb{X}^{\text{Strat}}_{s,t}] = \tfrac12 (t-s) I`.
"""

import numpy as np
import pytest

from roughpaths import brownian_increments_and_areas, brownian_rough_path, chen_defect, refine


def test_ito_equals_stratonovich_minus_half_h_identity_pathwise():
    h = np.array([0.1, 0.4, 0.05])
    dW_s, XX_s = brownian_increments_and_areas(np.random.default_rng(3), 3, h, 3, batch_shape=(4,))
    dW_i, XX_i = brownian_increments_and_areas(np.random.default_rng(3), 3, h, 3, batch_shape=(4,), kind="ito")
    assert np.array_equal(dW_s, dW_i)
    np.testing.assert_allclose(XX_i, XX_s - 0.5 * h[:, None, None] * np.eye(3), atol=1e-15)
    outer = dW_s[..., :, None] * dW_s[..., None, :]
    np.testing.assert_allclose(0.5 * (XX_s + np.swapaxes(XX_s, -1, -2)), 0.5 * outer, atol=1e-15)
    np.testing.assert_allclose(0.5 * (XX_i + np.swapaxes(XX_i, -1, -2)),
                               0.5 * outer - 0.5 * h[:, None, None] * np.eye(3), atol=1e-15)
    # same Lévy area
    np.testing.assert_allclose(XX_i - np.swapaxes(XX_i, -1, -2), XX_s - np.swapaxes(XX_s, -1, -2), atol=1e-15)


def test_rough_path_kinds():
    t = [0.0, 0.3, 1.0]
    assert brownian_rough_path(t, 2, np.random.default_rng(0)).kind == "geometric"
    assert brownian_rough_path(t, 2, np.random.default_rng(0), kind="ito").kind == "ito"


def test_expected_area_over_interval():
    times = np.array([0.0, 0.1, 0.25, 0.7, 1.0])
    n, d = 40000, 2
    Xi = brownian_rough_path(times, d, np.random.default_rng(8), batch_shape=(n,), kind="ito")
    Xs = brownian_rough_path(times, d, np.random.default_rng(8), batch_shape=(n,))
    for s, t in [(0.0, 1.0), (0.1, 0.7)]:
        ai, as_ = Xi.area(s, t), Xs.area(s, t)
        se = ai.std(axis=0) / np.sqrt(n)
        assert np.all(np.abs(ai.mean(axis=0)) <= 5 * se)                      # E[XX^Itô] = 0
        assert np.all(np.abs(as_.mean(axis=0) - 0.5 * (t - s) * np.eye(d)) <= 5 * se)
        # wrong variant "XX^Strat - (t-s) I" (no ½) has mean -½(t-s) I: rejected
        wrong = as_ - (t - s) * np.eye(d)
        assert not np.all(np.abs(wrong.mean(axis=0)) <= 5 * se)
        # Chen over the Itô path keeps the Itô/Strat relation on the whole interval
        np.testing.assert_allclose(ai, as_ - 0.5 * (t - s) * np.eye(d), atol=1e-12)


def test_ito_diagonal_is_ito_integral():
    """XX^Itô_ii = ∫ W^i dW^i = ½ (W_i² - h) exactly."""
    h = 0.3
    dW, XX = brownian_increments_and_areas(np.random.default_rng(1), 5, h, 3, kind="ito")
    np.testing.assert_allclose(np.diagonal(XX, axis1=-2, axis2=-1), 0.5 * (dW ** 2 - h), atol=1e-15)


@pytest.mark.parametrize("factor", [2, 3])
def test_refine_ito_path_stays_ito_and_chen_consistent(factor):
    X = brownian_rough_path([0.0, 0.2, 0.5, 1.0], 3, np.random.default_rng(2), batch_shape=(6,), kind="ito")
    Y = refine(X, factor, np.random.default_rng(5))
    assert Y.kind == "ito"
    assert chen_defect(Y, X) < 1e-13
    sym = 0.5 * (Y.areas + np.swapaxes(Y.areas, -1, -2))
    outer = Y.increments[..., :, None] * Y.increments[..., None, :]
    np.testing.assert_allclose(sym, 0.5 * outer - 0.5 * Y.dt[:, None, None] * np.eye(3), atol=1e-14)
