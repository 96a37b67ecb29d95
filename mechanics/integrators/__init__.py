r"""Casimir-preserving coadjoint solvers for Lie–Poisson systems, under the :class:`roughpaths.Solver` contract.

``roughpaths.solve(system, X, mu0, LieHeun())`` integrates a :class:`~mechanics.systems.lie_poisson.LiePoissonSystem`
on a rough path or a driver and returns a :class:`roughpaths.Solution` (see :mod:`.base` for the
schemes). Compiled so(3) and se(3) kernels are chosen inside the solvers by the type of the algebra.
"""

from .base import ChordConvergenceError, CoadjointSolver, ImplicitMidpoint, LieEuler, LieHeun, check_on_orbit

__all__ = ["CoadjointSolver", "LieEuler", "LieHeun", "ImplicitMidpoint", "ChordConvergenceError",
           "check_on_orbit"]
