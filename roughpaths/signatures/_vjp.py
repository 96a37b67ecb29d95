"""Vector–Jacobian products of the signature kernels (private; called by :mod:`roughpaths.signatures.signature`).

Reversed layout (word (i_1..i_k) at sum_j i_j d^(j-1)), so that a word u w splits as
index(u) + d^|u| index(w). Pairing <G, S> = sum over words (levels 1..m).
Backward through S = S_prev ⊗ exp(D) per segment (last to first):

* S_prev = S ⊗ exp(-D) (the same Horner step, nothing of the forward pass stored);
* then backward through the Horner step itself (:func:`_step_vjp_d`), which gives both the
  cotangent of D and G_prev = G ◁ exp(D) for about three Horner steps' work.

A unit's backward pass starts from the cotangent of its own signature: its path's for a path that is one
unit, else ``P ▷ (G ◁ Q)`` (P, Q the products of the path's units before and after it), formed for all units
first by :func:`unit_cotangents`, so that the backward kernels never compile that glue. :func:`_lcon` /
:func:`_rcon` (general contractions) serve it and the log's backward pass. Serial kernels over a range
``[lo, hi)`` of work items (GIL released).
:func:`sig_vjp_groups` runs the backward pass of LANES units side by side in packed registers
(about 4-5x faster than :func:`sig_vjp_units`, one unit at a time, and bitwise the same).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants
from ._lane_top import _top_registers, _top_rows
from ._lanes import (BLOCK, _addto, _axpy, _horner_step_d, _lane_step_d, _wide_step,
                     mul_inplace, step_key)
from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


@njit(cache=True, inline="always")
def _tb_row(tb, to, x, xo, n, e, s, so):
    """``tb[to:to+n] = x[xo:xo+n] * e + s[so:so+n]`` (unsigned indices: vectorised)."""
    u = np.uint64(to)
    v = np.uint64(xo)
    w = np.uint64(so)
    for p in range(np.uint64(n)):
        tb[u + p] = x[v + p] * e + s[w + p]


@njit(cache=True, inline="always")
def _dot_wide(a, ao, b, bo, n):
    """``sum_p a[ao+p] b[bo+p]`` in four running sums (``p mod 4``) added as ``(s0 + s1) + (s2 + s3)``:
    a fixed order (a function of ``n`` only) without one long chain of dependent additions."""
    u = np.uint64(ao)
    v = np.uint64(bo)
    n4 = np.uint64(n - n % 4)
    s0 = s1 = s2 = s3 = 0.0
    for p in range(np.uint64(0), n4, np.uint64(4)):
        s0 += a[u + p] * b[v + p]
        s1 += a[u + p + 1] * b[v + p + 1]
        s2 += a[u + p + 2] * b[v + p + 2]
        s3 += a[u + p + 3] * b[v + p + 3]
    for p in range(n4, np.uint64(n)):
        s0 += a[u + p] * b[v + p]
    return (s0 + s1) + (s2 + s3)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _lcon(x0, s, g, d, m, offsets, out):
    """``out <- (x0 + s) ▷ g``: ``out_j[w] = x0 g_j[w] + sum_{i>=1} sum_u s_i[u] g_{i+j}[u w]``.

    Per path, never per lane: the sums over ``u`` run in :func:`_dot_wide` for every ``d``."""
    for j in range(1, m + 1):
        oj = offsets[j]
        nj = d ** j
        for w in range(nj):
            out[oj + w] = x0 * g[oj + w]
        for i in range(1, m - j + 1):
            ni = d ** i
            oi = offsets[i]
            ok = offsets[i + j]
            for w in range(nj):
                out[oj + w] += _dot_wide(s, oi, g, ok + ni * w, ni)


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _rcon(x0, g, e, d, m, offsets, out):
    """``out <- g ◁ (x0 + e)``: ``out_i[p] = x0 g_i[p] + sum_{j>=1} sum_q g_{i+j}[p q] e_j[q]``."""
    for i in range(1, m + 1):
        oi = offsets[i]
        ni = d ** i
        for p in range(ni):
            out[oi + p] = x0 * g[oi + p]
        for j in range(1, m - i + 1):
            oj = offsets[j]
            ok = offsets[i + j]
            for q in range(d ** j):
                _axpy(out, oi, g, ok + ni * q, ni, e[oj + q])


@njit(cache=True, inline="always")
def _step_vjp_d(s, g, delta, d, m, offsets, gprev, tb, ga, gb, gdelta):
    """Backward through one Horner step ``S_cur = S ⊗ exp(delta)`` (``s`` = S before the step).

    Level ``k`` of the step is ``S_k + B_k`` with ``B_1 = delta/k``, ``T_j = B_j + S_j``,
    ``B_{j+1} = T_j ⊗ delta / (k - j)``. Per level: recompute the ``T_j`` (kept in ``tb``, at
    the level offsets), then walk back ``gT_j = (gB_{j+1} ◁ delta)/(k-j)``,
    ``gdelta += (T_j ▷ gB_{j+1})/(k-j)``. ``gprev <- G ◁ exp(delta)`` (cotangent of S) and
    ``gdelta`` (cotangent of delta) are written (levels ``< m`` of ``gprev``: its top level is
    ``G_m``); ``ga``, ``gb`` are scratch of ``d^m``. The same operations, in the same order, as
    every lane of :func:`_lane_step_vjp_d`, the dot products in the four sums of :func:`_dot_wide`
    (one chain of dependent additions measured 3x slower on a lone 4^8 path).
    """
    for r in range(offsets[m]):                             # levels < m (gprev_m = g_m: never copied)
        gprev[r] = g[r]
    for q in range(d):
        gdelta[q] = g[q]
    for k in range(m, 1, -1):
        # forward: T_1 = delta/k + S_1, T_{j+1} = T_j ⊗ delta/(k-j) + S_{j+1}
        inv = 1.0 / k
        for q in range(d):
            tb[q] = delta[q] * inv + s[q]
        size = d
        for j in range(1, k - 1):
            f = 1.0 / (k - j)
            oj = offsets[j]
            on = offsets[j + 1]
            for q in range(d):
                base = on + size * q
                _tb_row(tb, base, tb, oj, size, delta[q] * f, s, base)
            size *= d
        # backward: gB_k = G_k (read in place from g), then gB_j in ga
        ok = offsets[k]
        for j in range(k - 1, 0, -1):
            f = 1.0 / (k - j)
            nj = d ** j
            oj = offsets[j]
            for p in range(nj):
                gb[p] = 0.0
            for q in range(d):
                if j == k - 1:
                    base = ok + nj * q
                    _axpy(gb, 0, g, base, nj, delta[q] * f)
                    gdelta[q] += _dot_wide(g, base, tb, oj, nj) * f
                else:
                    base = nj * q
                    _axpy(gb, 0, ga, base, nj, delta[q] * f)
                    gdelta[q] += _dot_wide(ga, base, tb, oj, nj) * f
            _addto(gprev, oj, gb, 0, nj)
            for p in range(nj):
                ga[p] = gb[p]
        for q in range(d):
            gdelta[q] += ga[q] * inv


def vjp_key(d: int) -> int:
    """The compile-time alphabet size of the backward step's variant (0: at run time)."""
    return d if d in (2, 3) else 0


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _unit_cotangent(part, gtot, u, nchunks, d, m, offsets, g):
    """Cotangent of unit ``u``'s signature: ``P ▷ (G ◁ Q)``, P/Q the products of the units before/after."""
    dim = offsets[m + 1]
    b = u // nchunks
    c = u - b * nchunks
    q = np.zeros(dim)
    for cc in range(c + 1, nchunks):
        mul_inplace(q, part[b * nchunks + cc], d, m, offsets)
    tmp = np.empty(dim)
    _rcon(1.0, gtot[b], q, d, m, offsets, tmp)
    pre = np.zeros(dim)
    for cc in range(c):
        mul_inplace(pre, part[b * nchunks + cc], d, m, offsets)
    _lcon(1.0, pre, tmp, d, m, offsets, g)


@njit(**_NOGIL)
def unit_cotangents(part, gtot, nchunks, d, m, offsets, lo, hi, out):
    """``out[u]``, the cotangent of unit ``u``'s signature (:func:`_unit_cotangent`), for units ``lo..hi-1`` of
    paths cut into ``nchunks > 1`` units. Unchunked paths need none: a unit's cotangent is its path's, ``gtot``
    itself, which the backward kernels take as it is (so they never compile this glue: 0.8-1.2 s of a first
    gradient). Compiled on the first gradient of paths cut into units: 1.7 s cold with the glue it calls
    (``benchmarks/bench_first_call.py``, "signature_vjp, long paths": 6.2 s in all)."""
    for u in range(lo, hi):
        _unit_cotangent(part, gtot, u, nchunks, d, m, offsets, out[u])


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _mul_rev(x0, xs, a, d, m, offsets, out):
    """``out <- (x0 + xs) ⊗ a`` (``a`` with no scalar), reversed layout, levels 1..m."""
    for k in range(1, m + 1):
        ok = offsets[k]
        for r in range(d ** k):
            out[ok + r] = x0 * a[ok + r]
        for i in range(1, k):
            oi = offsets[i]
            oj = offsets[k - i]
            ni = d ** i
            for q in range(d ** (k - i)):
                _axpy(out, ok + ni * q, xs, oi, ni, a[oj + q])


@njit(cache=True, inline="always")
def _log_vjp_one(a, g, d, m, offsets, ga):
    """``ga <- d/da <g, log(1 + a)>`` (reversed layout), backward through the Horner recursion
    ``r_m = c_m a``, ``r_n = (c_n + r_{n+1}) ⊗ a``, ``log(1 + a) = r_1``. Only levels ``<= m - n + 1``
    of ``r_n`` (and of its cotangent) reach the result: each step runs at that depth (about
    ``1 + 1/d + ...`` full products instead of ``m - 1``; the dropped terms are exact zeros)."""
    dim = offsets[m + 1]
    r = np.zeros((m + 2, dim))
    for u in range(d):
        r[m, u] = a[u] * ((-1.0) ** (m + 1) / m)
    for n in range(m - 1, 0, -1):
        c = (-1.0) ** (n + 1) / n
        _mul_rev(c, r[n + 1], a, d, m - n + 1, offsets, r[n])
    gc = g.copy()
    tmp = np.empty(dim)
    for u in range(dim):
        ga[u] = 0.0
    for n in range(1, m):
        c = (-1.0) ** (n + 1) / n
        mm = m - n + 1                                      # gc: the cotangent of r_n, levels <= mm
        _lcon(c, r[n + 1], gc, d, mm, offsets, tmp)
        for u in range(offsets[mm + 1]):
            ga[u] += tmp[u]
        _rcon(0.0, gc, a, d, mm, offsets, tmp)              # levels < mm: the cotangent of r_{n+1}
        for u in range(offsets[mm]):
            gc[u] = tmp[u]
    cm = (-1.0) ** (m + 1) / m
    for u in range(d):
        ga[u] += cm * gc[u]


@variants
def _sig_vjp_units_kernel(K: int, V: int):
    """The compiled one-unit backward pass for the step variants ``K`` (:func:`step_key`), ``V`` (:func:`vjp_key`)."""

    @njit(**_NOGIL)
    def sig_vjp_units_variant(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd):
        d = x.shape[2]
        dim = offsets[m + 1]
        g = np.empty(dim)
        buf = np.empty(2 * d ** max(m - 1, 1) + d)
        tb = np.empty(dim)
        ga = np.empty(d ** m)
        gb = np.empty(d ** m)
        gn = np.empty(dim)
        delta = np.empty(d)
        neg = np.empty(d)
        gdelta = np.empty(d)
        for u in range(lo, hi):
            for r in range(dim):
                g[r] = gunit[u, r]
            s = part[u].copy()
            b = ub[u]
            for k in range(uhi[u], ulo[u], -1):        # backward over the unit's segments, last first
                for i in range(d):
                    delta[i] = x[b, k, i] - x[b, k - 1, i]
                    neg[i] = -delta[i]
                # S_prev (its top level is never read): the branches on the constants K and V are here, in the
                # kernel, where numba prunes them before typing; in an inlined helper taking K or V as an argument
                # every branch was compiled (14.6 s for this kernel at d = 3, against 4.5 s). The same branch is
                # written out in each kernel that steps one unit (scalar_units, the wide VJP): pruned only there
                if K > 0:
                    _horner_step_d(s, neg, K, m - 1, offsets, buf)
                elif K < 0:
                    _wide_step(s, neg, d, m - 1, offsets, buf)
                else:
                    _horner_step_d(s, neg, d, m - 1, offsets, buf)
                if V > 0:
                    _step_vjp_d(s, g, delta, V, m, offsets, gn, tb, ga, gb, gdelta)
                else:
                    _step_vjp_d(s, g, delta, d, m, offsets, gn, tb, ga, gb, gdelta)
                for i in range(d):
                    gd[b, k - 1, i] = gdelta[i]
                for r in range(offsets[m]):               # the top level of g never changes
                    g[r] = gn[r]

    return sig_vjp_units_variant


def sig_vjp_units(d: int):
    """The one-unit backward kernel for alphabet size ``d`` (compiled on first use, without the GIL):
    ``kernel(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd)`` writes the cotangents of the segment
    increments of units ``lo..hi-1`` into ``gd`` (B, n-1, d), given their forward signatures ``part`` and the
    cotangents ``gunit`` of those (:func:`unit_cotangents`; for unchunked paths the paths'). Each variant's
    compiled symbols carry its key (:func:`roughpaths._variants._named`): :mod:`roughpaths.signatures.xla_handlers`
    finds the kernel by its name."""
    return _sig_vjp_units_kernel(step_key(d), vjp_key(d))


@njit(**_NOGIL)
def log_vjp_rows(a, g, d, m, offsets, lo, hi, out):
    """Row-wise :func:`_log_vjp_one` (reversed layout) for rows ``lo..hi-1``."""
    for b in range(lo, hi):
        _log_vjp_one(a[b], g[b], d, m, offsets, out[b])


# ---------------------------------------------------------------------------------- lanes
# The backward pass on LANES units side by side (rows of LANES values, roughpaths.signatures._simd), the
# operations of sig_vjp_units / _step_vjp_d on every lane; the sums over p are per lane, in the same
# order, so the results are bitwise those of sig_vjp_units. Units are aligned at their last
# segment: step tau handles segment uhi - tau of every unit that has it; the others get zero
# increments and their values are not used.


@njit(cache=True, inline="always")
def _lane_step_vjp_d(s, g, blk, do, d, m, offsets, gprev, tb, ga, gb, gdelta):
    """:func:`_step_vjp_d` on every lane; the increment is rows ``do/LANES ..`` of ``blk``."""
    L = LANES
    dim = offsets[m + 1]
    for r in range(dim):
        vstore(gprev, r * L, vload(g, r * L))
    for q in range(d):
        vstore(gdelta, q * L, vload(g, q * L))
    for k in range(m, 1, -1):
        inv = vsplat(1.0 / k)
        for q in range(d):
            vstore(tb, q * L, vadd(vmul(vload(blk, do + q * L), inv), vload(s, q * L)))
        size = d
        for j in range(1, k - 1):
            f = vsplat(1.0 / (k - j))
            oj = offsets[j] * L
            on = offsets[j + 1] * L
            for q in range(d):
                e = vmul(vload(blk, do + q * L), f)
                base = on + size * q * L
                for p in range(size):
                    vstore(tb, base + p * L, vadd(vmul(vload(tb, oj + p * L), e), vload(s, base + p * L)))
            size *= d
        ok = offsets[k] * L
        for r in range(d ** k):
            vstore(ga, r * L, vload(g, ok + r * L))
        for j in range(k - 1, 0, -1):
            f = vsplat(1.0 / (k - j))
            nj = d ** j
            oj = offsets[j] * L
            zero = vsplat(0.0)
            for p in range(nj):
                vstore(gb, p * L, zero)
            for q in range(d):
                e = vmul(vload(blk, do + q * L), f)
                base = nj * q * L
                a0 = a1 = a2 = a3 = vsplat(0.0)                  # the sums of _dot_wide, per lane
                for p in range(0, nj - nj % 4, 4):
                    a = vload(ga, base + p * L)
                    vstore(gb, p * L, vadd(vload(gb, p * L), vmul(a, e)))
                    a0 = vadd(a0, vmul(a, vload(tb, oj + p * L)))
                    a = vload(ga, base + (p + 1) * L)
                    vstore(gb, (p + 1) * L, vadd(vload(gb, (p + 1) * L), vmul(a, e)))
                    a1 = vadd(a1, vmul(a, vload(tb, oj + (p + 1) * L)))
                    a = vload(ga, base + (p + 2) * L)
                    vstore(gb, (p + 2) * L, vadd(vload(gb, (p + 2) * L), vmul(a, e)))
                    a2 = vadd(a2, vmul(a, vload(tb, oj + (p + 2) * L)))
                    a = vload(ga, base + (p + 3) * L)
                    vstore(gb, (p + 3) * L, vadd(vload(gb, (p + 3) * L), vmul(a, e)))
                    a3 = vadd(a3, vmul(a, vload(tb, oj + (p + 3) * L)))
                for p in range(nj - nj % 4, nj):
                    a = vload(ga, base + p * L)
                    vstore(gb, p * L, vadd(vload(gb, p * L), vmul(a, e)))
                    a0 = vadd(a0, vmul(a, vload(tb, oj + p * L)))
                acc = vadd(vadd(a0, a1), vadd(a2, a3))
                vstore(gdelta, q * L, vadd(vload(gdelta, q * L), vmul(acc, f)))
            for p in range(nj):
                b = vload(gb, p * L)
                vstore(gprev, oj + p * L, vadd(vload(gprev, oj + p * L), b))
                vstore(ga, p * L, b)
        for q in range(d):
            vstore(gdelta, q * L, vadd(vload(gdelta, q * L), vmul(vload(ga, q * L), inv)))


@njit(cache=True, inline="always")
def _back_block_d(x, ub, uhi, nsteps, grp, t0, nt, d, m, offsets, s, g, gn, blk, neg, buf, tb, ga, gb,
                  gdelta, gd, top):
    L = LANES
    for l in range(L):                                       # increments, last segment first
        u = grp * L + l
        live = min(max(nsteps[l] - t0, 0), nt)
        for t in range(live):
            b = ub[u]
            k = uhi[u] - t0 - t
            for i in range(d):
                v = x[b, k, i] - x[b, k - 1, i]
                blk[(t * d + i) * L + l] = v
                neg[(t * d + i) * L + l] = -v
        for t in range(live, nt):
            for i in range(d):
                blk[(t * d + i) * L + l] = 0.0
                neg[(t * d + i) * L + l] = 0.0
    for t in range(nt):
        do = t * d * L
        _lane_step_d(s, neg, do, d, m - 1, offsets, buf, top)  # S_prev = S ⊗ exp(-D): its top level is never read
        _lane_step_vjp_d(s, g, blk, do, d, m, offsets, gn, tb, ga, gb, gdelta)
        for l in range(L):
            if t0 + t < nsteps[l]:
                u = grp * L + l
                k = uhi[u] - t0 - t
                for i in range(d):
                    gd[ub[u], k - 1, i] = gdelta[i * L + l]
        dim = offsets[m + 1]
        for r in range(dim * L):
            g[r] = gn[r]


@variants
def _sig_vjp_groups_kernel(V: int):
    """The compiled lane backward pass for the variant ``V`` (:func:`vjp_key`)."""
    rows4k = V in (0, 2)               # rows of a level 4 KiB apart can occur (d = 2, 4): :func:`._lane_top._top_rows`

    @njit(**_NOGIL)
    def sig_vjp_groups_variant(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd):
        L = LANES
        T = BLOCK
        d = x.shape[2]
        dim = offsets[m + 1]
        nunits = ub.shape[0]
        s = np.empty(dim * L)
        g = np.empty(dim * L)
        gn = np.empty(dim * L)
        tb = np.empty(dim * L)
        ga = np.empty(d ** m * L)
        gb = np.empty(d ** m * L)
        gdelta = np.empty(d * L)
        blk = np.empty(T * d * L)
        neg = np.empty(T * d * L)
        buf = np.empty((2 * d ** max(m - 2, 1) + (d ** max(m - 1, 1) if rows4k else 0)) * L)     # _top_rows' T
        nsteps = np.zeros(L, dtype=np.int64)
        for grp in range(lo, hi):
            steps = 0
            for l in range(L):
                u = grp * L + l
                if u < nunits:
                    nsteps[l] = uhi[u] - ulo[u]
                    for r in range(dim):
                        s[r * L + l] = part[u, r]
                        g[r * L + l] = gunit[u, r]
                else:
                    nsteps[l] = 0
                    for r in range(dim):
                        s[r * L + l] = 0.0
                        g[r * L + l] = 0.0
                steps = max(steps, nsteps[l])
            for t0 in range(0, steps, T):
                nt = min(T, steps - t0)
                if rows4k:             # a branch on the variant's constant (see _lanes.lane_groups)
                    _back_block_d(x, ub, uhi, nsteps, grp, t0, nt, V if V else d, m, offsets, s, g, gn, blk, neg,
                                  buf, tb, ga, gb, gdelta, gd, _top_rows)
                else:
                    _back_block_d(x, ub, uhi, nsteps, grp, t0, nt, V if V else d, m, offsets, s, g, gn, blk, neg,
                                  buf, tb, ga, gb, gdelta, gd, _top_registers)

    return sig_vjp_groups_variant


def sig_vjp_groups(d: int):
    """The lane backward kernel for alphabet size ``d`` (compiled on first use, without the GIL):
    ``kernel(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd)``, :func:`sig_vjp_units` on lane
    groups ``lo..hi-1`` (units ``g*LANES ..``), the same bits."""
    return _sig_vjp_groups_kernel(vjp_key(d))