r"""Forces of a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` (Section 2.2, rough Lagrange–d'Alembert).

``force`` :math:`F^0(\mu)` is added to the drift and ``noise_forces`` :math:`F^i(\mu)` to the driving fields
:math:`\mathrm{ad}^*_{\xi_i}\mu`. This mixin holds the callables, checks their shapes, and evaluates them and
their Jacobians (central differences when no Jacobian is given). The model solved everywhere
(coadjoint solvers, and ``solve`` with ``system.vector_fields()``):

.. math::

    d\mu = \big(\mathrm{ad}^*_{w(\mu)}\mu + F^0(\mu)\big)\,dt
          + \sum_i\big(\mathrm{ad}^*_{\xi_i}\mu + F^i(\mu)\big)\,d\mathbf X^i ,

driven by :math:`\mathbf X` (not perturbed). This is the paper's eq. (forcedeulerpoincare) in the
library's signs: the paper writes the forces on the left-hand side (:math:`F_{\rm paper} = -F`) with
the opposite ``ad*``, and its Lévy term with the printed sign slip; here the Lévy term is
:math:`\mathrm{ad}^*_\ell\mu` inside :math:`w`. The Lévy term comes from the action and involves the
:math:`\xi_i` only. Driving the *uncorrected* forced system by :math:`\tilde{\mathbf X}` = ``X.perturb(s)``
is a different equation when some :math:`F^i\ne0`: its Friz–Oberhauser drift
:math:`\tfrac12\mathsf s^{ij}[V_i, V_j]` of the full fields :math:`V_i = \mathrm{ad}^*_{\xi_i} + F^i` also
contains the brackets of the :math:`F^i` (``docs/conventions.md``, "Forces"). Casimirs are conserved by
the exact flow only when every force is tangent to the coadjoint orbits (e.g. :math:`F = \mathrm{ad}^*_{\eta(\mu)}\mu`);
a force that is not moves the solution across orbits. The double-bracket term is the special case
:math:`F^0 = \vartheta\,\mathrm{ad}^*_{(\mathrm{ad}^*_{\nabla\tilde h}\mu)^\sharp}\mu` (but ``theta`` is
treated inside the coadjoint group update, a ``force`` outside it: :mod:`mechanics.integrators`).
"""

from __future__ import annotations

import numpy as np

import roughpaths

__all__ = ["ForcesMixin"]


class ForcesMixin:
    """Force bookkeeping shared by :class:`~mechanics.systems.lie_poisson.LiePoissonSystem`."""

    def _set_forces(self, force, noise_forces, force_jacobian, noise_forces_jacobian):
        n, m = self.dim, self.n_noise
        for name, f in (("force", force), ("noise_forces", noise_forces), ("force_jacobian", force_jacobian),
                        ("noise_forces_jacobian", noise_forces_jacobian)):
            if f is not None and not callable(f):
                raise TypeError(f"{name} must be a callable of mu (..., {n}) or None, got {type(f).__name__}.")
        if force is None and force_jacobian is not None:
            raise TypeError("force_jacobian given without force.")
        if noise_forces is None and noise_forces_jacobian is not None:
            raise TypeError("noise_forces_jacobian given without noise_forces.")
        self.force, self.noise_forces = force, noise_forces
        self.force_jacobian, self.noise_forces_jacobian = force_jacobian, noise_forces_jacobian
        probe = np.random.default_rng(0).standard_normal((2, n))
        for name, f, shape in (("force", force, (2, n)), ("noise_forces", noise_forces, (2, n, m)),
                               ("force_jacobian", force_jacobian, (2, n, n)),
                               ("noise_forces_jacobian", noise_forces_jacobian, (2, n, m, n))):
            if f is not None:
                got = np.shape(f(probe))
                if got != shape:
                    raise ValueError(f"{name}(mu) must have shape (..., {', '.join(map(str, shape[1:]))}) for mu of "
                                     f"shape (..., {n}) ({m} noises); on mu of shape {probe.shape} it returned {got}.")

    @property
    def has_forces(self) -> bool:
        """Whether a ``force`` or ``noise_forces`` is set (the coadjoint solvers then take their numpy path)."""
        return self.force is not None or self.noise_forces is not None

    def _f0(self, mu):
        return np.asarray(self.force(mu), dtype=np.float64)

    def _f0_jacobian(self, mu):
        if self.force_jacobian is not None:
            return np.asarray(self.force_jacobian(mu), dtype=np.float64)
        return roughpaths.central_jacobian(self.force, mu)

    def _fi(self, mu):
        return np.asarray(self.noise_forces(mu), dtype=np.float64)

    def _fi_jacobian(self, mu):
        """``[..., a, i, b] = ∂F^i_a/∂μ_b``."""
        if self.noise_forces_jacobian is not None:
            return np.asarray(self.noise_forces_jacobian(mu), dtype=np.float64)
        return roughpaths.central_jacobian(self.noise_forces, mu)

    def forces(self, mu) -> np.ndarray:
        r""":math:`F^0(\mu)`, shape ``(..., n)`` (zero without ``force``)."""
        mu = self._mu(mu)
        return self._f0(mu) if self.force is not None else np.zeros(mu.shape)

    def noise_force_fields(self, mu) -> np.ndarray:
        r""":math:`(F^1,\dots,F^m)(\mu)` as columns, shape ``(..., n, m)`` (zero without ``noise_forces``)."""
        mu = self._mu(mu)
        return self._fi(mu) if self.noise_forces is not None else np.zeros(mu.shape + (self.n_noise,))

    def _noise_jacobians_rp(self, mu):
        """:meth:`noise_jacobian` in the layout of ``roughpaths.VectorFields``: ``[..., i, a, b]``."""
        return np.moveaxis(self.noise_jacobian(mu), -2, -3)
