"""The bookkeeping of :mod:`roughpaths.rde.adaptive`'s attempts, compiled: one call per loop iteration each.

An adaptive solve with steps per member runs as many iterations as its slowest member takes attempts (about
2700 for the noise burst of ``benchmarks/bench_adaptive_steps.py`` at rtol 1e-3), and every iteration snapped
step ends, stacked step doubling's inputs, kept the results, reduced error ratios and advanced lanes with some
seventy small numpy calls (about 110 µs of an iteration's 490). Each kernel here is elementwise over lanes and
members and does the arithmetic of the numpy code it replaced, in the same order, so a member's numbers are
its own in any batch and the same as before (the burst's solve is bitwise unchanged).

Compiling (first adaptive solve, empty cache, CPU, load about 1): :func:`_snap_nb` 0.32 s, :func:`_advance_nb`
0.34 s, :func:`_doubling_nb` 0.31 s, :func:`_ratios_nb` 0.26 s, :func:`_judge_nb` 0.14 s; about 1.4 s together
(with ``PIController``'s kernel and the tree walk's time check, 1.8 s; less 0.3 s taken out of the tree's split
kernel in the same change). From numba's cache a few milliseconds. They buy about 20 % of the burst's CPU.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = []


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _snap_nb(i, h, targets, end, L, fine, mc, t0, span, cell, dt_min, j, floor, act, cols, t_at, h_at):
    """The next step ends ``j`` of the live lanes (``i < end``): ``h`` snapped to the grid of spacing ``(h/2^(fine+1), h/2^fine]``
    (cells of the tree's level ``L``), at least ``mc`` cells, never past the next target (a save time or ``end``;
    within ``mc`` cells of it: the target). Writes ``j``, ``floor`` (the step is at ``dt_min``: at most ``mc``
    cells or at most ``dt_min``), the live lanes ``act[:n]`` and their grid ends ``cols[:n]`` (start, midpoint
    if three columns, end), and every lane's attempted ``[t_at, t_at + h_at]`` (``h_at = 0`` for a lane done); returns
    ``n``."""
    n = 0
    thr = dt_min * (1 + 1e-12)
    three = cols.shape[1] == 3
    for k in range(i.size):
        floor[k] = False
        ik = i[k]
        t_at[k] = t0 + ik * cell
        if ik >= end:
            h_at[k] = (j[k] - ik) * cell
            continue
        lo, hi = 0, targets.size                    # the first target after ik (searchsorted, side right)
        while lo < hi:
            mid = (lo + hi) // 2
            if targets[mid] <= ik:
                lo = mid + 1
            else:
                hi = mid
        target = targets[lo]
        depth = min(max(np.int64(math.ceil(math.log2(span / h[k]))) + fine, 0), L)
        unit = np.int64(1) << (L - depth)
        jk = np.int64(np.rint((ik + h[k] / cell) / unit)) * unit
        jk = max(max(jk, ik + mc), (ik // unit + 1) * unit)
        if jk > target - mc:
            jk = target
        j[k] = jk
        h_at[k] = (jk - ik) * cell
        floor[k] = (jk - ik <= mc) or ((jk - ik) * cell <= thr)
        act[n] = k
        cols[n, 0] = ik
        cols[n, cols.shape[1] - 1] = jk
        if three:
            cols[n, 1] = (ik + jk) // 2
        n += 1
    return n


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _ratios_nb(err, tried, bad, healthy, lane_of, floor, adaptive, r, unmet):
    """The error ratio ``r`` of every lane from its members' ``err``: the maximum over its members that were tried,
    healthy and finite (NaN propagates; 0 if none), ``inf`` if one became non-finite (``bad``). A member whose
    ratio exceeds 1 (or is NaN) on a lane at ``dt_min`` (``floor``) is ``unmet`` instead (a failure by
    ``on_failure``) and does not count. Returns the number unmet."""
    n = 0
    for k in range(r.size):
        r[k] = 0.0
    for m in range(err.size):
        unmet[m] = False
        if not (tried[m] and healthy[m]):
            continue
        k = lane_of[m]
        if bad[m]:
            r[k] = math.inf
            continue
        if not adaptive:
            continue
        e = err[m]
        if floor[k] and not e <= 1.0:
            unmet[m] = True
            n += 1
        elif r[k] != math.inf and (e > r[k] or e != e):
            r[k] = e
    return n


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _advance_nb(accept, floor, live, tried, bad, healthy, lane_of, accepted, rejected, i, j, y, y_new, lanes, failing,
                held):
    """Accept the attempts of the lanes the controller accepted (or at ``dt_min``, ``floor``), count the others as
    rejected, move the accepted lanes' starts ``i`` to their ends ``j`` and their tried members' states ``y`` to
    ``y_new`` (NaN for a member not healthy or ``bad``). Writes the accepted lanes to ``lanes[:n]``. A healthy
    member that became non-finite on an accepted lane is ``failing``; its lane is ``held``: neither counted nor
    moved, so that the failure is reported at the attempt's own step (the caller then moves it). Returns ``(n,
    number failing)``."""
    n = 0
    for k in range(accept.size):
        a = (accept[k] or floor[k]) and live[k]
        accept[k] = a
        held[k] = False
        if a:
            lanes[n] = k
            n += 1
    nbad = 0
    for m in range(y.shape[0]):
        k = lane_of[m]
        failing[m] = False
        if not (accept[k] and tried[m]):
            continue
        ok = healthy[m] and not bad[m]
        if bad[m] and healthy[m]:
            failing[m] = True
            held[k] = True
            nbad += 1
        for c in range(y.shape[1]):
            y[m, c] = y_new[m, c] if ok else np.nan
    for k in range(accept.size):
        if accept[k] and not held[k]:
            accepted[k] += 1
            i[k] = j[k]
        elif live[k] and not accept[k]:
            rejected[k] += 1
    return n, nbad


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _doubling_nb(y, ts, W, XX, Y2, T2, DT2, DX2, DXX2):
    """The inputs of step doubling's first call (:func:`~roughpaths.rde.adaptive._step_doubling`): the members'
    first halves (rows ``:n``) and whole steps (rows ``n:``) stacked. ``y (n, e)``, ``ts (n, 3)`` the start,
    midpoint and end, ``W (n, 2, d)``, ``XX (n, 2, d, d)`` the halves' increments and areas; writes ``Y2 (2n, e)``
    (``y`` twice), ``T2, DT2 (2n, 1)`` starts and lengths, ``DX2 (2n, d)``, ``DXX2 (2n, d, d)``, the whole step's
    by Chen: ``X = X_1 + X_2``, ``XX = XX_1 + XX_2 + X_1 ⊗ X_2``."""
    n, e, d = y.shape[0], y.shape[1], W.shape[2]
    for m in range(n):
        for c in range(e):
            Y2[m, c] = y[m, c]
            Y2[n + m, c] = y[m, c]
        T2[m, 0] = ts[m, 0]
        T2[n + m, 0] = ts[m, 0]
        DT2[m, 0] = ts[m, 1] - ts[m, 0]
        DT2[n + m, 0] = ts[m, 2] - ts[m, 0]
        for a in range(d):
            DX2[m, a] = W[m, 0, a]
            DX2[n + m, a] = W[m, 0, a] + W[m, 1, a]
            for b in range(d):
                DXX2[m, a, b] = XX[m, 0, a, b]
                DXX2[n + m, a, b] = XX[m, 0, a, b] + XX[m, 1, a, b] + W[m, 0, a] * W[m, 1, b]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _judge_nb(members, y_new, err, has_err, Y_new, tried, bad, ERR):
    """Keep an attempt's members' new states ``y_new`` in ``Y_new``, mark them tried, ``bad`` if a component is not
    finite, and their error ratios ``err`` in ``ERR`` (if ``has_err``)."""
    for k in range(members.size):
        m = members[k]
        finite = True
        for c in range(y_new.shape[1]):
            v = y_new[k, c]
            Y_new[m, c] = v
            finite = finite and math.isfinite(v)
        tried[m] = True
        bad[m] = not finite
        if has_err:
            ERR[m] = err[k]
