"""Invariance of the Brownian driver's numbers, for every Lévy-area method.

Statement: for each ``levy_area`` in ``{None, "davie", "foster", "exact", "fourier",
"mrongowius-rossler", "wiktorsson", "auto"}`` the increments and areas of path ``i`` depend only
on the seed, ``i`` and the method: the same bits whatever the time blocks, the subset of paths
generated together (``select``), the process that generates them, and whatever batch split and
executor :func:`roughpaths.solve` uses. The reference is always the driver's whole
``rough_path()`` computed serially in this process.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

from roughpaths import BrownianDriver, Heun, LinearVectorFields, LogODE, solve

METHODS = [None, "davie", "foster", "exact", "fourier", "mrongowius-rossler", "wiktorsson", "auto"]


def _driver(method, batch_shape=(3, 3)):
    # d = 2 for "exact" (its only dimension); d = 3 otherwise, so that the Fourier samplers'
    # d >= 3 layouts are covered; a non-uniform grid makes the error-controlled methods pick
    # different truncations on different steps
    d = 2 if method == "exact" else 3
    times = np.cumsum(np.r_[0.0, np.tile([0.02, 0.005, 0.03], 7)])
    return BrownianDriver(d, seed=np.random.SeedSequence(2024, spawn_key=(5,)), times=times,
                          batch_shape=batch_shape, levy_area=method)


def _rows(drv, idx):
    X = drv.select(idx).rough_path()
    return X.increments, (None if X.areas is None else X.areas)


@pytest.fixture(scope="module")
def pool():
    with ProcessPoolExecutor(2) as ex:
        yield ex


@pytest.mark.parametrize("method", METHODS)
def test_blocks_selection_and_processes_give_the_same_bits(method, pool):
    drv = _driver(method)
    X = drv.rough_path()
    inc = X.increments.reshape(9, 21, -1)
    areas = None if X.areas is None else X.areas.reshape(9, 21, drv.dim, drv.dim)
    for K in (1, 4, 21):
        blocks = list(drv.blocks(K))
        np.testing.assert_array_equal(np.concatenate([b.increments for b in blocks], axis=-2), X.increments)
        if areas is not None:
            np.testing.assert_array_equal(np.concatenate([b.areas for b in blocks], axis=-3), X.areas)
    groups = [[8, 0], [3], [1, 2, 4, 5, 6, 7]]
    for idx, (i_sub, a_sub) in zip(groups, pool.map(_rows, [drv] * 3, groups)):
        np.testing.assert_array_equal(i_sub, inc[idx])
        if areas is not None:
            np.testing.assert_array_equal(a_sub, areas[idx])
        i_loc, a_loc = _rows(drv, idx)                     # the same subset in this process
        np.testing.assert_array_equal(i_loc, i_sub)
        if areas is not None:
            np.testing.assert_array_equal(a_loc, a_sub)


@pytest.mark.parametrize("method", METHODS)
def test_solve_split_over_executors_gives_the_serial_bits(method):
    drv = _driver(method, batch_shape=(7,))
    d = drv.dim
    rng = np.random.default_rng(3)
    fields = LinearVectorFields(0.4 * rng.standard_normal((d, 2, 2)))
    y0 = np.array([1.0, -0.5])
    scheme = Heun() if method is None else LogODE()           # LogODE consumes the areas
    ref = solve(fields, drv.rough_path(), y0, scheme)
    serial = solve(fields, drv, y0, scheme, block_steps=5)
    np.testing.assert_array_equal(serial.states, ref.states)
    with ThreadPoolExecutor(2) as ex:
        split = solve(fields, drv, y0, scheme, executor=ex, chunks=3, block_steps=2)
    np.testing.assert_array_equal(split.states, ref.states)
