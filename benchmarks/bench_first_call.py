"""Benchmark: the first call of every public family in a fresh process, cold and warm (targets 10 s / 1 s).

A *cold* cell is a new Python process with an empty numba cache (``NUMBA_CACHE_DIR`` set to a new
folder): it imports the packages, makes the family's first call (numba compiles what the call reaches)
and reports the CPU time of the process and the wall time, import included. The *warm* cell is a second
process on the same cache folder (what a user meets after the install-time warm-up, or on the second
run): the kernels are loaded from disk. Imports (of the library and, for the torch and JAX steps, of the
framework and its front end: about 1 s each for torch and jax themselves) count as setup, not as the call. Targets (issue "First contact"): cold <= 10 s, warm <= 1 s.

``--breakdown`` prints, for every cold cell, the kernels that took longest to compile (numba's
compile events, inclusive of what a kernel inlines or calls for the first time), so that compile
time can be traced to one kernel and one specialisation.

Usage: ``python benchmarks/bench_first_call.py [--only NAME,...] [--breakdown] [--top K]``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

SETUP = {
    "sig": "rng = np.random.default_rng(0); x = np.cumsum(rng.standard_normal((16, 100, 3)), axis=1) * 0.1",
}

#: family -> (setup, call); each call is what a user's first try looks like
FAMILIES = {
    "signature depth 2-4": ("sig", "rp.signature(x, 2); rp.signature(x, 3); rp.signature(x, 4)"),
    "logsignature depth 4": ("sig", "rp.logsignature(x, 4)"),
    "signature_vjp depth 4": ("sig", "rp.signature_vjp(x, 4, np.ones((16, rp.sigdim(3, 4))))"),
    # one path: the one-unit kernels (forward: the blocked kernel's depth-3 variant; backward), not the lanes
    "signature_vjp, one path": ("sig", "rp.signature_vjp(x[0], 3, np.ones(rp.sigdim(3, 3)))"),
    # two paths of 2100 points: each cut into work units, whose cotangents a kernel of their own glues first
    "signature_vjp, long paths": ("sig", "xl = np.cumsum(rng.standard_normal((2, 2100, 3)), axis=1) * 0.01\n"
                                         "rp.signature_vjp(xl, 3, np.ones((2, rp.sigdim(3, 3))))"),
    "logsignature_vjp depth 4": ("sig", "rp.logsignature_vjp(x, 4, np.ones((16, rp.logsigdim(3, 4))))"),
    "torch step (sig depth 3)": ("sig torch", "t = torch.tensor(x, requires_grad=True)\n"
                                              "rt.signature(t, 3).sum().backward()"),
    "jax step (sig depth 3)": ("sig jax", "jax.grad(lambda a: rj.signature(a, 3).sum())(x)"),
    # one short path: the compiled XLA handlers of roughpaths.jax (roughpaths.signatures.xla_handlers) take it
    "jax step, one path (depth 3)": ("sig jax", "jax.grad(lambda a: rj.signature(a, 3).sum())(x[0, :8])"),
    # a deep signature: the one-unit kernel's run-time variant that updates the lower levels in place
    "signature depth 9 (in place)": ("sig", "rp.signature(x[:2], 9)"),
    "signature_coefficients (words)": ("sig", "rp.signature_coefficients(x, [(0, 1), (2, 0, 1), (1, 1, 2, 0)])"),
    # the first job split over threads: the workers' idle and watch loops (roughpaths._threads._idle, _watch, _open) compile
    "parallel_ranges (work sharing)": ("", "from roughpaths.validation import parallel_ranges\n"
                                           "parallel_ranges(lambda lo, hi: None, 2, 1)"),
    "signature kernel + gram": ("sig", "rp.signature_kernel(x[:4], x[4:8]); "
                                       "rp.signature_kernel_gram(x[:4], x[4:8])"),
    "Brownian driver d=2,3": ("", "for d in (2, 3):\n"
                                  "    rp.BrownianDriver(d, seed=0, dt=0.01, n_steps=50, batch_shape=(8,)).rough_path()"),
    "Brownian tree": ("", "rp.BrownianTree(3, seed=0).area(0.1, 0.3)"),
    "solve Euler/Heun": ("lin", "for m in (rp.Euler(), rp.Heun()): rp.solve(V, X, y0, m)"),
    "solve Davie/LogODE": ("lin", "for m in (rp.Davie(), rp.LogODE()): rp.solve(V, X, y0, m)"),
    "solve Davie3/LogODE3": ("lin", "for m in (rp.Davie3(), rp.LogODE3()): rp.solve(V, XN, y0, m)"),
    "solve adaptive (tree)": ("lin", "rp.solve(V, rp.BrownianTree(2, seed=0, batch_shape=(4,)), y0[:4], rp.Davie(), "
                                     "step_control=rp.PIController(1e-2, 1e-2))"),
    "rigid body LieHeun": ("", "from mechanics import rigid_body, LieHeun\n"
                               "b = rigid_body([1.0, 2.0, 3.0], sigma=0.1)\n"
                               "rp.solve(b, rp.BrownianDriver(3, seed=0, dt=0.01, n_steps=20, batch_shape=(4,)), "
                               "np.ones((4, 3)), LieHeun())"),
    "rigid body, large steps": ("", "from mechanics import rigid_body, LieHeun\n"       # the exact-step variants
                                    "b = rigid_body([1.0, 2.0, 3.0], sigma=2.0)\n"
                                    "rp.solve(b, rp.BrownianDriver(3, seed=0, dt=0.05, n_steps=20, batch_shape=(4,)), "
                                    "np.ones((4, 3)), LieHeun())"),
    "user algebra (su2) LieHeun": ("", "from mechanics import LiePoissonSystem, LieHeun\n"
                                       "from mechanics.systems.lie_algebra import su2\n"
                                       "s = LiePoissonSystem(su2(), np.eye(3), np.eye(3), theta=0.1)\n"
                                       "rp.solve(s, rp.BrownianDriver(3, seed=0, dt=0.01, n_steps=20, "
                                       "batch_shape=(4,)), np.ones((4, 3)), LieHeun())"),
    "heavy top LieHeun": ("", "from mechanics import heavy_top, LieHeun\n"
                              "t = heavy_top([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], sigma=0.1)\n"
                              "rp.solve(t, rp.BrownianDriver(3, seed=0, dt=0.01, n_steps=20, batch_shape=(4,)), "
                              "np.tile([0.1, 0.2, 0.3, 0.0, 0.0, 1.0], (4, 1)), LieHeun())"),
    "matrix algebra su(6) LieHeun": ("", "from mechanics import LiePoissonSystem, LieHeun, su\n"
                                         "g = su(6)\n"
                                         "s = LiePoissonSystem(g, np.ones(g.dim), 0.3 * np.eye(g.dim)[:3], theta=0.1)\n"
                                         "rp.solve(s, rp.BrownianDriver(3, seed=0, dt=0.01, n_steps=20, "
                                         "batch_shape=(4,)), np.ones((4, g.dim)), LieHeun())"),
    # adaptive steps per member on a tree: the walk, the loop's kernels and the so(3) / se(3) / generic member steps
    "rigid body, adaptive": ("", "from mechanics import rigid_body, LieHeun\n"
                                 "b = rigid_body([1.0, 2.0, 3.0], sigma=0.5)\n"
                                 "rp.solve(b, rp.BrownianTree(3, seed=0, batch_shape=(4,)), np.ones((4, 3)), "
                                 "LieHeun(), step_control=rp.PIController(1e-2, 1e-2))"),
    "heavy top, adaptive": ("", "from mechanics import heavy_top, LieHeun\n"
                                "t = heavy_top([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], sigma=0.3)\n"
                                "rp.solve(t, rp.BrownianTree(3, seed=0, batch_shape=(4,)), "
                                "np.tile([0.1, 0.2, 0.3, 0.0, 0.0, 1.0], (4, 1)), LieHeun(), "
                                "step_control=rp.PIController(1e-2, 1e-2))"),
    "su(2), adaptive": ("", "from mechanics import LiePoissonSystem, LieHeun, su2\n"
                            "s = LiePoissonSystem(su2(), np.diag([1.0, 2.0, 3.0]), 0.5 * np.eye(3), theta=1.0)\n"
                            "rp.solve(s, rp.BrownianTree(3, seed=0, batch_shape=(4,)), np.ones((4, 3)), LieHeun(), "
                            "step_control=rp.PIController(1e-2, 1e-2))"),
    "run_ensemble (rigid body)": ("", "from mechanics import rigid_body, run_ensemble\n"
                                      "run_ensemble(rigid_body([1.0, 2.0, 3.0], sigma=0.1), np.ones(3), dt=0.01, "
                                      "n_steps=8, n_paths=4, seed=0)"),
}

SETUP["sig torch"] = SETUP["sig"] + "\nimport torch, roughpaths.torch as rt"      # the framework's import is
SETUP["sig jax"] = SETUP["sig"] + "\nimport jax, roughpaths.jax as rj"            # setup (about 1 s each)
SETUP["lin"] = ("rng = np.random.default_rng(0); V = rp.LinearVectorFields(rng.standard_normal((2, 3, 3)) * 0.3)\n"
                "X = rp.brownian_rough_path(np.linspace(0, 1, 33), dim=2, rng=rng, batch_shape=(8,))\n"
                "XN = rp.RoughPathN.from_rough_path(X, 3)\n"
                "y0 = np.ones((8, 3))")

CODE = r"""
import json, os, resource, sys, time
def cpu():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime
events = []
if os.environ.get("BENCH_BREAKDOWN"):
    from numba.core import event as ev
    class T(ev.Listener):
        stack = []
        def on_start(self, e):
            self.stack.append(time.perf_counter())
        def on_end(self, e):
            t = time.perf_counter() - self.stack.pop()
            d = e.data.get("dispatcher")
            name = getattr(getattr(d, "py_func", None), "__module__", "?") + "." + getattr(getattr(d, "py_func", None), "__qualname__", "?")
            events.append((name, str(e.data.get("args")), t))
    ev.register("numba:compile", T())
w0, c0 = time.perf_counter(), cpu()
import numpy as np
import roughpaths as rp
SETUP
w1, c1 = time.perf_counter(), cpu()
CALL
w2, c2 = time.perf_counter(), cpu()
CALL
w3, c3 = time.perf_counter(), cpu()
print(json.dumps(dict(import_wall=w1 - w0, import_cpu=c1 - c0, wall=w2 - w0, cpu=c2 - c0, call_wall=w2 - w1,
                      call_cpu=c2 - c1, again=w3 - w2, events=events)))
"""


def run_cell(setup: str, call: str, cache: str, breakdown: bool) -> dict:
    code = CODE.replace("SETUP", SETUP.get(setup, "")).replace("CALL", call)
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    if breakdown:
        env["BENCH_BREAKDOWN"] = "1"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    if out.returncode != 0:
        raise RuntimeError(out.stderr[-3000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", default="", help="comma-separated substrings of family names")
    parser.add_argument("--breakdown", action="store_true", help="print the slowest compiles of each cold cell")
    parser.add_argument("--top", type=int, default=8)
    args = parser.parse_args()
    only = [s.strip() for s in args.only.split(",") if s.strip()]
    print(f"load: {os.getloadavg()[0]:.1f}; cold = empty numba cache (CPU and wall time of the process, import "
          "included), warm = the first call in a second process on that cache (import not included)")
    print(f"{'family':<30}{'cold CPU s':>11}{'cold wall s':>12}{'warm call CPU s':>16}{'warm call wall s':>17}"
          f"{'import+setup s':>15}{'2nd call s':>11}  targets 10 / 1")
    for name, (setup, call) in FAMILIES.items():
        if only and not any(o in name for o in only):
            continue
        with tempfile.TemporaryDirectory() as cache:
            cold = run_cell(setup, call, cache, args.breakdown)
            warm = run_cell(setup, call, cache, False)
        ok = "met" if cold["cpu"] <= 10 and warm["call_wall"] <= 1 else "NOT met"
        print(f"{name:<30}{cold['cpu']:>11.1f}{cold['wall']:>12.1f}{warm['call_cpu']:>16.2f}"
              f"{warm['call_wall']:>17.2f}{warm['import_wall']:>15.2f}{cold['again']:>11.4f}  {ok}", flush=True)
        if args.breakdown:
            for kname, sig, t in sorted(cold["events"], key=lambda e: -e[2])[:args.top]:
                print(f"      {t:7.2f} s  {kname}  {sig[:90]}")


if __name__ == "__main__":
    main()
