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
The (6, 4) variant and d = 4 from depth 7 update the lower levels in place instead (rows end one entry at a time;
no second copy to zero, to stream and to copy out), and every other width once a row of the top level's ``T``
passes 4096 entries defers levels ``m - 1`` and ``m`` both, forming ``T`` a chunk at a time instead of a block's
rows of it (:mod:`roughpaths.signatures._inplace`), which is faster there (:func:`block_key`); the same bits.
Where ``d^(m-1)`` is a multiple of 512 floats, the block's rows are ``LANES`` entries more apart
(:func:`_tb_stride`; 64 bytes a row, at most 1 KiB a call): 4 KiB apart, the sweep ran up to 12 % slower in
some processes (memory placement) than in others. Measured one thread, old and new interleaved in one
process, 8 processes: 64 x 256 points, d = 8 depth 4 6.1-7.1 ms against 6.4-7.9 (median ratio 0.95,
0.88-1.01), 16 x 256, d = 16 depth 4 0.87-0.98; the same bits (only the addresses move).

Measured (one thread, CPU time, this 2-core machine): the sweep 0.14-0.17 ns per entry and
segment (the rank-one update: 0.31; two packed multiplies and two packed adds a cycle give
0.125 at 2 GHz; tiles of 2 packed rows x 4 rows: 0.04-0.06); per segment (16 x 256 points, one
thread, interleaved with pysiglib 4.0 ``n_jobs=1``) d = 8 depth 4 450-500 ns (pysiglib 590-890), d = 6 depth 4
200-230 (300). d = 8 and d = 6 at depth 4 are compiled with constant ``d`` and ``m`` (loops unrolled), d = 4 with a
constant ``d``; every other width runs a run-time variant, and depth 3 its own
(:mod:`roughpaths.signatures._depth3`: level 2 transposed). Compile cost (cold, empty cache, one variant, CPU, with
the import): 4.6 s for the run-time variant (2.8 s before the packed row ends and the 2 x 4 tiles).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._variants import variants

from ._depth3 import _unit_3
from ._inplace import CHUNK, _unit_inplace, _unit_two
from ._simd import LANES
from ._sweep import KBLOCK, _increment, _row, _tb_stride, _top_sweep

_NOGIL = dict(cache=True, nogil=True, no_cfunc_wrapper=True)


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
def _unit_d(x, b, k0, k1, s, d, m, offsets, fac, buf, hs, tb, ts, dl, delta, w, lw, ls):
    """Signature (reversed layout) of points ``k0..k1`` of path ``b`` into ``s`` (depth ``m >= 2``); the
    lower levels run in ``lw`` (two copies ``ls`` apart) and are copied into ``s`` at the end."""
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
            _increment(x, b, t0 + k, k, d, dl, delta)
            _fused_d(lw, so, sn, delta, d, m, offsets, fac, buf, hs, tb, kk * np.uint64(ts))
            so, sn = sn, so
        _top_sweep(s, ok, n, n, d, tb, ts, dl, nk, w)
    for r in range(ok):
        s[r] = lw[so + r]


def block_key(d: int, m: int) -> tuple:
    """``(D, M, LOWER)``: the compile-time alphabet size and depth of the one-unit kernel's variant (0: at run time),
    and how it updates the lower levels (``LOWER``: 0 double-buffered, :func:`_unit_d`; 1 in place,
    :func:`~roughpaths.signatures._inplace._unit_inplace`; 2 in place with levels ``m - 1`` and ``m`` both deferred
    over a block, :func:`~roughpaths.signatures._inplace._unit_two`; 3 at depth 3, level 2 transposed,
    :func:`~roughpaths.signatures._depth3._unit_3`). The same bits in every variant.

    Compile-time widths (and depths) let LLVM unroll the loops over the letters and the levels:
    (d, m) = (8, 4) and (6, 4) (cells (d) and (h) of ``benchmarks/bench_signatures.py``: the run-time variant
    measured 10 % and 15-25 % slower there), and d = 4 at any depth. Every other width runs a run-time variant
    (:func:`runtime_key`): (20, 3) had a variant of its own until the run-time one came within 5-8 % of it (cell
    (e)), and (8, 3) until the depth-3 variant passed it (53 ns a segment against 59-60). Each variant is its own
    kernel, compiled on first use (a few seconds of CPU, then cached), so a call compiles only the one it runs.

    In place (the same bits): (6, 4) and d = 4 from depth 7. There the double buffer's second copy of the lower
    levels, its zeroing and its copy-out cost more than the rows that end one entry at a time: measured (one thread,
    interleaved) 16 x 256 points at (6, 4) 663-692 us against 749-780 double-buffered (the kernel before the double
    buffer: 726-784); a lone 10 x 4 path at depth 8 183-222 us against 231-273 (before: 194-245); d = 4 at depth 8,
    1 x 257 points 4.9-5.1 ms against 5.2-5.4. d = 4 at depths 5 and 6 stays double-buffered (in place 5-50 % slower
    on 17-257 points). Both top levels deferred (:func:`runtime_key`) measured 5-8 % slower at (6, 4) (16 and 64 x
    256 points: 0.78-0.83 / 4.0-4.1 ms against 0.79 / 3.7-3.8) and even at d = 4 from depth 7 (4 x 256 points at
    depths 8 and 9: 14.4-14.8 / 62-63 ms against 13.8-16.8 / 62-66; 16 x 64 at depth 7 3.5-3.6 against 2.8-3.4).
    """
    if (d, m) == (6, 4):
        return 6, 4, 1
    if (d, m) == (8, 4):
        return 8, 4, 0
    if d == 4:
        return 4, 0, 1 if m >= 7 else 0
    return runtime_key(d, m)


def runtime_key(d: int, m: int) -> tuple:
    """:func:`block_key` of the run-time variants: at depth 3, level 2 transposed (``LOWER`` 3,
    :func:`~roughpaths.signatures._depth3._unit_3`); deeper, double-buffered, or in place with both top levels deferred
    where a row of ``T`` passes 4096 entries (32 KiB, the L1 cache).

    Depth 3 (``(0, 3, 3)``): at d = 10 the double-buffered kernel spent about half its time on levels 1 and 2 (68 ns
    a segment of 123, the kernel alone, against ~20 by their operation count). One thread, ns a segment, 16 x 256
    points, ``signature``, three interleaved process pairs: d = 8 53 against 59-60 (the (8, 3) variant), d = 9 92-95
    against 115-121, d = 10 108-111 against 128-134, d = 11 144-145 against 171-178, d = 12 141-142 against 165,
    d = 13 199-202 against 232-237, d = 14 283-294 against 312-321, d = 16 394-405 against 425-433, d = 20 553-556
    against 579-594; the same bits. Compile (cold, the first call at d = 10 / d = 8): 4.6 / 4.3-4.7 s against
    5.2-5.5 / 4.6-4.8 (the run-time and (8, 3) variants); ``benchmarks/bench_first_call.py``'s cell "signature_vjp,
    one path" compiles it (its forward pass).

    Deeper, where a row of ``T`` passes 4096 entries, the second copy of the lower levels is memory traffic, and so is
    the block's ``T`` (16 rows of ``d^(m-1)`` entries, written and read back: 12.8 MB at d = 10, depth 6, more than the
    signature's top level):
    :func:`~roughpaths.signatures._inplace._unit_two` keeps only the chains of level ``m - 2`` for the block and forms
    ``T`` a chunk at a time in the L1 cache. One thread, CPU time, 4 x 256 points, three interleaved process pairs,
    against the code before (one level deferred in place here, which had measured against double-buffered: d = 10 at
    depth 6, 8 x 256 points, 267-273 ms against 306-323): d = 10 at depth 6 101-135 ms against 152-190, d = 11 at
    depth 6 205-231 against 348-400, d = 16 at depth 5 83-88 against 148-161, d = 14 at depth 5 44-45 against 53-55,
    d = 12 at depth 5 21-22 against 23-28, d = 9 at depth 6 52-56 against 65-66, d = 3 at depth 9 9.8-9.9 against
    10.2-10.3; the same bits (hashed: signatures, log-signatures, VJPs; one and two threads). At 4096 entries and
    below (d = 8 at depth 5, d = 16, 12, 10 at depth 4, d = 5 at depth 6) in place was even or slower.
    """
    if m == 3:
        return 0, 3, 3
    return 0, 0, 2 if m >= 3 and d ** (m - 1) > 4096 else 0


@variants
def _block_units_kernel(D: int, M: int, LOWER: int):
    """The compiled :func:`block_units` of variant ``(D, M, LOWER)`` (:func:`block_key`)."""

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
        for r in range(2 * mm + 2 if LOWER == 0 else 0):         # (rows in place read no further)
            for j in range(mm - 1):
                buf[r * hs + d ** j:r * hs + d ** j + L] = 0.0
        ls = (offsets[mm] + 2 * L - 1) // L * L if LOWER == 0 else 0  # the lower levels, with slack (or in s)
        lw = np.empty(2 * ls)
        lw[offsets[mm]:ls] = 0.0
        lw[ls + offsets[mm]:] = 0.0
        most = 1
        for u in range(lo, hi):
            most = max(most, uhi[u] - ulo[u])
        rows = min(KBLOCK, most)
        n1 = d ** (mm - 1) if LOWER != 2 else 1
        ts = _tb_stride(n1)
        tb = np.empty(rows * ts + L)                            # the block's T (a short path's: its segments)
        for r in range(rows):
            tb[r * ts + n1:r * ts + n1 + L] = 0.0
        w = np.zeros((d + 3) * 4 * LANES)                       # the rows' ends (_top_sweep)
        dl = np.zeros(KBLOCK * d + 3)
        delta = np.zeros(d + L)                                 # (zero past d: _unit_3's packed rows)
        fac = np.empty(mm + 1)
        for k in range(1, mm + 1):
            fac[k] = 1.0 / k
        cst = (d ** (mm - 2) + 2 * L - 1) // L * L if LOWER == 2 else 0
        cs = np.empty(2 * rows * cst)                           # the block's chains (_unit_two: read where written)
        tts = _tb_stride(CHUNK)
        tt = np.zeros(rows * tts + L if LOWER == 2 else 1)      # a chunk of the block's T (_unit_two)
        r2 = (d + L - 1) // L * L
        lw3 = np.empty(r2 * (d + 1) if LOWER == 3 else 1)         # _unit_3's levels 1 and 2 (transposed)
        sp = np.empty(d ** 3 if LOWER == 3 else 1)                # and its level 3
        for u in range(lo, hi):
            if LOWER == 3:
                _unit_3(x, ub[u], ulo[u], uhi[u], part[u], d, fac, tb, ts, dl, delta, w, lw3, r2, sp)
            elif LOWER == 2:
                _unit_two(x, ub[u], ulo[u], uhi[u], part[u], d, mm, offsets, fac, buf, hs, cs, cst, tt, tts, dl, delta,
                          w)
            elif LOWER == 1:
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
