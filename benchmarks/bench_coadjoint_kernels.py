"""Benchmark: compiled coadjoint kernels against the numpy scheme they implement (same run).

Problem: the dissipative heavy top on se(3)* (I = diag(1, 2, 3), χ = (0.1, −0.2, 1), σ = 0.2, θ = 0.3)
and the rigid body on so(3)* (σ = 0.3, θ = 0.5), driven by one precomputed Brownian rough path with its
Lévy area (dt = 0.01). For each solver (Lie–Euler, Lie–Heun, implicit midpoint with the chord
iteration) ``roughpaths.solve`` takes the compiled path chosen by the algebra type; the numpy path is
the same solver stepped by the generic ``roughpaths.Solver.integrate`` loop (one vectorised numpy step
per time step). Reported: median wall time of ``--repeats`` runs after a warm-up (numba compile/cache
load), µs per path-step, the ratio numpy / compiled, and the largest difference between the two
(relative, per entry) and the largest Casimir drift of the compiled result.

Usage: ``python benchmarks/bench_coadjoint_kernels.py [--paths P] [--steps K] [--repeats R]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from _timing import median_time


def main():
    from mechanics import ImplicitMidpoint, LieEuler, LieHeun, heavy_top, rigid_body
    from roughpaths import BrownianDriver, Solver, solve

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args()
    P, K = a.paths, a.steps
    rng = np.random.default_rng(0)
    systems = {
        "se(3) heavy top": heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.3),
        "so(3) rigid body": rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5),
    }
    print(f"{P} paths x {K} steps, dt = 0.01, medians of {a.repeats}")
    print(f"{'system':18s} {'solver':18s} {'compiled µs/ps':>15s} {'numpy µs/ps':>12s} {'numpy/compiled':>15s} "
          f"{'max rel diff':>13s} {'Casimir drift':>14s}")
    for name, system in systems.items():
        mu0 = rng.standard_normal((P, system.dim))
        X = BrownianDriver(system.n_noise, seed=1, dt=0.01, n_steps=K, batch_shape=(P,)).rough_path()
        save = np.ones(K, dtype=bool)
        for solver in (LieEuler(), LieHeun(), ImplicitMidpoint()):
            def compiled():
                return solve(system, X, mu0, solver).states

            def numpy_path():
                _, saved, _ = Solver.integrate(solver, system, mu0.copy(), X.times, X.increments, X.areas, save)
                return np.concatenate([mu0[:, None], saved], axis=1)

            ta = median_time(compiled, a.repeats, warmup=True)
            tb = median_time(numpy_path, a.repeats, warmup=True)
            sa, sb = compiled(), numpy_path()
            diff = float(np.max(np.abs(sa - sb) / np.maximum(1.0, np.abs(sb))))
            c0 = system.casimirs(mu0)[:, None]
            drift = float(np.max(np.abs(system.casimirs(sa) - c0) / np.maximum(1.0, np.abs(c0))))
            print(f"{name:18s} {repr(solver)[:18]:18s} {1e6 * ta / (P * K):15.3f} {1e6 * tb / (P * K):12.3f} "
                  f"{tb / ta:15.1f} {diff:13.2e} {drift:14.2e}")


if __name__ == "__main__":
    main()
