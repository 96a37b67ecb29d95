"""Claim: ``signature`` and ``logsignature`` equal iisignature (and esig) for every d = 1..6 and depth 1..6.

The default suite checks one diagonal of the grid (each d and each depth at least once, both the
serial and the parallel/chunked routes); ``-m slow`` runs the full 6 x 6 grid with batches and a
long path per cell. Oracles: ``iisignature.sig``, ``iisignature.logsig`` (Lyndon basis, default
method) to 1e-12 relative, ``esig.stream2sig`` for the signature.
"""

import esig
import iisignature
import numpy as np
import pytest

from roughpaths import logsignature, signature


def _path(rng, shape, n, d):
    return np.cumsum(rng.standard_normal(shape + (n, d)) / np.sqrt(n), axis=-2)


def _check(rng, d, m, shape, n):
    x = _path(rng, shape, n, d)
    ref = iisignature.sig(x, m)
    scale = max(1.0, float(np.max(np.abs(ref))))
    np.testing.assert_allclose(signature(x, m), ref, rtol=0, atol=1e-12 * scale)
    if d >= 2:
        refl = iisignature.logsig(x, iisignature.prepare(d, m))
    else:
        refl = ref[..., :1]
    np.testing.assert_allclose(logsignature(x, m), refl, rtol=0,
                               atol=1e-12 * max(1.0, float(np.max(np.abs(refl)))))
    if not shape:
        np.testing.assert_allclose(signature(x, m), np.asarray(esig.stream2sig(x, m))[1:], rtol=0,
                                   atol=1e-12 * scale)


DIAGONAL = [(1, 6), (2, 5), (3, 4), (4, 3), (5, 2), (6, 1), (2, 6), (6, 3)]


@pytest.mark.parametrize("d,m", DIAGONAL)
def test_grid_diagonal(rng, d, m):
    _check(rng, d, m, (), 9)
    _check(rng, d, m, (3,), 6)


@pytest.mark.slow
@pytest.mark.parametrize("d", range(1, 7))
@pytest.mark.parametrize("m", range(1, 7))
def test_full_grid(rng, d, m):
    _check(rng, d, m, (), 12)
    _check(rng, d, m, (2, 5), 8)
    if d ** m <= 5000:
        _check(rng, d, m, (1,), 3000)          # cut into chunks glued by Chen
