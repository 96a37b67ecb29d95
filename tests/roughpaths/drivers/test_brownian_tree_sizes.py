"""Claim: ``BrownianTree`` checks every size before work: its batch (with the root and one split that any query
needs), a cache size given by the user, each query's outputs and splits, and an interval whose length
overflows or whose finest segment underflows float64 (which answered zeros).

Oracles: the memory budget set through ``ROUGHPATHS_MAX_BYTES``; tracemalloc (the refusal allocates
nothing of the batch's size); the law of the increment (variance ``t - s``) on a huge but finite interval.
"""

import time
import tracemalloc

import numpy as np
import pytest

import roughpaths as rp


def test_a_billion_paths_are_refused_before_allocating():
    tracemalloc.start()
    t = time.perf_counter()
    try:
        with pytest.raises(ValueError, match=r"tree of 1000000000 path\(s\).* would take [\d.]+ TiB"):
            rp.BrownianTree(2, seed=1, batch_shape=(10 ** 9,))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 ** 20 and time.perf_counter() - t < 5.0          # it allocated 7.45 GiB before


def test_a_batch_whose_size_overflows_int64_is_refused():
    with pytest.raises(ValueError, match="would take"):
        rp.BrownianTree(2, seed=1, batch_shape=(10 ** 10, 10 ** 10))


@pytest.mark.parametrize("t0,t1,match", [(-1e308, 1e308, "t1 - t0 overflows"),
                                         (0.0, 1e-300, "finest segment .* underflows")])
def test_intervals_beyond_float64_are_refused(t0, t1, match):
    with pytest.raises(ValueError, match=match):
        rp.BrownianTree(2, seed=1, t0=t0, t1=t1)


def test_a_huge_finite_interval_still_answers_brownian_increments():
    tree = rp.BrownianTree(1, seed=2, t0=-1e300, t1=1e300, batch_shape=(4000,))
    w = tree.increment(-0.5e300, 0.5e300)[:, 0]
    assert np.all(np.isfinite(w))
    var = np.mean(w ** 2) / 1e300
    assert abs(var - 1.0) < 5 * np.sqrt(2 / 4000), var                # Var = t - s, to 5 standard errors


def test_a_large_cache_size_is_refused_with_its_estimate(monkeypatch):
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(64 * 2 ** 20))
    with pytest.raises(ValueError, match=r"cache_size=100000 nodes .* would take [\d.]+ GiB"):
        rp.BrownianTree(2, seed=1, batch_shape=(1000,), cache_size=100_000)
    rp.BrownianTree(2, seed=1, batch_shape=(1000,))                     # the default cache fits 64 MiB


def test_a_query_beyond_the_budget_is_refused_before_the_walk(monkeypatch):
    tree = rp.BrownianTree(2, seed=1, batch_shape=(2000,))
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(32 * 2 ** 20))
    with pytest.raises(ValueError, match=r"a query of 999 interval\(s\) of the tree of 2000 path\(s\)"):
        tree.rough_path(np.linspace(0.0, 1.0, 1000))
    assert tree.cached_nodes == 0                                      # nothing was split
    assert tree.increment(0.0, 0.5).shape == (2000, 2)                 # a small query still fits
