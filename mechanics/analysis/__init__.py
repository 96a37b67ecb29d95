r"""Deterministic analysis of the modified rigid body: equilibria, phase portraits and Gibbs measures.

:mod:`.modified_energy` defines the Lévy-area-modified rigid body once (``h̃``, its shift ``c``, its
vector field); :mod:`.equilibria` finds every equilibrium of it on a momentum sphere and classifies
its stability; :mod:`.phase_portrait` draws the level sets of ``h̃`` there (with the separatrices);
:mod:`.gibbs` integrates the Gibbs measure ``∝ exp(−β h̃)`` on the sphere (Theorem 3.1's invariant
law) to a stated accuracy; :mod:`.orbit_gibbs` estimates it on the coadjoint orbits of any compact
matrix algebra (so(n), su(N), u(N)) by importance sampling of exact orbit samples; :mod:`.lagrange_top`
is the closed-form stability test of the sleeping heavy top.
"""

from .equilibria import Equilibrium, rigid_body_equilibria
from .gibbs import GibbsMeasure, gibbs_beta, gibbs_moments
from .orbit_gibbs import OrbitExpectation, OrbitGibbsMeasure, isotropic_sigma, orbit_gibbs_beta
from .lagrange_top import lagrange_top_sleeping_stability
from .modified_energy import as_inverse_inertia, isotropic_levy_shift, modified_hamiltonian, rigid_body_vector_field
from .phase_portrait import LevelSets, rigid_body_level_sets

__all__ = [
    "Equilibrium", "rigid_body_equilibria", "isotropic_levy_shift", "modified_hamiltonian", "as_inverse_inertia",
    "rigid_body_vector_field", "lagrange_top_sleeping_stability",
    "LevelSets", "rigid_body_level_sets",
    "GibbsMeasure", "gibbs_beta", "gibbs_moments",
    "OrbitGibbsMeasure", "OrbitExpectation", "orbit_gibbs_beta", "isotropic_sigma",
]
