r"""The Lévy area of the piecewise-linear lift of fBM converges as the fine grid shrinks, at rate ``δ^{2H - 1/2}``.

Claim: for fractional Brownian motion with ``H > 1/4`` sampled exactly on a grid of mesh ``δ``, the Lévy
area (over a fixed coarse step) of the piecewise-linear interpolation converges in ``L²`` as ``δ → 0``;
the error is the sum of the missing Lévy areas inside the ``δ``-steps, of ``L²`` size ``∝ δ^{2H - 1/2}``
(``δ^{1/2}`` for Brownian motion, ``δ^{0.3}`` for ``H = 0.4``, ``δ^{0.1}`` for ``H = 0.3``).

Oracle: one exact sample on the finest grid ``δ_ref`` is subsampled (subsamples of an exact fBM sample
are exact fBM samples on the coarser grid) and the Lévy area of each polygon is compared with that of the
finest polygon. Because the reference has its own error, ``E|A_δ - A_ref|² = c(δ^κ - δ_ref^κ)`` for
nested grids (the missing areas at mesh ``δ_ref`` are uncorrelated with the difference of the two
polygons' areas only asymptotically, so this is a model); ``κ/2`` is fitted by least squares on the
logarithms and compared with ``2H - 1/2``. The Lévy areas are computed by the library; the oracle
for them is the shoelace formula written here.
"""

import numpy as np
import pytest

from roughpaths import fbm, piecewise_linear_lift


def _shoelace(v):
    """Lévy area ½∫(x dy - y dx) of the polygon through v (..., n, 2), relative to its start."""
    x = v[..., 0] - v[..., :1, 0]
    y = v[..., 1] - v[..., :1, 1]
    return 0.5 * np.sum(x[..., :-1] * y[..., 1:] - x[..., 1:] * y[..., :-1], axis=-1)


def _fitted_rate(H, n_fine, batch, meshes, seed):
    v = fbm(n_fine, H, rng=seed, dim=2, batch_shape=(batch,))
    K = 4
    ref = piecewise_linear_lift(v, n_fine // K).step_levy_areas[..., 0, 1]
    # the library's lift against the shoelace oracle on the finest grid
    steps = v.reshape(batch, -1, 2)
    m = n_fine // K
    oracle = np.stack([_shoelace(steps[:, k * m:(k + 1) * m + 1]) for k in range(K)], axis=-1)
    np.testing.assert_allclose(ref, oracle, atol=1e-12)
    err2 = []
    for n in meshes:
        A = piecewise_linear_lift(v[..., ::n_fine // n, :], n // K).step_levy_areas[..., 0, 1]
        err2.append(np.mean((A - ref) ** 2))
    err2 = np.array(err2)
    delta = 1.0 / np.asarray(meshes, dtype=float)
    d_ref = 1.0 / n_fine
    best = None
    for kappa in np.linspace(0.05, 2.0, 391):                   # least squares over kappa, c in closed form
        basis = np.log(delta ** kappa - d_ref ** kappa)
        logc = np.mean(np.log(err2) - basis)
        res = np.sum((np.log(err2) - basis - logc) ** 2)
        if best is None or res < best[0]:
            best = (res, kappa)
    return best[1] / 2.0


@pytest.mark.parametrize("H", [0.3, 0.4, 0.5])
def test_levy_area_rate_reduced(H):
    rate = _fitted_rate(H, 4096, 120, [16, 32, 64, 128, 256], seed=11)
    assert abs(rate - (2 * H - 0.5)) < 0.1, (H, rate)


def test_levy_area_error_shrinks():
    """The L² error decreases monotonically in δ (H = 0.4): a lift that does not converge fails here."""
    v = fbm(4096, 0.4, rng=5, dim=2, batch_shape=(100,))
    ref = piecewise_linear_lift(v, 1024).step_levy_areas[..., 0, 1]
    errs = [np.sqrt(np.mean((piecewise_linear_lift(v[..., ::4096 // n, :], n // 4).step_levy_areas[..., 0, 1]
                             - ref) ** 2)) for n in (16, 64, 256, 1024)]
    assert all(a > b for a, b in zip(errs, errs[1:])), errs
    assert errs[-1] < 0.5 * errs[0]


@pytest.mark.slow
@pytest.mark.parametrize("H", [0.3, 0.35, 0.4, 0.5, 0.6])
def test_levy_area_rate_full(H):
    rate = _fitted_rate(H, 16384, 400, [16, 32, 64, 128, 256, 512], seed=12)
    assert abs(rate - (2 * H - 0.5)) < 0.05, (H, rate)
