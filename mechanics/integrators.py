r"""Casimir-preserving coadjoint integrators driven by level-2 rough-path increments.

Every scheme updates

.. math::  \mu_{n+1} = \mathrm{Ad}^*_{\exp\sigma_n}\mu_n := \exp(\mathrm{ad}^*_{\sigma_n})\,\mu_n,

so :math:`\mu_{n+1}` stays on the coadjoint orbit of :math:`\mu_n` and every Casimir is conserved to
round-off. The Lie-algebra increment is :math:`\sigma_n = \bar w\,\Delta t_n + \eta_n` with the
*stochastic velocity*

.. math::  \eta_n = \sum_i \xi_i X^i_{n} + \tfrac12\sum_{i,j} A^{ij}_n[\xi_i,\xi_j],

built from the step's increment :math:`X_n` and Lévy area :math:`A_n = \tfrac12(\mathbb X_n - \mathbb X_n^T)`
(the level-2 log-signature), and a drift velocity :math:`\bar w` (:math:`w(\mu) = \nabla\tilde h +
\vartheta(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp`, :mod:`mechanics.lie_poisson`):

* :class:`LieEuler`: :math:`\bar w = w(\mu_n)`;
* :class:`LieHeun`: :math:`\bar w = \tfrac12(w(\mu_n) + w(\mu^*))`,
  :math:`\mu^* = (1 + \mathrm{ad}^*_{\sigma^*} + \tfrac12(\mathrm{ad}^*_{\sigma^*})^2)\mu_n`,
  :math:`\sigma^* = w(\mu_n)\Delta t + \eta_n` (the predictor need not lie on the orbit: it only
  feeds the drift velocity; its :math:`O(|\sigma|^3)` error keeps both orders);
* :class:`ImplicitMidpoint` (the paper's appendix scheme): :math:`\bar w = w(\tfrac12(\mu_n+\mu_{n+1}))`,
  solved by the chord method (Newton with the Jacobian frozen at :math:`\mu_n`).

Why the area term, and why :math:`+\tfrac12`: the noise fields are linear, :math:`V_i\mu = B_i\mu` with
:math:`B_i = \mathrm{ad}^*_{\xi_i}`; Davie's step contains :math:`B_jB_i\mathbb X^{ij} = \tfrac12(B_iX^i)^2 +
\tfrac12A^{ij}(B_jB_i - B_iB_j)`, and :math:`B_jB_i - B_iB_j = \mathrm{ad}^*_{[\xi_i,\xi_j]}`. The second-order
term of :math:`\exp(\mathrm{ad}^*_\sigma)` reproduces both exactly when :math:`\sigma\ni\tfrac12A^{ij}[\xi_i,\xi_j]`.
With the area the schemes have strong order 1 for Brownian drivers (order 2 in ``dt`` without
noise, for Lie–Heun and the midpoint rule); without it, only order ½ for non-commuting ``ξ``.
Perturbing the area, :math:`A\mapsto A + \mathsf s\Delta t`, adds exactly
:math:`\ell\Delta t = \tfrac12\mathsf s^{ij}[\xi_i,\xi_j]\Delta t` to :math:`\sigma_n`: the discrete
Proposition 2.1.

Entry points: :func:`simulate` (a materialised :class:`roughpaths.RoughPath`) and
:func:`simulate_brownian` (Stratonovich Brownian motion generated in time chunks, constant memory).
For so(3) with a quadratic Hamiltonian both run a numba kernel; other algebras use a batched numpy
loop (``Ad*exp`` in closed form for so(3)/se(3), batched ``expm`` otherwise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from roughpaths._validation import as_float_array, check_positive_int, check_rng
from roughpaths.rough_path import RoughPath

from .lie_algebra import rodrigues_ad_star_exp
from .lie_poisson import LiePoissonSystem

__all__ = [
    "LieEuler",
    "LieHeun",
    "ImplicitMidpoint",
    "ChordConvergenceError",
    "coadjoint_step",
    "simulate",
    "simulate_brownian",
    "check_on_orbit",
]


class ChordConvergenceError(RuntimeError):
    """The implicit midpoint's chord iteration did not converge (the message names the step)."""


@dataclass(frozen=True)
class LieEuler:
    """Explicit Lie–Euler: :math:`\\sigma_n = w(\\mu_n)\\Delta t + \\eta_n` (order 1 in dt; strong order 1 with area)."""

    code = 0


@dataclass(frozen=True)
class LieHeun:
    """Explicit Lie–Heun (predictor–corrector on the drift velocity; the noise part is additive in
    :math:`\\mathfrak g`, so it enters predictor and corrector alike). Order 2 in ``dt`` without noise."""

    code = 1


@dataclass(frozen=True)
class ImplicitMidpoint:
    r"""The paper's implicit midpoint Munthe-Kaas step, :math:`\bar w = w(\tfrac12(\mu_n+\mu_{n+1}))`.

    Solved for :math:`\sigma_n` by the chord method: :math:`\sigma\leftarrow\sigma - J^{-1}F(\sigma)`,
    :math:`F(\sigma) = \sigma - w(\tfrac12(\mu_n + e^{\mathrm{ad}^*_\sigma}\mu_n))\Delta t - \eta_n`,
    :math:`J = I - \tfrac{\Delta t}2 Dw(\mu_n) L(\mu_n)` with :math:`L(\mu)\delta = \mathrm{ad}^*_\delta\mu`
    (frozen for the step). Stops when :math:`\max|\Delta\sigma| \le` ``tol`` :math:`(1 + |\sigma|_\infty)`;
    raises :class:`ChordConvergenceError` naming the step after ``max_iter`` iterations.
    """

    tol: float = 1e-13
    max_iter: int = 50
    code = 2

    def __post_init__(self):
        if not (isinstance(self.tol, (int, float)) and np.isfinite(self.tol) and self.tol > 0):
            raise ValueError(f"tol must be a positive finite number, got {self.tol!r}.")
        check_positive_int(self.max_iter, "max_iter")


_METHODS = (LieEuler, LieHeun, ImplicitMidpoint)


def _check_method(method):
    if isinstance(method, type) and method in _METHODS:
        method = method()
    if not isinstance(method, _METHODS):
        raise TypeError(f"method must be LieEuler(), LieHeun() or ImplicitMidpoint(...), got {method!r}.")
    return method


# ---------------------------------------------------------------------- orbit checks
def check_on_orbit(system: LiePoissonSystem, mu, orbit, *, rtol: float = 1e-10, name: str = "mu0"):
    """Require ``system.casimirs(mu) == orbit`` (relative tolerance ``rtol``) for every batch entry.

    ``orbit`` has shape ``(k,)`` or broadcasts against ``(..., k)``. Raises ``ValueError`` naming the
    Casimir, the worst batch index, the value and the expected value.
    """
    cas = system.casimirs(mu)
    target = as_float_array(orbit, "orbit")
    if target.ndim == 0:
        target = target[None]
    try:
        target = np.broadcast_to(target, cas.shape)
    except ValueError:
        raise ValueError(f"orbit must give the {cas.shape[-1]} Casimir value(s) "
                         f"{system.algebra.casimir_names}, got shape {np.shape(orbit)}.") from None
    err = np.abs(cas - target) / np.maximum(1.0, np.abs(target))
    if np.any(err > rtol):
        flat = int(np.argmax(err))
        idx = np.unravel_index(flat, err.shape)
        k = idx[-1]
        names = system.algebra.casimir_names
        label = names[k] if k < len(names) else f"Casimir {k}"
        raise ValueError(f"{name} is off the coadjoint orbit: {label} = {float(cas[idx])!r} at batch index "
                         f"{tuple(int(i) for i in idx[:-1])}, expected {float(target[idx])!r} (relative error "
                         f"{err[idx]:.3g} > {rtol:g}). A Casimir-preserving method keeps the orbit of the "
                         f"initial state; project {name} onto the orbit (e.g. normalise |Pi|) or pass the "
                         f"orbit it lies on.")


# ---------------------------------------------------------------------- generic (numpy) steps
def _ad_star_exp(system, sigma, mu):
    return system.algebra._ad_star_exp_unchecked(sigma, mu)


def _chord_solve(system, method, mu, dt, eta, step_index, t):
    alg = system.algebra
    c = alg._c
    n = system.dim
    w0 = system._w(mu)
    lmu = np.einsum("...k,ijk->...ji", mu, c)
    jac = np.eye(n) - 0.5 * dt * (system._w_jacobian(mu) @ lmu)
    jinv = np.linalg.inv(jac)
    sigma = w0 * dt + eta
    for _ in range(method.max_iter):
        mu1 = _ad_star_exp(system, sigma, mu)
        resid = sigma - system._w(0.5 * (mu + mu1)) * dt - eta
        delta = np.einsum("...ij,...j->...i", jinv, resid)
        sigma = sigma - delta
        scale = 1.0 + np.max(np.abs(sigma), axis=-1)
        if not np.all(np.isfinite(delta)):
            break
        if np.all(np.max(np.abs(delta), axis=-1) <= method.tol * scale):
            return sigma
    bad = np.max(np.abs(delta), axis=-1) / scale
    bad = np.where(np.isfinite(bad), bad, np.inf)
    worst = np.unravel_index(int(np.argmax(bad)), bad.shape) if bad.ndim else ()
    raise ChordConvergenceError(
        f"implicit midpoint: the chord iteration did not converge at step {step_index} (t = {t:.6g}, "
        f"dt = {dt:.3g}) for batch index {tuple(int(i) for i in worst)}: last correction "
        f"{float(np.max(bad)):.3g} (relative) > tol = {method.tol:g} after max_iter = {method.max_iter} "
        f"iterations. Reduce dt (or use LieHeun), or raise max_iter / tol.")


def coadjoint_step(system: LiePoissonSystem, mu, dt: float, eta, method=LieHeun(), *, step_index: int = 0,
                   t: float = 0.0) -> np.ndarray:
    r"""One coadjoint step :math:`\mu\mapsto\exp(\mathrm{ad}^*_{\sigma})\mu` (batched, numpy).

    Parameters
    ----------
    mu : array, shape ``(..., n)``
    dt : float
    eta : array, shape ``(..., n)``
        Stochastic velocity of the step (:meth:`LiePoissonSystem.stochastic_velocity`).
    method : LieEuler | LieHeun | ImplicitMidpoint
    """
    method = _check_method(method)
    if method.code == 0:
        sigma = system._w(mu) * dt + eta
    elif method.code == 1:
        w0 = system._w(mu)
        sig0 = w0 * dt + eta
        a = system._ad_star(sig0, mu)
        mu_p = mu + a + 0.5 * system._ad_star(sig0, a)        # predictor: 2nd-order Taylor of exp
        sigma = 0.5 * (w0 + system._w(mu_p)) * dt + eta
    else:
        sigma = _chord_solve(system, method, mu, dt, eta, step_index, t)
    return _ad_star_exp(system, sigma, mu)


# ---------------------------------------------------------------------- numba kernel (so(3), quadratic h)
@numba.njit(cache=True, inline="always")
def _rod(s0, s1, s2, m0, m1, m2):
    # exp(ad*_s) m = m - a s×m + b s×(s×m), a = sin t / t, b = (1 - cos t)/t²
    t2 = s0 * s0 + s1 * s1 + s2 * s2
    if t2 < 1e-2:
        # Taylor to t^8: truncation < t^10/11! < 3e-18, i.e. exact in float64; no transcendental calls
        a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0)))
        b = 0.5 - t2 / 24.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0 * (1.0 - t2 / 90.0)))
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
    g0 = q[0, 0] * m0 + q[0, 1] * m1 + q[0, 2] * m2 + lin[0]
    g1 = q[1, 0] * m0 + q[1, 1] * m1 + q[1, 2] * m2 + lin[1]
    g2 = q[2, 0] * m0 + q[2, 1] * m1 + q[2, 2] * m2 + lin[2]
    if theta == 0.0:
        return g0, g1, g2
    # v = ad*_g mu = mu × g ; w = g + theta * Minv v
    v0 = m1 * g2 - m2 * g1
    v1 = m2 * g0 - m0 * g2
    v2 = m0 * g1 - m1 * g0
    return (g0 + theta * (minv[0, 0] * v0 + minv[0, 1] * v1 + minv[0, 2] * v2),
            g1 + theta * (minv[1, 0] * v0 + minv[1, 1] * v1 + minv[1, 2] * v2),
            g2 + theta * (minv[2, 0] * v0 + minv[2, 1] * v1 + minv[2, 2] * v2))


@numba.njit(cache=True)
def _so3_chord(m0, m1, m2, e0, e1, e2, s0, s1, s2, dt, q, lin, minv, theta, tol, max_iter):
    """Chord iteration for the implicit midpoint sigma on so(3)*; returns sigma and a convergence flag."""
    # chord Jacobian J = I - dt/2 Dw(mu) L(mu), L(mu) d = ad*_d mu = mu × d
    g0 = q[0, 0] * m0 + q[0, 1] * m1 + q[0, 2] * m2 + lin[0]
    g1 = q[1, 0] * m0 + q[1, 1] * m1 + q[1, 2] * m2 + lin[1]
    g2 = q[2, 0] * m0 + q[2, 1] * m1 + q[2, 2] * m2 + lin[2]
    L = np.empty((3, 3))
    L[0, 0], L[0, 1], L[0, 2] = 0.0, -m2, m1
    L[1, 0], L[1, 1], L[1, 2] = m2, 0.0, -m0
    L[2, 0], L[2, 1], L[2, 2] = -m1, m0, 0.0
    Dw = q.copy()
    if theta != 0.0:
        # d(mu × g) = -hat(g) dmu + hat(mu) q dmu
        A = np.empty((3, 3))
        A[0, 0], A[0, 1], A[0, 2] = 0.0, g2, -g1
        A[1, 0], A[1, 1], A[1, 2] = -g2, 0.0, g0
        A[2, 0], A[2, 1], A[2, 2] = g1, -g0, 0.0
        Dw = Dw + theta * (minv @ (A + L @ q))
    Ji = np.linalg.inv(np.eye(3) - 0.5 * dt * (Dw @ L))
    ok = False
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


@numba.njit(cache=True)
def _so3_kernel(mu, eta, dts, q, lin, minv, theta, code, tol, max_iter, save_every, phase, out, k0):
    """Advance mu (B, 3) in place over eta (B, K, 3); store every save_every-th state into out.

    ``phase`` is the global index of the first step of this chunk; the state after global step j
    is stored at out[:, j // save_every - k0] when j % save_every == 0. Returns -1, or
    (global step) * B + path when the chord iteration fails.
    """
    nb = mu.shape[0]
    nk = eta.shape[1]
    for p in range(nb):
        m0, m1, m2 = mu[p, 0], mu[p, 1], mu[p, 2]
        for k in range(nk):
            m0, m1, m2, ok = _so3_step(m0, m1, m2, eta[p, k, 0], eta[p, k, 1], eta[p, k, 2], dts[k], q, lin,
                                       minv, theta, code, tol, max_iter)
            if not ok:
                mu[p, 0], mu[p, 1], mu[p, 2] = m0, m1, m2
                return (phase + k) * nb + p
            j = phase + k + 1
            if j % save_every == 0:
                r = j // save_every - k0
                out[p, r, 0], out[p, r, 1], out[p, r, 2] = m0, m1, m2
        mu[p, 0], mu[p, 1], mu[p, 2] = m0, m1, m2
    return -1


@numba.njit(cache=True)
def _so3_brownian_kernel(mu, rng, n_steps, dt, xi, brk, with_area, q, lin, minv, theta, code, tol, max_iter,
                         save_every, out):
    """Fused Brownian driver + coadjoint step on so(3)* (no noise arrays are materialised).

    Draw order per step and path (step-major, so independent of any chunking in time): the m
    increments N(0, dt), then (with the area) the m space-time areas H ~ N(0, dt/12) and the
    m(m-1)/2 residuals lambda_ij ~ N(0, dt^2/12), i < j lexicographic; the step Lévy area is
    A_ij = H_i dW_j - dW_i H_j + lambda_ij (Davie's moment-matched area, exact second moments).
    Returns -1 or step * B + path of a chord failure.
    """
    nb = mu.shape[0]
    m = xi.shape[0]
    sq = math.sqrt(dt)
    sh = math.sqrt(dt / 12.0)
    sl = dt / math.sqrt(12.0)
    dw = np.empty(m)
    hh = np.empty(m)
    for k in range(n_steps):
        for p in range(nb):
            for i in range(m):
                dw[i] = sq * rng.standard_normal()
            e0 = 0.0
            e1 = 0.0
            e2 = 0.0
            for i in range(m):
                e0 += dw[i] * xi[i, 0]
                e1 += dw[i] * xi[i, 1]
                e2 += dw[i] * xi[i, 2]
            if with_area:
                for i in range(m):
                    hh[i] = sh * rng.standard_normal()
                for i in range(m):
                    for j in range(i + 1, m):
                        a = hh[i] * dw[j] - dw[i] * hh[j] + sl * rng.standard_normal()
                        # ½ Σ_{ij} A^{ij}[ξ_i, ξ_j] = Σ_{i<j} A^{ij}[ξ_i, ξ_j]
                        e0 += a * brk[i, j, 0]
                        e1 += a * brk[i, j, 1]
                        e2 += a * brk[i, j, 2]
            m0, m1, m2, ok = _so3_step(mu[p, 0], mu[p, 1], mu[p, 2], e0, e1, e2, dt, q, lin, minv, theta, code,
                                       tol, max_iter)
            if not ok:
                return k * nb + p
            mu[p, 0], mu[p, 1], mu[p, 2] = m0, m1, m2
            if (k + 1) % save_every == 0:
                r = (k + 1) // save_every
                out[p, r, 0], out[p, r, 1], out[p, r, 2] = m0, m1, m2
    return -1


def _fast_so3(system):
    from .lie_algebra import rodrigues_ad_star_exp as rod
    return (system.algebra._ad_star_exp is rod and system.hamiltonian.is_quadratic
            and system.dim == 3)


def _so3_args(system, method):
    h = system.hamiltonian
    minv = np.eye(3) if system._metric_inv is None else system._metric_inv
    lin = np.ascontiguousarray(h.linear + system._shift)
    tol = float(getattr(method, "tol", 1e-13))
    max_iter = int(getattr(method, "max_iter", 1))
    return (np.ascontiguousarray(h.q), lin, np.ascontiguousarray(minv), system.theta, method.code, tol, max_iter)


def _chord_failure(res, nb, times, dts, method):
    step, path = divmod(int(res), nb)
    return ChordConvergenceError(
        f"implicit midpoint: the chord iteration did not converge at step {step} (t = {times[step]:.6g}, "
        f"dt = {dts:.3g}) for path {path}: tolerance {method.tol:g} not reached after max_iter = "
        f"{method.max_iter} iterations. Reduce dt (or use LieHeun), or raise max_iter / tol.")


def _run_chunk(system, method, mu, eta, dts, t0_index, times, save_every, out, k0):
    """Advance ``mu`` (B, n) over the chunk ``eta`` (B, K, n); fill ``out`` (B, nsave, n)."""
    if _fast_so3(system):
        res = _so3_kernel(mu, np.ascontiguousarray(eta), np.ascontiguousarray(dts), *_so3_args(system, method),
                          save_every, t0_index, out, k0)
        if res >= 0:
            raise _chord_failure(res, mu.shape[0], times, float(dts[int(res) // mu.shape[0] - t0_index]), method)
        return
    for k in range(eta.shape[1]):
        j = t0_index + k
        mu[...] = coadjoint_step(system, mu, float(dts[k]), eta[:, k], method, step_index=j, t=float(times[j]))
        if (j + 1) % save_every == 0:
            out[:, (j + 1) // save_every - k0] = mu


def _check_finite_state(mu, step):
    if not np.all(np.isfinite(mu)):
        bad = int(np.argmax(~np.all(np.isfinite(mu), axis=-1)))
        raise FloatingPointError(f"the state became non-finite by step {step} (path {bad}); the Hamiltonian "
                                 f"or its gradient returned NaN/inf. Check them, or reduce dt.")


def _prepare(system, mu0, batch_shape, orbit):
    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a LiePoissonSystem (e.g. mechanics.rigid_body.rigid_body(...)), "
                        f"got {type(system).__name__}.")
    mu0 = as_float_array(mu0, "mu0", last_dims=(system.dim,))
    try:
        batch = np.broadcast_shapes(mu0.shape[:-1], batch_shape)
    except ValueError:
        raise ValueError(f"mu0 has batch shape {mu0.shape[:-1]}, which does not broadcast against the "
                         f"driver's batch shape {batch_shape}.") from None
    if orbit is not None:
        check_on_orbit(system, mu0, orbit)
    return mu0, batch


def simulate(system: LiePoissonSystem, mu0, driver: RoughPath, method=LieHeun(), save_every: int = 1, *,
             orbit=None):
    r"""Solve the system pathwise on a level-2 geometric rough path with a coadjoint scheme.

    Parameters
    ----------
    system : LiePoissonSystem
    mu0 : array_like, shape ``(..., n)``
        Initial state(s); broadcast against the driver's batch shape.
    driver : RoughPath
        Level-2 geometric rough path of dimension ``m = system.n_noise`` (its step Lévy areas are
        used; a level-1 path is refused — use ``RoughPath.from_path`` for the piecewise-linear lift).
    method : LieEuler() | LieHeun() | ImplicitMidpoint(tol, max_iter)
    save_every : int
        Keep every ``save_every``-th state (the final state is always at the end of the grid when
        ``n_steps`` is a multiple of it).
    orbit : array_like, optional
        Casimir values the initial state must have (e.g. ``[1.0]`` for the unit sphere); a state off
        this orbit raises ``ValueError``.

    Returns
    -------
    times : ndarray, shape ``(K,)``
        ``driver.times[::save_every]``.
    states : ndarray, shape ``(..., K, n)``

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> from mechanics.rigid_body import rigid_body
    >>> from mechanics.integrators import simulate, LieHeun
    >>> rb = rigid_body([1.0, 2.0, 3.0], sigma=0.1, theta=1.0)
    >>> X = RoughPath.from_path(np.cumsum(np.random.default_rng(0).normal(0, 0.03, (101, 3)), axis=0),
    ...                         times=np.linspace(0, 1, 101))
    >>> t, Pi = simulate(rb, [0.0, 0.6, 0.8], X, LieHeun())
    >>> Pi.shape, bool(abs(np.linalg.norm(Pi[-1]) - 1.0) < 1e-14)
    ((101, 3), True)
    """
    method = _check_method(method)
    if not isinstance(driver, RoughPath):
        raise TypeError(f"driver must be a roughpaths.RoughPath, got {type(driver).__name__}; for "
                        f"Brownian forcing without materialising a path use simulate_brownian.")
    if driver.level != 2:
        raise ValueError("driver is a level-1 path (no area); the coadjoint schemes need the step Lévy "
                         "areas. Use RoughPath.from_path(values) for the piecewise-linear lift (zero Lévy "
                         "area per step) or pass the areas.")
    if driver.kind != "geometric":
        raise ValueError(f"driver is a {driver.kind!r} rough path; the coadjoint schemes solve the geometric "
                         f"(Stratonovich-type) RDE. Convert an Itô lift with XX + ½(t-s)I first.")
    if driver.dim != system.n_noise:
        raise ValueError(f"driver has dimension {driver.dim} but the system has {system.n_noise} noise "
                         f"vectors xi; they must match.")
    save_every = check_positive_int(save_every, "save_every")
    mu0, batch = _prepare(system, mu0, driver.batch_shape, orbit)
    n, nsteps = system.dim, driver.n_steps
    eta = system.stochastic_velocity(driver.increments, driver.step_levy_areas)     # (..., N, n)
    eta = np.broadcast_to(eta, batch + eta.shape[-2:]).reshape((-1,) + eta.shape[-2:])
    mu = np.array(np.broadcast_to(mu0, batch + (n,)).reshape(-1, n), dtype=np.float64)
    nsave = nsteps // save_every + 1
    out = np.empty((mu.shape[0], nsave, n))
    out[:, 0] = mu
    _run_chunk(system, method, mu, eta, driver.dt, 0, driver.times, save_every, out, 0)
    _check_finite_state(mu, nsteps)
    times = driver.times[::save_every][:nsave]
    return times, out.reshape(batch + (nsave, n))


# ---------------------------------------------------------------------- Brownian streaming
def _brownian_chunk(rng, batch, k, dt, m, levy_area, substeps):
    r"""Increments (batch, k, m) and Lévy areas (batch, k, m, m) (or None) of Stratonovich Brownian motion.

    ``substeps == 1`` with the Davie area (or no area): drawn here in the same order as the fused
    numba kernel (step-major; per step and path: ``dW`` (m), ``H`` (m), ``lambda`` (m(m-1)/2)), so
    both implementations give the same paths for the same seed, and the stream does not depend on
    the chunking in time. Area :math:`A_{ij} = H_i dW_j - dW_i H_j + \lambda_{ij}` with
    :math:`H\sim N(0, dt/12)`, :math:`\lambda_{ij}\sim N(0, dt^2/12)` (Davie's moment-matched area;
    exact second moments). Otherwise ``roughpaths.brownian.brownian_increments_and_areas``.
    """
    method = None if not levy_area else ("davie" if levy_area is True else levy_area)
    if method is None or m < 2:
        z = rng.standard_normal((k, batch, m))
        return np.swapaxes(z, 0, 1) * math.sqrt(dt), None
    if method == "davie" and substeps == 1:
        npair = m * (m - 1) // 2
        z = np.swapaxes(rng.standard_normal((k, batch, 2 * m + npair)), 0, 1)
        dw = z[..., :m] * math.sqrt(dt)
        h = z[..., m:2 * m] * math.sqrt(dt / 12.0)
        a = h[..., :, None] * dw[..., None, :]
        a = a - np.swapaxes(a, -1, -2)
        iu = np.triu_indices(m, 1)
        lam = z[..., 2 * m:] * (dt / math.sqrt(12.0))
        a[..., iu[0], iu[1]] += lam
        a[..., iu[1], iu[0]] -= lam
        return dw, a
    from roughpaths.brownian import brownian_increments_and_areas
    dw, xx = brownian_increments_and_areas(rng, k, dt, m, batch_shape=(batch,), levy_area=method,
                                           substeps=substeps)
    return dw, 0.5 * (xx - np.swapaxes(xx, -1, -2))


def simulate_brownian(system: LiePoissonSystem, mu0, dt: float, n_steps: int, rng, *, n_paths=None,
                      method=LieHeun(), levy_area=True, area_substeps: int = 1, save_every: int = 1,
                      chunk_steps=None, orbit=None):
    r"""Simulate on Stratonovich Brownian motion, generated chunk by chunk (memory independent of ``n_steps``).

    Parameters
    ----------
    system : LiePoissonSystem
    mu0 : array_like, shape ``(n,)`` or ``(P, n)``
    dt : float
        Step size.
    n_steps : int
    rng : numpy.random.Generator
    n_paths : int, optional
        Number of paths ``P`` (default: ``mu0``'s batch size, or 1).
    method : LieEuler() | LieHeun() | ImplicitMidpoint(...)
    levy_area : bool or {"davie", "foster"}
        Include the step Lévy area in :math:`\sigma_n`. ``True`` means ``"davie"`` (every second
        moment of (W, A) exact); ``False`` drops the area (then the scheme is only order ½ even
        against its own driver). The area is sampled (``roughpaths.brownian``), so the scheme has
        strong order 1 with respect to the sampled rough path and weak order 1 for Brownian motion;
        no sampler using finitely many Gaussians per step beats strong order ½ against *the*
        Brownian path (Clark–Cameron), only its constant (``area_substeps``) improves.
    area_substeps : int
        Substeps per step for the area sampler (default 1: cheapest, exact second moments).
    save_every : int
        Keep every ``save_every``-th state.
    chunk_steps : int, optional
        Steps generated per chunk (default: about 2 MB of noise per chunk).
    orbit : array_like, optional
        Casimir values the initial states must have (see :func:`simulate`).

    Returns
    -------
    times : ndarray ``(K,)``, states : ndarray ``(P, K, n)``
    """
    method = _check_method(method)
    rng = check_rng(rng)
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.floating)) or not np.isfinite(dt) or dt <= 0:
        raise ValueError(f"dt must be a positive finite number, got {dt!r}.")
    dt = float(dt)
    n_steps = check_positive_int(n_steps, "n_steps")
    save_every = check_positive_int(save_every, "save_every")
    if not (isinstance(levy_area, (bool, np.bool_)) or levy_area in ("davie", "foster")):
        raise ValueError(f"levy_area must be True, False, 'davie' or 'foster', got {levy_area!r}.")
    area_substeps = check_positive_int(area_substeps, "area_substeps")
    mu0 = as_float_array(mu0, "mu0", last_dims=(system.dim,) if isinstance(system, LiePoissonSystem) else None)
    if mu0.ndim > 2:
        raise ValueError(f"mu0 must have shape (n,) or (n_paths, n), got {mu0.shape}.")
    if n_paths is None:
        n_paths = mu0.shape[0] if mu0.ndim == 2 else 1
    n_paths = check_positive_int(n_paths, "n_paths")
    mu0, _ = _prepare(system, mu0, (n_paths,), orbit)
    n, m = system.dim, system.n_noise
    mu = np.array(np.broadcast_to(mu0, (n_paths, n)), dtype=np.float64)
    if chunk_steps is None:
        chunk_steps = max(1, min(n_steps, (2 << 20) // (8 * n_paths * (m * m + m + n))))
    chunk_steps = check_positive_int(chunk_steps, "chunk_steps")
    nsave = n_steps // save_every + 1
    out = np.empty((n_paths, nsave, n))
    out[:, 0] = mu
    times = np.arange(n_steps + 1) * dt
    if _fast_so3(system) and (levy_area is True or levy_area is False or levy_area == "davie") and area_substeps == 1:
        with_area = bool(levy_area)
        res = _so3_brownian_kernel(mu, rng, n_steps, dt, np.ascontiguousarray(system.xi),
                                   np.ascontiguousarray(system.xi_brackets), with_area, *_so3_args(system, method),
                                   save_every, out)
        if res >= 0:
            raise _chord_failure(res, n_paths, times, dt, method)
    else:
        start = 0
        while start < n_steps:
            k = min(chunk_steps, n_steps - start)
            dw, areas = _brownian_chunk(rng, n_paths, k, dt, m, levy_area, area_substeps)
            eta = system.stochastic_velocity(dw, areas)
            _run_chunk(system, method, mu, eta, np.full(k, dt), start, times, save_every, out, 0)
            start += k
    _check_finite_state(mu, n_steps)
    return times[::save_every][:nsave], out
