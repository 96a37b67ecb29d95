"""Benchmark: Brownian increments and Lévy areas (``roughpaths.brownian``).

Times ``brownian_increments_and_areas`` for ``paths × steps`` (default 1000 × 1000), d = 2, 3,
substeps m = 1, 8 (Davie areas), against the increments alone (``levy_area=None``), and prints
medians of several repeats with same-run ratios. Two references explain the numbers:

* ``normals``: the time to draw, with the same ``numpy.random.Generator``, as many standard
  normals as the sampler consumes (``d`` per step for the increments; ``2 m d + d(d-1)/2`` more
  per step for the areas, ``m d + d(d-1)/2`` for ``m = 1``). The sampler must draw exactly these
  numbers in this order (seed reproducibility), so ``normals`` is a floor for its time;
* ``numpy``: the former pure-numpy implementation (batched matmuls, kept here only as a timing
  reference; ``--no-numpy`` skips it, it is the slow part of this script).

Usage::

    python benchmarks/bench_brownian.py [--paths 1000] [--steps 1000] [--repeats 5] [--no-numpy]

The machine is shared: compare ratios within one run, not absolute times across runs.
"""

from __future__ import annotations

import argparse

import numpy as np

from roughpaths.brownian import _CHUNK_FLOATS, brownian_increments_and_areas


from _timing import median_time as _median_time


def _numpy_reference(rng, n_steps, h, d, paths, m):
    """The former implementation (numpy batched products), Davie areas, Stratonovich."""
    dW = rng.standard_normal((paths, n_steps, d)) * np.sqrt(h)
    rows = dW.reshape(-1, d)
    R = rows.shape[0]
    iu = np.triu_indices(d, 1)
    A = np.empty((R, d, d))
    chunk = max(1, _CHUNK_FLOATS // (m * d * 4 + d * d))
    for lo in range(0, R, chunk):
        hi = min(R, lo + chunk)
        W = rows[lo:hi]
        sq = np.sqrt(h / m)
        if m == 1:
            w = W[:, None, :]
        else:
            z = rng.standard_normal((hi - lo, m, d)) * sq
            w = z - z.mean(axis=1, keepdims=True) + W[:, None, :] / m
        H = rng.standard_normal((hi - lo, m, d)) * (sq / np.sqrt(12.0))
        s_excl = np.cumsum(w, axis=-2) - w
        g = np.matmul(np.swapaxes(H + 0.5 * s_excl, -1, -2), w)
        a = g - np.swapaxes(g, -1, -2)
        lam = np.zeros((hi - lo, d, d))
        zz = rng.standard_normal((hi - lo, iu[0].size))
        lam[:, iu[0], iu[1]] = zz
        lam[:, iu[1], iu[0]] = -zz
        A[lo:hi] = a + lam * (h / np.sqrt(12.0 * m))
    return dW, A.reshape(paths, n_steps, d, d) + 0.5 * dW[..., :, None] * dW[..., None, :]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--no-numpy", action="store_true", help="skip the former numpy implementation")
    args = ap.parse_args(argv)
    B, N, h, rep = args.paths, args.steps, 1.0 / args.steps, args.repeats

    brownian_increments_and_areas(np.random.default_rng(0), 2, h, 2, batch_shape=(2,))   # JIT warm-up
    print(f"Brownian increments + Davie Lévy areas, {B} paths x {N} steps, median of {rep} "
          f"(numpy reference: median of {max(1, rep // 2)})")
    print(f"{'d':>2} {'m':>2} | {'incr s':>7} {'areas s':>8} {'normals s':>9} {'numpy s':>8} | "
          f"{'areas/incr':>10} {'areas/normals':>13} {'numpy/areas':>11}")
    for d in (2, 3):
        t_inc = _median_time(lambda: brownian_increments_and_areas(
            np.random.default_rng(1), N, h, d, batch_shape=(B,), levy_area=None), rep)
        for m in (1, 8):
            t_area = _median_time(lambda: brownian_increments_and_areas(
                np.random.default_rng(1), N, h, d, batch_shape=(B,), substeps=m), rep)
            per_step = d + (m * d if m > 1 else 0) + m * d + d * (d - 1) // 2
            buf = np.empty(B * N * per_step)
            t_norm = _median_time(lambda: np.random.default_rng(1).standard_normal(out=buf), rep)
            del buf
            if args.no_numpy:
                t_np, r_np = float("nan"), float("nan")
            else:
                t_np = _median_time(lambda: _numpy_reference(np.random.default_rng(1), N, h, d, B, m),
                                    max(1, rep // 2))
                r_np = t_np / t_area
            print(f"{d:>2} {m:>2} | {t_inc:7.3f} {t_area:8.3f} {t_norm:9.3f} {t_np:8.3f} | "
                  f"{t_area / t_inc:10.1f} {t_area / t_norm:13.2f} {r_np:11.1f}")


if __name__ == "__main__":
    main()
