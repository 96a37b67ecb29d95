"""``save_at`` is taken in the caller's order or refused, never reordered (issue 36, item 5).

Claim: every route of ``roughpaths.solve`` that takes ``save_at`` (a ``RoughPath``, a lazy ``Driver``, a
batch split over an ``executor``, adaptive steps on a ``BrownianTree``) refuses times out of increasing
order with a ``ValueError`` that names the offending entries and says to sort them (before, ``[0, .5, .25]``
was silently sorted, so the caller's third time was paired with the state at ``.5``). Increasing times are
kept, a repeated time once, and the states are those of ``save_at="all"`` at those times (the oracle).
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import roughpaths as rp

V = rp.LinearVectorFields(0.3 * np.random.default_rng(0).standard_normal((2, 2, 2)))
TIMES = np.linspace(0.0, 1.0, 9)
UNSORTED = [0.0, 0.5, 0.25]
MESSAGE = (r"save_at must be in increasing order .* save_at\[1\]=0\.5 > save_at\[2\]=0\.25 in "
           r"save_at=\[0\.0, 0\.5, 0\.25\]; sort it")


def _routes():
    X = rp.brownian_rough_path(TIMES, 2, 3, batch_shape=(4,))
    drv = rp.BrownianDriver(2, seed=3, dt=0.125, n_steps=8, batch_shape=(4,))
    tree = rp.BrownianTree(2, seed=3, batch_shape=(2,))
    pool = ThreadPoolExecutor(2)
    return {
        "rough path": lambda s: rp.solve(V, X, np.ones(2), rp.Davie(), save_at=s),
        "driver": lambda s: rp.solve(V, drv, np.ones(2), rp.Davie(), save_at=s),
        "executor": lambda s: rp.solve(V, X, np.ones(2), rp.Davie(), save_at=s, executor=pool, chunks=2),
        "adaptive": lambda s: rp.solve(V, tree, np.ones(2), rp.Davie(), save_at=s,
                                       step_control=rp.PIController(rtol=1e-2, atol=1e-2)),
    }, pool


@pytest.fixture(scope="module")
def routes():
    r, pool = _routes()
    yield r
    pool.shutdown()


@pytest.mark.parametrize("route", ["rough path", "driver", "executor", "adaptive"])
def test_unsorted_times_are_refused_on_every_route(routes, route):
    with pytest.raises(ValueError, match=MESSAGE):
        routes[route](UNSORTED)
    with pytest.raises(ValueError, match=r"save_at must be a 1-D array of times, got shape \(2, 2\)"):
        routes[route](np.array([[0.0, 0.25], [0.5, 0.75]]))


@pytest.mark.parametrize("route", ["rough path", "driver", "executor"])
def test_increasing_times_give_the_states_of_save_all_at_those_times(routes, route):
    full = routes[route]("all")
    sol = routes[route]([0.25, 0.25, 0.5, 1.0])
    np.testing.assert_array_equal(sol.times, [0.25, 0.5, 1.0])
    np.testing.assert_array_equal(sol.states, full.states[..., [2, 4, 8], :])
    single = routes[route](0.5)
    np.testing.assert_array_equal(single.states, full.states[..., [4], :])


def test_adaptive_steps_hit_increasing_times(routes):
    sol = routes["adaptive"]([0.25, 0.5, 1.0])
    np.testing.assert_allclose(sol.times, [0.25, 0.5, 1.0], rtol=0, atol=1e-12)
