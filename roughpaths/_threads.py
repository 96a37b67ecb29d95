"""Work sharing for the compiled kernels (private; :func:`parallel_ranges` is public as
:func:`roughpaths.validation.parallel_ranges`).

:func:`run` executes ``fn(lo, hi)`` over a list of item ranges on persistent worker threads. The
kernels release the GIL. Ranges are taken from a shared counter by whoever is free, *including the
calling thread*, and the call returns as soon as every range is done: a worker that the OS has not
scheduled yet (a busy machine) simply finds nothing left to do, so the call never waits for it, and
at worst waits for one range that a descheduled thread had started. Small jobs run on the calling
thread only (no thread hand-off at all).

Hand-off. A worker that finishes a job watches for the next one for a short while (:data:`LINGER`
rounds of ``sched_yield``, about 0.1 ms here) before it sleeps on a condition, and the caller watches
for its workers' last ranges in the same way before it sleeps: waking a sleeping thread cost 35-170 us
on this 2-core machine (a virtual CPU wakes from idle), against 5-26 us for a watching one, and a split
job of 0.24 ms paid it twice. Calls in quick succession (a training loop, a benchmark, an adaptive
solve's walks) find their workers awake; a lone call pays the wake-up once, as before. Watching costs
CPU time only, never results, and yields the core to any other runnable thread.

The split into ranges never changes a result: every item is computed by the same code whatever
thread runs it. The number of threads is numba's (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``).
"""

from __future__ import annotations

import itertools
import os
import threading

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

__all__ = ["run", "ranges", "parallel_ranges"]

#: Below this much work (roughly, floating-point operations) a job stays on the calling thread.
SERIAL_WORK = 1 << 20
#: Target work per range (enough to amortise a hand-off of a few tens of microseconds).
RANGE_WORK = 1 << 17
#: Rounds of ``sched_yield`` (0.2-0.4 us each here) a thread watches for a job or its end before it sleeps;
#: 0 where the C library has no ``sched_yield`` (watching then never compiles).
LINGER = 500 if hasattr(os, "sched_yield") else 0

_sched_yield = types.ExternalFunction("sched_yield", types.int32())


@intrinsic
def _read_acquire(typingctx, flag):
    """``flag[0]`` of an int64 array, read with acquire ordering. Another thread stores there while this one reads:
    for a plain load that race is undefined, and a compiler may hoist the load out of a loop (only the opaque C call
    in :func:`_watch`'s loop keeps it there); an atomic read is never hoisted or merged."""
    if not (isinstance(flag, types.Array) and flag.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        return builder.load_atomic(data, "acquire", 8)
    return types.int64(flag), codegen


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _watch(flag, value, rounds):
    """Whether ``flag[0]`` leaves ``value`` within ``rounds`` rounds of ``sched_yield``, without the GIL.
    Compile: 0.1 s cold, on the first call split over threads, cached (``bench_first_call.py``, "parallel_ranges
    (work sharing)": 0.9 s cold with the import, 0.55 s warm)."""
    for _ in range(rounds):
        if _read_acquire(flag) != value:
            return True
        _sched_yield()
    return _read_acquire(flag) != value


class _Job:
    """One call of :func:`run`: its ranges, taken in turn by the caller and by at most ``helpers`` workers."""

    def __init__(self, fn, parts, helpers):
        self.fn, self.parts, self.helpers = fn, parts, helpers
        self.next, self.left = itertools.count(), len(parts)
        self.lock, self.done, self.flag = threading.Lock(), threading.Event(), np.zeros(1, dtype=np.int64)
        self.errors: list = []

    def work(self) -> None:
        """Run ranges until none is left (exceptions are kept for the caller)."""
        while (i := next(self.next)) < len(self.parts):
            try:
                self.fn(*self.parts[i])
            except BaseException as exc:      # re-raised in the caller
                self.errors.append(exc)
            with self.lock:
                self.left -= 1
                if self.left == 0:
                    self.flag[0] = 1
                    self.done.set()

    def help(self) -> None:
        """A worker joins, if the job still takes helpers (numba's thread count of the caller)."""
        with self.lock:
            if self.helpers <= 0:
                return
            self.helpers -= 1
        self.work()

    def wait(self) -> None:
        """Return when every range is done, and let go of ``fn`` (and the arrays its closure holds): a worker may
        still hold the job object (a late helper finds no range left)."""
        if not self.done.is_set() and not (LINGER and _watch(self.flag, 0, LINGER)):
            self.done.wait()
        self.parts, self.fn = (), None


class _Workers:
    """The worker threads of a process and the job they are offered (the latest posted; an older job's
    ranges are finished by its own caller)."""

    def __init__(self):
        self.threads: list = []
        self.cond = threading.Condition()
        self.sleeping = 0
        self.generation = np.zeros(1, dtype=np.int64)       # bumped for every job posted
        self.job = None

    def post(self, job: _Job, workers: int) -> None:
        if len(self.threads) < workers:
            with self.cond:
                if LINGER and not self.threads:
                    _watch(self.generation, -1, 0)           # compiled (or loaded) here, not on a worker
                while len(self.threads) < workers:
                    t = threading.Thread(target=self._serve, name=f"roughpaths-sig-{len(self.threads)}", daemon=True)
                    self.threads.append(t)
                    t.start()
        self.job = job
        self.generation[0] += 1
        if self.sleeping:                                   # read after the bump: a worker counted itself first
            with self.cond:
                self.cond.notify_all()

    def _serve(self) -> None:
        seen = int(self.generation[0])
        while True:
            if not (LINGER and _watch(self.generation, seen, LINGER)):
                with self.cond:
                    self.sleeping += 1
                    while int(self.generation[0]) == seen:
                        self.cond.wait()
                    self.sleeping -= 1
            seen = int(self.generation[0])
            job = self.job
            if job is not None:
                job.help()
            job = None                     # not kept while watching or asleep (wait() frees the job's own arrays)


_WORKERS = _Workers()


def _forget_workers() -> None:             # in a forked child the parent's worker threads do not exist
    global _WORKERS
    _WORKERS = _Workers()


os.register_at_fork(after_in_child=_forget_workers)


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


def run(fn, parts: list, *, merge: bool = False) -> None:
    """Call ``fn(lo, hi)`` for every range in ``parts``, shared between the caller and the workers.

    With ``merge`` (for contiguous ranges, in order, and an ``fn`` whose set-up does not grow with its
    range) one thread calls ``fn`` once over their union instead: each call of a kernel allocates its
    scratch and is dispatched anew (16 ranges of the one-unit signature kernel, d = 10 at depth 3,
    16 x 256 points: ~45 us of 600).
    """
    if len(parts) <= 1:                     # decided before asking numba (its query costs ~5 us)
        for lo, hi in parts:
            fn(lo, hi)
        return
    threads = numba.get_num_threads()
    if threads <= 1:
        if merge:
            fn(parts[0][0], parts[-1][1])
            return
        for lo, hi in parts:
            fn(lo, hi)
        return
    job = _Job(fn, parts, min(threads - 1, len(parts) - 1))
    _WORKERS.post(job, threads - 1)
    job.work()
    job.wait()
    if _WORKERS.job is job:                 # not offered (nor kept) after it is done
        _WORKERS.job = None
    if job.errors:
        raise job.errors[0]


def parallel_ranges(fn, n_items: int, block: int) -> None:
    """Call ``fn(lo, hi)`` for the ranges ``[0, block), [block, 2 block), ...`` of ``range(n_items)`` on
    numba's threads, the calling thread included (public as :func:`roughpaths.validation.parallel_ranges`).

    For compiled kernels that release the GIL (``numba.njit(nogil=True)``) and compute each item by the
    same code whatever range it is in, so that the result never depends on the number of threads
    (``numba.set_num_threads``, ``NUMBA_NUM_THREADS``). Plain Python threads from a persistent pool,
    dropped in a forked child: safe under ``fork`` and when called from several threads at once (unlike
    numba's OpenMP ``prange``). Exceptions raised by ``fn`` are re-raised in the caller.

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
