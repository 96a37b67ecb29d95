"""Run a compiled block kernel over blocks of paths on a small thread pool (private to the integrators).

:func:`run_blocks` calls ``fn(lo, hi)`` for consecutive ranges of ``block`` paths. The kernels are
compiled with ``nogil=True``; ranges are taken from a shared iterator by whoever is free, the calling
thread included, so a pool thread that the OS has not scheduled yet (a busy machine) costs nothing.
The number of threads is numba's (``numba.set_num_threads``, ``NUMBA_NUM_THREADS``).

Why not ``numba.prange``: with the OpenMP threading layer (numba's default here; TBB is not installed)
a process that forks after a parallel kernel ran cannot run one in the child (GNU OpenMP is not
fork-safe: ``run_ensemble`` with a ``ProcessPoolExecutor`` crashed), and the workqueue layer refuses
concurrent calls from several threads (``run_ensemble`` with a ``ThreadPoolExecutor``). Plain Python
threads over ``nogil`` kernels are safe for both; the pool is dropped in a forked child.
(``roughpaths`` has the same pattern for its signature kernels, private to it.)

A range's result never depends on the thread that ran it: each path is computed by the same code.
"""

from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numba

_POOL: ThreadPoolExecutor | None = None
_LOCK = threading.Lock()


def _forget_pool() -> None:                      # in a forked child: the parent's pool threads do not exist
    global _POOL, _LOCK
    _POOL = None
    _LOCK = threading.Lock()


os.register_at_fork(after_in_child=_forget_pool)


def _pool(workers: int) -> ThreadPoolExecutor:
    global _POOL
    with _LOCK:
        if _POOL is None or _POOL._max_workers < workers:
            _POOL = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="mechanics-coadjoint")
        return _POOL


def run_blocks(fn, n_items: int, block: int) -> None:
    """Call ``fn(lo, hi)`` for the ranges ``[0, block), [block, 2 block), ...`` of ``range(n_items)``,
    on up to ``numba.get_num_threads()`` threads (the caller's included)."""
    parts = [(lo, min(lo + block, n_items)) for lo in range(0, n_items, block)]
    threads = min(numba.get_num_threads(), len(parts))
    if threads <= 1:
        for lo, hi in parts:
            fn(lo, hi)
        return
    todo = iter(parts)
    lock = threading.Lock()

    def work() -> None:
        while True:
            with lock:
                part = next(todo, None)
            if part is None:
                return
            fn(*part)

    futures = [_pool(threads - 1).submit(work) for _ in range(threads - 1)]
    try:
        work()
    finally:
        for f in futures:
            f.result()
