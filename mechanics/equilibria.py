r"""Equilibria of the modified (Lévy-area-shifted) rigid body and their stability; phase portraits.

The deterministic part of the rough-path-correct (RP) rigid body of ``docs/conventions.md`` is

.. math::

    \dot\Pi = \Pi\times W + \vartheta\,\Pi\times(\Pi\times W), \qquad
    W = \nabla\tilde h(\Pi) = \mathbb I^{-1}\Pi + c, \qquad
    \tilde h(\Pi) = \tfrac12\,\Pi\cdot\mathbb I^{-1}\Pi + c\cdot\Pi,

with ``c = +½ Σ_ij s^{ij} ξ_i × ξ_j`` (for isotropic noise ``ξ_i = σ e_i``:
``c = σ² (s23, -s13, s12)``; the paper's printed ``-½`` flips it, see :func:`isotropic_levy_shift`).
Both terms are tangent to the sphere ``|Π| = r`` (a Casimir); the second one is
``-ϑ r² P_T ∇h̃``, the gradient descent of ``h̃`` on the sphere, so with ``ϑ > 0`` the flow is
attracted to the local minima of ``h̃`` on the sphere.

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
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from roughpaths._validation import as_float_array, check_antisymmetric

__all__ = [
    "Equilibrium",
    "LevelSets",
    "as_inverse_inertia",
    "isotropic_levy_shift",
    "modified_hamiltonian",
    "rigid_body_vector_field",
    "rigid_body_equilibria",
    "rigid_body_level_sets",
    "lagrange_top_sleeping_stability",
]


# ---------------------------------------------------------------------------------------- inputs
def as_inverse_inertia(inertia, name: str = "inertia") -> np.ndarray:
    """Return ``𝕀⁻¹`` (3×3) from an inertia given as 3 principal moments or a 3×3 SPD matrix.

    Raises ``ValueError`` for non-symmetric, non-positive-definite or wrongly shaped input.
    """
    arr = as_float_array(inertia, name)
    if arr.shape == (3,):
        if np.any(arr <= 0):
            raise ValueError(f"{name} must have positive principal moments, got {arr.tolist()}; "
                             f"a rigid body needs 𝕀 = diag(I1, I2, I3) with every Ik > 0.")
        return np.diag(1.0 / arr)
    if arr.shape != (3, 3):
        raise ValueError(f"{name} must be 3 principal moments (shape (3,)) or a 3x3 symmetric "
                         f"positive-definite matrix, got shape {arr.shape}.")
    scale = max(float(np.max(np.abs(arr))), 1e-300)
    asym = float(np.max(np.abs(arr - arr.T)))
    if asym > 1e-12 * scale:
        raise ValueError(f"{name} must be symmetric, but |𝕀 - 𝕀ᵀ| = {asym:.3g}; "
                         f"pass 0.5 * ({name} + {name}.T) if the asymmetry is round-off.")
    sym = 0.5 * (arr + arr.T)
    w = np.linalg.eigvalsh(sym)
    if w[0] <= 0:
        raise ValueError(f"{name} must be positive definite, its eigenvalues are {w.tolist()}.")
    return np.linalg.inv(sym)


def _as_c(c, name: str = "c") -> np.ndarray:
    if c is None:
        return np.zeros(3)
    return as_float_array(c, name, ndim=1, last_dims=(3,))


def _check_radius(radius) -> float:
    r = float(as_float_array(radius, "radius", ndim=0))
    if not r > 0:
        raise ValueError(f"radius must be > 0 (the Casimir |Π| of the orbit), got {r!r}.")
    return r


def _check_theta(theta) -> float:
    th = float(as_float_array(theta, "theta", ndim=0))
    if th < 0:
        raise ValueError(f"theta must be >= 0 (a dissipation rate), got {th!r}; "
                         f"theta < 0 is anti-dissipation and has no Gibbs measure.")
    return th


def isotropic_levy_shift(sigma, s, convention: str = "rp") -> np.ndarray:
    r"""The Lévy-area velocity ``c`` for isotropic noise ``ξ_i = σ e_i`` on so(3) ≅ R³.

    ``convention="rp"`` (default, ``docs/conventions.md``): ``c = +½ Σ_ij s^{ij} ξ_i × ξ_j
    = σ² (s23, −s13, s12)``. ``convention="paper"``: the paper's printed ``−½`` (torque sign
    flipped), ``c = −σ² (s23, −s13, s12)``.

    Examples
    --------
    >>> s = np.zeros((3, 3)); s[0, 2], s[2, 0] = 25.0, -25.0
    >>> isotropic_levy_shift(0.05, s)            # the paper's Fig. surf2 parameters
    array([ 0.    , -0.0625,  0.    ])
    """
    sig = float(as_float_array(sigma, "sigma", ndim=0))
    s = check_antisymmetric(s, "s", dim=3)
    if s.ndim != 2:
        raise ValueError(f"s must be a single 3x3 antisymmetric matrix, got shape {s.shape}.")
    c = sig * sig * np.array([s[1, 2], -s[0, 2], s[0, 1]])
    if convention == "rp":
        return c
    if convention == "paper":
        return -c
    raise ValueError(f"convention must be 'rp' or 'paper', got {convention!r}.")


def modified_hamiltonian(Pi, inertia, c=None) -> np.ndarray:
    """``h̃(Π) = ½ Π·𝕀⁻¹Π + c·Π`` for ``Π`` of shape ``(..., 3)``; returns shape ``(...)``."""
    A = as_inverse_inertia(inertia)
    c = _as_c(c)
    P = as_float_array(Pi, "Pi", last_dims=(3,))
    return 0.5 * np.einsum("...i,ij,...j->...", P, A, P) + P @ c


def rigid_body_vector_field(Pi, inertia, c=None, theta=0.0) -> np.ndarray:
    """RP deterministic vector field ``Π × W + ϑ Π × (Π × W)``, ``W = 𝕀⁻¹Π + c``; shape ``(..., 3)``.

    Independent of the integrators module (plain numpy), for deterministic checks with
    ``scipy.integrate.solve_ivp``.
    """
    A = as_inverse_inertia(inertia)
    c = _as_c(c)
    th = _check_theta(theta)
    P = as_float_array(Pi, "Pi", last_dims=(3,))
    W = P @ A.T + c
    PxW = np.cross(P, W)
    return PxW + th * np.cross(P, PxW)


# ------------------------------------------------------------------------------------ equilibria
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


def _tangent_basis(n: np.ndarray) -> np.ndarray:
    """Orthonormal basis (3, 2) of the plane ⟂ n, right-handed: b1 × b2 = n/|n|."""
    u = n / np.linalg.norm(n)
    k = int(np.argmin(np.abs(u)))
    e = np.zeros(3)
    e[k] = 1.0
    b1 = np.cross(u, e)
    b1 /= np.linalg.norm(b1)
    b2 = np.cross(u, b1)
    return np.stack([b1, b2], axis=1)


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
    energy = float(0.5 * P @ A @ P + c @ P)
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


# ------------------------------------------------------------------------------ phase portraits
@dataclass
class LevelSets:
    """Level curves of ``h̃`` on the sphere ``|Π| = r`` (for phase portraits).

    Attributes
    ----------
    levels : ndarray (L,)
        The energy values.
    curves : list of list of ndarray
        ``curves[k]`` holds the polylines (each of shape ``(m, 3)``, on the sphere to round-off,
        projected onto the exact level set) of ``h̃ = levels[k]``; closed curves repeat their first
        point at the end.
    separatrix : ndarray of bool (L,)
        True for the levels of saddle equilibria (the separatrices).
    equilibria : list of Equilibrium
        All equilibria, with type (see :func:`rigid_body_equilibria`).
    radius : float
    """

    levels: np.ndarray
    curves: list
    separatrix: np.ndarray
    equilibria: list
    radius: float = 1.0
    energy_range: tuple = field(default=(0.0, 0.0))


def _join_polylines(lines, tol):
    """Join polylines whose end points coincide (the φ seam of the chart), in 3-D."""
    lines = [np.asarray(l) for l in lines if len(l) >= 2]
    changed = True
    while changed:
        changed = False
        for i in range(len(lines)):
            for j in range(len(lines)):
                if i == j:
                    continue
                a, b = lines[i], lines[j]
                if np.linalg.norm(a[-1] - b[0]) <= tol:
                    new = np.concatenate([a, b[1:]])
                elif np.linalg.norm(a[-1] - b[-1]) <= tol:
                    new = np.concatenate([a, b[::-1][1:]])
                else:
                    continue
                lines = [l for k, l in enumerate(lines) if k not in (i, j)] + [new]
                changed = True
                break
            if changed:
                break
    out = []
    for l in lines:
        if np.linalg.norm(l[0] - l[-1]) <= tol and len(l) > 2:
            l = np.concatenate([l[:-1], l[:1]])
        out.append(l)
    return out


def rigid_body_level_sets(inertia, c=None, *, radius=1.0, levels=12, include_separatrices=True,
                          n_theta=181, n_phi=361, theta=0.0, project=True):
    r"""Level curves of ``h̃ = ½Π·𝕀⁻¹Π + c·Π`` on the sphere ``|Π| = r``, with the equilibria.

    The rigid body's (modified) phase portrait: the conservative orbits are exactly these curves.
    Contouring is done by ``contourpy`` (matplotlib's engine) on a (colatitude, longitude) grid,
    seam pieces are joined in 3-D and every vertex is projected onto the exact level set (Newton
    along the tangential gradient, then back to the sphere).

    Parameters
    ----------
    inertia, c, radius, theta
        As in :func:`rigid_body_equilibria` (RP sign of ``c``). The paper's Fig. surf2 caption
        (``h̃ = ½Π·𝕀⁻¹Π + 0.0625 Π·e2`` for ``s13 = 25``, σ = 0.05) uses its printed sign: in the RP
        convention that case is ``c = (0, −0.0625, 0)``; surf4/surf5 (``+0.0625, −0.0625, −0.125``
        for ``s12 = −50, s13 = s23 = 25``) already agree with RP.
    levels : int or array_like
        Number of equally spaced interior levels between min and max of ``h̃`` on the sphere, or the
        level values themselves.
    include_separatrices : bool
        Add the energies of the saddle equilibria (flagged in ``separatrix``).
    n_theta, n_phi : int
        Contouring grid.
    project : bool
        Project the vertices onto the exact level set (default True).

    Returns
    -------
    LevelSets

    Examples
    --------
    >>> ls = rigid_body_level_sets([1.0, 2.0, 3.0], levels=[0.2, 0.4])
    >>> ls.levels.tolist(), ls.separatrix.tolist()    # the saddle level 1/4 is added
    ([0.2, 0.25, 0.4], [False, True, False])
    >>> [len(cs) for cs in ls.curves]   # ovals around ±e3, the two separatrix circles, ovals around ±e1
    [2, 2, 2]
    >>> bool(np.allclose(np.linalg.norm(ls.curves[0][0], axis=1), 1.0))
    True
    """
    import contourpy

    A = as_inverse_inertia(inertia)
    c = _as_c(c)
    r = _check_radius(radius)
    eqs = rigid_body_equilibria(_inertia_from_inverse(A), c, radius=r, theta=theta)
    emin, emax = eqs[0].energy, eqs[-1].energy
    if np.ndim(levels) == 0:
        n = int(levels)
        if n < 1:
            raise ValueError(f"levels must be a positive number of levels or an array of values, got {levels!r}.")
        lv = list(np.linspace(emin, emax, n + 2)[1:-1])
    else:
        lv = list(as_float_array(levels, "levels", ndim=1))
    sep = [False] * len(lv)
    if include_separatrices:
        for e in eqs:
            if e.kind == "saddle" and not any(abs(e.energy - x) <= 1e-12 * (abs(emax) + abs(emin) + 1) for x in lv):
                lv.append(e.energy)
                sep.append(True)
    order = np.argsort(lv)
    lv = np.array(lv)[order]
    sep = np.array(sep)[order]

    th = np.linspace(0.0, np.pi, n_theta)
    ph = np.linspace(-np.pi, np.pi, n_phi)
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    P = r * np.stack([np.sin(TH) * np.cos(PH), np.sin(TH) * np.sin(PH), np.cos(TH)], axis=-1)
    H = 0.5 * np.einsum("...i,ij,...j->...", P, A, P) + P @ c
    gen = contourpy.contour_generator(ph, th, H, line_type="Separate")
    curves = []
    for level in lv:
        pieces = []
        for seg in gen.lines(float(level)):
            phs, ths = seg[:, 0], seg[:, 1]
            xyz = r * np.stack([np.sin(ths) * np.cos(phs), np.sin(ths) * np.sin(phs), np.cos(ths)], axis=-1)
            if project:
                xyz = _project_to_level(xyz, A, c, r, float(level))
            pieces.append(xyz)
        curves.append(_join_polylines(pieces, tol=1e-6 * r))
    return LevelSets(levels=lv, curves=curves, separatrix=sep, equilibria=eqs, radius=r,
                     energy_range=(emin, emax))


def _inertia_from_inverse(A):
    return np.linalg.inv(A)


def _project_to_level(x, A, c, r, level, iters=4):
    for _ in range(iters):
        g = x @ A.T + c
        n = x / np.linalg.norm(x, axis=-1, keepdims=True)
        gt = g - np.sum(g * n, axis=-1, keepdims=True) * n
        f = 0.5 * np.einsum("...i,ij,...j->...", x, A, x) + x @ c - level
        g2 = np.sum(gt * gt, axis=-1)
        ok = g2 > 1e-20 * (1.0 + float(np.max(g2, initial=0.0)))
        step = np.where(ok, f / np.where(ok, g2, 1.0), 0.0)
        step = np.clip(step, -0.05 * r / np.sqrt(np.maximum(g2, 1e-300)), 0.05 * r / np.sqrt(np.maximum(g2, 1e-300)))
        x = x - step[..., None] * gt
        x = r * x / np.linalg.norm(x, axis=-1, keepdims=True)
    return x


# ------------------------------------------------------------------------------------ heavy top
def lagrange_top_sleeping_stability(I1, I3, omega3, mgl):
    r"""The sleeping Lagrange top: linear stability of ``Π = (0, 0, I3 ω3)``, ``Γ = e3``.

    Symmetric top ``𝕀 = diag(I1, I1, I3)``, ``h = ½Π·𝕀⁻¹Π + χ·Γ`` with ``χ = M g ℓ e3`` (centre of
    mass on the symmetry axis at distance ``ℓ``), Lie–Poisson equations on se(3)* in the
    ``docs/conventions.md`` form ``Π̇ = Π × Ω + Γ × χ``, ``Γ̇ = Γ × Ω``. The upright spin is an equilibrium
    for every ``ω3``; it is linearly (and, by energy–Casimir, nonlinearly) stable iff
    ``Π3² > 4 I1 M g ℓ`` (the fast-top criterion). The body-frame linearisation has the eigenvalues
    ``± √(4 I1 M g ℓ − Π3²) / (2 I1)`` (each twice) plus two zeros along the Casimir directions.

    Returns
    -------
    dict with ``stable`` (bool), ``margin`` ``Π3² − 4 I1 M g ℓ`` and ``eigenvalues`` (complex, 6).

    Examples
    --------
    >>> lagrange_top_sleeping_stability(1.0, 2.0, 2.0, 1.0)["stable"]
    True
    """
    I1 = float(I1)
    I3 = float(I3)
    if not (I1 > 0 and I3 > 0):
        raise ValueError(f"I1 and I3 must be > 0, got I1={I1!r}, I3={I3!r}.")
    p3 = I3 * float(omega3)
    margin = p3 * p3 - 4.0 * I1 * float(mgl)
    lam = np.sqrt(complex(-margin)) / (2.0 * I1)
    return {"stable": bool(margin > 0), "margin": margin,
            "eigenvalues": np.array([lam, lam, -lam, -lam, 0.0, 0.0], dtype=complex)}
