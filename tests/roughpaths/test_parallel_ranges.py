"""roughpaths.validation.parallel_ranges: every item once, the caller's exceptions, bad block sizes; several
callers at once, nested calls, and a forked child that starts a pool of its own."""

import os
import subprocess
import sys
import threading

import numba
import numpy as np
import pytest

from roughpaths.validation import parallel_ranges


def test_every_item_exactly_once_on_all_threads():
    seen = np.zeros(1000, dtype=np.int64)
    lock = threading.Lock()
    calls = []

    def fn(lo, hi):
        with lock:
            calls.append((lo, hi))
            seen[lo:hi] += 1

    parallel_ranges(fn, 1000, 7)
    assert np.all(seen == 1)
    assert sorted(calls) == [(lo, min(lo + 7, 1000)) for lo in range(0, 1000, 7)]


def test_one_thread_runs_in_order_on_the_caller():
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        calls = []
        parallel_ranges(lambda lo, hi: calls.append((lo, hi, threading.get_ident())), 10, 4)
    finally:
        numba.set_num_threads(threads)
    assert [(lo, hi) for lo, hi, _ in calls] == [(0, 4), (4, 8), (8, 10)]
    assert {t for _, _, t in calls} == {threading.get_ident()}


def test_exception_reaches_the_caller_and_empty_is_a_no_op():
    def fn(lo, hi):
        if lo == 30:
            raise RuntimeError("range 30")

    with pytest.raises(RuntimeError, match="range 30"):
        parallel_ranges(fn, 100, 10)
    parallel_ranges(fn, 0, 10)


@pytest.mark.parametrize("block", [0, -3, 2.5, True])
def test_bad_block_is_refused(block):
    with pytest.raises(ValueError, match="block must be a positive int"):
        parallel_ranges(lambda lo, hi: None, 10, block)


def _fill(n, block):
    out = np.zeros(n, dtype=np.int64)

    def fn(lo, hi):
        out[lo:hi] += np.arange(lo, hi)

    parallel_ranges(fn, n, block)
    return out


def test_several_callers_at_once_and_nested_calls():
    want = np.arange(5000)
    results, errors = [], []

    def caller():
        try:
            for _ in range(20):
                results.append(np.array_equal(_fill(5000, 97), want))
                inner = np.zeros(40, dtype=np.int64)

                def outer(lo, hi):                 # a range that runs a parallel job of its own
                    for i in range(lo, hi):
                        inner[i] = _fill(50, 7).sum()
                parallel_ranges(outer, 40, 3)
                results.append(bool(np.all(inner == 1225)))
        except BaseException as exc:             # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=caller) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "a caller hung"
    assert not errors and len(results) == 160 and all(results)


_FORK_SCRIPT = """
import multiprocessing, numpy as np
from roughpaths.validation import parallel_ranges

def fill():
    out = np.zeros(3000, dtype=np.int64)
    def fn(lo, hi):
        out[lo:hi] += np.arange(lo, hi)
    parallel_ranges(fn, 3000, 11)
    return bool(np.array_equal(out, np.arange(3000)))

def child(q):
    q.put(fill())

if __name__ == "__main__":
    assert fill()                       # the parent's workers exist before the fork
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=child, args=(q,))
    p.start()
    p.join(timeout=120)
    assert p.exitcode == 0 and q.get(timeout=5)
    print("ok")
"""


def test_forked_child_gets_workers_of_its_own(tmp_path):
    """In a fresh interpreter (this one may hold other libraries' threads, which fork does not copy)."""
    script = tmp_path / "fork_child.py"
    script.write_text(_FORK_SCRIPT)
    env = dict(os.environ, NUMBA_NUM_THREADS="2")
    res = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, env=env)
    assert res.returncode == 0 and res.stdout.strip() == "ok", res.stderr


def test_merged_ranges_are_one_call_on_one_thread_and_every_item_once_on_all():
    from roughpaths import _threads

    parts = _threads.ranges(1000, float(_threads.SERIAL_WORK))        # one range per ~RANGE_WORK: many
    assert len(parts) > 2
    before = numba.get_num_threads()
    lock = threading.Lock()
    try:
        # one thread: a single call over the union; several: the ranges as given (each item once)
        for threads, want in ((1, [(0, 1000)]), (before, parts if before > 1 else [(0, 1000)])):
            numba.set_num_threads(threads)
            calls, seen = [], np.zeros(1000, dtype=np.int64)

            def fn(lo, hi):
                with lock:
                    calls.append((lo, hi))
                    seen[lo:hi] += 1

            _threads.run(fn, parts, merge=True)
            assert np.all(seen == 1)
            assert sorted(calls) == want
    finally:
        numba.set_num_threads(before)


def test_watching_sees_another_threads_store():
    """A worker watching for the next job reads the flag anew every round: with the read hoisted out of its loop
    (a compiler may hoist a plain load) the watch below would spin for its 10^9 rounds, minutes, instead of
    returning."""
    from roughpaths import _threads

    if not _threads.LINGER:
        pytest.skip("no sched_yield on this platform: workers sleep at once")
    flag = np.zeros(1, dtype=np.int64)
    seen = []
    t = threading.Thread(target=lambda: seen.append(_threads._watch(flag, 0, 10 ** 9)), daemon=True)
    t.start()
    flag[0] = 1
    t.join(timeout=30)
    assert not t.is_alive() and seen == [True]
    assert _threads._watch(flag, 1, 3) is False and _threads._watch(flag, 0, 0) is True


def test_a_sleeping_worker_is_woken_and_an_awake_one_helps():
    """Range 0 waits for range 1 to start on another thread: only a worker (asleep after a pause, or still
    watching right after a job) can start it, else range 0 gives up after 20 s and the caller runs range 1."""
    import time

    if numba.get_num_threads() < 2:
        pytest.skip("one thread: no workers")
    for pause in (0.2, 0.0):                     # long enough to fall asleep; none: still watching
        started = threading.Event()
        who = {}

        def fn(lo, hi):
            who[lo] = threading.get_ident()
            if lo == 0:
                started.wait(timeout=20)
            else:
                started.set()

        time.sleep(pause)
        parallel_ranges(fn, 2, 1)
        assert who[0] != who[1], f"no worker took range 1 after a pause of {pause} s"


def test_a_finished_job_keeps_nothing_alive():
    """The arrays a job's function holds are freed when the call returns (the workers keep no finished job): a
    signature's scratch of hundreds of MB must not live on until the next parallel call."""
    import gc
    import weakref

    if numba.get_num_threads() < 2:
        pytest.skip("one thread: no workers")

    class Big:
        pass

    big = Big()
    ref = weakref.ref(big)

    def fn(lo, hi, big=big):
        assert big is not None

    parallel_ranges(fn, 8, 1)
    del fn, big
    gc.collect()
    assert ref() is None


def test_no_wake_up_is_lost_whenever_the_job_comes():
    """Jobs posted at every phase of a worker's idling (watching, falling asleep, asleep): each time range 0 waits for
    range 1 to start on another thread, which only a worker can do. A wake-up lost between a worker counting itself
    asleep and the job opening would leave range 0 waiting for its 5 s and the caller running range 1 itself."""
    import time

    if numba.get_num_threads() < 2:
        pytest.skip("one thread: no workers")
    rng = np.random.default_rng(0)
    lost = []
    for pause in rng.uniform(0.0, 4e-4, 150):          # the workers watch for about 1e-4 s, then sleep
        started = threading.Event()
        who = {}

        def fn(lo, hi):
            who[lo] = threading.get_ident()
            if lo == 0:
                if not started.wait(timeout=5):
                    lost.append(pause)
            else:
                started.set()

        time.sleep(pause)
        parallel_ranges(fn, 2, 1)
        if lost:
            break
    assert not lost, f"no worker took range 1 after a pause of {lost[0]:.2e} s"
