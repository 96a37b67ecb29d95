"""Every bad input named by the reliability probe gets a clear error: the argument, the value, the fix.

Each case was found by a probe (issue "Reliability") to give a silent wrong answer, an allocation nobody
estimated, an IndexError or a message naming an internal variable. Each must now raise ``ValueError`` or
``TypeError`` whose message names the argument (and, where there is one, the fix), before any large
allocation.
"""

import numpy as np
import pytest

import mechanics as mc
import roughpaths as rp
from _oracles import trig_fields, trig_jacobians


def _solve_davie3_bad_hessians():
    V = rp.VectorFields(trig_fields, jacobians=trig_jacobians, dim_state=2, dim_noise=2)
    X = rp.RoughPathN.from_rough_path(rp.brownian_rough_path(np.linspace(0, 1, 5), 2, 0), 3)
    rp.solve(V, X, np.ones(2), rp.Davie3(hessians=lambda y: np.zeros(y.shape[:-1] + (2, 2))))


CASES = [
    ("refine of a driver by 1e9", lambda: rp.BrownianDriver(2, seed=0, dt=0.1, n_steps=3).refine(10**9),
     ValueError, ["factor=1000000000", "smaller factor"]),
    ("non-finite t0", lambda: rp.BrownianDriver(2, seed=0, dt=0.1, n_steps=3, t0=np.inf), ValueError, ["t0"]),
    ("grid overflowing to inf", lambda: rp.BrownianDriver(2, seed=0, dt=1e308, n_steps=3), ValueError,
     ["overflows", "smaller dt"]),
    ("term count overflow", lambda: rp.sample_levy_areas(np.zeros((2, 3)), 0.1, np.random.default_rng(0),
                                                          levy_area="fourier", levy_area_error=1e-300),
     ValueError, ["terms", "larger error"]),
    ("auto beyond the term limit", lambda: rp.BrownianDriver(3, seed=0, dt=0.1, n_steps=2, levy_area_error=1e-300),
     ValueError, ["levy_area='auto'", "levy_area_error"]),
    ("lift of 9 points in 1000 dimensions", lambda: rp.RoughPathN.from_path(np.zeros((9, 1000)), 3), ValueError,
     ["level-3 lift", "memory budget"]),
    ("level-50 lift", lambda: rp.RoughPathN.from_path(np.zeros((5, 2)), 50), ValueError, ["level", "lower level"]),
    ("signature depth 1000", lambda: rp.signature(np.zeros((5, 2)), 1000), ValueError, ["depth=1000", "e+301"]),
    ("1-D path hint", lambda: rp.signature(np.zeros(5), 2), ValueError, ["paths[:, None]"]),
    ("null byte in a path", lambda: rp.save(rp.brownian_rough_path([0, 1, 2], 2, 0), "/tmp/a\0b.npz"),
     ValueError, ["path", "null byte"]),
    ("one-argument time-dependent field", lambda: rp.VectorFields(lambda y: np.zeros(y.shape + (1,)), dim_state=1,
                                                                   dim_noise=1, time_dependent=True),
     TypeError, ["(t, y)", "time_dependent=False"]),
    ("scalar moment_observable", lambda: mc.moment_observable(3.0), ValueError, ["moment_observable", "(..., n)"]),
    ("degenerate inertia", lambda: mc.rigid_body([1, 1, 1e-320]), ValueError, ["inertia", "rescale"]),
    ("a coadjoint solver given a Lévy-area flag", lambda: mc.LieHeun(levy_area=False), TypeError,
     ["takes no arguments", "levy_area=None"]),
    ("Davie3 hessians of the wrong shape", _solve_davie3_bad_hessians, ValueError, ["hessians", "(..., d, e, e, e)"]),
]


@pytest.mark.parametrize("name, call, exc, words", CASES, ids=[c[0] for c in CASES])
def test_clear_error(name, call, exc, words):
    with pytest.raises(exc) as info:
        call()
    msg = str(info.value)
    for w in words:
        assert w in msg, (name, w, msg)
