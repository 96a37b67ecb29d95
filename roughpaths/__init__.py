"""roughpaths: level-2 (and level-N) geometric rough paths, fractional Brownian motion, signatures, Brownian lifts, norms and RDE solvers.

Conventions are fixed once, in ``docs/conventions.md`` of the project: the area ``XX[i, j]`` is
``∫ (X^i - X^i_s) dX^j`` (iisignature ordering), the Lévy area is ``½(XX - XXᵀ)``, and the
Friz–Oberhauser drift of a perturbation ``s`` is ``½ Σ s^{ij} [V_i, V_j]``.

The package is filed by concept, one subpackage each (imports point down this list, never up):
:mod:`~roughpaths.algebra` (tensor algebra, level-2 group, Lyndon basis), :mod:`~roughpaths.paths`
(rough paths, rough integral), :mod:`~roughpaths.signatures`, :mod:`~roughpaths.norms`,
:mod:`~roughpaths.drivers` (Brownian with Lévy areas, coloured noise, fBM, chaotic maps) and :mod:`~roughpaths.rde`
(``solve``, the solvers, vector fields); :mod:`~roughpaths.io` saves and loads them. Every public name
is importable from here.
"""

from ._linalg import expm_batched
from ._version import __version__
from .algebra import (from_level2, from_lyndon_coordinates, level2_exp, level2_inv, level2_log, level2_mul,
                      logsigdim, lyndon_basis, lyndon_coordinates, sigdim, tensor_exp, tensor_inverse, tensor_log,
                      tensor_product, to_level2)
from .drivers import (DEFAULT_SUBSTEPS, LEVY_AREA_METHODS, BrownianDriver, BrownianTree, ColouredNoiseDriver,
                      ColouredNoiseLimit, ColouredNoiseSample, Driver, ResolutionWarning, brownian_increments_and_areas,
                      brownian_rough_path, choose_levy_area_method, coloured_noise_limit, coloured_noise_limit_path,
                      expected_area_rate, fbm, fbm_rough_path, fgn_autocovariance, iter_coloured_noise,
                      levy_area_normals, levy_area_terms, levy_areas_from_normals, lift_area_rate, ou_step_law,
                      paper_coloured_noise_matrices, piecewise_linear_lift, refine, sample_coloured_noise,
                      sample_levy_areas)
from .drivers import (ChaoticDriver, ChaoticLimit, ChaoticMap, GreenKuboEstimate, SineObservable, cat_map,
                      chaotic_limit, chaotic_limit_path, green_kubo, lorenz63_map, observable_orbits)
from .io import load, load_metadata, register_format, save
from .norms import (area_holder_seminorm, area_p_variation, holder_distance, holder_seminorm, p_variation,
                    rough_path_holder_norm, rough_path_p_variation)
from .paths import RoughPath, RoughPathN, chen_defect, rough_integral
from .progress import Progress, ProgressRecord, progress_reporter
from .rde import (SOLVERS, Davie, Davie3, Euler, FixedSteps, Heun, LinearDrift, LinearVectorFields, LogODE, LogODE3,
                  NonFiniteStateError, PIController, Solution, Solver, StepController, VectorFields, central_jacobian,
                  solve)
from .signatures import (LinearKernel, MMDTestResult, RBFKernel, SignatureStream, basepoint,
                         brownian_expected_signature, invisibility_reset, lead_lag, logsignature,
                         logsignature_vjp, rough_path_signature, rough_path_signature_vjp, sig_mmd_test, signature,
                         signature_kernel, signature_kernel_gram, signature_kernel_gram_vjp, signature_kernel_vjp,
                         signature_vjp, signature_coefficients, time_augment, windowed_signature)

__all__ = [
    # RDE entry point, solvers, vector fields, rough integral
    "solve", "Solution", "NonFiniteStateError", "PIController", "FixedSteps", "StepController", "Driver", "Solver", "Euler", "Heun", "Davie",
    "LogODE", "LogODE3", "Davie3", "SOLVERS", "expm_batched", "VectorFields", "LinearVectorFields", "LinearDrift",
    "central_jacobian", "rough_integral",
    # progress and the time left of long work (the progress= option)
    "ProgressRecord", "Progress", "progress_reporter",
    # coloured noise
    "coloured_noise_limit", "ColouredNoiseDriver", "ColouredNoiseLimit", "ColouredNoiseSample",
    "sample_coloured_noise", "iter_coloured_noise", "coloured_noise_limit_path", "paper_coloured_noise_matrices",
    "ou_step_law", "lift_area_rate", "expected_area_rate", "ResolutionWarning",
    # deterministic chaos: drivers from chaotic maps, their limit with the Lévy-area drift Alt(E)
    "ChaoticDriver", "ChaoticMap", "cat_map", "lorenz63_map", "observable_orbits", "green_kubo",
    "GreenKuboEstimate", "chaotic_limit", "ChaoticLimit", "chaotic_limit_path", "SineObservable",
    # saving and loading (versioned .npz)
    "save", "load", "load_metadata", "register_format",
    # rough paths, the level-2 group
    "RoughPath", "chen_defect", "level2_mul", "level2_inv", "level2_exp", "level2_log",
    # level-N rough paths, fractional Brownian motion
    "RoughPathN", "fbm", "fbm_rough_path", "fgn_autocovariance", "piecewise_linear_lift",
    # Brownian motion and Lévy areas
    "brownian_rough_path", "BrownianDriver", "BrownianTree", "brownian_increments_and_areas", "refine",
    "DEFAULT_SUBSTEPS",
    "sample_levy_areas", "levy_areas_from_normals", "levy_area_terms", "levy_area_normals",
    "choose_levy_area_method", "LEVY_AREA_METHODS",
    # norms
    "holder_seminorm", "area_holder_seminorm", "rough_path_holder_norm", "p_variation", "area_p_variation",
    "rough_path_p_variation", "holder_distance",
    # signatures and the tensor algebra
    "signature", "logsignature", "signature_vjp", "logsignature_vjp", "rough_path_signature_vjp",
    "rough_path_signature", "brownian_expected_signature", "sigdim", "logsigdim", "tensor_product", "tensor_inverse", "tensor_exp", "tensor_log",
    "to_level2", "from_level2", "lyndon_basis", "lyndon_coordinates", "from_lyndon_coordinates",
    # signature kernels and the two-sample test
    "signature_kernel", "signature_kernel_gram", "signature_kernel_vjp", "signature_kernel_gram_vjp",
    "LinearKernel", "RBFKernel", "sig_mmd_test", "MMDTestResult",
    # path transforms, streams (signatures of sub-intervals and windows), chosen words
    "lead_lag", "time_augment", "basepoint", "invisibility_reset", "SignatureStream", "windowed_signature",
    "signature_coefficients",
]
