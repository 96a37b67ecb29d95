"""run_ensemble speaks the drivers' Lévy-area vocabulary and holds no solver flag.

Claim: :func:`mechanics.run_ensemble` accepts every name of :data:`roughpaths.LEVY_AREA_METHODS` (and
``None``) as ``levy_area``, and ``levy_area_error`` for the error-controlled ones; its statistics with a
method equal those of the direct ``solve`` on ``BrownianDriver(..., levy_area=method)`` path by path; its
default is level-1 driving, and its docstring says why; the caller's solver is used as given (the
driving level comes from the driver).
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
    solver = mechanics.LieHeun()
    res = mechanics.run_ensemble(RB, MU0, dt=0.01, n_steps=20, n_paths=5, seed=3, levy_area=method,
                                 method=solver, keep_final=True, chunk_size=2, **kw)
    drv = rp.BrownianDriver(3, seed=3, dt=0.01, n_steps=20, batch_shape=(5,), levy_area=method, **kw)
    direct = rp.solve(RB, drv, MU0, mechanics.LieHeun(), save_at="end").final
    np.testing.assert_array_equal(res.final_states, direct)
    assert repr(solver) == "LieHeun()"


def test_unknown_method_refused():
    with pytest.raises(ValueError, match="levy_area must be one of"):
        mechanics.run_ensemble(RB, MU0, dt=0.1, n_steps=2, n_paths=1, seed=0, levy_area="levy")
