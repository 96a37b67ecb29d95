r"""The heavy top's Lie–Euler and Lie–Heun: the generic kernel's arithmetic, se(3)'s structure constants written out.

:func:`._generic_kernels.integrate_generic` runs this kernel instead of its own block kernel when the algebra's
non-zero structure constants are those of se(3) (:data:`SE3_TI` ... :data:`SE3_TV`, the order of
:func:`._soa_rows.algebra_tables`): :class:`~mechanics.systems.lie_algebra.SE3Algebra` (the heavy top) and
se(3) given by its constants alike. The numbers are the generic kernel's, bit for bit: every sum has the same
terms in the same order (a term :math:`(\pm1\cdot x)\,m` of the table is written :math:`\pm(x\,m)`, which
rounds alike), the exponential is the same Taylor series with each member's own degree, the velocity the same
sparse rows of ``Q`` and ``θM⁻¹`` (:func:`._soa_rows.affine_rows`), and a member with a large or non-finite
:math:`\theta` takes the same scalar path (:func:`._generic_member.rare_steps`, compiled when first needed).

What differs is the memory traffic. The generic kernel writes an output row once per non-zero constant (18
passes over the block for one ``ad*``); here one pass over the block's members computes all six components
of ``ad*`` in registers, and one pass does two Taylor degrees. Every row lives in one flat buffer at a
distance that is a compile-time constant (:data:`B` members a row), so LLVM proves the passes free of
aliasing and vectorises them without run-time checks (two separate arrays, or an offset known only at
run time, left some of them scalar). Measured (``benchmarks/bench_coadjoint_kernels.py --ratio-only``, the
heavy top of ``bench_rigid_body.py``, 1000 paths x 500 steps, default areas, the solver alone, CPU time, two
runs at load 8-11, each against the generic kernel's in the run before it): Lie–Heun 42-49 ns per path-step
(the generic kernel: 75-98), 2.1-2.3x the rigid body's on one thread, 1.9-2.3x on two (was 3.8-4.2x,
3.7-3.8x); Lie–Euler 36-37 ns (60-61), 2.0-2.1x (3.6-3.7x).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ._generic_member import exp1
from ._soa_rows import NON_FINITE, STEPS, affine_rows

#: The non-zero structure constants of se(3) in the order of :func:`._soa_rows.algebra_tables` (grouped by
#: the output component ``j``): ``(ad*_x m)_j = Σ tv · x_ti · m_tk``.
SE3_TI = np.array([1, 2, 4, 5, 0, 2, 3, 5, 0, 1, 3, 4, 1, 2, 0, 2, 0, 1])
SE3_TJ = np.array([0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 4, 4, 5, 5])
SE3_TK = np.array([2, 1, 5, 4, 2, 0, 5, 3, 1, 0, 4, 3, 5, 4, 5, 3, 4, 3])
SE3_TV = np.array([-1.0, 1, -1, 1, 1, -1, 1, -1, -1, 1, -1, 1, -1, 1, 1, -1, -1, 1])


def has_se3_table(ti, tj, tk, tv) -> bool:
    """Whether the non-zero structure constants ``(ti, tj, tk, tv)`` are se(3)'s, in this order."""
    return (np.shape(tv) == SE3_TV.shape and np.array_equal(ti, SE3_TI) and np.array_equal(tj, SE3_TJ)
            and np.array_equal(tk, SE3_TK) and np.array_equal(tv, SE3_TV))


#: Members per block: the length of a row of the work buffer (a compile-time constant, see the module docstring).
B = 128
# rows of the work buffer (each B floats): the state μ, the drift velocities w(μ), w(μ*), σ, the Taylor sum (μ at
# the start of a step, then μ*, then exp(ad*_σ) μ) and term, the velocity's work rows, the stochastic velocity, θ
_MU, _W0, _W1, _S, _A1, _TERM, _G, _T2, _E = (6 * r * B for r in range(9))
_TH = 54 * B
_NROW = 55


@numba.njit(cache=True, inline="always")
def _ad6(x0, x1, x2, x3, x4, x5, m0, m1, m2, m3, m4, m5):
    """ad*_x m on se(3)*: the generic kernel's sums (:data:`SE3_TV`'s terms in order, ``(±1·x)·m`` as ``±(x·m)``)."""
    o0 = -(x1 * m2)
    o0 += x2 * m1
    o0 -= x4 * m5
    o0 += x5 * m4
    o1 = x0 * m2
    o1 -= x2 * m0
    o1 += x3 * m5
    o1 -= x5 * m3
    o2 = -(x0 * m1)
    o2 += x1 * m0
    o2 -= x3 * m4
    o2 += x4 * m3
    o3 = -(x1 * m5)
    o3 += x2 * m4
    o4 = x0 * m5
    o4 -= x2 * m3
    o5 = -(x0 * m4)
    o5 += x1 * m3
    return o0, o1, o2, o3, o4, o5


@numba.njit(cache=True, inline="always")
def _get6(wb, at, p):
    return wb[at + p], wb[at + B + p], wb[at + 2 * B + p], wb[at + 3 * B + p], wb[at + 4 * B + p], wb[at + 5 * B + p]


@numba.njit(cache=True, inline="always")
def _set6(wb, at, p, v):
    wb[at + p] = v[0]
    wb[at + B + p] = v[1]
    wb[at + 2 * B + p] = v[2]
    wb[at + 3 * B + p] = v[3]
    wb[at + 4 * B + p] = v[4]
    wb[at + 5 * B + p] = v[5]


@numba.njit(cache=True, inline="always")
def _rows(wb, at):
    """Six rows of the buffer from ``at`` as a (6, B) view."""
    return wb[at:at + 6 * B].reshape((6, B))


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _velocity(wb, out, lin, f, theta, qs, mts, bc, yes):
    """``out`` (6 rows of ``wb``) = w(rows ``_A1``) = g + θ M⁻¹ ad*_{g+f} μ, g = Q μ + lin (rows ``_G``, ``_T2`` are
    work; ``yes`` is True, passed as a value: a literal would compile a variant of :func:`._soa_rows.affine_rows`).

    :func:`._soa_rows.velocity_rows`'s sums, but ``g + f`` also where ``f`` is 0 (the generic kernel then takes
    ``g``): the bits of w are the same. A zero of ``g`` may change sign, and with it at most the sign of a zero
    of ``ad*_{g+f} μ``; each term ``θM⁻¹ ad*`` is added to ``g_i + 0``, and a sum that starts there is never
    -0, so adding +0 or -0 leaves it as it is."""
    g = _rows(wb, _G)
    if theta == 0.0:
        affine_rows(out, lin, qs[0], qs[1], qs[2], _rows(wb, _A1), out, bc, not yes)
        return
    affine_rows(g, lin, qs[0], qs[1], qs[2], _rows(wb, _A1), g, bc, not yes)
    f0, f1, f2, f3, f4, f5 = f[0], f[1], f[2], f[3], f[4], f[5]
    for p in range(bc):                          # the offsets stay constants (see the module docstring)
        x0, x1, x2, x3, x4, x5 = _get6(wb, _G, p)
        m0, m1, m2, m3, m4, m5 = _get6(wb, _A1, p)
        _set6(wb, _T2, p, _ad6(x0 + f0, x1 + f1, x2 + f2, x3 + f3, x4 + f4, x5 + f5, m0, m1, m2, m3, m4, m5))
    affine_rows(g, mts[3], mts[0], mts[1], mts[2], _rows(wb, _T2), out, bc, yes)


@numba.njit(cache=True, inline="always")
def _tile3(dX, dXX, area, lo, bc, k0, kc, xt):
    """``xt[kk, :, p]`` = ``dX_0, dX_1, dX_2`` and (with the area) ``A_01, A_02, A_12``, ``A = ½(XX − XXᵀ)``, of member
    ``lo + p`` at step ``k0 + kk`` (member by member: the driver's arrays are read in order)."""
    for p in range(bc):
        for kk in range(kc):
            k = k0 + kk
            xt[kk, 0, p] = dX[lo + p, k, 0]
            xt[kk, 1, p] = dX[lo + p, k, 1]
            xt[kk, 2, p] = dX[lo + p, k, 2]
            if area:
                xt[kk, 3, p] = 0.5 * (dXX[lo + p, k, 0, 1] - dXX[lo + p, k, 1, 0])
                xt[kk, 4, p] = 0.5 * (dXX[lo + p, k, 0, 2] - dXX[lo + p, k, 2, 0])
                xt[kk, 5, p] = 0.5 * (dXX[lo + p, k, 1, 2] - dXX[lo + p, k, 2, 1])


@numba.njit(cache=True, inline="always")
def _eta3(x, wb, bc, xi, brk):
    """Rows ``_E`` = the stochastic velocities Σ_r dX_r ξ_r + Σ_{i<j} A_ij [ξ_i, ξ_j] of one step of the tile ``x``
    (6, B): the sums of :func:`._soa_rows.eta_rows` for three noise components, in its order. Without the area
    the tile's area rows are 0 and their terms ±0, added to a sum that starts at ``0.0 + ...`` and so is never
    -0: the same bits as the sum without them."""
    for i in range(6):
        u0, u1, u2, b0, b1, b2 = xi[0, i], xi[1, i], xi[2, i], brk[0, i], brk[1, i], brk[2, i]
        for p in range(bc):
            acc = 0.0 + x[0, p] * u0
            acc += x[1, p] * u1
            acc += x[2, p] * u2
            acc += x[3, p] * b0
            acc += x[4, p] * b1
            acc += x[5, p] * b2
            wb[_E + i * B + p] = acc


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _sigma(wb, heun, pred, dt, c, l1, l2, bc):
    """Row ``_S`` = σ = w(μ) dt + e (Lie–Euler, and Lie–Heun's predictor step) or, with ``heun``, ½(w(μ) + w(μ*)) dt
    + e; row ``_TH`` = θ = Σ|σ_i| cnorm_i; rows ``_A1`` = the Taylor sum of exp(ad*_σ) μ to degree 2, a degree added
    where θ exceeds its level ``l1``, ``l2`` (with ``pred`` every degree: μ* = (μ + ad*_σ μ) + ½ ad*_σ(ad*_σ μ), θ
    +inf); rows ``_TERM`` = the degree-2 term."""
    for p in range(bc):
        w0, w1, w2, w3, w4, w5 = _get6(wb, _W0, p)
        e0, e1, e2, e3, e4, e5 = _get6(wb, _E, p)
        if heun:
            v0, v1, v2, v3, v4, v5 = _get6(wb, _W1, p)
            s0, s1, s2 = 0.5 * (w0 + v0) * dt + e0, 0.5 * (w1 + v1) * dt + e1, 0.5 * (w2 + v2) * dt + e2
            s3, s4, s5 = 0.5 * (w3 + v3) * dt + e3, 0.5 * (w4 + v4) * dt + e4, 0.5 * (w5 + v5) * dt + e5
        else:
            s0, s1, s2, s3, s4, s5 = w0 * dt + e0, w1 * dt + e1, w2 * dt + e2, w3 * dt + e3, w4 * dt + e4, w5 * dt + e5
        _set6(wb, _S, p, (s0, s1, s2, s3, s4, s5))
        th = 0.0
        th += abs(s0) * c[0]
        th += abs(s1) * c[1]
        th += abs(s2) * c[2]
        th += abs(s3) * c[3]
        th += abs(s4) * c[4]
        th += abs(s5) * c[5]
        th = np.inf if pred else th
        wb[_TH + p] = th
        m0, m1, m2, m3, m4, m5 = _get6(wb, _MU, p)
        x0, x1, x2, x3, x4, x5 = _ad6(s0, s1, s2, s3, s4, s5, m0, m1, m2, m3, m4, m5)    # degree 1 (1/1! = 1)
        a = th > l1
        m0, m1, m2 = (m0 + x0, m1 + x1, m2 + x2) if a else (m0, m1, m2)
        m3, m4, m5 = (m3 + x3, m4 + x4, m5 + x5) if a else (m3, m4, m5)
        x0, x1, x2, x3, x4, x5 = _ad6(s0, s1, s2, s3, s4, s5, x0, x1, x2, x3, x4, x5)
        x0, x1, x2, x3, x4, x5 = x0 * 0.5, x1 * 0.5, x2 * 0.5, x3 * 0.5, x4 * 0.5, x5 * 0.5
        a = th > l2
        m0, m1, m2 = (m0 + x0, m1 + x1, m2 + x2) if a else (m0, m1, m2)
        m3, m4, m5 = (m3 + x3, m4 + x4, m5 + x5) if a else (m3, m4, m5)
        _set6(wb, _TERM, p, (x0, x1, x2, x3, x4, x5))
        _set6(wb, _A1, p, (m0, m1, m2, m3, m4, m5))


@numba.njit(cache=True, inline="always")
def _theta_max(wb, lim, big, bc):
    """``big[p]`` = not θ_p ≤ ``lim`` (NaN too: the scalar path diagnoses it); returns (their number, the largest
    θ of the others)."""
    nbig = 0
    thmax = 0.0
    for p in range(bc):
        th = wb[_TH + p]
        b = not (th <= lim)
        big[p] = b
        nbig += b
        if not b:
            thmax = max(thmax, th)
    return nbig, thmax


@numba.njit(cache=True, inline="always")
def _accept(wb, big, bc):
    """μ = the Taylor sum (rows ``_A1``) for every member that is not ``big``."""
    for i in range(6):
        for p in range(bc):
            wb[_MU + i * B + p] = wb[_A1 + i * B + p] if not big[p] else wb[_MU + i * B + p]


@numba.njit(cache=True, inline="always")
def _taylor_degrees(wb, inv1, inv2, two, l1, l2, bc):
    """Taylor degrees r and (with ``two``) r + 1: term ← ad*_σ(term) · ``inv`` (1 / r, 1 / (r + 1)), sum ← sum + term
    where the member's θ exceeds the level of the degree (the generic kernel's ``select``)."""
    for p in range(bc):
        s0, s1, s2, s3, s4, s5 = _get6(wb, _S, p)
        t0, t1, t2, t3, t4, t5 = _get6(wb, _TERM, p)
        m0, m1, m2, m3, m4, m5 = _get6(wb, _A1, p)
        th = wb[_TH + p]
        x0, x1, x2, x3, x4, x5 = _ad6(s0, s1, s2, s3, s4, s5, t0, t1, t2, t3, t4, t5)
        x0, x1, x2, x3, x4, x5 = x0 * inv1, x1 * inv1, x2 * inv1, x3 * inv1, x4 * inv1, x5 * inv1
        a = th > l1
        m0 = m0 + x0 if a else m0
        m1 = m1 + x1 if a else m1
        m2 = m2 + x2 if a else m2
        m3 = m3 + x3 if a else m3
        m4 = m4 + x4 if a else m4
        m5 = m5 + x5 if a else m5
        if two:
            x0, x1, x2, x3, x4, x5 = _ad6(s0, s1, s2, s3, s4, s5, x0, x1, x2, x3, x4, x5)
            x0, x1, x2, x3, x4, x5 = x0 * inv2, x1 * inv2, x2 * inv2, x3 * inv2, x4 * inv2, x5 * inv2
            a = th > l2
            m0 = m0 + x0 if a else m0
            m1 = m1 + x1 if a else m1
            m2 = m2 + x2 if a else m2
            m3 = m3 + x3 if a else m3
            m4 = m4 + x4 if a else m4
            m5 = m5 + x5 if a else m5
        _set6(wb, _TERM, p, (x0, x1, x2, x3, x4, x5))
        _set6(wb, _A1, p, (m0, m1, m2, m3, m4, m5))


def _kernel(full: bool):
    """:func:`run_block` (``full=False``) or :func:`run_block_full` (the exact exponential of the rare large steps
    inline): see :func:`._generic_kernels._block_kernel`. ``full`` is a closure constant."""

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def run_block(y, dX, dXX, xi, brk, pi, pj, dts, code, q, lin, f, mth, theta, tol, max_iter, ti, tj, tk, tv, cnorm,
                  degth, save, out, first_bad, reason, stop, flag, sout, lo, hi, k0, start, qs, mts, has_f):
        """Members lo .. hi-1 (at most :data:`B`) over the steps from ``k0`` on by Lie–Euler (``code`` 0) or Lie–Heun
        (``code`` 1), with the signature and the returns of :func:`._generic_kernels._block_kernel`'s kernels (the
        exact exponential of the rare large steps runs in :func:`._generic_member.rare_steps`).

        One compiled kernel for both schemes (the scheme is a value: Lie–Euler merely skips the predictor), so the
        heavy top's second scheme compiles nothing. Compile cost: the heavy top's first Lie–Heun solve with an empty
        numba cache takes 6.5 s of CPU (this kernel and the passes it calls; with the generic kernel it replaces:
        6.9 s), its first Lie–Euler solve 6.7 s (6.7 s); minima of 3-4 fresh processes at load 3-6. The passes called
        twice (:func:`_velocity`, :func:`_sigma`) are compiled functions of their own, called with flags as values
        rather than literals (numba would compile a variant per literal); those called once are inlined (as kernels
        of their own they compiled ~0.5 s longer; inlining ``_sigma`` too cost 1.5-2 s more). The heavy top no
        longer shares the generic kernel's compiled variants with the other algebras, so a process that solves both compiles both: ``tools/warm_kernels.py --part mechanics --more``
        took 57 s of CPU before, 68-79 s with this kernel (two pairs of fresh processes, load 3-6).
        """
        n = 6
        bc = hi - lo
        nk = dX.shape[1]
        area = dXX.shape[0] > 0
        c = (cnorm[0], cnorm[1], cnorm[2], cnorm[3], cnorm[4], cnorm[5])
        wb = np.empty(_NROW * B)
        xt = np.zeros((STEPS, 6, B))               # without the area its rows 3-5 stay 0 (see _eta3)
        # flags as values, not literals (numba would compile a variant of the callee per literal True / False)
        heun = code == 1
        pred = nk >= 0
        w0, w1 = _rows(wb, _W0), _rows(wb, _W1)
        big = np.empty(bc, dtype=np.bool_)
        lim = degth[degth.shape[0] - 1]
        work = (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((8, n)))
        vs, vm, vo = np.empty(n), np.empty(n), np.empty(n)
        for p in range(bc):
            for i in range(n):
                wb[_MU + i * B + p] = y[lo + p, i]
                wb[_A1 + i * B + p] = y[lo + p, i]         # rows _A1 hold μ at the start of every step
        nfail = 0
        slot = 0
        for k in range(k0):
            if save[k]:
                slot += 1
        for k in range(k0, nk):
            dt = dts[k]
            kk = (k - k0) % STEPS
            if kk == 0:
                _tile3(dX, dXX, area, lo, bc, k, min(STEPS, nk - k), xt)
            _eta3(xt[kk], wb, bc, xi, brk)
            _velocity(wb, w0, lin, f, theta, qs, mts, bc, pred)
            if heun:
                # the predictor μ* = (μ + ad*_σ* μ) + ½ ad*_σ*(ad*_σ* μ), σ* = w(μ) dt + e: Taylor degrees 1 and 2 of
                # exp(ad*_σ*) μ, every member adding both (θ row +inf), in rows _A1; then w(μ*)
                _sigma(wb, not heun, pred, dt, c, 0.0, 0.0, bc)
                _velocity(wb, w1, lin, f, theta, qs, mts, bc, pred)
            _sigma(wb, heun, not pred, dt, c, degth[0], degth[1], bc)
            # exp(ad*_σ) μ: the Taylor sum to the degree of the block's largest θ (each member adds its own degrees)
            nbig, thmax = _theta_max(wb, lim, big, bc)
            r = 3
            while thmax > degth[r - 1]:
                two = thmax > degth[r]
                _taylor_degrees(wb, 1.0 / r, 1.0 / (r + 1), two, degth[r - 1], degth[r], bc)
                r += 2 if two else 1
            if thmax > degth[0]:
                _accept(wb, big, bc)
            if nbig > 0:
                nl = 0
                for p in range(bc):
                    if big[p] and first_bad[lo + p] >= 0:        # failed before: stays NaN
                        for i in range(n):
                            wb[_MU + i * B + p] = np.nan
                            wb[_A1 + i * B + p] = np.nan
                    elif big[p]:
                        nl += 1
                if nl > 0 and not full:                         # the exact exponential: rare_steps, when needed
                    for p in range(bc):
                        flag[lo + p] = big[p] and first_bad[lo + p] < 0
                        for i in range(n):
                            y[lo + p, i] = wb[_MU + i * B + p]
                            sout[lo + p, i] = wb[_S + i * B + p]
                    return nfail, k
                if nl > 0 and full:
                    nfail += _exact_steps(wb, big, first_bad[lo:hi], reason[lo:hi], k, ti, tj, tk, tv, cnorm, degth,
                                          work, vs, vm, vo, bc)
            if save[k]:
                for p in range(bc):
                    for i in range(n):
                        out[lo + p, slot, i] = wb[_MU + i * B + p]
                slot += 1
            if stop and nfail > 0:
                break
        for p in range(bc):
            for i in range(n):
                y[lo + p, i] = wb[_MU + i * B + p]
        return nfail, -1

    return run_block


@numba.njit(cache=True, inline="always")
def _exact_steps(wb, big, first_bad, reason, k, ti, tj, tk, tv, cnorm, degth, work, vs, vm, vo, bc):
    """The exact exponential (:func:`._generic_member.exp1`) of the members of ``big`` that have not failed
    before, in the rows of ``wb``; a failure gets NaN, ``first_bad = k`` and ``reason`` NON_FINITE. Returns
    the number of first failures."""
    n = vs.shape[0]
    nnew = 0
    for p in range(bc):
        if not big[p] or first_bad[p] >= 0:
            continue
        finite_in = True
        for i in range(n):
            vm[i] = wb[_MU + i * B + p]
            vs[i] = wb[_S + i * B + p]
            if not (math.isfinite(vm[i]) and math.isfinite(vs[i])):
                finite_in = False
        ok = finite_in and exp1(vs, vm, vo, work[0], work[1], work[2], work[3][0], work[3][1], ti, tj, tk, tv,
                                cnorm, degth)
        for i in range(n):
            wb[_MU + i * B + p] = vo[i] if ok else np.nan
            wb[_A1 + i * B + p] = wb[_MU + i * B + p]
        if not ok:
            first_bad[p] = k
            reason[p] = NON_FINITE
            nnew += 1
    return nnew


#: The block kernel without, and with, the exact exponential of the rare large steps inline.
run_block, run_block_full = _kernel(False), _kernel(True)
