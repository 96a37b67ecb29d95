r"""Zeitlin's model: 2-D incompressible Euler on the unit sphere quantised on :math:`\mathfrak{su}(N)`.

:mod:`.quantisation` builds the quantised spherical harmonics :math:`T_{lm}` (Hoppe) and the maps between a
vorticity matrix :math:`W` and the coefficients of its field; :mod:`.laplacian` the Hoppe–Yau Laplacian
:math:`\Delta_N` (exact eigenvalues :math:`-l(l+1)`) and its :math:`O(N^2)` inverse, the stream matrix;
:mod:`.grid` the fields on a Gauss–Legendre latitude–longitude grid; :mod:`.euler` the Hamiltonian for
matrix-state Lie–Poisson solvers (:math:`\dot W = [W, \nabla h] = \kappa[P, W]`), energy, enstrophy,
Casimirs and SALT noise matrices; :mod:`.solutions` the Rossby–Haurwitz wave in closed form; :mod:`.system` the stochastic model (SALT noise, the
Lévy-area correction, dissipation) as a Lie–Poisson system on :func:`mechanics.su` for :func:`roughpaths.solve`.

States are complex ``(..., N, N)`` arrays, batch first; an :math:`\mathfrak{su}(N)` element is skew-Hermitian
and trace-free, paired with itself by :math:`B(A, C) = -\tfrac12\operatorname{Re}\operatorname{tr}(AC)`.
Conventions and their derivations: the module docstrings and ``docs/conventions.md`` ("Euler on the sphere").
"""

from .euler import ZeitlinHamiltonian, casimirs, energy, enstrophy, real_harmonic_matrix, salt_noise
from .grid import (coefficients_to_grid, function_to_matrix, grid_to_coefficients, grid_to_matrix, matrix_to_grid,
                   sphere_grid)
from .laplacian import inverse_laplacian, laplacian
from .quantisation import coefficients_to_matrix, harmonic_matrix, hbar, lm_index, matrix_to_coefficients, spin_matrices
from .solutions import RossbyHaurwitzWave
from .system import zeitlin_system

__all__ = [
    "hbar", "spin_matrices", "lm_index", "harmonic_matrix", "coefficients_to_matrix", "matrix_to_coefficients",
    "laplacian", "inverse_laplacian",
    "sphere_grid", "coefficients_to_grid", "grid_to_coefficients", "matrix_to_grid", "grid_to_matrix",
    "function_to_matrix",
    "ZeitlinHamiltonian", "energy", "enstrophy", "casimirs", "real_harmonic_matrix", "salt_noise",
    "RossbyHaurwitzWave", "zeitlin_system",
]
