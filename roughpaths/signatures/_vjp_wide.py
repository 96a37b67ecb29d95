"""Backward pass of the signature for d >= 6, the top level in blocks of segments (private).

Called by :mod:`roughpaths.signatures.gradients` for every ``d >= 6`` (``_engine._WIDE``: every
unit runs alone there, no lane kernel to match bit for bit). The arithmetic of
:func:`roughpaths.signatures._vjp.sig_vjp_units` (reversed layout, backward through
``S = S_prev ⊗ exp(D)`` segment by segment, last to first), with the top level ``m`` handled apart:

* the cotangent of the top level, ``G_m``, is the same for every segment (``G ◁ exp(D)`` changes
  levels ``< m`` only), and the signature's top level is never read backward: ``S_prev`` is
  recovered at depth ``m - 1``;
* the top level's two products with ``G_m`` per segment, ``gB_{m-1} = G_m · D`` (the cotangent
  of ``T_{m-1}``) and ``gD[q] += <G_m[., q], T_{m-1}>``, are matrix products over a block of
  :data:`KB` segments: the first before the block (the increments are known), the second after it
  (the ``T_{m-1}`` of its segments kept), each reading ``G_m`` once a block (register-blocked
  sweeps, about 0.15 ns a product here, instead of one pass over ``G_m`` per segment and product).

Levels ``< m`` go through :func:`roughpaths.signatures._vjp._step_vjp_d` at depth ``m - 1`` and the
rest of the top level's backward chain as in it. The order of the sums differs from
``sig_vjp_units`` (the dot products with ``G_m`` are summed in LANES running sums), and is fixed
for a given ``d`` and ``m``: a unit's bits do not depend on its batch or the thread count.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants
from ._lanes import _horner_step_d, _wide_step, step_key
from ._simd import LANES, vadd, vload, vmul, vsplat, vstore
from ._vjp import _dot_wide, _step_vjp_d, _tb_row

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)

#: Segments whose top-level products with ``G_m`` are formed in one sweep.
KB = 16


@njit(cache=True, inline="always")
def _gb_block(g, ok, n, d, dl, nk, out):
    """``out[k n + p] = sum_q g[ok + q n + p] dl[k d + q]`` for ``k < nk`` (``q`` in order)."""
    L = np.uint64(LANES)
    un = np.uint64(n)
    ud = np.uint64(d)
    n1 = un - un % L
    k4 = np.uint64(nk - nk % 4)
    for p in range(np.uint64(0), n1, L):
        for k in range(np.uint64(0), k4, np.uint64(4)):
            a0 = vsplat(0.0)
            a1 = vsplat(0.0)
            a2 = vsplat(0.0)
            a3 = vsplat(0.0)
            for q in range(ud):
                gv = vload(g, np.uint64(ok) + q * un + p)
                a0 = vadd(a0, vmul(gv, vsplat(dl[k * ud + q])))
                a1 = vadd(a1, vmul(gv, vsplat(dl[(k + 1) * ud + q])))
                a2 = vadd(a2, vmul(gv, vsplat(dl[(k + 2) * ud + q])))
                a3 = vadd(a3, vmul(gv, vsplat(dl[(k + 3) * ud + q])))
            vstore(out, k * un + p, a0)
            vstore(out, (k + 1) * un + p, a1)
            vstore(out, (k + 2) * un + p, a2)
            vstore(out, (k + 3) * un + p, a3)
        for k in range(k4, np.uint64(nk)):
            a0 = vsplat(0.0)
            for q in range(ud):
                a0 = vadd(a0, vmul(vload(g, np.uint64(ok) + q * un + p), vsplat(dl[k * ud + q])))
            vstore(out, k * un + p, a0)
    for k in range(np.uint64(nk)):
        for p in range(n1, un):
            a = 0.0
            for q in range(ud):
                a += g[np.uint64(ok) + q * un + p] * dl[k * ud + q]
            out[k * un + p] = a


@njit(cache=True, inline="always")
def _dot_end(v, tmp, g, row, tk, t, n1, un):
    """The LANES running sums ``v`` added in order, then the products past the last full row."""
    vstore(tmp, 0, v)
    a = tmp[0]
    for i in range(1, LANES):
        a += tmp[i]
    for p in range(n1, un):
        a += g[row + p] * tk[t + p]
    return a


@njit(cache=True, inline="always")
def _gd_block(g, ok, n, d, tk, nk, gdl, tmp):
    """``gdl[k d + q] += sum_p g[ok + q n + p] tk[k n + p]`` (LANES running sums, then the tail)."""
    L = np.uint64(LANES)
    un = np.uint64(n)
    ud = np.uint64(d)
    n1 = un - un % L
    k4 = np.uint64(nk - nk % 4)
    for q in range(ud):
        row = np.uint64(ok) + q * un
        for k in range(np.uint64(0), k4, np.uint64(4)):
            a0 = vsplat(0.0)
            a1 = vsplat(0.0)
            a2 = vsplat(0.0)
            a3 = vsplat(0.0)
            for p in range(np.uint64(0), n1, L):
                gv = vload(g, row + p)
                a0 = vadd(a0, vmul(gv, vload(tk, k * un + p)))
                a1 = vadd(a1, vmul(gv, vload(tk, (k + 1) * un + p)))
                a2 = vadd(a2, vmul(gv, vload(tk, (k + 2) * un + p)))
                a3 = vadd(a3, vmul(gv, vload(tk, (k + 3) * un + p)))
            gdl[k * ud + q] += _dot_end(a0, tmp, g, row, tk, k * un, n1, un)
            gdl[(k + 1) * ud + q] += _dot_end(a1, tmp, g, row, tk, (k + 1) * un, n1, un)
            gdl[(k + 2) * ud + q] += _dot_end(a2, tmp, g, row, tk, (k + 2) * un, n1, un)
            gdl[(k + 3) * ud + q] += _dot_end(a3, tmp, g, row, tk, (k + 3) * un, n1, un)
        for k in range(k4, np.uint64(nk)):
            a0 = vsplat(0.0)
            for p in range(np.uint64(0), n1, L):
                a0 = vadd(a0, vmul(vload(g, row + p), vload(tk, k * un + p)))
            gdl[k * ud + q] += _dot_end(a0, tmp, g, row, tk, k * un, n1, un)


@njit(cache=True, inline="always")
def _top_back(s, g, delta, d, m, offsets, gbt, go, gprev, tb, ga, gb, gdelta):
    """The top level's share of the step's backward pass, given ``gB_{m-1}`` (``gbt[go:]``).

    Forms ``T_1 .. T_{m-1}`` (into ``tb`` at the level offsets), sets ``gprev``'s level ``m - 1`` to
    ``G_{m-1} + gB_{m-1}``, then walks ``gB_j`` down as :func:`~roughpaths.signatures._vjp._step_vjp_d`."""
    inv = 1.0 / m
    for q in range(d):
        tb[q] = delta[q] * inv + s[q]
    size = d
    for j in range(1, m - 1):
        f = 1.0 / (m - j)
        oj = offsets[j]
        on = offsets[j + 1]
        for q in range(d):
            base = on + size * q
            _tb_row(tb, base, tb, oj, size, delta[q] * f, s, base)
        size *= d
    nt = d ** (m - 1)
    ot = offsets[m - 1]
    for p in range(nt):
        gprev[ot + p] = g[ot + p] + gbt[go + p]
        ga[p] = gbt[go + p]
    for j in range(m - 2, 0, -1):
        f = 1.0 / (m - j)
        nj = d ** j
        oj = offsets[j]
        for p in range(nj):
            gb[p] = 0.0
        for q in range(d):
            base = nj * q
            e = delta[q] * f
            for p in range(nj):
                gb[p] += ga[base + p] * e
            gdelta[q] += _dot_wide(ga, base, tb, oj, nj) * f
        for p in range(nj):
            gprev[oj + p] += gb[p]
            ga[p] = gb[p]
    for q in range(d):
        gdelta[q] += ga[q] * inv


@variants
def _sig_vjp_wide_kernel(K: int):
    """The compiled wide backward pass for the step variant ``K`` (:func:`~._lanes.step_key`)."""

    @njit(**_NOGIL)
    def sig_vjp_wide_variant(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd):
        d = x.shape[2]
        dim = offsets[m + 1]
        n = d ** (m - 1)
        w = (np.empty(2 * n + d), np.empty(dim), np.empty(n), np.empty(n), np.empty(dim), np.empty(d),
             np.empty(d), np.empty(d), np.empty(KB * d), np.empty(KB * n), np.empty(KB * n), np.empty(KB * d),
             np.empty(LANES))
        buf, tb, ga, gb, gn, delta, neg, gdelta, dl, gbt, tk, gdl, tmp = w
        ok = offsets[m]
        g = np.empty(dim)
        for u in range(lo, hi):
            for r in range(dim):
                g[r] = gunit[u, r]
            s = part[u].copy()
            # backward over the unit's segments, last first, in blocks of KB; one run-time d: a compile-time
            # d = 8 variant measured 20% faster at depth 3, but took 100 s more to compile
            b, lo_u = ub[u], ulo[u]
            for t0 in range(uhi[u], lo_u, -KB):
                nk = min(KB, t0 - lo_u)
                for k in range(nk):
                    for i in range(d):
                        dl[k * d + i] = x[b, t0 - k, i] - x[b, t0 - k - 1, i]
                _gb_block(g, ok, n, d, dl, nk, gbt)
                for k in range(nk):
                    for i in range(d):
                        delta[i] = dl[k * d + i]
                        neg[i] = -delta[i]
                    # S_prev, levels < m. The branch on the constant K is here, in the kernel, where numba prunes
                    # it before typing; in an inlined helper taking K as an argument every step kind was compiled
                    # (this kernel: 19.7 s to compile at d = 8, depth 3, against 8.0 s)
                    if K > 0:
                        _horner_step_d(s, neg, K, m - 1, offsets, buf)
                    elif K < 0:
                        _wide_step(s, neg, d, m - 1, offsets, buf)
                    else:
                        _horner_step_d(s, neg, d, m - 1, offsets, buf)
                    _step_vjp_d(s, g, delta, d, m - 1, offsets, gn, tb, ga, gb, gdelta)
                    _top_back(s, g, delta, d, m, offsets, gbt, k * n, gn, tb, ga, gb, gdelta)
                    for p in range(n):                              # T_{m-1} of this segment
                        tk[k * n + p] = tb[offsets[m - 1] + p]
                    for i in range(d):
                        gdl[k * d + i] = gdelta[i]
                    for r in range(ok):
                        g[r] = gn[r]
                _gd_block(g, ok, n, d, tk, nk, gdl, tmp)
                for k in range(nk):
                    for i in range(d):
                        gd[b, t0 - k - 1, i] = gdl[k * d + i]

    return sig_vjp_wide_variant


def sig_vjp_wide(d: int):
    """The wide backward kernel (d >= 6, m >= 3; compiled on first use, without the GIL):
    ``kernel(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd)`` writes the cotangents of the
    segment increments of units ``lo..hi-1`` into ``gd`` (B, n-1, d)."""
    return _sig_vjp_wide_kernel(step_key(d))
