"""Work sharing for the compiled kernels (private; :func:`parallel_ranges` is public as
:func:`roughpaths.validation.parallel_ranges`).

:func:`run` executes ``fn(lo, hi)`` over a list of item ranges on persistent worker threads. The
kernels release the GIL. Ranges are taken from a shared counter by whoever is free, *including the
calling thread*, and the call returns as soon as every range is done: a worker that the OS has not
scheduled yet (a busy machine) simply finds nothing left to do, so the call never waits for it, and
at worst waits for one range that a descheduled thread had started. Small jobs run on the calling
thread only (no thread hand-off at all).

Hand-off: a worker that has finished a job keeps polling for the next one for :data:`SPIN_NS`
nanoseconds in compiled code, without the GIL, before it sleeps on a condition variable. Waking a
sleeping thread took 40-100 us on this project's 2-core machines (a halted virtual CPU must be woken);
a polling worker joins a new job in about 25 us (the GIL hand-off), as TBB's and OpenMP's workers do.
Jobs below :data:`SERIAL_WORK` still stay on the caller: splitting them (tried at a quarter of it) was no
faster alone and slower beside a CPU-bound process (a worker that takes a range and is then descheduled
delays the whole call).

The split into ranges never changes a result: every item is computed by the same code whatever
thread runs it. The number of threads is numba's (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``),
read by the calling thread for each job.
"""

from __future__ import annotations

import itertools
import os
import platform
import threading
import time

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

__all__ = ["run", "ranges", "parallel_ranges"]

#: Below this much work (roughly, floating-point operations) a job stays on the calling thread.
SERIAL_WORK = 1 << 20
#: Target work per range (enough to amortise a hand-off of a few tens of microseconds).
RANGE_WORK = 1 << 17
#: How long an idle worker polls for the next job before it sleeps (nanoseconds).
SPIN_NS = 1_000_000

_X86 = platform.machine().lower() in ("x86_64", "amd64", "i386", "i686")


@intrinsic
def _load_acquire(typingctx, arr):
    """``arr[0]`` of an int64 array as an atomic (acquire) load: re-read from memory at every call."""
    sig = types.int64(arr)

    def codegen(context, builder, signature, args):
        ary = context.make_array(signature.args[0])(context, builder, args[0])
        val = builder.load_atomic(ary.data, "acquire", 8)
        if _X86:                            # the spin-wait hint (frees the core's pipeline while polling)
            pause = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), []),
                                                   "llvm.x86.sse2.pause")
            builder.call(pause, [])
        return val

    return sig, codegen


@numba.njit(cache=True, nogil=True)
def _poll(gen, seen, polls):
    """Return ``gen[0]`` as soon as it differs from ``seen``, or ``seen`` after ``polls`` reads."""
    for _ in range(polls):
        g = _load_acquire(gen)
        if g != seen:
            return g
    return seen


class _Job:
    """One :func:`run` call: its ranges, a shared counter, and up to ``helpers`` workers beside the caller."""

    __slots__ = ("fn", "parts", "counter", "remaining", "helpers", "lock", "done", "errors")

    def __init__(self, fn, parts, helpers):
        self.fn, self.parts, self.helpers = fn, parts, helpers
        self.counter = itertools.count()
        self.remaining = len(parts)
        self.lock = threading.Lock()
        self.done = threading.Event()
        self.errors: list = []

    def join(self) -> bool:
        """A worker asks to help; False once ``helpers`` workers have joined."""
        with self.lock:
            if self.helpers <= 0:
                return False
            self.helpers -= 1
            return True

    def work(self) -> None:
        while not self.done.is_set():
            i = next(self.counter)
            if i >= len(self.parts):
                return
            try:
                self.fn(*self.parts[i])
            except BaseException as exc:      # re-raised in the caller
                self.errors.append(exc)
            with self.lock:
                self.remaining -= 1
                if self.remaining == 0:
                    self.done.set()


class _Workers:
    """Daemon worker threads that take jobs posted by :func:`run` (state dropped in a forked child)."""

    def __init__(self):
        self.gen = np.zeros(1, dtype=np.int64)          # bumped for every posted job
        self.cond = threading.Condition()
        self.active: list = []                          # jobs with ranges possibly left
        self.threads: list = []
        self.polls = 0

    def ensure(self, n: int) -> None:
        with self.cond:
            if not self.polls:
                seen = int(self.gen[0])
                _poll(self.gen, seen, 1)                # compile (or load) the poll loop once
                t0 = time.perf_counter_ns()
                _poll(self.gen, seen, 100_000)
                per = max((time.perf_counter_ns() - t0) / 100_000, 0.1)
                self.polls = max(int(SPIN_NS / per), 1)
            while len(self.threads) < n:
                t = threading.Thread(target=self._main, name=f"roughpaths-worker-{len(self.threads)}", daemon=True)
                self.threads.append(t)
                t.start()

    def post(self, job: _Job) -> None:
        with self.cond:
            self.active.append(job)
            self.gen[0] += 1
            self.cond.notify_all()

    def retire(self, job: _Job) -> None:
        with self.cond:
            self.active.remove(job)

    def _main(self) -> None:
        seen = int(self.gen[0])
        while True:
            g = int(_poll(self.gen, seen, self.polls))  # without the GIL
            if g == seen:
                with self.cond:
                    while int(self.gen[0]) == seen:
                        self.cond.wait()
                    g = int(self.gen[0])
            seen = g
            with self.cond:
                jobs = list(self.active)
            for job in jobs:
                if job.join():
                    job.work()


_WORKERS: _Workers | None = None
_WORKERS_LOCK = threading.Lock()


def _forget_workers() -> None:             # in a forked child the parent's worker threads do not exist
    global _WORKERS, _WORKERS_LOCK
    _WORKERS = None
    _WORKERS_LOCK = threading.Lock()


os.register_at_fork(after_in_child=_forget_workers)


def _workers(n: int) -> _Workers:
    global _WORKERS
    with _WORKERS_LOCK:
        if _WORKERS is None:
            _WORKERS = _Workers()
        _WORKERS.ensure(n)
        return _WORKERS


def ranges(n_items: int, work_per_item: float) -> list:
    """Split ``range(n_items)`` into contiguous ``(lo, hi)`` ranges of about :data:`RANGE_WORK` each."""
    if n_items <= 0:
        return []
    total = n_items * max(work_per_item, 1.0)
    if total < SERIAL_WORK:
        return [(0, n_items)]
    k = int(min(n_items, max(1, total // RANGE_WORK), 64))
    step = -(-n_items // k)
    return [(lo, min(lo + step, n_items)) for lo in range(0, n_items, step)]


def run(fn, parts: list) -> None:
    """Call ``fn(lo, hi)`` for every range in ``parts``, shared between the caller and the workers."""
    if len(parts) <= 1:                     # decided before asking numba (its query costs ~5 us)
        for lo, hi in parts:
            fn(lo, hi)
        return
    threads = numba.get_num_threads()
    if threads <= 1:
        for lo, hi in parts:
            fn(lo, hi)
        return
    helpers = min(threads - 1, len(parts) - 1)
    workers = _workers(threads - 1)
    job = _Job(fn, parts, helpers)
    workers.post(job)
    try:
        job.work()
        job.done.wait()
    finally:
        workers.retire(job)
    if job.errors:
        raise job.errors[0]


def parallel_ranges(fn, n_items: int, block: int) -> None:
    """Call ``fn(lo, hi)`` for the ranges ``[0, block), [block, 2 block), ...`` of ``range(n_items)`` on
    numba's threads, the calling thread included (public as :func:`roughpaths.validation.parallel_ranges`).

    For compiled kernels that release the GIL (``numba.njit(nogil=True)``) and compute each item by the
    same code whatever range it is in, so that the result never depends on the number of threads
    (``numba.set_num_threads``, ``NUMBA_NUM_THREADS``). Plain Python threads, persistent, that poll for
    the next job for a millisecond before they sleep (so a job of a few hundred microseconds is worth
    splitting), and are dropped in a forked child: safe under ``fork``, when called from several threads
    at once and from inside ``fn`` (unlike numba's OpenMP ``prange``). Exceptions raised by ``fn`` are
    re-raised in the caller.

    Parameters
    ----------
    fn : callable
        ``fn(lo, hi)``, writing its results for items ``lo .. hi-1``.
    n_items : int
    block : int
        Items per range (positive).

    Examples
    --------
    >>> import numpy as np
    >>> out = np.zeros(10)
    >>> def fill(lo, hi):
    ...     out[lo:hi] = np.arange(lo, hi) ** 2
    >>> parallel_ranges(fill, 10, 3)
    >>> out.tolist() == [float(i * i) for i in range(10)]
    True
    """
    if isinstance(block, bool) or not isinstance(block, int) or block < 1:
        raise ValueError(f"block must be a positive int (items per range), got {block!r}.")
    run(fn, [(lo, min(lo + block, n_items)) for lo in range(0, max(int(n_items), 0), block)])
