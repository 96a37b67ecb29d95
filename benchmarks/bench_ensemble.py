"""Benchmark: ``run_ensemble`` against a direct ``solve`` of the same problem (issue "One engine").

Problem: the dissipative rigid body (I = diag(1, 2, 3), θ = 1, σ = 0.05), Lie–Heun with Davie's Lévy
area, ``--paths`` paths × ``--steps`` steps of dt = 1e-3 on ``roughpaths.BrownianDriver(seed=1)``.

* direct: ``solve(rb, BrownianDriver(...), mu0, LieHeun(), save_at="end")`` (final states only);
* ensemble: ``run_ensemble(..., levy_area="davie")`` with its defaults (moment statistics of the final
  state and of every step's time average, serial), plus ``chunk_size``/``block_steps`` variants.

Prints medians of ``--repeats`` interleaved runs (direct, ensemble, direct, ...; after a warm-up) in process
CPU time (``--clock wall`` for wall time), ns per path-step and the ratio ensemble / direct (target ≤ 1.15).
The final states are checked to be bitwise equal.

Usage: ``python benchmarks/bench_ensemble.py [--paths P] [--steps N] [--repeats R] [--clock cpu|wall]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def _interleaved(fa, fb, repeats, clock):
    ta, tb, out = [], [], None
    for _ in range(repeats):
        t0 = clock()
        fa()
        ta.append(clock() - t0)
        t0 = clock()
        out = fb()
        tb.append(clock() - t0)
    return statistics.median(ta), statistics.median(tb), out


def main(argv=None):
    from mechanics import LieHeun, rigid_body, run_ensemble
    from roughpaths import BrownianDriver, solve

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu")
    args = ap.parse_args(argv)
    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    P, N, dt = args.paths, args.steps, 1e-3
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.05, theta=1.0)
    mu0 = np.array([0.0, 0.0, 1.0])

    def direct():
        drv = BrownianDriver(3, seed=1, dt=dt, n_steps=N, batch_shape=(P,), levy_area="davie")
        return solve(rb, drv, mu0, LieHeun(), save_at="end").final

    def ensemble(**kw):
        return run_ensemble(rb, mu0, dt=dt, n_steps=N, n_paths=P, seed=1, levy_area="davie", keep_final=True,
                            **kw).final_states

    direct()
    ensemble()                                                                 # warm-up / compile
    print(f"rigid body, Lie-Heun + Davie area, {P} paths x {N} steps, {args.clock} time, medians of "
          f"{args.repeats} interleaved pairs")
    fd = direct()
    for label, kw in (("run_ensemble (defaults)", {}), ("run_ensemble chunk 1000, block 200",
                                                        {"chunk_size": 1000, "block_steps": 200})):
        t_d, t_e, fe = _interleaved(direct, lambda: ensemble(**kw), args.repeats, clock)
        same = np.array_equal(fe, fd)
        print(f"  direct solve                      {t_d:8.3f} s  {t_d / (P * N) * 1e9:8.1f} ns/path-step")
        print(f"  {label:33s} {t_e:8.3f} s  {t_e / (P * N) * 1e9:8.1f} ns/path-step   ratio {t_e / t_d:5.2f}x"
              f"   final states bitwise equal to direct: {same}")


if __name__ == "__main__":
    main()
