"""Claim: the log-signature machinery is bounded in memory and ``logsigdim`` is Witt's formula.

* ``logsigdim(d, m)`` equals the number of Lyndon words (enumerated naively here, by testing every
  word for being strictly smaller than its rotations) and iisignature's ``logsiglength``; it is
  instant for huge depths;
* the cache of Lyndon expansions / projection maps never holds more than its byte budget;
* a request whose output cannot fit in memory is refused before allocating, naming the size and
  the fix;
* high-depth log-signatures agree with iisignature (depth 8; depth 10 in the slow suite).
"""

import itertools
import time

import iisignature
import numpy as np
import pytest

from roughpaths.algebra import _lyndon
from roughpaths import logsigdim, logsignature, signature


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


def test_depth_8_matches_iisignature(rng):
    x = np.cumsum(rng.standard_normal((8, 3)), axis=0) * 0.4
    ref = iisignature.logsig(x, iisignature.prepare(3, 8))
    np.testing.assert_allclose(logsignature(x, 8), ref, rtol=0, atol=1e-10 * np.abs(ref).max())


@pytest.mark.slow
def test_depth_10_matches_iisignature(rng):
    x = np.cumsum(rng.standard_normal((10, 3)), axis=0) * 0.4
    ref = iisignature.logsig(x, iisignature.prepare(3, 10))
    np.testing.assert_allclose(logsignature(x, 10), ref, rtol=0, atol=1e-9 * np.abs(ref).max())
