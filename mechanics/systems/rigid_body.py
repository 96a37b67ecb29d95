r"""The stochastic rigid body on so(3)* ≅ R³ (body angular momentum :math:`\Pi`).

Rough-path-correct equation (``docs/conventions.md``), with :math:`W = \mathbb I^{-1}\Pi + c`:

.. math::

    d\Pi = \Pi\times W\,dt + \vartheta\,\Pi\times(\Pi\times W)\,dt + \sum_i \Pi\times\xi_i\circ dX^i,
    \qquad c = +\tfrac12\sum_{i,j}\mathsf s^{ij}\,\xi_i\times\xi_j .

For isotropic noise :math:`\xi_i = \sigma e_i`, :math:`c = \sigma^2(\mathsf s^{23}, -\mathsf s^{13},
\mathsf s^{12})`. The modified Hamiltonian is :math:`\tilde h = \tfrac12\Pi\cdot\mathbb I^{-1}\Pi +
c\cdot\Pi` and :math:`|\Pi|` is the Casimir. ``convention="paper"`` uses :math:`-c` (the printed
(srblevy)).

``levy_in_dissipation=False`` keeps the torque in the conservative term only,
:math:`d\Pi = \Pi\times W\,dt + \vartheta\,\Pi\times(\Pi\times\mathbb I^{-1}\Pi)\,dt + \sum_i
\Pi\times\xi_i\circ dX^i`: the body with ``s = 0`` driven by ``X.perturb(s)`` (e.g. the white-noise
limit of the coloured-noise body, :mod:`mechanics.limits.wong_zakai`), not Theorem 3.1's model.
"""

from __future__ import annotations

import numpy as np

from roughpaths.validation import as_float_array, check_memory, check_positive_int, check_positive_real

from .lie_algebra import so3
from .hamiltonian import QuadraticHamiltonian, check_inertia
from .lie_poisson import LiePoissonSystem

__all__ = ["RigidBody", "rigid_body", "isotropic_xi"]


def isotropic_xi(sigma, dim: int = 3) -> np.ndarray:
    r"""Isotropic SALT noise :math:`\xi_i = \sigma e_i`, shape ``(dim, dim)``."""
    sigma = check_positive_real(sigma, "sigma", allow_zero=True)
    dim = check_positive_int(dim, "dim")
    check_memory(8.0 * dim * dim, f"the noise vectors (dim={dim} x dim)", "use a smaller dim")
    return sigma * np.eye(dim)


def _noise_vectors(xi, sigma, dim):
    if xi is not None and sigma is not None:
        raise ValueError("pass either xi (the noise vectors, shape (m, 3)) or sigma (isotropic xi_i = "
                         "sigma e_i), not both.")
    if xi is None:
        return isotropic_xi(0.0 if sigma is None else sigma, dim)
    return xi


class RigidBody(LiePoissonSystem):
    """A :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` on so(3) with :math:`h = \\tfrac12\\Pi\\cdot\\mathbb I^{-1}\\Pi`."""

    def __init__(self, inertia, xi=None, s=None, theta=0.0, convention="rp", *, metric=None,
                 levy_in_dissipation=True):
        inertia = check_inertia(inertia, "inertia", dim=3)
        xi = as_float_array(xi, "xi")
        if xi.ndim != 2 or xi.shape[1] != 3:
            raise ValueError(f"xi must have shape (m, 3): one so(3) ≅ R³ noise vector per row, got shape "
                             f"{xi.shape}.")
        super().__init__(so3(), QuadraticHamiltonian.from_inertia(inertia), xi, s=s, theta=theta,
                         convention=convention, metric=metric, levy_in_dissipation=levy_in_dissipation)
        self.inertia = inertia
        self.inertia.setflags(write=False)

    def angular_velocity(self, Pi) -> np.ndarray:  # noqa: N803
        r""":math:`\Omega = \mathbb I^{-1}\Pi`, shape ``(..., 3)``."""
        return self.hamiltonian.gradient(self._mu(Pi))

    def modified_energy(self, Pi) -> np.ndarray:  # noqa: N803
        r""":math:`\tilde h = \tfrac12\Pi\cdot\mathbb I^{-1}\Pi + c\cdot\Pi` (``-c`` for "paper")."""
        return self.modified_hamiltonian(Pi)


def rigid_body(inertia, xi=None, sigma=None, s=None, theta=0.0, convention="rp", *, metric=None,
               levy_in_dissipation=True) -> RigidBody:
    r"""The stochastic rigid body with SALT noise, Lévy-area perturbation ``s`` and dissipation ``theta``.

    Parameters
    ----------
    inertia : array_like, ``(3,)`` principal moments or ``(3, 3)`` symmetric positive definite
    xi : array_like ``(m, 3)``, optional
        Noise vectors; or give ``sigma`` for isotropic :math:`\xi_i = \sigma e_i` (``m = 3``).
        With neither the body is deterministic (``xi = 0``).
    s : array_like ``(m, m)``, antisymmetric, optional
    theta : float >= 0
    convention : {"rp", "paper"}
    levy_in_dissipation : bool
        ``True`` (default): the torque ``c`` in both terms (``W`` in the double bracket: Theorem 3.1,
        Gibbs density ``∝ exp(-2θh̃/σ²)``). ``False``: ``c`` in the conservative term only, the double
        bracket built from ``h`` (``I⁻¹Π``) — exactly the ``s = 0`` body driven by ``X.perturb(s)``.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.zeros((3, 3)); s[0, 2], s[2, 0] = 25.0, -25.0
    >>> rb = rigid_body([1.0, 2.0, 3.0], sigma=0.05, s=s, theta=1.0)
    >>> rb.levy_velocity               # c = σ² (s23, -s13, s12)
    array([ 0.    , -0.0625,  0.    ])
    >>> float(rb.modified_energy([0.0, 0.0, 1.0]))
    0.16666666666666666
    """
    return RigidBody(inertia, _noise_vectors(xi, sigma, 3), s=s, theta=theta, convention=convention,
                     metric=metric, levy_in_dissipation=levy_in_dissipation)
