"""Claim: ``signature`` and ``logsignature`` refuse a path holding NaN or inf anywhere, naming its index.

At depth >= 2 the check runs on the (small) output and scans the input only when the output is
not finite; this is sound because every point enters the output through the increments on both
of its sides and NaN/inf never cancel. The test puts the bad value at the first, an interior and
the last point, in every coordinate, at depths 1..4, for both functions.
"""

import numpy as np
import pytest

from roughpaths import logsigdim, logsignature, logsignature_vjp, sigdim, signature, signature_vjp


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("f", [signature, logsignature])
def test_nonfinite_point_is_refused_with_its_index(bad, f):
    x = np.cumsum(np.random.default_rng(7).standard_normal((3, 40, 3)), axis=-2)
    for pos in [(0, 0, 0), (1, 17, 1), (2, 39, 2), (2, 20, 0)]:
        y = x.copy()
        y[pos] = bad
        for m in (1, 2, 3, 4):
            with pytest.raises(ValueError, match=r"paths contains 1 non-finite value.*index \(%d, %d, %d\)" % pos):
                f(y, m)


@pytest.mark.parametrize("f", [signature, logsignature])
def test_nonfinite_interior_point_is_refused_in_one_dimension(f):
    # d = 1: level 2 is ½ X², which an interior point does not enter
    x = np.cumsum(np.ones((2, 10, 1)), axis=-2)
    x[1, 4, 0] = np.nan
    for m in (1, 2, 3):
        with pytest.raises(ValueError, match=r"paths contains 1 non-finite value.*index \(1, 4, 0\)"):
            f(x, m)


@pytest.mark.parametrize("f", [signature, logsignature])
@pytest.mark.parametrize("shape, depth", [((3, 2), 2), ((2, 40, 3), 3), ((2, 3), 6), ((1, 2, 3), 5), ((30, 2), 1)])
def test_finite_paths_whose_result_overflows_are_refused_with_the_fix(f, shape, depth):
    # the signature of finite paths that leaves float64 came back as inf, and the log-signature (inf - inf) as
    # nan: silently, where signature_coefficients and signature_kernel refuse the same overflow. Checked on long
    # paths (the output scanned) and short ones at high depth (the input scanned, its size bounding the output)
    rng = np.random.default_rng(0)
    x = rng.standard_normal(shape)
    x[..., -1, :] = 0.0
    if depth == 1:                                                  # the increment itself leaves float64
        big = x.copy()
        big[..., 0, :], big[..., -1, :] = -1.5e308, 1.5e308
    else:
        big = x * 10.0 ** (330 / depth)                             # level depth ~ |x|^depth > 1.8e308
    with pytest.raises(ValueError, match=r"depth-%d .*overflows float64.*Rescale the paths" % depth):
        f(big, depth)
    y = f(x / np.max(np.abs(x)) * 10.0 ** (250 / depth) / depth, depth)    # large but representable: returned
    assert np.all(np.isfinite(y))


@pytest.mark.parametrize("vjp, dim", [(signature_vjp, sigdim), (logsignature_vjp, logsigdim)])
def test_a_gradient_that_overflows_is_refused(vjp, dim):
    x = np.random.default_rng(1).standard_normal((2, 6, 3)) * 1e110
    with pytest.raises(ValueError, match=r"gradient of the depth-4 .*overflows float64.*Rescale the paths"):
        vjp(x, 4, np.ones((2, dim(3, 4))))


@pytest.mark.parametrize("f", [signature, logsignature])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nonfinite_point_of_a_short_path_at_high_depth_is_refused(f, bad):
    # the input is the smaller array: it is scanned instead of the output
    x = np.random.default_rng(2).standard_normal((2, 3, 3))
    x[1, 1, 2] = bad
    with pytest.raises(ValueError, match=r"non-finite value.*index \(1, 1, 2\)"):
        f(x, 6)
