"""Benchmark: fractional Brownian motion sampling and its level-3 lift (``roughpaths.drivers.fractional``).

Times, as medians of several repeats:

* ``fbm``: ``paths x steps`` (default 1000 x 4096) exact fBM values, ``H = 0.3``, ``d = 1`` and ``2``
  (Davies–Harte); reference in the same run: ``normals``, drawing as many standard normals as the sampler
  consumes (``2K`` per series: a floor, the sampler must draw them);
* ``lift3``: the level-3 piecewise-linear lift of that batch (``d = 2``) onto ``steps / m`` coarse steps,
  ``m = 16, 64``; reference: ``iisignature.sig`` of the same segments (one call on the stacked batch).

Usage::

    python benchmarks/bench_fbm.py [--paths 1000] [--steps 4096] [--repeats 5]

Targets (issue 14): sampling under 1 s, the level-3 lift under 2 s. The machine is shared: compare the
ratios within one run.
"""

from __future__ import annotations

import argparse

import numpy as np

from _timing import median_time

from roughpaths import fbm, piecewise_linear_lift


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=4096)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    P, K, r = a.paths, a.steps, a.repeats
    print(f"fBM, {P} paths x {K} steps, H = 0.3 (median of {r})")
    for d in (1, 2):
        t = median_time(lambda: fbm(K, 0.3, rng=1, dim=d, batch_shape=(P,)), r, warmup=True)
        rng = np.random.default_rng(1)
        n_normals = ((P * d + 1) // 2) * 2 * 2 * K
        tn = median_time(lambda: rng.standard_normal(n_normals), r)
        print(f"  d={d}: fbm {t:.3f} s | normals floor {tn:.3f} s (ratio {t / tn:.2f})")
    B = fbm(K, 0.3, rng=2, dim=2, batch_shape=(P,))
    try:
        import iisignature
    except ImportError:  # pragma: no cover - optional peer
        iisignature = None
    print("level-3 lift of that batch (d = 2)")
    for m in (16, 64):
        t = median_time(lambda: piecewise_linear_lift(B, m, level=3), r, warmup=True)
        line = f"  m={m:3d} ({K // m} coarse steps): lift3 {t:.3f} s"
        if iisignature is not None:
            st = B.strides
            seg = np.lib.stride_tricks.as_strided(B, shape=(P, K // m, m + 1, 2),
                                                  strides=(st[0], m * st[1], st[1], st[2]))
            seg = np.ascontiguousarray(seg)
            ti = median_time(lambda: iisignature.sig(seg, 3), r)
            line += f" | iisignature.sig on the segments {ti:.3f} s (ratio {ti / t:.2f})"
        print(line)


if __name__ == "__main__":
    main()
