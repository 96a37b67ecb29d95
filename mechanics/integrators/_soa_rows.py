r"""Structure-of-arrays row operations of the compiled coadjoint block kernels (:mod:`._generic_kernels`,
:mod:`._se3_block`), and the tables they read.

A block of members lives as rows ``(n, members)``: row ``i`` holds component ``i`` of every member, and each
operation is a loop over the members, pure arithmetic that LLVM vectorises (no fast-math: vector and scalar
loops round alike). The structure constants are given as their non-zeros (:func:`algebra_tables`), the
Hamiltonian's ``Q`` and the metric's ``θM⁻¹`` as their non-zeros by rows (:func:`sparse_rows`).
"""

from __future__ import annotations

import numba
import numpy as np

#: ``reason`` codes of the block kernels: a member that failed is NON_FINITE, or CHORD_FAILED when the
#: implicit midpoint's chord iteration did not converge.
OK, NON_FINITE, CHORD_FAILED = 0, 1, 2


def algebra_tables(c):
    """Non-zero structure constants ``(ti, tj, tk, tv)`` grouped by ``tj`` (row ``j``'s terms are
    ``start[j] .. start[j+1]``), ``start`` and ``cnorm (n,)`` of ``c (n, n, n)``."""
    c = np.asarray(c, dtype=np.float64)
    n = c.shape[0]
    ti, tj, tk = np.nonzero(c)
    order = np.lexsort((tk, ti, tj))                           # grouped by output component j
    ti, tj, tk = ti[order], tj[order], tk[order]
    tv = np.ascontiguousarray(c[ti, tj, tk])
    start = np.searchsorted(tj, np.arange(n + 1)).astype(np.int64)
    cnorm = np.ascontiguousarray(np.max(np.sum(np.abs(c), axis=2), axis=1))
    return ti.astype(np.int64), tj.astype(np.int64), tk.astype(np.int64), tv, start, cnorm


def sparse_rows(m):
    """Non-zeros of ``m (n, n)`` by rows: ``(cols, vals, start)`` (row ``i``: ``start[i] .. start[i+1]``)."""
    m = np.asarray(m, dtype=np.float64)
    rows, cols = np.nonzero(m)
    start = np.searchsorted(rows, np.arange(m.shape[0] + 1)).astype(np.int64)
    return cols.astype(np.int64), np.ascontiguousarray(m[rows, cols]), start


#: Per kernel (a key of the caller's), whether a solve starts with the variant that has the exact step inline.
_STARTS: dict = {}


def starts_full(key, system, y, dX, dXX, dts, past) -> bool:
    """Whether the solves of kernel ``key`` start with its variant that has the exact exponential inline.

    Decided once a process: by the first solve's first step (``past(sigma)`` on the Lie–Euler ``σ = w(μ) dt + e``
    of every member, ``(B, n)``, in numpy: a system whose steps are routinely past the vectorised exponential
    would otherwise compile both variants), and turned on for good by :func:`saw_rare_step`. Not per call:
    an adaptive solve calls the kernel at every attempt. Members get the same bits from either variant."""
    if key not in _STARTS:
        full = False
        if dX.shape[1] > 0:
            levy = None if dXX is None else 0.5 * (dXX[:, 0] - np.swapaxes(dXX[:, 0], -1, -2))
            with np.errstate(all="ignore"):
                full = bool(past(system.drift_velocity(y) * float(dts[0]) + system.stochastic_velocity(dX[:, 0], levy)))
        _STARTS[key] = full
    return _STARTS[key]


def saw_rare_step(key) -> None:
    """A solve of kernel ``key`` needed the exact step: its later solves start with the variant that has it."""
    _STARTS[key] = True


# ---------------------------------------------------------------------- block (structure-of-arrays) operations
# Every output row is written in passes over the block's members (measured: one non-zero per pass is
# faster than two per pass here: 2.7 against 4.6 ns per member for so(3)'s ad*, 3.7 with a zeroing pass).
@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def ad_star_rows(x, mu, out, ti, tk, tv, start, bc):
    """out[j, p] = (ad*_{x[:, p]} mu[:, p])_j for p < bc (terms grouped by j: ``start[j] .. start[j+1]``;
    one pass per non-zero, the first one of a row writing it)."""
    for j in range(out.shape[0]):
        o = out[j]
        a, b = start[j], start[j + 1]
        if a == b:
            for p in range(bc):
                o[p] = 0.0
        for t in range(a, b):
            xa, ma, va = x[ti[t]], mu[tk[t]], tv[t]
            if t == a:
                for p in range(bc):
                    o[p] = va * xa[p] * ma[p]
            else:
                for p in range(bc):
                    o[p] += va * xa[p] * ma[p]


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def affine_rows(base, const, cols, vals, start, x, out, bc, use_base):
    """out[i, p] = ((base[i, p] if use_base) + const[i]) + Σ_t vals[t] x[cols[t], p] over the row's non-zeros
    (one pass per non-zero; the first also writes the constant)."""
    for i in range(out.shape[0]):
        o = out[i]
        c = const[i]
        bi = base[i]
        a, b = start[i], start[i + 1]
        if a == b:
            if use_base:
                for p in range(bc):
                    o[p] = bi[p] + c
            else:
                for p in range(bc):
                    o[p] = c
        for t in range(a, b):
            xa, va = x[cols[t]], vals[t]
            if t == a and use_base:
                for p in range(bc):
                    o[p] = (bi[p] + c) + va * xa[p]
            elif t == a:
                for p in range(bc):
                    o[p] = c + va * xa[p]
            else:
                for p in range(bc):
                    o[p] += va * xa[p]


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def velocity_rows(mu, lin, f, has_f, theta, qs, mts, g, t1, t2, out, ti, tk, tv, start, bc):
    """out = w(mu) = g + θ M⁻¹ ad*_{g+f} mu, g = Q mu + lin; ``qs``, ``mts``: the non-zeros of Q and θ M⁻¹."""
    yes = bc >= 0           # True as a plain bool: the literals True and False compile two variants of affine_rows
    affine_rows(g, lin, qs[0], qs[1], qs[2], mu, g, bc, not yes)
    if theta == 0.0:
        for i in range(mu.shape[0]):
            o, gi = out[i], g[i]
            for p in range(bc):
                o[p] = gi[p]
        return
    if has_f:
        for i in range(mu.shape[0]):
            fi = f[i]
            o, gi = t1[i], g[i]
            for p in range(bc):
                o[p] = gi[p] + fi
        ad_star_rows(t1, mu, t2, ti, tk, tv, start, bc)
    else:
        ad_star_rows(g, mu, t2, ti, tk, tv, start, bc)
    affine_rows(g, mts[3], mts[0], mts[1], mts[2], t2, out, bc, yes)


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def eta_rows3(dX, dXX, area, lo, bc, k0, kc, xi, brk, e):
    """:func:`eta_rows` for three noise components: the same sums in the same order (the same bits), the
    loops over the components and pairs written out."""
    n = e.shape[1]
    for p in range(bc):
        for kk in range(kc):
            k = k0 + kk
            x0 = dX[lo + p, k, 0]
            x1 = dX[lo + p, k, 1]
            x2 = dX[lo + p, k, 2]
            if area:
                a0 = 0.5 * (dXX[lo + p, k, 0, 1] - dXX[lo + p, k, 1, 0])
                a1 = 0.5 * (dXX[lo + p, k, 0, 2] - dXX[lo + p, k, 2, 0])
                a2 = 0.5 * (dXX[lo + p, k, 1, 2] - dXX[lo + p, k, 2, 1])
            for i in range(n):
                acc = 0.0 + x0 * xi[0, i]
                acc += x1 * xi[1, i]
                acc += x2 * xi[2, i]
                if area:
                    acc += a0 * brk[0, i]
                    acc += a1 * brk[1, i]
                    acc += a2 * brk[2, i]
                e[kk, i, p] = acc


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def eta_rows(dX, dXX, area, lo, bc, k0, kc, xi, brk, pi, pj, e):
    """e[kk, :, p] = Σ_r dX_r ξ_r + Σ_{i<j} A_ij [ξ_i, ξ_j] (A = ½(XX − XXᵀ)) for members lo .. lo+bc-1 and
    steps k0 .. k0+kc-1 (member by member, so each member's increments are read in order). Three noise
    components: :func:`eta_rows3` (the kernels choose when they are compiled, so each compiles one of them)."""
    n = e.shape[1]
    nm = dX.shape[2]
    for p in range(bc):
        for kk in range(kc):
            k = k0 + kk
            for i in range(n):
                acc = 0.0
                for r in range(nm):
                    acc += dX[lo + p, k, r] * xi[r, i]
                e[kk, i, p] = acc
            if area:
                for r in range(pi.shape[0]):
                    a = 0.5 * (dXX[lo + p, k, pi[r], pj[r]] - dXX[lo + p, k, pj[r], pi[r]])
                    for i in range(n):
                        e[kk, i, p] += a * brk[r, i]


#: Steps whose stochastic velocities are formed at once (a (STEPS, n, BLOCK) buffer per block).
STEPS = 16
