r"""The coadjoint schemes with forces (numpy path; the compiled kernels serve systems without forces).

For a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` with ``force`` :math:`F^0` and/or
``noise_forces`` :math:`F^i`, a step is the solver's own group update plus an additive correction
outside it,

.. math::  \mu_{n+1} = e^{\mathrm{ad}^*_{\sigma}}\mu_n + \Delta^0_n + \Delta^F_n ,

where :math:`\sigma` is the solver's Lie-algebra increment (area term and ``theta`` inside, as without
forces) and

.. math::

    \Delta^F_n = F^i(\mu_n) X^i + \big(\mathrm{ad}^*_{\xi_j}F^i + DF^j\cdot(\mathrm{ad}^*_{\xi_i}\mu + F^i)\big)(\mu_n)\,\mathbb X^{ij}

is what Davie's term :math:`DV_j\cdot V_i\,\mathbb X^{ij}` of the full fields
:math:`V_i = \mathrm{ad}^*_{\xi_i} + F^i` adds to the :math:`B_jB_i\mu\,\mathbb X^{ij}` already in
:math:`e^{\mathrm{ad}^*_\sigma}\mu` (a level-1 driver: :math:`\mathbb X = \tfrac12 X\otimes X`). The drift force:

* :class:`~mechanics.integrators.LieEuler`, :class:`~mechanics.integrators.ImplicitMidpoint`:
  :math:`\Delta^0_n = F^0(\mu_n)\Delta t` (explicit Euler; the chord iteration of the midpoint rule does not
  see the force);
* :class:`~mechanics.integrators.LieHeun`: a Heun correction carried by the flow,
  :math:`\Delta^0_n = \tfrac12\big(e^{\mathrm{ad}^*_{\bar\sigma}}F^0(\mu_n) + F^0(\mu^*)\big)\Delta t`, with the
  predictor :math:`\mu^*` = LieHeun's (second-order Taylor of the exponential) plus :math:`F^0(\mu_n)\Delta t + \Delta^F_n`, and :math:`\bar\sigma = \tfrac12(w(\mu_n) + w(\mu^*))\Delta t + \eta_n`.
  Transporting :math:`F^0(\mu_n)` by :math:`e^{\mathrm{ad}^*_{\bar\sigma}}` supplies the
  :math:`\tfrac12\mathrm{ad}^*_w F^0\,\Delta t^2` term that an untransported sum would miss.

Orders (measured in ``tests/mechanics/systems/test_forced_euler_poincare.py``): strong order 1 on Brownian
rough paths with the Lévy area for all three (the scheme is Davie's to :math:`O(h^{3/2})`); on smooth
drivers order 2 for LieHeun with ``force`` alone, and order 1 otherwise (LieEuler, ImplicitMidpoint, and any
scheme with ``noise_forces``: :math:`\Delta^F` is a Davie term frozen at :math:`\mu_n`). Casimirs: the group part keeps
the orbit, the additive part does not, so with forces the Casimirs are conserved only to the scheme's
order, and only when the forces are tangent to the orbits (a ``theta`` term stays inside the group
update and is conserved to round-off).
"""

from __future__ import annotations

import numpy as np


def noise_force_increment(system, mu, dx, dxx):
    r""":math:`\Delta^F` above, shape ``(..., n)`` (zero without ``noise_forces``)."""
    if system.noise_forces is None:
        return 0.0
    f = system._fi(mu)                                                  # (..., n, m): F^i
    jf = system._fi_jacobian(mu)                                        # (..., n, m, n): ∂_b F^i_a
    v = system.noise(mu)                                                # (..., n, m): B_i μ + F^i
    if dxx is None:
        dxx = 0.5 * dx[..., :, None] * dx[..., None, :]
    b = system.noise_matrices                                           # (m, n, n)
    out = np.einsum("...ai,...i->...a", f, dx)
    out = out + np.einsum("jab,...bi,...ij->...a", b, f, dxx)           # ad*_{ξ_j} F^i XX^{ij}
    out = out + np.einsum("...ajb,...bi,...ij->...a", jf, v, dxx)       # DF^j·V_i XX^{ij}
    return out


def _f0(system, mu):
    return system._f0(mu) if system.force is not None else 0.0


def forced_sigma_and_state(solver_code, system, mu, dt, eta, dx, dxx, sigma_fn):
    """One forced step on live members: ``(new mu, converged mask or None)``."""
    alg = system.algebra
    dnoise = noise_force_increment(system, mu, dx, dxx)
    f0 = _f0(system, mu)
    if solver_code == 1:                                                # LieHeun
        w0 = system.drift_velocity(mu)
        sig0 = w0 * dt + eta
        a = alg.ad_star(sig0, mu)
        pred = mu + a + 0.5 * alg.ad_star(sig0, a) + f0 * dt + dnoise    # LieHeun's predictor + the forces
        fin = np.all(np.isfinite(pred), axis=-1, keepdims=True)
        pred = np.where(fin, pred, 0.0)
        sigma = 0.5 * (w0 + system.drift_velocity(pred)) * dt + eta
        sigma = np.where(fin, sigma, np.nan)
        carried = mu + 0.5 * dt * f0 if system.force is not None else mu
        new = alg.Ad_star_exp(sigma, carried) + 0.5 * dt * _f0(system, pred) + dnoise
        return new, None
    sigma, conv = sigma_fn(system, mu, dt, eta)
    return alg.Ad_star_exp(sigma, mu) + f0 * dt + dnoise, conv
