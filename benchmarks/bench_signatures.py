"""Benchmark: level-2 and level-4 signatures against iisignature and esig (same run, same data).

Cases (d = 3, float64):
  (a) one path of 100,000 points;
  (b) 1,000 paths of 1,000 points (iisignature takes the batch through its leading axes; esig
      has no batch API and is timed on a subset of paths, then scaled).

Prints medians over repeats and same-run ratios. For level 2 it also prints the time of a
streaming read of the same input (``np.sum`` and a parallel numba sum), i.e. how close the fused
level-2 kernel is to memory-bound. Finally it measures a warm import + first call in a fresh
subprocess (numba cache populated by this run).

Targets (issue 2): level 2 at least 10x faster than iisignature on (a) and (b); level 4 at least
as fast as iisignature; warm import + first call < 1 s.

Usage: ``python benchmarks/bench_signatures.py [--repeats 7] [--quick]``
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

import numpy as np
from _timing import median_time as _median_time


def median_time(fn, repeats: int) -> float:
    return _median_time(fn, repeats, warmup=True)   # warm-up: compilation, caches


def warm_start_seconds() -> tuple:
    code = (
        "import time; t0 = time.perf_counter()\n"
        "import numpy as np\n"
        "from roughpaths.signature import signature\n"
        "t1 = time.perf_counter()\n"
        "x = np.random.default_rng(0).standard_normal((10, 100, 3))\n"
        "signature(x, 2); t2 = time.perf_counter(); signature(x, 4); t3 = time.perf_counter()\n"
        "import resource; r = resource.getrusage(resource.RUSAGE_SELF)\n"
        "print(t1 - t0, t2 - t1, t3 - t2, r.ru_utime + r.ru_stime)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    return tuple(float(v) for v in out.stdout.split())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--quick", action="store_true", help="smaller sizes (smoke test)")
    args = parser.parse_args()

    import esig
    import iisignature
    import numba

    from roughpaths import _signature_kernels as kern
    from roughpaths.signature import signature

    rng = np.random.default_rng(12345)
    scale = 10 if args.quick else 1
    cases = {
        "(a) 1 x 100,000": np.cumsum(rng.standard_normal((100_000 // scale, 3)), axis=0),
        "(b) 1,000 x 1,000": np.cumsum(rng.standard_normal((1_000 // scale, 1_000, 3)), axis=-2),
    }
    esig_subset = 20 if not args.quick else 5
    print(f"numba threads: {numba.get_num_threads()}, repeats: {args.repeats}, cpu count: {os.cpu_count()}")
    print(f"{'case':<20}{'level':>6}{'ours [ms]':>12}{'iisig [ms]':>12}{'esig [ms]':>12}"
          f"{'iisig/ours':>12}{'esig/ours':>11}")
    rows = []
    for name, x in cases.items():
        batched = x.ndim == 3
        for depth in (2, 4):
            t_ours = median_time(lambda: signature(x, depth), args.repeats)
            t_ii = median_time(lambda: iisignature.sig(x, depth), args.repeats)
            if batched:
                sub = x[:esig_subset]
                t_es = median_time(lambda: [esig.stream2sig(p, depth) for p in sub], max(1, args.repeats // 2))
                t_es *= x.shape[0] / sub.shape[0]
            else:
                t_es = median_time(lambda: esig.stream2sig(x, depth), max(1, args.repeats // 2))
            err = float(np.max(np.abs(signature(x, depth) - iisignature.sig(x, depth))
                               / (1.0 + np.abs(iisignature.sig(x, depth)))))
            rows.append((name, depth, t_ours, t_ii, t_es, err))
            print(f"{name:<20}{depth:>6}{1e3 * t_ours:>12.3f}{1e3 * t_ii:>12.3f}{1e3 * t_es:>12.1f}"
                  f"{t_ii / t_ours:>12.1f}{t_es / t_ours:>11.0f}   (max rel. diff vs iisig {err:.1e})")
        flat = np.ascontiguousarray(x).reshape(-1)
        kern.stream_sum(flat)
        t_sum = median_time(lambda: np.sum(flat), args.repeats)
        t_nsum = median_time(lambda: kern.stream_sum(flat), args.repeats)
        t2 = [r[2] for r in rows if r[0] == name and r[1] == 2][0]
        print(f"{'':<20}streaming read of the input ({flat.nbytes / 1e6:.1f} MB): np.sum {1e3 * t_sum:.3f} ms, "
              f"numba parallel sum {1e3 * t_nsum:.3f} ms -> level 2 takes {t2 / min(t_sum, t_nsum):.1f}x "
              f"a streaming read")

    # single-thread view of the same kernels (the 2-core machine is shared; shows what parallelism adds)
    threads = numba.get_num_threads()
    if threads > 1:
        numba.set_num_threads(1)
        for name, x in cases.items():
            for depth in (2, 4):
                t1 = median_time(lambda: signature(x, depth), args.repeats)
                tp = [r[2] for r in rows if r[0] == name and r[1] == depth][0]
                print(f"single thread: {name:<20} level {depth}: {1e3 * t1:.3f} ms "
                      f"(iisig/ours {[r[3] for r in rows if r[0] == name and r[1] == depth][0] / t1:.1f}, "
                      f"{threads} threads {1e3 * tp:.3f} ms)")
        numba.set_num_threads(threads)

    t_imp, t_first2, t_first4, cpu = warm_start_seconds()
    print(f"warm start in a fresh process: import {t_imp:.3f} s, first level-2 call {t_first2:.3f} s, "
          f"first level-4 call {t_first4:.3f} s, total {t_imp + t_first2 + t_first4:.3f} s wall, "
          f"{cpu:.3f} s CPU (target < 1 s; wall time counts waiting for the shared cores)")

    print("targets:")
    for name, depth, t_ours, t_ii, _, _ in rows:
        need = 10.0 if depth == 2 else 1.0
        ok = "met" if t_ii / t_ours >= need else "NOT met"
        print(f"  {name:<20} level {depth}: iisig/ours = {t_ii / t_ours:.1f} (target >= {need:g}) {ok}")


if __name__ == "__main__":
    main()
