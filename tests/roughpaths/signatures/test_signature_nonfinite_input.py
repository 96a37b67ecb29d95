"""Claim: ``signature`` and ``logsignature`` refuse a path holding NaN or inf anywhere, naming its index.

At depth >= 2 the check runs on the (small) output and scans the input only when the output is
not finite; this is sound because every point enters the output through the increments on both
of its sides and NaN/inf never cancel. The test puts the bad value at the first, an interior and
the last point, in every coordinate, at depths 1..4, for both functions.
"""

import numpy as np
import pytest

from roughpaths import logsignature, signature


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


def test_finite_overflow_is_returned_not_refused():
    x = np.array([[0.0, 0.0], [1e200, 1e200], [0.0, 2e200]])     # level 2 overflows to inf
    s = signature(x, 2)
    assert np.isinf(s).any() and np.isfinite(s[:2]).all()
