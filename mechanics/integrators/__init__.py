r"""Casimir-preserving coadjoint solvers for Lie–Poisson systems, under the :class:`roughpaths.Solver` contract.

``roughpaths.solve(system, X, mu0, LieHeun())`` integrates a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem`
on a rough path or a driver and returns a :class:`roughpaths.Solution` (see :mod:`.base` for the
schemes). Compiled kernels are chosen inside the solvers: hand-written ones for so(3) and se(3) (by the type
of the algebra), a generic one compiled from the structure constants for every other algebra; they run
on numba's threads (``numba.set_num_threads``). On a matrix Lie algebra (:func:`mechanics.su` and the like)
the state is held as a matrix and updated by conjugation (isospectral), at the cost of matrix products.
"""

from .base import ChordConvergenceError, CoadjointSolver, ImplicitMidpoint, LieEuler, LieHeun, check_on_orbit
from .reconstruction import GroupSolution, solve_with_group

__all__ = ["CoadjointSolver", "LieEuler", "LieHeun", "ImplicitMidpoint", "ChordConvergenceError",
           "check_on_orbit", "GroupSolution", "solve_with_group"]
