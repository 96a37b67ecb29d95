"""Claim: signatures, log-signatures and their gradients are bitwise identical for any number of threads.

The split of a path into chunks depends on the input's size only; each work unit is computed by
the same arithmetic whichever thread runs it (and whichever range of units a thread takes), and
the units are glued by Chen's identity in a fixed order. So ``numba.set_num_threads(1)`` and
``(2)`` give the same bits, the lane kernels (units side by side; signature and gradient) give the
same bits as the one-unit-at-a-time kernels, and splitting the work into other ranges changes
nothing.
"""

import numba
import numpy as np
import pytest

from roughpaths.signatures import _lanes as kern
from roughpaths import logsignature, signature, signature_vjp
from roughpaths.algebra.flat import level_offsets as _offsets
from roughpaths.signatures._engine import _units


def _path(shape, seed=3):
    return np.cumsum(np.random.default_rng(seed).standard_normal(shape), axis=-2)


CASES = [((1, 40_000, 3), 2), ((1, 6_000, 3), 3), ((3, 3_000, 2), 4), ((70, 50, 3), 3)]


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs numba with at least 2 threads")
@pytest.mark.parametrize("shape,m", CASES)
def test_one_thread_equals_two_threads(shape, m):
    x = _path(shape)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = (signature(x, m), logsignature(x, m))
        numba.set_num_threads(2)
        two = (signature(x, m), logsignature(x, m))
    finally:
        numba.set_num_threads(before)
    assert one[0].tobytes() == two[0].tobytes()
    assert one[1].tobytes() == two[1].tobytes()


@pytest.mark.parametrize("nchunks", [1, 5])
# d <= 5, (2, 4), (6, 3) and (7, 3) specialised (lane_key); key (0, 0): the run-time variant (what d = 1
# reaches) at d = 6; d = 3 defers the top level over 16 segments (units end inside such a run of segments)
@pytest.mark.parametrize("d,m,key", [(2, 4, None), (2, 5, None), (3, 3, None), (3, 4, None), (5, 3, None), (6, 3, None),
                                     (7, 3, None), (6, 3, (0, 0))])
def test_lanes_equal_one_unit_at_a_time_and_any_split(nchunks, d, m, key):
    # 9 paths: a group of 8 lanes and one of 1; with 5 chunks the last chunk of each path is
    # shorter than the others (units end at different steps); one path is scaled by 1e12
    x = _path((9, 700, d))
    x[4] *= 1e12
    units = _units(9, 700, nchunks)
    nu = 9 * nchunks
    off = _offsets(d, m)
    one = np.empty((nu, off[m + 1]))
    kern.scalar_units(x.shape[2])(x, *units, m, off, 0, nu, one)
    lanes = np.empty_like(one)
    groups = -(-nu // kern.LANES)
    lane_kernel = kern.lane_groups(d, m) if key is None else kern._lane_groups_kernel(*key)
    for g in range(groups):                       # one range per group, in reverse order
        lane_kernel(x, *units, m, off, groups - 1 - g, groups - g, lanes)
    assert one.tobytes() == lanes.tobytes()


def test_lanes_with_empty_units():
    x = _path((3, 10, 3))                         # 9 segments in 4 chunks of 3: the last is empty
    units = _units(3, 10, 4)
    assert np.any(units[1] == units[2])
    off = _offsets(3, 3)
    one = np.empty((12, off[4]))
    kern.scalar_units(x.shape[2])(x, *units, 3, off, 0, 12, one)
    lanes = np.full_like(one, np.nan)
    kern.lane_groups(x.shape[2], 3)(x, *units, 3, off, 0, 2, lanes)
    assert one.tobytes() == lanes.tobytes()


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="needs numba with at least 2 threads")
def test_gradients_one_thread_equals_two_threads():
    x = _path((20, 400, 3))
    g = np.random.default_rng(1).standard_normal((20, 39))
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = signature_vjp(x, 3, g)
        numba.set_num_threads(2)
        two = signature_vjp(x, 3, g)
    finally:
        numba.set_num_threads(before)
    assert one.tobytes() == two.tobytes()


@pytest.mark.parametrize("nchunks", [1, 5])
@pytest.mark.parametrize("d,m", [(2, 4), (3, 3), (4, 3)])
def test_gradient_lanes_equal_one_unit_at_a_time(nchunks, d, m):
    from roughpaths.signatures import _vjp as _sig_vjp
    from roughpaths.signatures._engine import _reversed_parts

    x = _path((9, 300, d))
    x[2] *= 1e6
    g = np.random.default_rng(5).standard_normal((9, _offsets(d, m)[m + 1]))
    units = _units(9, 300, nchunks)
    nu = 9 * nchunks
    off = _offsets(d, m)
    part = _reversed_parts(x, m, nchunks)
    gunit = g                                     # each unit's cotangent: its path's, or glued across the chunks
    if nchunks > 1:
        gunit = np.empty(part.shape)
        _sig_vjp.unit_cotangents(part, g, nchunks, d, m, off, 0, nu, gunit)
    one = np.zeros((9, 299, d))
    _sig_vjp.sig_vjp_units(d)(x, *units, m, off, part, gunit, 0, nu, one)
    lanes = np.full_like(one, np.nan)
    groups = -(-nu // kern.LANES)
    for grp in range(groups):                     # one range per group, in reverse order
        _sig_vjp.sig_vjp_groups(d)(x, *units, m, off, part, gunit, groups - 1 - grp, groups - grp, lanes)
    assert one.tobytes() == lanes.tobytes()
