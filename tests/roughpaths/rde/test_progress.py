"""``progress=`` of ``solve``: reports per block of steps (grid) or per accepted step (adaptive), never changes results.

Claims:

* A callable gets one :class:`roughpaths.ProgressRecord` per block of a lazy driver (per finished group with
  ``executor``, per accepted step with adaptive steps); ``done`` increases, the last report has
  ``done == total`` (``N × members`` member-steps on a grid, ``t1 − t0`` with adaptive steps), ``elapsed``
  does not decrease and ``eta`` is finite, ``>= 0``, and the linear extrapolation of the rate so far.
* The solution is bitwise the same with progress off, with a callable and with a bar.
* ``progress=True`` draws ``tqdm`` when it is importable, else a plain line on stderr updated in place
  (``\\r``) and ended by a newline, also when the work stops with an error.
* Off means off: no reporter is built. Anything but None, a bool or a callable is a ``TypeError`` naming
  ``progress``.
"""

from __future__ import annotations

import math
import sys
import types
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import roughpaths as rp
import roughpaths.progress as progress_module

M = 0.3 * np.random.default_rng(5).standard_normal((2, 3, 3))       # two non-commuting linear fields
Y0 = np.ones(3)
PATHS, STEPS, BLOCK = 6, 50, 8


def _driver():
    return rp.BrownianDriver(2, seed=4, dt=0.02, n_steps=STEPS, batch_shape=(PATHS,), levy_area="davie")


def _check_records(records, total):
    done = [r.done for r in records]
    assert len(records) >= 1
    assert all(b > a for a, b in zip(done, done[1:])), done               # strictly increasing
    assert done[-1] == total and all(r.total == total for r in records)
    elapsed = [r.elapsed for r in records]
    assert all(b >= a >= 0.0 for a, b in zip(elapsed, elapsed[1:]))
    assert all(math.isfinite(r.eta) and r.eta >= 0.0 for r in records)
    assert records[-1].eta == 0.0
    for r in records[:-1]:                 # eta: elapsed time per unit done so far, times the units left
        assert r.eta == pytest.approx(r.elapsed * (r.total - r.done) / r.done, rel=1e-12, abs=1e-300)


def test_grid_solve_reports_each_block_and_is_bitwise_unchanged(capsys):
    V = rp.LinearVectorFields(M)
    ref = rp.solve(V, _driver(), Y0, rp.Davie(), block_steps=BLOCK)
    seen = []
    got = rp.solve(V, _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=seen.append)
    bar = rp.solve(V, _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=True)
    assert np.array_equal(got.states, ref.states) and np.array_equal(bar.states, ref.states)
    assert np.array_equal(got.times, ref.times)
    _check_records(seen, STEPS * PATHS)
    # one report per block of BLOCK steps (the last block shorter), in member-steps
    expected = [min(k, STEPS) * PATHS for k in range(BLOCK, STEPS + BLOCK, BLOCK)]
    assert [r.done for r in seen] == expected
    assert got.stats["n_blocks"] == len(seen)
    capsys.readouterr()


def test_rough_path_is_one_block_reported_at_the_end():
    X = rp.RoughPath.from_path(np.cumsum(0.1 * np.random.default_rng(1).standard_normal((3, 20, 2)), axis=-2))
    seen = []
    got = rp.solve(rp.LinearVectorFields(M), X, Y0, rp.LogODE(), progress=seen.append)
    assert np.array_equal(got.states, rp.solve(rp.LinearVectorFields(M), X, Y0, rp.LogODE()).states)
    assert [(r.done, r.total) for r in seen] == [(19 * 3, 19 * 3)]


def test_executor_reports_each_group_in_order():
    V = rp.LinearVectorFields(M)
    ref = rp.solve(V, _driver(), Y0, rp.Davie())
    seen = []
    with ThreadPoolExecutor(2) as pool:
        got = rp.solve(V, _driver(), Y0, rp.Davie(), executor=pool, chunks=3, progress=seen.append)
    assert np.array_equal(got.states, ref.states)
    _check_records(seen, STEPS * PATHS)
    assert [r.done for r in seen] == [STEPS * 2, STEPS * 4, STEPS * 6]        # 6 members in 3 groups


def test_adaptive_solve_reports_the_time_reached_per_accepted_step():
    V = rp.LinearVectorFields(M)
    tree = rp.BrownianTree(2, seed=9, batch_shape=(4,), t0=0.5, t1=2.0)
    ctrl = rp.PIController(1e-2, 1e-2)
    ref = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, shared_steps=True)
    seen = []
    got = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, progress=seen.append, shared_steps=True)
    assert np.array_equal(got.states, ref.states) and np.array_equal(got.times, ref.times)
    assert got.stats["accepted"] == ref.stats["accepted"] == len(seen)
    _check_records(seen, 1.5)
    # save_at="all" keeps every accepted step: the reports are the saved times, less t0
    assert [r.done for r in seen] == pytest.approx(list(got.times[1:] - 0.5), rel=0, abs=1e-15)
    # steps per member: the time every member has reached, reported when it grows
    seen = []
    own = rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl, progress=seen.append)
    _check_records(seen, 1.5)
    assert 0 < len(seen) <= own.stats["accepted"].sum()         # a report needs an accepted step of some member
    assert np.array_equal(own.states, rp.solve(V, tree, Y0, rp.Davie(), step_control=ctrl).states)


def test_bad_progress_is_refused_by_name():
    V = rp.LinearVectorFields(M)
    for bad in (1, "yes", 0.5, [print]):
        with pytest.raises(TypeError, match=r"progress must be None, False, True or a callable.*progress=True"):
            rp.solve(V, _driver(), Y0, rp.Davie(), progress=bad)
    with pytest.raises(TypeError, match="progress must be"):
        rp.solve(V, rp.BrownianTree(2, seed=1), Y0, rp.Davie(), step_control=rp.PIController(1e-2, 1e-2),
                 progress="bar")
    with pytest.raises(TypeError, match="progress must be"), ThreadPoolExecutor(1) as pool:
        rp.solve(V, _driver(), Y0, rp.Davie(), executor=pool, progress=2)


def test_off_builds_no_reporter(monkeypatch):
    """progress=None and False never construct a reporter: the loop only tests one None per block."""
    def refuse(*args, **kwargs):
        raise AssertionError("a reporter was built with progress off")

    monkeypatch.setattr(progress_module.Progress, "__init__", refuse)
    V = rp.LinearVectorFields(M)
    for off in (None, False, np.False_):
        rp.solve(V, _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=off)
        rp.solve(V, rp.BrownianTree(2, seed=1), Y0, rp.Davie(), step_control=rp.PIController(3e-2, 3e-2),
                 progress=off)
    with pytest.raises(AssertionError, match="reporter was built"):    # the spy itself works
        rp.solve(V, _driver(), Y0, rp.Davie(), progress=True)


def test_plain_line_without_tqdm(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)              # import tqdm raises ImportError
    monkeypatch.setattr(progress_module, "REDRAW_INTERVAL", 0.0)
    rp.solve(rp.LinearVectorFields(M), _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=True)
    err = capsys.readouterr().err
    lines = err.split("\r")[1:]
    assert len(lines) >= 2 and err.endswith("\n") and err.count("\n") == 1
    assert lines[0].startswith("solve:   0% 0/300 member-steps")
    assert lines[-1].startswith("solve: 100% 300/300 member-steps") and "00:00 left" in lines[-1]
    widths = [len(line.rstrip("\n")) for line in lines]
    assert widths == sorted(widths)                # a shorter line is padded to cover the longer one before it


def test_plain_line_is_ended_when_the_work_stops(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "tqdm", None)

    def bad_fields(t, y):
        if t > 0.5:
            raise RuntimeError("field failed")
        return np.einsum("iab,...b->...ai", M, y)

    V = rp.VectorFields(bad_fields, lambda t, y: np.broadcast_to(M, y.shape[:-1] + M.shape), dim_state=3,
                        dim_noise=2, time_dependent=True)
    with pytest.raises(RuntimeError, match="field failed"):
        rp.solve(V, _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=True)
    assert capsys.readouterr().err.endswith("\n")


def test_a_raising_callback_stops_the_solve():
    class Stop(Exception):
        pass

    def stop_at_half(record):
        if record.done >= record.total / 2:
            raise Stop

    seen = []
    with pytest.raises(Stop):
        rp.solve(rp.LinearVectorFields(M), _driver(), Y0, rp.Davie(), block_steps=BLOCK,
                 progress=lambda r: (seen.append(r), stop_at_half(r)))
    assert seen[-1].done == 4 * BLOCK * PATHS                     # the first report at or past half of 300


def test_tqdm_gets_the_total_and_the_increments(monkeypatch):
    """With tqdm importable, the bar is tqdm's: its total, and increments that add up to it."""
    made = []

    class FakeBar:
        def __init__(self, total, initial, desc, unit, **options):
            self.total, self.n, self.desc, self.unit, self.closed = total, initial, desc, unit, False
            self.updates = []
            made.append(self)

        def update(self, k):
            self.updates.append(k)
            self.n += k

        def close(self):
            self.closed = True

    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    rp.solve(rp.LinearVectorFields(M), _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=True)
    rp.solve(rp.LinearVectorFields(M), rp.BrownianTree(2, seed=2, t1=3.0), Y0, rp.Davie(),
             step_control=rp.PIController(3e-2, 3e-2), progress=True)
    grid, adaptive = made
    assert (grid.total, grid.n, grid.unit, grid.closed) == (300.0, 300.0, "member-steps", True)
    assert grid.updates == [BLOCK * PATHS] * 6 + [2 * PATHS]
    assert adaptive.total == 3.0 and adaptive.closed and adaptive.unit == "time"
    assert all(k > 0 for k in adaptive.updates) and sum(adaptive.updates) == pytest.approx(3.0, rel=1e-14)


def test_real_tqdm_bar(capsys):
    pytest.importorskip("tqdm")
    rp.solve(rp.LinearVectorFields(M), _driver(), Y0, rp.Davie(), block_steps=BLOCK, progress=True)
    err = capsys.readouterr().err
    assert "solve: 100%" in err and "300/300 member-steps" in err            # tqdm's unit_scale: 300 as is


def test_resumed_work_estimates_from_this_runs_rate():
    seen = []
    with rp.Progress(seen.append, 10.0, desc="x", unit="paths", initial=4.0) as report:
        report.update(6.0)
        report.update(10.0)
    first, last = seen
    assert first.done == 6.0 and first.eta == pytest.approx(first.elapsed * 4.0 / 2.0, rel=1e-12, abs=1e-300)
    assert last.eta == 0.0
    with pytest.raises(ValueError, match=r"initial must lie in \[0, total\]"):
        rp.Progress(seen.append, 10.0, desc="x", unit="paths", initial=11.0)
    with pytest.raises(ValueError, match="total must be finite"):
        rp.progress_reporter(True, math.inf, desc="x", unit="paths")
