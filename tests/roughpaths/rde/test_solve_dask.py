"""``solve`` on a Dask cluster (``client.get_executor()``) is bitwise the serial solve, for any number of groups.

Claim: a ``BrownianDriver`` group sent to a worker (``driver.select``) draws each path's noise from the path's
own stream (seed, path index), so the states do not depend on how the batch is cut, on the workers or on
the cluster; with ``progress=`` the groups report in order and the states are unchanged. The default run
uses in-process workers (a small ``LocalCluster(processes=False)``); the ``slow`` run starts worker
processes, so every task is pickled and the noise is drawn in another interpreter. ``./test.sh`` installs the
``dask`` extra, so under ``CI=true`` a missing ``dask.distributed`` is a failure; elsewhere the test skips.
"""

import os

import numpy as np
import pytest

try:
    import distributed
except ImportError:
    if os.environ.get("CI"):
        raise
    pytest.skip("dask.distributed is not installed (pip install -e '.[dask]')", allow_module_level=True)

import roughpaths as rp  # noqa: E402

M = 0.3 * np.random.default_rng(8).standard_normal((2, 3, 3))
PATHS, STEPS = 23, 40


def _driver():
    return rp.BrownianDriver(2, seed=21, dt=0.025, n_steps=STEPS, batch_shape=(PATHS,), levy_area="davie")


def _check(processes):
    V = rp.LinearVectorFields(M)
    y0 = 1.0 + 0.1 * np.arange(PATHS * 3, dtype=np.float64).reshape(PATHS, 3)     # one initial state per path
    ref = rp.solve(V, _driver(), y0, rp.Davie())
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=processes, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        pool = client.get_executor()
        for chunks in (1, 3, 7, PATHS):
            seen = []
            got = rp.solve(V, _driver(), y0, rp.Davie(), executor=pool, chunks=chunks, progress=seen.append)
            assert got.stats["chunks"] == chunks
            assert np.array_equal(got.states, ref.states) and np.array_equal(got.times, ref.times)
            assert len(seen) == chunks and seen[-1].done == seen[-1].total == STEPS * PATHS
            assert all(b.done > a.done for a, b in zip(seen, seen[1:]))
        # a member solved alone, serially: the same bits as inside any group (its own noise stream)
        alone = rp.solve(V, _driver().select([17]), y0[17], rp.Davie())
        assert np.array_equal(alone.states[0], ref.states[17])


def test_dask_solve_is_bitwise_serial_for_any_groups():
    _check(processes=False)


@pytest.mark.slow
def test_dask_solve_is_bitwise_serial_in_worker_processes():
    _check(processes=True)
