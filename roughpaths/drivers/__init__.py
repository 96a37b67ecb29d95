"""Drivers: what a solver integrates against, generated lazily and seeded per path.

* :mod:`~roughpaths.drivers.base`: the :class:`Driver` contract.
* :mod:`~roughpaths.drivers.brownian`: Brownian motion with Lévy areas (:class:`BrownianDriver`),
  :mod:`~roughpaths.drivers.areas` (every Lévy-area method behind one ``levy_area``),
  :mod:`~roughpaths.drivers.levy_area` (the error-controlled and exact samplers),
  :mod:`~roughpaths.drivers.refinement` (the same path on a finer grid) and
  :mod:`~roughpaths.drivers.tree` (the same path on any interval: :class:`BrownianTree`).
* :mod:`~roughpaths.drivers.coloured_noise` (and its law, :mod:`~roughpaths.drivers.coloured_noise_law`):
  Ornstein–Uhlenbeck coloured noise and its Wong–Zakai limit.
* :mod:`~roughpaths.drivers.fractional`: fractional Brownian motion and its rough-path lift.
* :mod:`~roughpaths.drivers.chaotic`: sums of an observable along orbits of a chaotic map, lifted
  (:class:`ChaoticDriver`), and :mod:`~roughpaths.drivers.chaotic_limit`: their Brownian limit with the
  Lévy-area drift ``Alt(E)`` (Green–Kubo estimates, the perturbed limit path).

The per-path streams (``_random``, ``_ziggurat``, ``_seeded``) and the compiled samplers are private.
"""

from .base import Driver
from .areas import DEFAULT_SUBSTEPS, sample_levy_areas
from .brownian import BrownianDriver, brownian_increments_and_areas, brownian_rough_path
from .coloured_noise import (ColouredNoiseDriver, ColouredNoiseSample, ResolutionWarning,
                             coloured_noise_limit_path, iter_coloured_noise, sample_coloured_noise)
from .coloured_noise_law import (ColouredNoiseLimit, coloured_noise_limit, expected_area_rate,
                                 lift_area_rate, ou_step_law, paper_coloured_noise_matrices)
from .chaotic import ChaoticDriver, ChaoticMap, cat_map, lorenz63_map, observable_orbits
from .chaotic_limit import (ChaoticLimit, GreenKuboEstimate, SineObservable, chaotic_limit, chaotic_limit_path,
                            green_kubo)
from .fractional import fbm, fbm_rough_path, fgn_autocovariance, piecewise_linear_lift
from .levy_area import (LEVY_AREA_METHODS, choose_levy_area_method, levy_area_normals, levy_area_terms,
                        levy_areas_from_normals)
from .refinement import RefinedBrownianDriver, refine
from .tree import BrownianTree

__all__ = [
    "Driver", "DEFAULT_SUBSTEPS", "BrownianDriver", "brownian_increments_and_areas", "brownian_rough_path",
    "ColouredNoiseDriver", "ColouredNoiseSample", "ResolutionWarning", "coloured_noise_limit_path",
    "iter_coloured_noise", "sample_coloured_noise", "ColouredNoiseLimit", "coloured_noise_limit",
    "expected_area_rate", "lift_area_rate", "ou_step_law", "paper_coloured_noise_matrices", "fbm",
    "fbm_rough_path", "fgn_autocovariance", "piecewise_linear_lift", "LEVY_AREA_METHODS",
    "choose_levy_area_method", "levy_area_normals", "levy_area_terms", "levy_areas_from_normals",
    "sample_levy_areas", "RefinedBrownianDriver", "refine", "BrownianTree",
    "ChaoticDriver", "ChaoticMap", "cat_map", "lorenz63_map", "observable_orbits", "ChaoticLimit",
    "GreenKuboEstimate", "SineObservable", "chaotic_limit", "chaotic_limit_path", "green_kubo",
]
