"""Benchmark: coadjoint steps per member (adaptive solves) on algebras beyond so(3) and se(3) (issue "One time loop").

Adaptive solves step every member on its own times (``Solver.member_times``). On a structure-constant algebra the
members take a compiled scalar step each (``mechanics/integrators/_generic_member_steps.py``); on matrices, the
numpy path's conjugation, vectorised over the members. ``_dispatch.member_system`` picks one of the two per system
by the cost model, at a reference step. This script times both options per member-step, so the choice can be
checked, and then whole adaptive solves.

1. Per member-step (Lie–Heun, 1000 members, ``dt`` uniform in [0.005, 0.02], increments without areas, one thread;
   CPU time, median of ``--repeats`` interleaved pairs): su(N) from its matrix basis, N = 2 .. 8 (noise
   ``ξ = 0.4 N(0, 1)``, θ = 1), on its structure constants (compiled) and on its matrix twin (numpy), with what the
   cost model picks.
2. Adaptive solves (``PIController(1e-3, 1e-3)``, LieHeun, 1000 paths of a ``BrownianTree(3)``, one thread, CPU
   time; a first solve of 4 paths compiles, untimed): su(2) (``Q = diag(1, 4/3, 5/3)``, ``ξ = I/2``, θ = 1),
   sl(2, R) (``ξ = 0.3 I``, θ = 1), su(3) as a matrix algebra (``ξ = 0.4 N(0, 1)``, θ = 0). Accepted and rejected
   steps are properties of the paths (the same on any machine); the CPU time is the machine's. "first" is the first
   solve on the tree (it sets up the walk's store of nodes, 64 MiB at most), "again" a second solve on it.

Usage: ``python benchmarks/bench_member_steps.py [--repeats R] [--paths P] [--only su2,sl2r,su3]`` (about 1 minute).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numba
import numpy as np

import roughpaths as rp
from mechanics import LieAlgebra, LieHeun, LiePoissonSystem, sl2r, su, su2
from mechanics.integrators._dispatch import _matrix_twin, member_system
from mechanics.integrators._generic_member_steps import generic_member_steps


def per_member_step(repeats):
    print("1. cost per member-step, Lie-Heun, 1000 members, one thread (CPU, median of interleaved pairs)")
    print(f"   {'algebra':>10s} {'n':>3s} {'constants':>10s} {'matrices':>10s}  cost model picks")
    rng = np.random.default_rng(0)
    solver = LieHeun()
    for N in (2, 3, 4, 6, 8):
        g = su2() if N == 2 else LieAlgebra.from_matrix_basis(su(N).basis)
        n = g.dim
        system = LiePoissonSystem(g, np.diag(1.0 + np.arange(n) / n), 0.4 * rng.standard_normal((3, n)), theta=1.0)
        twin = _matrix_twin(system)
        B = 1000
        mu, dt = rng.standard_normal((B, n)), rng.uniform(0.005, 0.02, B)
        eta = solver._eta(system, rng.standard_normal((B, 3)) * np.sqrt(dt)[:, None], None)
        generic_member_steps(system, 1, 1e-13, 1, mu[:2], dt[:2], eta[:2])          # compile
        tc, tm = [], []
        for _ in range(repeats):
            c0 = time.process_time()
            generic_member_steps(system, 1, 1e-13, 1, mu, dt, eta)
            tc.append(time.process_time() - c0)
            c0 = time.process_time()
            solver._advance(twin, mu, dt[:, None], eta)
            tm.append(time.process_time() - c0)
        pick = "matrices" if member_system(system) is not system else "constants"
        print(f"   {g.name if N == 2 else f'su({N})':>10s} {n:3d} {statistics.median(tc) / B * 1e6:8.2f}us "
              f"{statistics.median(tm) / B * 1e6:8.2f}us  {pick}", flush=True)


def _system(name):
    if name == "su2":
        return LiePoissonSystem(su2(), np.diag([1.0, 4 / 3, 5 / 3]), 0.5 * np.eye(3), theta=1.0)
    if name == "sl2r":
        return LiePoissonSystem(sl2r(), np.diag([1.0, 4 / 3, 5 / 3]), 0.3 * np.eye(3), theta=1.0)
    g = su(3)
    return LiePoissonSystem(g, np.diag(1.0 + np.arange(g.dim) / g.dim),
                            0.4 * np.random.default_rng(2).standard_normal((3, g.dim)), theta=0.0)


def adaptive(names, paths):
    print(f"\n2. adaptive solves, LieHeun, PIController(1e-3, 1e-3), {paths} paths, one thread (CPU)")
    print(f"   {'system':>18s} {'accepted':>9s} {'rejected':>9s} {'first':>8s} {'again':>8s}  stepped on")
    for name in names:
        system = _system(name)
        mu0 = np.broadcast_to(np.linspace(0.5, 1.0, system.dim), (paths, system.dim))
        tree = rp.BrownianTree(3, seed=5, batch_shape=(paths,))
        ctrl = rp.PIController(1e-3, 1e-3)
        rp.solve(system, tree.select([0, 1, 2, 3]), mu0[:4], LieHeun(), step_control=ctrl, save_at="end")
        cpu = []
        for _ in range(2):
            c0 = time.process_time()
            sol = rp.solve(system, tree, mu0, LieHeun(), step_control=ctrl, save_at="end")
            cpu.append(time.process_time() - c0)
        on = member_system(system).algebra
        label = {"su2": "su(2)", "sl2r": "sl(2, R)", "su3": "su(3), matrices"}[name]
        print(f"   {label:>18s} {int(np.sum(sol.stats['accepted'])):9d} {int(np.sum(sol.stats['rejected'])):9d} "
              f"{cpu[0]:7.2f}s {cpu[1]:7.2f}s  {type(on).__name__}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--paths", type=int, default=1000)
    ap.add_argument("--only", default="su2,sl2r,su3")
    args = ap.parse_args(argv)
    numba.set_num_threads(1)
    per_member_step(args.repeats)
    adaptive([s for s in args.only.split(",") if s], args.paths)


if __name__ == "__main__":
    main()
