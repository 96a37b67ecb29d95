r"""Deterministic analysis of the modified rigid body: equilibria, phase portraits and Gibbs measures.

:mod:`.equilibria` finds every equilibrium of the Lévy-area-modified rigid body on a momentum sphere
and classifies its stability; :mod:`.phase_portrait` draws the level sets of the modified Hamiltonian
``h̃`` there (with the separatrices); :mod:`.gibbs` integrates the Gibbs measure
``∝ exp(−β h̃)`` on the sphere (Theorem 3.1's invariant law) to a stated accuracy.
"""

from .equilibria import (
    Equilibrium,
    as_inverse_inertia,
    isotropic_levy_shift,
    lagrange_top_sleeping_stability,
    modified_hamiltonian,
    rigid_body_equilibria,
    rigid_body_vector_field,
)
from .gibbs import GibbsMeasure, gibbs_beta, gibbs_moments
from .phase_portrait import LevelSets, rigid_body_level_sets

__all__ = [
    "Equilibrium", "rigid_body_equilibria", "isotropic_levy_shift", "modified_hamiltonian", "as_inverse_inertia",
    "rigid_body_vector_field", "lagrange_top_sleeping_stability",
    "LevelSets", "rigid_body_level_sets",
    "GibbsMeasure", "gibbs_beta", "gibbs_moments",
]
