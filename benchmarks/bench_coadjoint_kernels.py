"""Benchmark: the coadjoint kernels — built-in (so(3), se(3)) against the generic one, and threads (same run).

Problems (driven by one precomputed Brownian rough path with its Lévy area, dt = 0.01, θ > 0):

* the rigid body on so(3)* (I = diag(1, 2, 3), σ = 0.3, θ = 0.5) and the heavy top on se(3)*
  (χ = (0.1, −0.2, 1), σ = 0.2, θ = 0.3), each solved by its built-in kernel (hand-written for so(3), and
  for the se(3) implicit midpoint; for se(3) Lie–Euler / Lie–Heun the se(3) block kernel, the generic
  kernel's numbers with se(3)'s constants written out) and by the generic kernel on the *same* problem
  (the algebra rebuilt as a plain ``LieAlgebra`` from its own structure constants, and for se(3) the table
  match of the se(3) block kernel hidden, so only the kernel differs);
* su(2), sl(2, R) and so(4) (6-dimensional) with a diagonal inertia and three noise vectors: the generic
  kernel against the numpy scheme (``roughpaths.Solver.integrate``'s loop, one vectorised numpy step per
  time step), the path the library took for them before the generic kernel.

For Lie–Euler, Lie–Heun and the chord implicit midpoint. Timings are medians of interleaved runs
(A, B, A, B, ...) in process CPU time (``--clock wall`` for wall time) on one thread, in ns per
path-step, with the ratio. Then one thread against all of numba's threads (``numba.set_num_threads``)
on LieHeun, in wall *and* CPU time (the machine may be shared: the wall ratio is what the threads
give, the CPU ratio what they cost; the calling thread's CPU time over the one-thread CPU time estimates the
wall ratio of an idle machine, since the caller shares the ranges with the pool), with a bitwise check
that the results are equal. The largest
relative difference generic/numpy and the largest Casimir drift are printed too.

Last, the heavy top against the rigid body (the target: at most 3x per path-step for Lie-Heun): the problems
of ``benchmarks/bench_rigid_body.py`` (I = diag(1, 2, 3), θ = 1, σ = 0.05, dt = 1e-3; the heavy top with χ = e3),
driven by the same Brownian driver with its default (error-controlled) Lévy areas, for each scheme, on one
thread and on two: the solver alone on the same sampled path (held in memory), and the full solve (the
driver sampling its blocks included). Process CPU time, medians of interleaved runs (rigid body, heavy top,
...), ns per path-step; the ratio of the medians and the median of the per-pair ratios, with the load.

Usage: ``python benchmarks/bench_coadjoint_kernels.py [--paths P] [--steps K] [--repeats R] [--clock cpu|wall]
[--ratio-only]``.
"""

from __future__ import annotations

import argparse
import contextlib
import statistics
import time

import numba
import numpy as np


def _so4():
    from mechanics import LieAlgebra

    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    basis = np.zeros((6, 4, 4))
    for r, (a, b) in enumerate(pairs):
        basis[r, a, b], basis[r, b, a] = 1.0, -1.0
    return LieAlgebra.from_matrix_basis(basis, name="so4")


@contextlib.contextmanager
def _generic_forced():
    """The generic block kernel also where the se(3) block kernel would run (its table match hidden)."""
    from mechanics.integrators import _se3_block

    real = _se3_block.has_se3_table
    _se3_block.has_se3_table = lambda *a: False
    try:
        yield
    finally:
        _se3_block.has_se3_table = real


def _interleaved(fns, repeats, clock):
    """Median time of each function, run interleaved (f0, f1, ..., f0, f1, ...) after one warm-up each."""
    for f in fns:
        f()
    times = [[] for _ in fns]
    for _ in range(repeats):
        for t, f in zip(times, fns):
            t0 = clock()
            f()
            t.append(clock() - t0)
    return [statistics.median(t) for t in times]


def heavy_top_ratio(paths, steps, repeats):
    """The heavy top / rigid body table (module docstring): per scheme, 1 and 2 threads, solver alone and full solve."""
    import os

    from mechanics import ImplicitMidpoint, LieEuler, LieHeun, heavy_top, rigid_body
    from roughpaths import BrownianDriver, solve

    inertia = [1.0, 2.0, 3.0]
    rb = rigid_body(inertia, sigma=0.05, theta=1.0)
    top = heavy_top(inertia, chi=[0.0, 0.0, 1.0], sigma=0.05, theta=1.0)
    mu0 = {rb: np.array([0.0, 0.0, 1.0]), top: np.array([0.0, 0.0, 1.0, 0.0, 0.6, 0.8])}

    def driver():
        return BrownianDriver(3, seed=1, dt=1e-3, n_steps=steps, batch_shape=(paths,))

    X = driver().rough_path()
    threads = numba.get_num_threads()
    print(f"\nheavy top / rigid body: {paths} paths x {steps} steps, dt = 1e-3, default Lévy areas, CPU time, medians "
          f"of {repeats} interleaved runs, ns per path-step; load {os.getloadavg()[0]:.1f}")
    print(f"{'solver':18s} {'threads':>7s} {'what':>13s} {'rigid body':>11s} {'heavy top':>10s} {'ratio':>6s} "
          f"{'pairs':>6s}")
    try:
        for solver in (LieEuler(), LieHeun(), ImplicitMidpoint()):
            for t in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
                numba.set_num_threads(t)
                for what in ("solver alone", "full solve"):
                    def run(system, what=what, solver=solver):
                        drv = X if what == "solver alone" else driver()
                        return solve(system, drv, mu0[system], solver, save_at="end").final

                    for system in (rb, top):
                        run(system)
                    times = {rb: [], top: []}
                    for _ in range(repeats):
                        for system in (rb, top):
                            t0 = time.process_time()
                            run(system)
                            times[system].append(time.process_time() - t0)
                    r, h = (1e9 * statistics.median(times[s]) / (paths * steps) for s in (rb, top))
                    pairs = statistics.median(b / a for a, b in zip(times[rb], times[top]))
                    print(f"{repr(solver)[:18]:18s} {t:7d} {what:>13s} {r:11.1f} {h:10.1f} {h / r:6.2f} {pairs:6.2f}",
                          flush=True)
    finally:
        numba.set_num_threads(threads)


def main():
    from mechanics import ImplicitMidpoint, LieAlgebra, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body
    from mechanics.systems.lie_algebra import sl2r, su2
    from roughpaths import BrownianDriver, Solver, solve

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--clock", choices=("cpu", "wall"), default="cpu")
    ap.add_argument("--ratio-only", action="store_true", help="only the heavy top / rigid body table")
    a = ap.parse_args()
    if a.ratio_only:
        heavy_top_ratio(a.paths, a.steps, max(a.repeats, 5))
        return
    clock = time.process_time if a.clock == "cpu" else time.perf_counter
    P, K = a.paths, a.steps
    all_threads = numba.get_num_threads()
    numba.set_num_threads(1)
    rb = rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5)
    top = heavy_top([1.0, 2.0, 3.0], chi=[0.1, -0.2, 1.0], sigma=0.2, theta=0.3)

    def generic_solve(system, X, mu0, solver):
        with _generic_forced():
            return solve(system, X, mu0, solver)

    def generic_copy(system):
        alg = system.algebra
        plain = LieAlgebra(alg.structure_constants, name=alg.name + " (constants)", casimirs=alg.casimirs,
                           check=False)
        return LiePoissonSystem(plain, system.hamiltonian, system.xi, theta=system.theta)

    rng = np.random.default_rng(0)
    solvers = (LieEuler(), LieHeun(), ImplicitMidpoint())
    print(f"{P} paths x {K} steps, dt = 0.01, with the Lévy area; {a.clock} time, medians of {a.repeats} "
          f"interleaved runs, one thread; ns per path-step")
    print(f"{'algebra':10s} {'solver':18s} {'built-in':>13s} {'generic':>9s} {'generic/built-in':>16s} "
          f"{'max rel diff':>13s} {'Casimir drift':>14s}")
    problems = {}
    for name, system in (("so(3)", rb), ("se(3)", top)):
        mu0 = rng.standard_normal((P, system.dim))
        X = BrownianDriver(system.n_noise, seed=1, dt=0.01, n_steps=K, batch_shape=(P,)).rough_path()
        gen = generic_copy(system)
        problems[name] = (system, gen, mu0, X)
        for solver in solvers:
            th, tg = _interleaved([lambda: solve(system, X, mu0, solver), lambda: generic_solve(gen, X, mu0, solver)],
                                  a.repeats, clock)
            sa, sb = solve(system, X, mu0, solver).states, generic_solve(gen, X, mu0, solver).states
            diff = float(np.max(np.abs(sa - sb) / np.maximum(1.0, np.abs(sa))))
            c0 = system.casimirs(mu0)[:, None]
            drift = float(np.max(np.abs(system.casimirs(sb) - c0) / np.maximum(1.0, np.abs(c0))))
            print(f"{name:10s} {repr(solver)[:18]:18s} {1e9 * th / (P * K):13.1f} {1e9 * tg / (P * K):9.1f} "
                  f"{tg / th:16.2f} {diff:13.2e} {drift:14.2e}")

    print("(se(3) Lie-Euler / Lie-Heun: built-in = the se(3) block kernel, bitwise the generic kernel's numbers)")
    print(f"\n{'algebra':10s} {'solver':18s} {'numpy':>13s} {'generic':>9s} {'numpy/generic':>13s} "
          f"{'max rel diff':>13s} {'Casimir drift':>14s}")
    save = np.ones(K, dtype=bool)
    for alg in (su2(), sl2r(), _so4()):
        n = alg.dim
        system = LiePoissonSystem(alg, np.diag(1.0 + np.arange(n) / 2.0), 0.3 * rng.standard_normal((3, n)),
                                  theta=0.3)
        mu0 = rng.standard_normal((P, n))
        X = BrownianDriver(3, seed=1, dt=0.01, n_steps=K, batch_shape=(P,)).rough_path()
        problems[alg.name] = (None, system, mu0, X)
        for solver in solvers:
            def numpy_path():
                return Solver.integrate(solver, system, mu0.copy(), X.times, X.increments, X.areas, save)[1]

            tn, tg = _interleaved([numpy_path, lambda: solve(system, X, mu0, solver)], a.repeats, clock)
            sa, sb = numpy_path(), solve(system, X, mu0, solver).states[:, 1:]
            diff = float(np.max(np.abs(sa - sb) / np.maximum(1.0, np.abs(sa))))
            c0 = system.casimirs(mu0)[:, None]
            drift = float(np.max(np.abs(system.casimirs(sb) - c0) / np.maximum(1.0, np.abs(c0))))
            print(f"{alg.name:10s} {repr(solver)[:18]:18s} {1e9 * tn / (P * K):13.1f} {1e9 * tg / (P * K):9.1f} "
                  f"{tn / tg:13.1f} {diff:13.2e} {drift:14.2e}")

    print(f"\nLieHeun, 1 thread against {all_threads} (numba.set_num_threads); ns per path-step")
    print(f"{'problem':22s} {'wall 1':>8s} {'wall N':>8s} {'wall N/1':>9s} {'cpu 1':>8s} {'cpu N':>8s} "
          f"{'cpu N/1':>8s} {'caller N/cpu 1':>14s} {'bitwise':>8s}")
    for name, (hand, gen, mu0, X) in problems.items():
        for label, system in (("built-in", hand), ("generic", gen)):
            if system is None:
                continue
            walls, cpus, outs = {1: [], all_threads: []}, {1: [], all_threads: []}, {}
            caller = []
            for _ in range(a.repeats):
                for t in (1, all_threads):
                    numba.set_num_threads(t)
                    w0, c0, m0 = time.perf_counter(), time.process_time(), time.thread_time()
                    with _generic_forced() if label == "generic" else contextlib.nullcontext():
                        outs[t] = solve(system, X, mu0, LieHeun()).states
                    walls[t].append(time.perf_counter() - w0)
                    cpus[t].append(time.process_time() - c0)
                    if t == all_threads:
                        caller.append(time.thread_time() - m0)
            numba.set_num_threads(1)
            w1, wn = (1e9 * statistics.median(walls[t]) / (P * K) for t in (1, all_threads))
            c1, cn = (1e9 * statistics.median(cpus[t]) / (P * K) for t in (1, all_threads))
            same = bool(np.array_equal(outs[1], outs[all_threads]))
            mn = 1e9 * statistics.median(caller) / (P * K)
            print(f"{name + ' ' + label:22s} {w1:8.1f} {wn:8.1f} {wn / w1:9.2f} {c1:8.1f} {cn:8.1f} {cn / c1:8.2f} "
                  f"{mn / c1:14.2f} {str(same):>8s}")
    numba.set_num_threads(all_threads)
    heavy_top_ratio(P, K, max(a.repeats, 5))


if __name__ == "__main__":
    main()
