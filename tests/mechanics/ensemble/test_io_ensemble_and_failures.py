"""Save/load round trips for ensemble results and for solutions that kept failed members.

Statement: ``roughpaths.load(roughpaths.save(obj))`` returns, bit for bit, the statistics of an
``EnsembleResult`` (counts, means, scatter matrices of every statistic, snapshot times, final
states) and the ``failed_step`` marks of a ``Solution`` solved with ``on_failure="mask"``.
"""

import numpy as np
import pytest

import mechanics
import roughpaths as rp


def _same_moments(a, b):
    assert a.count == b.count
    np.testing.assert_array_equal(a.mean, b.mean)
    np.testing.assert_array_equal(a.scatter, b.scatter)


def test_ensemble_result_round_trip(tmp_path):
    rb = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.2, theta=0.5)
    res = mechanics.run_ensemble(rb, [0.0, 0.6, 0.8], dt=0.01, n_steps=40, n_paths=12, seed=3, keep_final=True,
                                 record_every=20)
    back = rp.load(rp.save(res, tmp_path / "ens", seed=3, metadata={"note": "test"}))
    _same_moments(back.final, res.final)
    _same_moments(back.time_average, res.time_average)
    assert len(back.snapshots) == len(res.snapshots) > 0
    for a, b in zip(back.snapshots, res.snapshots):
        _same_moments(a, b)
    np.testing.assert_array_equal(back.snapshot_times, res.snapshot_times)
    np.testing.assert_array_equal(back.final_states, res.final_states)
    assert (back.n_paths, back.n_steps, back.dt, back.seed, back.state_dim) == (12, 40, 0.01, 3, 3)
    for x, y in zip(back.moments(), res.moments()):
        np.testing.assert_array_equal(x, y)
    meta = rp.load_metadata(tmp_path / "ens.npz")
    assert meta["type"] == "EnsembleResult" and meta["user"] == {"note": "test"}


def test_solution_keeps_its_failure_marks(tmp_path):
    V = rp.LinearVectorFields(np.array([[[0.0, 1.0], [-1.0, 0.0]]]))
    X = rp.brownian_rough_path(np.linspace(0.0, 1.0, 9), 1, np.random.default_rng(0), batch_shape=(3,))
    inc = X.increments.copy()
    inc[1, 4] = np.nan
    sol = rp.solve(V, rp.RoughPath(inc, X.areas, times=X.times, kind="general", check=False), np.ones(2),
                   rp.Davie(), on_failure="mask")
    back = rp.load(rp.save(sol, tmp_path / "sol"))
    np.testing.assert_array_equal(back.failed_step, [-1, 4, -1])
    np.testing.assert_array_equal(back.states, sol.states)
    assert back.failed.tolist() == [False, True, False]


def test_unregistered_objects_are_refused_with_the_supported_types(tmp_path):
    with pytest.raises(TypeError, match="EnsembleResult"):
        rp.save(object(), tmp_path / "x")


@pytest.mark.parametrize("entry,value,message", [
    ("final_count", np.array(10**6), "not a number of paths from 0 to 12"),
    ("final_count", np.array(-1), "not a number of paths"),
    ("final_mean", None, "non-finite"),
    ("time_average_scatter", None, "not a scatter matrix"),
])
def test_a_tampered_ensemble_file_is_refused(tmp_path, entry, value, message):
    """Files are untrusted input: counts beyond the run's paths, non-finite statistics and a scatter matrix that is
    not one are refused by load (not returned as an EnsembleResult whose standard errors are nonsense)."""
    rb = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.2, theta=0.5)
    res = mechanics.run_ensemble(rb, [0.0, 0.6, 0.8], dt=0.01, n_steps=20, n_paths=12, seed=3)
    path = rp.save(res, tmp_path / "ens")
    with np.load(path) as f:
        arrays = {k: f[k] for k in f.files}
    if value is None and entry.endswith("_mean"):
        value = arrays[entry].copy()
        value[0] = np.nan
    elif value is None:
        value = arrays[entry].copy()
        value[0, 1] += 1.0                                               # no longer symmetric
    arrays[entry] = value
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ValueError, match=message):
        rp.load(tmp_path / "bad.npz")
