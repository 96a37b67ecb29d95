r"""The modified (Lévy-area-shifted) rigid body on so(3)* ≅ R³: ``h̃``, its shift ``c`` and its vector field.

The deterministic part of the rough-path-correct (RP) rigid body of ``docs/conventions.md`` is

.. math::

    \dot\Pi = \Pi\times W + \vartheta\,\Pi\times(\Pi\times W), \qquad
    W = \nabla\tilde h(\Pi) = \mathbb I^{-1}\Pi + c, \qquad
    \tilde h(\Pi) = \tfrac12\,\Pi\cdot\mathbb I^{-1}\Pi + c\cdot\Pi,

with ``c = +½ Σ_ij s^{ij} ξ_i × ξ_j`` (for isotropic noise ``ξ_i = σ e_i``:
``c = σ² (s23, -s13, s12)``; the paper's printed ``-½`` flips it, see :func:`isotropic_levy_shift`).
Both terms are tangent to the sphere ``|Π| = r`` (a Casimir); the second one is
``-ϑ r² P_T ∇h̃``, the gradient descent of ``h̃`` on the sphere, so with ``ϑ > 0`` the flow is
attracted to the local minima of ``h̃`` on the sphere. This module is the one definition of ``h̃``
used by :mod:`~mechanics.analysis.equilibria`, :mod:`~mechanics.analysis.phase_portrait` and
:mod:`~mechanics.analysis.gibbs` (a system's own ``h̃`` is
:meth:`~mechanics.systems.lie_poisson.LiePoissonSystem.modified_hamiltonian`).
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array, check_antisymmetric

from ..systems.hamiltonian import check_inertia
from ..systems.lie_poisson import levy_velocity
from ._inputs import _as_c, _check_theta

__all__ = ["as_inverse_inertia", "isotropic_levy_shift", "modified_hamiltonian", "rigid_body_vector_field"]


def as_inverse_inertia(inertia, name: str = "inertia") -> np.ndarray:
    """Return ``𝕀⁻¹`` (3×3) from an inertia given as 3 principal moments or a 3×3 SPD matrix.

    Raises ``ValueError`` for non-symmetric, non-positive-definite or wrongly shaped input.
    """
    return np.linalg.inv(check_inertia(inertia, name, dim=3))


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
    c = levy_velocity(s, sig * np.eye(3))
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
    return _modified_hamiltonian(P, A, c)


def _modified_hamiltonian(P, A, c):
    """The one formula for ``h̃ = ½ Π·AΠ + c·Π`` on so(3)* (``A = 𝕀⁻¹``): every ``h̃`` of this subpackage
    (equilibrium energies, phase-portrait levels, the Gibbs density) is computed here."""
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
