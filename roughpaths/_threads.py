"""Work sharing for the compiled kernels (private; :func:`parallel_ranges` is public as
:func:`roughpaths.validation.parallel_ranges`).

:func:`run` executes ``fn(lo, hi)`` over a list of item ranges on a persistent thread pool. The
kernels release the GIL. Ranges are taken from a shared counter by whoever is free, *including the
calling thread*, and the call returns as soon as every range is done: a pool thread that the OS
has not scheduled yet (a busy machine) simply finds nothing left to do, so the call never waits
for it, and at worst waits for one range that a descheduled thread had started. Small jobs run
on the calling thread only (no thread hand-off at all).

The split into ranges never changes a result: every item is computed by the same code whatever
thread runs it. The number of threads is numba's (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``).
"""

from __future__ import annotations

import itertools
import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba

__all__ = ["run", "ranges", "parallel_ranges"]

#: Below this much work (roughly, floating-point operations) a job stays on the calling thread.
SERIAL_WORK = 1 << 20
#: Target work per range (enough to amortise a hand-off of a few tens of microseconds).
RANGE_WORK = 1 << 17

_POOL: ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()


def _forget_pool() -> None:                # in a forked child the parent's pool threads do not exist
    global _POOL, _POOL_LOCK
    _POOL = None
    _POOL_LOCK = threading.Lock()


os.register_at_fork(after_in_child=_forget_pool)


def _pool(workers: int) -> ThreadPoolExecutor:
    global _POOL
    with _POOL_LOCK:
        if _POOL is None or _POOL._max_workers < workers:
            _POOL = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="roughpaths-sig")
        return _POOL


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
    """Call ``fn(lo, hi)`` for every range in ``parts``, shared between the caller and the pool.

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
    counter = itertools.count()
    remaining = [len(parts)]
    lock = threading.Lock()
    done = threading.Event()
    errors: list = []

    def work() -> None:
        while not done.is_set():
            i = next(counter)
            if i >= len(parts):
                return
            try:
                fn(*parts[i])
            except BaseException as exc:      # re-raised in the caller
                errors.append(exc)
            with lock:
                remaining[0] -= 1
                if remaining[0] == 0:
                    done.set()

    pool = _pool(threads - 1)
    for _ in range(min(threads - 1, len(parts) - 1)):
        pool.submit(work)
    work()
    done.wait()
    if errors:
        raise errors[0]


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
