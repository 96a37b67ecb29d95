"""The top level's update on lanes (private): per segment, or deferred over a few segments.

Called by :mod:`roughpaths.signatures._lanes` (and its backward pass, :mod:`roughpaths.signatures._vjp`): the last
link of a level's Horner chain, ``T_{lev-1} = T_{lev-2} ⊗ D/2 + S_{lev-1}`` and ``S_lev += T_{lev-1} ⊗ D``, on
``LANES`` units at once (every array ``(entries, LANES)`` flattened). :func:`_top_registers` and :func:`_top_rows`
update ``S_lev`` every segment; :func:`_top_stored` and :func:`_lane_sweep` defer the top level's update over
:data:`SUB` segments, as :mod:`roughpaths.signatures._blocked` does for one unit. Every entry gets the same
operations in the same order in all of them (the same bits).
"""

from __future__ import annotations

from numba import njit

from ._simd import LANES, vadd, vload, vmul, vsplat, vstore

#: Segments whose top-level products :func:`_lane_sweep` adds at once.
SUB = 16


@njit(cache=True, inline="always")
def _top_registers(s, delta, do, d, ok, o, size, cur, buf, half):
    """``S_lev += T_{lev-1} ⊗ D`` (level ``lev`` at ``ok``) of :func:`_lane_step_d`, ``T_{lev-1} = T_{lev-2} ⊗ D/2 +
    S_{lev-1}`` (``T_{lev-2}``: ``size`` rows at ``cur`` in ``buf``; ``S_{lev-1}`` at ``o``) formed one row at a time in
    registers and used at once (never stored)."""
    L = LANES
    f = vsplat(0.5)
    big = size * d
    for p in range(size):
        t = vload(buf, cur + p * L)
        for q1 in range(d):
            p1 = p + q1 * size
            sc = vmul(vload(delta, do + q1 * L), f)
            t1 = vadd(vmul(t, sc), vload(s, o + p1 * L))
            for q in range(d):
                r = ok + (p1 + q * big) * L
                vstore(s, r, vadd(vload(s, r), vmul(t1, vload(delta, do + q * L))))


@njit(cache=True, inline="always")
def _store_t(s, delta, do, d, o, size, cur, buf, dst):
    """``T_{lev-1} = T_{lev-2} ⊗ D/2 + S_{lev-1}`` into ``buf`` from ``dst`` (``T_{lev-2}``: ``size`` rows at ``cur``;
    ``S_{lev-1}`` at ``o``): the operations of :func:`_top_registers`, stored instead of used at once."""
    L = LANES
    f = vsplat(0.5)
    for p in range(size):
        t = vload(buf, cur + p * L)
        for q1 in range(d):
            p1 = p + q1 * size
            sc = vmul(vload(delta, do + q1 * L), f)
            vstore(buf, dst + p1 * L, vadd(vmul(t, sc), vload(s, o + p1 * L)))


@njit(cache=True, inline="always")
def _top_rows(s, delta, do, d, ok, o, size, cur, buf, half):
    """:func:`_top_registers`, except where the rows of ``S_lev`` are a multiple of 4 KiB apart (``d^(lev-1)`` a
    multiple of 64: d = 4 at level 4, d = 2 from level 7). There each row's store was followed by the load of the row
    4 KiB on, which waits for the store (4K aliasing), so ``T_{lev-1}`` is stored in ``buf`` (after its two blocks of
    ``T_1 .. T_{lev-2}``) and ``S_lev`` swept row by row: the same operations on every entry, the same bits.
    16 x 256 points, one thread, CPU time, three process pairs: d = 4, depth 4 0.197-0.205 ms against 0.22-0.38
    (the old loop's time depended on where the process placed its arrays; 64 paths 0.78-0.80 against 0.81-1.52),
    d = 2, depth 7 0.22-0.23 against 0.27-0.36. Kernels whose ``d`` cannot have such rows (d = 3) take
    :func:`_top_registers` instead: this loop, compiled into them, cost 0.25 s more on a first call."""
    L = LANES
    big = size * d
    if (big * L) % 512 != 0:
        _top_registers(s, delta, do, d, ok, o, size, cur, buf, half)
        return
    tt = 2 * half
    _store_t(s, delta, do, d, o, size, cur, buf, tt)
    for q in range(d):
        dq = vload(delta, do + q * L)
        r0 = ok + q * big * L
        for p1 in range(big):
            r = r0 + p1 * L
            vstore(s, r, vadd(vload(s, r), vmul(vload(buf, tt + p1 * L), dq)))


@njit(cache=True, inline="always")
def _top_stored(s, delta, do, d, ok, o, size, cur, buf, half):
    """:func:`_top_registers` below the top level; on the top level (``S_lev`` the last rows of ``s``) ``T_{lev-1}`` is
    stored, in slot ``t mod SUB`` of the segment ``t = do / (d LANES)`` after ``buf``'s two blocks of chains, for
    :func:`_lane_sweep` to add to ``S_lev``."""
    L = LANES
    big = size * d
    if ok + big * d * L != s.shape[0]:
        _top_registers(s, delta, do, d, ok, o, size, cur, buf, half)
        return
    _store_t(s, delta, do, d, o, size, cur, buf, 2 * half + (do // (d * L)) % SUB * big * L)


@njit(cache=True, inline="always")
def _lane_sweep(s, ok, big, d, buf, base, nk, delta, t0):
    """``S_m[p + q big] += sum_{k < nk} T^(k)[p] D_{t0 + k}[q]`` on every lane (``S_m`` at ``ok``, ``T^(k)`` stored
    by :func:`_top_stored` in slot ``k`` from ``base``, ``D_t`` row ``t d`` of ``delta``), the products added in the
    order of the segments: up to four rows ``q`` at a time, their sums in registers, each entry loaded and stored
    once."""
    L = LANES
    bl = big * L
    for q0 in range(0, d, 4):
        nq = min(4, d - q0)
        for p in range(big):
            r = ok + (p + q0 * big) * L
            a0 = vload(s, r)
            a1 = vload(s, r + bl) if nq > 1 else a0
            a2 = vload(s, r + 2 * bl) if nq > 2 else a0
            a3 = vload(s, r + 3 * bl) if nq > 3 else a0
            for k in range(nk):
                t = vload(buf, base + (k * big + p) * L)
                e = ((t0 + k) * d + q0) * L
                a0 = vadd(a0, vmul(t, vload(delta, e)))
                if nq > 1:
                    a1 = vadd(a1, vmul(t, vload(delta, e + L)))
                if nq > 2:
                    a2 = vadd(a2, vmul(t, vload(delta, e + 2 * L)))
                if nq > 3:
                    a3 = vadd(a3, vmul(t, vload(delta, e + 3 * L)))
            vstore(s, r, a0)
            if nq > 1:
                vstore(s, r + bl, a1)
            if nq > 2:
                vstore(s, r + 2 * bl, a2)
            if nq > 3:
                vstore(s, r + 3 * bl, a3)
