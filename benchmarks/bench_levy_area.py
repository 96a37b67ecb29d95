"""Work–precision of the Lévy-area sources against Brownian motion, and area sampling against torchsde.

1. **Work–precision.** A linear Stratonovich SDE in ``R^3`` with ``d = 2, 3, 5`` non-commuting noises,

       dY = A Y dt + Σ_i σ M_i Y ∘ dW^i,   Y_0 = (1, 0.5, -0.3),   T = 1,

   (``M_i``: rotation generators cycled over the noises plus a random shear; seeded). Strong error = RMS
   over paths of ``|Y_T - Y_T^ref|``, where the reference is ``LogODE`` on ``driver.refine(F)``: the same
   Brownian path, ``F`` times finer (``roughpaths.drivers.refinement``). Methods: ``Heun`` (no area; its
   error is measured on the same increments), ``Davie`` with Davie's areas (``levy_area="davie"``, one
   sub-step: not the area of the path), and ``Davie`` / ``LogODE`` with the default areas
   (``levy_area="auto"``: exact for ``d = 2``, Mrongowius–Rößler with error ``h^1.5`` per step for ``d >= 3``). For each, the step count ``N*`` reaching strong error ``1e-3`` is interpolated
   (log–log) on the ladder, or extrapolated with the order fitted on its last three points when the
   ladder stops first (printed as ``~``: the log–log fit over the whole ladder); then the wall time of ``solve`` on a lazy driver at ``N*``
   (sampling included; Heun's driver draws increments only) for a batch of paths, median of repeats.
2. **Sampling throughput.** Path-steps per second for increments + areas: ``BrownianDriver`` blocks
   (``"davie"``; the default ``"auto"``) against torchsde's ``BrownianInterval(
   levy_area_approximation="davie" | "foster")`` queried step by step (how its solvers use it), same run.

Usage: ``python benchmarks/bench_levy_area.py`` (a few minutes), ``--quick`` for a smoke run.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from roughpaths import BrownianDriver, Davie, Heun, LinearVectorFields, LogODE, solve

from _timing import median_time

TOL = 1e-3
Y0 = np.array([1.0, 0.5, -0.3])


def make_fields(d: int, sigma: float) -> LinearVectorFields:
    rng = np.random.default_rng(1234 + d)
    so3 = np.array([[[0, 0, 0], [0, 0, -1], [0, 1, 0]],
                    [[0, 0, 1], [0, 0, 0], [-1, 0, 0]],
                    [[0, -1, 0], [1, 0, 0], [0, 0, 0]]], dtype=float)
    M = sigma * (so3[np.arange(d) % 3] + 0.3 * rng.standard_normal((d, 3, 3)))
    return LinearVectorFields(M, drift=-0.2 * np.eye(3) + 0.1 * rng.standard_normal((3, 3)))


METHODS = {  # name: (solver, levy_area for the error ladder, levy_area for the timing)
    "Heun (no area)": (Heun(), "auto", None),
    "Davie, davie areas": (Davie(), "davie", "davie"),
    "Davie, default areas": (Davie(), "auto", "auto"),
    "LogODE, default areas": (LogODE(), "auto", "auto"),
}


def ladder(V, d, solver, levy_area, paths, factor, n0, n_max, seed=7):
    ns, errs = [], []
    n = n0
    while n <= n_max:
        drv = BrownianDriver(d, seed=seed, dt=1.0 / n, n_steps=n, batch_shape=(paths,), levy_area=levy_area)
        ref = solve(V, drv.refine(factor), Y0, LogODE(), save_at="end").final
        y = solve(V, drv, Y0, solver, save_at="end").final
        ns.append(n)
        errs.append(float(np.sqrt(np.mean(np.sum((y - ref) ** 2, axis=-1)))))
        if errs[-1] < TOL / 2 and len(ns) >= 3:
            break
        n *= 2
    return ns, errs


def steps_for_tol(ns, errs):
    """``(N*, extrapolated)``: log–log interpolation, or the last three points' order beyond the ladder."""
    ln, le = np.log(ns), np.log(errs)
    for k in range(1, len(ns)):
        if errs[k] <= TOL:
            a = (np.log(TOL) - le[k - 1]) / (le[k] - le[k - 1])
            return int(np.ceil(np.exp(ln[k - 1] + a * (ln[k] - ln[k - 1])))), False
    if errs[0] <= TOL:
        return ns[0], False
    slope, icpt = np.polyfit(ln, le, 1)
    return int(np.ceil(np.exp((np.log(TOL) - icpt) / slope))), True


def work_precision(args):
    print(f"work-precision: strong error {TOL:g} at T = 1 (reference: LogODE on driver.refine({args.factor})); "
          f"{args.paths} paths for the errors, {args.batch} for the timings (median of {args.repeats})")
    rows = []
    for d in args.dims:
        V = make_fields(d, args.sigma)
        for name, (solver, la_err, la_time) in METHODS.items():
            n_max = args.n_max_heun if name.startswith("Heun") else args.n_max
            ns, errs = ladder(V, d, solver, la_err, args.paths, args.factor, args.n0, n_max)
            order = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
            nstar, extra = steps_for_tol(ns, errs)
            rng_seed = 99

            def run():
                drv = BrownianDriver(d, seed=rng_seed, dt=1.0 / nstar, n_steps=nstar, batch_shape=(args.batch,),
                                     levy_area=la_time)
                solve(V, drv, Y0, solver, save_at="end")

            t = median_time(run, args.repeats, warmup=True) if nstar <= args.n_time_max else float("nan")
            rows.append((d, name, order, nstar, extra, t, ns, errs))
            print(f"  d={d} {name:20s} order {order:5.2f}  N* {'~' if extra else ' '}{nstar:8d}  "
                  f"time {t * 1e3:10.1f} ms   errors " + " ".join(f"{e:.1e}" for e in errs), flush=True)
    print("\n| d | method | fitted order | N* for 1e-3 | time (ms, batch, sampling incl.) | time / best |")
    print("|---|---|---|---|---|---|")
    for d in args.dims:
        sub = [r for r in rows if r[0] == d]
        best = min(r[5] for r in sub if np.isfinite(r[5]))
        for (_, name, order, nstar, extra, t, _, _) in sub:
            tt = f"{t * 1e3:.1f}" if np.isfinite(t) else f"not timed (N* > {args.n_time_max})"
            rr = f"{t / best:.1f}x" if np.isfinite(t) else "-"
            print(f"| {d} | {name} | {order:.2f} | {'~' if extra else ''}{nstar} | {tt} | {rr} |")
    return rows


def throughput(args):
    try:
        import torch
        import torchsde
    except ImportError:                                             # pragma: no cover - optional peer
        print("\ntorchsde not installed (pip install '.[bench]'): throughput table skipped")
        return
    torch.set_num_threads(1)
    B, N = args.batch, args.steps
    print(f"\nsampling throughput, increments + Lévy areas, {B} paths x {N} steps, h = 1/{N}: "
          f"million path-steps per second (median of {args.repeats}), same run")
    print("| d | ours davie | ours default (auto) | torchsde davie | torchsde foster | ours default / torchsde davie |")
    print("|---|---|---|---|---|---|")
    for d in args.dims:
        def ours(method):
            for _ in BrownianDriver(d, seed=1, dt=1.0 / N, n_steps=N, batch_shape=(B,), levy_area=method).blocks():
                pass

        def theirs(approx):
            bm = torchsde.BrownianInterval(t0=0.0, t1=1.0, size=(B, d), dtype=torch.float64, entropy=1,
                                           dt=1.0 / N, levy_area_approximation=approx)
            for k in range(N):
                bm(k / N, (k + 1) / N, return_A=True)

        t = {m: median_time(lambda: ours(m), args.repeats, warmup=True) for m in ("davie", "auto")}
        t.update({"t-" + a: median_time(lambda: theirs(a), args.repeats, warmup=True) for a in ("davie", "foster")})
        rate = {k: B * N / v / 1e6 for k, v in t.items()}
        print(f"| {d} | {rate['davie']:.2f} | {rate['auto']:.2f} | {rate['t-davie']:.3f} | "
              f"{rate['t-foster']:.3f} | {t['t-davie'] / t['auto']:.1f}x |", flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="small sizes (smoke run, numbers not meaningful)")
    p.add_argument("--sigma", type=float, default=0.3)
    p.add_argument("--dims", type=int, nargs="+", default=[2, 3, 5])
    p.add_argument("--throughput-only", action="store_true", help="skip the work-precision part")
    args = p.parse_args(argv)
    q = args.quick
    args.paths, args.batch, args.repeats = (16, 50, 1) if q else (64, 1000, 3)
    args.factor, args.n0 = (4, 4) if q else (8, 8)
    args.n_max, args.n_max_heun, args.n_time_max = (64, 64, 4096) if q else (512, 512, 65536)
    args.steps = 100 if q else 1000
    t0 = time.perf_counter()
    if not args.throughput_only:
        work_precision(args)
    throughput(args)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
