r"""Coloured (Ornstein–Uhlenbeck) noise as a level-2 rough path, and its exact white-noise limit.

The process (paper, Section 4.2 and appendix "Coloured noise as a rough path")

.. math::

    dy = -\varepsilon^{-2} A\, y\, dt + \varepsilon^{-1} D\, dB, \qquad
    B^\varepsilon_t = \int_0^t \frac{y_r}{\varepsilon}\, dr,

with ``A`` (n×n) whose eigenvalues have positive real part and ``D`` (n×m), ``B`` an m-dimensional
Brownian motion. ``y`` has the ε-independent stationary covariance ``Σ``, ``AΣ + ΣAᵀ = DDᵀ``.

Limit (``docs/conventions.md``, "Coloured noise"). As ε → 0 the canonical (Young) lift of ``B^ε``
converges to

.. math::

    \bigl(M B,\; M\,\mathbb{B}^{\mathrm{Strat}} M^T + N\,(t - s)\bigr), \qquad
    M = A^{-1} D, \qquad N = \mathrm{Alt}(\Sigma A^{-T}) = \tfrac12(\Sigma A^{-T} - A^{-1}\Sigma),

and ``E[XX^ε_{0,T}]/T → ΣA⁻ᵀ``, whose symmetric part is ``½ M Mᵀ`` (the Itô–Stratonovich part)
and whose antisymmetric part ``N`` is the perturbation ``s`` of the area **in B^ε coordinates**.
The paper's eq. (levycoloured) ``s = ΣA⁻ᵀ − A⁻¹Σ`` equals ``2N``: it is the rate of the
*unnormalised* area ``XX − XXᵀ``, exposed here as :attr:`ColouredNoiseLimit.unnormalised_area_rate`
and never used as a perturbation.

Exact transitions (derivation). Work in the fast time ``τ = t/ε²``, where ``ỹ_τ = y_{ε²τ}`` solves
``dỹ = −Aỹ dτ + D dB̃`` with the Brownian motion ``B̃_τ = ε⁻¹ B_{ε²τ}``. Over a step of fast length
``δ = h/ε²`` the vector ``z = (ỹ, J, B̃)`` with ``J = ∫ ỹ dτ`` solves the linear SDE
``dz = F z dτ + G dB̃`` with ``F = [[−A, 0, 0], [I, 0, 0], [0, 0, 0]]``, ``G = [D; 0; I]``. Hence,
given ``ỹ_0``, ``z_δ`` is Gaussian with mean ``e^{Fδ} z_0`` (``ỹ_δ``: ``e^{−Aδ}ỹ_0``; ``J``:
``A⁻¹(I − e^{−Aδ})ỹ_0``; ``B̃``: 0) and covariance ``Q(δ) = ∫_0^δ e^{Fr} G Gᵀ e^{Fᵀr} dr``, computed
by Van Loan's method: ``expm(δ [[−F, GGᵀ], [0, Fᵀ]]) = [[·, e^{−Fδ}Q], [0, e^{Fᵀδ}]]``
(for ``δ‖A‖ > 1`` it is evaluated at ``δ/2^k`` and doubled with ``Q(2δ) = e^{Fδ}Q(δ)e^{Fᵀδ} + Q(δ)``).
``Q`` is singular: integrating the SDE gives the pathwise identity ``J = A⁻¹(ỹ_0 − ỹ_δ + D ΔB̃)``.
The sampler therefore draws ``(ỹ_δ, ΔB̃)`` from its (non-degenerate) Gaussian law and sets ``J`` by
the identity; the tests compare the sampled law of all three with the Van Loan ``Q``.
Back in physical units: ``ΔB^ε = ε J``, ``ΔB = ε ΔB̃``.

Area of the smooth path (accuracy). On each step ``B^ε`` is C¹, so its area is not determined by
the step's endpoint data. Each grid step is split into ``m`` sub-steps of fast length ``δ`` sampled
exactly as above; on a sub-step the path is replaced by the cubic Hermite interpolant of the exact
data ``B^ε`` increment and end slopes ``ε ỹ_0``, ``ε ỹ_δ`` (for ``A = 0`` this is the conditional mean
of the path given those data), whose Lévy area is, with ``a ∧ b = a⊗b − b⊗a``, ``x`` the increment,
``u = εδỹ_0``, ``v = εδỹ_δ``,

.. math:: -\tfrac1{10}\, x\wedge u + \tfrac1{10}\, x\wedge v - \tfrac1{60}\, u\wedge v,

and sub-steps are combined by Chen sums (exact). The lift is geometric by construction. Its
expected area rate is known exactly (:func:`lift_area_rate`): the relative bias of the Lévy-area
rate is ``O((δ‖A‖)²)`` with the piecewise-linear lift (e.g. 0.4 % at ``δ‖A‖ = 0.25`` for the paper's
``A``) and ``O(10⁻⁵)`` with the Hermite correction (see :func:`lift_area_rate`). Pathwise, the
Lévy-area error is a mean-zero fluctuation of order ``ε² δ^{5/2}`` per sub-step, i.e. an L² error
``≈ c δ²`` per unit of fast time (measured in ``tests/test_coloured_noise_driver.py`` for a
non-normal 2×2 ``A``: ``c ≈ 0.3`` with the Hermite correction, ``≈ 1`` for the chord lift). A
:class:`ResolutionWarning` (stating ``h/ε²``) is issued when a sub-step exceeds ``max_substep``
in units of ``ε²/‖A‖``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numba
import numpy as np
import scipy.linalg as sla

from ._validation import as_float_array, check_positive_int, check_rng, check_times
from .rough_path import RoughPath

__all__ = [
    "ResolutionWarning",
    "ColouredNoiseLimit",
    "ColouredNoiseSample",
    "coloured_noise_limit",
    "paper_coloured_noise_matrices",
    "ou_step_law",
    "lift_area_rate",
    "expected_area_rate",
    "sample_coloured_noise",
    "coloured_noise_limit_path",
    "iter_coloured_noise",
]

# Hermite Lévy-area coefficients (see module docstring).
_K_XU, _K_XV, _K_UV = -0.1, 0.1, -1.0 / 60.0


class ResolutionWarning(UserWarning):
    """A time step does not resolve the correlation time ``ε²/‖A‖`` of the coloured noise."""


# ---------------------------------------------------------------------------------------- checks
def _check_eps(eps) -> float:
    if isinstance(eps, bool) or not np.isscalar(eps) or not np.isreal(eps):
        raise TypeError(f"eps must be a positive real number, got {eps!r}.")
    e = float(eps)
    if not math.isfinite(e) or e <= 0.0:
        raise ValueError(f"eps must be a finite number > 0 (the noise correlation time is eps**2), "
                         f"got eps={eps!r}; eps -> 0 is the white-noise limit, use "
                         f"coloured_noise_limit(...) / coloured_noise_limit_path(...) for it.")
    return e


def _check_AD(A, D):
    A = as_float_array(A, "A", ndim=2)
    if A.shape[0] != A.shape[1] or A.shape[0] == 0:
        raise ValueError(f"A must be a square (n, n) matrix, got shape {A.shape}.")
    n = A.shape[0]
    D = as_float_array(D, "D", min_ndim=1)
    if D.ndim == 1:
        D = D[:, None]
    if D.ndim != 2 or D.shape[0] != n:
        raise ValueError(f"D must have shape (n, m) = ({n}, m) to match A of shape {A.shape}, got "
                         f"shape {D.shape}.")
    eig = np.linalg.eigvals(A)
    if np.min(eig.real) <= 1e-12 * max(1.0, float(np.max(np.abs(eig)))):
        k = int(np.argmin(eig.real))
        raise ValueError(f"A must have all eigenvalues in the open right half-plane (dy = -A y dt/eps² "
                         f"+ ... has no stationary law otherwise); its eigenvalue {eig[k]:.6g} has real "
                         f"part {eig[k].real:.3g} <= 0. Shift it, e.g. A + c*I with c > {-eig[k].real:.3g}.")
    return A, D


def _lyapunov(A, D):
    """Stationary covariance Σ with ``AΣ + ΣAᵀ = DDᵀ``; raise if singular."""
    Sigma = sla.solve_continuous_lyapunov(A, D @ D.T)
    Sigma = 0.5 * (Sigma + Sigma.T)
    w = np.linalg.eigvalsh(Sigma)
    if w[0] <= 1e-10 * max(w[-1], 1e-300):
        raise ValueError(
            f"the stationary covariance Sigma (A Sigma + Sigma A^T = D D^T) is singular: eigenvalues "
            f"{np.array2string(w, precision=3)} (condition > 1e10). The noise D does not excite every "
            f"direction of y (the pair (A, D) is not controllable), so some component of y is "
            f"deterministic and decays to 0. Remove that direction from the model (reduce n) or add "
            f"noise to it (a D with rank(D) = n always works).")
    return Sigma


# --------------------------------------------------------------------------------- exact limit
@dataclass(frozen=True)
class ColouredNoiseLimit:
    r"""Exact ε → 0 data of the coloured noise ``dy = −ε⁻²Ay dt + ε⁻¹D dB`` (B^ε coordinates).

    Attributes
    ----------
    A, D : ndarray, shapes ``(n, n)``, ``(n, m)``
    Sigma : ndarray ``(n, n)``
        Stationary covariance of ``y``: ``AΣ + ΣAᵀ = DDᵀ`` (ε-independent).
    area_rate : ndarray ``(n, n)``
        ``ΣA⁻ᵀ = lim E[XX^ε_{0,T}]/T`` (iisignature ordering ``XX[i, j] = ∫ B^i dB^j``).
    scaling : ndarray ``(n, m)``
        ``M = A⁻¹D``: ``B^ε → M B``.
    levy_perturbation : ndarray ``(n, n)``
        ``N = Alt(ΣA⁻ᵀ)``, the antisymmetric perturbation of the area in B^ε coordinates: the limit
        is ``(MB, M B^{Strat} Mᵀ + N (t−s))``. This is the ``s`` to give to ``RoughPath.perturb``
        or to the Friz–Oberhauser drift ``½ Σ N^{ij}[V_i, V_j]`` of fields ``V_i`` driven by B^ε.
    unnormalised_area_rate : ndarray ``(n, n)``
        ``2N = ΣA⁻ᵀ − A⁻¹Σ``, the paper's eq. (levycoloured) "s": the rate of ``XX − XXᵀ``. Never a
        perturbation (using it doubles the Lévy drift).
    ito_stratonovich_rate : ndarray ``(n, n)``
        ``Sym(ΣA⁻ᵀ) = ½ M Mᵀ``.
    """

    A: np.ndarray
    D: np.ndarray
    Sigma: np.ndarray
    area_rate: np.ndarray
    scaling: np.ndarray
    levy_perturbation: np.ndarray
    unnormalised_area_rate: np.ndarray
    ito_stratonovich_rate: np.ndarray

    @property
    def N(self) -> np.ndarray:
        """Alias of :attr:`levy_perturbation`."""
        return self.levy_perturbation

    @property
    def M(self) -> np.ndarray:
        """Alias of :attr:`scaling` (``A⁻¹D``)."""
        return self.scaling


def coloured_noise_limit(A, D) -> ColouredNoiseLimit:
    r"""Exact white-noise limit of the coloured noise ``dy = −ε⁻²Ay dt + ε⁻¹D dB``.

    Parameters
    ----------
    A : array_like, shape ``(n, n)``
        Drift matrix, all eigenvalues with positive real part (else ``ValueError``).
    D : array_like, shape ``(n, m)`` or ``(n,)``
        Noise matrix; ``Σ`` must be non-singular (``(A, D)`` controllable, else ``ValueError``).

    Returns
    -------
    ColouredNoiseLimit
        ``Sigma``, ``area_rate = ΣA⁻ᵀ``, ``scaling = A⁻¹D``, ``levy_perturbation = N = Alt(ΣA⁻ᵀ)``
        and, labelled, the paper's ``unnormalised_area_rate = 2N``.

    Examples
    --------
    The paper's rigid-body example ``A = kI + Λ`` (``Λ13 = 1 = −Λ31``), ``D = I``, ``k = 0.05``:
    the paper's "s13 ≈ 19.95" is ``2 N13``.

    >>> from roughpaths.coloured_noise import coloured_noise_limit, paper_coloured_noise_matrices
    >>> lim = coloured_noise_limit(*paper_coloured_noise_matrices(k=0.05))
    >>> round(float(lim.N[0, 2]), 4), round(float(lim.unnormalised_area_rate[0, 2]), 3)
    (9.9751, 19.95)
    """
    A, D = _check_AD(A, D)
    Sigma = _lyapunov(A, D)
    Ainv = np.linalg.inv(A)
    rate = Sigma @ Ainv.T
    N = 0.5 * (rate - rate.T)
    M = Ainv @ D
    return ColouredNoiseLimit(A=A, D=D, Sigma=Sigma, area_rate=rate, scaling=M, levy_perturbation=N,
                              unnormalised_area_rate=2.0 * N, ito_stratonovich_rate=0.5 * (rate + rate.T))


def paper_coloured_noise_matrices(k: float = 0.05, l12: float = 0.0, l13: float = 1.0, l23: float = 0.0):
    r"""The paper's rigid-body noise ``A = kI + Λ``, ``D = I`` (3×3).

    ``Λ`` is antisymmetric with ``Λ12 = l12``, ``Λ13 = l13``, ``Λ23 = l23`` (``Λji = −Λij``). The paper's
    ``skew(0, 0, 1)`` is undefined in its text; its printed ``A⁻¹D`` fixes ``Λ13 = +1, Λ31 = −1``, the
    default here. Then ``Σ = I/(2k)`` and ``N13 = 1/(2k(1 + k²))``.

    Returns
    -------
    A, D : ndarray, shape ``(3, 3)``
    """
    k = float(k)
    if not math.isfinite(k) or k <= 0:
        raise ValueError(f"k must be a finite number > 0 (A = k I + Lambda needs Re eig = k > 0), got {k!r}.")
    L = np.array([[0.0, l12, l13], [-l12, 0.0, l23], [-l13, -l23, 0.0]], dtype=float)
    return k * np.eye(3) + L, np.eye(3)


# ---------------------------------------------------------------------------- transition law
def _van_loan(F, GGt, delta):
    """Covariance ``∫_0^δ e^{Fr} GGᵀ e^{Fᵀr} dr`` and ``e^{Fδ}`` (scaled Van Loan + doubling)."""
    k = F.shape[0]
    nrm = float(np.linalg.norm(F, 2))
    j = max(0, int(math.ceil(math.log2(max(nrm * delta, 1e-300)))) if nrm * delta > 1.0 else 0)
    d0 = delta / 2.0 ** j
    C = np.zeros((2 * k, 2 * k))
    C[:k, :k] = -F
    C[:k, k:] = GGt
    C[k:, k:] = F.T
    E = sla.expm(C * d0)
    Phi = E[k:, k:].T
    Q = Phi @ E[:k, k:]
    for _ in range(j):
        Q = Phi @ Q @ Phi.T + Q
        Phi = Phi @ Phi
    return Phi, 0.5 * (Q + Q.T)


def ou_step_law(A, D, eps, h):
    r"""Exact joint law of ``(y_{t+h}, ∫_t^{t+h} y dr, B_{t+h} − B_t)`` given ``y_t``.

    For ``dy = −ε⁻²Ay dt + ε⁻¹D dB`` the vector ``w = (y_{t+h}, ∫_t^{t+h} y dr, ΔB)`` (length
    ``2n + m``, physical time units) is Gaussian given ``y_t`` with mean ``T y_t`` and covariance
    ``Q`` (Van Loan; see the module docstring). Note ``ΔB^ε = ∫ y dr / ε``.

    Parameters
    ----------
    A, D : array_like, shapes ``(n, n)``, ``(n, m)``
    eps, h : float
        ``ε > 0`` and the step ``h > 0``.

    Returns
    -------
    mean_map : ndarray, shape ``(2n + m, n)``
        ``[e^{−Ah/ε²}; ε² A⁻¹(I − e^{−Ah/ε²}); 0]``.
    cov : ndarray, shape ``(2n + m, 2n + m)``
        Covariance of ``w`` given ``y_t`` (rank ``n + m``).

    Examples
    --------
    Scalar OU (``A = a``, ``D = 1``, ``ε = 1``): ``Var(y_h) = (1 − e^{−2ah})/(2a)``.

    >>> import numpy as np
    >>> from roughpaths.coloured_noise import ou_step_law
    >>> T, Q = ou_step_law([[2.0]], [[1.0]], 1.0, 0.3)
    >>> bool(np.isclose(Q[0, 0], (1 - np.exp(-1.2)) / 4))
    True
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    h = float(h)
    if not math.isfinite(h) or h <= 0:
        raise ValueError(f"h must be a finite step > 0, got {h!r}.")
    n, m = D.shape
    delta = h / eps ** 2
    Tm, Qf = _fast_law(A, D, delta)
    scale = np.concatenate([np.ones(n), np.full(n, eps ** 2), np.full(m, eps)])
    return Tm * scale[:, None], Qf * np.outer(scale, scale)


def _fast_law(A, D, delta):
    """Mean map and covariance of ``(ỹ_δ, J, ΔB̃)`` in fast time (``ε = 1`` units)."""
    n, m = D.shape
    k = 2 * n + m
    F = np.zeros((k, k))
    F[:n, :n] = -A
    F[n:2 * n, :n] = np.eye(n)
    G = np.zeros((k, m))
    G[:n] = D
    G[2 * n:] = np.eye(m)
    Phi, Q = _van_loan(F, G @ G.T, delta)
    return Phi[:, :n].copy(), Q


def _substep_factor(A, D, delta):
    """Transition ``Φ = e^{−Aδ}`` and a factor ``L`` with ``LLᵀ = Cov(ỹ_δ, ΔB̃)`` (fast units)."""
    n, m = D.shape
    Tm, Q = _fast_law(A, D, delta)
    idx = np.r_[0:n, 2 * n:2 * n + m]
    C = Q[np.ix_(idx, idx)]
    try:
        L = np.linalg.cholesky(C)
    except np.linalg.LinAlgError:  # rank-deficient D (m > rank): symmetric square root instead
        w, V = np.linalg.eigh(C)
        L = V * np.sqrt(np.clip(w, 0.0, None))
    return Tm[:n].copy(), L


# --------------------------------------------------------------------------- accuracy of the lift
def expected_area_rate(A, D, eps, window):
    r"""Exact ``E[XX^ε_{t,t+w}]/w`` of the true (continuous) ``B^ε`` under the stationary law.

    ``E[XX^ε_{t,t+w}] = w ΣA⁻ᵀ − ε² Σ A⁻ᵀA⁻ᵀ (I − e^{−Aᵀw/ε²})``; tends to ``ΣA⁻ᵀ`` as ``ε²/w → 0``.
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    Sigma = _lyapunov(A, D)
    AiT = np.linalg.inv(A).T
    w = float(window)
    return Sigma @ AiT - (eps ** 2 / w) * Sigma @ AiT @ AiT @ (np.eye(A.shape[0]) - sla.expm(-A.T * w / eps ** 2))


def lift_area_rate(A, D, substep, *, hermite: bool = True):
    r"""Exact stationary area rate ``lim E[XX_{0,T}]/T`` of the sub-stepped lift (ε-free).

    The lift samples ``B^ε`` exactly at sub-step nodes spaced ``δ`` apart in fast time
    (``δ = sub-step/ε²``) and fills each sub-step with the cubic Hermite interpolant
    (``hermite=True``) or the chord (``hermite=False``). Its long-run area rate (physical units,
    independent of ε) is, with ``E = e^{−Aᵀδ}``,

    ``ΣA⁻ᵀA⁻ᵀ(I − E)/δ`` (Chen cross terms) ``+ ½E[J Jᵀ]/δ`` (each sub-step's ``½ x⊗x``)
    ``+ E[Hermite Lévy area]/δ``,

    the latter from the stationary second moments of ``(ỹ_0, J, ỹ_δ)``. Compare with
    ``ΣA⁻ᵀ`` (:func:`coloured_noise_limit`) to get the lift's bias.

    Returns
    -------
    ndarray, shape ``(n, n)``
    """
    A, D = _check_AD(A, D)
    delta = float(substep)
    if not math.isfinite(delta) or delta <= 0:
        raise ValueError(f"substep must be > 0 (fast time units, sub-step / eps**2), got {substep!r}.")
    n = A.shape[0]
    Sigma = _lyapunov(A, D)
    AiT = np.linalg.inv(A).T
    E = sla.expm(-A.T * delta)
    rate = Sigma @ AiT @ AiT @ (np.eye(n) - E) / delta
    Tm, Q = _fast_law(A, D, delta)                                       # each sub-step's ½ x⊗x
    TJ = Tm[n:2 * n]
    rate = rate + 0.5 * (TJ @ Sigma @ TJ.T + Q[n:2 * n, n:2 * n]) / delta
    if hermite:
        Ai = np.linalg.inv(A)
        EJy0 = Ai @ (np.eye(n) - sla.expm(-A * delta)) @ Sigma          # E[J ỹ_0ᵀ]
        EJy1 = Sigma @ AiT @ (np.eye(n) - E)                             # E[J ỹ_δᵀ]
        Ey0y1 = Sigma @ E                                                # E[ỹ_0 ỹ_δᵀ]

        def wedge(C):                                                    # E[a∧b] from C = E[a bᵀ]
            return C - C.T

        lev = (_K_XU * delta * wedge(EJy0) + _K_XV * delta * wedge(EJy1)
               + _K_UV * delta ** 2 * wedge(Ey0y1))
        rate = rate + lev / delta
    return rate


# ------------------------------------------------------------------------------ numba kernel
@numba.njit(cache=True)
def _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc, area, ygrid, binc, barea):  # pragma: no cover
    """Advance ``y`` (P, n) over S coarse steps of ``msub`` sub-steps each (z: (P, S, msub, n+m))."""
    P, S, msub, k = z.shape
    n = y.shape[1]
    m = k - n
    w = np.empty(k)
    y1 = np.empty(n)
    x = np.empty(n)
    u = np.empty(n)
    v = np.empty(n)
    r = np.empty(n)
    X = np.empty(n)
    BX = np.empty(m)
    b = np.empty(m)
    for p in range(P):
        y0 = y[p].copy()
        for s in range(S):
            X[:] = 0.0
            BX[:] = 0.0
            for i in range(n):
                for j in range(n):
                    area[p, s, i, j] = 0.0
            for i in range(m):
                for j in range(m):
                    barea[p, s, i, j] = 0.0
            for q in range(msub):
                for i in range(k):
                    acc = 0.0
                    for j in range(k):
                        acc += L[i, j] * z[p, s, q, j]
                    w[i] = acc
                for i in range(n):
                    acc = w[i]
                    for j in range(n):
                        acc += Phi[i, j] * y0[j]
                    y1[i] = acc
                for i in range(m):
                    b[i] = w[n + i]
                for i in range(n):
                    acc = y0[i] - y1[i]
                    for j in range(m):
                        acc += D[i, j] * b[j]
                    r[i] = acc
                for i in range(n):
                    acc = 0.0
                    for j in range(n):
                        acc += Ainv[i, j] * r[j]
                    x[i] = eps * acc
                    u[i] = eps * delta * y0[i]
                    v[i] = eps * delta * y1[i]
                for i in range(n):
                    for j in range(n):
                        lev = (-0.1 * (x[i] * u[j] - u[i] * x[j]) + 0.1 * (x[i] * v[j] - v[i] * x[j])
                               - (1.0 / 60.0) * (u[i] * v[j] - v[i] * u[j]))
                        area[p, s, i, j] += 0.5 * x[i] * x[j] + lev + X[i] * x[j]
                for i in range(n):
                    X[i] += x[i]
                for i in range(m):
                    b[i] *= eps
                for i in range(m):
                    for j in range(m):
                        barea[p, s, i, j] += 0.5 * b[i] * b[j] + BX[i] * b[j]
                for i in range(m):
                    BX[i] += b[i]
                for i in range(n):
                    y0[i] = y1[i]
            for i in range(n):
                inc[p, s, i] = X[i]
                ygrid[p, s, i] = y0[i]
            for i in range(m):
                binc[p, s, i] = BX[i]
        for i in range(n):
            y[p, i] = y0[i]


def _path_major(z):
    """Normals are drawn time-major (chunk-independent stream); the kernel reads them path-major."""
    return np.ascontiguousarray(z.transpose(2, 0, 1, 3))


# ------------------------------------------------------------------------------- sampler
@dataclass
class ColouredNoiseSample:
    r"""One draw of the coloured noise on a grid, coupled with its Brownian motion.

    Attributes
    ----------
    path : RoughPath
        Level-2 geometric lift of ``B^ε = ∫ y/ε dt``, batch ``(...)``, dimension ``n``.
    y : ndarray, shape ``(..., N + 1, n)``
        The OU process on the grid.
    brownian : RoughPath
        The driving ``B`` (dimension ``m``) on the same grid, lifted by the piecewise-linear
        (Chen) lift over the sub-steps: its area is the conditional expectation of the
        Stratonovich area given the sub-step increments (variance deficit ``1/substeps`` per step).
    limit : ColouredNoiseLimit
    eps : float
    substeps : int
    """

    path: RoughPath
    y: np.ndarray
    brownian: RoughPath
    limit: ColouredNoiseLimit
    eps: float
    substeps: int

    def limit_path(self) -> RoughPath:
        """The coupled limit driver ``(MB, M BB Mᵀ + N dt)`` built from :attr:`brownian`."""
        return coloured_noise_limit_path(self.limit, self.brownian)


def _resolve_substeps(A, eps, h, substeps, max_substep):
    """Sub-steps per grid step; warn if the sub-step exceeds ``max_substep · ε²/‖A‖``."""
    nrm = float(np.linalg.norm(A, 2))
    if substeps is None:
        return max(1, int(math.ceil(h * nrm / (eps ** 2 * max_substep))))
    m = check_positive_int(substeps, "substeps")
    ratio = h / (m * eps ** 2)
    if ratio * nrm > max_substep * (1 + 1e-12):
        warnings.warn(
            f"the sub-step h/substeps = {h / m:.3g} does not resolve the noise correlation time "
            f"eps**2 = {eps ** 2:.3g}: (h/substeps)/eps**2 = {ratio:.3g} (times ||A|| = {ratio * nrm:.3g} "
            f"> max_substep = {max_substep}); the Lévy area of B^eps is biased (see lift_area_rate). "
            f"Use substeps >= {int(math.ceil(h * nrm / (eps ** 2 * max_substep)))} or substeps=None.",
            ResolutionWarning, stacklevel=3)
    return m


def sample_coloured_noise(A, D, eps, times, *, rng, batch_shape=(), y0="stationary", substeps=None,
                          max_substep: float = 0.5) -> ColouredNoiseSample:
    r"""Sample coloured noise exactly on a grid and lift ``B^ε = ∫ y/ε dt`` to a level-2 rough path.

    Parameters
    ----------
    A : array_like, shape ``(n, n)``
        Drift matrix (eigenvalues in the open right half-plane).
    D : array_like, shape ``(n, m)``
        Noise matrix (``Σ`` non-singular).
    eps : float
        Correlation parameter ``ε > 0`` (correlation time ``ε²/‖A‖``).
    times : array_like, shape ``(N + 1,)``
        Increasing grid.
    rng : numpy.random.Generator
    batch_shape : tuple of int
        Leading batch axes of the output.
    y0 : "stationary" or array_like ``(..., n)``
        Start: a draw from ``N(0, Σ)`` or a given value (broadcast to ``batch_shape``).
    substeps : int or None
        Exact sub-steps per grid step used for the area (module docstring). ``None`` picks the
        smallest number with sub-step ``≤ max_substep · ε²/‖A‖₂``; an explicit coarser choice
        emits a :class:`ResolutionWarning` with the ratio ``(h/substeps)/ε²``.
    max_substep : float
        Resolution target in units of ``ε²/‖A‖₂`` (default 0.5: Lévy-area rate bias below 5e-4 relative, see :func:`lift_area_rate`).

    Returns
    -------
    ColouredNoiseSample
        ``.path`` (the lift, kind ``"geometric"``), ``.y``, the coupled ``.brownian`` and ``.limit``.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths.coloured_noise import sample_coloured_noise
    >>> A = np.array([[1.0, 1.0], [-1.0, 1.0]])
    >>> s = sample_coloured_noise(A, np.eye(2), 0.1, np.linspace(0, 1, 11), rng=np.random.default_rng(0),
    ...                           batch_shape=(4,))
    >>> s.path.batch_shape, s.path.dim, s.path.kind, s.y.shape
    ((4,), 2, 'geometric', (4, 11, 2))
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    rng = check_rng(rng)
    t = check_times(times)
    lim = coloured_noise_limit(A, D)
    n, m = D.shape
    batch_shape = tuple(int(b) for b in np.atleast_1d(np.asarray(batch_shape, dtype=int))) if batch_shape != () else ()
    P = int(np.prod(batch_shape)) if batch_shape else 1
    N = t.size - 1
    dts = np.diff(t)
    uniform = np.allclose(dts, dts[0], rtol=1e-10, atol=0.0)
    if isinstance(y0, str):
        if y0 != "stationary":
            raise ValueError(f"y0 must be 'stationary' or an array of shape (..., {n}), got {y0!r}.")
        Ls = np.linalg.cholesky(lim.Sigma)
        ystart = rng.standard_normal((P, n)) @ Ls.T
    else:
        yv = as_float_array(y0, "y0", last_dims=(n,))
        try:
            ystart = np.broadcast_to(yv, batch_shape + (n,)).reshape(P, n).copy()
        except ValueError:
            raise ValueError(f"y0 of shape {yv.shape} does not broadcast to batch_shape + (n,) = "
                             f"{batch_shape + (n,)}.") from None
    hmax = float(np.max(dts))
    msub = _resolve_substeps(A, eps, hmax, substeps, max_substep)
    Ainv = np.linalg.inv(A)
    inc = np.empty((P, N, n))
    area = np.empty((P, N, n, n))
    ygrid = np.empty((P, N, n))
    binc = np.empty((P, N, m))
    barea = np.empty((P, N, m, m))
    y = ystart.copy()
    groups = [(0, N, dts[0])] if uniform else [(i, i + 1, dts[i]) for i in range(N)]
    cache = {}
    for lo, hi, h in groups:
        key = float(h)
        if key not in cache:
            cache[key] = _substep_factor(A, D, h / (msub * eps ** 2))
        Phi, L = cache[key]
        delta = h / (msub * eps ** 2)
        z = _path_major(rng.standard_normal((hi - lo, msub, P, n + m)))
        _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc[:, lo:hi], area[:, lo:hi], ygrid[:, lo:hi],
                        binc[:, lo:hi], barea[:, lo:hi])
    yall = np.concatenate([ystart[:, None, :], ygrid], axis=1)
    shp = batch_shape
    path = RoughPath(inc.reshape(shp + (N, n)), area.reshape(shp + (N, n, n)), times=t, kind="geometric",
                     check=False)
    bro = RoughPath(binc.reshape(shp + (N, m)), barea.reshape(shp + (N, m, m)), times=t, kind="geometric",
                    check=False)
    return ColouredNoiseSample(path=path, y=yall.reshape(shp + (N + 1, n)), brownian=bro, limit=lim,
                               eps=eps, substeps=msub)


def coloured_noise_limit_path(limit, brownian: RoughPath) -> RoughPath:
    r"""The limit driver ``(M B, M BB Mᵀ + N (t − s))`` in B^ε coordinates.

    Parameters
    ----------
    limit : ColouredNoiseLimit or tuple ``(A, D)``
    brownian : RoughPath
        A level-2 (Stratonovich, geometric) lift of an ``m``-dimensional Brownian motion, e.g.
        :attr:`ColouredNoiseSample.brownian` (coupled with a coloured sample) or any Brownian lift.

    Returns
    -------
    RoughPath
        Dimension ``n``, geometric: the scaled Brownian rough path perturbed by ``N``.
    """
    if not isinstance(limit, ColouredNoiseLimit):
        limit = coloured_noise_limit(*limit)
    if not isinstance(brownian, RoughPath):
        raise TypeError(f"brownian must be a RoughPath, got {type(brownian).__name__}.")
    M = limit.scaling
    if brownian.dim != M.shape[1]:
        raise ValueError(f"brownian has dimension {brownian.dim} but D has {M.shape[1]} columns; they "
                         f"must match.")
    if brownian.level != 2:
        raise ValueError("brownian must be a level-2 rough path (with its area); the limit's area "
                         "M BB M^T + N dt needs it.")
    inc = brownian.increments @ M.T
    area = M @ brownian.areas @ M.T
    base = RoughPath(inc, area, times=brownian.times, x0=brownian.x0 @ M.T, kind=brownian.kind, check=False)
    return base.perturb(limit.levy_perturbation)


def iter_coloured_noise(A, D, eps, h, n_steps, *, rng, n_paths=1, y0="stationary", substeps=None,
                        max_substep: float = 0.5, chunk_steps=None):
    r"""Stream the lift of ``B^ε`` (and of ``B``) in time chunks, in constant memory.

    Same law, sub-stepping and area construction as :func:`sample_coloured_noise` on the uniform
    grid ``h·(0, …, n_steps)``; random numbers are drawn in time-major order, so the output does
    not depend on ``chunk_steps`` (and equals :func:`sample_coloured_noise` with the same seed).

    Parameters
    ----------
    A, D, eps : as in :func:`sample_coloured_noise`
    h : float
        Grid step.
    n_steps : int
    rng : numpy.random.Generator
    n_paths : int
    y0 : "stationary" or array_like ``(n_paths, n)`` / ``(n,)``
    substeps, max_substep : as in :func:`sample_coloured_noise`
    chunk_steps : int, optional
        Grid steps per chunk (default: about 2·10⁶ random numbers per chunk).

    Yields
    ------
    inc : ndarray ``(n_paths, S, n)``
        Increments of ``B^ε``.
    area : ndarray ``(n_paths, S, n, n)``
        Step areas of ``B^ε`` (geometric).
    b_inc, b_area : ndarrays ``(n_paths, S, m)``, ``(n_paths, S, m, m)``
        The coupled Brownian ``B`` and its piecewise-linear (sub-step Chen) areas.
    y : ndarray ``(n_paths, S, n)``
        ``y`` at the end of each step.
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    rng = check_rng(rng)
    h = float(h)
    if not math.isfinite(h) or h <= 0:
        raise ValueError(f"h must be a finite step > 0, got {h!r}.")
    n_steps = check_positive_int(n_steps, "n_steps")
    P = check_positive_int(n_paths, "n_paths")
    lim = coloured_noise_limit(A, D)
    n, m = D.shape
    if isinstance(y0, str):
        if y0 != "stationary":
            raise ValueError(f"y0 must be 'stationary' or an array of shape (n_paths, {n}), got {y0!r}.")
        y = rng.standard_normal((P, n)) @ np.linalg.cholesky(lim.Sigma).T
    else:
        y = np.array(np.broadcast_to(as_float_array(y0, "y0", last_dims=(n,)), (P, n)))
    msub = _resolve_substeps(A, eps, h, substeps, max_substep)
    Phi, L = _substep_factor(A, D, h / (msub * eps ** 2))
    delta = h / (msub * eps ** 2)
    Ainv = np.linalg.inv(A)
    if chunk_steps is None:
        chunk_steps = max(1, int(2_000_000 // (P * msub * (n + m))))
    chunk_steps = check_positive_int(chunk_steps, "chunk_steps")
    done = 0
    while done < n_steps:
        S = min(chunk_steps, n_steps - done)
        z = _path_major(rng.standard_normal((S, msub, P, n + m)))
        inc = np.empty((P, S, n))
        area = np.empty((P, S, n, n))
        yg = np.empty((P, S, n))
        binc = np.empty((P, S, m))
        barea = np.empty((P, S, m, m))
        _ou_lift_kernel(y, z, Phi, L, Ainv, D, eps, delta, inc, area, yg, binc, barea)
        done += S
        yield inc, area, binc, barea, yg
