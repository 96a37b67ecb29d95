r"""The chord iteration of the implicit midpoint rule (numpy path), per batch member.

Solves :math:`F(\sigma) = \sigma - w(\tfrac12(\mu + e^{\mathrm{ad}^*_\sigma}\mu))\Delta t - \eta = 0` by
:math:`\sigma\leftarrow\sigma - J^{-1}F(\sigma)` with the Jacobian frozen at :math:`\mu`,
:math:`J = I - \tfrac{\Delta t}2 Dw(\mu) L(\mu)`, :math:`L(\mu)\delta = \mathrm{ad}^*_\delta\mu`. Each member
iterates until its own correction satisfies :math:`\max|\Delta\sigma|\le` ``tol`` :math:`(1 + |\sigma|_\infty)`
and is then frozen: its result is the one it has when solved alone, whatever the rest of the batch
does (no early exit on the first converged or failed member, no batch-wide stopping rule).
"""

from __future__ import annotations

import numpy as np


def chord_solve(system, mu, dt, eta, tol, max_iter):
    """Return ``(sigma (..., n), converged (...) bool)`` for states ``mu``, steps ``dt`` (a float, or ``(..., 1)``
    per member) and stochastic velocities ``eta``.

    ``mu`` and ``eta`` broadcast to a common batch; a member that does not converge within
    ``max_iter`` iterations (or becomes non-finite) gets ``converged = False`` and NaN ``sigma``.
    """
    mu, eta = np.broadcast_arrays(np.asarray(mu, dtype=np.float64), np.asarray(eta, dtype=np.float64))
    shape = mu.shape
    n = shape[-1]
    mu = mu.reshape(-1, n)
    eta = eta.reshape(-1, n)
    member_dt = np.ndim(dt) > 0                 # dt (..., 1) per member, else one float
    if member_dt:
        dt = np.broadcast_to(np.asarray(dt, dtype=np.float64), shape[:-1] + (1,)).reshape(-1, 1)
    alg = system.algebra
    w0 = system.drift_velocity(mu)
    jac = np.eye(n) - 0.5 * (dt[..., None] if member_dt else dt) * (
        system.drift_velocity_jacobian(mu) @ alg.coadjoint_orbit_tangent(mu))
    jinv = _member_inverses(jac)
    sigma = w0 * dt + eta
    done = np.zeros(mu.shape[0], dtype=bool)
    ok = np.zeros(mu.shape[0], dtype=bool)
    active = np.flatnonzero(np.all(np.isfinite(jinv), axis=(-2, -1)))     # a singular Jacobian fails alone
    for _ in range(max_iter):
        if active.size == 0:
            break
        mu_a, s_a = mu[active], sigma[active]
        with np.errstate(all="ignore"):
            mu1 = alg.Ad_star_exp(s_a, mu_a)
        fin = np.all(np.isfinite(mu1), axis=-1)
        if not np.all(fin):                      # overflowed members fail; the others go on alone
            done[active[~fin]] = True
            active, mu_a, s_a, mu1 = active[fin], mu_a[fin], s_a[fin], mu1[fin]
            if active.size == 0:
                break
        with np.errstate(all="ignore"):
            resid = s_a - system.drift_velocity(0.5 * (mu_a + mu1)) * (dt[active] if member_dt else dt) - eta[active]
            delta = (jinv[active] @ resid[..., None])[..., 0]
            s_a = s_a - delta
        sigma[active] = s_a
        err = np.max(np.abs(delta), axis=-1)
        finite = np.isfinite(err) & np.all(np.isfinite(s_a), axis=-1)
        conv = finite & (err <= tol * (1.0 + np.max(np.abs(s_a), axis=-1)))
        ok[active[conv]] = True
        stop = conv | ~finite
        done[active[stop]] = True
        active = active[~stop]
    sigma[~ok] = np.nan
    return sigma.reshape(shape), ok.reshape(shape[:-1])


def _member_inverses(jac):
    """Inverses of a stack ``(B, n, n)``; a non-finite or singular member gets NaN, alone.

    ``numpy.linalg.inv`` raises for the whole stack when one member is singular; then the members
    are inverted one by one (each as a stack of one, the same LAPACK call a solo solve makes).
    """
    out = np.full(jac.shape, np.nan)
    good = np.flatnonzero(np.all(np.isfinite(jac), axis=(-2, -1)))
    if good.size == 0:
        return out
    try:
        with np.errstate(all="ignore"):
            out[good] = np.linalg.inv(jac[good])
    except np.linalg.LinAlgError:
        for i in good:
            try:
                with np.errstate(all="ignore"):
                    out[i] = np.linalg.inv(jac[i:i + 1])[0]
            except np.linalg.LinAlgError:
                pass
    return out
