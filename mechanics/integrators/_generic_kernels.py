r"""Compiled coadjoint kernels for any Lie algebra given by its structure constants (quadratic Hamiltonian).

:meth:`~mechanics.integrators.base.CoadjointSolver.integrate` selects them for every algebra without a
hand-written kernel (:mod:`._so3_kernels`, :mod:`._se3_kernels`) when the Hamiltonian is quadratic and
the system has no forces. Same schemes as the numpy path (:mod:`mechanics.integrators.base`), same
contract as the hand-written kernels (``first_bad``, ``reason`` NON_FINITE / CHORD_FAILED, saved steps).

What the kernels are given (arrays, never closures: one compiled kernel serves every algebra)
------------------------------------------------------------------------------------------------
* the structure constants as a list of their non-zero entries ``(i, j, k, c[i, j, k])``, so that
  :math:`(\mathrm{ad}^*_x\mu)_j = \sum x_i\mu_k c^k_{ij}` costs one multiply-add per non-zero (6 for
  so(3), 18 for se(3)) and no ``n × n`` matrix is formed on the fast path;
* ``cnorm[i]`` :math:`= \max_j\sum_k|c^k_{ij}|`, so :math:`\theta = \sum_i|\sigma_i|\,\mathrm{cnorm}_i
  \ge\|\mathrm{ad}^*_\sigma\|_\infty`, a per-member bound read from the member's own ``σ``;
* the drift velocity :math:`w(\mu) = g + \vartheta M^{-1}\mathrm{ad}^*_{g+f}\mu`, :math:`g = Q\mu + b'`
  (:meth:`~mechanics.systems.lie_poisson.LiePoissonSystem.quadratic_velocity_data`).

The coadjoint action :math:`e^{\mathrm{ad}^*_\sigma}\mu`, per member
---------------------------------------------------------------------
* :math:`\theta\le` :data:`._generic_member.THETA_VECTOR` (every step of a sane run): the Taylor series applied to the
  vector, :math:`\sum_{r\le m}(\mathrm{ad}^*_\sigma)^r\mu/r!`, with the degree ``m`` the smallest for
  which :math:`\theta^{m+1}/(m+1)!\le 2^{-54}` (table :data:`._generic_member.DEGREE_THETA`): the truncation is below
  round-off relative to :math:`|\mu|`, so the Casimirs are kept to round-off. The degree is the
  member's own (a member of a block computes the higher terms its neighbours need but does not add
  them: ``select``, not a multiplication by 0), so its bits never depend on the batch.
* larger :math:`\theta` (or non-finite): the scalar path, matrix scaling and squaring: :math:`A =
  \mathrm{ad}^*_\sigma/2^s` with :math:`\theta/2^s\le\tfrac12`, Taylor of the degree of the table, then
  ``s`` squarings, times ``μ``.

Layout: a block of up to :data:`BLOCK` members lives as ``(n, BLOCK)`` rows (structure of arrays);
each operation is a loop over the members of the block, pure arithmetic, so LLVM vectorises it
(no fast-math: vector and scalar loops round alike). Blocks run in parallel (:func:`roughpaths.validation.parallel_ranges`, numba's
number of threads: ``numba.set_num_threads`` / ``NUMBA_NUM_THREADS``); a member's result does not depend
on its block, its neighbours or the thread. The implicit midpoint rule runs the chord iteration member by member
(scalar code, as the hand-written kernels do).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np

from roughpaths.validation import parallel_ranges
from ._generic_member import DEGREE_THETA, DIMS3, DIMS6, exp1, midpoint1

OK, NON_FINITE, CHORD_FAILED = 0, 1, 2
#: Members per block (structure-of-arrays rows; the unit of the thread split).
BLOCK = 128
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


# ---------------------------------------------------------------------- block (structure-of-arrays) operations
# Every output row is written in passes over the block's members (measured: one non-zero per pass is
# faster than two per pass here: 2.7 against 4.6 ns per member for so(3)'s ad*, 3.7 with a zeroing pass).
@numba.njit(cache=True)
def _ad_star_rows(x, mu, out, ti, tk, tv, start, bc):
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


@numba.njit(cache=True)
def _affine_rows(base, const, cols, vals, start, x, out, bc, use_base):
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


@numba.njit(cache=True)
def _velocity_rows(mu, lin, f, has_f, theta, qs, mts, g, t1, t2, out, ti, tk, tv, start, bc):
    """out = w(mu) = g + θ M⁻¹ ad*_{g+f} mu, g = Q mu + lin; ``qs``, ``mts``: the non-zeros of Q and θ M⁻¹."""
    _affine_rows(g, lin, qs[0], qs[1], qs[2], mu, g, bc, False)
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
        _ad_star_rows(t1, mu, t2, ti, tk, tv, start, bc)
    else:
        _ad_star_rows(g, mu, t2, ti, tk, tv, start, bc)
    _affine_rows(g, mts[3], mts[0], mts[1], mts[2], t2, out, bc, True)


@numba.njit(cache=True)
def _eta_rows3(dX, dXX, area, lo, bc, k0, kc, xi, brk, e):
    """:func:`_eta_rows` for three noise components: the same sums in the same order (the same bits), the
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


@numba.njit(cache=True)
def _eta_rows(dX, dXX, area, lo, bc, k0, kc, xi, brk, pi, pj, e):
    """e[kk, :, p] = Σ_r dX_r ξ_r + Σ_{i<j} A_ij [ξ_i, ξ_j] (A = ½(XX − XXᵀ)) for members lo .. lo+bc-1 and
    steps k0 .. k0+kc-1 (member by member, so each member's increments are read in order)."""
    n = e.shape[1]
    nm = dX.shape[2]
    if nm == 3 and (not area or pi.shape[0] == 3):
        _eta_rows3(dX, dXX, area, lo, bc, k0, kc, xi, brk, e)
        return
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


@lru_cache(maxsize=None)
def _block_kernel(C: int, N: int):
    """The compiled block kernel for scheme ``C`` (0 LieEuler, 1 LieHeun, 2 implicit midpoint) and, for the
    midpoint rule, the compile-time dimension ``N`` (3, 6; 0 reads it from the arrays).

    Each variant is its own kernel, compiled on first use and cached: a LieHeun solve compiles neither
    the chord iteration nor its three dimension variants (which cost most of the kernel's compile time).
    """

    @numba.njit(cache=True, nogil=True)
    def run_block(y, dX, dXX, xi, brk, pi, pj, dts, code, q, lin, f, mth, theta, tol, max_iter, ti, tj, tk, tv, cnorm,
                  degth, save, out, first_bad, reason, stop, lo, hi, start, qs, mts, has_f):
        """Members lo .. hi-1 over every step of the block; returns the number of members that failed
        (``code`` is the scheme the variant was made for, ``C``)."""
        n = y.shape[1]
        bc = hi - lo
        nk = dX.shape[1]
        area = dXX.shape[0] > 0
        mu, w0, s = np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc))
        ebuf = np.empty((STEPS, n, bc))
        a1, a2, pred, w1 = np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc))
        g, t1, t2, term, term2 = np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc)), np.empty((n, bc))
        th = np.empty(bc)
        big = np.empty(bc, dtype=np.bool_)
        work = (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, 2 * n)),
                np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((8, n)))
        vs, vm, vo, ve = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
        lim = degth[degth.shape[0] - 1]
        for p in range(bc):
            for i in range(n):
                mu[i, p] = y[lo + p, i]
        nfail = 0
        slot = 0
        for k in range(nk):
            dt = dts[k]
            kk = k % STEPS
            if kk == 0:
                _eta_rows(dX, dXX, area, lo, bc, k, min(STEPS, nk - k), xi, brk, pi, pj, ebuf)
            e = ebuf[kk]
            nbig = 0
            if C == 2:
                for p in range(bc):
                    big[p] = True
                nbig = bc
            else:
                _velocity_rows(mu, lin, f, has_f, theta, qs, mts, g, t1, t2, w0, ti, tk, tv, start, bc)
                for i in range(n):
                    si, wi, ei = s[i], w0[i], e[i]
                    for p in range(bc):
                        si[p] = wi[p] * dt + ei[p]
                if C == 1:
                    # predictor mu* = (1 + ad*_s + ½ ad*_s²) mu, corrector s = ½(w(mu) + w(mu*)) dt + e
                    _ad_star_rows(s, mu, a1, ti, tk, tv, start, bc)
                    _ad_star_rows(s, a1, a2, ti, tk, tv, start, bc)
                    for i in range(n):
                        pr, mi, b1, b2 = pred[i], mu[i], a1[i], a2[i]
                        for p in range(bc):
                            pr[p] = mi[p] + b1[p] + 0.5 * b2[p]
                    _velocity_rows(pred, lin, f, has_f, theta, qs, mts, g, t1, t2, w1, ti, tk, tv, start, bc)
                    for i in range(n):
                        si, wi, vi, ei = s[i], w0[i], w1[i], e[i]
                        for p in range(bc):
                            si[p] = 0.5 * (wi[p] + vi[p]) * dt + ei[p]
                # exp(ad*_s) mu: Taylor on the vector, each member to its own degree (select, not multiply)
                for p in range(bc):
                    th[p] = 0.0
                for i in range(n):
                    ci = cnorm[i]
                    si = s[i]
                    for p in range(bc):
                        th[p] += abs(si[p]) * ci
                thmax = 0.0
                for p in range(bc):
                    b = not (th[p] <= lim)                 # NaN too: the scalar path diagnoses it
                    big[p] = b
                    nbig += b
                    if not b:
                        thmax = max(thmax, th[p])
                r = 1
                while thmax > degth[r - 1]:                # a1: the sum, term: the current term
                    _ad_star_rows(s, mu if r == 1 else term, term2, ti, tk, tv, start, bc)
                    inv = 1.0 / r
                    lev = degth[r - 1]
                    for i in range(n):
                        tt, t2i, ai, mi = term[i], term2[i], a1[i], mu[i]
                        if r == 1:
                            for p in range(bc):
                                x = t2i[p] * inv
                                tt[p] = x
                                ai[p] = mi[p] + x if th[p] > lev else mi[p]
                        else:
                            for p in range(bc):
                                x = t2i[p] * inv
                                tt[p] = x
                                ai[p] = ai[p] + x if th[p] > lev else ai[p]
                    r += 1
                if r > 1:
                    for i in range(n):
                        mi, ai = mu[i], a1[i]
                        for p in range(bc):
                            mi[p] = ai[p] if not big[p] else mi[p]
            if nbig > 0:
                for p in range(bc):
                    if not big[p]:
                        continue
                    finite_in = True
                    for i in range(n):
                        vm[i] = mu[i, p]
                        ve[i] = e[i, p]
                        vs[i] = s[i, p]
                        if not (math.isfinite(vm[i]) and math.isfinite(ve[i])):
                            finite_in = False
                    ok = False
                    chord_failed = False
                    if finite_in and C == 2:                 # dimensions 3 and 6: compiled variants (DIMS3/6)
                        if N == 6:
                            ok, chord_failed = midpoint1(vm, ve, vs, vo, dt, q, qs, lin, f, mts, theta, tol, max_iter,
                                                         ti, tj, tk, tv, cnorm, degth, work, DIMS6)
                        elif N == 3:
                            ok, chord_failed = midpoint1(vm, ve, vs, vo, dt, q, qs, lin, f, mts, theta, tol, max_iter,
                                                         ti, tj, tk, tv, cnorm, degth, work, DIMS3)
                        else:
                            ok, chord_failed = midpoint1(vm, ve, vs, vo, dt, q, qs, lin, f, mts, theta, tol, max_iter,
                                                         ti, tj, tk, tv, cnorm, degth, work)
                    elif finite_in:
                        ok = exp1(vs, vm, vo, work[5], work[6], work[7], work[8][6], work[8][7], ti, tj, tk, tv,
                                  cnorm, degth)
                    if ok:
                        for i in range(n):
                            mu[i, p] = vo[i]
                    else:
                        for i in range(n):
                            mu[i, p] = np.nan
                        if first_bad[lo + p] < 0:
                            first_bad[lo + p] = k
                            reason[lo + p] = CHORD_FAILED if chord_failed else NON_FINITE
                            nfail += 1
            if save[k]:
                for p in range(bc):
                    for i in range(n):
                        out[lo + p, slot, i] = mu[i, p]
                slot += 1
            if stop and nfail > 0:
                break
        for p in range(bc):
            for i in range(n):
                y[lo + p, i] = mu[i, p]
        return nfail

    return run_block


def _readonly(a):
    """A read-only view: the kernels then compile one signature whether the driver's arrays are writable or not."""
    v = a.view()
    v.flags.writeable = False
    return v


def integrate_generic(system, code, tol, max_iter, y, dX, dXX, dts, save, stop_on_failure):
    """Run the generic kernel on ``y`` (B, n) over ``dX`` (B, K, d), ``dXX`` (B, K, d, d) or None (C-contiguous).

    Returns ``(y, saved (B, S, n), first_bad (B,), reason (B,))``. Blocks of :data:`BLOCK` members run in
    parallel on numba's threads (``numba.set_num_threads``); the result does not depend on their number.
    """
    data = system.quadratic_velocity_data()
    ti, tj, tk, tv, start, cnorm = algebra_tables(system.algebra.structure_constants)
    nb, n = y.shape
    nm = dX.shape[-1]
    pi, pj = np.triu_indices(nm, 1)
    brk = np.array(system.xi_brackets[pi, pj], dtype=np.float64, order="C")
    y = np.array(y, dtype=np.float64, order="C")
    out = np.full((nb, int(np.count_nonzero(save)), n), np.nan)
    first_bad = np.full(nb, -1, dtype=np.int64)
    reason = np.zeros(nb, dtype=np.int8)
    theta = float(data["theta"])
    mth = np.array(theta * data["metric_inv"].T, dtype=np.float64, order="C")
    f = np.array(data["dissipation_change"], dtype=np.float64)
    qs = sparse_rows(data["q"])
    mts = sparse_rows(mth) + (np.zeros(n),)
    args = (y, _readonly(dX), _readonly(np.empty((0, 0, 0, 0)) if dXX is None else dXX),
            np.array(system.xi, dtype=np.float64, order="C"), brk, pi.astype(np.int64), pj.astype(np.int64),
            np.array(dts, dtype=np.float64), int(code), np.array(data["q"], dtype=np.float64, order="C"),
            np.array(data["linear"], dtype=np.float64), f, mth, theta, float(tol), int(max_iter), ti, tj, tk,
            tv, cnorm, DEGREE_THETA, np.array(save, dtype=np.bool_), out, first_bad, reason,
            bool(stop_on_failure))
    tail = (start, qs, mts, bool(np.any(f != 0.0)))
    kernel = _block_kernel(int(code), n if code == 2 and n in (3, 6) else 0)
    parallel_ranges(lambda lo, hi: kernel(*args, lo, hi, *tail), nb, BLOCK)
    return y, out, first_bad, reason
