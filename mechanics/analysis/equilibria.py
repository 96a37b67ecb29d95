r"""Equilibria of the modified (Lévy-area-shifted) rigid body and their stability.

The model, ``Π̇ = Π × ∇h̃ + ϑ Π × (Π × ∇h̃)`` with ``h̃ = ½ Π·𝕀⁻¹Π + c·Π``, is in
:mod:`mechanics.analysis.modified_energy`; phase portraits (level sets of ``h̃`` on the sphere) are
in :mod:`mechanics.analysis.phase_portrait`.

Equilibria are the points where ``Π ∥ ∇h̃``: ``(𝕀⁻¹ − λ) Π = −c``, ``|Π| = r``. In the eigenbasis
``𝕀⁻¹ = Q diag(a) Qᵀ``, ``b = Qᵀ c``, this is the secular equation
``g(λ) = Σ_k b_k² / (a_k − λ)² = r²`` (plus the "non-generic" solutions ``λ = a_k`` when
``b_k = 0``). :func:`rigid_body_equilibria` brackets every real root between the poles (``g`` is
convex between consecutive poles, so each interval holds 0, 1 or 2 roots), polishes each point by
Newton on the bordered system ``[(𝕀⁻¹ − λ)Π + c, ½(|Π|² − r²)] = 0`` and classifies it.

Stability (energy–Casimir / linearisation): at an equilibrium with multiplier ``λ`` the
linearisation of the full vector field is ``J = ([Π]_× + ϑ [Π]_×²)(𝕀⁻¹ − λ)`` (exact, derived from
``Π × W = 0``); restricted to the tangent plane, with ``H = Bᵀ(𝕀⁻¹ − λ)B`` the constrained Hessian
of ``h̃`` (``B`` an orthonormal tangent basis), ``J_T = (r R − ϑ r²) H`` where ``R`` is the rotation
by +90°. Hence ``H`` definite ⇒ centre when ``ϑ = 0`` (Lyapunov stable by energy–Casimir), and for
``ϑ > 0`` asymptotically stable (minimum of ``h̃``) or unstable (maximum); ``H`` indefinite ⇒
saddle in both cases.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._inputs import _as_c, _check_radius, _check_theta
from ._sphere import _tangent_basis
from .modified_energy import _modified_hamiltonian, as_inverse_inertia

__all__ = ["Equilibrium", "rigid_body_equilibria"]


@dataclass(frozen=True)
class Equilibrium:
    """One equilibrium of the modified rigid body on the sphere ``|Π| = r``.

    Attributes
    ----------
    point : ndarray (3,)
        ``Π*`` (body frame).
    multiplier : float
        ``λ`` with ``∇h̃(Π*) = λ Π*``.
    energy : float
        ``h̃(Π*)``.
    hessian_eigenvalues : ndarray (2,)
        Eigenvalues of the constrained Hessian ``Bᵀ(𝕀⁻¹ − λ)B`` on the tangent plane (ascending).
    kind : str
        ``"minimum"``, ``"maximum"``, ``"saddle"`` (of ``h̃`` on the sphere) or ``"degenerate"``.
    conservative_type : str
        Type when ``ϑ = 0``: ``"centre"`` (Lyapunov stable), ``"saddle"`` or ``"degenerate"``.
    dissipative_type : str
        Type for the ``theta`` passed: ``"centre"``/``"saddle"`` if ``theta == 0``, otherwise
        ``"stable node"``, ``"stable focus"``, ``"unstable node"``, ``"unstable focus"``,
        ``"saddle"`` or ``"degenerate"``.
    jacobian_eigenvalues : ndarray (2,) complex
        Eigenvalues of the linearisation restricted to the tangent plane, for ``theta``.
    stable : bool
        Lyapunov stable for ``theta`` (a minimum, or a definite extremum when ``theta == 0``).
    manifold_dim : int
        0 for an isolated equilibrium; ``k > 0`` when it belongs to a ``k``-dimensional continuum
        (symmetric bodies), in which case ``point`` is one representative.
    """

    point: np.ndarray
    multiplier: float
    energy: float
    hessian_eigenvalues: np.ndarray
    kind: str
    conservative_type: str
    dissipative_type: str
    jacobian_eigenvalues: np.ndarray
    stable: bool
    manifold_dim: int = 0

    def __repr__(self) -> str:
        p = np.array2string(self.point, precision=6, suppress_small=True)
        return (f"Equilibrium(point={p}, energy={self.energy:.6g}, kind={self.kind!r}, "
                f"type={self.dissipative_type!r})")


def _hat(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _classify(P, lam, A, c, r, theta, scale, manifold_dim=0) -> Equilibrium:
    B = _tangent_basis(P)
    M = A - lam * np.eye(3)
    H = B.T @ M @ B
    H = 0.5 * (H + H.T)
    hev = np.linalg.eigvalsh(H)
    tol = 1e-9 * scale
    if hev[0] > tol:
        kind = "minimum"
    elif hev[1] < -tol:
        kind = "maximum"
    elif hev[0] < -tol and hev[1] > tol:
        kind = "saddle"
    else:
        kind = "degenerate"
    hatP = _hat(P)
    J = (hatP + theta * hatP @ hatP) @ M
    JT = B.T @ J @ B
    jev = np.linalg.eigvals(JT)
    jev = jev[np.argsort(jev.real)]
    cons = {"minimum": "centre", "maximum": "centre", "saddle": "saddle"}.get(kind, "degenerate")
    if theta == 0.0:
        dis = cons
        stable = kind in ("minimum", "maximum")
    else:
        if kind == "saddle":
            dis = "saddle"
        elif kind == "degenerate":
            dis = "degenerate"
        else:
            focus = bool(np.any(np.abs(jev.imag) > 1e-12 * max(1.0, float(np.max(np.abs(jev))))))
            dis = ("stable " if kind == "minimum" else "unstable ") + ("focus" if focus else "node")
        stable = kind == "minimum"
    energy = float(_modified_hamiltonian(P, A, c))
    return Equilibrium(point=P.copy(), multiplier=float(lam), energy=energy, hessian_eigenvalues=hev,
                       kind=kind, conservative_type=cons, dissipative_type=dis,
                       jacobian_eigenvalues=jev, stable=bool(stable), manifold_dim=manifold_dim)


def _polish(P, lam, A, c, r, iters=8):
    """Newton on F(Π, λ) = [(A − λ)Π + c, ½(|Π|² − r²)] (bordered Hessian); keeps the input if singular."""
    x = np.concatenate([P, [lam]])
    for _ in range(iters):
        Pk, lk = x[:3], x[3]
        F = np.concatenate([(A - lk * np.eye(3)) @ Pk + c, [0.5 * (Pk @ Pk - r * r)]])
        Jm = np.zeros((4, 4))
        Jm[:3, :3] = A - lk * np.eye(3)
        Jm[:3, 3] = -Pk
        Jm[3, :3] = Pk
        if np.linalg.cond(Jm) > 1e12:
            break
        dx = np.linalg.solve(Jm, -F)
        x = x + dx
        if np.max(np.abs(dx)) <= 1e-16 * (1.0 + np.max(np.abs(x))):
            break
    return x[:3], float(x[3])


def rigid_body_equilibria(inertia, c=None, *, radius=1.0, theta=0.0):
    r"""All equilibria of ``Π̇ = Π × ∇h̃ + ϑ Π × (Π × ∇h̃)`` on the sphere ``|Π| = radius``.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        Principal moments or a symmetric positive-definite inertia tensor 𝕀.
    c : array_like, shape (3,), optional
        The Lévy-area velocity (default 0), ``h̃ = ½ Π·𝕀⁻¹Π + c·Π``. RP convention: use
        :func:`isotropic_levy_shift` or the system's own ``c``; never the paper's printed
        "(0, 3σ²s13, …)".
    radius : float
        The Casimir ``|Π|`` of the orbit.
    theta : float
        Double-bracket dissipation rate ``ϑ ≥ 0``; only changes the dynamic type, not the points.

    Returns
    -------
    list of Equilibrium
        Sorted by increasing energy ``h̃``. For a body with a repeated principal moment and ``c``
        with no component in that eigenspace there are continua of equilibria: one representative
        is returned with ``manifold_dim > 0``.

    Examples
    --------
    >>> eqs = rigid_body_equilibria([1.0, 2.0, 3.0])
    >>> [(np.round(e.point, 12).tolist(), e.kind) for e in eqs][:2]
    [([0.0, 0.0, -1.0], 'minimum'), ([0.0, 0.0, 1.0], 'minimum')]
    >>> [e.conservative_type for e in eqs]
    ['centre', 'centre', 'saddle', 'saddle', 'centre', 'centre']
    >>> eq = rigid_body_equilibria([1.0, 2.0, 3.0], [0.0, -0.0625, 0.0], theta=1.0)[1]
    >>> np.round(eq.point, 6), eq.dissipative_type
    (array([0.      , 0.375   , 0.927025]), 'stable focus')
    """
    A = as_inverse_inertia(inertia)
    c = _as_c(c)
    r = _check_radius(radius)
    theta = _check_theta(theta)
    a, Q = np.linalg.eigh(A)
    b = Q.T @ c
    scale = float(a[-1]) + float(np.linalg.norm(c)) / r
    tol_a = 1e-10 * float(a[-1])
    tol_b = 1e-14 * max(scale * r, float(np.linalg.norm(c)))

    # group equal eigenvalues; within a group rotate so b lies along one direction
    groups: list[dict] = []
    for k in range(3):
        if groups and abs(a[k] - groups[-1]["a"]) <= tol_a:
            groups[-1]["idx"].append(k)
        else:
            groups.append({"a": float(a[k]), "idx": [k]})
    for g in groups:
        bg = b[g["idx"]]
        beta = float(np.linalg.norm(bg))
        g["beta"] = beta if beta > tol_b else 0.0
        g["basis"] = Q[:, g["idx"]]                       # original coordinates of the group's space
        g["u"] = (g["basis"] @ bg) / beta if g["beta"] > 0 else None   # unit direction of c there

    active = [g for g in groups if g["beta"] > 0]
    cands: list[tuple[np.ndarray, float, int]] = []

    def point_at(lam):
        return sum((-g["beta"] / (g["a"] - lam)) * g["u"] for g in active)

    if active:
        poles = np.array([g["a"] for g in active])
        betas = np.array([g["beta"] for g in active])

        def sec(lam):
            return float(np.sum((betas / (poles - lam)) ** 2) - r * r)

        def dsec(lam):
            return float(np.sum(2.0 * betas ** 2 / (poles - lam) ** 3))

        def off(p, beta):
            # a point just beside the pole p where g > 0 (|b|/(r·1e-8) away, at least a few ulps)
            return max(beta / r * 1e-8, 8.0 * float(np.spacing(abs(p) + tol_a)))

        def root(f, x0, x1):
            from scipy.optimize import brentq        # lazy: scipy.optimize costs ~0.2 s of import mechanics

            return brentq(f, x0, x1, xtol=1e-300, rtol=1e-15, maxiter=500)

        roots = []
        # outer intervals: exactly one root each (g falls from +inf to below -r² / rises back)
        bsum = float(np.sum(betas))
        roots.append(root(sec, poles[0] - bsum / r - 1.0, poles[0] - off(poles[0], betas[0])))
        roots.append(root(sec, poles[-1] + off(poles[-1], betas[-1]), poles[-1] + bsum / r + 1.0))
        # interior intervals: g convex, 0, 1 or 2 roots around the minimiser of g
        for p, q, bp, bq in zip(poles[:-1], poles[1:], betas[:-1], betas[1:]):
            left, right = p + off(p, bp), q - off(q, bq)
            if not (left < right and dsec(left) < 0 < dsec(right)):
                continue
            m = root(dsec, left, right)
            gm = sec(m)
            if gm < -1e-13 * r * r:
                roots.append(root(sec, left, m))
                roots.append(root(sec, m, right))
            elif gm <= 1e-13 * r * r:
                roots.append(m)                      # tangency: a degenerate (fold) equilibrium
        for lam in roots:
            cands.append((point_at(lam), float(lam), 0))

    # non-generic branch: λ = a_g for a group with no component of c
    for g in groups:
        if g["beta"] > 0:
            continue
        lam = g["a"]
        base = point_at(lam) if active else np.zeros(3)
        rho2 = r * r - float(base @ base)
        dim = len(g["idx"])
        if rho2 < -1e-12 * r * r:
            continue
        rho = math.sqrt(max(rho2, 0.0))
        if rho <= 1e-7 * r:
            cands.append((base, lam, 0))
        elif dim == 1:
            e = g["basis"][:, 0]
            cands.append((base + rho * e, lam, 0))
            cands.append((base - rho * e, lam, 0))
        else:
            cands.append((base + rho * g["basis"][:, 0], lam, dim - 1))

    out: list[Equilibrium] = []
    seen: list[np.ndarray] = []
    for P, lam, mdim in cands:
        if mdim == 0:
            P, lam = _polish(P, lam, A, c, r)
        if any(np.linalg.norm(P - q) <= 1e-8 * r for q in seen):
            continue
        seen.append(P)
        out.append(_classify(P, lam, A, c, r, theta, scale, mdim))
    esc = scale * r * r
    out.sort(key=lambda e: (round(e.energy / esc, 10), tuple(np.round(e.point / r, 10))))
    return out
