"""One-unit signature kernel with the top level deferred over blocks of segments (private).

Called by :mod:`roughpaths.signatures._engine` for the units that run alone (every ``d >= 8``, d = 6, 7
beyond depth 3, and lane groups with few units), except units of at most 7 segments, which run the plain
one-unit kernel (:func:`roughpaths.signatures._engine.alone_kernel`: as fast there, and quicker to compile).
Layout and arithmetic are those of :mod:`roughpaths.signatures._lanes` (reversed word order, the Horner–Chen
update with every product rounded, then every sum).

The top level of the Horner update of segment ``k`` is a rank-one update,
``S_m <- S_m + T^(k)_{m-1} ⊗ D_k``, where ``T^(k)_{m-1}`` depends on levels ``1..m-1`` only (before
segment ``k``), and nothing reads ``S_m`` until the end. So the kernel forms ``T^(k)_{m-1}`` for a
block of up to :data:`KBLOCK` segments while levels ``1..m-1`` advance one segment at a time
(:func:`_fused_d`: every level's Horner chain in one pass over the lower levels), then adds the
block to ``S_m`` in one sweep (:func:`_top_sweep`): each entry is loaded once, gets its ``K``
products added *in the order of the segments* in a register, and is stored once,

    S_m[p + N q] <- (...((S_m[p + N q] + T^(1)[p] D_1[q]) + T^(2)[p] D_2[q]) + ...),   N = d^(m-1).

These are the operations of the segment-by-segment update in the same order, so the result has
the same bits as :func:`~roughpaths.signatures._lanes.scalar_units` and the lanes, for any block
size. The sweep is a small matrix product (``N x K`` times ``K x d``): two floating-point
operations per loaded value instead of one load and one store per product, so it runs at the
machine's multiply/add rate instead of its load/store rate, and a top level larger than the L1 (or
the L2) cache is streamed once a block instead of once a segment.

*Any width.* No loop ends one entry at a time, so a run-time ``d`` that is not a multiple of
``LANES`` costs no scalar tails: the lower levels advance in a private double buffer (read the old
copy, write the new one: never in place), every row of them is whole packed rows whose last one may
spill past the row (into the next row, written next, or into slack) (:func:`_row`), and the ends of
the top level's rows are swept in a zero-padded scratch, four rows at a time (:func:`_top_sweep`).
Before, those ends were scalar loops, and the top level's a chain of dependent adds per entry:
d = 6, 7, 10, 14 at depth 3 took 127, 148, 198, 437 ns a segment, now 68, 95, 148, 298 (one thread,
16 x 256 points; pysiglib 4.0 ``n_jobs=1`` 61, 89, 161, 399).
The (6, 4) variant, d = 4 from depth 7 and every other width once a row of the top level's ``T`` passes 4096
entries update the lower levels in place instead (rows end one entry at a time; no second copy to zero, to
stream and to copy out), which is faster there (:func:`block_key`); the same bits.
Where ``d^(m-1)`` is a multiple of 512 floats, the block's rows are ``LANES`` entries more apart
(:func:`_tb_stride`; 64 bytes a row, at most 1 KiB a call): 4 KiB apart, the sweep ran up to 12 % slower in
some processes (memory placement) than in others. Measured one thread, old and new interleaved in one
process, 8 processes: 64 x 256 points, d = 8 depth 4 6.1-7.1 ms against 6.4-7.9 (median ratio 0.95,
0.88-1.01), 16 x 256, d = 16 depth 4 0.87-0.98; the same bits (only the addresses move).

Measured (one thread, CPU time, this 2-core machine): the sweep 0.14-0.17 ns per entry and
segment (the rank-one update: 0.31; two packed multiplies and two packed adds a cycle give
0.125 at 2 GHz; tiles of 2 packed rows x 4 rows: 0.04-0.06); per segment (16 x 256 points, one
thread, interleaved with pysiglib 4.0 ``n_jobs=1``) d = 8 depth 3 58 ns (pysiglib 130), depth 4
450-500 (590-890), d = 6 depth 4 200-230 (300), d = 20 depth 3 780 (2000). d = 8 at depths 3 and
4 and d = 6 at depth 4 are compiled with constant ``d`` and ``m`` (loops unrolled: at d = 8, depth 3
58 ns a segment against 85 with a run-time ``d``), d = 4 with a constant ``d``; every other width runs
the run-time variant. Compile
cost (cold, empty cache, one variant, CPU, with the import): 4.6 s for the run-time variant (2.8 s
before the packed row ends and the 2 x 4 tiles), 4.0 s for (8, 3) (2.5 s).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)

#: Segments whose top-level products are added in one sweep.
KBLOCK = 16

#: Entries of the top level's rows that :func:`_top_sweep` takes at a time for every row ``q`` (1 KiB of a row): with a
#: top level of tens of MB (d = 11 at depth 6: rows of 1.3 MB, 16 rows of the block ``tb`` and 11 of ``S_m``), a
#: tile that went on to the next entries of its rows touched 27 new pages each time; a chunk of all the rows ``q``
#: reuses them. One thread, CPU time, three process pairs: 4 x 256 points at d = 11, depth 6 364-383 ms against
#: 417-451, d = 16 at depth 5 122-128 against 128-148; d = 10 at depth 6, d = 8 at depth 4 and d = 20 at depth 3
#: unchanged. The same operations on every entry (the same bits). Compile: the run-time variant 3.65-3.68 s against
#: 3.58-3.62 (cold, numba's events, three pairs).
_SWEEP_CHUNK = 128


@njit(cache=True, inline="always")
def _row(y, yo, x, xo, c, z, zo, n):
    """``y[yo + p] = x[xo + p] * c + z[zo + p]`` for ``p < n``, in whole packed rows of LANES.

    The last packed row runs past ``n`` by up to ``LANES - 1`` entries: it reads what follows ``x`` and
    ``z`` and writes garbage after ``y[yo + n - 1]``. The callers keep that harmless: ``y`` is never
    ``z`` nor ``x`` (no update in place), rows are written in increasing order (row ``q + 1``, written
    next, overwrites what row ``q`` spilled), and every region ends in ``LANES`` entries of slack.
    """
    L = np.uint64(LANES)
    cv = vsplat(c)
    for p in range(np.uint64(0), n, L):
        vstore(y, yo + p, vadd(vmul(vload(x, xo + p), cv), vload(z, zo + p)))


@njit(cache=True, inline="always")
def _row_tail(y, yo, x, xo, c, z, zo, n):
    """:func:`_row` writing nothing past ``n`` (the last ``n mod LANES`` entries one at a time): safe in
    place (``y`` is ``z``)."""
    L = np.uint64(LANES)
    n1 = n - n % L
    cv = vsplat(c)
    for p in range(np.uint64(0), n1, L):
        vstore(y, yo + p, vadd(vmul(vload(x, xo + p), cv), vload(z, zo + p)))
    for p in range(n1, n):
        y[yo + p] = x[xo + p] * c + z[zo + p]


@njit(cache=True, inline="always")
def _fused_d(lw, so, sn, delta, d, m, offsets, fac, cb, hs, tb, to):
    """Levels ``1..m-1`` advance one segment, and ``tb[to:to + d^(m-1)] = T^m_{m-1}`` (old levels).

    The lower levels are double-buffered in ``lw``: read at ``so``, the new ones written at ``sn``.
    Every level's Horner chain at once, level ``j`` of ``S`` read once: ``C^l_1 = D/l + S_1`` and
    ``C^l_j = C^l_{j-1} ⊗ D/(l - j + 1) + S_j`` for the levels ``l > j`` (``cb``: two regions of
    ``hs`` entries per ``l``), then ``S_j <- S_j + C^j_{j-1} ⊗ D``: the operations of
    :func:`~roughpaths.signatures._lanes._horner_step_d` in another order (the same bits;
    ``fac[k] = 1.0 / k``). Every row is whole packed rows (:func:`_row`): no loop ends one entry at a
    time, whatever ``d``.
    """
    ud = np.uint64(d)
    uh = np.uint64(hs)
    # C^l_j lives at cb[(2 l + j % 2) hs ...]
    for lev in range(2, m):
        inv = fac[lev]
        o = np.uint64(2 * lev + 1) * uh
        for i in range(ud):
            cb[o + i] = delta[i] * inv + lw[so + i]
    inv = fac[m]
    if m == 2:
        for i in range(ud):
            tb[to + i] = delta[i] * inv + lw[so + i]
    else:
        o = np.uint64(2 * m + 1) * uh
        for i in range(ud):
            cb[o + i] = delta[i] * inv + lw[so + i]
    for i in range(ud):
        lw[sn + i] = lw[so + i] + delta[i]
    size = ud                                       # d^(j-1)
    for j in range(2, m):
        oj = np.uint64(offsets[j])
        rd = np.uint64((j + 1) % 2)                 # C_{j-1} parity
        wr = np.uint64(j % 2)
        top = j == m - 1
        for q in range(ud):
            base = q * size
            row = oj + base
            for lev in range(j + 1, m if top else m + 1):
                c = delta[q] * fac[lev - j + 1]
                src = (np.uint64(2 * lev) + rd) * uh
                dst = (np.uint64(2 * lev) + wr) * uh + base
                _row(cb, dst, cb, src, c, lw, so + row, size)
            if top:
                c = delta[q] * fac[2]
                src = (np.uint64(2 * m) + rd) * uh
                _row(tb, to + base, cb, src, c, lw, so + row, size)
            src = (np.uint64(2 * j) + rd) * uh
            _row(lw, sn + row, cb, src, delta[q], lw, so + row, size)
        size *= ud


@njit(cache=True, inline="always")
def _fused_inplace(s, delta, d, m, offsets, fac, cb, hs, tb, to):
    """:func:`_fused_d` with the lower levels updated in place in ``s`` (the same operations in the same
    order: a row of level ``j`` is read, by the chains and by its own update, before it is written), its
    rows ending one entry at a time (:func:`_row_tail`)."""
    ud = np.uint64(d)
    uh = np.uint64(hs)
    for lev in range(2, m):
        inv = fac[lev]
        o = np.uint64(2 * lev + 1) * uh
        for i in range(ud):
            cb[o + i] = delta[i] * inv + s[i]
    inv = fac[m]
    o = np.uint64(to) if m == 2 else np.uint64(2 * m + 1) * uh
    dst = tb if m == 2 else cb
    for i in range(ud):
        dst[o + i] = delta[i] * inv + s[i]
    for i in range(ud):
        s[i] += delta[i]
    size = ud
    for j in range(2, m):
        oj = np.uint64(offsets[j])
        rd = np.uint64((j + 1) % 2)
        wr = np.uint64(j % 2)
        top = j == m - 1
        for q in range(ud):
            base = q * size
            row = oj + base
            for lev in range(j + 1, m if top else m + 1):
                c = delta[q] * fac[lev - j + 1]
                _row_tail(cb, (np.uint64(2 * lev) + wr) * uh + base, cb, (np.uint64(2 * lev) + rd) * uh, c, s,
                          row, size)
            if top:
                _row_tail(tb, np.uint64(to) + base, cb, (np.uint64(2 * m) + rd) * uh, delta[q] * fac[2], s, row,
                          size)
            _row_tail(s, row, cb, (np.uint64(2 * j) + rd) * uh, delta[q], s, row, size)
        size *= ud


@njit(cache=True, inline="always")
def _top_sweep(s, ok, n, d, tb, ts, dl, nk, w):
    """``S_m[p + n q] += sum_k tb[k ts + p] dl[k d + q]``, the products added one segment after another
    (``tb``'s rows ``ts >= n`` apart: :func:`_tb_stride`).

    The first ``n - n mod 2 LANES`` entries of every row go, a chunk of :data:`_SWEEP_CHUNK` entries of all the rows at
    a time, in tiles of 2 packed rows x 4 rows ``q``:
    eight independent sums advance together, and each packed row of ``tb`` loaded serves four
    products (measured alone at d = 8, depth 4: 0.06 ns an entry and segment, against 0.14 for tiles
    of 4 packed rows x 1 row ``q``, whose four sums wait on the adds' latency); the last ``d mod 4``
    rows go in tiles of 4 (or 2) packed rows. The rest of each row (fewer than ``2 LANES``) is copied
    into the zero-padded rows of the scratch ``w`` (``(d + 3) x 2 LANES``) and swept there by whole
    packed rows, four rows ``q`` at a time (summed one entry at a time, each entry's ``K`` additions
    form a chain of dependent adds: ~10x slower a product). ``tb`` needs ``LANES`` readable entries
    past its last segment and ``dl`` 3 past its last (the padded lanes and rows read them and are never
    copied back). Every entry gets the same operations in the same order on either path.
    """
    L = np.uint64(LANES)
    un = np.uint64(n)
    ud = np.uint64(d)
    unk = np.uint64(nk)
    uts = np.uint64(ts)
    n2 = un - un % (2 * L)
    q4 = ud - ud % np.uint64(4)
    ch = np.uint64(_SWEEP_CHUNK)
    for p0 in range(np.uint64(0), n2, ch):            # a chunk of the rows at a time (TLB: see _SWEEP_CHUNK)
        for q in range(np.uint64(0), q4, np.uint64(4)):
            for p in range(p0, min(p0 + ch, n2), 2 * L):    # tiles of 2 packed rows x 4 rows q: 8 sums at once
                r = np.uint64(ok) + q * un + p
                a0 = vload(s, r)
                a1 = vload(s, r + L)
                b0 = vload(s, r + un)
                b1 = vload(s, r + un + L)
                c0 = vload(s, r + 2 * un)
                c1 = vload(s, r + 2 * un + L)
                e0 = vload(s, r + 3 * un)
                e1 = vload(s, r + 3 * un + L)
                for k in range(unk):
                    t = k * uts + p
                    t0 = vload(tb, t)
                    t1 = vload(tb, t + L)
                    e = k * ud + q
                    c = vsplat(dl[e])
                    a0 = vadd(a0, vmul(t0, c))
                    a1 = vadd(a1, vmul(t1, c))
                    c = vsplat(dl[e + 1])
                    b0 = vadd(b0, vmul(t0, c))
                    b1 = vadd(b1, vmul(t1, c))
                    c = vsplat(dl[e + 2])
                    c0 = vadd(c0, vmul(t0, c))
                    c1 = vadd(c1, vmul(t1, c))
                    c = vsplat(dl[e + 3])
                    e0 = vadd(e0, vmul(t0, c))
                    e1 = vadd(e1, vmul(t1, c))
                vstore(s, r, a0)
                vstore(s, r + L, a1)
                vstore(s, r + un, b0)
                vstore(s, r + un + L, b1)
                vstore(s, r + 2 * un, c0)
                vstore(s, r + 2 * un + L, c1)
                vstore(s, r + 3 * un, e0)
                vstore(s, r + 3 * un + L, e1)
    n4 = n2 - n2 % (4 * L)
    for q in range(q4, ud):                             # the last d mod 4 rows: 4 packed rows at once
        row = np.uint64(ok) + q * un
        for p in range(np.uint64(0), n4, 4 * L):
            r = row + p
            a0 = vload(s, r)
            a1 = vload(s, r + L)
            a2 = vload(s, r + 2 * L)
            a3 = vload(s, r + 3 * L)
            for k in range(unk):
                c = vsplat(dl[k * ud + q])
                t = k * uts + p
                a0 = vadd(a0, vmul(vload(tb, t), c))
                a1 = vadd(a1, vmul(vload(tb, t + L), c))
                a2 = vadd(a2, vmul(vload(tb, t + 2 * L), c))
                a3 = vadd(a3, vmul(vload(tb, t + 3 * L), c))
            vstore(s, r, a0)
            vstore(s, r + L, a1)
            vstore(s, r + 2 * L, a2)
            vstore(s, r + 3 * L, a3)
        for p in range(n4, n2, 2 * L):                  # at most one tile of 2
            r = row + p
            a0 = vload(s, r)
            a1 = vload(s, r + L)
            for k in range(unk):
                c = vsplat(dl[k * ud + q])
                t = k * uts + p
                a0 = vadd(a0, vmul(vload(tb, t), c))
                a1 = vadd(a1, vmul(vload(tb, t + L), c))
            vstore(s, r, a0)
            vstore(s, r + L, a1)
    rest = un - n2
    wn = (rest + L - np.uint64(1)) // L * L                  # scratch row: whole packed rows (0 if none)
    nq = (ud + np.uint64(3)) // np.uint64(4) * np.uint64(4)  # rows d .. nq - 1 of w are slack
    for q in range(nq if rest else np.uint64(0)):
        row = np.uint64(ok) + q * un + n2
        for p in range(wn):
            w[q * wn + p] = s[row + p] if q < ud and p < rest else 0.0
    for c in range(np.uint64(0), wn, L):
        p = n2 + c
        for q in range(np.uint64(0), ud, np.uint64(4)):
            r = q * wn + c
            a0 = vload(w, r)
            a1 = vload(w, r + wn)
            a2 = vload(w, r + 2 * wn)
            a3 = vload(w, r + 3 * wn)
            for k in range(unk):
                t = vload(tb, k * uts + p)
                e = k * ud + q
                a0 = vadd(a0, vmul(t, vsplat(dl[e])))
                a1 = vadd(a1, vmul(t, vsplat(dl[e + 1])))
                a2 = vadd(a2, vmul(t, vsplat(dl[e + 2])))
                a3 = vadd(a3, vmul(t, vsplat(dl[e + 3])))
            vstore(w, r, a0)
            vstore(w, r + wn, a1)
            vstore(w, r + 2 * wn, a2)
            vstore(w, r + 3 * wn, a3)
    for q in range(ud if rest else np.uint64(0)):
        row = np.uint64(ok) + q * un + n2
        for p in range(rest):
            s[row + p] = w[q * wn + p]


@njit(cache=True, inline="always")
def _tb_stride(n):
    """The distance between rows of ``n`` entries of the block ``tb``: ``n``, or ``n + LANES`` when ``n`` is a
    multiple of 512 floats (rows 4 KiB apart share their L1 sets and the low address bits that loads are
    checked against pending stores by)."""
    return n + LANES if n % 512 == 0 else n


@njit(cache=True, inline="always")
def _unit_d(x, b, k0, k1, s, d, m, offsets, fac, buf, hs, tb, ts, dl, delta, w, lw, ls):
    """Signature (reversed layout) of points ``k0..k1`` of path ``b`` into ``s`` (depth ``m >= 2``); the
    lower levels run in ``lw`` (two copies ``ls`` apart) and are copied into ``s`` at the end."""
    ud = np.uint64(d)
    n = np.uint64(d ** (m - 1))
    ok = offsets[m]
    for r in range(ok, s.shape[0]):
        s[r] = 0.0
    for r in range(ok):
        lw[r] = 0.0
    so = np.uint64(0)
    sn = np.uint64(ls)
    for t0 in range(k0, k1, KBLOCK):
        nk = min(KBLOCK, k1 - t0)
        for k in range(nk):
            kk = np.uint64(k)
            for i in range(ud):
                v = x[b, t0 + k + 1, i] - x[b, t0 + k, i]
                dl[kk * ud + i] = v
                delta[i] = v
            _fused_d(lw, so, sn, delta, d, m, offsets, fac, buf, hs, tb, kk * np.uint64(ts))
            so, sn = sn, so
        _top_sweep(s, ok, n, d, tb, ts, dl, nk, w)
    for r in range(ok):
        s[r] = lw[so + r]


@njit(cache=True, inline="always")
def _unit_inplace(x, b, k0, k1, s, d, m, offsets, fac, buf, hs, tb, ts, dl, delta, w):
    """:func:`_unit_d` with the lower levels updated in place in ``s`` (:func:`_fused_inplace`)."""
    ud = np.uint64(d)
    n = np.uint64(d ** (m - 1))
    ok = offsets[m]
    for r in range(s.shape[0]):
        s[r] = 0.0
    for t0 in range(k0, k1, KBLOCK):
        nk = min(KBLOCK, k1 - t0)
        for k in range(nk):
            kk = np.uint64(k)
            for i in range(ud):
                v = x[b, t0 + k + 1, i] - x[b, t0 + k, i]
                dl[kk * ud + i] = v
                delta[i] = v
            _fused_inplace(s, delta, d, m, offsets, fac, buf, hs, tb, kk * np.uint64(ts))
        _top_sweep(s, ok, n, d, tb, ts, dl, nk, w)


def block_key(d: int, m: int) -> tuple:
    """``(D, M, T)``: the compile-time alphabet size and depth of the one-unit kernel's variant (0: at run time),
    and whether its lower levels are updated in place (``T``).

    Compile-time widths (and depths) let LLVM unroll the loops over the letters and the levels:
    (d, m) = (8, 3) (the lower levels 40 against 57 ns a segment), (8, 4) and (6, 4) (cells (d) and (h)
    of ``benchmarks/bench_signatures.py``: the run-time variant measured 10 % and 15-25 % slower there),
    and d = 4 at any depth. Every other width runs the run-time variant: (20, 3) had a variant of its
    own until the run-time one came within 5-8 % of it (cell (e)). Each variant is its own kernel,
    compiled on first use (a few seconds of CPU, then cached), so a call compiles only the one it runs.

    In place (:func:`_unit_inplace`, the same bits): (6, 4) and d = 4 from depth 7. There the double
    buffer's second copy of the lower levels, its zeroing and its copy-out cost more than the rows that
    end one entry at a time: measured (one thread, interleaved) 16 x 256 points at (6, 4) 663-692 us
    against 749-780 double-buffered (the kernel before the double buffer: 726-784); a lone 10 x 4 path at
    depth 8 183-222 us against 231-273 (before: 194-245); d = 4 at depth 8, 1 x 257 points 4.9-5.1 ms
    against 5.2-5.4. d = 4 at depths 5 and 6 stays double-buffered (in place 5-50 % slower on 17-257 points).
    A variant compiles one of the two (cold, empty cache, CPU with the import, two runs interleaved with
    the code before: (6, 4) 5.9 and 5.4 s against 5.6 and 5.3, d = 4 at depth 8 6.0 and 5.4 against 6.2
    and 6.1, the run-time variant, whose code is unchanged, 5.7 and 5.2 against 5.3 and 6.0).

    The run-time variant runs in place too where a row of ``T`` passes 4096 entries (32 KiB, the L1 cache):
    there the second copy of the lower levels is memory traffic. One thread, CPU time, three process pairs,
    in place against double-buffered: d = 10 at depth 6 (8 x 256 points) 267-273 ms against 306-323, d = 11 at
    depth 6 302-322 against 349-376, d = 12 at depth 5 45-48 against 51, d = 8 at depth 6 31-32 against 35-36,
    d = 6 at depth 6 27-28 against 29-31, d = 3 at depth 9 3.7-3.8 against 4.0-4.2, d = 2 at depth 14 6.3-6.5
    against 7.1-8.0; at 4096 entries and below even or slower (d = 8 at depth 5, d = 16 and d = 10 at depth 4).
    That variant compiles in 3.9-4.2 s (cold, numba's events; the double-buffered one 3.8 s), once, for the
    calls that need it.
    """
    if (d, m) == (6, 4):
        return 6, 4, True
    if (d, m) in ((8, 3), (8, 4)):
        return d, m, False
    return (4, 0, m >= 7) if d == 4 else (0, 0, d ** (m - 1) > 4096)


@variants
def _block_units_kernel(D: int, M: int, TAIL: bool):
    """The compiled :func:`block_units` of variant ``(D, M, TAIL)`` (:func:`block_key`)."""

    @njit(**_NOGIL)
    def block_units_variant(x, ub, ulo, uhi, m, offsets, lo, hi, part):
        d = D if D else x.shape[2]
        mm = M if M else m
        # Scratch from np.empty (np.zeros of a large array costs a memset of it on every call, measured
        # +40 % on a lone 10 x 4 path at depth 8); only the windows that packed rows read past valid
        # entries before anything is written there are zeroed (no garbage, e.g. subnormals, in the lanes).
        L = LANES
        hs = (d ** max(mm - 2, 1) + 2 * L - 1) // L * L         # a chain's region, with slack
        buf = np.empty((2 * mm + 2) * hs)                       # the chains C^l_j (_fused_d)
        for r in range(0 if TAIL else 2 * mm + 2):              # (rows in place read no further)
            for j in range(mm - 1):
                buf[r * hs + d ** j:r * hs + d ** j + L] = 0.0
        ls = 0 if TAIL else (offsets[mm] + 2 * L - 1) // L * L  # the lower levels, with slack (or in s)
        lw = np.empty(2 * ls)
        lw[offsets[mm]:ls] = 0.0
        lw[ls + offsets[mm]:] = 0.0
        most = 1
        for u in range(lo, hi):
            most = max(most, uhi[u] - ulo[u])
        rows = min(KBLOCK, most)
        n1 = d ** (mm - 1)
        ts = _tb_stride(n1)
        tb = np.empty(rows * ts + L)                            # a short path's block: its segments
        for r in range(rows):
            tb[r * ts + n1:r * ts + n1 + L] = 0.0
        w = np.zeros((d + 3) * 4 * LANES)                       # the rows' ends (_top_sweep)
        dl = np.zeros(KBLOCK * d + 3)
        delta = np.empty(d)
        fac = np.empty(mm + 1)
        for k in range(1, mm + 1):
            fac[k] = 1.0 / k
        for u in range(lo, hi):
            if TAIL:
                _unit_inplace(x, ub[u], ulo[u], uhi[u], part[u], d, mm, offsets, fac, buf, hs, tb, ts, dl, delta,
                              w)
            else:
                _unit_d(x, ub[u], ulo[u], uhi[u], part[u], d, mm, offsets, fac, buf, hs, tb, ts, dl, delta, w, lw,
                        ls)

    return block_units_variant


def block_units(d: int, m: int):
    """The one-unit kernel for alphabet size ``d`` and depth ``m >= 2`` (compiled on first use, without the
    GIL): ``kernel(x, ub, ulo, uhi, m, offsets, lo, hi, part)`` writes the signatures (reversed layout) of
    units ``lo..hi-1`` into ``part`` (units, sigdim).

    Unit ``u`` covers points ``ulo[u]..uhi[u]`` of path ``ub[u]``. The same bits as
    :func:`~roughpaths.signatures._lanes.scalar_units`. Each variant's compiled symbols carry its key
    (:func:`roughpaths._variants._named`): :mod:`roughpaths.signatures.xla_handlers` finds the kernel by its name.
    """
    return _block_units_kernel(*block_key(d, m))
