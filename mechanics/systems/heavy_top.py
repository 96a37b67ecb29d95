r"""The stochastic heavy top: Lie–Poisson on se(3)* with :math:`\mu = (\Pi, \Gamma)`.

:math:`h = \tfrac12\Pi\cdot\mathbb I^{-1}\Pi + \chi\cdot\Gamma`, so :math:`\nabla h = (\Omega, \chi)` and
(``ad*`` of :func:`mechanics.systems.lie_algebra.se3`) the rough-path-correct equations are

.. math::

    d\Pi &= \Pi\times W\,dt + \Gamma\times\chi\,dt + \sum_i\Pi\times\xi_i\circ dX^i\ (+\text{dissipation}),\\
    d\Gamma &= \Gamma\times W\,dt + \sum_i\Gamma\times\xi_i\circ dX^i,\qquad W = \Omega + c,

with :math:`c = \tfrac12\mathsf s^{ij}\xi_i\times\xi_j` for noise in the so(3) part. The gravity term is
:math:`\Gamma\times\chi` (``docs/conventions.md``); the paper's (heavytoplevy) prints :math:`+\chi\times\gamma`,
which does not conserve :math:`h` — ``convention="paper"`` reproduces it (it is the flow of
:math:`\tfrac12\Pi\cdot\mathbb I^{-1}\Pi - \chi\cdot\Gamma`) together with the flipped Lévy torque.
Casimirs :math:`|\Gamma|^2` and :math:`\Pi\cdot\Gamma` are conserved in both conventions.
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array

from .lie_algebra import se3
from .hamiltonian import QuadraticHamiltonian, check_inertia
from .lie_poisson import LiePoissonSystem
from .rigid_body import _noise_vectors

__all__ = ["HeavyTop", "heavy_top"]


class HeavyTop(LiePoissonSystem):
    """A :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` on se(3)* (state ``(..., 6) = (Pi, Gamma)``)."""

    def __init__(self, inertia, chi, xi, s=None, theta=0.0, convention="rp", *, metric=None,
                 levy_in_dissipation=True):
        inertia = check_inertia(inertia, "inertia", dim=3)
        chi = as_float_array(chi, "chi", ndim=1)
        if chi.shape != (3,):
            raise ValueError(f"chi must be a 3-vector (pivot to centre of mass, times m g), got shape {chi.shape}.")
        xi = as_float_array(xi, "xi")
        if xi.ndim != 2 or xi.shape[1] not in (3, 6):
            raise ValueError(f"xi must have shape (m, 3) (noise in the so(3) part) or (m, 6) (full se(3) "
                             f"noise vectors), got shape {xi.shape}.")
        if xi.shape[1] == 3:
            xi = np.concatenate([xi, np.zeros_like(xi)], axis=1)
        q = np.zeros((6, 6))
        q[:3, :3] = np.linalg.inv(inertia)
        sign = 1.0 if convention == "rp" else -1.0
        lin = np.concatenate([np.zeros(3), sign * chi])
        super().__init__(se3(), QuadraticHamiltonian(q, lin), xi, s=s, theta=theta, convention=convention,
                         metric=metric, levy_in_dissipation=levy_in_dissipation)
        self.inertia, self.chi = inertia, chi
        self._q, self._chi_lin = q, np.concatenate([np.zeros(3), chi])

    def energy(self, mu) -> np.ndarray:
        r""":math:`h = \tfrac12\Pi\cdot\mathbb I^{-1}\Pi + \chi\cdot\Gamma` (the physical energy, both conventions)."""
        mu = self._mu(mu)
        return 0.5 * np.einsum("...i,ij,...j->...", mu, self._q, mu) + mu @ self._chi_lin

    def modified_energy(self, mu) -> np.ndarray:
        r""":math:`\tilde h = h + \langle\mu, \ell\rangle` (``- ⟨μ, ℓ⟩`` for "paper")."""
        return self.energy(mu) + self._mu(mu) @ self.torque_velocity


def heavy_top(inertia, chi, xi=None, sigma=None, s=None, theta=0.0, convention="rp", *, metric=None,
              levy_in_dissipation=True) -> HeavyTop:
    r"""The stochastic heavy top on se(3)*.

    Parameters
    ----------
    inertia : array_like ``(3,)`` or ``(3, 3)``, symmetric positive definite
    chi : array_like ``(3,)``
    xi : array_like ``(m, 3)`` or ``(m, 6)``, optional; or ``sigma`` for :math:`\xi_i = (\sigma e_i, 0)`
    s : array_like ``(m, m)`` antisymmetric, optional
    theta : float >= 0
    convention : {"rp", "paper"}
    levy_in_dissipation : bool
        Where the Lévy-area velocity enters (see :class:`~mechanics.systems.lie_poisson.LiePoissonSystem`):
        ``True`` (default) in the Hamiltonian of both the conservative and the double-bracket term;
        ``False`` in the conservative term only (the exact form of driving by ``X.perturb(s)``).

    Examples
    --------
    >>> import numpy as np
    >>> top = heavy_top([1.0, 2.0, 3.0], chi=[0.0, 0.0, 1.0])
    >>> mu = np.array([0.1, 0.2, 0.3, 0.0, 0.6, 0.8])
    >>> top.drift(mu)[:3] - (np.cross(mu[:3], mu[:3] / [1, 2, 3]) + np.cross(mu[3:], [0, 0, 1.0]))
    array([0., 0., 0.])
    """
    return HeavyTop(inertia, chi, _noise_vectors(xi, sigma, 3), s=s, theta=theta, convention=convention,
                    metric=metric, levy_in_dissipation=levy_in_dissipation)
