r"""Reconstruction: the group element along a coadjoint solution, from the same steps.

The reduced solution :math:`\mu(t)` of a Lie–Poisson RDE is the coadjoint image of a conserved spatial
momentum, :math:`\mu(t) = \mathrm{Ad}^*_{g(t)}m`, along the group path solving the reconstruction equation

.. math::  dg = g\,w(\mu)\,dt + \sum_i g\,\xi_i\circ dX^i

(``docs/conventions.md``: :math:`\mathrm{Ad}^*_g = \mathrm{Ad}_g^T` on coordinates, so that
:math:`\exp(\mathrm{ad}^*_\sigma) = \mathrm{Ad}^*_{\exp\sigma}`; for the rigid body :math:`g = R` the attitude,
:math:`\dot R = R\,\hat\Omega`, and :math:`m = R\Pi` the spatial angular momentum). The coadjoint schemes
update :math:`\mu_{n+1} = \exp(\mathrm{ad}^*_{\sigma_n})\mu_n`; the same increment gives

.. math::  g_{n+1} = g_n\exp(\sigma_n),\qquad\text{so}\qquad \mathrm{Ad}^*_{g_{n+1}}{}^{-1}\mu_{n+1} =
           \mathrm{Ad}^*_{g_n}{}^{-1}\mu_n = m

exactly (the discrete Noether theorem: the scheme conserves the spatial momentum, not only the Casimirs), and
:math:`g_n` stays on the group to round-off (a product of exponentials of algebra elements: orthogonal or
unitary for so(n), su(N), u(N) and so(3)). The order of :math:`g` is the scheme's (strong order 1 with the
Lévy areas: :math:`\sigma_n` carries :math:`\tfrac12A^{ij}[\xi_i, \xi_j]`).

What it costs: :func:`solve_with_group` steps the scheme in numpy (the solver's own increment
``σ_n``, the same code as the solvers' numpy path), one matrix exponential per member and step for ``g``;
the reduced states agree with :func:`roughpaths.solve`'s to round-off (its compiled kernels sum in another order).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from roughpaths import Driver, RoughPath, expm_batched
from roughpaths.validation import as_float_array, check_memory

from ..systems.lie_poisson import LiePoissonSystem
from ..systems.matrix_algebra import MatrixLieAlgebra
from .base import CoadjointSolver

__all__ = ["GroupSolution", "solve_with_group"]


@dataclass(frozen=True)
class GroupSolution:
    r"""The reduced states and the group path at every grid time.

    Attributes
    ----------
    times : ndarray ``(K + 1,)``
    states : ndarray ``(..., K + 1, n)``
        :math:`\mu_n`, as :func:`roughpaths.solve` returns them.
    group : ndarray ``(..., K + 1, N, N)``
        :math:`g_n` in the algebra's matrix representation (real or complex).
    algebra : LieAlgebra or MatrixLieAlgebra
    """

    times: np.ndarray
    states: np.ndarray
    group: np.ndarray
    algebra: object

    def spatial_momentum(self) -> np.ndarray:
        r""":math:`m_n = \mathrm{Ad}^*_{g_n}{}^{-1}\mu_n`, shape ``(..., K + 1, n)`` (conserved by the schemes)."""
        return _spatial(self.algebra, self)


def _matrix_exp(algebra, sigma):
    if isinstance(algebra, MatrixLieAlgebra):
        return expm_batched(algebra.to_matrix(sigma))
    if algebra.basis is None:
        raise ValueError(f"the Lie algebra {algebra.name!r} has no matrix basis to hold the group element; build it "
                         f"with LieAlgebra.from_matrix_basis, or use a MatrixLieAlgebra.")
    return expm_batched(np.einsum("...i,iab->...ab", sigma, algebra.basis))


def solve_with_group(system: LiePoissonSystem, X, mu0, solver: CoadjointSolver, *, g0=None) -> GroupSolution:
    r"""Solve a Lie–Poisson RDE and reconstruct the group element :math:`g_n` along it (module docstring).

    Parameters
    ----------
    system : LiePoissonSystem
        Without forces (they break the coadjoint form of the update). Its algebra needs a matrix
        representation: a :class:`~mechanics.systems.matrix_algebra.MatrixLieAlgebra`, or a
        :class:`~mechanics.systems.lie_algebra.LieAlgebra` with a basis (so3(), se3(), su2(), from_matrix_basis).
    X : RoughPath or Driver
        The driving rough path, ``(..., K, m)`` (a driver is materialised, with its memory checked).
    mu0 : array_like ``(..., n)``
    solver : LieEuler, LieHeun or ImplicitMidpoint
    g0 : array_like ``(..., N, N)``, optional
        The initial group element (default the identity).

    Returns
    -------
    GroupSolution
        With ``spatial_momentum()``, :math:`\mathrm{Ad}^*_{g}{}^{-1}\mu`.

    Examples
    --------
    The rigid body's attitude: ``R`` stays a rotation, and the spatial angular momentum ``R Π`` is conserved.

    >>> import numpy as np
    >>> import roughpaths as rp
    >>> from mechanics import LieHeun, rigid_body
    >>> body = rigid_body([1.0, 2.0, 3.0], sigma=0.3)
    >>> X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 201), 3, np.random.default_rng(0))
    >>> sol = solve_with_group(body, X, [0.6, 0.0, 0.8], LieHeun())
    >>> R = sol.group[-1]
    >>> bool(np.allclose(R.T @ R, np.eye(3), atol=1e-13)), bool(np.allclose(R @ sol.states[-1], [0.6, 0.0, 0.8]))
    (True, True)
    """
    if not isinstance(system, LiePoissonSystem):
        raise TypeError(f"system must be a mechanics.LiePoissonSystem, got {type(system).__name__}.")
    if not isinstance(solver, CoadjointSolver):
        raise TypeError(f"solver must be LieEuler(), LieHeun() or ImplicitMidpoint(), got {solver!r}.")
    if system.has_forces:
        raise ValueError("solve_with_group needs a system without forces: a force is added outside the coadjoint "
                         "update, so the spatial momentum is not conserved and g_{n+1} = g_n exp(sigma_n) does not "
                         "reconstruct the solution.")
    alg = system.algebra
    if isinstance(X, Driver):
        X = X.rough_path()
    if not isinstance(X, RoughPath):
        raise TypeError(f"X must be a roughpaths.RoughPath or a Driver, got {type(X).__name__}.")
    solver.check_driver(X)
    n, m = system.dim, system.n_noise
    if X.dim != m:
        raise ValueError(f"X has dimension {X.dim} but the system has {m} noise vectors; pass a {m}-dimensional path.")
    mu = as_float_array(mu0, "mu0", last_dims=(n,))
    batch = np.broadcast_shapes(mu.shape[:-1], X.batch_shape)
    K = X.n_steps
    probe = _matrix_exp(alg, np.zeros(n))
    N, dtype = probe.shape[-1], probe.dtype
    members = float(np.prod(batch, dtype=np.float64))
    check_memory(members * (K + 1) * (8.0 * n + N * N * dtype.itemsize) * 1.5,
                 f"the states and group elements of {members:.0f} member(s) at {K + 1} times",
                 "solve fewer members or a shorter grid at once")
    g = np.broadcast_to(np.eye(N, dtype=dtype) if g0 is None else np.asarray(g0), batch + (N, N)).copy()
    mu = np.broadcast_to(mu, batch + (n,)).copy()
    dX = np.broadcast_to(X.increments, batch + (K, m))
    areas = None if X.areas is None else np.broadcast_to(X.step_levy_areas, batch + (K, m, m))
    dts = np.diff(X.times)
    states = np.empty(batch + (K + 1, n))
    group = np.empty(batch + (K + 1, N, N), dtype=np.result_type(dtype, g.dtype))
    states[..., 0, :], group[..., 0, :, :] = mu, g
    for k in range(K):
        eta = system.stochastic_velocity(dX[..., k, :], None if areas is None else areas[..., k, :, :])
        sigma, conv = solver._sigma(system, mu, float(dts[k]), eta)
        if conv is not None and not np.all(conv):
            raise ValueError(f"the implicit midpoint's iteration did not converge at step {k}; reduce the step or "
                             f"use LieHeun().")
        mu = alg.Ad_star_exp(sigma, mu)
        g = g @ _matrix_exp(alg, sigma)
        states[..., k + 1, :], group[..., k + 1, :, :] = mu, g
    return GroupSolution(np.array(X.times), states, group, alg)


def _spatial(alg, sol):
    """``Ad*_{g^-1} mu``: the coordinates of ``g M g^-1`` (matrix algebras), ``Ad_g^{-T} mu`` from the basis
    (structure constants: ``Ad_g`` is the matrix of ``X -> g X g^-1`` on the basis)."""
    g, mu = sol.group, sol.states
    ginv = np.linalg.inv(g)
    if isinstance(alg, MatrixLieAlgebra):
        return alg.matrix_to_dual(g @ alg.dual_to_matrix(mu) @ ginv)
    B = alg.basis
    n = alg.dim
    flat = B.reshape(n, -1)
    F = np.concatenate([flat.real, flat.imag], axis=1).T                     # (2 N², n): coordinates of a matrix
    conj = g[..., None, :, :] @ B @ ginv[..., None, :, :]                   # g E_j g^-1, (..., n, N, N)
    cf = conj.reshape(conj.shape[:-2] + (-1,))
    rhs = np.concatenate([cf.real, cf.imag], axis=-1)                       # (..., n, 2 N²)
    ad = np.linalg.lstsq(F, rhs.reshape(-1, F.shape[0]).T, rcond=None)[0]   # (n, ... n): column j = Ad_g e_j
    ad = np.moveaxis(ad.T.reshape(rhs.shape[:-1] + (n,)), -1, -2)           # (..., n, n): Ad_g
    return np.linalg.solve(np.swapaxes(ad, -1, -2), mu[..., None])[..., 0]  # Ad_g^{-T} mu
