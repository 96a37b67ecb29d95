"""run_ensemble speaks the drivers' Lévy-area vocabulary and holds no solver flag.

Claim: :func:`mechanics.run_ensemble` accepts every name of :data:`roughpaths.LEVY_AREA_METHODS` (and
``None``) as ``levy_area``, and ``levy_area_error`` for the error-controlled ones; its statistics with a
method equal those of the direct ``solve`` on ``BrownianDriver(..., levy_area=method)`` path by path; its
default is level-1 driving, and its docstring says why; the driving level follows ``levy_area`` through
the driver alone (the solver holds no flag).
"""

import inspect

import numpy as np
import pytest

import mechanics
import roughpaths as rp

RB = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.3)
MU0 = np.array([0.0, 0.6, 0.8])


def test_default_is_level1_and_documented():
    assert inspect.signature(mechanics.run_ensemble).parameters["levy_area"].default is None
    assert "level-1" in mechanics.run_ensemble.__doc__


@pytest.mark.parametrize("method", [m for m in rp.LEVY_AREA_METHODS if m != "exact"] + [None])  # d = 3
def test_every_method_matches_the_direct_solve(method):
    kw = dict(levy_area_error=1e-3) if method in ("fourier", "mrongowius-rossler", "wiktorsson", "auto") else {}
    res = mechanics.run_ensemble(RB, MU0, dt=0.01, n_steps=20, n_paths=5, seed=3, levy_area=method,
                                 method=mechanics.LieHeun(), keep_final=True, chunk_size=2, **kw)
    drv = rp.BrownianDriver(3, seed=3, dt=0.01, n_steps=20, batch_shape=(5,), levy_area=method, **kw)
    direct = rp.solve(RB, drv, MU0, mechanics.LieHeun(), save_at="end").final
    np.testing.assert_array_equal(res.final_states, direct)


def test_the_driving_level_follows_levy_area():
    """The same increments with and without the areas: the area enters exactly when a method is named."""
    kw = dict(dt=0.05, n_steps=40, n_paths=4, seed=5, keep_final=True)
    rb = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.8, s=np.array([[0, 1.0, 0], [-1.0, 0, 0], [0, 0, 0]]))
    level1 = mechanics.run_ensemble(rb, MU0, levy_area=None, **kw).final_states
    davie = mechanics.run_ensemble(rb, MU0, levy_area="davie", **kw).final_states
    X = rp.BrownianDriver(3, seed=5, dt=0.05, n_steps=40, batch_shape=(4,), levy_area="davie").rough_path()
    np.testing.assert_array_equal(level1, rp.solve(rb, X.to_level1(), MU0, mechanics.LieHeun(),
                                                   save_at="end").final)
    assert np.max(np.abs(level1 - davie)) > 1e-3


def test_unknown_method_refused():
    with pytest.raises(ValueError, match="levy_area must be one of"):
        mechanics.run_ensemble(RB, MU0, dt=0.1, n_steps=2, n_paths=1, seed=0, levy_area="levy")
