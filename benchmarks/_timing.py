"""Timing helper shared by the benchmark scripts (run them as ``python benchmarks/bench_*.py``)."""

from __future__ import annotations

import statistics
import time


def median_time(fn, repeats: int = 5, *, warmup: bool = False) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls, in seconds (after one untimed call if ``warmup``).

    The machine is shared and noisy: medians, and ratios taken within one run, are what we quote.
    """
    if warmup:
        fn()
    times = []
    for _ in range(max(1, int(repeats))):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(statistics.median(times))
