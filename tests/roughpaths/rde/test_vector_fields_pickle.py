"""Vector-field families built from module-level callables pickle, and solve runs in a process pool.

Statement: ``pickle.loads(pickle.dumps(V))`` evaluates like ``V`` (fields, Jacobians, drift, brackets,
Friz–Oberhauser drifts, added drifts), and a solve of the unpickled family in another process gives
the same bits as in this one.
"""

import pickle
from concurrent.futures import ProcessPoolExecutor
import multiprocessing

import numpy as np
import pytest

import roughpaths as rp

M = np.array([[[0.0, 1.0, 0.2], [-1.0, 0.0, 0.0], [0.3, 0.0, -0.1]],
              [[0.1, 0.0, 0.0], [0.0, -0.2, 1.0], [0.0, -1.0, 0.0]]])


def f0(y):
    return np.sin(y @ M[0].T)


def f1(y):
    return y * y[..., [1, 2, 0]]


def stacked(y):
    return np.stack([f0(y), f1(y)], axis=-1)


def damping(y):
    return -0.5 * y


def _families():
    s = np.array([[0.0, 0.4], [-0.4, 0.0]])
    lin = rp.LinearVectorFields(M, drift=0.1 * np.eye(3))
    gen = rp.VectorFields([f0, f1], dim_state=3, dim_noise=2, drift=damping)
    one = rp.VectorFields(stacked, dim_state=3, dim_noise=2)
    return {"linear": lin, "linear+FO": lin.with_drift(lin.friz_oberhauser_drift(s)),
            "list": gen, "list+FO": gen.with_drift(gen.friz_oberhauser_drift(s)), "single": one}


@pytest.mark.parametrize("name", list(_families()))
def test_pickle_round_trip_evaluates_identically(name):
    V = _families()[name]
    W = pickle.loads(pickle.dumps(V))
    y = np.random.default_rng(0).standard_normal((4, 3))
    for method in ("fields", "jacobians", "drift", "brackets"):
        np.testing.assert_array_equal(getattr(W, method)(y), getattr(V, method)(y))
    np.testing.assert_array_equal(W.bracket(0, 1)(y), V.bracket(0, 1)(y))


def _solve_final(V, X, y0):
    return rp.solve(V, X, y0, rp.Davie()).final


def test_solve_in_a_process_pool_gives_the_same_bits():
    V = _families()["list+FO"]
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 65), dim=2, rng=np.random.default_rng(1), batch_shape=(3,))
    here = _solve_final(V, X, np.full(3, 0.2))
    with ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as pool:
        there = pool.submit(_solve_final, V, X, np.full(3, 0.2)).result()
    np.testing.assert_array_equal(here, there)


def test_lambda_families_fail_to_pickle_with_pythons_own_error():
    V = rp.VectorFields(lambda y: np.stack([y, y], axis=-1), dim_state=2, dim_noise=2)
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        pickle.dumps(V)


@pytest.mark.parametrize("solver", [rp.Heun(), rp.Davie(), rp.LogODE()], ids=repr)
def test_solve_split_across_an_executor_is_bitwise_serial(solver):
    """solve(..., executor=pool) splits the batch; members are independent, so the bits agree."""
    from concurrent.futures import ThreadPoolExecutor

    V = _families()["list+FO"]
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 33), dim=2, rng=np.random.default_rng(2), batch_shape=(2, 5))
    y0 = np.random.default_rng(3).uniform(0.1, 0.3, (5, 3))
    serial = rp.solve(V, X, y0, solver)
    with ThreadPoolExecutor(max_workers=2) as pool:
        split = rp.solve(V, X, y0, solver, executor=pool, chunks=3)
    np.testing.assert_array_equal(split.states, serial.states)
    assert split.states.shape == (2, 5, 33, 3)


def test_solve_split_on_a_process_pool_names_failures_globally():
    V = rp.LinearVectorFields(M)
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 17), dim=2, rng=np.random.default_rng(4), batch_shape=(6,))
    inc = X.increments.copy()
    inc[4, 3] = np.nan
    Y = rp.RoughPath(inc, X.areas, times=X.times, kind="general", check=False)
    with ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("spawn")) as pool:
        with pytest.raises(rp.NonFiniteStateError, match=r"member \(4,\)"):
            rp.solve(V, Y, np.ones(3), rp.Davie(), executor=pool, chunks=3)
        kept = rp.solve(V, Y, np.ones(3), rp.Davie(), executor=pool, chunks=3, on_failure="mask")
    assert kept.failed_step.tolist() == [-1, -1, -1, -1, 3, -1]
