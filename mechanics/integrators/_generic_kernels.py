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

se(3) (the heavy top): Lie–Euler and Lie–Heun with three noise fields run :mod:`._se3_block`, the same
numbers bit for bit with se(3)'s structure constants written out (chosen by the table of non-zeros, so se(3)
given by its constants takes it too).

Layout: a block of up to :data:`BLOCK` members lives as ``(n, BLOCK)`` rows (structure of arrays, the row
operations of :mod:`._soa_rows`);
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
from . import _se3_block
from ._generic_member import DEGREE_THETA, DIMS3, DIMS6, exp1, midpoint1, rare_steps
from ._soa_rows import (CHORD_FAILED, NON_FINITE, OK, STEPS, ad_star_rows, algebra_tables, eta_rows, eta_rows3,
                        saw_rare_step, starts_full,
                        sparse_rows, velocity_rows)

#: Members per block (structure-of-arrays rows; the unit of the thread split).
BLOCK = 128


@lru_cache(maxsize=None)
def _block_kernel(C: int, N: int, full: bool, M3: bool):
    """The compiled block kernel for scheme ``C`` (0 LieEuler, 1 LieHeun, 2 implicit midpoint) and, for the
    midpoint rule, the compile-time dimension ``N`` (3, 6; 0 reads it from the arrays).

    Each variant is its own kernel, compiled on first use and cached: a LieHeun solve compiles neither
    the chord iteration nor its three dimension variants (which cost most of the kernel's compile time).
    Lie–Euler and Lie–Heun come in two variants: without the exact exponential of the rare large steps
    (``full=False``: the kernel returns at such a step, :func:`integrate_generic` does it with
    :func:`._generic_member.rare_steps` and goes on with the other variant) and with it inline (``full=True``).
    A solve that never takes such a step compiles only the first (about 1.2 s of CPU less). ``M3``: three
    noise components (:func:`._soa_rows.eta_rows3`, else :func:`._soa_rows.eta_rows`: one of them compiles).
    """

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def run_block(y, dX, dXX, xi, brk, pi, pj, dts, code, q, lin, f, mth, theta, tol, max_iter, ti, tj, tk, tv, cnorm,
                  degth, save, out, first_bad, reason, stop, flag, sout, lo, hi, k0, start, qs, mts, has_f):
        """Members lo .. hi-1 over the steps from ``k0`` on (``code`` is the scheme the variant was made for, ``C``).

        Returns ``(failed, k)``: the number of members that failed, and ``-1`` when done (or stopped), or, for
        Lie–Euler and Lie–Heun, the step ``k`` at which members flagged in ``flag`` need the exact exponential
        (:func:`._generic_member.rare_steps`): the state before step ``k`` is in ``y`` for them (after it for the others), the
        step's ``σ`` in ``sout``; step ``k`` is not saved yet."""
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
        for k in range(k0):
            if save[k]:
                slot += 1
        for k in range(k0, nk):
            dt = dts[k]
            kk = (k - k0) % STEPS
            if kk == 0:
                if M3:
                    eta_rows3(dX, dXX, area, lo, bc, k, min(STEPS, nk - k), xi, brk, ebuf)
                else:
                    eta_rows(dX, dXX, area, lo, bc, k, min(STEPS, nk - k), xi, brk, pi, pj, ebuf)
            e = ebuf[kk]
            nbig = 0
            if C == 2:
                for p in range(bc):
                    big[p] = True
                nbig = bc
            else:
                velocity_rows(mu, lin, f, has_f, theta, qs, mts, g, t1, t2, w0, ti, tk, tv, start, bc)
                for i in range(n):
                    si, wi, ei = s[i], w0[i], e[i]
                    for p in range(bc):
                        si[p] = wi[p] * dt + ei[p]
                if C == 1:
                    # predictor mu* = (1 + ad*_s + ½ ad*_s²) mu, corrector s = ½(w(mu) + w(mu*)) dt + e
                    ad_star_rows(s, mu, a1, ti, tk, tv, start, bc)
                    ad_star_rows(s, a1, a2, ti, tk, tv, start, bc)
                    for i in range(n):
                        pr, mi, b1, b2 = pred[i], mu[i], a1[i], a2[i]
                        for p in range(bc):
                            pr[p] = mi[p] + b1[p] + 0.5 * b2[p]
                    velocity_rows(pred, lin, f, has_f, theta, qs, mts, g, t1, t2, w1, ti, tk, tv, start, bc)
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
                    ad_star_rows(s, mu if r == 1 else term, term2, ti, tk, tv, start, bc)
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
            if nbig > 0 and C != 2 and not full:     # the exact exponential: rare_steps, compiled when needed
                nl = 0
                for p in range(bc):
                    if big[p] and first_bad[lo + p] < 0:
                        nl += 1
                if nl > 0:
                    for p in range(bc):
                        flag[lo + p] = big[p] and first_bad[lo + p] < 0
                        for i in range(n):
                            y[lo + p, i] = mu[i, p]
                            sout[lo + p, i] = s[i, p]
                    return nfail, k
            if nbig > 0 and (C == 2 or full):
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
        return nfail, -1

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
    Lie–Euler and Lie–Heun on se(3) with three noise fields (the structure constants' non-zeros those of
    se(3): the heavy top) run :mod:`._se3_block`'s kernel, which computes the same numbers with less memory
    traffic.
    """
    data = system.quadratic_velocity_data()
    ti, tj, tk, tv, start, cnorm = algebra_tables(system.algebra.structure_constants)
    nb, n = y.shape
    nk, nm = dX.shape[1], dX.shape[-1]
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
            bool(stop_on_failure), np.zeros(nb, dtype=np.bool_), np.empty((nb, n)))
    tail = (start, qs, mts, bool(np.any(f != 0.0)))
    save, flag, sout = args[22], args[27], args[28]
    se3 = code != 2 and nm == 3 and _se3_block.has_se3_table(ti, tj, tk, tv)
    key = ("se3" if se3 else "generic", int(code), nm == 3)
    start_full = code != 2 and starts_full(key, system, y, dX, dXX, dts,
                                           lambda sig: np.any(~(np.abs(sig) @ cnorm <= DEGREE_THETA[-1])))
    if se3:                                                                 # the same numbers, written out
        full, block = _se3_block.run_block_full, _se3_block.B
        kernel = full if start_full else _se3_block.run_block
    else:
        N = n if code == 2 and n in (3, 6) else 0
        kernel, full, block = _block_kernel(int(code), N, start_full, nm == 3), None, BLOCK

    def run(lo, hi):
        _, k = kernel(*args, lo, hi, 0, *tail)
        if k < 0:
            return
        # a step the vectorised Taylor loop left to the exact exponential: do it, then go on with the variant
        # that has it inline
        saw_rare_step(key)
        nnew = rare_steps(y[lo:hi], sout[lo:hi], flag[lo:hi], ti, tj, tk, tv, cnorm, DEGREE_THETA,
                          first_bad[lo:hi], reason[lo:hi], k)
        if save[k]:
            out[lo:hi, np.count_nonzero(save[:k])] = y[lo:hi]
        if not ((stop_on_failure and nnew > 0) or k + 1 == nk):
            (full or _block_kernel(int(code), 0, True, nm == 3))(*args, lo, hi, k + 1, *tail)

    parallel_ranges(run, nb, block)
    return y, out, first_bad, reason
