"""``run_ensemble(progress=...)``: one report per chunk, in paths, and the same bits as a silent run.

Claims: a callable gets one :class:`roughpaths.ProgressRecord` per chunk with ``done`` the paths merged so far
(the chunk ends, in path order, serially and on an executor), the last ``done == total == n_paths``, finite
``eta``; the results (every statistic and the final states) are bitwise those of ``progress=None``. A run
resumed from its checkpoint starts at the checkpoint's paths and extrapolates the time left from its own
rate; a callback that raises stops the run (and leaves the checkpoint of the chunks done). A bad
``progress`` is a ``TypeError`` naming it, raised before any work.
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import mechanics

BODY = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5)
KW = dict(dt=0.01, n_steps=30, n_paths=70, seed=5, chunk_size=16, record_every=10, keep_final=True,
          levy_area="davie")
MU0 = [0.0, 0.6, 0.8]
ENDS = [16, 32, 48, 64, 70]


def _same(a, b):
    for x, y in [(a.final, b.final), (a.time_average, b.time_average)] + list(zip(a.snapshots, b.snapshots)):
        assert x.count == y.count
        assert np.array_equal(x.mean, y.mean) and np.array_equal(x.scatter, y.scatter)
    assert np.array_equal(a.final_states, b.final_states)


def _check(records, ends, total):
    assert [r.done for r in records] == ends
    assert all(r.total == total for r in records)
    assert all(b.elapsed >= a.elapsed for a, b in zip(records, records[1:]))
    assert all(math.isfinite(r.eta) and r.eta >= 0 for r in records) and records[-1].eta == 0.0


def test_one_report_per_chunk_and_the_same_bits(capsys):
    ref = mechanics.run_ensemble(BODY, MU0, **KW)
    seen = []
    got = mechanics.run_ensemble(BODY, MU0, progress=seen.append, **KW)
    _same(got, ref)
    _check(seen, ENDS, 70)
    for r in seen[:-1]:
        assert r.eta == pytest.approx(r.elapsed * (70 - r.done) / r.done, rel=1e-12, abs=1e-300)
    _same(mechanics.run_ensemble(BODY, MU0, progress=True, **KW), ref)
    assert "run_ensemble" in capsys.readouterr().err


def test_executor_reports_in_path_order():
    ref = mechanics.run_ensemble(BODY, MU0, **KW)
    seen = []
    with ThreadPoolExecutor(2) as pool:
        got = mechanics.run_ensemble(BODY, MU0, executor=pool, progress=seen.append, **KW)
    _same(got, ref)
    _check(seen, ENDS, 70)


def test_resume_starts_at_the_checkpoint(tmp_path):
    ck = tmp_path / "ck.npz"

    class Stop(Exception):
        pass

    def stop_after_two_chunks(record):
        if record.done >= 32:
            raise Stop

    with pytest.raises(Stop):
        mechanics.run_ensemble(BODY, MU0, checkpoint=ck, progress=stop_after_two_chunks, **KW)
    assert ck.exists()                                   # the callback ran after the second chunk was saved
    seen = []
    got = mechanics.run_ensemble(BODY, MU0, checkpoint=ck, progress=seen.append, **KW)
    _same(got, mechanics.run_ensemble(BODY, MU0, **KW))
    _check(seen, ENDS[2:], 70)
    first = seen[0]                                      # the rate of this run: 16 paths in first.elapsed
    assert first.eta == pytest.approx(first.elapsed * (70 - 48) / 16, rel=1e-12, abs=1e-300)


def test_bad_progress_is_refused_before_work(monkeypatch):
    import mechanics.ensemble.run as run

    def no_work(*args):
        raise AssertionError("a chunk ran")

    monkeypatch.setattr(run, "_run_chunk", no_work)
    for bad in (1, "tqdm", 0.0):
        with pytest.raises(TypeError, match=r"progress must be None, False, True or a callable"):
            mechanics.run_ensemble(BODY, MU0, progress=bad, **KW)
