"""roughpaths.validation.parallel_ranges: every item once, the caller's exceptions, bad block sizes."""

import threading

import numba
import numpy as np
import pytest

from roughpaths.validation import parallel_ranges


def test_every_item_exactly_once_on_all_threads():
    seen = np.zeros(1000, dtype=np.int64)
    lock = threading.Lock()
    calls = []

    def fn(lo, hi):
        with lock:
            calls.append((lo, hi))
            seen[lo:hi] += 1

    parallel_ranges(fn, 1000, 7)
    assert np.all(seen == 1)
    assert sorted(calls) == [(lo, min(lo + 7, 1000)) for lo in range(0, 1000, 7)]


def test_one_thread_runs_in_order_on_the_caller():
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        calls = []
        parallel_ranges(lambda lo, hi: calls.append((lo, hi, threading.get_ident())), 10, 4)
    finally:
        numba.set_num_threads(threads)
    assert [(lo, hi) for lo, hi, _ in calls] == [(0, 4), (4, 8), (8, 10)]
    assert {t for _, _, t in calls} == {threading.get_ident()}


def test_exception_reaches_the_caller_and_empty_is_a_no_op():
    def fn(lo, hi):
        if lo == 30:
            raise RuntimeError("range 30")

    with pytest.raises(RuntimeError, match="range 30"):
        parallel_ranges(fn, 100, 10)
    parallel_ranges(fn, 0, 10)


@pytest.mark.parametrize("block", [0, -3, 2.5, True])
def test_bad_block_is_refused(block):
    with pytest.raises(ValueError, match="block must be a positive int"):
        parallel_ranges(lambda lo, hi: None, 10, block)
