r"""The law of coloured (Ornstein–Uhlenbeck) noise: its exact white-noise limit and exact transitions.

The process (paper, Section 4.2 and appendix "Coloured noise as a rough path")

.. math::

    dy = -\varepsilon^{-2} A\, y\, dt + \varepsilon^{-1} D\, dB, \qquad
    B^\varepsilon_t = \int_0^t \frac{y_r}{\varepsilon}\, dr,

with ``A`` (n×n) whose eigenvalues have positive real part and ``D`` (n×m), ``B`` an m-dimensional
Brownian motion. ``y`` has the ε-independent stationary covariance ``Σ``, ``AΣ + ΣAᵀ = DDᵀ``.
The sampler and the driver built on this law are in :mod:`roughpaths.drivers.coloured_noise`.

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


Hermite area of a sub-step (used by the sampler, whose accuracy :func:`lift_area_rate` states):
with ``a ∧ b = a⊗b − b⊗a``, ``x`` the increment, ``u = εδỹ_0``, ``v = εδỹ_δ``, the cubic Hermite
interpolant has Lévy area ``−x∧u/10 + x∧v/10 − u∧v/60``.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ..validation import as_float_array, check_positive_real

__all__ = [
    "ColouredNoiseLimit",
    "coloured_noise_limit",
    "paper_coloured_noise_matrices",
    "ou_step_law",
    "lift_area_rate",
    "expected_area_rate",
]

# Hermite Lévy-area coefficients (see the module docstring).
_K_XU, _K_XV, _K_UV = -0.1, 0.1, -1.0 / 60.0


# ---------------------------------------------------------------------------------------- checks

def _sla():
    """scipy.linalg, imported on first use (keeps ``import roughpaths`` light)."""
    import scipy.linalg

    return scipy.linalg

def _check_eps(eps) -> float:
    if isinstance(eps, (bool, np.bool_)) or not isinstance(eps, numbers.Real):
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
    Sigma = _sla().solve_continuous_lyapunov(A, D @ D.T)
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

    >>> from roughpaths import coloured_noise_limit, paper_coloured_noise_matrices
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
    E = _sla().expm(C * d0)
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
    >>> from roughpaths import ou_step_law
    >>> T, Q = ou_step_law([[2.0]], [[1.0]], 1.0, 0.3)
    >>> bool(np.isclose(Q[0, 0], (1 - np.exp(-1.2)) / 4))
    True
    """
    A, D = _check_AD(A, D)
    eps = _check_eps(eps)
    h = check_positive_real(h, "h")
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
    w = check_positive_real(window, "window")
    return Sigma @ AiT - (eps ** 2 / w) * Sigma @ AiT @ AiT @ (np.eye(A.shape[0]) - _sla().expm(-A.T * w / eps ** 2))


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
    delta = check_positive_real(substep, "substep")
    if not math.isfinite(delta) or delta <= 0:
        raise ValueError(f"substep must be > 0 (fast time units, sub-step / eps**2), got {substep!r}.")
    n = A.shape[0]
    Sigma = _lyapunov(A, D)
    AiT = np.linalg.inv(A).T
    E = _sla().expm(-A.T * delta)
    rate = Sigma @ AiT @ AiT @ (np.eye(n) - E) / delta
    Tm, Q = _fast_law(A, D, delta)                                       # each sub-step's ½ x⊗x
    TJ = Tm[n:2 * n]
    rate = rate + 0.5 * (TJ @ Sigma @ TJ.T + Q[n:2 * n, n:2 * n]) / delta
    if hermite:
        Ai = np.linalg.inv(A)
        EJy0 = Ai @ (np.eye(n) - _sla().expm(-A * delta)) @ Sigma          # E[J ỹ_0ᵀ]
        EJy1 = Sigma @ AiT @ (np.eye(n) - E)                             # E[J ỹ_δᵀ]
        Ey0y1 = Sigma @ E                                                # E[ỹ_0 ỹ_δᵀ]

        def wedge(C):                                                    # E[a∧b] from C = E[a bᵀ]
            return C - C.T

        lev = (_K_XU * delta * wedge(EJy0) + _K_XV * delta * wedge(EJy1)
               + _K_UV * delta ** 2 * wedge(Ey0y1))
        rate = rate + lev / delta
    return rate
