"""The adaptive loop's compiled bookkeeping (``roughpaths.rde._attempts``) against the numpy formulas it replaced.

Claims: the step ends are snapped as the numpy code did (the grid of spacing ``(h/2^(fine+1), h/2^fine]``, at
least ``min_cells`` cells, never past the next target, the target when within ``min_cells`` of it), bit for bit;
the error ratio of a lane is the maximum over its tried, healthy, finite members with NaN propagating, ``inf`` if
one became non-finite, and the members over the tolerance at ``dt_min`` are failures instead. The oracles are
the numpy expressions, written out here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from roughpaths.rde._attempts import _ratios_nb, _snap_nb


def _snap_numpy(i, h, targets, end, L, fine, mc, t0, span, cell, dt_min, three):
    live = i < end
    act = np.flatnonzero(live)
    i, h = i[act], h[act]
    target = targets[np.searchsorted(targets, i, side="right")]
    depth = np.minimum(np.maximum(np.ceil(np.log2(span / h)).astype(np.int64) + fine, 0), L)
    unit = np.left_shift(np.int64(1), L - depth)
    j = np.rint((i + h / cell) / unit).astype(np.int64) * unit
    j = np.maximum(np.maximum(j, i + mc), (i // unit + 1) * unit)
    j = np.where(j > target - mc, target, j)
    floor = (j - i <= mc) | ((j - i) * cell <= dt_min * (1 + 1e-12))
    cols = np.stack([i, (i + j) // 2, j], axis=1) if three else np.stack([i, j], axis=1)
    return act, j, floor, cols, t0 + i * cell, (j - i) * cell


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("fine, three", [(1, True), (3, True), (3, False)])
def test_step_ends_are_snapped_as_the_numpy_formula(seed, fine, three):
    rng = np.random.default_rng(seed)
    L, n = 40, 200
    end = np.int64(1) << L
    t0, span = 0.25, 1.5
    cell = span / end
    targets = np.sort(rng.choice(np.arange(1, 64), 3, replace=False) * (end // 64)).astype(np.int64)
    targets = np.append(targets[targets < end], end)
    i = (rng.integers(0, 64, n) * (end // 64) + rng.integers(0, 2 ** 20, n)).astype(np.int64)
    i[rng.random(n) < 0.2] = end                                      # lanes already done
    h = span * np.exp(rng.uniform(np.log(2.0 ** -32), 0.0, n))        # steps from dt_min-size to the whole span
    mc, dt_min = 2, span * 2.0 ** -30
    j, floor, act = np.zeros(n, np.int64), np.zeros(n, bool), np.zeros(n, np.int64)
    cols, t_at, h_at = np.zeros((n, 3 if three else 2), np.int64), np.zeros(n), np.zeros(n)
    j[:] = i                                                          # a done lane's end is its start
    k = _snap_nb(i, h, targets, end, L, fine, mc, t0, span, cell, dt_min, j, floor, act, cols, t_at, h_at)
    act_r, j_r, floor_r, cols_r, t_r, h_r = _snap_numpy(i, h, targets, end, L, fine, mc, t0, span, cell, dt_min, three)
    assert k == act_r.size and 0 < k < n
    np.testing.assert_array_equal(act[:k], act_r)
    np.testing.assert_array_equal(j[act_r], j_r)
    np.testing.assert_array_equal(floor[act_r], floor_r)
    np.testing.assert_array_equal(cols[:k], cols_r)
    np.testing.assert_array_equal(t_at[act_r], t_r)
    np.testing.assert_array_equal(h_at[act_r], h_r)
    assert not floor[i >= end].any() and (h_at[i >= end] == 0).all()
    assert (j_r > i[act_r]).all() and floor_r.any()                   # every live lane moves; some are at dt_min


def _ratios_numpy(err, tried, bad, healthy, lane_of, floor, lanes):
    bad = bad & healthy
    ok = tried & healthy & ~bad
    unmet = ok & ~(err <= 1.0) & floor[lane_of]
    ok &= ~unmet
    r = np.zeros(lanes)
    for k in range(lanes):                          # the lane's maximum, NaN propagating (np.max), inf if one is bad
        mine = ok & (lane_of == k)
        r[k] = np.max(err[mine]) if mine.any() else 0.0
    r[lane_of[bad]] = math.inf
    return r, unmet


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("shared", [False, True])
def test_error_ratios_are_reduced_over_each_lane_as_in_numpy(seed, shared):
    rng = np.random.default_rng(100 + seed)
    P = 50
    lanes = 1 if shared else P
    lane_of = np.zeros(P, np.int64) if shared else np.arange(P)
    err = rng.exponential(0.7, P)
    err[rng.random(P) < 0.1] = np.nan
    tried, healthy = rng.random(P) < 0.9, rng.random(P) < 0.9
    bad = tried & (rng.random(P) < 0.05 * (1 + shared))             # flagged only for the tried (the loop's judge)
    floor = rng.random(lanes) < 0.3
    r, unmet = np.full(lanes, -1.0), np.ones(P, bool)
    n = _ratios_nb(err, tried, bad, healthy, lane_of, floor, True, r, unmet)
    r_ref, unmet_ref = _ratios_numpy(err, tried, bad, healthy, lane_of, floor, lanes)
    np.testing.assert_array_equal(r, r_ref)                          # NaN where numpy has NaN
    np.testing.assert_array_equal(unmet, unmet_ref)
    assert n == unmet_ref.sum()
