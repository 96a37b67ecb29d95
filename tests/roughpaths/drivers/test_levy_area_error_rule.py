"""One rule for ``levy_area_error`` at every door (issue 36, item 5).

Claim: ``levy_area_error`` is accepted exactly where it sets the accuracy of the areas, with the Fourier
methods and ``"auto"`` (which meets any error with ``"exact"`` for ``d <= 2``), and refused with a
``ValueError`` that says so and how to fix it with ``"exact"``, ``"davie"``, ``"foster"`` and ``None``
(before, ``"exact"`` silently ignored it while ``"davie"`` refused it). The same answer comes from every
door that samples areas: ``BrownianDriver``, ``brownian_rough_path``, ``brownian_increments_and_areas``,
``sample_levy_areas``, ``BrownianTree`` and ``mechanics.run_ensemble``.
"""

import numpy as np
import pytest

import mechanics
import roughpaths as rp
from mechanics.systems.lie_algebra import so3
from mechanics.systems.lie_poisson import LiePoissonSystem

ACCEPTING = ("fourier", "mrongowius-rossler", "wiktorsson", "auto")
REFUSING = ("exact", "davie", "foster", None)
ERR = 0.05          # per-step L2 error at h = 0.1: a few Fourier terms, cheap

DOORS = {
    "BrownianDriver": lambda m: rp.BrownianDriver(2, seed=1, dt=0.1, n_steps=3, batch_shape=(2,), levy_area=m,
                                                  levy_area_error=ERR).rough_path(),
    "brownian_rough_path": lambda m: rp.brownian_rough_path(np.linspace(0, 0.3, 4), 2, 1, levy_area=m,
                                                            levy_area_error=ERR),
    "brownian_increments_and_areas": lambda m: rp.brownian_increments_and_areas(1, 3, 0.1, 2, levy_area=m,
                                                                                levy_area_error=ERR),
    "sample_levy_areas": lambda m: rp.sample_levy_areas(np.full((3, 2), 0.1), 0.1, np.random.default_rng(1),
                                                        levy_area=m, levy_area_error=ERR),
    "BrownianTree": lambda m: rp.BrownianTree(2, seed=1, levy_area=m, levy_area_error=ERR).area(0.0, 0.5),
    "run_ensemble": lambda m: mechanics.run_ensemble(
        LiePoissonSystem(so3(), np.diag([1.0, 2.0, 3.0]), 0.2 * np.eye(3)[:2]), [0.0, 0.6, 0.8], dt=0.1,
        n_steps=3, n_paths=2, seed=1, levy_area=m, levy_area_error=ERR),
}


@pytest.mark.parametrize("door", sorted(DOORS))
@pytest.mark.parametrize("method", REFUSING, ids=str)
def test_refused_where_it_has_no_effect(door, method):
    if door == "BrownianTree" and method is None:
        with pytest.raises(ValueError, match="levy_area=None: the tree always carries Lévy areas"):
            DOORS[door](method)
        return
    if door == "sample_levy_areas" and method is None:
        with pytest.raises(ValueError, match="levy_area=None samples no area"):
            DOORS[door](method)
        return
    with pytest.raises(ValueError, match=rf"levy_area_error applies to the error-controlled methods .* only; "
                                         rf"levy_area={method!r}, .*would ignore levy_area_error=0.05\. Leave "
                                         rf"levy_area_error unset, or pick one of those"):
        DOORS[door](method)


@pytest.mark.parametrize("door", sorted(DOORS))
@pytest.mark.parametrize("method", ACCEPTING)
def test_accepted_where_it_sets_the_accuracy(door, method):
    assert DOORS[door](method) is not None


def test_auto_meets_any_error_with_the_exact_law_in_two_dimensions():
    """``"auto"`` with an error at d = 2 is the exact sampler: the same numbers as ``"exact"`` without one."""
    times = np.linspace(0.0, 1.0, 9)
    auto = rp.brownian_rough_path(times, 2, 5, batch_shape=(3,), levy_area="auto", levy_area_error=1e-3)
    exact = rp.brownian_rough_path(times, 2, 5, batch_shape=(3,), levy_area="exact")
    np.testing.assert_array_equal(auto.areas, exact.areas)
