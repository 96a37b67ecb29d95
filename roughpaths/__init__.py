"""roughpaths: level-2 (and level-N) geometric rough paths, fractional Brownian motion, signatures, Brownian lifts, norms and RDE solvers.

Conventions are fixed once, in ``docs/conventions.md`` of the project: the area ``XX[i, j]`` is
``∫ (X^i - X^i_s) dX^j`` (iisignature ordering), the Lévy area is ``½(XX - XXᵀ)``, and the
Friz–Oberhauser drift of a perturbation ``s`` is ``½ Σ s^{ij} [V_i, V_j]``.
"""

from .drivers.brownian import DEFAULT_SUBSTEPS, BrownianDriver, brownian_increments_and_areas, brownian_rough_path
from .drivers.coloured_noise import (
    ColouredNoiseDriver,
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
from .paths.integral import rough_integral
from .io import load, load_metadata, register_format, save
from .drivers.levy_area import (LEVY_AREA_METHODS, choose_levy_area_method, levy_area_normals, levy_area_terms,
                        levy_areas_from_normals, sample_levy_areas)
from .algebra.level2 import level2_exp, level2_inv, level2_log, level2_mul
from .norms import (
    area_holder_seminorm,
    area_p_variation,
    holder_distance,
    holder_seminorm,
    p_variation,
    rough_path_holder_norm,
    rough_path_p_variation,
)
from .paths.rough_path import RoughPath, chen_defect
from .paths.rough_path_n import RoughPathN
from .drivers.fractional import fbm, fbm_rough_path, fgn_autocovariance, piecewise_linear_lift
from .drivers.base import Driver
from .drivers.refinement import refine
from .rde.integrate import NonFiniteStateError, Solution, solve
from ._linalg import expm_batched
from .rde.integrate import SOLVERS
from .rde.base import Solver
from .rde.davie import Davie, Davie3
from .rde.euler import Euler, Heun
from .rde.logode import LogODE, LogODE3
from .signatures.signature import logsignature, rough_path_signature, signature
from .signatures.gradients import logsignature_vjp, rough_path_signature_vjp, signature_vjp
from .rde.vector_fields import LinearDrift, VectorFields
from .rde.linear_fields import LinearVectorFields
from .algebra.tensor import (
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
    "NonFiniteStateError",
    "Driver",
    "Solver",
    "Euler",
    "Heun",
    "Davie",
    "LogODE",
    "LogODE3",
    "Davie3",
    "SOLVERS",
    "expm_batched",
    "VectorFields",
    "LinearVectorFields",
    "LinearDrift",
    "rough_integral",
    # coloured noise
    "coloured_noise_limit",
    "ColouredNoiseDriver",
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
    # saving and loading (versioned .npz)
    "save",
    "load",
    "load_metadata",
    "register_format",
    # rough paths, group, Brownian lifts, norms, signatures
    "RoughPath",
    "chen_defect",
    # level-N rough paths, fractional Brownian motion
    "RoughPathN",
    "fbm",
    "fbm_rough_path",
    "fgn_autocovariance",
    "piecewise_linear_lift",
    "brownian_rough_path",
    "BrownianDriver",
    "brownian_increments_and_areas",
    "refine",
    "DEFAULT_SUBSTEPS",
    "sample_levy_areas",
    "levy_areas_from_normals",
    "levy_area_terms",
    "levy_area_normals",
    "choose_levy_area_method",
    "LEVY_AREA_METHODS",
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
    "signature_vjp",
    "logsignature_vjp",
    "rough_path_signature_vjp",
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
