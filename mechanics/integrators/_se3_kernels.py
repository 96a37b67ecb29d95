r"""Compiled se(3) kernels of the coadjoint solvers (quadratic Hamiltonian): an implementation detail.

Selected by :meth:`~mechanics.integrators.base.CoadjointSolver.integrate` when the algebra is a
:class:`~mechanics.systems.lie_algebra.SE3Algebra` and the Hamiltonian is quadratic (the heavy top), for
the implicit midpoint rule only (its chord iteration, :mod:`._chord`, with the
6×6 chord Jacobian inverted per member by Gauss–Jordan elimination with partial pivoting: a singular
Jacobian fails that member alone). Same scheme as the numpy path; state ``μ = (Π, Γ)``, algebra element
``σ = (ω, v)``, :math:`\mathrm{ad}^*_{(\omega,v)}(\Pi,\Gamma) = (\Pi\times\omega + \Gamma\times v,\ \Gamma\times\omega)`
and the closed-form exponential of :func:`mechanics.systems.lie_algebra.se3_ad_star_exp`
(:math:`\Gamma' = T\Gamma`, :math:`\Pi' = T(\Pi - (Jv)\times\Gamma)`), with the one small-angle switch
and Taylor coefficients of :mod:`mechanics.lie_algebra`. Members are independent (a loop over
members, then over the block's steps); a member that becomes non-finite, or whose chord iteration
fails, is marked by itself (``reason`` NON_FINITE or CHORD_FAILED, as in :mod:`._so3_kernels`).
"""

from __future__ import annotations

import functools
import math

import numba
import numpy as np

from ..systems.lie_algebra import SMALL_ANGLE2, taylor_coefficients
from roughpaths.validation import parallel_ranges

_taylor = numba.njit(cache=True, inline="always")(taylor_coefficients)
OK, NON_FINITE, CHORD_FAILED = 0, 1, 2


@numba.njit(cache=True, inline="always")
def _ad_star(x, mu, out):
    """out = ad*_x mu on se(3)*: (Π×ω + Γ×v, Γ×ω), x = (ω, v), mu = (Π, Γ)."""
    w0, w1, w2, v0, v1, v2 = x[0], x[1], x[2], x[3], x[4], x[5]
    p0, p1, p2, g0, g1, g2 = mu[0], mu[1], mu[2], mu[3], mu[4], mu[5]
    out[0] = p1 * w2 - p2 * w1 + g1 * v2 - g2 * v1
    out[1] = p2 * w0 - p0 * w2 + g2 * v0 - g0 * v2
    out[2] = p0 * w1 - p1 * w0 + g0 * v1 - g1 * v0
    out[3] = g1 * w2 - g2 * w1
    out[4] = g2 * w0 - g0 * w2
    out[5] = g0 * w1 - g1 * w0


@numba.njit(cache=True, inline="always")
def _velocity(mu, q, lin, f, minv, theta, g, t1, t2, out):
    """out = w(mu) = g + theta M⁻¹ ad*_{g+f} mu, g = Q mu + lin (buffers g, t1, t2 of length 6)."""
    for i in range(6):
        acc = lin[i]
        for j in range(6):
            acc += q[i, j] * mu[j]
        g[i] = acc
    if theta == 0.0:
        for i in range(6):
            out[i] = g[i]
        return
    for i in range(6):
        t1[i] = g[i] + f[i]
    _ad_star(t1, mu, t2)
    for i in range(6):
        acc = 0.0
        for j in range(6):
            acc += minv[i, j] * t2[j]
        out[i] = g[i] + theta * acc


@numba.njit(cache=True, inline="always")
def _rot(w0, w1, w2, a, b, x0, x1, x2):
    # x - a ω×x + b ω×(ω×x)
    c0 = w1 * x2 - w2 * x1
    c1 = w2 * x0 - w0 * x2
    c2 = w0 * x1 - w1 * x0
    d0 = w1 * c2 - w2 * c1
    d1 = w2 * c0 - w0 * c2
    d2 = w0 * c1 - w1 * c0
    return x0 - a * c0 + b * d0, x1 - a * c1 + b * d1, x2 - a * c2 + b * d2


@numba.njit(cache=True, inline="always")
def _exp(s, mu, out):
    """out = exp(ad*_s) mu on se(3)* (closed form, one small-angle switch)."""
    w0, w1, w2, v0, v1, v2 = s[0], s[1], s[2], s[3], s[4], s[5]
    t2 = w0 * w0 + w1 * w1 + w2 * w2
    if t2 < SMALL_ANGLE2:
        a, b, c = _taylor(t2)
    else:
        t = math.sqrt(t2)
        sn = math.sin(t)
        a = sn / t
        h = math.sin(0.5 * t)
        b = 2.0 * h * h / t2
        c = (t - sn) / (t2 * t)
    # J v = v + b ω×v + c ω×(ω×v)
    c0 = w1 * v2 - w2 * v1
    c1 = w2 * v0 - w0 * v2
    c2 = w0 * v1 - w1 * v0
    j0 = v0 + b * c0 + c * (w1 * c2 - w2 * c1)
    j1 = v1 + b * c1 + c * (w2 * c0 - w0 * c2)
    j2 = v2 + b * c2 + c * (w0 * c1 - w1 * c0)
    g0, g1, g2 = mu[3], mu[4], mu[5]
    p0 = mu[0] - (j1 * g2 - j2 * g1)
    p1 = mu[1] - (j2 * g0 - j0 * g2)
    p2 = mu[2] - (j0 * g1 - j1 * g0)
    out[0], out[1], out[2] = _rot(w0, w1, w2, a, b, p0, p1, p2)
    out[3], out[4], out[5] = _rot(w0, w1, w2, a, b, g0, g1, g2)


@numba.njit(cache=True, inline="always")
def _hat_into(M, r0, c0, x0, x1, x2, sign):
    """M[r0:r0+3, c0:c0+3] = sign * hat(x) (hat(x) y = x × y)."""
    M[r0, c0], M[r0, c0 + 1], M[r0, c0 + 2] = 0.0, -sign * x2, sign * x1
    M[r0 + 1, c0], M[r0 + 1, c0 + 1], M[r0 + 1, c0 + 2] = sign * x2, 0.0, -sign * x0
    M[r0 + 2, c0], M[r0 + 2, c0 + 1], M[r0 + 2, c0 + 2] = -sign * x1, sign * x0, 0.0


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _invert6(J, Ji, W):
    """Ji = J⁻¹ (6×6) by Gauss–Jordan elimination with partial pivoting; False if a pivot is zero or
    not finite (the member then fails alone). ``W`` is a (6, 12) work array."""
    for i in range(6):
        for j in range(6):
            W[i, j] = J[i, j]
            W[i, 6 + j] = 1.0 if i == j else 0.0
    for c in range(6):
        piv = c
        best = abs(W[c, c])
        for r in range(c + 1, 6):
            v = abs(W[r, c])
            if v > best:
                best, piv = v, r
        if not (best > 0.0 and best < np.inf):
            return False
        if piv != c:
            for j in range(12):
                W[c, j], W[piv, j] = W[piv, j], W[c, j]
        inv = 1.0 / W[c, c]
        for j in range(12):
            W[c, j] *= inv
        for r in range(6):
            if r != c:
                f = W[r, c]
                if f != 0.0:
                    for j in range(12):
                        W[r, j] -= f * W[c, j]
    for i in range(6):
        for j in range(6):
            v = W[i, 6 + j]
            if not math.isfinite(v):
                return False
            Ji[i, j] = v
    return True


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _se3_chord(mu, e, s, dt, q, lin, f, minv, theta, tol, max_iter, L, Dw, J, Ji, W, g, t1, t2, m1, mid, u):
    """Chord iteration for the implicit midpoint sigma (in ``s``, started at w(mu) dt + e) on se(3)*.

    ``J = I - dt/2 Dw(mu) L(mu)`` frozen at ``mu``, ``L(mu) δ = ad*_δ mu = [[hat Π, hat Γ], [hat Γ, 0]] δ``,
    ``Dw = Q + θ M⁻¹ (ad*_{g+f} + L(mu) Q)`` (``g + f`` the gradient inside the double bracket).
    Returns True if the member converged (``max|Δσ| ≤ tol (1 + |σ|_∞)``), as the numpy chord does.
    """
    for i in range(6):
        for j in range(6):
            L[i, j] = 0.0
    _hat_into(L, 0, 0, mu[0], mu[1], mu[2], 1.0)
    _hat_into(L, 0, 3, mu[3], mu[4], mu[5], 1.0)
    _hat_into(L, 3, 0, mu[3], mu[4], mu[5], 1.0)
    for i in range(6):
        for j in range(6):
            Dw[i, j] = q[i, j]
    if theta != 0.0:
        # ad*_x mu for fixed x = (ω, v) = g + f: (-hat ω Π - hat v Γ, -hat ω Γ)
        for i in range(6):
            acc = lin[i] + f[i]
            for j in range(6):
                acc += q[i, j] * mu[j]
            g[i] = acc
        for i in range(6):
            for j in range(6):
                J[i, j] = 0.0
        _hat_into(J, 0, 0, g[0], g[1], g[2], -1.0)
        _hat_into(J, 0, 3, g[3], g[4], g[5], -1.0)
        _hat_into(J, 3, 3, g[0], g[1], g[2], -1.0)
        for i in range(6):                      # J += L(mu) Q
            for j in range(6):
                acc = 0.0
                for k in range(6):
                    acc += L[i, k] * q[k, j]
                J[i, j] += acc
        for i in range(6):                      # Dw += θ M⁻¹ J
            for j in range(6):
                acc = 0.0
                for k in range(6):
                    acc += minv[i, k] * J[k, j]
                Dw[i, j] += theta * acc
    for i in range(6):                          # J = I - dt/2 Dw L
        for j in range(6):
            acc = 0.0
            for k in range(6):
                acc += Dw[i, k] * L[k, j]
            J[i, j] = (1.0 if i == j else 0.0) - 0.5 * dt * acc
    if not _invert6(J, Ji, W):
        return False
    for it in range(max_iter):
        _exp(s, mu, m1)
        for i in range(6):
            if not math.isfinite(m1[i]):
                return False
            mid[i] = 0.5 * (mu[i] + m1[i])
        _velocity(mid, q, lin, f, minv, theta, g, t1, t2, u)
        for i in range(6):
            t1[i] = s[i] - u[i] * dt - e[i]
        err = 0.0
        smax = 0.0
        for i in range(6):
            acc = 0.0
            for j in range(6):
                acc += Ji[i, j] * t1[j]
            t2[i] = acc
        for i in range(6):
            s[i] -= t2[i]
            err = max(err, abs(t2[i]))
            smax = max(smax, abs(s[i]))
        if not (math.isfinite(err) and math.isfinite(smax)):
            return False
        if err <= tol * (1.0 + smax):
            return True
    return False


@numba.njit(cache=True, inline="always")
def _step_velocity(dX, dXX, p, k, xi, brk, pi, pj, area, e):
    """e = Σ_r dX_r ξ_r + Σ_{r: i<j} A_ij [ξ_i, ξ_j] (A = ½(XX − XXᵀ)) for member p, step k."""
    nm = dX.shape[2]
    for i in range(6):
        acc = 0.0
        for r in range(nm):
            acc += dX[p, k, r] * xi[r, i]
        e[i] = acc
    if area:
        for r in range(pi.shape[0]):
            aij = 0.5 * (dXX[p, k, pi[r], pj[r]] - dXX[p, k, pj[r], pi[r]])
            for i in range(6):
                e[i] += aij * brk[r, i]


@numba.njit(cache=True, inline="always")
def _finish_step(mu, new, ok, finite_in, p, k, first_bad, reason, save, out, slot):
    """mu = new (NaN if not ok or not finite; first failure recorded); save it. Returns (finite, slot)."""
    finite = ok
    for i in range(6):
        mu[i] = new[i]
        if not math.isfinite(new[i]):
            finite = False
    nfail = 0
    if not finite:
        for i in range(6):
            mu[i] = np.nan
        if first_bad[p] < 0:
            first_bad[p] = k
            reason[p] = NON_FINITE if (not finite_in or ok) else CHORD_FAILED
            nfail = 1
    if save[k]:
        for i in range(6):
            out[p, slot, i] = mu[i]
        slot += 1
    return finite, slot, nfail


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _se3_midpoint_block(y, dX, dXX, xi, brk, pi, pj, dts, q, lin, f, minv, theta, tol, max_iter, save, out,
                        first_bad, reason, stop, lo, hi):
    """Advance members lo .. hi-1 of y (B, 6) over dX (B, K, d), dXX (B, K, d, d) (or empty) by the implicit
    midpoint rule: sigma from the chord iteration (:func:`_se3_chord`); a member whose iteration fails gets
    ``reason = CHORD_FAILED``, a non-finite one NON_FINITE. Returns the number of members that failed."""
    nb, nk, nm = dX.shape
    area = dXX.shape[0] > 0
    mu, e, w0, s, g, t1, t2, new = (np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6), np.empty(6),
                                    np.empty(6), np.empty(6))
    L, Dw, J, Ji, W = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 12))
    m1, mid, u = np.empty(6), np.empty(6), np.empty(6)
    nfail = 0
    for p in range(lo, hi):
        for i in range(6):
            mu[i] = y[p, i]
        slot = 0
        for k in range(nk):
            dt = dts[k]
            _step_velocity(dX, dXX, p, k, xi, brk, pi, pj, area, e)
            finite_in = True
            for i in range(6):
                if not (math.isfinite(mu[i]) and math.isfinite(e[i])):
                    finite_in = False
            conv = True
            if finite_in:
                _velocity(mu, q, lin, f, minv, theta, g, t1, t2, w0)
                for i in range(6):
                    s[i] = w0[i] * dt + e[i]
                conv = _se3_chord(mu, e, s, dt, q, lin, f, minv, theta, tol, max_iter, L, Dw, J, Ji, W, g, t1, t2,
                                  m1, mid, u)
                _exp(s, mu, new)
            else:
                for i in range(6):
                    new[i] = np.nan
            finite, slot, nf = _finish_step(mu, new, conv, finite_in, p, k, first_bad, reason, save, out, slot)
            nfail += nf
            if stop and not finite:
                break
        for i in range(6):
            y[p, i] = mu[i]
    return nfail


#: Members per block of the thread split.
BLOCK = 64


def integrate_se3(system, code, tol, max_iter, y, dX, dXX, dts, save, stop_on_failure):
    """Run the se(3) implicit-midpoint kernel (``code`` 2) on ``y`` (B, 6) over ``dX`` (B, K, d), ``dXX`` (B, K, d, d)
    or None.

    Returns ``(y, saved (B, S, 6), first_bad (B,), reason (B,))``. Blocks of :data:`BLOCK` members run in
    parallel (:func:`roughpaths.validation.parallel_ranges`; ``numba.set_num_threads``). Lie–Euler and
    Lie–Heun on se(3) run the generic kernel (:mod:`._generic_kernels`), which measured faster there.
    """
    if code != 2:
        raise ValueError(f"the se(3) kernel runs the implicit midpoint rule (code 2) only, got code {code}; "
                         f"Lie-Euler and Lie-Heun use mechanics.integrators._generic_kernels.")
    data = system.quadratic_velocity_data()
    nb = y.shape[0]
    nm = dX.shape[-1]
    pi, pj = np.triu_indices(nm, 1)
    brk = np.ascontiguousarray(system.xi_brackets[pi, pj])
    y = np.array(y, dtype=np.float64, order="C")
    out = np.full((nb, int(np.count_nonzero(save)), 6), np.nan)
    first_bad = np.full(nb, -1, dtype=np.int64)
    reason = np.zeros(nb, dtype=np.int8)
    args = (y, dX, np.empty((0, 0, 0, 0)) if dXX is None else dXX, np.ascontiguousarray(system.xi), brk,
            pi.astype(np.int64), pj.astype(np.int64), np.ascontiguousarray(dts, dtype=np.float64))
    consts = (data["q"], np.ascontiguousarray(data["linear"]), np.ascontiguousarray(data["dissipation_change"]),
              data["metric_inv"], float(data["theta"]))
    tail = (np.ascontiguousarray(save, dtype=np.bool_), out, first_bad, reason, bool(stop_on_failure))
    parallel_ranges(lambda lo, hi: _se3_midpoint_block(*args, *consts, float(tol), int(max_iter), *tail, lo, hi),
                    nb, BLOCK)
    return y, out, first_bad, reason


@functools.lru_cache(maxsize=None)
def _member_kernel(C: int):
    """One step of scheme ``C`` (0 Lie–Euler, 1 Lie–Heun, 2 implicit midpoint) for members each on a step of its own
    (``dt (B,)``): the numpy path's scheme (:mod:`mechanics.integrators.base`) with this module's velocity, ``ad*``,
    closed-form exponential and chord iteration, a member at a time. ``C`` is a compile-time constant, so Lie–Euler
    and Lie–Heun compile without the chord iteration. A member whose input, Lie–Heun predictor or result is not
    finite, or whose chord iteration fails, comes back NaN with ``first_bad = 0`` and its ``reason``."""

    @numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
    def se3_members(y, e, dt, q, lin, f, minv, theta, tol, max_iter, first_bad, reason):
        V = np.empty((12, 6))
        mu, ee, w0, w1, s, a, b, mp, g, t1, t2, new = V[0], V[1], V[2], V[3], V[4], V[5], V[6], V[7], V[8], V[9], \
            V[10], V[11]
        if C == 2:                           # the chord iteration's buffers (no allocation compiled otherwise)
            L, Dw, J, Ji, W = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 12))
            m1, mid, u = np.empty(6), np.empty(6), np.empty(6)
        for p in range(y.shape[0]):
            finite_in = True
            for i in range(6):
                mu[i], ee[i] = y[p, i], e[p, i]
                if not (math.isfinite(mu[i]) and math.isfinite(ee[i])):
                    finite_in = False
            ok = finite_in
            conv = True
            if finite_in:
                _velocity(mu, q, lin, f, minv, theta, g, t1, t2, w0)
                for i in range(6):
                    s[i] = w0[i] * dt[p] + ee[i]
                    if not math.isfinite(s[i]):
                        ok = False
                if ok and C == 1:               # predictor mu + a + ½ ad*_s a, a = ad*_s mu; corrector on its velocity
                    _ad_star(s, mu, a)
                    _ad_star(s, a, b)
                    for i in range(6):
                        mp[i] = mu[i] + a[i] + 0.5 * b[i]
                        if not math.isfinite(mp[i]):
                            ok = False
                    _velocity(mp, q, lin, f, minv, theta, g, t1, t2, w1)
                    for i in range(6):
                        s[i] = 0.5 * (w0[i] + w1[i]) * dt[p] + ee[i]
                elif ok and C == 2:
                    conv = _se3_chord(mu, ee, s, dt[p], q, lin, f, minv, theta, tol, max_iter, L, Dw, J, Ji, W, g,
                                      t1, t2, m1, mid, u)
                    ok = conv
                if ok:
                    _exp(s, mu, new)
                    for i in range(6):
                        if not math.isfinite(new[i]):
                            ok = False
            for i in range(6):
                y[p, i] = new[i] if ok else np.nan
            if not ok:
                first_bad[p] = 0
                reason[p] = NON_FINITE if conv else CHORD_FAILED

    return se3_members


def se3_member_steps(system, code, tol, max_iter, mu, dt, eta):
    """One step of every member on its own step (contract item 10: adaptive steps per member), compiled
    (:func:`_member_kernel`); ``mu``, ``eta`` (B, 6), ``dt`` (B,). Returns ``(mu, ok, converged)`` as the numpy
    path's ``_advance`` does (``converged`` None but for the implicit midpoint, ``code`` 2). The heavy top, LieHeun
    adaptive per member, 1000 paths at rtol 1e-3: see ``docs/adaptive-steps.md``."""
    data = system.quadratic_velocity_data()
    B = mu.shape[0]
    y = np.array(mu, dtype=np.float64, order="C")
    first_bad, reason = np.full(B, -1, dtype=np.int64), np.zeros(B, dtype=np.int8)
    own = lambda a: np.array(a, dtype=np.float64, order="C")      # noqa: E731  writeable copies: one signature
    _member_kernel(int(code))(y, own(eta), own(dt), own(data["q"]), own(data["linear"]),
                              own(data["dissipation_change"]), own(data["metric_inv"]), float(data["theta"]),
                              float(tol), int(max_iter), first_bad, reason)
    return y, first_bad < 0, (reason != CHORD_FAILED) if code == 2 else None
