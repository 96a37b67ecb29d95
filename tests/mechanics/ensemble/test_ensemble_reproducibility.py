"""Ensembles: per-path reproducible random streams and exact streaming statistics.

Claims checked:
* path ``i`` is path ``i`` of ``roughpaths.BrownianDriver(..., seed=seed)``: the same seed gives
  bit-identical paths *and statistics* whatever the chunk size, the time-block length, the executor
  (serial, threads, processes) or the number of paths simulated (a path does not depend on the
  others), for every Lévy-area method, and different seeds differ;
* the Welford/Chan running moments equal numpy's mean/covariance for any split of the data
  (hypothesis);
* the time-average and snapshot statistics equal those recomputed from the stored trajectories
  of an independent, direct simulation with the same noise.
"""

from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from mechanics.ensemble import (
    RunningMoments,
    moment_observable,
    run_ensemble,
    split_moment_features,
)
from mechanics.systems.rigid_body import rigid_body

RB = rigid_body([1.0, 2.0, 3.0], sigma=0.4, s=np.array([[0, 0, 1.0], [0, 0, 0], [-1.0, 0, 0]]), theta=0.5)
KW = dict(dt=0.01, n_steps=60, n_paths=70, seed=2024, burn_in=20, record_every=15, keep_final=True)  # > 1 leaf


def _same(a, b):
    assert np.array_equal(a.final_states, b.final_states)
    for x, y in ((a.final, b.final), (a.time_average, b.time_average)):
        assert x.count == y.count
        assert np.array_equal(x.mean, y.mean)
        assert np.array_equal(x.covariance, y.covariance)
    assert np.array_equal(a.snapshot_times, b.snapshot_times)
    assert len(a.snapshots) == len(b.snapshots)
    for x, y in zip(a.snapshots, b.snapshots):
        assert np.array_equal(x.mean, y.mean) and np.array_equal(x.scatter, y.scatter)


def test_same_seed_same_paths_whatever_the_chunking():
    ref = run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=70, **KW)
    for chunk in (3, 64, 65):
        _same(ref, run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=chunk, **KW))
    other = run_ensemble(RB, [0.0, 0.0, 1.0], **{**KW, "seed": 2025})
    assert not np.allclose(other.final_states, ref.final_states)
    # a path does not depend on how many others are simulated
    few = run_ensemble(RB, [0.0, 0.0, 1.0], **{**KW, "n_paths": 5}, chunk_size=2)
    assert np.array_equal(few.final_states, ref.final_states[:5])
    # nor does the time-block length
    blk = run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=5, block_steps=17, **KW)
    _same(ref, blk)


def test_executors_give_identical_results():
    ref = run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=3, **KW)
    with ThreadPoolExecutor(max_workers=2) as ex:
        _same(ref, run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=3, executor=ex, **KW))
    with ProcessPoolExecutor(max_workers=2) as ex:
        _same(ref, run_ensemble(RB, [0.0, 0.0, 1.0], chunk_size=4, executor=ex, **KW))


@pytest.mark.parametrize("levy_area", ["davie", "foster"])
def test_sampled_levy_area_streams_are_reproducible(levy_area):
    kw = {**KW, "n_steps": 30, "burn_in": 0, "record_every": 10}
    a = run_ensemble(RB, [0.0, 0.0, 1.0], levy_area=levy_area, chunk_size=70, block_steps=30, **kw)
    b = run_ensemble(RB, [0.0, 0.0, 1.0], levy_area=levy_area, chunk_size=9, block_steps=7, **kw)
    _same(a, b)
    with ThreadPoolExecutor(max_workers=2) as ex:
        _same(a, run_ensemble(RB, [0.0, 0.0, 1.0], levy_area=levy_area, chunk_size=33, executor=ex, **kw))
    c = run_ensemble(RB, [0.0, 0.0, 1.0], levy_area=None, chunk_size=5, block_steps=20, **kw)
    assert not np.array_equal(a.final_states, c.final_states)       # the area does enter the step


def test_statistics_match_a_direct_simulation():
    """Recompute every statistic from full trajectories driven by the same per-path noise."""
    from mechanics.integrators import LieHeun
    from roughpaths import BrownianDriver, solve

    n_paths, n_steps, dt, burn = 6, 90, 0.01, 30
    res = run_ensemble(RB, [0.0, 0.0, 1.0], dt=dt, n_steps=n_steps, n_paths=n_paths, seed=7,
                       burn_in=burn, record_every=45, chunk_size=4, block_steps=25, keep_final=True)
    X = BrownianDriver(3, seed=7, dt=dt, n_steps=n_steps, batch_shape=(n_paths,), levy_area=None).rough_path()
    traj = solve(RB, X, np.array([0.0, 0.0, 1.0]), LieHeun()).states    # (P, N+1, 3); level-1 X
    assert np.allclose(traj[:, -1], res.final_states, rtol=0, atol=1e-13)
    f = moment_observable(traj)                                               # (P, N+1, 9)
    tavg = f[:, burn + 1:].mean(axis=1)
    assert np.allclose(res.time_average.mean, tavg.mean(0), atol=1e-13)
    assert np.allclose(res.time_average.covariance, np.cov(tavg.T), atol=1e-13)
    assert np.allclose(res.final.mean, f[:, -1].mean(0), atol=1e-13)
    assert np.allclose(res.snapshot_times, [0.0, 0.45, 0.9])
    for t_idx, snap in zip((0, 45, 90), res.snapshots):
        assert np.allclose(snap.mean, f[:, t_idx].mean(0), atol=1e-13)
    # strided time averages: steps n > burn with n % 4 == 0, across block boundaries
    res4 = run_ensemble(RB, [0.0, 0.0, 1.0], dt=dt, n_steps=n_steps, n_paths=n_paths, seed=7,
                        burn_in=burn + 1, average_every=4, chunk_size=4, block_steps=25)
    steps = [n for n in range(1, n_steps + 1) if n > burn + 1 and n % 4 == 0]
    assert np.allclose(res4.time_average.mean, f[:, steps].mean(axis=1).mean(0), atol=1e-13)
    # a user observable goes through the generic path
    res_e = run_ensemble(RB, [0.0, 0.0, 1.0], dt=dt, n_steps=n_steps, n_paths=n_paths, seed=7,
                         burn_in=burn, observable=_energy_like, chunk_size=4, block_steps=25)
    assert np.allclose(res_e.time_average.mean, _energy_like(traj[:, burn + 1:]).mean(axis=1).mean(0), atol=1e-13)
    mean, m2, se, se2 = res.moments("final")
    assert np.allclose(mean, traj[:, -1].mean(0), atol=1e-13)
    assert np.allclose(m2, np.einsum("pi,pj->ij", traj[:, -1], traj[:, -1]) / n_paths, atol=1e-13)
    assert np.allclose(se, traj[:, -1].std(0, ddof=1) / np.sqrt(n_paths), atol=1e-13)


def _energy_like(x):
    return np.stack([0.5 * (x[..., 0] ** 2 + x[..., 1] ** 2 / 2 + x[..., 2] ** 2 / 3), x[..., 2] ** 3], axis=-1)


def test_per_path_initial_states():
    rng = np.random.default_rng(0)
    mu0 = rng.standard_normal((5, 3))
    mu0 /= np.linalg.norm(mu0, axis=1, keepdims=True)
    a = run_ensemble(RB, mu0, dt=0.01, n_steps=10, n_paths=5, seed=1, chunk_size=2, keep_final=True)
    b = run_ensemble(RB, mu0[3], dt=0.01, n_steps=10, n_paths=5, seed=1, chunk_size=2, keep_final=True)
    assert np.array_equal(a.final_states[3], b.final_states[3])
    assert np.allclose(np.linalg.norm(a.final_states, axis=1), 1.0, atol=1e-13)


@given(st.lists(st.integers(1, 9), min_size=1, max_size=6), st.integers(0, 2**31 - 1))
def test_running_moments_merge_equals_numpy(sizes, seed):
    rng = np.random.default_rng(seed)
    data = rng.standard_normal((sum(sizes), 4)) * [1.0, 10.0, 1e-3, 1e4] + [5.0, -3.0, 1e6, 0.0]
    parts = np.split(data, np.cumsum(sizes)[:-1])
    acc = RunningMoments(4)
    for p in parts:
        acc.merge(RunningMoments(4).update(p))
    assert acc.count == len(data)
    assert np.allclose(acc.mean, data.mean(0), rtol=1e-12, atol=1e-9)
    if len(data) > 1:
        assert np.allclose(acc.covariance, np.cov(data.T), rtol=1e-9, atol=1e-12 * np.abs(data).max() ** 2)


def test_split_moment_features_roundtrip():
    x = np.array([[1.0, 2.0, 3.0]])
    m, m2 = split_moment_features(moment_observable(x), 3)
    assert np.array_equal(m, x) and np.array_equal(m2[0], np.outer(x[0], x[0]))


@pytest.mark.parametrize("kwargs, exc, word", [
    (dict(dt=-0.1), ValueError, "dt"),
    (dict(n_steps=0), ValueError, "n_steps"),
    (dict(n_paths=2.5), TypeError, "n_paths"),
    (dict(seed=-1), ValueError, "seed"),
    (dict(seed=1.5), TypeError, "seed"),
    (dict(levy_area="exact"), ValueError, "levy_area"),
    (dict(executor=object()), TypeError, "executor"),
    (dict(mu0=np.zeros((3, 3))), ValueError, "mu0"),
    (dict(observable=3), TypeError, "observable"),
])
def test_bad_input(kwargs, exc, word):
    base = dict(mu0=[0.0, 0.0, 1.0], dt=0.01, n_steps=5, n_paths=2, seed=0)
    base.update(kwargs)
    mu0 = base.pop("mu0")
    with pytest.raises(exc, match=word):
        run_ensemble(RB, mu0, **base)
