"""Work–precision of RDE solvers on a 3-d linear Stratonovich SDE with non-commuting noise.

    dY = A Y dt + Σ_{i=1}^{3} σ M_i Y ∘ dW^i,   Y_0 = (1, 0.5, -0.3),   T = 1.

Strong error = root-mean-square over paths of |Y_T − Y_T^ref| (Euclidean), against a reference on the
*same* Brownian rough path: a ``BrownianDriver`` on the fine grid of ``N_ref`` steps with
error-controlled areas (``levy_area="mrongowius-rossler"``, L² error ``h^1.5`` per step, so the fine
path has the Brownian law up to ~1e-7 per step), where ``LogODE`` (exact exponential per step) gives
the reference. Every solver then runs on restrictions of that same path (Chen sums: the coarse
increments and areas are those of the fine path), so the errors are pathwise. The errors of sampled
coarse areas (Davie's, Foster's, the error-controlled ones) against the refined path are measured by
``bench_levy_area.py``.

The time to reach strong error 1e-3 is measured for each solver at its own required number of
steps ``N*`` (interpolated on the error ladder), **including the sampling of its driver**: the order-1
solvers draw increments and Lévy areas (``brownian_rough_path``, Davie's sampler), Heun draws increments
only. Same run, same machine, ratio printed. Then path-steps per second for a batch of 1,000 paths.

Usage: ``python benchmarks/bench_rde.py`` (about a minute), ``--quick`` for a smoke run.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from roughpaths import (brownian_rough_path, BrownianDriver, Davie, Euler, Heun, LinearVectorFields, LogODE,
                        solve)

TOL = 1e-3
Y0 = np.array([1.0, 0.5, -0.3])


def make_fields(sigma: float) -> LinearVectorFields:
    rng = np.random.default_rng(1234)
    # three non-commuting generators: rotations about the axes plus a shear each
    so3 = np.array([[[0, 0, 0], [0, 0, -1], [0, 1, 0]],
                    [[0, 0, 1], [0, 0, 0], [-1, 0, 0]],
                    [[0, -1, 0], [1, 0, 0], [0, 0, 0]]], dtype=float)
    M = sigma * (so3 + 0.3 * rng.standard_normal((3, 3, 3)))
    A = -0.2 * np.eye(3) + 0.1 * rng.standard_normal((3, 3))
    return LinearVectorFields(M, drift=A)


from _timing import median_time


def error_ladder(V, paths, n0, levels, seed):
    n_ref = n0 * 2 ** levels
    drv = BrownianDriver(3, seed=seed, dt=1.0 / n_ref, n_steps=n_ref, batch_shape=(paths,),
                         levy_area="mrongowius-rossler")
    X = drv.rough_path()
    ref = solve(V, X, Y0, LogODE(), save_at="end").final
    return X, ref


def steps_for_tol(ns, errs, tol):
    """Smallest N reaching ``tol``, log–log interpolated between ladder points (None if not reached)."""
    ns, errs = np.asarray(ns, float), np.asarray(errs, float)
    for k in range(len(ns)):
        if errs[k] <= tol:
            if k == 0:
                return int(ns[0])
            a = (np.log(tol) - np.log(errs[k - 1])) / (np.log(errs[k]) - np.log(errs[k - 1]))
            return int(np.ceil(np.exp(np.log(ns[k - 1]) + a * (np.log(ns[k]) - np.log(ns[k - 1])))))
    return None


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="small sizes (smoke run, numbers not meaningful)")
    p.add_argument("--sigma", type=float, default=0.2, help="noise scale (default 0.2)")
    args = p.parse_args(argv)
    quick = args.quick
    paths = 32 if quick else 128
    n0, levels = 16, (8 if quick else 12)                          # reference grid n0 * 2**levels
    repeats = 3 if quick else 5
    batch = 100 if quick else 1000
    V = make_fields(args.sigma)

    t0 = time.perf_counter()
    X, ref = error_ladder(V, paths, n0, levels, seed=7)
    n_ref = X.n_steps
    print(f"reference: {paths} paths, N_ref = {n_ref} steps (LogODE on a Brownian rough path, MR areas), "
          f"{time.perf_counter() - t0:.1f} s")

    solvers = {"Davie": Davie(), "LogODE": LogODE(), "Heun (no area)": Heun()}
    ladders = {}
    print(f"\n{'solver':16s} {'N':>7s} {'strong err':>11s}")
    for name, solver in solvers.items():
        ns, errs = [], []
        n = n0
        while n <= n_ref // 4:
            Xc = X.restrict(X.times[:: n_ref // n])
            if solver.increment_level == 1:
                Xc = Xc.to_level1()
            y = solve(V, Xc, Y0, solver, save_at="end").final
            err = float(np.sqrt(np.mean(np.sum((y - ref) ** 2, axis=-1))))
            ns.append(n)
            errs.append(err)
            print(f"{name:16s} {n:7d} {err:11.3e}")
            if err < TOL / 4 and n >= 8 * n0:
                break
            n *= 2
        slope = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
        ladders[name] = (ns, errs, slope)
    print("\nfitted strong orders (slope of log-error vs log-step):")
    for name, (ns, errs, slope) in ladders.items():
        tail = -np.polyfit(np.log(ns[-3:]), np.log(errs[-3:]), 1)[0]
        print(f"  {name:16s} {slope:5.2f} over the ladder, {tail:5.2f} over its last 3 points   "
              f"(declared {solvers[name].order})")

    print(f"\nwork to reach strong error {TOL:g} (batch of {batch} paths, driver sampling included, median of "
          f"{repeats}):")
    timings = {}
    for name, solver in solvers.items():
        ns, errs, _ = ladders[name]
        nstar = steps_for_tol(ns, errs, TOL)
        if nstar is None:
            print(f"  {name:16s} did not reach {TOL:g} on the ladder (N <= {ns[-1]}); increase --levels")
            continue
        level2 = solver.increment_level == 2
        rng = np.random.default_rng(99)

        def run():
            Xd = brownian_rough_path(np.linspace(0.0, 1.0, nstar + 1), 3, rng, batch_shape=(batch,),
                                     levy_area="davie" if level2 else None)
            solve(V, Xd, Y0, solver, save_at="end")

        def sample_only():
            brownian_rough_path(np.linspace(0.0, 1.0, nstar + 1), 3, rng, batch_shape=(batch,),
                                levy_area="davie" if level2 else None)

        t = median_time(run, repeats)
        ts = median_time(sample_only, repeats)
        timings[name] = t
        print(f"  {name:16s} N* = {nstar:7d}   {t * 1e3:9.1f} ms   (of which sampling {ts * 1e3:7.1f} ms)")
    if "Heun (no area)" in timings:
        for name in ("Davie", "LogODE"):
            if name in timings:
                print(f"  ratio Heun / {name}: {timings['Heun (no area)'] / timings[name]:.1f}x")

    print(f"\npath-steps per second, batch of {batch} paths, 1000 steps (solve only, driver pre-sampled):")
    rng = np.random.default_rng(5)
    Xd = brownian_rough_path(np.linspace(0.0, 1.0, 1001), 3, rng, batch_shape=(batch,))
    for name, solver in {"Euler": Euler(), "Heun": Heun(), "Davie": Davie(), "LogODE": LogODE()}.items():
        t = median_time(lambda: solve(V, Xd, Y0, solver, save_at="end"), repeats)
        print(f"  {name:8s} {batch * 1000 / t:12.3e} path-steps/s   ({t * 1e3:.1f} ms)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
