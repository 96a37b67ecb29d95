"""Depth >= 3 signature kernels: the Horner–Chen update, run on lanes (private).

Called by :mod:`roughpaths.signatures.signature`. Internally level k is stored in *reversed* word order:
word (i_1..i_k) at ``sum_j i_j d^(j-1)``, so that a tensor product ``a_j ⊗ b_l`` is
``out[p + d^j q] = a[p] b[q]``; the Python wrapper permutes to iisignature's order at the end.
``offsets[k]`` is the start of level k (``offsets[1] = 0``, ``offsets[m + 1] = sigdim``).

One segment with increment D updates the running signature S in place, ``S <- S ⊗ exp(D)``,
level by level from the top (Horner's scheme for the segment exponential):

    T_1 = D / k + S_1,   T_{j+1} = T_j ⊗ D / (k - j) + S_{j+1},   S_k <- S_k + T_{k-1} ⊗ D,

then ``S_1 <- S_1 + D``. Every product is rounded, then every sum (no fused multiply-add).

*Lanes.* :data:`~roughpaths.signatures._simd.LANES` work units (a path, or a chunk of a long path) advance
together, one segment per step; every array holds ``(entries, LANES)`` flattened, and every
operation is one packed instruction on a row of LANES values (:mod:`roughpaths.signatures._simd`). A lane
does exactly the scalar operations of :func:`_horner_step_d` on its own unit, so a unit's result
does not depend on its lane, its neighbours, the grouping or the thread. A unit's signature is
copied out at its own last segment; lanes with no segment left get zero increments. The increments
of a group are gathered and transposed into a ``(BLOCK, d, LANES)`` block first, and the kernel is
specialised (loops over the letters unrolled) for d = 2..5, and also on the depth for depth 3 with
d = 2, 3, 5; d = 6, 7 (which run on lanes at depth 3 only) on both.

*One unit.* :func:`scalar_units` runs units one at a time with :func:`_horner_step_d`, whose loops
run over the first letters of a level (contiguous, packed ``LANES`` first letters at a time or
vectorised by LLVM; for d = 6..15 :func:`_wide_step`, the same operations with less loop
control): the same bits as the lanes. The engine runs it for units of at most 7 segments that run
alone (``_engine.alone_kernel``); its other one-unit kernel is the blocked one
(:mod:`roughpaths.signatures._blocked`, the same bits again), used for every d >= 8, for d = 6, 7
beyond depth 3 and for d = 4, 5 where ``LANES`` signatures take more than 64 KiB (they no longer
fit in the L1 cache, and one unit's rows are long enough to fill the vector registers), and for a
lane group that would hold at most two units. d = 6, 7 at depth 3 run on lanes with a compile-time
``d`` and ``m`` (:func:`lane_key`).

*The top level deferred.* In the variants with d = 3, 5, 6, 7 the top level's ``T^(k)_{m-1}`` of each segment is
stored and added to ``S_m`` once every :data:`~roughpaths.signatures._lane_top.SUB` segments
(:func:`_block_deferred`), each entry of ``S_m`` loaded and stored once a sweep instead of once a segment (d = 2, 4
keep the per-segment update, whose rows 4 KiB apart :func:`~roughpaths.signatures._lane_top._top_rows` handles). The
same bits. One thread, CPU time a unit and segment, three interleaved process pairs against the per-segment update:
1000 x 1000 points, d = 3, depth 3 9.7-10.1 ns against 10.6-10.8; 64 x 256 points, d = 3 at depths 3/4/5/6
11.4-13.1 / 22.8-23.3 / 54-56 / 165-179 against 13.2-13.9 / 23.8-25.2 / 60-62 / 181-190, d = 5 at depths 3/4 24-25 /
92-104 against 26-27 / 122-125; 16 x 256 points at depth 3, d = 6 37-41 against 43-45, d = 7 47-52 against 57-59.

Measured (one thread, CPU time per unit and segment, this 2-core machine): d = 3 at depths
3/4/5 about 10/23/58 ns, d = 5 at depths 3/4/5 about 25/140/660 ns, 4-9x less than the same
loops written with scalar lane loops. At d = 5, depth 5 the LANES signatures (250 KB) live in
L2, not L1, and the kernel is bound by L2 bandwidth.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants

from ._lane_top import SUB, _lane_sweep, _top_registers, _top_rows, _top_stored
from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)

#: Segments per transposed block of increments.
BLOCK = 64


# Index arithmetic in unsigned integers: numba then emits no negative-index wrap-around, and
# LLVM vectorises the loops (with signed indices these loops stay scalar).
@njit(cache=True, inline="always")
def _axpy(y, yo, x, xo, n, a):
    """``y[yo:yo+n] += x[xo:xo+n] * a``."""
    u = np.uint64(yo)
    v = np.uint64(xo)
    for p in range(np.uint64(n)):
        y[u + p] += x[v + p] * a


@njit(cache=True, inline="always")
def _scaled(y, yo, x, xo, n, a):
    """``y[yo:yo+n] = x[xo:xo+n] * a``."""
    u = np.uint64(yo)
    v = np.uint64(xo)
    for p in range(np.uint64(n)):
        y[u + p] = x[v + p] * a


@njit(cache=True, inline="always")
def _addto(y, yo, x, xo, n):
    """``y[yo:yo+n] += x[xo:xo+n]``."""
    u = np.uint64(yo)
    v = np.uint64(xo)
    for p in range(np.uint64(n)):
        y[u + p] += x[v + p]


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def mul_inplace(s, e, d, m, offsets):
    """In place Chen product ``s <- s ⊗ e`` of group-like elements (implicit 1, reversed layout)."""
    for k in range(m, 0, -1):
        ok = offsets[k]
        for r in range(d ** k):
            s[ok + r] += e[ok + r]
        for j in range(1, k):
            # s_k[p + d^j q] += s_j[p] e_{k-j}[q]
            oj = offsets[j]
            oe = offsets[k - j]
            nj = d ** j
            for q in range(d ** (k - j)):
                _axpy(s, ok + q * nj, s, oj, nj, e[oe + q])


@njit(cache=True, inline="always")
def _outer(y, yo, ys, x, xo, s, so, n, sc, d, acc):
    """``y[yo + q ys + p] (+)= (x[xo + p] + s[so + p]) * sc[q]`` for ``p < n``, ``q < d`` (one unit).

    ``T = x + s`` is formed ``LANES`` first letters at a time in registers and used for every last
    letter ``q``; the ``n mod LANES`` first letters left over go one by one. Each entry gets the
    operations of :func:`_lane_step_d` (``T``, then ``T * sc[q]``, then the sum), in any case.
    """
    L = LANES
    if d < 6 or ys % 512 == 0 or n % LANES != 0:
        # rows 4 KiB apart: storing row q then loading row q + 1 would stall on 4K aliasing, so
        # form T in place in x and sweep one row at a time instead
        _addto(x, xo, s, so, n)
        for q in range(d):
            if acc:
                _axpy(y, yo + q * ys, x, xo, n, sc[q])
            else:
                _scaled(y, yo + q * ys, x, xo, n, sc[q])
        return
    n8 = n - n % L
    for p in range(0, n8, L):
        t = vadd(vload(x, xo + p), vload(s, so + p))
        for q in range(d):
            r = yo + q * ys + p
            if acc:
                vstore(y, r, vadd(vload(y, r), vmul(t, vsplat(sc[q]))))
            else:
                vstore(y, r, vmul(t, vsplat(sc[q])))
    for p in range(n8, n):
        t = x[xo + p] + s[so + p]
        for q in range(d):
            r = yo + q * ys + p
            if acc:
                y[r] += t * sc[q]
            else:
                y[r] = t * sc[q]


@njit(cache=True, inline="always")
def _horner_step_d(s, delta, d, m, offsets, buf):
    """``s <- s ⊗ exp(delta)`` in place (reversed layout), one unit; ``buf`` scratch of ``2 d^(m-1) + d`` floats.

    Packed over the first letters (:func:`_outer`), so it runs at SIMD width for any ``d``; the same bits as a
    lane of :func:`_lane_step_d`. Kernels pass a compile-time ``d`` (their step variant ``K``, :func:`step_key`)
    for d = 2..5 and call :func:`_wide_step` (the same bits) for d = 6..15, branching on ``K`` in their own body:
    numba prunes a branch on a kernel's constant before typing, not one on an inlined helper's argument.
    """
    half = d ** max(m - 1, 1)
    so = 2 * half                                           # the scaled increments sc[q]
    sc = buf[so:so + d]
    for lev in range(m, 1, -1):
        inv = 1.0 / lev
        for i in range(d):
            buf[i] = delta[i] * inv
        size = d
        cur = 0
        nxt = half
        for j in range(1, lev - 1):                         # B_{j+1} = (B_j + S_j) ⊗ D / (lev - j)
            f = 1.0 / (lev - j)
            for q in range(d):
                sc[q] = delta[q] * f
            _outer(buf, nxt, size, buf, cur, s, offsets[j], size, sc, d, False)
            size *= d
            cur, nxt = nxt, cur
        for q in range(d):
            sc[q] = delta[q]
        _outer(s, offsets[lev], size, buf, cur, s, offsets[lev - 1], size, sc, d, True)
    for i in range(d):
        s[i] += delta[i]


@njit(cache=True, inline="always")
def _wide_step(s, delta, d, m, offsets, buf):
    """:func:`_horner_step_d` for a run-time ``d`` (d = 6..15): the same operations in the same
    order (the same bits), written as plain loops over one flat buffer with unsigned offsets.

    No array views are made and no arrays are swapped (each costs reference-count updates), and
    ``T_{j+1} = T_j ⊗ D/(lev - j) + S_{j+1}`` is formed in one sweep; LLVM vectorises every
    inner loop. When ``d^(lev-2)`` is a multiple of ``LANES`` and the rows of level ``lev`` are
    not a multiple of 4 KiB apart (d = 8 at level 3), ``T_{lev-1}`` is formed ``LANES`` first
    letters at a time in registers and used at once, as in :func:`_lane_step_d` (one load fewer
    per entry of ``S_lev``; with rows 4 KiB apart this measured 1.6x slower: 4K aliasing).
    Measured at d = 8 (one thread, CPU time a segment): depth 3 265 ns (the older loops:
    420), depth 4 1900 ns (2170).
    """
    L = np.uint64(LANES)
    half = np.uint64(d ** max(m - 1, 1))
    ud = np.uint64(d)
    for lev in range(m, 1, -1):
        inv = 1.0 / lev
        for i in range(ud):                                  # T_1 = D / lev + S_1
            buf[i] = delta[i] * inv + s[i]
        size = ud
        cur = np.uint64(0)
        nxt = half
        fused = lev >= 3 and (ud ** np.uint64(lev - 2)) % L == 0 and (ud ** np.uint64(lev - 1)) % 512 != 0
        for j in range(1, lev - 2 if fused else lev - 1):    # T_{j+1} = T_j ⊗ D/(lev-j) + S_{j+1}
            f = 1.0 / (lev - j)
            o = np.uint64(offsets[j + 1])
            for q in range(ud):
                c = delta[q] * f
                base = q * size
                for p in range(size):
                    buf[nxt + base + p] = buf[cur + p] * c + s[o + base + p]
            size *= ud
            cur, nxt = nxt, cur
        ok = np.uint64(offsets[lev])
        if fused:                # T_{lev-1} = T_{lev-2} ⊗ D/2 + S_{lev-1} in registers, S_lev += T_{lev-1} ⊗ D
            o = np.uint64(offsets[lev - 1])
            big = size * ud
            for q1 in range(ud):
                c = vsplat(delta[q1] * 0.5)
                b1 = q1 * size
                for p in range(np.uint64(0), size, L):
                    t = vadd(vmul(vload(buf, cur + p), c), vload(s, o + b1 + p))
                    for q in range(ud):
                        r = ok + q * big + b1 + p
                        vstore(s, r, vadd(vload(s, r), vmul(t, vsplat(delta[q]))))
            continue
        for q in range(ud):                                  # S_lev += T_{lev-1} ⊗ D
            c = delta[q]
            base = ok + q * size
            for p in range(size):
                s[base + p] += buf[cur + p] * c
    for i in range(ud):
        s[i] += delta[i]


def step_key(d: int) -> int:
    """The compile-time variant of the one-unit step for alphabet size ``d`` (see :func:`_horner_step_d`):
    ``d`` itself for d = 2..5, -1 for d = 6..15 (:func:`_wide_step`), 0 for a run-time ``d``."""
    return d if 2 <= d <= 5 else (-1 if d < 16 else 0)


@njit(cache=True, inline="always")
def _lane_step_d(s, delta, do, d, m, offsets, buf, top):
    """``S <- S ⊗ exp(D)`` on every lane; ``D`` is rows ``do/LANES ..`` of ``delta``.

    ``T_1 .. T_{k-2}`` go through ``buf`` (two blocks of ``d^(m-2)`` rows, then ``d^(m-1)`` for :func:`_top_rows`);
    ``T_{k-1}``, the largest, and the update of the top level are ``top``'s: :func:`_top_registers`,
    :func:`_top_rows` or :func:`_top_stored` (the top level's ``T`` kept for a later sweep), chosen by the kernel for
    its ``d`` (:mod:`roughpaths.signatures._lane_top`).
    """
    L = LANES
    half = d ** max(m - 2, 1) * L
    for lev in range(m, 1, -1):
        ok = offsets[lev] * L
        if lev == 2:                                         # S_2 += (D/2 + S_1) ⊗ D
            inv = vsplat(0.5)
            for p in range(d):
                t1 = vadd(vmul(vload(delta, do + p * L), inv), vload(s, p * L))
                for q in range(d):
                    r = ok + (p + q * d) * L
                    vstore(s, r, vadd(vload(s, r), vmul(t1, vload(delta, do + q * L))))
            continue
        inv = vsplat(1.0 / lev)
        for i in range(d):                                   # T_1 = D / lev + S_1
            vstore(buf, i * L, vadd(vmul(vload(delta, do + i * L), inv), vload(s, i * L)))
        size = d
        cur = 0
        nxt = half
        for j in range(1, lev - 2):                          # T_{j+1} = T_j ⊗ D/(lev-j) + S_{j+1}
            f = vsplat(1.0 / (lev - j))
            o = offsets[j + 1] * L
            for p in range(size):
                t = vload(buf, cur + p * L)
                for q in range(d):
                    r = (p + q * size) * L
                    sc = vmul(vload(delta, do + q * L), f)
                    vstore(buf, nxt + r, vadd(vmul(t, sc), vload(s, o + r)))
            size *= d
            cur, nxt = nxt, cur
        # T_{lev-1} = T_{lev-2} ⊗ D/2 + S_{lev-1}; S_lev += T_{lev-1} ⊗ D
        top(s, delta, do, d, ok, offsets[lev - 1] * L, size, cur, buf, half)
    for i in range(d):
        vstore(s, i * L, vadd(vload(s, i * L), vload(delta, do + i * L)))


@njit(cache=True, inline="always")
def _block_d(s, blk, nt, t0, g, nsteps, d, m, offsets, buf, part, top):
    """Segments ``t0 .. t0+nt-1`` of group ``g`` (increments in ``blk``); copies out the units that end."""
    L = LANES
    dim = offsets[m + 1]
    for t in range(nt):
        _lane_step_d(s, blk, t * d * L, d, m, offsets, buf, top)
        for l in range(L):
            if nsteps[l] == t0 + t + 1:                      # unit done: copy it out
                u = g * L + l
                for r in range(dim):
                    part[u, r] = s[r * L + l]


@njit(cache=True, inline="always")
def _block_deferred(s, blk, nt, t0, g, nsteps, d, m, offsets, buf, part):
    """:func:`_block_d` with the top level deferred over :data:`~roughpaths.signatures._lane_top.SUB` segments
    (:func:`~roughpaths.signatures._lane_top._top_stored`, then one sweep); a unit that ends is copied out after the
    sweep of its segment (the zero increments of the segments left are an exact identity on a finite signature:
    no entry is -0.0, whose sign adding +0.0 would change)."""
    L = LANES
    dim = offsets[m + 1]
    big = d ** (m - 1)
    base = 2 * d ** max(m - 2, 1) * L
    for t in range(nt):
        _lane_step_d(s, blk, t * d * L, d, m, offsets, buf, _top_stored)
        if (t + 1) % SUB == 0 or t == nt - 1:
            k0 = t - t % SUB
            _lane_sweep(s, offsets[m] * L, big, d, buf, base, t + 1 - k0, blk, k0)
            for l in range(L):
                if k0 < nsteps[l] - t0 <= t + 1:             # unit done: copy it out
                    u = g * L + l
                    for r in range(dim):
                        part[u, r] = s[r * L + l]


@njit(cache=True, inline="always")
def _gather_d(x, ub, ulo, nsteps, g, t0, nt, d, blk):
    L = LANES
    for l in range(L):
        live = min(max(nsteps[l] - t0, 0), nt)
        if live > 0:
            u = g * L + l
            k0 = ulo[u] + t0
            seg = x[ub[u], k0:k0 + live + 1]
            for t in range(live):
                for i in range(d):
                    blk[(t * d + i) * L + l] = seg[t + 1, i] - seg[t, i]
        for t in range(live, nt):
            for i in range(d):
                blk[(t * d + i) * L + l] = 0.0


def lane_key(d: int, m: int) -> tuple:
    """``(D, M)``: the compile-time alphabet size and depth of the lane kernel's variant (0: at run time).

    A compile-time ``d`` lets LLVM unroll the loops over the letters (d = 2..5); depth 3 with d = 2, 3 or 5
    also gets a compile-time ``m``, which unrolls the loops over the levels (about 10 % faster at d = 3;
    at d = 2, 16 x 256 points, 15 us against 44, where pysiglib ``n_jobs=1`` takes 60). Each
    variant is its own kernel, compiled on its first use and then cached on disk, so a call compiles only
    the variant it runs (a first d = 3 signature at depths 2-4 compiles two lane variants and the level-2
    kernels: 9.0 s of CPU in all, import included, in ``benchmarks/bench_first_call.py``).

    d = 6, 7 reach the lanes at depth 3 only (:func:`roughpaths.signatures._engine._split_units`) and get
    ``(d, 3)``: the unrolled loops over the last letters keep the increments' rows in registers, and the
    run-time variant spent half its time on loop control (16 x 256 points, one thread, CPU time a unit and
    segment: d = 6 24-29 ns against 48-50, d = 7 34 against 67). A first call compiles that variant instead
    of the run-time one, at the same cost (cold, empty cache, a first 16 x 256 x 6 signature at depth 3, CPU
    with the import, two runs each interleaved: 2.77 and 2.63 s against 2.65 and 2.78; d = 7 2.81 against
    2.87). The run-time variant stays for d = 1.

    d = 2 at depth 4 gets ``(2, 4)``: 64 x 256 points, one thread, 6.6 ns a unit and segment against 14.7
    for ``(2, 0)`` (at depth 5 a compile-time depth gained nothing: 22.7 against 23.0; d = 3 at depth 4
    gained 1.4x but stays on ``(3, 0)``, the variant of the first-call budget's d = 3 gradients).
    """
    if m == 3 and d in (6, 7):
        return d, 3
    if (d, m) == (2, 4):
        return 2, 4
    return (d if 2 <= d <= 5 else 0, 3 if m == 3 and d in (2, 3, 5) else 0)


@variants
def _lane_groups_kernel(D: int, M: int):
    """The compiled :func:`lane_groups` of variant ``(D, M)`` (:func:`lane_key`)."""

    rows4k = D in (0, 2, 4)            # rows of a level 4 KiB apart can occur (d = 2, 4): :func:`_top_rows`
    defer = D in (3, 5, 6, 7)          # the top level deferred over SUB segments (:func:`_block_deferred`)

    @njit(**_NOGIL)
    def lane_groups_variant(x, ub, ulo, uhi, m, offsets, lo, hi, part):
        L = LANES
        T = BLOCK
        d = D if D else x.shape[2]
        mm = M if M else m
        dim = offsets[mm + 1]
        nunits = ub.shape[0]
        s = np.empty(dim * L)
        buf = np.empty((2 * d ** max(mm - 2, 1) + (d ** max(mm - 1, 1) if rows4k else 0)       # _top_rows' T
                        + (SUB * d ** (mm - 1) if defer else 0)) * L)                        # the stored T^(k)
        blk = np.empty(T * d * L)
        nsteps = np.zeros(L, dtype=np.int64)
        for g in range(lo, hi):
            s[:] = 0.0
            steps = 0
            for l in range(L):
                u = g * L + l
                nsteps[l] = uhi[u] - ulo[u] if u < nunits else 0
                steps = max(steps, nsteps[l])
                if u < nunits and nsteps[l] == 0:
                    part[u, :] = 0.0
            for t0 in range(0, steps, T):
                nt = min(T, steps - t0)
                _gather_d(x, ub, ulo, nsteps, g, t0, nt, d, blk)
                if defer:
                    _block_deferred(s, blk, nt, t0, g, nsteps, d, mm, offsets, buf, part)
                elif rows4k:           # a branch on the variant's constant: numba compiles only the one taken
                    _block_d(s, blk, nt, t0, g, nsteps, d, mm, offsets, buf, part, _top_rows)
                else:                  # (a function held in the closure instead made numba's cache miss)
                    _block_d(s, blk, nt, t0, g, nsteps, d, mm, offsets, buf, part, _top_registers)

    return lane_groups_variant


def lane_groups(d: int, m: int):
    """The lane kernel for alphabet size ``d`` and depth ``m`` (compiled on first use, without the GIL):
    ``kernel(x, ub, ulo, uhi, m, offsets, lo, hi, part)`` writes the signatures (reversed layout) of the
    units of lane groups ``lo..hi-1`` into ``part`` (units, sigdim).

    Unit ``u`` covers points ``ulo[u]..uhi[u]`` of path ``ub[u]``; group ``g`` is units
    ``g*LANES .. g*LANES + LANES - 1``. The variant is :func:`lane_key` of ``(d, m)``.
    """
    return _lane_groups_kernel(*lane_key(d, m))


@njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _glue(part, nchunks, b, m, offsets, out):
    d = offsets[2]
    dim = offsets[m + 1]
    for r in range(dim):
        out[b, r] = part[b * nchunks, r]
    for c in range(1, nchunks):
        mul_inplace(out[b], part[b * nchunks + c], d, m, offsets)


@njit(**_NOGIL)
def lane_glue(part, nb, nchunks, m, offsets):
    """Per path, the Chen product of its units' signatures, in order (reversed layout)."""
    out = np.empty((nb, offsets[m + 1]))
    for b in range(nb):
        _glue(part, nchunks, b, m, offsets, out)
    return out


@variants
def _scalar_units_kernel(K: int):
    """The compiled :func:`scalar_units` for the step variant ``K`` (:func:`step_key`)."""

    @njit(**_NOGIL)
    def scalar_units_variant(x, ub, ulo, uhi, m, offsets, lo, hi, part):
        d = x.shape[2]
        buf = np.empty(2 * d ** max(m - 1, 1) + d)
        delta = np.empty(d)
        for u in range(lo, hi):
            s = part[u]
            for r in range(s.shape[0]):
                s[r] = 0.0
            b = ub[u]
            for k in range(ulo[u] + 1, uhi[u] + 1):
                for i in range(d):
                    delta[i] = x[b, k, i] - x[b, k - 1, i]
                # s <- s ⊗ exp(delta): d = 2..5 with a compile-time d (K), d = 6..15 _wide_step (the same bits, less
                # loop overhead), others a run-time d. The branch on the constant K is here, in the kernel, where
                # numba prunes it before typing (an inlined helper taking K as an argument compiled every branch)
                if K > 0:
                    _horner_step_d(s, delta, K, m, offsets, buf)
                elif K < 0:
                    _wide_step(s, delta, d, m, offsets, buf)
                else:                           # measured: at d = 20, depth 3 _wide_step is 10% slower
                    _horner_step_d(s, delta, d, m, offsets, buf)

    return scalar_units_variant


def scalar_units(d: int):
    """The plain one-unit kernel for alphabet size ``d`` (compiled on first use, without the GIL):
    ``kernel(x, ub, ulo, uhi, m, offsets, lo, hi, part)`` writes the signatures (reversed layout) of units
    ``lo..hi-1`` into ``part``, one unit at a time with :func:`_horner_step_d`.

    The same arithmetic, operation for operation, as :func:`lane_groups` and the blocked one-unit kernel
    (:mod:`roughpaths.signatures._blocked`): the same bits. The engine runs it for small lone units
    (:func:`roughpaths.signatures._engine.alone_kernel`), where it is as fast and compiles in a fraction of
    the blocked kernel's time; the tests use it as the blocked kernel's reference.
    """
    return _scalar_units_kernel(step_key(d))
