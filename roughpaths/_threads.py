"""Work sharing for the compiled kernels (private; :func:`parallel_ranges` is public as
:func:`roughpaths.validation.parallel_ranges`).

:func:`run` executes ``fn(lo, hi)`` over a list of item ranges on persistent worker threads. The
kernels release the GIL. Ranges are taken from a shared counter by whoever is free, *including the
calling thread*, and the call returns as soon as every range is done: a worker that the OS has not
scheduled yet (a busy machine) simply finds nothing left to do, so the call never waits for it, and
at worst waits for one range that a descheduled thread had started. Small jobs run on the calling
thread only (no thread hand-off at all).

Hand-off. A worker that finishes a job watches for the next one for a short while (:data:`LINGER` rounds of
``sched_yield``, about 0.1 ms here) before it sleeps, and the caller watches for its workers' last ranges in the
same way (for up to 5 ms, :data:`FINISH`) before it sleeps: waking a sleeping thread cost 35-170 us on this
2-core machine (a virtual CPU wakes from idle), against 5-26 us for a watching one. A worker idles without the
GIL (:func:`_idle`: it watches, then sleeps on Linux's futex; elsewhere on a condition), and asks for the GIL
only for a job still open to it (from the caller's first range until its last range is taken) and only after the
caller is likely to have let go of it (:data:`SETTLE`): a thread that asks for a GIL held by another sleeps
until it is released, and pays the wake-up again. So a worker woken too late for its job does not take the GIL
from the caller, and one that finished the job's last range tells the caller once it has let go of the GIL.
Calls in quick succession (a training loop, a benchmark, an adaptive solve's walks) find their workers awake; a
lone call pays the wake-up once. Watching costs CPU time only, never results, and yields the core to any other
runnable thread. Measured (a compiled kernel over two ranges, a 1 ms pause and an untimed call before each timed
one, medians of 61, three interleaved processes each, before :data:`FINISH` was raised): 2 x 25 us took 55 us
split (63-75 before the GIL-free idling; 50 serial), 2 x 50 us 72-109 (110-137; 100), 2 x 100 us 121-144
(143-148; 200).

The split into ranges never changes a result: every item is computed by the same code whatever
thread runs it. The number of threads is numba's (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``).
"""

from __future__ import annotations

import itertools
import os
import platform
import sys
import threading

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

__all__ = ["run", "ranges", "parallel_ranges"]

#: Below this much work (roughly, floating-point operations) a job stays on the calling thread.
SERIAL_WORK = 1 << 20
#: The serial threshold of estimates counted in units of about 0.23 ns of one core here (the signature kernels'
#: and the tensor algebra's rows): about 0.12 ms. Since idle workers wait without the GIL, a split pays from about
#: 0.1 ms (the measurements in :func:`roughpaths.signatures._engine._parts_plan` and
#: :func:`roughpaths.algebra.flat._log_work`).
SPLIT_WORK = SERIAL_WORK / 2
#: Target work per range (enough to amortise a hand-off of a few tens of microseconds).
RANGE_WORK = 1 << 17
#: Rounds of ``sched_yield`` (0.2-0.4 us each here) a thread watches for a job or its end before it sleeps;
#: 0 where the C library has no ``sched_yield`` (watching then never compiles).
LINGER = 500 if hasattr(os, "sched_yield") else 0
#: Rounds (about 5 ms here) the caller watches for its workers' last ranges before it sleeps. A caller that slept
#: there woke 100-250 us after the job was done, by when its worker had stopped watching for the next job: the next
#: call then waited for a sleeping worker too, and so on (16 paths at d = 3, depth 6 split over two lane groups, a
#: 1 ms pause and an untimed call before each timed one: 17-19 of 61 calls took 0.55-0.65 ms instead of ~0.4 ms
#: with 500 rounds, 0-1 of 61 with this). The wait is for a range already running, so the watch is short.
FINISH = 25000 if LINGER else 0
#: Rounds a worker still waits after it saw a job open, before it asks for the GIL: the caller opens the job right
#: before its own first range and holds the GIL until that range's kernel starts (1-3 us); a worker asking for the
#: GIL before that sleeps until the caller lets go of it, and waking it costs 10-50 us here. Two ranges of 50 / 100 us
#: (1 ms pause, untimed call, timed call; medians of 101, two runs): 106-108 / 134 us against 113-114 / 139 without.
SETTLE = 8
#: Linux's ``futex`` system call (its number; -1 elsewhere): idle workers sleep on the open job's word and are woken
#: without the GIL, so a worker woken late (after the job it was woken for was done) keeps watching for the next one
#: instead of waiting for the GIL. Elsewhere they sleep on a condition.
_FUTEX = ({"x86_64": 202, "aarch64": 98}.get(platform.machine(), -1)
          if LINGER and sys.platform.startswith("linux") and sys.byteorder == "little" else -1)
_FUTEX_WAIT, _FUTEX_WAKE = 128, 129            # FUTEX_WAIT_PRIVATE, FUTEX_WAKE_PRIVATE

_sched_yield = types.ExternalFunction("sched_yield", types.int32())
_syscall = types.ExternalFunction("syscall", types.int64(types.int64, types.uintp, types.int64, types.int64,
                                                         types.uintp))


def _int64_array(a) -> bool:
    return isinstance(a, types.Array) and a.dtype == types.int64


@intrinsic
def _read_acquire(typingctx, flag):
    """``flag[0]`` of an int64 array, read with acquire ordering. Another thread stores there while this one reads:
    for a plain load that race is undefined, and a compiler may hoist the load out of a loop (only the opaque C call
    in :func:`_watch`'s loop keeps it there); an atomic read is never hoisted or merged."""
    if not _int64_array(flag):
        return None

    def codegen(context, builder, signature, args):
        data = context.make_array(signature.args[0])(context, builder, args[0]).data
        return builder.load_atomic(data, "acquire", 8)
    return types.int64(flag), codegen


def _atomic(op: str):
    """An intrinsic ``f(flag, value)``: ``flag[0] <- op(flag[0], value)`` of an int64 array, atomically, as a full
    barrier (later reads are not moved before it); returns the old value."""
    @intrinsic
    def rmw(typingctx, flag, value):
        if not (_int64_array(flag) and isinstance(value, types.Integer)):
            return None

        def codegen(context, builder, signature, args):
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            v = context.cast(builder, args[1], signature.args[1], types.int64)
            return builder.atomic_rmw(op, data, v, "seq_cst")
        return types.int64(flag, value), codegen
    return rmw


_exchange = _atomic("xchg")      # flag[0] = value
_add = _atomic("add")            # flag[0] += value


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _watch(flag, value, rounds):
    """Whether ``flag[0]`` leaves ``value`` within ``rounds`` rounds of ``sched_yield``, without the GIL.
    Compiled with :func:`_idle` (its cost there)."""
    for _ in range(rounds):
        if _read_acquire(flag) != value:
            return True
        _sched_yield()
    return _read_acquire(flag) != value


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _idle(opened, sleepers, last, rounds, settle, signal, futex):
    """A worker between jobs, without the GIL: raise ``signal[0]`` (the flag of the job it just finished, if any: its
    caller watching the flag then finds the GIL free), then return the number of the next job opened
    (``opened[0]`` not 0 nor ``last``) after watching ``rounds`` rounds of ``sched_yield`` and then sleeping on
    Linux's futex until woken; with ``futex < 0``, 0 after the watch (the worker then sleeps on a condition).
    Compile: with :func:`_open` and :func:`_watch`, 0.5 s cold on the first call split over threads (0.3 s for
    :func:`_watch` alone before), cached (``bench_first_call.py``, "parallel_ranges (work sharing)")."""
    if signal.shape[0]:
        _exchange(signal, 1)
    while True:
        for _ in range(rounds):
            v = _read_acquire(opened)
            if v != 0 and v != last:
                for _ in range(settle):
                    _sched_yield()
                return v
            _sched_yield()
        if futex < 0:
            return 0
        _add(sleepers, 1)
        v = _read_acquire(opened)              # after the count: an opener that did not see it stored first
        if v == 0 or v == last:
            _syscall(futex, opened.ctypes.data, _FUTEX_WAIT, v & 0xFFFFFFFF, 0)
        _add(sleepers, -1)


@numba.njit(cache=True, nogil=True, no_cfunc_wrapper=True)
def _open(opened, sleepers, job, futex):
    """Open job number ``job`` to the workers, and wake those asleep on the futex (the library's flags: it lets go of
    the GIL for its fraction of a microsecond, a watching worker waits :data:`SETTLE` rounds before it asks)."""
    _exchange(opened, job)
    if futex >= 0 and _read_acquire(sleepers) > 0:
        _syscall(futex, opened.ctypes.data, _FUTEX_WAKE, 0x7FFFFFFF, 0)


class _Job:
    """One call of :func:`run`: its ranges, taken in turn by the caller and by at most ``helpers`` workers. The job
    is open to the workers from the caller's first range until its last range is taken."""

    def __init__(self, fn, parts, helpers, workers, number):
        self.fn, self.parts, self.helpers, self.workers, self.number = fn, parts, helpers, workers, number
        self.next, self.left = itertools.count(), len(parts)
        self.lock, self.flag = threading.Lock(), np.zeros(1, dtype=np.int64)
        self.done = None                   # an Event, made only when the caller sleeps (making one costs ~3 us)
        self.errors: list = []

    def work(self) -> bool:
        """Run ranges until none is left (exceptions are kept for the caller); whether this thread finished the
        job's last range."""
        last = False
        while (i := next(self.next)) < len(self.parts):
            if i == 0:
                self.workers.open(self.number)
            if i == len(self.parts) - 1:
                self.workers.close(self.number)
            try:
                self.fn(*self.parts[i])
            except BaseException as exc:      # re-raised in the caller
                self.errors.append(exc)
            with self.lock:
                self.left -= 1
                if self.left == 0:
                    last = True
                    if self.done is not None:
                        self.done.set()
        return last

    def help(self) -> np.ndarray:
        """A worker joins, if the job still takes helpers (numba's thread count of the caller); the flag the worker
        raises once it has let go of the GIL if it finished the job's last range, else :data:`_NOTHING`."""
        with self.lock:
            if self.helpers <= 0:
                return _NOTHING
            self.helpers -= 1
        return self.flag if self.work() else _NOTHING

    def wait(self) -> None:
        """Return when every range is done, and let go of ``fn`` (and the arrays its closure holds): a worker may
        still hold the job object (a late helper finds no range left)."""
        if self.left and not (LINGER and _watch(self.flag, 0, FINISH)):
            with self.lock:
                if self.left:
                    self.done = threading.Event()
            if self.done is not None:
                self.done.wait()
        self.parts, self.fn = (), None


#: ``signal`` of :func:`_idle` when there is nothing to raise.
_NOTHING = np.zeros(0, dtype=np.int64)


class _Workers:
    """The worker threads of a process and the job they are offered (the latest posted; an older job's
    ranges are finished by its own caller)."""

    def __init__(self):
        self.threads: list = []
        self.cond = threading.Condition()         # where workers sleep without the futex
        self.sleeping = 0
        self.opened = np.zeros(1, dtype=np.int64)  # the number of the job open to the workers, or 0
        self.sleepers = np.zeros(1, dtype=np.int64)  # workers asleep on the futex
        self.numbers = itertools.count(1)
        self.job = None

    def post(self, fn, parts: list, helpers: int, workers: int) -> _Job:
        if len(self.threads) < workers:
            with self.cond:
                if LINGER and not self.threads:         # compiled (or loaded) here, not on a worker
                    _watch(self.opened, -1, 0)
                    _open(np.zeros(1, dtype=np.int64), np.zeros(1, dtype=np.int64), 0, -1)
                    _idle(np.ones(1, dtype=np.int64), self.sleepers, 0, 1, 0, _NOTHING, -1)
                while len(self.threads) < workers:
                    t = threading.Thread(target=self._serve, name=f"roughpaths-sig-{len(self.threads)}", daemon=True)
                    self.threads.append(t)
                    t.start()
        job = _Job(fn, parts, helpers, self, next(self.numbers))
        self.job = job
        return job

    def open(self, number: int) -> None:
        if LINGER:
            _open(self.opened, self.sleepers, number, _FUTEX)
        else:
            self.opened[0] = number
        if self.sleeping:                                   # read after the store: a worker counted itself first
            with self.cond:
                self.cond.notify_all()

    def close(self, number: int) -> None:
        if self.opened[0] == number:
            self.opened[0] = 0

    def _serve(self) -> None:
        last, signal = 0, _NOTHING
        while True:
            if LINGER:
                number = _idle(self.opened, self.sleepers, last, LINGER, SETTLE, signal, _FUTEX)
            else:
                number = 0
                signal[:] = 1
            signal = _NOTHING
            if number == 0:                                 # no futex: sleep on the condition
                with self.cond:
                    self.sleeping += 1
                    while int(self.opened[0]) in (0, last):
                        self.cond.wait()
                    self.sleeping -= 1
                number = int(self.opened[0])
            last = number
            job = self.job
            if job is not None and job.number == number:
                signal = job.help()
            job = None                     # not kept while watching or asleep (wait() frees the job's own arrays)


_WORKERS = _Workers()


def _forget_workers() -> None:             # in a forked child the parent's worker threads do not exist
    global _WORKERS
    _WORKERS = _Workers()


os.register_at_fork(after_in_child=_forget_workers)


def ranges(n_items: int, work_per_item: float, serial_work: float = SERIAL_WORK) -> list:
    """Split ``range(n_items)`` into contiguous ``(lo, hi)`` ranges of about :data:`RANGE_WORK` each; one range
    below ``serial_work`` in all."""
    if n_items <= 0:
        return []
    total = n_items * max(work_per_item, 1.0)
    if total < serial_work:
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
    job = _WORKERS.post(fn, parts, min(threads - 1, len(parts) - 1), threads - 1)
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
