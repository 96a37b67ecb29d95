"""The blocked kernel's unit at depth 3, level 2 kept transposed (private).

Called by :mod:`roughpaths.signatures._blocked` for its depth-3 variant (:func:`~roughpaths.signatures._blocked.
block_key`). Layout and arithmetic are :mod:`roughpaths.signatures._blocked`'s: each entry gets the operations of the
segment-by-segment update in the same order, so the bits are the same.

At depth 3 the lower levels are level 1 (``d`` entries) and level 2 (``d x d``), and :func:`~roughpaths.signatures.
_blocked._fused_d` writes level 2 and the block's ``T_2`` as ``d`` rows ``q`` (the increment's letter) of ``d``
entries ``i``, ``S_2[q, i] <- C_2[i] D[q] + S_2[q, i]`` and ``T_2[q, i] = C_3[i] (D[q] / 2) + S_2[q, i]``, with the
chains ``C_l[i] = D[i] / l + S_1[i]`` stored to memory and read back as packed rows. Here the rows run over ``i``
with the packed lanes over ``q``: ``C_2[i]`` and ``C_3[i]`` are scalars in registers (nothing stored and read back),
the packed rows of ``D`` and ``D / 2`` are reused by every row, and a row of level 2 is read once for both products.
Level 2 lives transposed in a private buffer whose rows are whole packed rows (no row's packed row runs into the next
one), ``T_2``'s rows go to the block transposed, so the top level is summed transposed in a private buffer, and the
unit's end copies both back in the library's layout. Products are the same numbers (``a b = b a`` in IEEE
arithmetic), and every sum is formed in the same order.

Measured (one thread, 16 x 256 points, the kernel alone, minimum of 40 calls), ns a segment against
:func:`~roughpaths.signatures._blocked._unit_d`: see :func:`~roughpaths.signatures._blocked.runtime_key`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore
from ._sweep import KBLOCK, _increment, _top_sweep


@njit(cache=True, inline="always")
def _chains(lw, delta, i, half, third):
    """``C_2[i] = D[i] / 2 + S_1[i]`` and ``C_3[i] = D[i] / 3 + S_1[i]`` as packed rows; ``S_1[i] += D[i]``."""
    di = delta[i]
    s1 = lw[i]
    c2 = di * half + s1
    c3 = di * third + s1
    lw[i] = s1 + di
    return vsplat(c2), vsplat(c3)


@njit(cache=True, inline="always")
def _rows_n(lw, delta, tb, to, ud, ur2, half, third):
    """Level 2 (transposed, rows ``ur2`` apart from ``ur2``) advances a segment, and row ``to`` of the block's
    ``T_2`` (transposed) is written: ``T_2[q, i] = C_3[i] (D[q] / 2) + S_2[q, i]``, ``S_2[q, i] <- C_2[i] D[q] +
    S_2[q, i]``, packed over ``q``. A row of ``T_2``'s last packed row runs into the next row (written next) or past
    the last (zeros: the lanes past ``d`` of ``D`` and of level 2 are zero)."""
    L = np.uint64(LANES)
    hv = vsplat(half)
    for i in range(ud):
        c2v, c3v = _chains(lw, delta, i, half, third)
        row = ur2 * (np.uint64(1) + i)
        for p in range(np.uint64(0), ud, L):
            s2 = vload(lw, row + p)
            dq = vload(delta, p)
            vstore(tb, to + i * ud + p, vadd(vmul(c3v, vmul(dq, hv)), s2))
            vstore(lw, row + p, vadd(vmul(c2v, dq), s2))


@njit(cache=True, inline="always")
def _rows_1(lw, delta, tb, to, ud, half, third):
    """:func:`_rows_n` for ``d <= LANES`` (one packed row, ``D`` and ``D / 2`` kept in registers)."""
    L = np.uint64(LANES)
    d0 = vload(delta, 0)
    h0 = vmul(d0, vsplat(half))
    for i in range(ud):
        c2v, c3v = _chains(lw, delta, i, half, third)
        row = L * (np.uint64(1) + i)
        s2 = vload(lw, row)
        vstore(tb, to + i * ud, vadd(vmul(c3v, h0), s2))
        vstore(lw, row, vadd(vmul(c2v, d0), s2))


@njit(cache=True, inline="always")
def _rows_2(lw, delta, tb, to, ud, half, third):
    """:func:`_rows_n` for ``LANES < d <= 2 LANES`` (two packed rows in registers)."""
    L = np.uint64(LANES)
    hv = vsplat(half)
    d0 = vload(delta, 0)
    d1 = vload(delta, L)
    h0 = vmul(d0, hv)
    h1 = vmul(d1, hv)
    for i in range(ud):
        c2v, c3v = _chains(lw, delta, i, half, third)
        row = 2 * L * (np.uint64(1) + i)
        s2a = vload(lw, row)
        s2b = vload(lw, row + L)
        r = to + i * ud
        vstore(tb, r, vadd(vmul(c3v, h0), s2a))
        vstore(tb, r + L, vadd(vmul(c3v, h1), s2b))
        vstore(lw, row, vadd(vmul(c2v, d0), s2a))
        vstore(lw, row + L, vadd(vmul(c2v, d1), s2b))


@njit(cache=True, inline="always")
def _unit_3(x, b, k0, k1, s, d, fac, tb, ts, dl, delta, w, lw, r2, sp):
    """Signature (reversed layout) of points ``k0..k1`` of path ``b`` into ``s``, depth 3.

    ``lw``: level 1 (``r2`` entries) then level 2 transposed, row ``i`` at ``r2 (1 + i)`` (``r2``: ``d`` rounded up
    to whole packed rows); ``sp``: level 3 transposed in its first two letters (``d^3`` entries); ``delta`` zero
    past its ``d`` entries up to a packed row (the lanes past ``d`` then stay zero in ``lw``).
    """
    L = np.uint64(LANES)
    ud = np.uint64(d)
    ur2 = np.uint64(r2)
    n = ud * ud
    half = fac[2]
    third = fac[3]
    for r in range(ur2 * (ud + np.uint64(1))):
        lw[r] = 0.0
    for r in range(n * ud):
        sp[r] = 0.0
    for t0 in range(k0, k1, KBLOCK):
        nk = min(KBLOCK, k1 - t0)
        for k in range(nk):
            _increment(x, b, t0 + k, k, d, dl, delta)
            to = np.uint64(k) * np.uint64(ts)
            if ur2 == L:
                _rows_1(lw, delta, tb, to, ud, half, third)
            elif ur2 == 2 * L:
                _rows_2(lw, delta, tb, to, ud, half, third)
            else:
                _rows_n(lw, delta, tb, to, ud, ur2, half, third)
        _top_sweep(sp, 0, n, n, d, tb, ts, dl, nk, w)
    for i in range(ud):
        s[i] = lw[i]
    for i in range(ud):
        row = ur2 * (np.uint64(1) + i)
        for q in range(ud):
            s[ud + q * ud + i] = lw[row + q]
    o3 = ud + n
    for q3 in range(ud):
        for q in range(ud):
            for i in range(ud):
                s[o3 + q3 * n + q * ud + i] = sp[q3 * n + i * ud + q]
