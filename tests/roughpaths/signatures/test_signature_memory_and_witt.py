"""Claim: the log-signature machinery is bounded in memory and ``logsigdim`` is Witt's formula.

* ``logsigdim(d, m)`` equals the number of Lyndon words (enumerated naively here, by testing every
  word for being strictly smaller than its rotations) and iisignature's ``logsiglength``; it is
  instant for huge depths;
* the cache of Lyndon expansions / projection maps never holds more than its byte budget;
* a request whose output cannot fit in memory is refused before allocating, naming the size and
  the fix (the work units of long paths counted);
* high-depth log-signatures agree with iisignature (depth 8; depth 10 in the slow suite).
"""

import itertools
import time

import iisignature
import numpy as np
import pytest

from roughpaths.algebra import _lyndon
from roughpaths import logsigdim, logsignature, signature, signature_vjp, sigdim


def _naive_lyndon_count(d, m):
    count = 0
    for k in range(1, m + 1):
        for w in itertools.product(range(d), repeat=k):
            if all(w < w[i:] + w[:i] for i in range(1, k)):
                count += 1
    return count


@pytest.mark.parametrize("d,m", [(1, 4), (2, 7), (3, 5), (4, 4), (5, 3)])
def test_logsigdim_counts_lyndon_words(d, m):
    assert logsigdim(d, m) == _naive_lyndon_count(d, m)
    if d > 1:
        assert logsigdim(d, m) == iisignature.logsiglength(d, m)


def test_logsigdim_is_instant_at_huge_depth():
    t0 = time.perf_counter()
    n = logsigdim(2, 60)
    assert time.perf_counter() - t0 < 0.5
    # sum_k 2^k/k (1 + O(2^(-k/2))) = (2^61/60)(1 + O(1/60)) for the leading terms
    assert 2 ** 61 // 60 < n < 1.05 * 2 ** 61 / 60


def test_byte_lru_respects_its_budget():
    cache = _lyndon._ByteLRU(1000)
    for i in range(10):
        cache.get(i, lambda: np.zeros(50))          # 400 bytes each
    assert cache.nbytes <= 1000
    assert 9 in cache._data and 0 not in cache._data


def test_lyndon_cache_stays_under_budget(rng):
    x = rng.standard_normal((6, 3))
    logsignature(x, 8)
    assert _lyndon._CACHE.nbytes <= _lyndon.CACHE_BYTES


def test_refuses_a_depth_that_cannot_fit():
    x = np.zeros((3, 10))
    for fn in (lambda: signature(x, 14), lambda: logsignature(x, 14)):
        with pytest.raises(ValueError, match=r"GiB.*lower depth"):
            fn()


def test_the_work_units_of_long_paths_are_counted_before_allocating(monkeypatch):
    """Paths cut into work units (here 4 paths of 4097 points, d = 10 at depth 5: 4 units each) hold the units'
    signatures, 16 x 111110 floats (14 MB), beside the result; the gradients hold the units' cotangents too.
    Budgets between the estimate without them and with them: refused at once, naming the size."""
    x = np.zeros((4, 4097, 10))
    for budget, fn in ((75e6, lambda: signature(x, 5)),
                       (95e6, lambda: signature_vjp(x, 5, np.zeros((4, sigdim(10, 5)))))):
        monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(int(budget)))
        t = time.perf_counter()
        with pytest.raises(ValueError, match=r"depth=5 with d=10 and 4 path\(s\).* would take \d+ MiB"):
            fn()
        assert time.perf_counter() - t < 2.0                       # refused before the work


def test_depth_8_matches_iisignature(rng):
    x = np.cumsum(rng.standard_normal((8, 3)), axis=0) * 0.4
    ref = iisignature.logsig(x, iisignature.prepare(3, 8))
    np.testing.assert_allclose(logsignature(x, 8), ref, rtol=0, atol=1e-10 * np.abs(ref).max())


@pytest.mark.slow
def test_depth_10_matches_iisignature(rng):
    x = np.cumsum(rng.standard_normal((10, 3)), axis=0) * 0.4
    ref = iisignature.logsig(x, iisignature.prepare(3, 10))
    np.testing.assert_allclose(logsignature(x, 10), ref, rtol=0, atol=1e-9 * np.abs(ref).max())
