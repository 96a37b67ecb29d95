r"""The Gibbs measure of the dissipative stochastic rigid body on the sphere ``|Π| = r``.

Theorem 3.1 (with the ½ of ``docs/conventions.md``): for isotropic noise ``ξ_i = σ e_i`` the RP
equation

.. math::

    d\Pi = \Pi\times W\,dt + \vartheta\,\Pi\times(\Pi\times W)\,dt + \sigma\,\Pi\times\circ dB,
    \qquad W = \nabla\tilde h = \mathbb I^{-1}\Pi + c,

has the invariant density, with respect to the **surface (area) measure** ``dS`` of the sphere
of radius ``r``,

.. math::

    p(\Pi) = Z^{-1}\exp(-\beta\,\tilde h(\Pi)), \qquad \beta = 2\vartheta/\sigma^2, \qquad
    \tilde h = \tfrac12\,\Pi\cdot\mathbb I^{-1}\Pi + c\cdot\Pi,

(``c = σ²(s23, −s13, s12)``); the density does not depend on ``r`` except through ``h̃``.

Quadrature (:class:`GibbsMeasure`): spherical coordinates whose pole is the global minimiser of
``h̃`` (so the main mode sits where the chart is smooth), composite Gauss–Legendre in the
colatitude ``ϑ`` (area element ``r² sin ϑ dϑ dφ``) and the trapezoid rule in the longitude ``φ``
(spectrally accurate for periodic integrands). The node spacing is set by the concentration: the
angular width of any mode is at least ``s = (β κ)^{-1/2}`` where
``κ = r²(a_max − a_min) + r|c|`` bounds the second derivative of ``h̃`` along great circles
(``a`` = eigenvalues of ``𝕀⁻¹``), so a rule scaled by ``s`` resolves every mode wherever it is (no
need to know where the secondary modes are). Level ``k`` uses ϑ-panels of width ``2s/2^k`` with 10
Gauss nodes each and a φ-spacing ``s/2^k`` (capped for broad densities); the cost grows like ``β``
(``β = 800``: 5·10⁴ nodes at level 0; ``β = 2·10⁴``: 1.3·10⁶). The rule is Gauss–Legendre in
``ϑ`` rather than in ``cos ϑ``: at the pole the mode is a Gaussian in ``ϑ`` but a one-sided
exponential in ``cos ϑ``.
``h̃`` is shifted by its minimum before exponentiating (no overflow for ``β = 800`` or
``β = 10⁵``); the rule is refined until two successive levels agree to ``rtol``, and the last
difference is reported as ``error_estimate``. :meth:`GibbsMeasure.laplace` gives the independent
leading-order Laplace approximation (relative error ``O(1/β)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from roughpaths.validation import as_float_array, check_positive_int, check_positive_real, check_rng

from ._inputs import _as_c, _check_radius
from ._sphere import _tangent_basis
from .equilibria import rigid_body_equilibria
from .modified_energy import _modified_hamiltonian, as_inverse_inertia

__all__ = ["GibbsMeasure", "gibbs_beta", "gibbs_moments"]


def gibbs_beta(sigma, theta) -> float:
    """Inverse temperature ``β = 2ϑ/σ²`` of the rigid body's Gibbs density (isotropic ``ξ_i = σ e_i``)."""
    sig = float(as_float_array(sigma, "sigma", ndim=0))
    th = float(as_float_array(theta, "theta", ndim=0))
    if not sig > 0:
        raise ValueError(f"sigma must be > 0 (the noise amplitude), got {sig!r}.")
    if th < 0:
        raise ValueError(f"theta must be >= 0 (a dissipation rate), got {th!r}.")
    return 2.0 * th / (sig * sig)


@dataclass(frozen=True)
class _Quadrature:
    log_normaliser: float
    mean: np.ndarray
    second_moment: np.ndarray
    n_nodes: int
    error_estimate: float
    level: int


class GibbsMeasure:
    r"""The density ``Z⁻¹ exp(−β h̃(Π))`` on the sphere ``|Π| = r`` (w.r.t. the area measure).

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments or SPD inertia tensor.
    c : array_like, shape (3,), optional
        Lévy-area velocity (RP convention; default 0): ``h̃ = ½ Π·𝕀⁻¹Π + c·Π``.
    sigma, theta : float, optional
        Isotropic noise amplitude and dissipation rate; ``β = 2θ/σ²``.
    beta : float, optional
        Give ``β`` directly instead of ``sigma`` and ``theta``.
    radius : float
        Radius of the orbit (default 1).
    rtol : float
        Target relative accuracy of the quadrature (default 1e-10).
    max_nodes : int
        Refuse quadrature rules larger than this (default 4e7): use :meth:`laplace` instead.

    Attributes
    ----------
    log_normaliser : float
        ``log Z``, ``Z = ∫ exp(−β h̃) dS``.
    mean : ndarray (3,)
        ``E[Π]``.
    second_moment : ndarray (3, 3)
        ``E[Π Πᵀ]`` (its trace is ``r²``).
    covariance : ndarray (3, 3)
    error_estimate : float
        Largest relative change of ``Z``, ``mean/r``, ``second_moment/r²`` at the last refinement.

    Examples
    --------
    >>> g = GibbsMeasure([1.0, 2.0, 3.0], [0.0, -0.0625, 0.0], sigma=0.05, theta=1.0)
    >>> round(g.beta, 9)                    # 2θ/σ²
    800.0
    >>> np.round(g.mean, 6)   # modes at (0, 0.375, ±0.927025): equal weights, Π3 averages out
    array([0.      , 0.378436, 0.      ])
    >>> bool(np.isclose(np.trace(g.second_moment), 1.0, atol=1e-12)) and g.error_estimate < 1e-10
    True
    """

    def __init__(self, inertia, c=None, *, sigma=None, theta=None, beta=None, radius=1.0,
                 rtol=1e-10, max_nodes=40_000_000):
        self._A = as_inverse_inertia(inertia)
        self._c = _as_c(c)
        self.radius = _check_radius(radius)
        if beta is None:
            if sigma is None or theta is None:
                raise TypeError("give either beta, or both sigma and theta (beta = 2*theta/sigma**2).")
            self.beta = gibbs_beta(sigma, theta)
        else:
            if sigma is not None or theta is not None:
                raise TypeError("give either beta, or sigma and theta, not both.")
            b = float(as_float_array(beta, "beta", ndim=0))
            if b < 0:
                raise ValueError(f"beta must be >= 0 (beta = 2*theta/sigma**2), got {b!r}.")
            self.beta = b
        self.rtol = check_positive_real(rtol, "rtol")
        self.max_nodes = check_positive_int(max_nodes, "max_nodes")
        self.equilibria = rigid_body_equilibria(np.linalg.inv(self._A), self._c, radius=self.radius)
        mins = [e for e in self.equilibria if e.kind in ("minimum", "degenerate")]
        self._hmin = float(self.equilibria[0].energy)
        self._pole = (mins[0] if mins else self.equilibria[0]).point / self.radius
        a = np.linalg.eigvalsh(self._A)
        self._kappa = self.radius ** 2 * float(a[-1] - a[0]) + self.radius * float(np.linalg.norm(self._c))
        self._q: _Quadrature | None = None

    @classmethod
    def from_system(cls, system, *, radius=1.0, rtol=1e-10, max_nodes=40_000_000) -> "GibbsMeasure":
        """The Gibbs law of a rigid-body system (``mechanics.systems.rigid_body.rigid_body``) with isotropic noise.

        Uses ``system.inertia``, ``system.theta``, ``σ`` from ``system.xi = σ I`` (anything else
        raises: Theorem 3.1 needs isotropic noise) and ``c = system.torque_velocity`` (the shift
        actually in its ``h̃``; for ``convention="paper"`` that is the flipped one).
        """
        for attr in ("inertia", "xi", "theta", "torque_velocity"):
            if not hasattr(system, attr):
                raise TypeError(f"system must be a rigid body (mechanics.systems.rigid_body.rigid_body), it has no .{attr}.")
        if system.theta > 0 and not getattr(system, "levy_in_dissipation", True) and np.any(system.torque_velocity):
            raise ValueError("the Gibbs density exp(-2θh̃/σ²) is the invariant law of Theorem 3.1's model, whose "
                             "dissipation is built from h̃; this system has levy_in_dissipation=False (torque in "
                             "the conservative term only), whose invariant law is not of that form. Build the "
                             "system with levy_in_dissipation=True, or estimate its law by simulation.")
        xi = np.asarray(system.xi, dtype=np.float64)
        sigma = float(xi[0, 0]) if xi.shape == (3, 3) else 0.0
        if xi.shape != (3, 3) or not np.allclose(xi, sigma * np.eye(3), rtol=0, atol=1e-14 * max(abs(sigma), 1e-300)) \
                or sigma == 0.0:
            raise ValueError("the Gibbs density exp(-2θh̃/σ²) needs isotropic noise xi = σ·I with σ != 0; "
                             f"this system has xi of shape {xi.shape}.")
        return cls(system.inertia, system.torque_velocity, sigma=abs(sigma), theta=system.theta, radius=radius,
                   rtol=rtol, max_nodes=max_nodes)

    # ------------------------------------------------------------------ the density
    def energy(self, Pi) -> np.ndarray:
        """``h̃(Π)`` for ``Π`` of shape ``(..., 3)``."""
        P = as_float_array(Pi, "Pi", last_dims=(3,))
        return self._energy(P)

    def _energy(self, P):
        return _modified_hamiltonian(P, self._A, self._c)

    def log_density(self, Pi) -> np.ndarray:
        """``log p(Π) = −β h̃(Π) − log Z`` (w.r.t. the area measure); ``Π`` is taken as given (on the sphere)."""
        return -self.beta * (self.energy(Pi) - self._hmin) - (self.log_normaliser + self.beta * self._hmin)

    def density(self, Pi) -> np.ndarray:
        """``p(Π)`` (w.r.t. the area measure of the sphere of radius ``r``)."""
        return np.exp(self.log_density(Pi))

    # ------------------------------------------------------------------ quadrature
    def _frame(self):
        n = self._pole
        b = _tangent_basis(n)
        return b[:, 0], b[:, 1], n

    def _rule(self, level):
        """Nodes (ϑ, weights_ϑ) and the number of φ nodes of refinement ``level``."""
        bk = self.beta * self._kappa
        s = 1.0 / math.sqrt(bk) if bk > 0 else math.inf
        f = 2.0 * 0.5 ** level
        width = min(s, math.pi / 8) * f
        n_panels = max(4, math.ceil(math.pi / width))
        n_gl = 10
        x, w = np.polynomial.legendre.leggauss(n_gl)
        edges = np.linspace(0.0, math.pi, n_panels + 1)
        mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * np.diff(edges)
        th = (mid[:, None] + half[:, None] * x[None, :]).ravel()
        wt = (half[:, None] * w[None, :]).ravel()
        n_phi = max(32, 2 * math.ceil(math.pi / (0.5 * min(s, 1.0) * f)))
        return th, wt, n_phi

    def _integrate(self, level, funcs=None):
        th, wt, n_phi = self._rule(level)
        if th.size * n_phi > self.max_nodes:
            raise ValueError(
                f"the quadrature rule for beta={self.beta:g} needs {th.size * n_phi:,} nodes "
                f"(> max_nodes={self.max_nodes:,}); raise max_nodes, lower rtol, or use "
                f"GibbsMeasure.laplace() for such a concentrated density.")
        r = self.radius
        u, v, n = self._frame()
        phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
        cphi, sphi = np.cos(phi), np.sin(phi)
        w_phi = 2.0 * math.pi / n_phi
        Z = 0.0
        M1 = np.zeros(3)
        M2 = np.zeros((3, 3))
        F = None
        block = max(1, 500_000 // n_phi)
        for i0 in range(0, th.size, block):
            t = th[i0:i0 + block]
            st, ct = np.sin(t), np.cos(t)
            # Π = r (sinϑ cosφ u + sinϑ sinφ v + cosϑ n)
            P = r * (st[:, None, None] * (cphi[None, :, None] * u + sphi[None, :, None] * v)
                     + ct[:, None, None] * n)
            e = self._energy(P) - self._hmin
            wgt = np.exp(-self.beta * np.maximum(e, 0.0)) * (wt[i0:i0 + block] * st * r * r * w_phi)[:, None]
            Z += float(wgt.sum())
            M1 += np.einsum("ab,abi->i", wgt, P)
            M2 += np.einsum("ab,abi,abj->ij", wgt, P, P)
            if funcs is not None:
                val = np.einsum("ab,ab...->...", wgt, np.asarray(funcs(P), dtype=np.float64))
                F = val if F is None else F + val
        return Z, M1, M2, F, th.size * n_phi

    def _compute(self):
        prev = None
        err = math.inf
        r = self.radius
        for level in range(0, 6):
            Z, M1, M2, _, nn = self._integrate(level)
            cur = (Z, M1 / Z, M2 / Z)
            if prev is not None:
                err = max(abs(cur[0] - prev[0]) / cur[0],
                          float(np.max(np.abs(cur[1] - prev[1]))) / r,
                          float(np.max(np.abs(cur[2] - prev[2]))) / (r * r))
                if err <= self.rtol:
                    break
            prev = cur
        Z, mean, m2 = cur
        m2 = 0.5 * (m2 + m2.T)
        self._q = _Quadrature(log_normaliser=math.log(Z) - self.beta * self._hmin, mean=mean,
                              second_moment=m2, n_nodes=nn, error_estimate=err, level=level)

    @property
    def _quad(self) -> _Quadrature:
        if self._q is None:
            self._compute()
        return self._q

    @property
    def log_normaliser(self) -> float:
        return self._quad.log_normaliser

    @property
    def mean(self) -> np.ndarray:
        return self._quad.mean.copy()

    @property
    def second_moment(self) -> np.ndarray:
        return self._quad.second_moment.copy()

    @property
    def covariance(self) -> np.ndarray:
        m = self._quad.mean
        return self._quad.second_moment - np.outer(m, m)

    @property
    def error_estimate(self) -> float:
        return self._quad.error_estimate

    @property
    def n_nodes(self) -> int:
        return self._quad.n_nodes

    def expectation(self, f) -> np.ndarray:
        """``E[f(Π)]`` by the converged rule; ``f`` maps ``(..., 3)`` to ``(...)`` or ``(..., p)``."""
        q = self._quad
        Z, _, _, F, _ = self._integrate(q.level, funcs=f)
        return F / Z

    # ------------------------------------------------------------------ independent checks
    def laplace(self) -> dict:
        r"""Leading-order Laplace approximation (relative error ``O(1/β)``), an independent check.

        ``Z ≈ Σ_k exp(−β h̃_k) · 2π / (β √det H_k)`` over the local minima ``Π_k`` of ``h̃`` on the
        sphere (``H_k`` the constrained tangent Hessian), ``E[Π] ≈ Σ_k w_k Π_k``,
        ``E[ΠΠᵀ] ≈ Σ_k w_k Π_k Π_kᵀ`` with ``w_k ∝`` the terms of ``Z``.
        """
        if self.beta <= 0:
            raise ValueError("the Laplace approximation needs beta > 0.")
        mins = [e for e in self.equilibria if e.kind == "minimum"]
        if not mins:
            raise ValueError("no non-degenerate minimum of h̃: the Laplace approximation does not apply.")
        logs = np.array([-self.beta * (e.energy - self._hmin)
                         + math.log(2.0 * math.pi / (self.beta * math.sqrt(float(np.prod(e.hessian_eigenvalues)))))
                         for e in mins])
        m = float(np.max(logs))
        w = np.exp(logs - m)
        Z = float(w.sum())
        w = w / Z
        pts = np.array([e.point for e in mins])
        return {"log_normaliser": m + math.log(Z) - self.beta * self._hmin,
                "mean": w @ pts, "second_moment": np.einsum("k,ki,kj->ij", w, pts, pts),
                "minima": pts, "weights": w}

    def sample(self, n, rng, *, max_proposals=100_000_000) -> np.ndarray:
        """Exact samples by rejection from the uniform law on the sphere; shape ``(n, 3)``.

        The acceptance rate is ``Z e^{β h̃_min} / (4π r²)`` (about 0.2 % for ``β = 800``); raises
        ``RuntimeError`` if more than ``max_proposals`` proposals would be needed.
        """
        n = check_positive_int(n, "n")
        rng = check_rng(rng)
        out = []
        got = 0
        used = 0
        acc = math.exp(self.log_normaliser + self.beta * self._hmin) / (4 * math.pi * self.radius ** 2)
        while got < n:
            m = int(min(max(1024, 1.2 * (n - got) / max(acc, 1e-12)), 1_000_000))
            if used + m > max_proposals:
                raise RuntimeError(f"rejection sampling needs more than max_proposals={max_proposals:,} "
                                   f"proposals (acceptance rate {acc:.2g}); raise max_proposals.")
            x = rng.standard_normal((m, 3))
            x *= self.radius / np.linalg.norm(x, axis=1, keepdims=True)
            keep = rng.random(m) < np.exp(-self.beta * np.maximum(self._energy(x) - self._hmin, 0.0))
            out.append(x[keep])
            got += int(keep.sum())
            used += m
        return np.concatenate(out)[:n]

    def __repr__(self) -> str:
        return (f"GibbsMeasure(beta={self.beta:g}, radius={self.radius:g}, "
                f"c={np.array2string(self._c, precision=4)})")


def gibbs_moments(inertia, c=None, *, sigma=None, theta=None, beta=None, radius=1.0, rtol=1e-10):
    """Mean and second moment of the Gibbs density by quadrature.

    Returns
    -------
    mean : ndarray (3,)
    second_moment : ndarray (3, 3)
    log_normaliser : float

    See :class:`GibbsMeasure` for the parameters and the method.
    """
    g = GibbsMeasure(inertia, c, sigma=sigma, theta=theta, beta=beta, radius=radius, rtol=rtol)
    return g.mean, g.second_moment, g.log_normaliser
