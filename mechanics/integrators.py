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
For so(3) with a quadratic Hamiltonian both run numba block kernels (state as three rows of paths,
the per-step loop over paths vectorised); other algebras use a batched numpy loop (``Ad*exp`` in
closed form for so(3)/se(3), :func:`roughpaths.expm_batched` otherwise).

Random stream of :func:`simulate_brownian` (every path): for each step in turn, for each path in
turn, the ``w`` unit normals of that path-step: ``dW`` (``m``), then with the area ``H`` (``m``) and
``lambda`` (``m(m-1)/2``, pairs ``i < j`` lexicographic) — exactly ``rng.standard_normal((n_steps,
n_paths, w))`` in C order, whatever the chunking in time (``chunk_steps``), and the generator ends in
the same state as after that call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from roughpaths.validation import as_float_array, check_positive_int, check_rng
from roughpaths.rough_path import RoughPath

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


@numba.njit(cache=True)
def _so3_chord(m0, m1, m2, e0, e1, e2, s0, s1, s2, dt, q, lin, minv, theta, tol, max_iter):
    """Chord iteration for the implicit midpoint sigma on so(3)*; returns sigma and a convergence flag."""
    # chord Jacobian J = I - dt/2 Dw(mu) L(mu), L(mu) d = ad*_d mu = mu × d; g: the gradient inside
    # the double bracket (see _w3 for the layout of lin)
    g0 = q[0, 0] * m0 + q[0, 1] * m1 + q[0, 2] * m2 + lin[0] + lin[3]
    g1 = q[1, 0] * m0 + q[1, 1] * m1 + q[1, 2] * m2 + lin[1] + lin[4]
    g2 = q[2, 0] * m0 + q[2, 1] * m1 + q[2, 2] * m2 + lin[2] + lin[5]
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


# Structure-of-arrays block kernels. The state lives in three contiguous rows m[0], m[1], m[2]
# (one entry per path) and every step is a loop over paths whose body is pure arithmetic, so LLVM
# vectorises it (SIMD over paths). All constants are unpacked into scalars before the loops (no
# aliasing with the state rows, nothing recomputed per step). The Rodrigues factors use the Taylor
# branch of `_rod` (exact in float64 for |sigma|² < 1e-2, no trig); paths whose |sigma|² exceeds it
# keep their old state in the vector loop, are flagged, and are redone by the scalar exact step.
_NCOEF = 30
_FAST_BUFFER_BYTES = 1 << 19


def _so3_linear_terms(system):
    """(6,): the conservative linear term ``b + shift`` (3), then the change of the gradient inside the
    double bracket, ``shift_dissipation - shift`` (3; zero with ``levy_in_dissipation=True``)."""
    h = system.hamiltonian
    return np.concatenate([h.linear + system._shift, system._shift_dissipation - system._shift])


def _so3_coefficients(system, method):
    """Flat float64 vector of the constants of the so(3) kernels: Q (9), b + shift (3), theta·M⁻¹ (9),
    shift_dissipation - shift (3), spare."""
    h = system.hamiltonian
    minv = np.eye(3) if system._metric_inv is None else system._metric_inv
    coef = np.zeros(_NCOEF)
    lin = _so3_linear_terms(system)
    coef[0:9] = np.asarray(h.q, dtype=np.float64).ravel()
    coef[9:12] = lin[:3]
    coef[12:21] = (system.theta * np.asarray(minv, dtype=np.float64)).ravel()
    coef[21:24] = lin[3:]
    return coef


@numba.njit(cache=True)
def _so3_block_step(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta):
    """Advance every path of ``m`` (3, B) by one coadjoint step with stochastic velocities ``e`` (3, B).

    ``code`` 0 (Lie–Euler) and 1 (Lie–Heun) run the vectorised loop; 2 (implicit midpoint) the scalar
    chord solve. Returns -1, or the index of the first path whose chord iteration failed.
    """
    nb = m.shape[1]
    ma, mb, mc = m[0], m[1], m[2]
    ea, eb, ec = e[0], e[1], e[2]
    if code == 2:
        for p in range(nb):
            n0, n1, n2, ok = _so3_step(ma[p], mb[p], mc[p], ea[p], eb[p], ec[p], dt, q, lin, minv, theta, code,
                                       tol, max_iter)
            if not ok:
                return p
            ma[p], mb[p], mc[p] = n0, n1, n2
        return -1
    q00, q01, q02, q10, q11, q12, q20, q21, q22 = (coef[0], coef[1], coef[2], coef[3], coef[4], coef[5],
                                                   coef[6], coef[7], coef[8])
    l0, l1, l2 = coef[9], coef[10], coef[11]
    f0, f1, f2 = coef[21], coef[22], coef[23]     # gradient change inside the double bracket
    n00, n01, n02, n10, n11, n12, n20, n21, n22 = (coef[12], coef[13], coef[14], coef[15], coef[16],
                                                   coef[17], coef[18], coef[19], coef[20])
    hdt = 0.5 * dt
    nbad = 0
    for p in range(nb):
        m0 = ma[p]
        m1 = mb[p]
        m2 = mc[p]
        e0 = ea[p]
        e1 = eb[p]
        e2 = ec[p]
        # w(mu) = g + theta M⁻¹ (mu × (g + f)), g = Q mu + b + shift, f = shift_dissipation - shift
        g0 = q00 * m0 + q01 * m1 + q02 * m2 + l0
        g1 = q10 * m0 + q11 * m1 + q12 * m2 + l1
        g2 = q20 * m0 + q21 * m1 + q22 * m2 + l2
        v0 = m1 * (g2 + f2) - m2 * (g1 + f1)
        v1 = m2 * (g0 + f0) - m0 * (g2 + f2)
        v2 = m0 * (g1 + f1) - m1 * (g0 + f0)
        w0 = g0 + n00 * v0 + n01 * v1 + n02 * v2
        w1 = g1 + n10 * v0 + n11 * v1 + n12 * v2
        w2 = g2 + n20 * v0 + n21 * v1 + n22 * v2
        s0 = w0 * dt + e0
        s1 = w1 * dt + e1
        s2 = w2 * dt + e2
        if code == 1:
            # predictor mu* = (1 + ad*_s + ½ ad*_s²) mu, corrector s = ½(w(mu) + w(mu*)) dt + e
            c0 = m1 * s2 - m2 * s1
            c1 = m2 * s0 - m0 * s2
            c2 = m0 * s1 - m1 * s0
            y0 = m0 + c0 + 0.5 * (c1 * s2 - c2 * s1)
            y1 = m1 + c1 + 0.5 * (c2 * s0 - c0 * s2)
            y2 = m2 + c2 + 0.5 * (c0 * s1 - c1 * s0)
            g0 = q00 * y0 + q01 * y1 + q02 * y2 + l0
            g1 = q10 * y0 + q11 * y1 + q12 * y2 + l1
            g2 = q20 * y0 + q21 * y1 + q22 * y2 + l2
            v0 = y1 * (g2 + f2) - y2 * (g1 + f1)
            v1 = y2 * (g0 + f0) - y0 * (g2 + f2)
            v2 = y0 * (g1 + f1) - y1 * (g0 + f0)
            s0 = (w0 + g0 + n00 * v0 + n01 * v1 + n02 * v2) * hdt + e0
            s1 = (w1 + g1 + n10 * v0 + n11 * v1 + n12 * v2) * hdt + e1
            s2 = (w2 + g2 + n20 * v0 + n21 * v1 + n22 * v2) * hdt + e2
        # exp(ad*_s) m = m - a s×m + b s×(s×m), Taylor to t^8 (exact in float64 for t² < 1e-2)
        t2 = s0 * s0 + s1 * s1 + s2 * s2
        big = t2 >= 1e-2
        bad[p] = big
        nbad += big
        a = 1.0 - t2 * (1.0 / 6.0) * (1.0 - t2 * (1.0 / 20.0) * (1.0 - t2 * (1.0 / 42.0) * (1.0 - t2 * (1.0 / 72.0))))
        b = 0.5 - t2 * (1.0 / 24.0) * (1.0 - t2 * (1.0 / 30.0) * (1.0 - t2 * (1.0 / 56.0) * (1.0 - t2 * (1.0 / 90.0))))
        c0 = s1 * m2 - s2 * m1
        c1 = s2 * m0 - s0 * m2
        c2 = s0 * m1 - s1 * m0
        d0 = s1 * c2 - s2 * c1
        d1 = s2 * c0 - s0 * c2
        d2 = s0 * c1 - s1 * c0
        ma[p] = m0 if big else m0 - a * c0 + b * d0
        mb[p] = m1 if big else m1 - a * c1 + b * d1
        mc[p] = m2 if big else m2 - a * c2 + b * d2
    if nbad > 0:
        for p in range(nb):
            if bad[p]:
                ma[p], mb[p], mc[p], _ = _so3_step(ma[p], mb[p], mc[p], ea[p], eb[p], ec[p], dt, q, lin, minv,
                                                   theta, code, tol, max_iter)
    return -1


@numba.njit(cache=True)
def _so3_noise_velocity(zk, zt, e, xs, bs, pi, pj):
    """Stochastic velocities e (3, B) of one step from its unit normals zk (B, w) (stream layout).

    ``xs`` (m, 3) = sqrt(dt) ξ; with the area (``w > m``) ``bs`` (npair, 3) = dt/√12 [ξ_i, ξ_j] for
    the pairs ``pi < pj``: A_ij = dt/√12 (zH_i zW_j - zW_i zH_j + zλ_ij) (Davie's area, scaled).
    """
    nb, w = zk.shape
    nm = xs.shape[0]
    for p in range(nb):                      # transpose to rows, so the loops below vectorise
        for c in range(w):
            zt[c, p] = zk[p, c]
    ea, eb, ec = e[0], e[1], e[2]
    x0, x1, x2 = xs[0, 0], xs[0, 1], xs[0, 2]
    z0 = zt[0]
    for p in range(nb):
        ea[p] = z0[p] * x0
        eb[p] = z0[p] * x1
        ec[p] = z0[p] * x2
    for i in range(1, nm):
        x0, x1, x2 = xs[i, 0], xs[i, 1], xs[i, 2]
        zi = zt[i]
        for p in range(nb):
            ea[p] += zi[p] * x0
            eb[p] += zi[p] * x1
            ec[p] += zi[p] * x2
    if w > nm:
        for r in range(bs.shape[0]):
            i, j = pi[r], pj[r]
            b0, b1, b2 = bs[r, 0], bs[r, 1], bs[r, 2]
            wi, wj, hi, hj, lr = zt[i], zt[j], zt[nm + i], zt[nm + j], zt[2 * nm + r]
            for p in range(nb):
                a = hi[p] * wj[p] - wi[p] * hj[p] + lr[p]
                ea[p] += a * b0
                eb[p] += a * b1
                ec[p] += a * b2


@numba.njit(cache=True)
def _so3_brownian_block(m, z, zt, e, bad, xs, bs, pi, pj, dt, coef, code, tol, max_iter, q, lin, minv, theta,
                        save_every, phase, out):
    """Advance m (3, B) over the unit normals z (k, B, w) of k steps; global step index of z[0] is ``phase``.

    The state after global step j is stored at out[:, j // save_every] when j % save_every == 0.
    Returns -1, or (global step) * B + path of a chord failure.
    """
    nb = m.shape[1]
    for k in range(z.shape[0]):
        _so3_noise_velocity(z[k], zt, e, xs, bs, pi, pj)
        res = _so3_block_step(m, e, dt, coef, code, tol, max_iter, bad, q, lin, minv, theta)
        if res >= 0:
            return (phase + k) * nb + res
        j = phase + k + 1
        if j % save_every == 0:
            r = j // save_every
            for p in range(nb):
                out[p, r, 0] = m[0, p]
                out[p, r, 1] = m[1, p]
                out[p, r, 2] = m[2, p]
    return -1


@numba.njit(cache=True)
def _so3_eta_block(m, eta, dts, e, bad, coef, code, tol, max_iter, q, lin, minv, theta, save_every, phase, out,
                   k0):
    """Advance m (3, B) over given stochastic velocities eta (B, K, 3) (see :func:`_so3_brownian_block`)."""
    nb = m.shape[1]
    for k in range(eta.shape[1]):
        for p in range(nb):
            e[0, p] = eta[p, k, 0]
            e[1, p] = eta[p, k, 1]
            e[2, p] = eta[p, k, 2]
        res = _so3_block_step(m, e, dts[k], coef, code, tol, max_iter, bad, q, lin, minv, theta)
        if res >= 0:
            return (phase + k) * nb + res
        j = phase + k + 1
        if j % save_every == 0:
            r = j // save_every - k0
            for p in range(nb):
                out[p, r, 0] = m[0, p]
                out[p, r, 1] = m[1, p]
                out[p, r, 2] = m[2, p]
    return -1


def _fast_so3(system):
    from .lie_algebra import rodrigues_ad_star_exp as rod
    return (system.algebra._ad_star_exp is rod and system.hamiltonian.is_quadratic
            and system.dim == 3)


def _so3_args(system, method):
    """Constants of the so(3) kernels: (coef, code, tol, max_iter, q, lin, minv, theta)."""
    h = system.hamiltonian
    minv = np.eye(3) if system._metric_inv is None else system._metric_inv
    lin = np.ascontiguousarray(_so3_linear_terms(system))
    tol = float(getattr(method, "tol", 1e-13))
    max_iter = int(getattr(method, "max_iter", 1))
    return (_so3_coefficients(system, method), method.code, tol, max_iter, np.ascontiguousarray(h.q), lin,
            np.ascontiguousarray(minv), system.theta)


def _chord_failure(res, nb, times, dts, method):
    step, path = divmod(int(res), nb)
    return ChordConvergenceError(
        f"implicit midpoint: the chord iteration did not converge at step {step} (t = {times[step]:.6g}, "
        f"dt = {dts:.3g}) for path {path}: tolerance {method.tol:g} not reached after max_iter = "
        f"{method.max_iter} iterations. Reduce dt (or use LieHeun), or raise max_iter / tol.")


def _run_chunk(system, method, mu, eta, dts, t0_index, times, save_every, out, k0):
    """Advance ``mu`` (B, n) over the chunk ``eta`` (B, K, n); fill ``out`` (B, nsave, n)."""
    if _fast_so3(system):
        coef, code, tol, max_iter, q, lin, minv, theta = _so3_args(system, method)
        nb = mu.shape[0]
        m = np.ascontiguousarray(mu.T)
        res = _so3_eta_block(m, np.ascontiguousarray(eta), np.ascontiguousarray(dts, dtype=np.float64),
                             np.empty((3, nb)), np.empty(nb, dtype=np.bool_), coef, code, tol, max_iter, q, lin,
                             minv, theta, save_every, t0_index, out, k0)
        mu[...] = m.T
        if res >= 0:
            raise _chord_failure(res, nb, times, float(dts[int(res) // nb - t0_index]), method)
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
             orbit=None, levy_area: bool = True):
    r"""Solve the system pathwise on a geometric rough path with a coadjoint scheme.

    Parameters
    ----------
    system : LiePoissonSystem
    mu0 : array_like, shape ``(..., n)``
        Initial state(s); broadcast against the driver's batch shape.
    driver : RoughPath
        Rough path of dimension ``m = system.n_noise``. With ``levy_area=True`` (default) a level-2
        geometric path, whose step Lévy areas enter :math:`\sigma_n`; with ``levy_area=False`` a
        level-1 path (increments only; e.g. ``RoughPath.from_increments(dW)`` or ``X.to_level1()``).
    method : LieEuler() | LieHeun() | ImplicitMidpoint(tol, max_iter)
    save_every : int
        Keep every ``save_every``-th state (the final state is always at the end of the grid when
        ``n_steps`` is a multiple of it).
    orbit : array_like, optional
        Casimir values the initial state must have (e.g. ``[1.0]`` for the unit sphere); a state off
        this orbit raises ``ValueError``.
    levy_area : bool
        ``True``: use the driver's step Lévy areas (strong order 1 for non-commuting ``xi``).
        ``False``: level-1 driving, :math:`\sigma_n` built from the increments alone, i.e. the step
        Lévy areas are taken to be zero (the piecewise-linear / Wong–Zakai lift of the increments:
        strong order ½ against Brownian motion for non-commuting ``xi``, the same law-level
        limit). Requires a level-1 driver, so areas are never dropped silently: pass
        ``driver.to_level1()`` to discard the areas of a level-2 path deliberately.

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

    Level-1 driving (increments only, zero Lévy area per step) is explicit:

    >>> dW = np.random.default_rng(1).normal(0, 0.03, (100, 3))
    >>> X1 = RoughPath.from_increments(dW, times=np.linspace(0, 1, 101))
    >>> t, Pi1 = simulate(rb, [0.0, 0.6, 0.8], X1, LieHeun(), levy_area=False)
    >>> Pi1.shape
    (101, 3)
    """
    method = _check_method(method)
    if not isinstance(driver, RoughPath):
        raise TypeError(f"driver must be a roughpaths.RoughPath, got {type(driver).__name__}; for "
                        f"Brownian forcing without materialising a path use simulate_brownian.")
    if not isinstance(levy_area, (bool, np.bool_)):
        raise TypeError(f"levy_area must be True (use the driver's Lévy areas) or False (level-1 driving, "
                        f"zero area), got {levy_area!r}.")
    if levy_area and driver.level != 2:
        raise ValueError("driver is a level-1 path (no area) but levy_area=True: the scheme would need the "
                         "step Lévy areas. Pass levy_area=False to drive with the increments alone (zero "
                         "Lévy area per step), or a level-2 path (e.g. RoughPath.from_path(values) for the "
                         "piecewise-linear lift, or the increments with their areas).")
    if not levy_area and driver.level != 1:
        raise ValueError("levy_area=False but driver is a level-2 path: its areas would be discarded. Pass "
                         "driver.to_level1() to drop them deliberately, or levy_area=True to use them.")
    if levy_area and driver.kind != "geometric":
        raise ValueError(f"driver is a {driver.kind!r} rough path; the coadjoint schemes solve the geometric "
                         f"(Stratonovich-type) RDE. Convert an Itô lift with XX + ½(t-s)I first.")
    if driver.dim != system.n_noise:
        raise ValueError(f"driver has dimension {driver.dim} but the system has {system.n_noise} noise "
                         f"vectors xi; they must match.")
    save_every = check_positive_int(save_every, "save_every")
    mu0, batch = _prepare(system, mu0, driver.batch_shape, orbit)
    n, nsteps = system.dim, driver.n_steps
    eta = system.stochastic_velocity(driver.increments, driver.step_levy_areas if levy_area else None)
    eta = np.broadcast_to(eta, batch + eta.shape[-2:]).reshape((-1,) + eta.shape[-2:])
    mu = np.array(np.broadcast_to(mu0, batch + (n,)).reshape(-1, n), dtype=np.float64)
    nsave = nsteps // save_every + 1
    out = np.empty((mu.shape[0], nsave, n))
    out[:, 0] = mu
    _run_chunk(system, method, mu, eta, driver.dt, 0, driver.times, save_every, out, 0)
    _check_finite_state(mu, nsteps)
    times = driver.times[::save_every][:nsave]
    return times, out.reshape(batch + (nsave, n))


# ---------------------------------------------------------------------- bulk standard normals
# numpy's Generator.standard_normal (ziggurat, 256 layers) re-implemented over a buffer of raw
# 64-bit outputs of the bit generator (``bit_generator.random_raw``): the same raw words give the
# same normals, bit for bit, so paths agree with ``rng.standard_normal`` and the generator ends in
# the same state, but the per-draw function-pointer calls disappear (about 3x faster per normal).
# Used for bit generators whose ``next_double`` is ``(raw >> 11) * 2**-53`` (checked once per
# process against ``standard_normal``); any other generator (e.g. MT19937) uses numpy directly.
try:  # the ziggurat tables numpy uses (numba ships a copy for its own Generator support)
    from numba.np.random._constants import fi_double as _ZIG_F
    from numba.np.random._constants import ki_double as _ZIG_K
    from numba.np.random._constants import wi_double as _ZIG_W
    from numba.np.random._constants import ziggurat_nor_inv_r as _ZIG_INV_R
    from numba.np.random._constants import ziggurat_nor_r as _ZIG_R
except ImportError:  # pragma: no cover - another numba layout: fall back to numpy's sampler
    _ZIG_K = None

_RAW_BIT_GENERATORS = ("PCG64", "PCG64DXSM", "SFC64", "Philox")
_RAW_OK: dict = {}


@numba.njit(cache=True)
def _ziggurat_fill(raw, out, start, ki, wi, fi, r_tail, inv_r):
    """Fill ``out[start:]`` from ``raw`` (uint64) with numpy's ziggurat; returns (raw consumed, next index).

    Stops at the first attempt that would need more raw words than remain (that attempt is then
    redone from its first word on the next call, so no word is skipped or reused).
    """
    n = out.size
    nr = raw.size
    pos = 0
    i = start
    m255 = np.uint64(255)
    m52 = np.uint64(0x000FFFFFFFFFFFFF)
    one = np.uint64(1)
    s8 = np.uint64(8)
    s11 = np.uint64(11)
    scale = 1.0 / 9007199254740992.0
    while i < n:
        if pos >= nr:
            break
        first = pos
        r = raw[pos]
        pos += 1
        idx = np.intp(r & m255)
        r = r >> s8
        rabs = (r >> one) & m52
        x = float(rabs) * wi[idx]
        if r & one:
            x = -x
        if rabs < ki[idx]:
            out[i] = x
            i += 1
            continue
        if idx == 0:
            done = False
            while True:
                if pos + 2 > nr:
                    break
                xx = -inv_r * math.log1p(-(float(raw[pos] >> s11) * scale))
                yy = -math.log1p(-(float(raw[pos + 1] >> s11) * scale))
                pos += 2
                if yy + yy > xx * xx:
                    out[i] = -(r_tail + xx) if (rabs >> s8) & one else r_tail + xx
                    done = True
                    break
            if not done:
                pos = first
                break
            i += 1
        else:
            if pos + 1 > nr:
                pos = first
                break
            u = float(raw[pos] >> s11) * scale
            pos += 1
            if (fi[idx - 1] - fi[idx]) * u + fi[idx] < math.exp(-0.5 * x * x):
                out[i] = x
                i += 1
    return pos, i


def _raw_normals_ok(rng) -> bool:
    name = type(rng.bit_generator).__name__
    if _ZIG_K is None or name not in _RAW_BIT_GENERATORS:
        return False
    if name not in _RAW_OK:                  # one-off self-check against numpy on a private generator
        bg = type(rng.bit_generator)(12345)
        ref = np.random.Generator(type(rng.bit_generator)(12345)).standard_normal(20_000)
        got = np.empty(20_000)
        _RAW_OK[name] = _fill_normals_raw(bg, got) and np.array_equal(got, ref)
    return _RAW_OK[name]


def _fill_normals_raw(bit_generator, out) -> bool:
    """Fill ``out`` (C-contiguous float64) from ``bit_generator.random_raw``, requesting exactly the words used."""
    flat = out.reshape(-1)
    n = flat.size
    i = 0
    left = np.empty(0, dtype=np.uint64)
    while i < n:
        # every remaining normal needs >= 1 word and the pending attempt needs > len(left) words, so
        # asking for n - i new words never over-draws: the generator ends where numpy's would
        new = bit_generator.random_raw(n - i)
        raw = new if left.size == 0 else np.concatenate([left, new])
        used, i = _ziggurat_fill(raw, flat, i, _ZIG_K, _ZIG_W, _ZIG_F, _ZIG_R, _ZIG_INV_R)
        left = raw[used:]
    return left.size == 0


def _standard_normal_into(rng, out):
    """``rng.standard_normal(out=out)``, same values and end state, faster for 64-bit bit generators."""
    if _raw_normals_ok(rng):
        if _fill_normals_raw(rng.bit_generator, out):
            return
        raise RuntimeError("internal error: the raw-word normal sampler over-drew the bit generator.")
    rng.standard_normal(out=out)


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


def _so3_brownian(system, method, mu, rng, n_steps, dt, with_area, chunk_steps, save_every, out, times):
    """Fast path of :func:`simulate_brownian` (so(3), quadratic h, Davie area or none); updates ``mu`` (P, 3).

    The unit normals of ``chunk_steps`` steps are drawn in bulk into one reused buffer of shape
    ``(k, P, w)`` (``rng.standard_normal(out=...)``, C order: step-major, then path, then the w draws
    of the path: dW (m), and with the area H (m) and lambda (m(m-1)/2)); the numba kernel only does
    arithmetic. C order makes the stream independent of the chunking in time.
    """
    nb, nm = mu.shape[0], system.n_noise
    coef, code, tol, max_iter, q, lin, minv, theta = _so3_args(system, method)
    pi, pj = np.triu_indices(nm, 1)
    with_area = with_area and pi.size > 0
    w = 2 * nm + pi.size if with_area else nm
    xs = np.ascontiguousarray(math.sqrt(dt) * system.xi)
    bs = np.ascontiguousarray(dt / math.sqrt(12.0) * system.xi_brackets[pi, pj])
    if chunk_steps is None:                  # a buffer that stays in cache between the fill and the kernel
        chunk_steps = _FAST_BUFFER_BYTES // (8 * nb * w)
    k_max = max(1, min(n_steps, chunk_steps))
    buf = np.empty((k_max, nb, w))
    zt, e, bad = np.empty((w, nb)), np.empty((3, nb)), np.empty(nb, dtype=np.bool_)
    m = np.ascontiguousarray(mu.T)
    start = 0
    while start < n_steps:
        k = min(k_max, n_steps - start)
        z = buf[:k]
        _standard_normal_into(rng, z)
        res = _so3_brownian_block(m, z, zt, e, bad, xs, bs, pi.astype(np.int64), pj.astype(np.int64), dt, coef,
                                  code, tol, max_iter, q, lin, minv, theta, save_every, start, out)
        if res >= 0:
            mu[...] = m.T
            raise _chord_failure(res, nb, times, dt, method)
        start += k
    mu[...] = m.T



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
    if chunk_steps is not None:
        chunk_steps = check_positive_int(chunk_steps, "chunk_steps")
    nsave = n_steps // save_every + 1
    out = np.empty((n_paths, nsave, n))
    out[:, 0] = mu
    times = np.arange(n_steps + 1) * dt
    if _fast_so3(system) and (levy_area is True or levy_area is False or levy_area == "davie") and area_substeps == 1:
        _so3_brownian(system, method, mu, rng, n_steps, dt, bool(levy_area), chunk_steps, save_every, out, times)
    else:
        if chunk_steps is None:
            chunk_steps = max(1, min(n_steps, (2 << 20) // (8 * n_paths * (m * m + m + n))))
        start = 0
        while start < n_steps:
            k = min(chunk_steps, n_steps - start)
            dw, areas = _brownian_chunk(rng, n_paths, k, dt, m, levy_area, area_substeps)
            eta = system.stochastic_velocity(dw, areas)
            _run_chunk(system, method, mu, eta, np.full(k, dt), start, times, save_every, out, 0)
            start += k
    _check_finite_state(mu, n_steps)
    return times[::save_every][:nsave], out
