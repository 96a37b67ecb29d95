r"""The mechanical systems: Lie algebras, Hamiltonians, Lie–Poisson systems, the rigid body and the heavy top.

:mod:`.lie_algebra` holds the Lie algebras (so(3), su(2), se(3), sl(2, R), or any from structure
constants) with their coadjoint exponentials; :mod:`.matrix_algebra` the matrix Lie algebras of any size
(:mod:`.classical_algebras`: so(n), su(N), u(N), sp(2n, R), sl(n, R); or a user basis), whose solvers hold the
state as a matrix; :mod:`.hamiltonian` the Hamiltonians and the inertia
check; :mod:`.lie_poisson` the stochastic Lie–Poisson system (SALT noise, the Lévy-area velocity
:math:`\ell = \tfrac12\sum s^{ij}[\xi_i, \xi_j]`, double-bracket dissipation) that every solver in
:mod:`mechanics.integrators` integrates; :mod:`.rigid_body` and :mod:`.heavy_top` are its two worked
examples on so(3)* and se(3)*; :mod:`.cotangent_lift` lifts a system to the rough symplectic system
on phase space that reduces to it (Section 2.3).
"""

from .classical_algebras import sl, so, sp, su, u
from .cotangent_lift import CotangentLift, cotangent_lift
from .hamiltonian import Hamiltonian, MatrixHamiltonian, QuadraticHamiltonian, check_inertia
from .heavy_top import HeavyTop, heavy_top
from .lie_algebra import (LieAlgebra, SE3Algebra, SO3Algebra, hat, rodrigues_ad_star_exp, se3, se3_ad_star_exp, sl2r,
                          so3, su2, vee)
from .girsanov import girsanov_shift
from .lie_poisson import LiePoissonSystem, levy_velocity
from .matrix_algebra import MatrixLieAlgebra
from .rigid_body import RigidBody, isotropic_xi, rigid_body

__all__ = [
    "LieAlgebra", "SO3Algebra", "SE3Algebra", "so3", "su2", "se3", "sl2r", "hat", "vee",
    "rodrigues_ad_star_exp", "se3_ad_star_exp",
    "MatrixLieAlgebra", "so", "su", "u", "sp", "sl",
    "Hamiltonian", "QuadraticHamiltonian", "MatrixHamiltonian", "check_inertia",
    "LiePoissonSystem", "levy_velocity", "girsanov_shift",
    "RigidBody", "rigid_body", "isotropic_xi", "HeavyTop", "heavy_top",
    "CotangentLift", "cotangent_lift",
]
