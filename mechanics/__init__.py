"""mechanics: stochastic geometric mechanics on geometric rough paths.

Lie–Poisson / Euler–Poincaré equations with SALT noise, the Lévy-area correction, double-bracket
dissipation, Casimir-preserving integrators, the stochastic rigid body and heavy top, Gibbs measures,
and the coloured-noise Wong–Zakai anomaly, built on :mod:`roughpaths`.

Conventions (``docs/conventions.md``): ``ad*_ξ μ = ad(ξ)ᵀ μ`` (on so(3): ``Π × ξ``); the Lévy-area
velocity is ``ℓ = +½ Σ s^{ij} [ξ_i, ξ_j]`` and the modified Hamiltonian ``h̃ = h + ⟨μ, ℓ⟩``; the
paper's printed signs are available as ``convention="paper"``.

Layout (imports point down this list, never in a circle): :mod:`mechanics.systems` (Lie algebras,
Hamiltonians, Lie–Poisson systems, rigid body, heavy top), :mod:`mechanics.integrators` (coadjoint
solvers for :func:`roughpaths.solve`), :mod:`mechanics.ensemble` (:func:`run_ensemble` and its
statistics), :mod:`mechanics.analysis` (modified Hamiltonian, equilibria, phase portraits, Gibbs
measures), :mod:`mechanics.limits` (Wong–Zakai limits). The paper's application
(:mod:`mechanics.paper`, ``python -m mechanics``) is built on them and never imported by them.
Every public name below is importable as ``mechanics.<name>``.
"""

from .ensemble import EnsembleResult, RunningMoments, moment_observable, run_ensemble, split_moment_features
from .analysis import (
    Equilibrium,
    GibbsMeasure,
    LevelSets,
    OrbitExpectation,
    OrbitGibbsMeasure,
    gibbs_beta,
    gibbs_moments,
    isotropic_levy_shift,
    isotropic_sigma,
    lagrange_top_sleeping_stability,
    modified_hamiltonian,
    orbit_gibbs_beta,
    rigid_body_equilibria,
    rigid_body_level_sets,
    rigid_body_vector_field,
)
from .integrators import (
    ChordConvergenceError,
    CoadjointSolver,
    GroupSolution,
    ImplicitMidpoint,
    LieEuler,
    LieHeun,
    check_on_orbit,
    solve_with_group,
)
from .systems import (
    CotangentLift,
    Hamiltonian,
    HeavyTop,
    LieAlgebra,
    LiePoissonSystem,
    MatrixHamiltonian,
    MatrixLieAlgebra,
    QuadraticHamiltonian,
    RigidBody,
    SE3Algebra,
    SO3Algebra,
    check_inertia,
    cotangent_lift,
    girsanov_shift,
    hat,
    heavy_top,
    isotropic_xi,
    levy_velocity,
    rigid_body,
    se3,
    sl,
    sl2r,
    so,
    so3,
    sp,
    su,
    su2,
    u,
    vee,
)
from .limits import (
    PlanarExample,
    RigidBodyWongZakai,
    planar_example,
    planar_limit_moments,
    rigid_body_wong_zakai_limit,
    simulate_wong_zakai_rigid_body,
)
from . import sphere
from .sphere import RossbyHaurwitzWave, ZeitlinHamiltonian, zeitlin_system

__version__ = "0.1.0"

__all__ = [
    # Lie algebras
    "LieAlgebra", "SO3Algebra", "SE3Algebra", "so3", "su2", "se3", "sl2r", "hat", "vee",
    "MatrixLieAlgebra", "so", "su", "u", "sp", "sl",
    # Lie–Poisson systems
    "LiePoissonSystem", "Hamiltonian", "QuadraticHamiltonian", "MatrixHamiltonian", "girsanov_shift", "check_inertia", "levy_velocity",
    "RigidBody", "rigid_body", "isotropic_xi", "HeavyTop", "heavy_top",
    # phase space and reduction (Section 2.3)
    "CotangentLift", "cotangent_lift",
    # integrators
    "CoadjointSolver", "LieEuler", "LieHeun", "ImplicitMidpoint", "ChordConvergenceError", "check_on_orbit",
    "solve_with_group", "GroupSolution",
    # equilibria, phase portraits, Gibbs measures
    "Equilibrium", "LevelSets", "rigid_body_equilibria", "rigid_body_level_sets", "isotropic_levy_shift",
    "modified_hamiltonian", "rigid_body_vector_field", "lagrange_top_sleeping_stability",
    "GibbsMeasure", "gibbs_beta", "gibbs_moments",
    # Theorem 3.1's Gibbs measure on the orbits of compact matrix algebras
    "OrbitGibbsMeasure", "OrbitExpectation", "orbit_gibbs_beta", "isotropic_sigma",
    # ensembles
    "run_ensemble", "EnsembleResult", "RunningMoments", "moment_observable", "split_moment_features",
    # coloured noise and the Wong–Zakai anomaly
    "RigidBodyWongZakai", "rigid_body_wong_zakai_limit", "simulate_wong_zakai_rigid_body",
    "PlanarExample", "planar_example", "planar_limit_moments",
    # Euler on the sphere (Zeitlin's model on su(N)): the subpackage and its two main objects
    "sphere", "ZeitlinHamiltonian", "RossbyHaurwitzWave", "zeitlin_system",
]
