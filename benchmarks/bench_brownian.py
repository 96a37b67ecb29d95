"""Benchmark: Brownian increments and Lévy areas, old samplers against ``roughpaths.BrownianDriver``.

Two tables, same run, medians of ``--repeats`` calls (the machine is shared: read the ratios):

1. **normals** (ns per normal): numpy's ``Generator.standard_normal(out=...)``; the raw-word
   ziggurat ``roughpaths.drivers._random.standard_normal_into`` (same numbers, one generator); the
   per-path streams ``roughpaths.drivers._random.PathStreams`` (numba ``SeedSequence`` + ``PCG64`` +
   ziggurat, one stream per path, the driver's generator), seeding included.
2. **sampling** (ns per path-step, ``paths x steps``, d = 3), for increments only and with
   areas (davie m = 1, foster m = 1, davie m = 8):

   * ``mech-old``: the former fused sampler of mechanics' Brownian simulation (since removed; one generator,
     unit normals step-major into a reused 512 KiB buffer ``(k, P, w)`` by the raw-word ziggurat,
     ``w = 2d + d(d-1)/2`` for davie m = 1); it only drew the normals (the integrator turned them
     into velocities), so it is a floor for any sampler of that stream;
   * ``driver``: ``BrownianDriver(...).blocks()`` iterated to the end (normals, increments and
     areas arrays, the ``RoughPath`` blocks a solver consumes; seeding included);
   * ``wrapper``: ``brownian_increments_and_areas`` (the same stream, whole path materialised).
     (The former ``roughpaths`` sampler, one numpy generator for all paths, was replaced by the
     driver; measured in the same run before its removal: driver/former 0.81 for davie m = 1 and
     0.77 for davie m = 8, d = 3, 1000 x 1000.)

3. d = 2: the driver with Davie's areas against the exact sampler (``levy_area="exact"``).

Usage::

    python benchmarks/bench_brownian.py [--paths 1000] [--steps 1000] [--repeats 5]
"""

from __future__ import annotations

import argparse

import numpy as np

from roughpaths import BrownianDriver
from roughpaths.drivers._random import PathStreams, standard_normal_into
from roughpaths import brownian_increments_and_areas

from _timing import median_time as _median_time

_MECH_BUFFER_BYTES = 1 << 19


def _mech_old(P, N, d, with_area, m=1, method="davie"):
    """The former mechanics fused sampler's random draws (its stream layout, only m = 1 davie existed)."""
    npair = d * (d - 1) // 2
    w = (2 * d + npair) if with_area else d
    rng = np.random.default_rng(1)
    k_max = max(1, min(N, _MECH_BUFFER_BYTES // (8 * P * w)))
    buf = np.empty((k_max, P, w))
    s = 0
    while s < N:
        k = min(k_max, N - s)
        standard_normal_into(rng, buf[:k])
        s += k


def _drive(P, N, d, method, m):
    for _ in BrownianDriver(d, seed=1, dt=1.0 / N, n_steps=N, batch_shape=(P,), levy_area=method,
                            substeps=m).blocks():
        pass


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    P, N, rep = args.paths, args.steps, args.repeats
    d = 3

    # warm-up (JIT, self-checks)
    _drive(2, 3, d, "davie", 2)
    _drive(2, 3, d, "foster", 1)
    _drive(2, 3, 2, "exact", 1)
    _mech_old(2, 3, d, True)
    brownian_increments_and_areas(np.random.default_rng(0), 2, 0.1, d, batch_shape=(2,))

    n = 1 << 22
    buf = np.empty(n)
    chunk = np.empty(_MECH_BUFFER_BYTES // 8)
    t_np = _median_time(lambda: np.random.default_rng(1).standard_normal(out=buf), rep)

    def raw():
        g = np.random.default_rng(1)
        for _ in range(n // chunk.size):
            standard_normal_into(g, chunk)
    t_raw = _median_time(raw, rep)
    keys = np.stack([np.arange(P), np.zeros(P, dtype=np.int64)], axis=1)
    pbuf = np.empty((P, n // P))
    t_ps = _median_time(lambda: PathStreams(np.random.SeedSequence(1), keys).fill(pbuf), rep)
    print(f"standard normals, {n} draws, median of {rep}: ns per normal")
    print(f"  numpy standard_normal {1e9 * t_np / n:6.2f} | raw-word ziggurat {1e9 * t_raw / n:6.2f} "
          f"| PathStreams ({P} streams, seeding incl.) {1e9 * t_ps / pbuf.size:6.2f}")
    print(f"  ratios: numpy/raw {t_np / t_raw:.2f}, numpy/PathStreams {t_np * pbuf.size / (t_ps * n):.2f}")
    del buf, pbuf

    ps = P * N
    print(f"\nsampling, {P} paths x {N} steps, d = {d}: ns per path-step (medians of {rep}); the ratio is the")
    print("median of per-pair ratios, old and new timed alternately (robust to the shared machine's drift)")
    print(f"{'case':>14} | {'mech-old':>8} {'driver':>8} {'wrapper':>8} | {'driver/mech-old':>15}")
    for name, method, m in (("increments", None, 1), ("davie m=1", "davie", 1), ("foster m=1", "foster", 1),
                            ("davie m=8", "davie", 8)):
        has_old = m == 1 and method != "foster"
        t_old, t_new, ratios = [], [], []
        for _ in range(rep):
            if has_old:
                t_old.append(_median_time(lambda: _mech_old(P, N, d, method is not None), 1))
            t_new.append(_median_time(lambda: _drive(P, N, d, method, m), 1))
            if has_old:
                ratios.append(t_new[-1] / t_old[-1])
        t_wr = _median_time(lambda: brownian_increments_and_areas(
            np.random.default_rng(1), N, 1.0 / N, d, batch_shape=(P,), levy_area=method, substeps=m), rep)
        to = float(np.median(t_old)) if has_old else float("nan")
        r = float(np.median(ratios)) if has_old else float("nan")
        print(f"{name:>14} | {1e9 * to / ps:8.1f} {1e9 * float(np.median(t_new)) / ps:8.1f} "
              f"{1e9 * t_wr / ps:8.1f} | {r:15.2f}")
    t_dav = _median_time(lambda: _drive(P, N, 2, "davie", 1), rep)
    t_ex = _median_time(lambda: _drive(P, N, 2, "exact", 1), rep)
    print(f"\nd = 2, driver: davie m=1 {1e9 * t_dav / ps:.1f}, exact {1e9 * t_ex / ps:.1f} ns per path-step "
          f"(exact/davie {t_ex / t_dav:.1f})")


if __name__ == "__main__":
    main()
