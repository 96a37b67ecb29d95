"""One vocabulary for the Lévy area: every door takes every method name, with the same default.

Claim: :data:`roughpaths.LEVY_AREA_METHODS` lists every method; :class:`roughpaths.BrownianDriver`,
:func:`roughpaths.brownian_rough_path` and :func:`roughpaths.brownian_increments_and_areas` accept
each of them (and ``None``) under the parameter name ``levy_area``, and ``levy_area_error`` where it
means something; they share one default and, for the same seed, give bitwise the same path. An unknown
name is refused with the list of valid ones, and ``substeps`` is refused only when the caller passed
it to a method it does not apply to. (``mechanics.run_ensemble``'s side:
``tests/mechanics/ensemble/test_run_ensemble_levy_methods.py``.)
"""

import inspect

import numpy as np
import pytest

import roughpaths as rp

ALL = ("davie", "foster", "exact", "fourier", "mrongowius-rossler", "wiktorsson", "auto")
ERROR_CONTROLLED = ("fourier", "mrongowius-rossler", "wiktorsson", "auto")


def test_the_list_is_complete():
    assert tuple(rp.LEVY_AREA_METHODS) == ALL


def test_one_default_for_the_roughpaths_doors():
    defaults = {f.__name__: inspect.signature(f).parameters["levy_area"].default
                for f in (rp.BrownianDriver, rp.brownian_rough_path, rp.brownian_increments_and_areas)}
    assert len(set(defaults.values())) == 1, defaults


@pytest.mark.parametrize("method", ALL + (None,))
def test_every_door_takes_every_method(method):
    d = 2                                           # "exact" is the d = 2 sampler
    times = np.linspace(0.0, 1.0, 9)
    drv = rp.BrownianDriver(d, seed=11, times=times, batch_shape=(3,), levy_area=method).rough_path()
    X = rp.brownian_rough_path(times, d, 11, batch_shape=(3,), levy_area=method)
    dW, A = rp.brownian_increments_and_areas(11, 8, 0.125, d, batch_shape=(3,), levy_area=method)
    assert X.level == drv.level == (1 if method is None else 2)
    np.testing.assert_array_equal(X.increments, drv.increments)
    np.testing.assert_array_equal(dW, drv.increments)
    if method is not None:
        np.testing.assert_array_equal(X.areas, drv.areas)
        np.testing.assert_array_equal(A, drv.areas)


@pytest.mark.parametrize("method", ERROR_CONTROLLED)
def test_levy_area_error_reaches_the_sampler(method):
    times = np.linspace(0.0, 1.0, 5)
    coarse = rp.brownian_rough_path(times, 3, 5, levy_area=method, levy_area_error=1e-1)
    fine = rp.brownian_rough_path(times, 3, 5, levy_area=method, levy_area_error=1e-4)
    np.testing.assert_array_equal(coarse.increments, fine.increments)   # same path, finer areas
    assert not np.array_equal(coarse.areas, fine.areas)


def test_refusals_name_the_fix():
    with pytest.raises(ValueError, match="levy_area must be one of"):
        rp.brownian_rough_path([0.0, 1.0], 2, 0, levy_area="levy")
    with pytest.raises(ValueError, match="substeps=2 applies to levy_area='davie' or 'foster' only"):
        rp.brownian_rough_path([0.0, 1.0], 2, 0, levy_area="wiktorsson", substeps=2)
    with pytest.raises(ValueError, match="levy_area_error applies to"):
        rp.brownian_increments_and_areas(0, 2, 0.1, 2, levy_area="davie", levy_area_error=1e-3)
