"""Benchmark: adaptive steps on a Brownian tree against fixed steps, and against diffrax's adaptive solve.

Issues "One Brownian path at every resolution", part 3, and "One time loop with step control as a contract"
(targets: the noise burst, 64 paths, rtol = atol = 1e-3, steps per path, <= 1 s of CPU in total; >= 5x less CPU
than diffrax at equal strong error at 1e-2 and 1e-3; the rigid body with LieHeun, adaptive, 1000 paths, within
3x the CPU of the fixed-step solve of equal error). Everything in one run, CPU time (``process_time``: every
thread of the process counts, so JAX/XLA threads are charged), float64, Stratonovich.

Problems
--------
* **Noise burst** (non-commuting linear SDE, e = 3, d = 2): ``dY = σ(t) Σ_i M_i Y ∘dW^i``, ``Y(0) = (1, 1, 1)``,
  ``T = 1``, ``M = 0.3 · N(0, 1)^{2×3×3}`` (seed 3), ``σ(t) = 0.2 + 3 exp(-((t - 0.5)/0.02)²)``: the noise is 16x
  stronger for a few hundredths of the interval. Both libraries cap the step at ``dt_max = 1/64``: an error
  estimate sees the fields only where it evaluates them, so a long step that starts before the burst can
  step over it.
* **Stochastic rigid body** (``mechanics.rigid_body``, I = diag(1, 2, 3), θ = 1, σ = 0.5, Π(0) = e3, d = 3),
  solved with ``LieHeun``: homogeneous noise, where adaptivity has little to find.

Method
------
1. Ours: ``solve(fields, BrownianTree(d, seed, batch_shape=(P,)), y0, Davie(), step_control=PIController(rtol,
   rtol, dt_max=1/64))``, steps per path (the fields are declared ``batched_time``, so every path is stepped on
   its own times in one call), and for comparison ``shared_steps=True`` (one step sequence for the batch, the
   error ratio the maximum over its paths). Its strong error is the RMS over paths of ``|Y(T) - Y_ref(T)|``, where ``Y_ref`` is a
   fixed-step Davie solve on the SAME tree (``tree.rough_path(grid)``) on a dyadic grid of spacing ``2^-13``,
   refined to ``2^-k_in`` on [0.4375, 0.5625] where the burst is (σ is within 2·10⁻⁴ of 0.2 outside); the
   script prints the reference's own error estimate (its difference to the grid with half the inner
   resolution: for an order-1 scheme about the reference's error). Compared with a uniform grid on the
   same tree with (a) as many steps as the adaptive solve accepted (per path: the mean), (b) as many solver steps
   as it took in all (3 per attempt: one whole step and two half steps); the uniform grids' ends are rounded to
   2^-24. The rigid body (``--rb-paths``, default 1000) is solved adaptively (steps per path, the default,
   then shared by the batch) and on uniform grids of 2^4 .. 2^10 steps; the fixed-step CPU at the adaptive
   solve's error is interpolated log-log, once for the solve alone on the tree's stored grid (its noise drawn
   beforehand, not timed) and once for the fixed-step solve a user runs, whose noise a ``BrownianDriver``
   draws on the way (timed; its error is the tree's at the same steps, the same law).
2. diffrax (``bench`` extra): ``diffeqsolve`` with ``SPaRK`` (its recommended adaptive SDE solver: an embedded
   error estimate; strong order ½ on general noise), ``VirtualBrownianTree(tol=2^-22,
   levy_area=SpaceTimeLevyArea)``, ``PIDController(rtol, atol=rtol, pcoeff=0.1, icoeff=0.3, dtmax=1/64)``,
   ``jit(vmap)`` over P paths (per-path steps), compile excluded. Its reference is the same solve at
   ``rtol = 3e-6`` on the same trees (the script prints its difference to ``rtol = 1e-5``).
3. Work–precision: for each library, attempts per path and CPU time per path against strong error; the
   attempts and CPU time needed for target errors are interpolated log-log between bracketing tolerances
   (or extrapolated with the law fitted to the last three, marked "fit").

Usage: ``python benchmarks/bench_adaptive_steps.py [--quick] [--paths P] [--rb-paths P] [--no-diffrax]``. Full:
64 paths, rtol 1e-1 … 1e-4 (ours) and 1e-2 … 1e-4 (diffrax), 1000 rigid-body paths, about 15 minutes on 2
cores; ``--quick``: 16 paths, coarser reference, about 2 minutes (a smoke run).
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))
Y0 = np.ones(3)
DT_MAX = 1 / 64


def sigma(t, xp=np):
    return 0.2 + 3.0 * xp.exp(-((t - 0.5) / 0.02) ** 2)


def _burst_fields():
    import roughpaths as rp
    return rp.VectorFields(lambda t, y: sigma(t)[..., None] * np.einsum("iab,...b->...ai", M, y),
                           lambda t, y: sigma(t)[..., None, None] * np.broadcast_to(M, y.shape[:-1] + M.shape),
                           dim_state=3, dim_noise=2, time_dependent=True, batched_time=True)


def _rms(a, b):
    return float(np.sqrt(np.mean(np.sum((np.asarray(a) - np.asarray(b)) ** 2, axis=-1))))


def _uniform(n):
    """``n`` uniform steps on [0, 1], their ends rounded to multiples of 2^-24 (a relative change of the steps
    below 10^-3 here) so that the tree answers them from depth <= 24 instead of 40."""
    return np.unique(np.round(np.linspace(0.0, 1.0, n + 1) * 2.0 ** 24) / 2.0 ** 24)


def _two_level_grid(k_out, k_in, lo=0.4375, hi=0.5625):
    """Dyadic grid: spacing 2^-k_out outside [lo, hi], 2^-k_in inside (lo, hi dyadic)."""
    return np.unique(np.concatenate([np.arange(0, 2 ** k_out + 1) / 2 ** k_out,
                                     lo + np.arange(0, int((hi - lo) * 2 ** k_in) + 1) / 2 ** k_in]))


def _interp(errs, work, target):
    """Work to reach ``target``: log-log between bracketing points (errs decreasing), else a fit to the last 3."""
    for i in range(len(errs) - 1):
        if errs[i] >= target >= errs[i + 1] and errs[i] > errs[i + 1]:
            s = math.log(errs[i] / target) / math.log(errs[i] / errs[i + 1])
            return math.exp(math.log(work[i]) + s * math.log(work[i + 1] / work[i])), "interp"
    p, c = np.polyfit(np.log(errs[-3:]), np.log(work[-3:]), 1)
    return float(math.exp(c) * target ** p), "fit"


# ------------------------------------------------------------------------------------------------ ours
def ours_burst(paths, rtols, k_in, seed, shared_rtols):
    import roughpaths as rp
    V = _burst_fields()
    tree = rp.BrownianTree(2, seed=seed, batch_shape=(paths,))
    t0 = time.process_time()
    ref = rp.solve(V, tree.rough_path(_two_level_grid(13, k_in)), Y0, rp.Davie(), save_at="end").final
    ref_half = rp.solve(V, tree.rough_path(_two_level_grid(13, k_in - 1)), Y0, rp.Davie(), save_at="end").final
    print(f"   reference: Davie on the same tree, dyadic grid 2^-13 outside [0.4375, 0.5625], 2^-{k_in} inside "
          f"({_two_level_grid(13, k_in).size - 1} steps); its difference to 2^-{k_in - 1} inside: "
          f"{_rms(ref, ref_half):.2e}  ({time.process_time() - t0:.0f} s CPU)")
    rows = []
    print(f"   {'steps':>6s} {'rtol':>7s} {'error':>9s} {'accepted':>8s} {'rejected':>8s} {'CPU total':>9s} "
          f"{'CPU/path':>9s} | {'uniform, same steps':>19s} {'ratio':>6s} | {'uniform, same work':>18s} {'ratio':>6s}")
    for shared, rts in ((False, rtols), (True, shared_rtols)):
        for rtol in rts:
            t0 = time.process_time()
            sol = rp.solve(V, tree, Y0, rp.Davie(), step_control=rp.PIController(rtol, rtol, dt_max=DT_MAX),
                           save_at="end", shared_steps=shared)
            cpu = time.process_time() - t0
            acc, rej = float(np.mean(sol.stats["accepted"])), float(np.mean(sol.stats["rejected"]))
            err = _rms(sol.final, ref)
            u1 = _rms(rp.solve(V, tree.rough_path(_uniform(round(acc))), Y0, rp.Davie(), save_at="end").final, ref)
            u3 = _rms(rp.solve(V, tree.rough_path(_uniform(round(3 * (acc + rej)))), Y0, rp.Davie(),
                               save_at="end").final, ref)
            if not shared:
                rows.append((rtol, err, acc + rej, cpu / paths))
            print(f"   {'shared' if shared else 'path':>6s} {rtol:7.0e} {err:9.2e} {acc:8.0f} {rej:8.0f} {cpu:8.2f}s "
                  f"{cpu / paths * 1e3:7.2f}ms | {u1:19.2e} {u1 / err:6.1f} | {u3:18.2e} {u3 / err:6.1f}", flush=True)
    slope = np.polyfit(np.log([r[0] for r in rows]), np.log([r[1] for r in rows]), 1)[0]
    print(f"   steps per path: fitted error ~ rtol^{slope:.2f}")
    return rows


def ours_rigid_body(paths, rtols, seed):
    import roughpaths as rp
    from mechanics import LieHeun, rigid_body
    system = rigid_body(np.array([1.0, 2.0, 3.0]), sigma=0.5, theta=1.0)
    mu0 = np.array([0.0, 0.0, 1.0])
    tree = rp.BrownianTree(3, seed=seed, batch_shape=(paths,))
    ref = rp.solve(system, tree.rough_path(np.linspace(0, 1, 2 ** 13 + 1)), mu0, LieHeun(), save_at="end").final
    print(f"   reference: LieHeun on the same tree, 2^13 uniform steps; {paths} paths")
    fixed, noisy = [], []
    for k in range(4, 11):
        grid = tree.rough_path(np.linspace(0, 1, 2 ** k + 1))
        t0 = time.process_time()
        f = rp.solve(system, grid, mu0, LieHeun(), save_at="end").final
        fixed.append((_rms(f, ref), time.process_time() - t0))
        # the same fixed-step solve as a user runs it, its noise drawn on the way (a BrownianDriver, default areas):
        # the error is the tree's at these steps (the same law), the CPU time includes the noise
        X = rp.BrownianDriver(3, seed=seed, dt=2.0 ** -k, n_steps=2 ** k, batch_shape=(paths,))
        t0 = time.process_time()
        rp.solve(system, X, mu0, LieHeun(), save_at="end")
        noisy.append(time.process_time() - t0)
    print("   fixed steps: " + ", ".join(f"2^{k}: {e:.2e} in {c:.3f}s" for k, (e, c) in zip(range(4, 11), fixed)))
    print("   fixed steps with their noise (BrownianDriver): " + ", ".join(
        f"2^{k}: {c:.3f}s" for k, c in zip(range(4, 11), noisy)))
    print(f"   {'steps':>6s} {'rtol':>7s} {'error':>9s} {'accepted':>8s} {'rejected':>8s} {'CPU total':>9s} "
          f"{'|Π|-1':>8s} | {'uniform, same steps':>19s} {'ratio':>6s} | {'fixed CPU, same error':>21s} "
          f"{'adaptive/fixed':>14s} | {'with noise':>10s} {'adaptive/it':>11s}")
    for shared, rtol in [(False, r) for r in rtols] + [(True, r) for r in rtols[:3]]:
        t0 = time.process_time()
        sol = rp.solve(system, tree, mu0, LieHeun(), step_control=rp.PIController(rtol, rtol), save_at="end",
                       shared_steps=shared)
        cpu = time.process_time() - t0
        acc, rej = float(np.mean(sol.stats["accepted"])), float(np.mean(sol.stats["rejected"]))
        err = _rms(sol.final, ref)
        cas = float(np.abs(np.linalg.norm(sol.final, axis=-1) - 1.0).max())
        u1 = _rms(rp.solve(system, tree.rough_path(_uniform(round(acc))), mu0, LieHeun(), save_at="end").final, ref)
        fcpu, how = _interp([e for e, _ in fixed], [max(c, 1e-6) for _, c in fixed], err)
        ncpu, _ = _interp([e for e, _ in fixed], [max(c, 1e-6) for c in noisy], err)
        print(f"   {'shared' if shared else 'path':>6s} {rtol:7.0e} {err:9.2e} {acc:8.0f} {rej:8.0f} {cpu:8.2f}s "
              f"{cas:8.1e} | {u1:19.2e} "
              f"{u1 / err:6.1f} | {fcpu:17.3f}s {how:>3s} {cpu / fcpu:14.1f} | {ncpu:9.3f}s {cpu / ncpu:11.1f}",
              flush=True)


# ------------------------------------------------------------------------------------------------ diffrax
def diffrax_burst(paths, rtols, ref_rtols, seed):
    import jax
    jax.config.update("jax_enable_x64", True)
    import diffrax
    import jax.numpy as jnp
    Mj = jnp.asarray(M)

    def drift(t, y, args):
        return jnp.zeros_like(y)

    def diffusion(t, y, args):
        return sigma(t, jnp) * jnp.einsum("iab,b->ai", Mj, y)

    def make(rtol):
        def one(key):
            bm = diffrax.VirtualBrownianTree(0.0, 1.0, tol=2.0 ** -22, shape=(2,), key=key,
                                             levy_area=diffrax.SpaceTimeLevyArea)
            terms = diffrax.MultiTerm(diffrax.ODETerm(drift), diffrax.ControlTerm(diffusion, bm))
            ctrl = diffrax.PIDController(rtol=rtol, atol=rtol, pcoeff=0.1, icoeff=0.3, dtmax=DT_MAX)
            sol = diffrax.diffeqsolve(terms, diffrax.SPaRK(), 0.0, 1.0, DT_MAX, jnp.asarray(Y0),
                                      stepsize_controller=ctrl, saveat=diffrax.SaveAt(t1=True), max_steps=2 ** 20,
                                      adjoint=diffrax.ForwardMode())
            return sol.ys[0], sol.stats["num_accepted_steps"], sol.stats["num_rejected_steps"]
        return jax.jit(jax.vmap(one))

    keys = jax.random.split(jax.random.PRNGKey(seed), paths)
    refs = []
    t0 = time.process_time()
    for r in ref_rtols:
        refs.append(np.asarray(make(r)(keys)[0]))
    ref = refs[-1]
    print(f"   reference: SPaRK at rtol {ref_rtols[-1]:.0e} on the same trees; its difference to rtol "
          f"{ref_rtols[0]:.0e}: {_rms(refs[0], ref):.2e}  ({time.process_time() - t0:.0f} s CPU)")
    rows = []
    print(f"   {'rtol':>7s} {'error':>9s} {'accepted':>8s} {'rejected':>8s} {'CPU/path':>9s}   (per-path means)")
    for rtol in rtols:
        fn = make(rtol)
        fn(keys)[0].block_until_ready()                 # compile (excluded)
        t0 = time.process_time()
        y, acc, rej = fn(keys)
        y.block_until_ready()
        cpu = (time.process_time() - t0) / paths
        err = _rms(y, ref)
        acc, rej = float(np.mean(acc)), float(np.mean(rej))
        rows.append((rtol, err, acc + rej, cpu))
        print(f"   {rtol:7.0e} {err:9.2e} {acc:8.0f} {rej:8.0f} {cpu * 1e3:7.2f}ms", flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small smoke run (about 2 minutes)")
    ap.add_argument("--paths", type=int, default=None)
    ap.add_argument("--no-diffrax", action="store_true", help="skip diffrax (no bench extra)")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--rb-paths", type=int, default=None, help="rigid-body paths (default 1000; --quick 64)")
    args = ap.parse_args(argv)
    if args.quick:
        paths, rtols, k_in, dfx_rtols, dfx_ref = 16, [1e-2, 3e-3, 1e-3], 17, [1e-2, 1e-3], [1e-4, 3e-5]
        rb_rtols, shared_rtols, rb_paths = [1e-2, 1e-3], [1e-2], 64
    else:
        paths, rtols, k_in, dfx_rtols, dfx_ref = 64, [1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], 20, \
            [1e-2, 3e-3, 1e-3, 3e-4, 1e-4], [1e-5, 3e-6]
        rb_rtols, shared_rtols, rb_paths = [1e-2, 3e-3, 1e-3, 3e-4], [1e-2, 3e-3, 1e-3], 1000
    paths = args.paths or paths
    rb_paths = args.rb_paths or rb_paths
    import roughpaths as rp
    rp.solve(_burst_fields(), rp.BrownianTree(2, seed=0), Y0, rp.Davie(),
             step_control=rp.PIController(1e-1, 1e-1))            # compile / cache load (excluded)
    rp.solve(_burst_fields(), rp.BrownianTree(2, seed=0, batch_shape=(2,)), Y0, rp.Davie(),
             step_control=rp.PIController(1e-1, 1e-1))
    print(f"cpus = {os.cpu_count()}, clock = CPU time (process_time), {paths} paths, float64")
    print("\n1. noise burst, ours: Davie, adaptive on a BrownianTree (steps per path, then shared by the batch) "
          "against uniform grids on the same tree")
    ours = ours_burst(paths, rtols, k_in, args.seed, shared_rtols)
    print("\n2. stochastic rigid body (sigma = 0.5, theta = 1), ours: LieHeun, adaptive vs uniform on the same tree")
    ours_rigid_body(rb_paths, rb_rtols, args.seed + 1)
    if args.no_diffrax:
        return
    print("\n3. noise burst, diffrax: SPaRK + VirtualBrownianTree(SpaceTimeLevyArea) + PIDController, jit(vmap)")
    dfx = diffrax_burst(paths, dfx_rtols, dfx_ref, args.seed)
    for name, rows in (("ours", ours), ("diffrax", dfx)):
        p = np.polyfit(np.log([r[2] for r in rows]), np.log([r[1] for r in rows]), 1)[0]
        print(f"   {name}: error ~ attempts^{p:.2f}")
    print("\n4. work-precision on the noise burst (attempts and CPU time per path to reach a strong error; "
          "interpolated log-log, 'fit' = extrapolated)")
    print(f"   {'error':>7s} | {'ours attempts':>13s} {'ours CPU':>10s} | {'diffrax attempts':>16s} "
          f"{'diffrax CPU':>11s} | {'CPU ratio diffrax/ours':>22s}")
    for target in (3e-2, 1e-2, 3e-3, 1e-3):
        cells = []
        for rows in (ours, dfx):
            errs = [r[1] for r in rows]
            a, how_a = _interp(errs, [r[2] for r in rows], target)
            c, how_c = _interp(errs, [r[3] for r in rows], target)
            cells.append((a, c, how_a))
        (oa, oc, oh), (da, dc, dh) = cells
        print(f"   {target:7.0e} | {oa:9.0f} {oh:>3s} {oc * 1e3:8.2f}ms | {da:12.0f} {dh:>3s} {dc * 1e3:9.2f}ms | "
              f"{dc / oc:22.1f}")


if __name__ == "__main__":
    main()
