"""The blocked kernel's in-place units: the lower levels updated in ``s`` itself (private).

Called by :mod:`roughpaths.signatures._blocked` for the variants that :func:`~roughpaths.signatures._blocked.block_key`
marks in place. Layout and arithmetic are :mod:`roughpaths.signatures._blocked`'s: each entry gets the operations of
the segment-by-segment update in the same order, so the bits are the same.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore
from ._sweep import KBLOCK, _increment, _row_tail, _top_sweep

#: Entries of level ``m - 1`` whose top-level products one pass of :func:`_unit_two` forms at a time.
CHUNK = 128


@njit(cache=True, inline="always")
def _fused_lower(s, delta, d, m, offsets, fac, cb, hs):
    """Levels ``1..m-2`` advance one segment in place in ``s`` (``m >= 3``), leaving the chains ``C^{m-1}_{m-2}``
    and ``C^m_{m-2}`` in ``cb`` (at ``(2 l + (m - 2) % 2) hs``): the operations of
    :func:`~roughpaths.signatures._blocked._fused_d` below level ``m - 1``, in the same order (a row is read, by the
    chains and by its own update, before it is written), rows ending one entry at a time (:func:`_row_tail`)."""
    ud = np.uint64(d)
    uh = np.uint64(hs)
    for lev in range(2, m + 1):
        inv = fac[lev]
        o = np.uint64(2 * lev + 1) * uh
        for i in range(ud):
            cb[o + i] = delta[i] * inv + s[i]
    for i in range(ud):
        s[i] += delta[i]
    size = ud
    for j in range(2, m - 1):
        oj = np.uint64(offsets[j])
        rd = np.uint64((j + 1) % 2)
        wr = np.uint64(j % 2)
        for q in range(ud):
            base = q * size
            row = oj + base
            for lev in range(j + 1, m + 1):
                c = delta[q] * fac[lev - j + 1]
                _row_tail(cb, (np.uint64(2 * lev) + wr) * uh + base, cb, (np.uint64(2 * lev) + rd) * uh, c, s,
                          row, size)
            _row_tail(s, row, cb, (np.uint64(2 * j) + rd) * uh, delta[q], s, row, size)
        size *= ud


@njit(cache=True, inline="always")
def _top_chains(m, hs):
    """Where :func:`_fused_lower` leaves ``C^{m-1}_{m-2}`` and ``C^m_{m-2}`` in its buffer
    (``(2 l + (m - 2) % 2) hs``)."""
    par = np.uint64((m - 2) % 2)
    return (np.uint64(2 * (m - 1)) + par) * np.uint64(hs), (np.uint64(2 * m) + par) * np.uint64(hs)


@njit(cache=True, inline="always")
def _unit_inplace(x, b, k0, k1, s, d, m, offsets, fac, buf, hs, tb, ts, dl, delta, w):
    """Signature (reversed layout) of points ``k0..k1`` of path ``b`` into ``s`` (depth ``m >= 3``), the lower levels
    updated in place: levels ``1..m-2`` by :func:`_fused_lower`, then level ``m - 1`` with the block's row
    ``T^(k)_{m-1}`` in ``tb`` (rows ``ts`` apart), swept into level ``m`` once a block."""
    ud = np.uint64(d)
    n = np.uint64(d ** (m - 1))
    n1 = np.uint64(d ** (m - 2))
    ok = offsets[m]
    o1 = np.uint64(offsets[m - 1])
    cm1, cm = _top_chains(m, hs)
    for r in range(s.shape[0]):
        s[r] = 0.0
    for t0 in range(k0, k1, KBLOCK):
        nk = min(KBLOCK, k1 - t0)
        for k in range(nk):
            kk = np.uint64(k)
            _increment(x, b, t0 + k, k, d, dl, delta)
            _fused_lower(s, delta, d, m, offsets, fac, buf, hs)
            to = kk * np.uint64(ts)
            for q in range(ud):
                row = o1 + q * n1
                _row_tail(tb, to + q * n1, buf, cm, delta[q] * fac[2], s, row, n1)
                _row_tail(s, row, buf, cm1, delta[q], s, row, n1)
        _top_sweep(s, ok, n, n, d, tb, ts, dl, nk, w)


@njit(cache=True, inline="always")
def _unit_two(x, b, k0, k1, s, d, m, offsets, fac, buf, hs, cs, cst, tt, ts, dl, delta, w):
    """:func:`_unit_inplace` with levels ``m - 1`` and ``m`` both deferred over a block of ``K`` segments.

    Levels ``1..m-2`` advance a segment at a time (:func:`_fused_lower`) and leave, for each segment ``k``, the chains
    ``C^m_{m-2}`` and ``C^{m-1}_{m-2}`` (``cs``, rows ``cst`` apart: ``2 K d^(m-2)`` entries). Then, for each chunk of
    :data:`CHUNK` words ``p`` of level ``m - 2`` and each last letter ``q``, the entries ``p + d^(m-2) q`` of level
    ``m - 1`` advance through the block's segments in registers, their ``T^(k)_{m-1} = C^m_{m-2}[p] (D_k[q] / 2) +
    S^(k-1)_{m-1}`` going to ``tt`` (``K x CHUNK`` entries, in the L1 cache), which :func:`_top_sweep` adds to level
    ``m`` at once. Every entry gets the operations of :func:`~roughpaths.signatures._blocked._fused_d` in the same
    order (the same bits); a block reads and writes ``S_m`` once and ``cs`` once, where :func:`_unit_inplace` writes
    and reads back ``K d^(m-1)`` entries of ``T``. The entries of ``tt`` past a chunk's last (up to a packed row) hold
    an earlier chunk's or zeros: the sweep's padded lanes read them and never copy them back."""
    L = np.uint64(LANES)
    ud = np.uint64(d)
    n = np.uint64(d ** (m - 1))
    n1 = np.uint64(d ** (m - 2))
    ok = np.uint64(offsets[m])
    o1 = np.uint64(offsets[m - 1])
    ucst = np.uint64(cst)
    uts = np.uint64(ts)
    cm1, cm = _top_chains(m, hs)
    for r in range(s.shape[0]):
        s[r] = 0.0
    for t0 in range(k0, k1, KBLOCK):
        nk = min(KBLOCK, k1 - t0)
        unk = np.uint64(nk)
        for k in range(nk):
            kk = np.uint64(k)
            _increment(x, b, t0 + k, k, d, dl, delta)
            _fused_lower(s, delta, d, m, offsets, fac, buf, hs)
            o = 2 * kk * ucst
            for i in range(n1):
                cs[o + i] = buf[cm + i]
                cs[o + ucst + i] = buf[cm1 + i]
        for p0 in range(np.uint64(0), n1, np.uint64(CHUNK)):
            a = min(np.uint64(CHUNK), n1 - p0)
            av = a - a % L
            for q1 in range(ud):
                row = o1 + q1 * n1 + p0
                for i in range(np.uint64(0), av, L):
                    sv = vload(s, row + i)
                    for k in range(unk):
                        e = k * ud + q1
                        c = 2 * k * ucst + p0 + i
                        vstore(tt, k * uts + i, vadd(vmul(vload(cs, c), vsplat(dl[e] * fac[2])), sv))
                        sv = vadd(vmul(vload(cs, c + ucst), vsplat(dl[e])), sv)
                    vstore(s, row + i, sv)
                for i in range(av, a):
                    sv = s[row + i]
                    for k in range(unk):
                        e = k * ud + q1
                        c = 2 * k * ucst + p0 + i
                        tt[k * uts + i] = cs[c] * (dl[e] * fac[2]) + sv
                        sv = cs[c + ucst] * dl[e] + sv
                    s[row + i] = sv
                _top_sweep(s, ok + q1 * n1 + p0, a, n, d, tt, ts, dl, nk, w)
