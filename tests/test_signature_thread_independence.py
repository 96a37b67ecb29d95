"""Claim: signatures and log-signatures are bitwise identical for any number of threads.

The split of the work (chunks of a long path, groups of paths) depends on the input's size only;
each work unit is computed by the same arithmetic whichever thread runs it, and the units are
glued by Chen's identity in a fixed order. So ``numba.set_num_threads(1)`` and ``(2)`` give the
same bits, and the serial twins of the parallel kernels give the same bits as the parallel ones.
"""

import numba
import numpy as np
import pytest

from roughpaths import _signature_kernels as kern
from roughpaths.signature import _offsets, _units, logsignature, signature


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
def test_serial_twin_equals_parallel_kernel(nchunks):
    x = np.ascontiguousarray(_path((9, 700, 3)))
    m = 4
    units = _units(9, 700, nchunks)
    par = kern.lane_sig_par(x, *units, nchunks, m, _offsets(3, m))
    ser = kern.lane_sig_ser(x, *units, nchunks, m, _offsets(3, m))
    assert par.tobytes() == ser.tobytes()
    assert kern.sig2_kernel(x, nchunks).tobytes() == kern.sig2_kernel_ser(x, nchunks).tobytes()
