"""roughpaths: level-2 geometric rough paths, signatures, Brownian lifts, norms and RDE solvers.

Conventions are fixed once, in ``docs/conventions.md`` of the project: the area ``XX[i, j]`` is
``∫ (X^i - X^i_s) dX^j`` (iisignature ordering), the Lévy area is ``½(XX - XXᵀ)``, and the
Friz–Oberhauser drift of a perturbation ``s`` is ``½ Σ s^{ij} [V_i, V_j]``.
"""

from .brownian import DEFAULT_SUBSTEPS, brownian_increments_and_areas, brownian_rough_path, refine
from .coloured_noise import (
    ColouredNoiseLimit,
    ColouredNoiseSample,
    ResolutionWarning,
    coloured_noise_limit,
    coloured_noise_limit_path,
    expected_area_rate,
    iter_coloured_noise,
    lift_area_rate,
    ou_step_law,
    paper_coloured_noise_matrices,
    sample_coloured_noise,
)
from .integral import rough_integral
from .level2 import level2_exp, level2_inv, level2_log, level2_mul
from .norms import (
    area_holder_seminorm,
    area_p_variation,
    holder_distance,
    holder_seminorm,
    p_variation,
    rough_path_holder_norm,
    rough_path_p_variation,
)
from .rough_path import RoughPath, chen_defect
from .solve import Solution, solve
from .solvers import SOLVERS, Davie, Euler, Heun, LogODE, expm_batched
from .signature import logsignature, rough_path_signature, signature
from .vector_fields import LinearDrift, LinearVectorFields, VectorFields
from .tensor_algebra import (
    from_level2,
    from_lyndon_coordinates,
    logsigdim,
    lyndon_basis,
    lyndon_coordinates,
    sigdim,
    tensor_exp,
    tensor_inverse,
    tensor_log,
    tensor_product,
    to_level2,
)

__version__ = "0.1.0"

__all__ = [
    # RDE entry point, solvers, vector fields, rough integral
    "solve",
    "Solution",
    "Euler",
    "Heun",
    "Davie",
    "LogODE",
    "SOLVERS",
    "expm_batched",
    "VectorFields",
    "LinearVectorFields",
    "LinearDrift",
    "rough_integral",
    # coloured noise
    "coloured_noise_limit",
    "ColouredNoiseLimit",
    "ColouredNoiseSample",
    "sample_coloured_noise",
    "iter_coloured_noise",
    "coloured_noise_limit_path",
    "paper_coloured_noise_matrices",
    "ou_step_law",
    "lift_area_rate",
    "expected_area_rate",
    "ResolutionWarning",
    # rough paths, group, Brownian lifts, norms, signatures
    "RoughPath",
    "chen_defect",
    "brownian_rough_path",
    "brownian_increments_and_areas",
    "refine",
    "DEFAULT_SUBSTEPS",
    "level2_mul",
    "level2_inv",
    "level2_exp",
    "level2_log",
    "holder_seminorm",
    "area_holder_seminorm",
    "rough_path_holder_norm",
    "p_variation",
    "area_p_variation",
    "rough_path_p_variation",
    "holder_distance",
    "signature",
    "logsignature",
    "rough_path_signature",
    "sigdim",
    "logsigdim",
    "tensor_product",
    "tensor_inverse",
    "tensor_exp",
    "tensor_log",
    "to_level2",
    "from_level2",
    "lyndon_basis",
    "lyndon_coordinates",
    "from_lyndon_coordinates",
]
