r"""One default and one vocabulary for the Lévy areas of every door.

Claims: ``BrownianDriver``, ``brownian_rough_path``, ``brownian_increments_and_areas`` and
``sample_levy_areas`` default to ``levy_area="auto"`` and accept every name of ``LEVY_AREA_METHODS``
(``run_ensemble`` keeps a level-1 default, documented); for ``d = 2`` the default areas pass a
Kolmogorov–Smirnov test against the exact law of the Lévy area of planar Brownian motion over a step
``h = 0.5``, :math:`P(A \le x) = \tfrac2\pi\arctan e^{\pi x/h}` (Lévy 1951), with 2·10⁵ samples, while Davie's
areas (the former default) are rejected by the same test.
"""

import inspect

import numpy as np
import pytest
from scipy import stats

import roughpaths as rp


DOORS = [rp.BrownianDriver, rp.brownian_rough_path, rp.brownian_increments_and_areas, rp.sample_levy_areas]


@pytest.mark.parametrize("door", DOORS, ids=lambda f: f.__name__)
def test_every_door_defaults_to_auto(door):
    params = inspect.signature(door).parameters
    assert params["levy_area"].default == "auto"
    assert params["levy_area_error"].default is None


@pytest.mark.parametrize("method", rp.LEVY_AREA_METHODS)
def test_every_door_accepts_every_method(method):
    h, d = 0.1, 2
    X = rp.brownian_rough_path(np.linspace(0, 0.3, 4), d, 1, batch_shape=(3,), levy_area=method)
    dW, XX = rp.brownian_increments_and_areas(1, 3, h, d, batch_shape=(3,), levy_area=method)
    A = rp.sample_levy_areas(dW, h, np.random.default_rng(0), levy_area=method)
    drv = rp.BrownianDriver(d, seed=1, dt=h, n_steps=3, batch_shape=(3,), levy_area=method)
    for areas in (X.areas, XX, drv.rough_path().areas):
        assert areas.shape == (3, 3, d, d) and np.all(np.isfinite(areas))
    np.testing.assert_array_equal(A, -np.swapaxes(A, -1, -2))
    assert np.all(A[..., 0, 1] != 0)


def _law(x, h):
    return (2 / np.pi) * np.arctan(np.exp(np.pi * x / h))


def test_default_d2_areas_pass_a_ks_test_against_the_exact_law_and_davie_fails():
    h, n = 0.5, 200_000
    X = rp.brownian_rough_path([0.0, h], 2, np.random.default_rng(2), batch_shape=(n,))
    a = X.step_levy_areas[:, 0, 0, 1]
    assert stats.kstest(a, lambda x: _law(x, h)).pvalue > 1e-3
    davie = rp.brownian_rough_path([0.0, h], 2, np.random.default_rng(2), batch_shape=(n,), levy_area="davie")
    assert stats.kstest(davie.step_levy_areas[:, 0, 0, 1], lambda x: _law(x, h)).pvalue < 1e-10


def test_sample_levy_areas_default_is_the_exact_law_and_members_are_independent():
    h, n = 0.5, 200_000
    rng = np.random.default_rng(3)
    w = rng.normal(0.0, np.sqrt(h), size=(n, 2))
    A = rp.sample_levy_areas(w, h, rng)
    assert stats.kstest(A[:, 0, 1], lambda x: _law(x, h)).pvalue > 1e-3
    # member i's area depends on its own increment and stream only
    B = rp.sample_levy_areas(w[:5], h, np.random.default_rng(7))
    C = rp.sample_levy_areas(w[:3], h, np.random.default_rng(7))
    np.testing.assert_array_equal(B[:3], C)


def test_refusals_name_the_fix():
    with pytest.raises(ValueError, match="dim <= 2 only.*levy_area='auto'"):
        rp.BrownianDriver(3, seed=0, dt=0.1, n_steps=2, levy_area="exact")
    with pytest.raises(ValueError, match="substeps=4 applies to levy_area='davie' or 'foster' only"):
        rp.brownian_rough_path([0.0, 1.0], 2, 0, substeps=4)
    with pytest.raises(ValueError, match="levy_area_error must be a positive number"):
        rp.BrownianDriver(3, seed=0, dt=0.1, n_steps=2, levy_area_error=-1.0)
    with pytest.raises(ValueError, match="levy_area=None samples no area"):
        rp.sample_levy_areas(np.zeros((2, 2)), 0.1, np.random.default_rng(0), levy_area=None)
