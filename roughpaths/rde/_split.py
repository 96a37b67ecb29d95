"""Splitting a fixed-step :func:`~roughpaths.solve` over an executor: groups of members, bitwise the serial result."""

from __future__ import annotations

import numpy as np

from ..drivers.base import Driver
from ..paths.rough_path import RoughPath
from ..progress import progress_reporter
from ..validation import as_float_array, check_same_batch
from .solution import NonFiniteStateError, Solution, _failure_message


def _chunk_of(driver, batch, lo, hi):
    """Members ``lo:hi`` of the flattened batch of ``driver`` (broadcast to ``batch``)."""
    if isinstance(driver, RoughPath):
        n, d = driver.n_steps, driver.dim
        inc = np.broadcast_to(driver.increments, batch + (n, d)).reshape((-1, n, d))[lo:hi]
        areas = None
        if driver.areas is not None:
            areas = np.broadcast_to(driver.areas, batch + (n, d, d)).reshape((-1, n, d, d))[lo:hi]
        x0 = np.broadcast_to(driver.x0, batch + (d,)).reshape((-1, d))[lo:hi]
        return RoughPath(inc, areas, times=driver.times, x0=x0, kind=driver.kind, check=False)
    if driver.batch_shape != batch:
        raise ValueError(f"with executor=, a lazy driver's batch shape {driver.batch_shape} must be the "
                         f"batch shape of the solve {batch}; give y0 without extra batch axes.")
    if not hasattr(driver, "select"):
        raise TypeError(f"executor= needs to split the driver's batch, but {type(driver).__name__} has no "
                        f"select(paths) method; materialise it with driver.rough_path() or solve serially.")
    return driver.select(np.arange(lo, hi))


def _solve_split(solve, fields, driver, y0, solver, executor, chunks, progress, **kw):
    """``solve`` (passed in: this module sits below it) over groups of members on ``executor``."""
    import os

    from ..validation import check_positive_int

    if not hasattr(executor, "submit"):
        raise TypeError(f"executor must be a concurrent.futures.Executor (e.g. ProcessPoolExecutor(), or a "
                        f"Dask client's get_executor()), got {type(executor).__name__}.")
    if not isinstance(driver, (RoughPath, Driver)):
        raise TypeError(f"driver must be a RoughPath or a Driver, got {type(driver).__name__}.")
    y = as_float_array(y0, "y0", min_ndim=1)
    batch = check_same_batch(y.shape[:-1], driver.batch_shape, "y0", "driver")
    members = int(np.prod(batch, dtype=np.int64))
    if kw["drift"] is not None:
        fields = fields.with_drift(kw["drift"])
    kw["drift"] = None
    if members == 0:
        return solve(fields, driver, y0, solver, progress=progress, **kw)
    n_chunks = min(members, 4 * (os.cpu_count() or 1)) if chunks is None else check_positive_int(chunks, "chunks")
    bounds = np.linspace(0, members, min(n_chunks, members) + 1).round().astype(int)
    yflat = np.broadcast_to(y, batch + y.shape[-1:]).reshape((-1, y.shape[-1]))
    mode, kw["on_failure"] = kw["on_failure"], "mask"
    report = progress_reporter(progress, driver.n_steps * members, desc="solve", unit="member-steps")
    futures = [executor.submit(solve, fields, _chunk_of(driver, batch, lo, hi), yflat[lo:hi], solver, **kw)
               for lo, hi in zip(bounds[:-1], bounds[1:])]
    parts = []
    try:
        for hi, f in zip(bounds[1:], futures):       # in group order: each finished group reports its members
            parts.append(f.result())
            if report is not None:
                report.update(driver.n_steps * int(hi))
    finally:
        if report is not None:
            report.close()
    states = np.concatenate([s.states for s in parts], axis=0).reshape(batch + parts[0].states.shape[-2:])
    failed = np.concatenate([s.failed_step for s in parts]).reshape(batch)
    if mode == "raise" and (failed >= 0).any():
        msg, mem, steps = _failure_message(failed, np.asarray(driver.times), batch)
        raise NonFiniteStateError(msg, mem, steps)
    stats = {"solver": repr(solver), "n_steps": driver.n_steps, "n_blocks": sum(s.stats["n_blocks"] for s in parts),
             "batch_shape": batch, "chunks": len(parts),
             "wall_time": max(s.stats["wall_time"] for s in parts)}
    return Solution(times=parts[0].times, states=states, failed_step=failed, stats=stats)
