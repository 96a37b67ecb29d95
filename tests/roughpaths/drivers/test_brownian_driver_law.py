r"""Law of the Brownian driver's rough path (``roughpaths.BrownianDriver``), at small size.

Claims tested (Lévy area ``A = ½(XX - XXᵀ)``, with the ½):

* increments are independent :math:`N(0, h I)` on a non-uniform grid;
* ``"davie"`` (any ``m``): :math:`\mathrm{Var}(A_{12}) = h^2/4` and the conditional structure
  :math:`E[A_{12}^2 W_1^2] = 5h^3/12` (from :math:`\mathrm{Var}(A_{12}\mid W) = h^2/12 + h(W_1^2+W_2^2)/12`),
  :math:`E[A_{12} W_1] = 0`;
* ``"foster"`` with ``m`` substeps: the variance deficit :math:`\mathrm{Var}(A_{12}) = h^2/4 - h^2/(12 m)`;
* Itô areas are the Stratonovich ones minus :math:`\tfrac12 h I` (same stream).
"""

import numpy as np
import pytest

from roughpaths import BrownianDriver


def _within(est, target, se, k=5.0):
    return abs(est - target) <= k * se


def test_increments_are_independent_gaussians_on_a_nonuniform_grid():
    times = np.array([0.0, 0.05, 0.3, 1.0])
    n = 40000
    X = BrownianDriver(3, seed=11, times=times, batch_shape=(n,), levy_area=None).rough_path()
    h = np.diff(times)
    for k in range(3):
        z = X.increments[:, k]
        cov = z.T @ z / n
        assert np.all(np.abs(z.mean(0)) <= 5 * np.sqrt(h[k] / n))
        assert np.all(np.abs(np.diag(cov) - h[k]) <= 5 * h[k] * np.sqrt(2.0 / n))
        assert np.all(np.abs(cov[~np.eye(3, dtype=bool)]) <= 5 * h[k] / np.sqrt(n))
        assert not np.all(np.abs(np.diag(cov) - h[k] ** 2) <= 5 * h[k] * np.sqrt(2.0 / n))   # wrong variant
    assert _within(np.mean(X.increments[:, 0, 0] * X.increments[:, 1, 0]), 0.0, np.sqrt(h[0] * h[1] / n))


@pytest.mark.parametrize("method, m", [("davie", 1), ("davie", 3), ("foster", 1), ("foster", 4)])
def test_levy_area_second_moments(method, m):
    h, n = 0.5, 60000
    X = BrownianDriver(3, seed=5, dt=h, n_steps=1, batch_shape=(n,), levy_area=method, substeps=m).rough_path()
    A = X.step_levy_areas[:, 0]
    W = X.increments[:, 0]
    a12 = A[:, 0, 1]
    target = h * h / 4 if method == "davie" else h * h / 4 - h * h / (12 * m)
    se = np.std(a12 ** 2) / np.sqrt(n)
    assert _within(a12.mean(), 0.0, a12.std() / np.sqrt(n))
    assert _within(np.mean(a12 ** 2), target, se)
    assert not _within(np.mean((2 * a12) ** 2), target, se)            # the area without the ½ fails
    f = a12 * W[:, 0]
    assert _within(f.mean(), 0.0, f.std() / np.sqrt(n))
    g = A[:, 0, 1] * A[:, 1, 2]
    assert _within(g.mean(), 0.0, g.std() / np.sqrt(n))
    if method == "davie":
        prod = a12 ** 2 * W[:, 0] ** 2
        assert _within(prod.mean(), 5 * h ** 3 / 12, prod.std() / np.sqrt(n))


def test_ito_areas_are_stratonovich_minus_half_h():
    kw = dict(seed=4, times=[0.0, 0.2, 0.7], batch_shape=(3,), substeps=2, levy_area="davie")
    S = BrownianDriver(2, **kw).rough_path()
    I = BrownianDriver(2, kind="ito", **kw).rough_path()
    assert I.kind == "ito" and S.kind == "geometric"
    np.testing.assert_allclose(I.areas, S.areas - 0.5 * np.diff(kw["times"])[:, None, None] * np.eye(2),
                               atol=1e-15)
