"""The blocked kernels' rows and their top-level sweep (private).

Shared by :mod:`roughpaths.signatures._blocked` (the lower levels double-buffered) and
:mod:`roughpaths.signatures._inplace` (in place): a row of a level written as whole packed rows (:func:`_row`) or
ending one entry at a time (:func:`_row_tail`), and the sweep that adds a block of segments' products to the top
level (:func:`_top_sweep`), each entry's products in the order of the segments.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

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
def _increment(x, b, t, k, d, dl, delta):
    """Segment ``t`` of path ``b`` (points ``t`` and ``t + 1``): its increment into ``delta`` and into row ``k`` of
    the block's increments ``dl``."""
    ud = np.uint64(d)
    kk = np.uint64(k)
    for i in range(ud):
        v = x[b, t + 1, i] - x[b, t, i]
        dl[kk * ud + i] = v
        delta[i] = v


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
def _top_sweep(s, ok, n, rs, d, tb, ts, dl, nk, w):
    """``s[ok + p + rs q] += sum_k tb[k ts + p] dl[k d + q]`` for ``p < n``, ``q < d``, the products added one segment
    after another (``tb``'s rows ``ts >= n`` apart: :func:`_tb_stride`). With ``ok`` the top level's offset and
    ``n = rs = d^(m-1)`` the whole level ``S_m``; a part of its rows otherwise.

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
    urs = np.uint64(rs)
    ud = np.uint64(d)
    unk = np.uint64(nk)
    uts = np.uint64(ts)
    n2 = un - un % (2 * L)
    q4 = ud - ud % np.uint64(4)
    ch = np.uint64(_SWEEP_CHUNK)
    for p0 in range(np.uint64(0), n2, ch):            # a chunk of the rows at a time (TLB: see _SWEEP_CHUNK)
        for q in range(np.uint64(0), q4, np.uint64(4)):
            for p in range(p0, min(p0 + ch, n2), 2 * L):    # tiles of 2 packed rows x 4 rows q: 8 sums at once
                r = np.uint64(ok) + q * urs + p
                a0 = vload(s, r)
                a1 = vload(s, r + L)
                b0 = vload(s, r + urs)
                b1 = vload(s, r + urs + L)
                c0 = vload(s, r + 2 * urs)
                c1 = vload(s, r + 2 * urs + L)
                e0 = vload(s, r + 3 * urs)
                e1 = vload(s, r + 3 * urs + L)
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
                vstore(s, r + urs, b0)
                vstore(s, r + urs + L, b1)
                vstore(s, r + 2 * urs, c0)
                vstore(s, r + 2 * urs + L, c1)
                vstore(s, r + 3 * urs, e0)
                vstore(s, r + 3 * urs + L, e1)
    n4 = n2 - n2 % (4 * L)
    for q in range(q4, ud):                             # the last d mod 4 rows: 4 packed rows at once
        row = np.uint64(ok) + q * urs
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
        row = np.uint64(ok) + q * urs + n2
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
        row = np.uint64(ok) + q * urs + n2
        for p in range(rest):
            s[row + p] = w[q * wn + p]


@njit(cache=True, inline="always")
def _tb_stride(n):
    """The distance between rows of ``n`` entries of the block ``tb``: ``n``, or ``n + LANES`` when ``n`` is a
    multiple of 512 floats (rows 4 KiB apart share their L1 sets and the low address bits that loads are
    checked against pending stores by)."""
    return n + LANES if n % 512 == 0 else n
