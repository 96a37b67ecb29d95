r"""One member of the generic coadjoint kernel (scalar code): the exponential, the velocity, the chord iteration.

Used by :mod:`._generic_kernels` for the members its vectorised block path does not take (a large or
non-finite :math:`\theta`) and for the implicit midpoint rule (the chord iteration runs member by
member). Shapes: ``mu``, ``s``, ``e`` (n,); the structure constants as their non-zeros ``(ti, tj, tk, tv)``
and ``cnorm`` (:func:`._generic_kernels.algebra_tables`).

The Taylor degrees: ``DEGREE_THETA[m]`` is the largest :math:`\theta` for which the degree-``m`` Taylor
polynomial of :math:`e^{A}` (:math:`\|A\|\le\theta`) leaves a remainder :math:`\theta^{m+1}/(m+1)!\le 2^{-54}`
(relative to :math:`|\mu|`; with the factor :math:`e^\theta` of the remainder the bound is :math:`2^{-51}` at
:data:`THETA_VECTOR` :math:`\approx 2.06`, below the rounding of the sum). The vector path's largest degree is 23
(it was 18, :math:`\theta\le 1.106`): su(6)'s θ bound (a sum over 35 components) passes 1.1 at ordinary
steps, and each such step cost a 35 × 35 scaling and squaring. Measured, LieHeun on su(6), 256 members × 200
steps with θ ≈ 1.5, one thread: 14.5 s before, 0.26 s after; the result agrees with a 40-digit matrix
exponential to 2.4 ε relative to :math:`|\mu|` for θ in (1.2, 2.06] on su(2), su(3), su(6).

The implicit midpoint rule (:func:`midpoint1`) is the costly case, so its code is compiled per algebra
dimension for ``n`` = 3 and 6 (an ``nd`` tuple of ``n`` zeros makes ``n`` a constant, see :func:`dim`; other
dimensions read ``n`` from the arrays), the velocity skips the zeros of ``Q`` and ``θM⁻¹``, and the
exponential inside the chord iteration forms ``ad*_σ`` once as a dense matrix (:func:`exp_dense1`).
Measured (``benchmarks/bench_coadjoint_kernels.py``, heavy top): 3.7x the hand-written se(3) kernel
before, 2.8-2.9x after.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ._soa_rows import NON_FINITE

_TOL = 2.0 ** -54

#: Largest Taylor degree of the vector path.
MAX_DEGREE = 23


def _degree_table():
    th = np.empty(MAX_DEGREE + 1)
    fact = 1.0
    for m in range(MAX_DEGREE + 1):
        fact *= m + 1                                          # (m + 1)!
        th[m] = (_TOL * fact) ** (1.0 / (m + 1))
    return th


#: ``DEGREE_THETA[m]``: the largest θ for which Taylor degree ``m`` is below round-off (increasing).
DEGREE_THETA = _degree_table()
#: Members with θ above this take the scalar scaling-and-squaring path.
THETA_VECTOR = float(DEGREE_THETA[MAX_DEGREE])
_THETA_SCALED = 0.5
_MAX_SQUARINGS = 1100


#: ``nd`` arguments: a tuple of ``n`` zeros makes the dimension a compile-time constant (numba compiles one
#: variant per tuple length, LLVM unrolls the loops over ``n``); ``()`` reads it from the arrays.
DIMS3, DIMS6 = (0, 0, 0), (0, 0, 0, 0, 0, 0)


@numba.njit(cache=True, inline="always")
def dim(nd, a):
    """The algebra dimension: ``len(nd)`` (a constant of the compiled variant) if ``nd`` is not empty, else
    ``a.shape[0]``."""
    if len(nd) > 0:
        return len(nd)
    return a.shape[0]


@numba.njit(cache=True, inline="always")
def ad_star1(x, mu, out, ti, tj, tk, tv, nd=()):
    """out = ad*_x mu from the non-zeros of the structure constants (grouped by ``tj``: each output
    component is summed in a register, from 0.0, in the order of the table)."""
    for j in range(dim(nd, out)):
        out[j] = 0.0
    nt = tv.shape[0]
    t = 0
    while t < nt:
        j = tj[t]
        acc = 0.0
        while t < nt and tj[t] == j:
            acc += tv[t] * x[ti[t]] * mu[tk[t]]
            t += 1
        out[j] = acc


@numba.njit(cache=True, inline="always")
def _sparse_affine(base, cols, vals, start, x, out, nd):
    """out[i] = base[i] + Σ_t vals[t] x[cols[t]] over row ``i``'s non-zeros (``start[i] .. start[i+1]``), in order."""
    for i in range(dim(nd, out)):
        acc = base[i]
        for t in range(start[i], start[i + 1]):
            acc += vals[t] * x[cols[t]]
        out[i] = acc


@numba.njit(cache=True, inline="always")
def velocity1(mu, qs, lin, f, mts, theta, g, t1, t2, out, ti, tj, tk, tv, nd=()):
    """out = w(mu) = g + θ M⁻¹ ad*_{g+f} mu, g = Q mu + lin; ``qs``, ``mts``: the non-zeros of Q and θ M⁻¹ by rows
    (:func:`._generic_kernels.sparse_rows`; the zeros of the dense products are skipped, the other terms are
    added in the same order); g, t1, t2: work."""
    n = dim(nd, mu)
    _sparse_affine(lin, qs[0], qs[1], qs[2], mu, g, nd)
    if theta == 0.0:
        for i in range(n):
            out[i] = g[i]
        return
    for i in range(n):
        t1[i] = g[i] + f[i]
    ad_star1(t1, mu, t2, ti, tj, tk, tv, nd)
    _sparse_affine(g, mts[0], mts[1], mts[2], t2, out, nd)


@numba.njit(cache=True, inline="always")
def theta_bound(s, cnorm, nd=()):
    """θ = Σ_i |s_i| cnorm_i ≥ ‖ad*_s‖_∞."""
    th = 0.0
    for i in range(dim(nd, s)):
        th += abs(s[i]) * cnorm[i]
    return th


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def exp1(s, mu, out, A, E, T, term, term2, ti, tj, tk, tv, cnorm, degth, nd=()):
    """out = exp(ad*_s) mu for one member; False if not finite. Vector Taylor for θ ≤ THETA_VECTOR
    (the block path's series, to the degree of the table), else matrix scaling and squaring."""
    n = dim(nd, mu)
    th = theta_bound(s, cnorm, nd)
    if not math.isfinite(th):
        return False
    if th <= degth[degth.shape[0] - 1]:
        for j in range(n):
            out[j] = mu[j]
            term[j] = mu[j]
        r = 1
        while th > degth[r - 1]:
            ad_star1(s, term, term2, ti, tj, tk, tv, nd)
            inv = 1.0 / r
            for j in range(n):
                term[j] = term2[j] * inv
                out[j] = out[j] + term[j]
            r += 1
    else:
        nsq = 0
        scale = 1.0
        while th > _THETA_SCALED:
            th *= 0.5
            scale *= 0.5
            nsq += 1
            if nsq > _MAX_SQUARINGS:
                return False
        for j in range(n):
            for k in range(n):
                A[j, k] = 0.0
        for t in range(tv.shape[0]):
            A[tj[t], tk[t]] += tv[t] * s[ti[t]] * scale
        m = 0
        while th > degth[m]:
            m += 1
        for j in range(n):                              # Horner: E = I + A E / r, r = m .. 1
            for k in range(n):
                E[j, k] = 1.0 if j == k else 0.0
        for r in range(m, 0, -1):
            inv = 1.0 / r
            for j in range(n):
                for k in range(n):
                    acc = 0.0
                    for l in range(n):
                        acc += A[j, l] * E[l, k]
                    T[j, k] = acc * inv
            for j in range(n):
                for k in range(n):
                    E[j, k] = T[j, k] + (1.0 if j == k else 0.0)
        for _ in range(nsq):
            for j in range(n):
                for k in range(n):
                    acc = 0.0
                    for l in range(n):
                        acc += E[j, l] * E[l, k]
                    T[j, k] = acc
            for j in range(n):
                for k in range(n):
                    E[j, k] = T[j, k]
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += E[j, k] * mu[k]
            out[j] = acc
    for j in range(n):
        if not math.isfinite(out[j]):
            return False
    return True


@numba.njit(cache=True, inline="always")
def exp_dense1(s, mu, out, A, E, T, term, term2, ti, tj, tk, tv, cnorm, degth, nd=()):
    """:func:`exp1` for the implicit midpoint rule: the same Taylor degree, but ``ad*_s`` is formed once as a
    dense matrix (stored transposed, ``A[k, j]``) and each term is a matrix-vector product over the rows of
    ``A`` (vectorised over ``j``; with ``nd`` of length 3 or 6 fully unrolled) instead of a pass over the
    non-zero structure constants. Same numbers to round-off; large or non-finite θ: :func:`exp1`."""
    n = dim(nd, mu)
    th = theta_bound(s, cnorm, nd)
    if not (th <= degth[degth.shape[0] - 1]):
        return exp1(s, mu, out, A, E, T, term, term2, ti, tj, tk, tv, cnorm, degth, nd)
    for k in range(n):
        for j in range(n):
            A[k, j] = 0.0
    for t in range(tv.shape[0]):                       # (ad*_s m)_j = Σ_k A[k, j] m_k
        A[tk[t], tj[t]] += tv[t] * s[ti[t]]
    for j in range(n):
        out[j] = mu[j]
        term[j] = mu[j]
    r = 1
    while th > degth[r - 1]:
        for j in range(n):
            term2[j] = 0.0
        for k in range(n):
            x = term[k]
            for j in range(n):
                term2[j] += A[k, j] * x
        inv = 1.0 / r
        for j in range(n):
            term[j] = term2[j] * inv
            out[j] = out[j] + term[j]
        r += 1
    for j in range(n):
        if not math.isfinite(out[j]):
            return False
    return True


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def invert(J, Ji, W, nd=()):
    """Ji = J⁻¹ (n × n) by Gauss–Jordan elimination with partial pivoting; False if singular / not finite."""
    n = dim(nd, J)
    for i in range(n):
        for j in range(n):
            W[i, j] = J[i, j]
            W[i, n + j] = 1.0 if i == j else 0.0
    for c in range(n):
        piv = c
        best = abs(W[c, c])
        for r in range(c + 1, n):
            v = abs(W[r, c])
            if v > best:
                best, piv = v, r
        if not (best > 0.0 and best < np.inf):
            return False
        if piv != c:
            for j in range(2 * n):
                W[c, j], W[piv, j] = W[piv, j], W[c, j]
        inv = 1.0 / W[c, c]
        for j in range(2 * n):
            W[c, j] *= inv
        for r in range(n):
            if r != c:
                fr = W[r, c]
                if fr != 0.0:
                    for j in range(2 * n):
                        W[r, j] -= fr * W[c, j]
    for i in range(n):
        for j in range(n):
            v = W[i, n + j]
            if not math.isfinite(v):
                return False
            Ji[i, j] = v
    return True


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def chord1(mu, e, s, dt, q, qs, lin, f, mts, theta, tol, max_iter, ti, tj, tk, tv, cnorm, degth, w, nd=()):
    """Chord iteration of the implicit midpoint rule for one member (``s`` in/out, started at
    w(mu) dt + e): J = I - dt/2 Dw(mu) L(mu), frozen; stops when max|Δσ| ≤ tol (1 + |σ|_∞)."""
    n = dim(nd, mu)
    Dw, J, Ji, W, A, E, T = w[1], w[2], w[3], w[4], w[5], w[6], w[7]
    g, t1, t2, m1, mid, u, term, term2 = w[8][0], w[8][1], w[8][2], w[8][3], w[8][4], w[8][5], w[8][6], w[8][7]
    # L(mu) δ = ad*_δ mu, L[j, i] = Σ_k mu_k c[i, j, k], is applied through the non-zeros of c (never formed)
    for i in range(n):
        for j in range(n):
            Dw[i, j] = q[i, j]
    if theta != 0.0:
        for i in range(n):                             # gradient inside the double bracket, g + f
            acc = lin[i] + f[i]
            for j in range(n):
                acc += q[i, j] * mu[j]
            g[i] = acc
        for j in range(n):                             # A = L(mu) Q + ad*_{g+f} (matrix), L from the non-zeros
            for k in range(n):
                A[j, k] = 0.0
        for t in range(tv.shape[0]):
            cf = tv[t] * mu[tk[t]]
            j, i = tj[t], ti[t]
            for k in range(n):
                A[j, k] += cf * q[i, k]
        for t in range(tv.shape[0]):
            A[tj[t], tk[t]] += tv[t] * g[ti[t]]
        for i in range(n):                             # Dw = Q + θ M⁻¹ A (the non-zeros of θ M⁻¹)
            for j in range(n):
                acc = 0.0
                for t in range(mts[2][i], mts[2][i + 1]):
                    acc += mts[1][t] * A[mts[0][t], j]
                Dw[i, j] += acc
    for i in range(n):                                 # J = I - dt/2 Dw L, L from the non-zeros
        for j in range(n):
            J[i, j] = 0.0
    for t in range(tv.shape[0]):
        cf = tv[t] * mu[tk[t]]
        j, i = tj[t], ti[t]
        for a in range(n):
            J[a, i] += Dw[a, j] * cf
    for i in range(n):
        for j in range(n):
            J[i, j] = (1.0 if i == j else 0.0) - 0.5 * dt * J[i, j]
    if not invert(J, Ji, W, nd):
        return False
    for it in range(max_iter):
        if not exp_dense1(s, mu, m1, A, E, T, term, term2, ti, tj, tk, tv, cnorm, degth, nd):
            return False
        for i in range(n):
            mid[i] = 0.5 * (mu[i] + m1[i])
        velocity1(mid, qs, lin, f, mts, theta, g, t1, t2, u, ti, tj, tk, tv, nd)
        for i in range(n):
            t1[i] = s[i] - u[i] * dt - e[i]
        err = 0.0
        smax = 0.0
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += Ji[i, j] * t1[j]
            t2[i] = acc
        for i in range(n):
            s[i] -= t2[i]
            err = max(err, abs(t2[i]))
            smax = max(smax, abs(s[i]))
        if not (math.isfinite(err) and math.isfinite(smax)):
            return False
        if err <= tol * (1.0 + smax):
            return True
    return False


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def midpoint1(mu, e, s, out, dt, q, qs, lin, f, mts, theta, tol, max_iter, ti, tj, tk, tv, cnorm, degth, w, nd=()):
    """One implicit-midpoint step of one member: ``s = w(mu) dt + e``, the chord iteration, ``out = exp(ad*_s) mu``.

    Returns ``(ok, chord_failed)``; ``w`` is the work tuple of :func:`chord1`."""
    n = dim(nd, mu)
    velocity1(mu, qs, lin, f, mts, theta, w[8][0], w[8][1], w[8][2], out, ti, tj, tk, tv, nd)
    for i in range(n):
        s[i] = out[i] * dt + e[i]
    if not chord1(mu, e, s, dt, q, qs, lin, f, mts, theta, tol, max_iter, ti, tj, tk, tv, cnorm, degth, w, nd):
        return False, True
    return exp_dense1(s, mu, out, w[5], w[6], w[7], w[8][6], w[8][7], ti, tj, tk, tv, cnorm, degth, nd), False


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def rare_steps(y, sout, flag, ti, tj, tk, tv, cnorm, degth, first_bad, reason, k):
    """The exact exponential (:func:`exp1`, scaling and squaring) of the flagged members of one
    block, rows ``y`` (B, n) and their step's ``σ`` in ``sout`` (B, n): the steps the vectorised Taylor loop
    left (θ past :data:`THETA_VECTOR`, or non-finite). Its own kernel, compiled only when a
    solve reaches such a step (about 1.2 s of CPU that a sane run never pays). A member that fails gets NaN
    and, on its first failure, ``first_bad = k`` and ``reason`` NON_FINITE. Returns the number of first
    failures."""
    n = y.shape[1]
    work = (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((8, n)))
    vs, vm, vo = np.empty(n), np.empty(n), np.empty(n)
    nnew = 0
    for p in range(y.shape[0]):
        if not flag[p]:
            continue
        finite_in = True
        for i in range(n):
            vm[i] = y[p, i]
            vs[i] = sout[p, i]
            if not (math.isfinite(vm[i]) and math.isfinite(vs[i])):
                finite_in = False
        ok = finite_in and exp1(vs, vm, vo, work[0], work[1], work[2], work[3][6], work[3][7], ti, tj, tk, tv,
                                cnorm, degth)
        for i in range(n):
            y[p, i] = vo[i] if ok else np.nan
        if not ok:
            first_bad[p] = k
            reason[p] = NON_FINITE
            nnew += 1
    return nnew
