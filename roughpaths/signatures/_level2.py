"""Level-2 signature kernels (private; called by :mod:`roughpaths.signatures.signature`).

The level-2 signature of a piecewise-linear path y (y_0 = 0) has symmetric part ½ X⊗X (X the
total increment) and antisymmetric part ½ Σ_k y_{k-1} ∧ y_k (the Lévy area, shoelace formula).
One pass over the points, d(d-1)/2 accumulators, no temporaries. A long path is cut into chunks
(:func:`sig2_tasks`, any range of chunks on any thread) glued by Chen's identity in a fixed order
(:func:`sig2_glue`), so the split into ranges never changes a bit of the result.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore, vsub

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _area_chunk_d2(x, b, lo, hi, out):
    x0, x1 = x[b, lo, 0], x[b, lo, 1]
    p0 = 0.0
    p1 = 0.0
    a01 = 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        a01 += p0 * y1 - p1 * y0
        p0, p1 = y0, y1
    out[0] = p0
    out[1] = p1
    out[2] = a01


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _area_chunk_d3(x, b, lo, hi, out):
    x0, x1, x2 = x[b, lo, 0], x[b, lo, 1], x[b, lo, 2]
    p0 = 0.0
    p1 = 0.0
    p2 = 0.0
    a01 = 0.0
    a02 = 0.0
    a12 = 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        y2 = x[b, k, 2] - x2
        a01 += p0 * y1 - p1 * y0
        a02 += p0 * y2 - p2 * y0
        a12 += p1 * y2 - p2 * y1
        p0, p1, p2 = y0, y1, y2
    out[0] = p0
    out[1] = p1
    out[2] = p2
    out[3] = a01
    out[4] = a02
    out[5] = a12


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _area_chunk_d4(x, b, lo, hi, out):
    x0, x1, x2, x3 = x[b, lo, 0], x[b, lo, 1], x[b, lo, 2], x[b, lo, 3]
    p0, p1, p2, p3 = 0.0, 0.0, 0.0, 0.0
    a01, a02, a03, a12, a13 = 0.0, 0.0, 0.0, 0.0, 0.0
    a23 = 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        y2 = x[b, k, 2] - x2
        y3 = x[b, k, 3] - x3
        a01 += p0 * y1 - p1 * y0
        a02 += p0 * y2 - p2 * y0
        a03 += p0 * y3 - p3 * y0
        a12 += p1 * y2 - p2 * y1
        a13 += p1 * y3 - p3 * y1
        a23 += p2 * y3 - p3 * y2
        p0, p1, p2, p3 = y0, y1, y2, y3
    out[0] = p0
    out[1] = p1
    out[2] = p2
    out[3] = p3
    out[4] = a01
    out[5] = a02
    out[6] = a03
    out[7] = a12
    out[8] = a13
    out[9] = a23


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _area_chunk_d5(x, b, lo, hi, out):
    x0, x1, x2, x3, x4 = x[b, lo, 0], x[b, lo, 1], x[b, lo, 2], x[b, lo, 3], x[b, lo, 4]
    p0, p1, p2, p3, p4 = 0.0, 0.0, 0.0, 0.0, 0.0
    a01, a02, a03, a04, a12 = 0.0, 0.0, 0.0, 0.0, 0.0
    a13, a14, a23, a24, a34 = 0.0, 0.0, 0.0, 0.0, 0.0
    for k in range(lo + 1, hi + 1):
        y0 = x[b, k, 0] - x0
        y1 = x[b, k, 1] - x1
        y2 = x[b, k, 2] - x2
        y3 = x[b, k, 3] - x3
        y4 = x[b, k, 4] - x4
        a01 += p0 * y1 - p1 * y0
        a02 += p0 * y2 - p2 * y0
        a03 += p0 * y3 - p3 * y0
        a04 += p0 * y4 - p4 * y0
        a12 += p1 * y2 - p2 * y1
        a13 += p1 * y3 - p3 * y1
        a14 += p1 * y4 - p4 * y1
        a23 += p2 * y3 - p3 * y2
        a24 += p2 * y4 - p4 * y2
        a34 += p3 * y4 - p4 * y3
        p0, p1, p2, p3, p4 = y0, y1, y2, y3, y4
    out[0] = p0
    out[1] = p1
    out[2] = p2
    out[3] = p3
    out[4] = p4
    out[5] = a01
    out[6] = a02
    out[7] = a03
    out[8] = a04
    out[9] = a12
    out[10] = a13
    out[11] = a14
    out[12] = a23
    out[13] = a24
    out[14] = a34


#: Points whose area terms the generic kernel adds in one sweep of the table.
_KB2 = 16


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _area_chunk_generic(x, b, lo, hi, out):
    # the d x d table above its diagonal, acc[i, j] += y_{k-1}[i] y_k[j] - y_{k-1}[j] y_k[i] (the same
    # expression per pair i < j as the d = 2..5 kernels), for _KB2 points at a time: each packed row
    # of LANES entries stays in registers while the points' terms are added in order (the same bits
    # as one point at a time; a - b computed as a + b (-1), the same IEEE operation). Entries below the
    # diagonal in the row's first packed block, and past d, are computed and never read.
    d = x.shape[2]
    ud = np.uint64(d)
    L = np.uint64(LANES)
    dp = ud + (L - ud % L) % L                 # rows padded to whole packed rows (zeros past d)
    K = _KB2
    pv = np.zeros(K * dp)                      # y_{k-1}, one row of dp a point
    cv = np.zeros(K * dp)                      # y_k
    nc = np.zeros(K * dp)                      # -y_k
    acc = np.zeros(d * dp)
    for k0 in range(lo + 1, hi + 1, K):
        nk = np.uint64(min(K, hi + 1 - k0))
        for t in range(nk):
            for i in range(d):
                c = x[b, k0 + t, i] - x[b, lo, i]
                pv[t * dp + i] = x[b, k0 + t - 1, i] - x[b, lo, i] if k0 + t - 1 > lo else 0.0
                cv[t * dp + i] = c
                nc[t * dp + i] = -c
        for i in range(ud):
            row = i * dp
            for j in range((i + np.uint64(1)) - (i + np.uint64(1)) % L, dp, L):
                a = vload(acc, row + j)
                for t in range(nk):
                    o = t * dp
                    a = vadd(a, vadd(vmul(vsplat(pv[o + i]), vload(cv, o + j)),
                                     vmul(vload(pv, o + j), vsplat(nc[o + i]))))
                vstore(acc, row + j, a)
    for i in range(d):
        out[i] = x[b, hi, i] - x[b, lo, i]
    q = d
    for i in range(d):
        for j in range(i + 1, d):
            out[q] = acc[i * dp + j]
            q += 1


@njit(cache=True, inline="always")
def _area_chunk(x, b, lo, hi, out, D):
    """Write ``(X, twice the Lévy area over i<j)`` of points ``lo..hi`` of path ``b`` into ``out``; ``D`` is
    the calling kernel's compile-time alphabet size (0: any), so only its chunk kernel is compiled."""
    if D == 2:
        _area_chunk_d2(x, b, lo, hi, out)
    elif D == 3:
        _area_chunk_d3(x, b, lo, hi, out)
    elif D == 4:
        _area_chunk_d4(x, b, lo, hi, out)
    elif D == 5:
        _area_chunk_d5(x, b, lo, hi, out)
    else:
        _area_chunk_generic(x, b, lo, hi, out)


@variants
def _sig2_tasks_kernel(D: int):
    """The compiled :func:`sig2_tasks` for the alphabet size ``D`` (2..5; 0 for any other)."""

    @njit(**_NOGIL)
    def sig2_tasks_variant(x, nchunks, lo, hi, part):
        n = x.shape[1]
        seg = (n - 1 + nchunks - 1) // nchunks if n > 1 else 0
        for t in range(lo, hi):
            b = t // nchunks
            c = t - b * nchunks
            a = min(c * seg, n - 1)
            e = min(a + seg, n - 1)
            for r in range(part.shape[1]):
                part[t, r] = 0.0
            if e > a:
                _area_chunk(x, b, a, e, part[t], D)

    return sig2_tasks_variant


def sig2_tasks(d: int):
    """The level-2 kernel for alphabet size ``d`` (compiled on first use, without the GIL):
    ``kernel(x, nchunks, lo, hi, part)`` writes ``(increment, twice the Lévy area)`` of chunks
    ``t = lo..hi-1`` (path ``t // nchunks``) into ``part``. d = 2..5 have unrolled chunk kernels of their
    own (each compiled only when its d is first used)."""
    return _sig2_tasks_kernel(d if 2 <= d <= 5 else 0)


#: From this width on, groups of LANES paths run side by side (:func:`sig2_lane_tasks`).
LANE_WIDTH = 6


@njit(**_NOGIL)
def sig2_lane_tasks(x, nchunks, lo, hi, part):
    """:func:`sig2_tasks` for LANES paths at a time, one per lane: tasks ``t = lo..hi-1`` are (path group
    ``t // nchunks``, chunk ``t % nchunks``), the paths ``LANES (t // nchunks) + l``.

    Each lane adds, per pair ``i < j`` and point, ``a + (p_i c_j - p_j c_i)`` in point order: the
    operations of :func:`_area_chunk_generic` on one path (``p_j (-c_i)`` is ``-(p_j c_i)`` exactly, and
    ``u + (-w)`` is the IEEE ``u - w``), so a path gets the same bits in a group or alone. (The generic
    kernel runs the table of one path over packed rows; at d = 8 it costs ~115 cycles a segment, mostly the
    packing, against ~20 here.) The points' rows swap buffers instead of being copied, and ``-c`` is not
    stored: at d = 20 the gather of eight paths' points (two stores an entry) and the copy were ~20 % of a
    segment's time.
    """
    n = x.shape[1]
    d = x.shape[2]
    L = np.uint64(LANES)
    seg = (n - 1 + nchunks - 1) // nchunks if n > 1 else 0
    npair = d * (d - 1) // 2
    x0 = np.empty(d * LANES)
    pv = np.empty(d * LANES)                   # y_{k-1}, lane l of coordinate i at i * LANES + l
    cv = np.empty(d * LANES)                   # y_k
    acc = np.empty(npair * LANES)
    for t in range(lo, hi):
        g = t // nchunks
        c = t - g * nchunks
        a = min(c * seg, n - 1)
        e = min(a + seg, n - 1)
        b0 = g * LANES
        if e <= a:                             # an empty chunk: no increment, no area
            for r in range(part.shape[1]):
                for l in range(LANES):
                    part[(b0 + l) * nchunks + c, r] = 0.0
            continue
        for i in range(d):
            for l in range(LANES):
                x0[i * LANES + l] = x[b0 + l, a, i]
                pv[i * LANES + l] = 0.0
        for q in range(npair * LANES):
            acc[q] = 0.0
        for k in range(a + 1, e + 1):
            for i in range(d):
                for l in range(LANES):
                    cv[i * LANES + l] = x[b0 + l, k, i] - x0[i * LANES + l]
            q = np.uint64(0)
            for i in range(np.uint64(d)):
                pi = vload(pv, i * L)
                ci = vload(cv, i * L)
                for j in range(i + np.uint64(1), np.uint64(d)):
                    s = vload(acc, q)
                    vstore(acc, q, vadd(s, vsub(vmul(pi, vload(cv, j * L)), vmul(vload(pv, j * L), ci))))
                    q += L
            pv, cv = cv, pv                    # y_k becomes y_{k-1}; the next point overwrites the other
        for l in range(LANES):
            row = part[(b0 + l) * nchunks + c]
            for i in range(d):
                row[i] = x[b0 + l, e, i] - x0[i * LANES + l]
            for q in range(npair):
                row[d + q] = acc[q * LANES + l]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _glue_total(part, b, nchunks, d, tot):
    """``tot <- (increment, twice the Lévy area over i<j)`` of path ``b``, chunks glued by Chen in order.

    The first chunk is glued to zero: ``0 + (p + 0 p_j - 0 p_i)`` is ``0 + p`` for finite entries (a zero of either
    sign becomes +0 both ways), so it is copied as ``0.0 + p``, the same bits without the products (16 paths at
    d = 19 in one chunk: 10 us of the glue's 16 before)."""
    p = part[b * nchunks]
    for r in range(tot.shape[0]):
        tot[r] = 0.0 + p[r]
    for c in range(1, nchunks):
        p = part[b * nchunks + c]
        q = 0
        for i in range(d):
            for j in range(i + 1, d):
                tot[d + q] += p[d + q] + tot[i] * p[j] - tot[j] * p[i]
                q += 1
        for i in range(d):
            tot[i] += p[i]


@njit(**_NOGIL)
def sig2_glue(part, nb, nchunks, d):
    """Level-2 signatures ``(B, d + d*d)`` from the chunk data, glued by Chen: ``2A = 2A_1 + 2A_2 + X_1 ∧ X_2``."""
    width = part.shape[1]
    out = np.empty((nb, d + d * d))
    tot = np.empty(width)
    for b in range(nb):
        _glue_total(part, b, nchunks, d, tot)
        for i in range(d):
            out[b, i] = tot[i]
        q = 0
        for i in range(d):
            out[b, d + i * d + i] = 0.5 * tot[i] * tot[i]
            for j in range(i + 1, d):
                sym = 0.5 * tot[i] * tot[j]
                out[b, d + i * d + j] = sym + 0.5 * tot[d + q]
                out[b, d + j * d + i] = sym - 0.5 * tot[d + q]
                q += 1
    return out


@njit(**_NOGIL)
def logsig2_glue(part, nb, nchunks, d):
    """Level-2 log-signatures in the Lyndon basis ``(B, d + d(d-1)/2)``: the increment, then the Lévy
    areas ``[i, j]`` (``i < j``, lexicographic), from the chunk data (glued as :func:`sig2_glue`)."""
    width = part.shape[1]
    out = np.empty((nb, width))
    tot = np.empty(width)
    for b in range(nb):
        _glue_total(part, b, nchunks, d, tot)
        for i in range(d):
            out[b, i] = tot[i]
        for r in range(d, width):
            out[b, r] = 0.5 * tot[r]
    return out


@njit(**_NOGIL)
def sig2_vjp_rows(x, g, lo, hi, gx):
    """Cotangent ``gx`` (B, n, d) of the points of paths ``lo..hi-1`` given ``g`` (B, d + d*d), the
    row-major cotangent of their level-2 signatures (``n >= 2``).

    With ``c_k`` the cotangent of the increment ``Δ_k``: ``c_k = G_1 + G_2 X + A (Y_{k-1} + Y_k) / 2``,
    ``X`` the total increment, ``Y_k`` the point ``k`` minus the first, ``A = G_2^T - G_2``. So an
    interior point gets ``c_k - c_{k+1} = -A (x_{k+1} - x_{k-1}) / 2``: ``d^2`` operations a point.
    """
    n = x.shape[1]
    d = x.shape[2]
    at = np.empty((d, d))                                   # at[j, a] = A[a, j]
    c = np.empty(d)
    w0 = np.empty(d)
    w1 = np.empty(d)
    for b in range(lo, hi):
        for j in range(d):
            for a in range(d):
                at[j, a] = g[b, d + j * d + a] - g[b, d + a * d + j]
        for a in range(d):
            acc = g[b, a]
            for j in range(d):
                acc += g[b, d + a * d + j] * (x[b, n - 1, j] - x[b, 0, j])
            c[a] = acc
        row = gx[b]
        for k in range(n):
            for a in range(d):
                row[k, a] = 0.0
        for k in range(1, n - 1):
            for j in range(d):
                w = -0.5 * (x[b, k + 1, j] - x[b, k - 1, j])
                for a in range(d):
                    row[k, a] += at[j, a] * w
        for j in range(d):
            w0[j] = 0.5 * (x[b, 1, j] - x[b, 0, j])
            w1[j] = (x[b, n - 1, j] - x[b, 0, j]) - 0.5 * (x[b, n - 1, j] - x[b, n - 2, j])
        for a in range(d):
            s0 = c[a]
            s1 = c[a]
            for j in range(d):
                s0 += at[j, a] * w0[j]
                s1 += at[j, a] * w1[j]
            row[0, a] = -s0
            row[n - 1, a] = s1
