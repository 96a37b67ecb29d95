"""Claim: a signature kernel (or its gradient, or an MMD statistic) that leaves float64 is refused with the
scale and the fix in the message, never returned as ``inf`` or ``nan``; large kernels that fit are returned
exactly as before; static kernels whose scale overflows the paths are refused.

Oracles: the naive full-grid Goursat solve of ``_oracles`` (plain loops) for the large finite kernels; the
bound ``|k| <= I0(2 sqrt(Lx Ly))`` (the signature's level ``k`` has norm at most ``L**k / k!``) for where
overflow must happen; the scale the message proposes, applied, gives a finite kernel.
"""

import re

import numpy as np
import pytest

import roughpaths as rp
from _oracles import naive_signature_kernel


def _monotone(seed, n, d=2):
    """A path with positive increments: every cell's <dx, dy> > 0, so the kernel grows without cancellation."""
    return np.random.default_rng(seed).uniform(0.0, 1.0, size=(n, d)).cumsum(axis=0) / n


def _length(x):
    return float(np.sum(np.linalg.norm(np.diff(x, axis=0), axis=-1)))


def test_large_finite_kernels_are_returned_and_match_the_naive_scheme():
    x, y = _monotone(0, 40), _monotone(1, 30)
    for s in (1.0, 30.0, 250.0):
        got = rp.signature_kernel(s * x, s * y, dyadic_order=1)
        want = naive_signature_kernel(s * x, s * y, 1)
        assert np.isfinite(got) and got > 0
        np.testing.assert_allclose(got, want, rtol=1e-11)
    assert got > 1e150                   # the last one is large, and still exact to round-off


def test_overflow_is_refused_with_the_scale_and_a_fix_that_works():
    x, y = _monotone(2, 40), _monotone(3, 30)
    s = 2000.0                           # Lx Ly ~ (0.7 s)^2: the kernel is about exp(2 * 0.7 s), beyond 1e308
    assert 2 * np.sqrt(_length(s * x) * _length(s * y)) > 2 * np.log(1e308)
    with pytest.raises(ValueError, match="overflows float64") as err:
        rp.signature_kernel(s * x, s * y, dyadic_order=1)
    msg = str(err.value)
    assert "Lx=" in msg and "Ly=" in msg and "LinearKernel(scale=s)" in msg
    shrink = float(re.search(r"s <= ([0-9.e+-]+) times", msg).group(1))
    k = rp.signature_kernel(s * x, s * y, dyadic_order=1, static_kernel=rp.LinearKernel(shrink))
    assert np.isfinite(k) and k < 1e300                        # the proposed scale is enough


def test_overflow_found_in_a_batch_names_the_pair():
    x = np.stack([_monotone(4, 20), 1e5 * _monotone(5, 20), _monotone(6, 20)])
    with pytest.raises(ValueError, match=r"1 pair\(s\).*pair of paths 1 and 1"):
        rp.signature_kernel(x, x)
    with pytest.raises(ValueError, match="overflows float64"):
        rp.signature_kernel_gram(x, x)
    with pytest.raises(ValueError, match="gradient of 1 pair"):
        rp.signature_kernel_vjp(x[1], 0.05 * x[1], 1.0)


def test_oscillating_paths_that_gave_nan_are_refused():
    # the probe's case: Brownian-like paths scaled up give inf, then nan (inf - inf), with no warning
    x = np.random.default_rng(7).normal(size=(2, 200, 3)).cumsum(axis=1) / np.sqrt(200)
    for s in (40.0, 80.0):
        with pytest.raises(ValueError, match="overflows float64"):
            rp.signature_kernel(s * x[0], s * x[1], dyadic_order=2)


def test_static_kernel_scales_that_overflow_the_paths_are_refused():
    x = np.random.default_rng(8).normal(size=(2, 10, 2)).cumsum(axis=1)
    with pytest.raises(ValueError, match="overflows float64"):
        rp.signature_kernel(x[0], x[1], static_kernel=rp.LinearKernel(1e200))
    with pytest.raises(ValueError, match=r"RBFKernel\(sigma=1e-308\).*overflows float64"):
        rp.signature_kernel(x[0], x[1], static_kernel=rp.RBFKernel(1e-308))
    with pytest.raises(ValueError, match="1/sigma overflows"):
        rp.signature_kernel(x[0], x[1], static_kernel=rp.RBFKernel(1e-310))
    with pytest.raises(ValueError, match="overflows float64"):
        rp.sig_mmd_test(x[:, None].repeat(2, 1).reshape(4, 10, 2) * 1e150, x[:, None].repeat(2, 1).reshape(4, 10, 2),
                        seed=0, n_permutations=9)


def test_mmd_statistics_that_overflow_are_refused():
    # every kernel is finite (5e307 to 1e308) but the sum of the nine cross kernels is not
    X = 100.0 * np.stack([_monotone(0, 30)] * 6)
    s = 1.0
    for step, target in ((1.01, 1e306), (1.002, 5e307)):     # k grows ~9.5x per 1 %, ~1.6x per 0.2 %
        while rp.signature_kernel(s * X[0], s * X[1]) < target:
            s *= step
    K = rp.signature_kernel_gram(s * X, s * X)
    assert np.all(np.isfinite(K)) and 5e307 <= K.min() and K.max() < 1e308
    with pytest.raises(ValueError, match="MMD statistics overflow"):
        rp.sig_mmd_test(s * X[:3], s * X[3:], seed=0, n_permutations=9)
