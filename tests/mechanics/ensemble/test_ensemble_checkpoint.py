"""Ensemble checkpoints: a run killed at any moment and started again gives the uninterrupted result.

Statement: ``run_ensemble(..., checkpoint=f)`` saves the statistics merged so far atomically after every
chunk; a rerun with the same arguments resumes from ``f``, and its result (every count, mean and scatter
matrix, the snapshots and the final states) is bitwise that of a run that was never interrupted, whether
the first run was stopped by an exception or killed with SIGKILL. A checkpoint of another run is refused,
including one of a run with another observable; an observable (or system) that cannot be identified
across processes (a lambda) is refused with checkpoint=...; a completed run removes its checkpoint unless
``keep_checkpoint=True``. (Untrusted and tampered files, and user code: test_checkpoint_untrusted.py.)
"""

import os
import signal
import subprocess
import sys
import textwrap
import time
from unittest import mock

import numpy as np
import pytest

import mechanics
import mechanics.ensemble.run as ens
import roughpaths as rp

BODY = dict(inertia=[1.0, 2.0, 3.0], sigma=0.2, theta=0.5)
KW = dict(dt=0.01, n_steps=60, n_paths=300, seed=3, keep_final=True, chunk_size=25, record_every=20,
          levy_area="davie")


def _same(a, b):
    for x, y in [(a.final, b.final), (a.time_average, b.time_average)] + list(zip(a.snapshots, b.snapshots)):
        assert x.count == y.count
        np.testing.assert_array_equal(x.mean, y.mean)
        np.testing.assert_array_equal(x.scatter, y.scatter)
    np.testing.assert_array_equal(a.final_states, b.final_states)


def _reference():
    return mechanics.run_ensemble(mechanics.rigid_body(**BODY), [0.0, 0.6, 0.8], **KW)


def test_resume_after_an_exception_is_bitwise(tmp_path):
    ck = tmp_path / "ck.npz"
    calls = {"n": 0}
    original = ens._run_chunk

    def interrupted(spec, a, b):
        calls["n"] += 1
        if calls["n"] == 5:
            raise KeyboardInterrupt
        return original(spec, a, b)

    body = mechanics.rigid_body(**BODY)
    with mock.patch.object(ens, "_run_chunk", interrupted):
        with pytest.raises(KeyboardInterrupt):
            mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, **KW)
    assert ck.exists()
    calls["n"] = 0
    with mock.patch.object(ens, "_run_chunk", lambda *a: (calls.__setitem__("n", calls["n"] + 1), original(*a))[1]):
        resumed = mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, **KW)
    assert calls["n"] == 12 - 4                                  # only the unfinished chunks ran again
    _same(resumed, _reference())


def test_checkpoint_of_another_run_is_refused(tmp_path):
    ck = tmp_path / "ck.npz"
    body = mechanics.rigid_body(**BODY)
    mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, keep_checkpoint=True, **dict(KW, n_paths=50))
    with pytest.raises(ValueError, match="belongs to a run with other arguments"):
        mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, **dict(KW, seed=4, n_paths=50))


SCRIPT = textwrap.dedent("""
    import sys
    import mechanics
    kw = dict(dt=0.01, n_steps=60, n_paths=300, seed=3, keep_final=True, chunk_size=25, record_every=20,
              levy_area="davie")
    res = mechanics.run_ensemble(mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.2, theta=0.5), [0.0, 0.6, 0.8],
                                 checkpoint=sys.argv[1], **kw)
    import roughpaths
    roughpaths.save(res, sys.argv[2])
""")


def test_sigkill_at_random_moments_then_resume_is_bitwise(tmp_path):
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    ck, out = tmp_path / "ck.npz", tmp_path / "result"
    rng = np.random.default_rng(0)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.getcwd()] + sys.path))
    kills = 0
    for _ in range(3):
        proc = subprocess.Popen([sys.executable, str(script), str(ck), str(out)], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        deadline = time.monotonic() + 60
        while not ck.exists() and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(float(rng.uniform(0.0, 0.3)))
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            kills += 1
        proc.wait()
    final = subprocess.run([sys.executable, str(script), str(ck), str(out)], env=env, capture_output=True,
                           text=True, timeout=300)
    assert final.returncode == 0, final.stderr
    assert kills >= 1
    assert not [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp")]       # no half-written files
    _same(rp.load(tmp_path / "result.npz"), _reference())


def _double(x):
    return 2.0 * np.asarray(x)


def _identity_obs(x):
    return np.asarray(x, dtype=float)


def test_another_observable_is_another_run_and_lambdas_are_refused(tmp_path):
    """User observables need code_version (test_checkpoint_untrusted.py); under the same code_version, another
    function is still another run, and a lambda, which does not pickle, is refused whatever the version."""
    ck = tmp_path / "ck.npz"
    body = mechanics.rigid_body(**BODY)
    kw = dict(KW, n_paths=50, code_version="1")
    mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, keep_checkpoint=True, observable=_identity_obs,
                           **kw)
    with pytest.raises(ValueError, match="belongs to a run with other arguments"):
        mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, observable=_double, **kw)
    for fn in (lambda x: x, lambda x: 2 * x):
        with pytest.raises(ValueError, match="observable=.*cannot be identified across runs.*module level"):
            mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=tmp_path / "other.npz", observable=fn, **kw)
    assert not (tmp_path / "other.npz").exists()


def test_a_completed_run_removes_its_checkpoint_unless_kept(tmp_path):
    ck = tmp_path / "ck.npz"
    body = mechanics.rigid_body(**BODY)
    mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, **dict(KW, n_paths=50))
    assert not ck.exists()
    mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, keep_checkpoint=True, **dict(KW, n_paths=50))
    assert ck.exists()


def test_a_damaged_checkpoint_names_the_file(tmp_path):
    ck = tmp_path / "ck.npz"
    body = mechanics.rigid_body(**BODY)
    mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, keep_checkpoint=True, **dict(KW, n_paths=50))
    with np.load(ck) as data:
        arrays = {k: data[k] for k in data.files if k != "final_mean"}
    np.savez(ck, **arrays)
    with pytest.raises(ValueError, match="ck.npz.*incomplete or damaged.*delete it"):
        mechanics.run_ensemble(body, [0.0, 0.6, 0.8], checkpoint=ck, **dict(KW, n_paths=50))
