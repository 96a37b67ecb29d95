"""The d = 3 area kernel (written-out pairs) gives the bits of the general loop nest, which the stream test
checks against a naive numpy reimplementation; here: every flag, with and without in-kernel drawing."""

import numpy as np
import pytest

from roughpaths.drivers._area_kernels import _areas_m1, _areas_m1_d3
from roughpaths.drivers._random import PathStreams


@pytest.mark.parametrize("davie, ito", [(True, False), (False, False), (True, True)])
def test_d3_kernel_equals_general_loop_bitwise(davie, ito):
    P, K, d = 5, 7, 3
    rng = np.random.default_rng(3)
    h = rng.uniform(1e-3, 1e-1, K)
    dW = rng.standard_normal((P, K, d)) * np.sqrt(h)[:, None]
    na = d + (3 if davie else 0)
    z = rng.standard_normal((P, K, na))
    none = np.empty((0, 4), dtype=np.uint64)
    a, b = np.empty((P, K, d, d)), np.empty((P, K, d, d))
    _areas_m1(dW, h, z, none, davie, ito, a)
    _areas_m1_d3(dW, h, z, none, davie, ito, b)
    np.testing.assert_array_equal(a, b)
    keys = np.stack([np.arange(P), np.ones(P, dtype=np.int64)], axis=1)
    s1 = PathStreams(np.random.SeedSequence(11), keys).states
    if s1 is None:
        pytest.skip("numba PCG64 streams unavailable (numpy fallback)")
    s2 = s1.copy()
    _areas_m1(dW, h, np.empty((1, 1, na)), s1, davie, ito, a)
    _areas_m1_d3(dW, h, np.empty((1, 1, na)), s2, davie, ito, b)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(s1, s2)           # the streams advance alike
    # the Lévy part is antisymmetric, the symmetric part is ½ W⊗W (- ½ h I for Itô)
    sym = 0.5 * (b + np.swapaxes(b, -1, -2))
    ref = 0.5 * dW[..., :, None] * dW[..., None, :] - (0.5 * h[:, None, None] * np.eye(3) if ito else 0.0)
    np.testing.assert_allclose(sym, ref, rtol=1e-13, atol=1e-17)
