"""Refinement of an empty batch of Brownian paths.

Claim: a ``BrownianDriver`` with an empty batch (``batch_shape`` containing a 0) refines like any other:
``driver.refine(F).rough_path()`` and ``roughpaths.refine(X, F, rng)`` return empty rough paths of the
right shapes (``F`` times the coarse steps, same batch shape, areas for a level-2 driver), for every
``levy_area`` method (``None`` included), both kinds, factors 1, 2, 3 and ``d = 2, 3`` where the method
allows it. Before the fix the driver raised "cannot reshape array of size 0".
"""

import numpy as np
import pytest

from roughpaths import BrownianDriver, refine

METHODS = [None, "davie", "foster", "exact", "fourier", "mrongowius-rossler", "wiktorsson", "auto"]


@pytest.mark.parametrize("factor", [1, 2, 3])
@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("batch_shape", [(0,), (2, 0)])
def test_empty_batch_refines_for_every_method(method, d, factor, batch_shape):
    if method == "exact" and d != 2:
        pytest.skip("levy_area='exact' is d = 2 only")
    for kind in ("stratonovich", "ito"):
        drv = BrownianDriver(d, seed=0, dt=0.1, n_steps=4, batch_shape=batch_shape, levy_area=method, kind=kind)
        X = drv.rough_path()
        for Y in (drv.refine(factor).rough_path(), refine(X, factor, np.random.default_rng(1))):
            assert Y.batch_shape == batch_shape
            assert Y.n_steps == 4 * factor
            assert Y.increments.shape == batch_shape + (4 * factor, d)
            if method is None:
                assert Y.areas is None
            else:
                assert Y.areas.shape == batch_shape + (4 * factor, d, d)
            np.testing.assert_allclose(Y.times[::factor], X.times)
