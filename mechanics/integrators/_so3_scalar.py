r"""The exact scalar so(3) step of the coadjoint solvers (quadratic Hamiltonian): an implementation detail.

The block kernels of :mod:`._so3_kernels` take every step in a vectorised loop with the Taylor branch of the
Rodrigues factors; a member whose ``|sigma|²`` is past it (or non-finite), and every member of the implicit
midpoint rule (the chord iteration), takes the scalar step here: :func:`_so3_step` per member, with the
exact trigonometric factors. :func:`so3_rare_steps` is its own kernel, compiled only when a Lie–Euler or
Lie–Heun solve first reaches such a step. Members on steps of their own (adaptive steps per member) take it too,
each with its own ``dt`` (:func:`._so3_kernels.so3_member_steps`).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types
from numba.extending import overload

from ..systems.lie_algebra import SMALL_ANGLE2, taylor_coefficients

OK, NON_FINITE, CHORD_FAILED = 0, 1, 2

_taylor = numba.njit(cache=True, inline="always")(taylor_coefficients)

@numba.njit(cache=True, inline="always")
def _rod(s0, s1, s2, m0, m1, m2):
    # exp(ad*_s) m = m - a s×m + b s×(s×m), a = sin t / t, b = (1 - cos t)/t²
    t2 = s0 * s0 + s1 * s1 + s2 * s2
    if t2 < SMALL_ANGLE2:
        a, b, _ = _taylor(t2)                # exact in float64 there; no transcendental calls
    else:
        t = math.sqrt(t2)
        a = math.sin(t) / t
        h = math.sin(0.5 * t)
        b = 2.0 * h * h / t2
    c0 = s1 * m2 - s2 * m1
    c1 = s2 * m0 - s0 * m2
    c2 = s0 * m1 - s1 * m0
    d0 = s1 * c2 - s2 * c1
    d1 = s2 * c0 - s0 * c2
    d2 = s0 * c1 - s1 * c0
    return m0 - a * c0 + b * d0, m1 - a * c1 + b * d1, m2 - a * c2 + b * d2


@numba.njit(cache=True, inline="always")
def _w3(q, lin, minv, theta, m0, m1, m2):
    # lin (6,): lin[0:3] = b + shift (conservative gradient g = Q mu + lin[0:3]); lin[3:6] = the change of
    # the gradient inside the double bracket, f = g + lin[3:6] (0, or -shift with levy_in_dissipation=False)
    g0 = q[0, 0] * m0 + q[0, 1] * m1 + q[0, 2] * m2 + lin[0]
    g1 = q[1, 0] * m0 + q[1, 1] * m1 + q[1, 2] * m2 + lin[1]
    g2 = q[2, 0] * m0 + q[2, 1] * m1 + q[2, 2] * m2 + lin[2]
    if theta == 0.0:
        return g0, g1, g2
    f0, f1, f2 = g0 + lin[3], g1 + lin[4], g2 + lin[5]
    # v = ad*_f mu = mu × f ; w = g + theta * Minv v
    v0 = m1 * f2 - m2 * f1
    v1 = m2 * f0 - m0 * f2
    v2 = m0 * f1 - m1 * f0
    return (g0 + theta * (minv[0, 0] * v0 + minv[0, 1] * v1 + minv[0, 2] * v2),
            g1 + theta * (minv[1, 0] * v0 + minv[1, 1] * v1 + minv[1, 2] * v2),
            g2 + theta * (minv[2, 0] * v0 + minv[2, 1] * v1 + minv[2, 2] * v2))


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _so3_chord(m0, m1, m2, e0, e1, e2, s0, s1, s2, dt, q, lin, minv, theta, tol, max_iter):
    """Chord iteration for the implicit midpoint sigma on so(3)*; returns sigma and a convergence flag."""
    # chord Jacobian J = I - dt/2 Dw(mu) L(mu), L(mu) d = ad*_d mu = mu × d; g: the gradient inside
    # the double bracket (see _w3 for the layout of lin)
    g0 = q[0, 0] * m0 + q[0, 1] * m1 + q[0, 2] * m2 + lin[0] + lin[3]
    g1 = q[1, 0] * m0 + q[1, 1] * m1 + q[1, 2] * m2 + lin[1] + lin[4]
    g2 = q[2, 0] * m0 + q[2, 1] * m1 + q[2, 2] * m2 + lin[2] + lin[5]
    # small matrix products as loops (numba's ``@`` on 3x3 arrays compiles a BLAS call: ~3 s of CPU)
    L = np.zeros((3, 3))
    L[0, 1], L[0, 2], L[1, 0], L[1, 2], L[2, 0], L[2, 1] = -m2, m1, m2, -m0, -m1, m0
    Dw = q.copy()
    if theta != 0.0:
        # d(mu × g) = -hat(g) dmu + hat(mu) q dmu
        B = np.zeros((3, 3))
        B[0, 1], B[0, 2], B[1, 0], B[1, 2], B[2, 0], B[2, 1] = g2, -g1, -g2, g0, g1, -g0
        for i in range(3):
            for j in range(3):
                for k in range(3):
                    B[i, j] += L[i, k] * q[k, j]
        for i in range(3):
            for j in range(3):
                acc = 0.0
                for k in range(3):
                    acc += minv[i, k] * B[k, j]
                Dw[i, j] += theta * acc
    J = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for k in range(3):
                acc += Dw[i, k] * L[k, j]
            J[i, j] = (1.0 if i == j else 0.0) - 0.5 * dt * acc
    # 3x3 inverse by cofactors: a singular or non-finite Jacobian fails this member alone (LAPACK's
    # inv would raise and abort the whole block)
    c00 = J[1, 1] * J[2, 2] - J[1, 2] * J[2, 1]
    c01 = J[1, 2] * J[2, 0] - J[1, 0] * J[2, 2]
    c02 = J[1, 0] * J[2, 1] - J[1, 1] * J[2, 0]
    det = J[0, 0] * c00 + J[0, 1] * c01 + J[0, 2] * c02
    ok = False
    if not (det != 0.0 and abs(det) < np.inf):
        return s0, s1, s2, ok
    Ji = np.empty((3, 3))
    Ji[0, 0], Ji[1, 0], Ji[2, 0] = c00 / det, c01 / det, c02 / det
    Ji[0, 1] = (J[0, 2] * J[2, 1] - J[0, 1] * J[2, 2]) / det
    Ji[1, 1] = (J[0, 0] * J[2, 2] - J[0, 2] * J[2, 0]) / det
    Ji[2, 1] = (J[0, 1] * J[2, 0] - J[0, 0] * J[2, 1]) / det
    Ji[0, 2] = (J[0, 1] * J[1, 2] - J[0, 2] * J[1, 1]) / det
    Ji[1, 2] = (J[0, 2] * J[1, 0] - J[0, 0] * J[1, 2]) / det
    Ji[2, 2] = (J[0, 0] * J[1, 1] - J[0, 1] * J[1, 0]) / det
    for it in range(max_iter):
        n0, n1, n2 = _rod(s0, s1, s2, m0, m1, m2)
        u0, u1, u2 = _w3(q, lin, minv, theta, 0.5 * (m0 + n0), 0.5 * (m1 + n1), 0.5 * (m2 + n2))
        r0 = s0 - u0 * dt - e0
        r1 = s1 - u1 * dt - e1
        r2 = s2 - u2 * dt - e2
        d0 = Ji[0, 0] * r0 + Ji[0, 1] * r1 + Ji[0, 2] * r2
        d1 = Ji[1, 0] * r0 + Ji[1, 1] * r1 + Ji[1, 2] * r2
        d2 = Ji[2, 0] * r0 + Ji[2, 1] * r1 + Ji[2, 2] * r2
        s0 -= d0
        s1 -= d1
        s2 -= d2
        err = max(abs(d0), abs(d1), abs(d2))
        if not (err == err):
            break
        if err <= tol * (1.0 + max(abs(s0), abs(s1), abs(s2))):
            ok = True
            break
    return s0, s1, s2, ok


@numba.njit(cache=True, inline="always")
def _so3_step(m0, m1, m2, e0, e1, e2, dt, q, lin, minv, theta, code, tol, max_iter):
    """One coadjoint step on so(3)*; returns the new state and a convergence flag."""
    w0, w1, w2 = _w3(q, lin, minv, theta, m0, m1, m2)
    s0, s1, s2 = w0 * dt + e0, w1 * dt + e1, w2 * dt + e2
    if code == 1:
        # predictor mu* = (1 + ad*_s + ½ ad*_s²) mu (local error O(|s|³): enough for both orders)
        c0 = m1 * s2 - m2 * s1
        c1 = m2 * s0 - m0 * s2
        c2 = m0 * s1 - m1 * s0
        p0 = m0 + c0 + 0.5 * (c1 * s2 - c2 * s1)
        p1 = m1 + c1 + 0.5 * (c2 * s0 - c0 * s2)
        p2 = m2 + c2 + 0.5 * (c0 * s1 - c1 * s0)
        v0, v1, v2 = _w3(q, lin, minv, theta, p0, p1, p2)
        s0 = 0.5 * (w0 + v0) * dt + e0
        s1 = 0.5 * (w1 + v1) * dt + e1
        s2 = 0.5 * (w2 + v2) * dt + e2
    elif code == 2:
        s0, s1, s2, ok = _so3_chord(m0, m1, m2, e0, e1, e2, s0, s1, s2, dt, q, lin, minv, theta, tol, max_iter)
        if not ok:
            return m0, m1, m2, False
    n0, n1, n2 = _rod(s0, s1, s2, m0, m1, m2)
    return n0, n1, n2, True


def _dt_of(dt, p):  # pragma: no cover - compiled only, by its overload
    """Member ``p``'s step: ``dt[p]`` of an array of steps per member, or ``dt`` itself, one step for all."""


@overload(_dt_of, inline="always")
def _dt_of_overload(dt, p):
    if isinstance(dt, types.Array):
        return lambda dt, p: dt[p]
    return lambda dt, p: dt


@numba.njit(cache=True, inline="always")
def so3_scalar_steps(ma, mb, mc, ea, eb, ec, bad, dt, q, lin, minv, theta, code, tol, max_iter, first_bad, reason, k):
    """The scalar exact step (:func:`_so3_step`) for the members flagged in ``bad``, with the step ``dt`` (a float,
    or ``(B,)``, one per member); a member that fails gets NaN and, on its first failure, ``first_bad = k`` and
    ``reason``. Returns the number of first failures."""
    nnew = 0
    for p in range(ma.shape[0]):
        if bad[p]:
            m0, m1, m2, e0, e1, e2 = ma[p], mb[p], mc[p], ea[p], eb[p], ec[p]
            finite_in = math.isfinite(m0 + m1 + m2) and math.isfinite(e0 + e1 + e2)
            ok = False
            finite_out = False
            if finite_in:
                m0, m1, m2, ok = _so3_step(m0, m1, m2, e0, e1, e2, _dt_of(dt, p), q, lin, minv, theta, code, tol,
                                            max_iter)
                finite_out = math.isfinite(m0 + m1 + m2)
            if not (ok and finite_out):
                if first_bad[p] < 0:
                    first_bad[p] = k
                    reason[p] = NON_FINITE if (not finite_in or ok) else CHORD_FAILED
                    nnew += 1
                m0 = m1 = m2 = np.nan
            ma[p], mb[p], mc[p] = m0, m1, m2
    return nnew


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def so3_rare_steps(y, e, bad, dt, q, lin, minv, theta, code, tol, max_iter, first_bad, reason, k):
    """:func:`so3_scalar_steps` on rows ``y`` (B, 3), ``e`` (B, 3) of one block: the steps the vector loop left
    (``|sigma|²`` past the Taylor branch, or non-finite). Its own kernel, compiled only when a solve reaches
    such a step (about 1.4 s of CPU at load 1, 3 s at load 2, that a sane run never pays)."""
    ma, mb, mc = y[:, 0].copy(), y[:, 1].copy(), y[:, 2].copy()
    nnew = so3_scalar_steps(ma, mb, mc, e[:, 0].copy(), e[:, 1].copy(), e[:, 2].copy(), bad, dt, q, lin, minv,
                             theta, code, tol, max_iter, first_bad, reason, k)
    for p in range(y.shape[0]):
        y[p, 0], y[p, 1], y[p, 2] = ma[p], mb[p], mc[p]
    return nnew
