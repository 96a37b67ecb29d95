r"""SALT Euler on the sphere as a stochastic Lie–Poisson system on :math:`\mathfrak{su}(N)^*`, for :func:`roughpaths.solve`.

:func:`zeitlin_system` puts together the Zeitlin Hamiltonian (:class:`~mechanics.sphere.euler.ZeitlinHamiltonian`),
SALT noise matrices (:func:`~mechanics.sphere.euler.salt_noise`, or the user's) and the library's
:class:`~mechanics.systems.lie_poisson.LiePoissonSystem` on the matrix algebra :func:`mechanics.su`, whose
basis is orthonormal for the same trace form :math:`B(A, C) = -\tfrac12\mathrm{Re}\,\mathrm{tr}(AC)`. The
equation (``docs/conventions.md``, "Matrix Lie algebras" and "Euler on the sphere") is

.. math::

    dW = [W, w]\,dt + \sum_i [W, \xi_i]\circ dX^i,\qquad w = -\kappa P + \ell + \vartheta[W, -\kappa P + \ell],
    \qquad \ell = \tfrac12\sum_{i,j}\mathsf s^{ij}[\xi_i, \xi_j],

i.e. :math:`dW = \kappa[P, W]dt + \sum_i[W,\xi_i]\circ dX^i` plus the Lévy-area correction
:math:`[W, \ell]dt` and, with :math:`\vartheta > 0`, double-bracket dissipation; the solvers hold :math:`W` as a
matrix and update it by conjugation (:mod:`mechanics.integrators`), so every Casimir
:math:`\mathrm{tr}((iW)^k)` is kept to round-off. States given to and returned by ``solve`` are the
coordinates of :math:`W` in the basis of :func:`mechanics.su` (``system.algebra.dual_to_matrix`` and
``matrix_to_dual`` convert).
"""

from __future__ import annotations

import numpy as np

from ..systems.classical_algebras import su
from ..systems.hamiltonian import MatrixHamiltonian
from ..systems.lie_poisson import LiePoissonSystem
from ._inputs import as_matrix
from .euler import ZeitlinHamiltonian, salt_noise

__all__ = ["zeitlin_system"]


def zeitlin_system(N: int, *, noise_modes=((1, 0), (1, 1), (2, 1)), noise=None, amplitudes=0.1, s=None,
                   theta: float = 0.0, levy_in_dissipation: bool = True,
                   time_unit: str = "physical") -> LiePoissonSystem:
    r"""The stochastic Zeitlin model on su(N) with SALT noise, the Lévy-area perturbation ``s`` and dissipation.

    Parameters
    ----------
    N : int
        Matrix size (the resolution: spherical harmonics up to degree ``N - 1``).
    noise_modes : sequence of (l, m)
        Stream functions of the noise, real spherical harmonics :math:`Y^{\mathbb R}_{lm}` (default: the three
        lowest modes that do not commute, so the Lévy areas matter), scaled by ``amplitudes``.
    noise : array_like ``(m, N, N)``, optional
        The noise matrices :math:`\xi_i` themselves (su(N) elements, e.g. from :func:`salt_noise` with fields);
        replaces ``noise_modes``.
    amplitudes : float or array_like ``(m,)``
        Factors of the mode stream functions.
    s : array_like ``(m, m)``, optional
        Antisymmetric Lévy-area perturbation (default 0).
    theta : float
        Double-bracket dissipation rate :math:`\vartheta \ge 0`.
    levy_in_dissipation : bool
        As for :class:`~mechanics.systems.lie_poisson.LiePoissonSystem` (``False``: the exact equation of the
        ``s = 0`` model driven by ``X.perturb(s)``).
    time_unit : {"physical", "quantum"}
        :class:`~mechanics.sphere.euler.ZeitlinHamiltonian`'s; the noise uses the same.

    Returns
    -------
    LiePoissonSystem
        On ``mechanics.su(N)``, with ``system.hamiltonian`` a :class:`~mechanics.systems.hamiltonian.MatrixHamiltonian`
        (``gradient_matrix`` = :math:`-\kappa P`) and ``system.zeitlin`` the :class:`ZeitlinHamiltonian`.

    Examples
    --------
    >>> import numpy as np
    >>> import roughpaths as rp
    >>> from mechanics import LieHeun
    >>> from mechanics.sphere import zeitlin_system
    >>> system = zeitlin_system(8, amplitudes=0.05)
    >>> g = system.algebra
    >>> W0 = g.matrix_to_dual(g._project(np.diag(np.arange(8.0)) * 1j))
    >>> X = rp.brownian_rough_path(np.linspace(0.0, 0.1, 11), 3, np.random.default_rng(0))
    >>> W1 = rp.solve(system, X, W0, LieHeun()).final
    >>> bool(np.allclose(g.casimirs(W1), g.casimirs(W0), rtol=1e-12))
    True
    """
    algebra = su(N)
    zh = ZeitlinHamiltonian(N, time_unit=time_unit)
    h = MatrixHamiltonian(algebra, zh.value_matrix, zh.gradient_matrix)
    if noise is None:
        mats = salt_noise(N, modes=noise_modes, amplitudes=amplitudes, time_unit=time_unit)
    else:
        mats = as_matrix(noise, "noise", N=N)
        if mats.ndim != 3 or mats.shape[1:] != (N, N):
            raise ValueError(f"noise must have shape (m, {N}, {N}) (one su({N}) matrix per noise), got {mats.shape}.")
        if mats.shape[0] == 0:
            raise ValueError(f"noise must hold at least one su({N}) matrix, got shape {mats.shape}; for the model "
                             f"without noise use ZeitlinHamiltonian(N).vector_field, or pass noise_modes.")
        defect = float(np.max(np.abs(algebra._project(mats) - mats))) if mats.size else 0.0
        if defect > 1e-12 * max(1.0, float(np.max(np.abs(mats)))):
            raise ValueError(f"noise matrices must lie in su({N}) (skew-Hermitian, trace-free); they are off by "
                             f"{defect:.3g}. Build them with mechanics.sphere.salt_noise.")
    xi = algebra.from_matrix(mats)
    system = LiePoissonSystem(algebra, h, xi, s=s, theta=theta, levy_in_dissipation=levy_in_dissipation)
    system.zeitlin = zh
    return system
