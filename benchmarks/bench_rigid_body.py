"""Benchmark: the dissipative stochastic rigid body, ours against diffrax, torchsde and sdeint.

Problem (issue 4): I = diag(1, 2, 3), θ = 1, ξ_i = σ e_i with σ = 0.05, s = 0, Π(0) = e3, dt = 1e-3,
1,000 paths × 10,000 steps, float64, Stratonovich:

    dΠ = Π × Ω dt + θ Π × (Π × Ω) dt + σ Π × ∘dW,   Ω = I⁻¹Π.

Ours: ``roughpaths.solve(rigid_body, BrownianDriver(3, seed, ...), mu0, LieHeun())`` (coadjoint
update, |Π| exact), the Lévy area included (Davie, strong order 1) and, for reference, without it.
The driver generates per-path seeded increments and areas block by block; the so(3) solver runs a
structure-of-arrays numba kernel (SIMD over paths, trig-free Rodrigues). The driver alone is timed
too: with the area it is most of the cost. Two rows answer the issue "One engine": the same problem
through ``run_ensemble`` (target ≤ 1.3x the direct solve) and the heavy top on se(3)* with the same
inertia, noise and θ and the same driver, Davie's areas (target ≤ 3x the rigid body per path-step; its column
shows ``||Γ(T)| - 1|``, a Casimir; until the driver's default became the error-controlled areas this row took
the default, so it compared two drivers: 2.5x before that change, 5.2x after, in the same interleaved run;
``benchmarks/bench_coadjoint_kernels.py --ratio-only`` has the table by scheme and thread count). Peers (where
installed, in the
same run): diffrax Heun on a batched (3, N) state (jit), torchsde Heun (noise_type="general",
sde_type="stratonovich"), sdeint stratHeun (no batching: fewer paths, time scaled per path-step).
Reported: median wall time and median process CPU time (all threads) of ``--repeats`` runs (after a
warm-up/compile run), ns per path-step, max ||Π(T)| - 1| over the paths, and ratios row / ours in both.

Then the cost of Davie's area (issue 24, item 4): a path-step of the solver on a sampled path, of the full
solve and of the driver alone, with the area and without it, CPU time, interleaved runs, the ratio (target
<= 1.6), and the floor that numpy's normals put under the full-solve ratio.

Last, one thread against all of numba's threads on the full solve (driver included, ``n_paths`` x 1,000
steps), with and without the area: wall, CPU, and the calling thread's CPU time (the idle-machine wall
estimate on a shared machine), with a bitwise check; and, on two cores, what two threads give a loop bound
by arithmetic and one that streams from the L2 cache on this machine.

Usage: ``python benchmarks/bench_rigid_body.py [--quick] [--repeats R]
[--skip diffrax,torchsde,sdeint] [--threads-only] [--area-only]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

INERTIA = np.array([1.0, 2.0, 3.0])
THETA, SIGMA, DT = 1.0, 0.05, 1e-3


def _median_time(fn, repeats):
    """``((median wall, median CPU), last result)``; CPU is the process's time summed over its threads."""
    wall, cpu, out = [], [], None
    for _ in range(repeats):
        w0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        wall.append(time.perf_counter() - w0)
        cpu.append(time.process_time() - c0)
    return (statistics.median(wall), statistics.median(cpu)), out


def _norm_err(final):
    return float(np.max(np.abs(np.linalg.norm(final, axis=-1) - 1.0)))


def bench_ours(n_paths, n_steps, repeats, levy_area=True):
    from mechanics import LieHeun, rigid_body
    from roughpaths import BrownianDriver, solve

    rb = rigid_body(INERTIA, sigma=SIGMA, theta=THETA)
    mu0 = np.array([0.0, 0.0, 1.0])
    method = "davie" if levy_area else None

    def run(n, p, seed):
        drv = BrownianDriver(3, seed=seed, dt=DT, n_steps=n, batch_shape=(p,), levy_area=method)
        return solve(rb, drv, mu0, LieHeun(), save_at="end").final

    run(10, 2, 0)                                                   # warm-up (numba compile/cache load)
    return _median_time(lambda: run(n_steps, n_paths, 1), repeats)


def bench_driver_only(n_paths, n_steps, repeats):
    """The Brownian driver alone (increments and Davie areas, block by block), for the cost split."""
    from roughpaths import BrownianDriver

    def run():
        for _ in BrownianDriver(3, seed=1, dt=DT, n_steps=n_steps, batch_shape=(n_paths,), levy_area="davie").blocks():
            pass
        return np.broadcast_to(np.array([0.0, 0.0, 1.0]), (n_paths, 3))
    return _median_time(run, repeats)


def bench_heavy_top(n_paths, n_steps, repeats):
    """The heavy top on se(3)* (same inertia, θ, σ e_i rotational noise, χ = e3), LieHeun + Davie area (the rigid
    body's driver)."""
    from mechanics import LieHeun, heavy_top
    from roughpaths import BrownianDriver, solve

    top = heavy_top(INERTIA, chi=[0.0, 0.0, 1.0], sigma=SIGMA, theta=THETA)
    mu0 = np.array([0.0, 0.0, 1.0, 0.0, 0.6, 0.8])

    def run(n, p, seed):
        drv = BrownianDriver(3, seed=seed, dt=DT, n_steps=n, batch_shape=(p,), levy_area="davie")
        return solve(top, drv, mu0, LieHeun(), save_at="end").final[..., 3:]   # Γ: |Γ| = 1 is a Casimir

    run(10, 2, 0)
    return _median_time(lambda: run(n_steps, n_paths, 1), repeats)


def bench_ensemble(n_paths, n_steps, repeats):
    """``run_ensemble`` on the same rigid-body problem (moment statistics streamed, serial)."""
    from mechanics import rigid_body, run_ensemble

    rb = rigid_body(INERTIA, sigma=SIGMA, theta=THETA)

    def run(n, p):
        res = run_ensemble(rb, [0.0, 0.0, 1.0], dt=DT, n_steps=n, n_paths=p, seed=1, levy_area="davie",
                           keep_final=True)
        return res.final_states

    run(10, 2)
    return _median_time(lambda: run(n_steps, n_paths), repeats)


def _drift_np(y):
    om = y / INERTIA
    pxo = np.cross(y, om)
    return pxo + THETA * np.cross(y, pxo)


def bench_diffrax(n_paths, n_steps, repeats):
    import jax
    jax.config.update("jax_enable_x64", True)
    import diffrax
    import jax.numpy as jnp
    import lineax as lx

    inertia = jnp.asarray(INERTIA)[:, None]

    def cross(a, b):                        # along axis 0 of (3, N)
        return jnp.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])

    def drift(t, y, args):
        om = y / inertia
        pxo = cross(y, om)
        return pxo + THETA * cross(y, pxo)

    struct = jax.ShapeDtypeStruct((3, n_paths), jnp.float64)

    def diffusion(t, y, args):
        return lx.FunctionLinearOperator(lambda dw: SIGMA * cross(y, dw), struct)

    @jax.jit
    def solve(key):
        bm = diffrax.UnsafeBrownianPath(shape=(3, n_paths), key=key)
        terms = diffrax.MultiTerm(diffrax.ODETerm(drift), diffrax.ControlTerm(diffusion, bm))
        y0 = jnp.zeros((3, n_paths)).at[2].set(1.0)
        sol = diffrax.diffeqsolve(terms, diffrax.Heun(), 0.0, n_steps * DT, DT, y0,
                                  saveat=diffrax.SaveAt(t1=True), max_steps=n_steps + 10,
                                  adjoint=diffrax.ForwardMode())
        return sol.ys[0]

    key = jax.random.PRNGKey(0)
    solve(key).block_until_ready()          # compile

    def run():
        return np.asarray(solve(jax.random.PRNGKey(1)).block_until_ready()).T
    return _median_time(run, repeats)


def bench_torchsde(n_paths, n_steps, repeats):
    import torch
    import torchsde
    torch.set_default_dtype(torch.float64)
    inertia = torch.tensor(INERTIA)

    class SDE(torch.nn.Module):
        noise_type, sde_type = "general", "stratonovich"

        def f(self, t, y):
            om = y / inertia
            pxo = torch.cross(y, om, dim=-1)
            return pxo + THETA * torch.cross(y, pxo, dim=-1)

        def g(self, t, y):                  # (N, 3, 3): column i is Π × σ e_i = -σ hat(e_i)... i.e. σ Π × e_i
            z = torch.zeros_like(y[:, 0])
            px, py, pz = y[:, 0], y[:, 1], y[:, 2]
            # Π × e1 = (0, pz, -py), Π × e2 = (-pz, 0, px), Π × e3 = (py, -px, 0)
            return SIGMA * torch.stack([torch.stack([z, -pz, py], -1), torch.stack([pz, z, -px], -1),
                                        torch.stack([-py, px, z], -1)], -2)

    sde = SDE()
    y0 = torch.zeros(n_paths, 3)
    y0[:, 2] = 1.0
    ts = torch.tensor([0.0, n_steps * DT])

    def run():
        torch.manual_seed(1)
        bm = torchsde.BrownianInterval(t0=0.0, t1=n_steps * DT, size=(n_paths, 3), dtype=torch.float64)
        with torch.no_grad():
            ys = torchsde.sdeint(sde, y0, ts, bm=bm, method="heun", dt=DT)
        return ys[-1].numpy()
    return _median_time(run, repeats)


def bench_sdeint(n_paths, n_steps, repeats):
    import sdeint

    def f(y, t):
        return _drift_np(y)

    def g(y, t):
        px, py, pz = y
        return SIGMA * np.array([[0.0, -pz, py], [pz, 0.0, -px], [-py, px, 0.0]])

    tspan = np.linspace(0.0, n_steps * DT, n_steps + 1)

    def run():
        rng = np.random.default_rng(1)
        out = []
        for _ in range(n_paths):
            dw = rng.standard_normal((n_steps, 3)) * np.sqrt(DT)
            out.append(sdeint.stratHeun(f, g, np.array([0.0, 0.0, 1.0]), tspan, dW=dw)[-1])
        return np.array(out)
    return _median_time(run, repeats)


def bench_area_ratio(n_paths, n_steps, repeats):
    """The cost of Davie's area: a path-step with the area against one without (issue 24, item 4; target <= 1.6x).

    Three measures, each in process CPU time, as interleaved runs (with, without, with, ...), medians per
    configuration and the median of the per-pair ratios:

    * the solver given the driver's increments and areas (a sampled ``RoughPath`` in memory, one thread): the
      measure of the issue's 70-76 against 26 ns;
    * the full solve (driver sampling included, LieHeun, ``save_at="end"``);
    * the driver alone.

    And the floor of the full-solve ratio while the normals are numpy's, bit for bit: the 6 normals per
    path-step that Davie's area adds at d = 3 (d normals of space-time area and d(d-1)/2 of Davie's own)
    cost what a driver of d = 9 without area costs over one of d = 3; even if every other area cost were
    zero, the full solve could not beat (no-area solve + that) / no-area solve.
    """
    import numba

    from mechanics import LieHeun, rigid_body
    from roughpaths import BrownianDriver, solve

    rb = rigid_body(INERTIA, sigma=SIGMA, theta=THETA)
    mu0 = np.array([0.0, 0.0, 1.0])

    def driver(area, dim=3, steps=n_steps):
        return BrownianDriver(dim, seed=1, dt=DT, n_steps=steps, batch_shape=(n_paths,), levy_area=area)

    def run_solve(area):
        return solve(rb, driver(area), mu0, LieHeun(), save_at="end").final

    def run_driver(area, dim=3):
        for _ in driver(area, dim).blocks():
            pass

    k_steps = max(n_steps // 2, 1)                      # the sampled paths are held in memory (96 B/path-step)
    sampled = {a: driver(a, steps=k_steps).rough_path() for a in ("davie", None)}

    def run_kernel(area):
        threads = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            return solve(rb, sampled[area], mu0, LieHeun(), save_at="end").final
        finally:
            numba.set_num_threads(threads)

    cfg = [("kernel", run_kernel, "davie"), ("kernel", run_kernel, None), ("solve", run_solve, "davie"),
           ("solve", run_solve, None), ("driver", run_driver, "davie"), ("driver", run_driver, None),
           ("driver d=9", lambda a: run_driver(None, 9), None)]
    for _, fn, area in cfg:
        fn(area)
    times = {i: [] for i in range(len(cfg))}
    for _ in range(repeats):
        for i, (_, fn, area) in enumerate(cfg):
            t0 = time.process_time()
            fn(area)
            times[i].append(time.process_time() - t0)
    steps = [k_steps if name == "kernel" else n_steps for name, _, _ in cfg]
    ns = {i: 1e9 * statistics.median(t) / (n_paths * steps[i]) for i, t in times.items()}

    def pair(i, j):
        return statistics.median(a / b for a, b in zip(times[i], times[j]))

    print(f"area cost: {n_paths} paths x {n_steps} steps ({k_steps} for the sampled path), LieHeun, CPU time "
          f"(all threads), medians of {repeats} interleaved runs, ns per path-step")
    print(f"  {'':34s} {'Davie area':>10s} {'no area':>8s} {'ratio':>6s} {'pairs':>6s}")
    print(f"  {'solver on a sampled path, 1 thread':34s} {ns[0]:10.1f} {ns[1]:8.1f} {ns[0] / ns[1]:6.2f} "
          f"{pair(0, 1):6.2f}   (target <= 1.6)")
    print(f"  {'full solve':34s} {ns[2]:10.1f} {ns[3]:8.1f} {ns[2] / ns[3]:6.2f} {pair(2, 3):6.2f}")
    print(f"  {'driver alone':34s} {ns[4]:10.1f} {ns[5]:8.1f} {ns[4] / ns[5]:6.2f} {pair(4, 5):6.2f}")
    six = ns[6] - ns[5]
    print(f"  6 more normals a path-step (driver d=9 - d=3, no area): {six:.1f} ns; floor of the full-solve ratio "
          f"with numpy's normals: ({ns[3]:.1f} + {six:.1f}) / {ns[3]:.1f} = {(ns[3] + six) / ns[3]:.2f}")
    return ns[0] / ns[1]


def _machine_scaling(repeats):
    """This machine's wall-time ratio for two copies of a job on two threads against both on one, for a loop
    bound by its own arithmetic (8 independent multiply-add chains in registers) and for a loop that streams
    a 256 KiB array from the L2 cache: what two threads can give a compute-bound and a memory-bound kernel."""
    import threading

    import numba

    @numba.njit(nogil=True)
    def registers(n):
        a0 = a1 = a2 = a3 = a4 = a5 = a6 = a7 = 1.0
        for _ in range(n):
            a0 = a0 * 1.0000001 + 1e-9
            a1 = a1 * 1.0000002 + 1e-9
            a2 = a2 * 1.0000003 + 1e-9
            a3 = a3 * 1.0000004 + 1e-9
            a4 = a4 * 1.0000005 + 1e-9
            a5 = a5 * 1.0000006 + 1e-9
            a6 = a6 * 1.0000007 + 1e-9
            a7 = a7 * 1.0000008 + 1e-9
        return a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7

    @numba.njit(nogil=True)
    def streaming(a, reps):
        s = 0.0
        for r in range(reps):
            for i in range(a.size):
                s += a[i] * 1.5 + r
        return s

    arr = np.ones(1 << 15)
    jobs = (("registers", registers, (20_000_000,)), ("L2 stream", streaming, (arr, 600)))
    out = []
    for name, fn, args in jobs:
        fn(*args)
        ratios = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            fn(*args)
            fn(*args)
            one = time.perf_counter() - t0
            ts = [threading.Thread(target=fn, args=args) for _ in range(2)]
            t0 = time.perf_counter()
            for t in ts:
                t.start()
            for t in ts:
                t.join()
            ratios.append((time.perf_counter() - t0) / one)
        out.append(f"{name} {statistics.median(ratios):.2f}")
    return ", ".join(out)


def bench_threads(n_paths, n_steps, repeats):
    """One thread against all of numba's threads on the full solve (driver sampling included), interleaved.

    Prints wall and process CPU time per path-step and, for the threaded run, the CPU time of the calling
    thread alone: the work is shared between the caller and the pool, so on an idle machine the wall time
    of the threaded run is about the caller's CPU time; on a machine whose other cores are busy the wall
    ratio measures the other load, and the caller's CPU time estimates what the threads give.
    """
    import numba

    from mechanics import LieHeun, rigid_body
    from roughpaths import BrownianDriver, solve

    rb = rigid_body(INERTIA, sigma=SIGMA, theta=THETA)
    mu0 = np.array([0.0, 0.0, 1.0])
    n_all = numba.get_num_threads()
    print(f"threads: 1 against {n_all} (numba.set_num_threads), full solve {n_paths} x {n_steps}, medians of "
          f"{repeats} interleaved runs, ns per path-step")
    if n_all == 2:
        print(f"  this machine, 2 jobs on 2 threads / on 1 (wall): {_machine_scaling(repeats)}")
    print(f"  {'problem':26s} {'wall 1':>8s} {'wall N':>8s} {'N/1':>5s} {'cpu 1':>8s} {'cpu N':>8s} {'N/1':>5s} "
          f"{'caller cpu N':>12s} {'/ cpu 1':>7s} {'bitwise':>7s}")
    for label, area in (("LieHeun + default area", "auto"), ("LieHeun + Davie area", "davie"),
                        ("LieHeun, no area", None)):
        def run():
            drv = BrownianDriver(3, seed=1, dt=DT, n_steps=n_steps, batch_shape=(n_paths,), levy_area=area)
            return solve(rb, drv, mu0, LieHeun(), save_at="end").final

        run()
        wall, cpu, caller, out = {1: [], n_all: []}, {1: [], n_all: []}, {1: [], n_all: []}, {}
        try:
            for _ in range(repeats):
                for t in (1, n_all):
                    numba.set_num_threads(t)
                    w0, c0, m0 = time.perf_counter(), time.process_time(), time.thread_time()
                    out[t] = run()
                    wall[t].append(time.perf_counter() - w0)
                    cpu[t].append(time.process_time() - c0)
                    caller[t].append(time.thread_time() - m0)
        finally:
            numba.set_num_threads(n_all)
        w1, wn, c1, cn, mn = (1e9 * statistics.median(x) / (n_paths * n_steps)
                              for x in (wall[1], wall[n_all], cpu[1], cpu[n_all], caller[n_all]))
        print(f"  {label:26s} {w1:8.1f} {wn:8.1f} {wn / w1:5.2f} {c1:8.1f} {cn:8.1f} {cn / c1:5.2f} {mn:12.1f} "
              f"{mn / c1:7.2f} {str(np.array_equal(out[1], out[n_all])):>7s}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="100 paths x 1,000 steps (smoke run)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--skip", default="", help="comma-separated peers to skip: diffrax,torchsde,sdeint")
    ap.add_argument("--threads-only", action="store_true", help="only the table of 1 thread against all")
    ap.add_argument("--area-only", action="store_true", help="only the table of the area's cost (with / without)")
    args = ap.parse_args(argv)
    n_paths, n_steps = (100, 1_000) if args.quick else (1_000, 10_000)
    sde_paths = 1 if args.quick else 4
    skip = set(filter(None, args.skip.split(",")))
    if args.threads_only:
        bench_threads(n_paths, min(n_steps, 1_000), max(args.repeats, 5))
        return 0
    if args.area_only:
        bench_area_ratio(n_paths, min(n_steps, 2_000), max(args.repeats, 5))
        return 0
    print(f"rigid body: I = diag(1,2,3), theta = {THETA}, sigma = {SIGMA}, dt = {DT}, "
          f"{n_paths} paths x {n_steps} steps, float64, repeats = {args.repeats}, "
          f"cpus = {os.cpu_count()}; wall and process CPU time (all threads), medians")
    rows = []

    print(f"  {'':32s} {'wall s':>8s} {'ns/path-step':>12s} {'CPU s':>8s} {'ns/path-step':>12s}   max||Pi(T)|-1|")

    def record(name, paths, fn):
        try:
            (tw, tc), final = fn()
        except ImportError as exc:
            print(f"  {name:32s} not installed ({exc.name}); skipped")
            return
        nw, nc = (t / (paths * n_steps) * 1e9 for t in (tw, tc))
        rows.append((name, nw, nc))
        print(f"  {name:32s} {tw:8.3f} {nw:12.1f} {tc:8.3f} {nc:12.1f}   {_norm_err(final):.2e}")

    record("ours LieHeun + Levy area", n_paths, lambda: bench_ours(n_paths, n_steps, args.repeats, True))
    record("ours LieHeun, no area", n_paths, lambda: bench_ours(n_paths, n_steps, args.repeats, False))
    record("  (BrownianDriver alone, Davie)", n_paths, lambda: bench_driver_only(n_paths, n_steps, args.repeats))
    record("  (run_ensemble, same problem)", n_paths, lambda: bench_ensemble(n_paths, n_steps, args.repeats))
    record("  (heavy top, LieHeun + area)", n_paths, lambda: bench_heavy_top(n_paths, n_steps, args.repeats))
    if "diffrax" not in skip:
        record("diffrax Heun (batched 3xN)", n_paths, lambda: bench_diffrax(n_paths, n_steps, args.repeats))
    if "torchsde" not in skip:
        record("torchsde heun", n_paths, lambda: bench_torchsde(n_paths, n_steps, args.repeats))
    if "sdeint" not in skip:
        record(f"sdeint stratHeun ({sde_paths} paths)", sde_paths,
               lambda: bench_sdeint(sde_paths, n_steps, max(1, args.repeats // 3)))
    ran = [r[0] for r in rows]
    print("peers that ran:", ", ".join(ran[5:]) or "none")
    print("ratios (ns per path-step, row / ours with Levy area):  wall    CPU")
    for name, nw, nc in rows[1:]:
        print(f"  {name:32s} {nw / rows[0][1]:20.2f}x {nc / rows[0][2]:6.2f}x")
    bench_area_ratio(n_paths, min(n_steps, 2_000), max(args.repeats, 5))
    bench_threads(n_paths, min(n_steps, 1_000), max(args.repeats, 5))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
