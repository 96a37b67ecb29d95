"""Benchmark: the torch and JAX front ends, forward plus backward, against pysiglib's torch and JAX APIs.

Everything is timed in one run on the same data, in CPU time (``time.process_time``: the machine is
shared, and CPU time does not count the time other processes hold the cores); each cell is the
median over ``--repeats`` interleaved pairs (ours, peer, ours, peer, ...), each timed call right
after an untimed call of the same function. "ratio" is ours / peer (below 1: ours is cheaper).

1. torch, forward + backward of ``sum(sig * G)`` with respect to the points, float64, batch of
   ``--batch`` paths of ``--length`` points, d = 3, 5, 8, depths 2-4: ``roughpaths.torch.signature``
   against ``pysiglib.torch_api.sig`` (``n_jobs=-1``); also the log-signature (Lyndon basis,
   pysiglib ``method=2``). Both libraries get the machine's threads; torch's own intra-op threads are
   set to 1 (``torch.set_num_threads(1)``) for both, since their idle spinning after a torch operation
   is counted as CPU time and is nobody's kernel.
2. The wrappers' own cost: a torch step (forward + backward) minus the bare numpy calls it makes
   (``roughpaths.signature`` + ``roughpaths.signature_vjp``), and the same for pysiglib
   (``pysiglib.torch_api.sig`` against ``pysiglib.sig`` + ``pysiglib.sig_backprop``), from a tiny
   input (one path of 8 points) up; "overhead ratio" is ours / pysiglib's (not printed where an overhead
   is within 3% of the step, the medians' noise: the large cells). Both include torch's own
   autograd cost (the ``torch.autograd.Function`` node, ``backward``'s argument checks), which is
   printed as "autograd floor": the same step through an identity ``Function``.
3. JAX: a jitted ``value_and_grad`` of ``sum(roughpaths.jax.signature(x, 3) * G)`` (two XLA FFI custom
   calls) against the bare numpy calls and against pysiglib's JAX API (its own XLA FFI custom calls
   into compiled C++) where it loads, at a tiny and a moderate size. The tiny one (one path of 8
   points) runs in the compiled handlers of ``roughpaths.signatures.xla_handlers`` (the numpy API's kernels
   called from numba C callbacks that read XLA's call frame), the others in the Python handler of
   ``roughpaths._xla_ffi`` (the numpy API called from Python). "host floor" is the same program through
   ``roughpaths.jax.differentiable`` with Python host functions that only allocate their (zero)
   results: the XLA program, the two host calls and their frames, without the numpy API; the compiled
   handlers run below it. Measured (two runs, 11 pairs, loaded 2-core machine): one path 0.021-0.023 ms
   against pysiglib's 0.017-0.018 (1.24-1.27x; the Python handler: 0.075-0.088 ms, 4.2-5.3x, host floor
   0.036-0.040); 32 x 128, d = 3 1.1-1.2x, d = 8 0.8x (Python handler).

Usage: ``python benchmarks/bench_frameworks.py [--repeats 7] [--batch 32] [--length 128] [--sections 123]``
(with ``PYTHONPATH`` putting this checkout first; needs torch, jax and pysiglib: the ``bench`` extra).
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np


def cpu_medians(fns, repeats: int) -> list:
    """Median CPU times of several functions timed in turn (ours, peer, ours, peer, ...)."""
    for fn in fns:
        fn()                                    # warm-up (compilation, caches)
    times = [[] for _ in fns]
    for _ in range(max(1, repeats)):
        for i, fn in enumerate(fns):
            fn()
            t0 = time.process_time()
            fn()
            times[i].append(time.process_time() - t0)
    return [float(np.median(t)) for t in times]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--length", type=int, default=128)
    parser.add_argument("--sections", default="123", help="which sections to run, e.g. 23")
    args = parser.parse_args()

    import numba
    import pysiglib
    import pysiglib.torch_api as pst
    import torch

    import roughpaths as rp
    import roughpaths.torch as rpt

    torch.set_num_threads(1)
    rng = np.random.default_rng(2026)
    B, n = args.batch, args.length
    print(f"numba threads {numba.get_num_threads()}, cpu count {os.cpu_count()}, load average "
          f"{os.getloadavg()[0]:.1f}; torch {torch.__version__}, pysiglib {pysiglib.__version__}")
    print(f"batch {B} paths x {n} points, float64; CPU-time medians of {args.repeats} interleaved pairs, in ms; "
          f"ratio = ours / peer (below 1: ours cheaper)\n")

    def fwd_bwd(fn, x, g):
        def run():
            xt = x.detach().requires_grad_()
            out = fn(xt)
            out.backward(g)
            return xt.grad
        return run

    for kind in ("signature", "log-signature") if "1" in args.sections else ():
        print(f"1. torch, forward + backward, {kind}")
        print(f"{'d':>3}{'depth':>7}{'ours':>10}{'pysiglib':>10}{'ratio':>8}{'max |Δgrad|':>14}")
        for d in (3, 5, 8):
            x = torch.from_numpy(np.cumsum(rng.standard_normal((B, n, d)), axis=1) / np.sqrt(n))
            for depth in (2, 3, 4):
                if kind == "signature":
                    ours = lambda p, m=depth: rpt.signature(p, m)
                    peer = lambda p, m=depth: pst.sig(p, m, n_jobs=-1)
                    width = rp.sigdim(d, depth)
                else:
                    pysiglib.prepare_log_sig(d, depth, method=2)
                    ours = lambda p, m=depth: rpt.logsignature(p, m)
                    peer = lambda p, m=depth: pst.log_sig(p, m, method=2, n_jobs=-1)
                    width = rp.logsigdim(d, depth)
                g = torch.from_numpy(rng.standard_normal((B, width)))
                f_o, f_p = fwd_bwd(ours, x, g), fwd_bwd(peer, x, g)
                t_o, t_p = cpu_medians((f_o, f_p), args.repeats)
                diff = float((f_o() - f_p()).abs().max())
                print(f"{d:>3}{depth:>7}{1e3 * t_o:>10.2f}{1e3 * t_p:>10.2f}{t_o / t_p:>8.2f}{diff:>14.1e}", flush=True)
        print()

    print("2. the torch wrappers' own cost (a step minus its bare numpy calls), signature, ms")
    print(f"{'case':<20}{'ours':>8}{'numpy':>8}{'overhead':>10}{'pysiglib':>10}{'numpy':>8}{'overhead':>10}"
          f"{'overhead ratio':>16}{'autograd floor':>16}")

    class Identity(torch.autograd.Function):
        @staticmethod
        def forward(ctx, p):
            return p * 1.0

        @staticmethod
        def backward(ctx, g):
            return g

    for B2, n2, d, depth in ((1, 8, 3, 2), (B, n, 3, 2), (B, n, 3, 4), (B, n, 8, 4)) if "2" in args.sections else ():
        xn = np.cumsum(rng.standard_normal((B2, n2, d)), axis=1) / np.sqrt(n2)
        gn = rng.standard_normal((B2, rp.sigdim(d, depth)))
        xt, gt = torch.from_numpy(xn), torch.from_numpy(gn)
        f_o = fwd_bwd(lambda p, m=depth: rpt.signature(p, m), xt, gt)
        f_on = lambda m=depth: (rp.signature(xn, m), rp.signature_vjp(xn, m, gn))
        f_p = fwd_bwd(lambda p, m=depth: pst.sig(p, m, n_jobs=-1), xt, gt)

        def f_pn(m=depth):
            s = pysiglib.sig(xn, m, n_jobs=-1)
            return pysiglib.sig_backprop(xn, s, gn, m, n_jobs=-1)
        f_id = fwd_bwd(Identity.apply, xt, xt)
        t = cpu_medians((f_o, f_on, f_p, f_pn, f_id), args.repeats)
        ov_o, ov_p = t[0] - t[1], t[2] - t[3]
        noise = 0.03 * max(t[:4])                # a difference below this is within the medians' noise
        ratio = f"{ov_o / ov_p:>16.2f}" if min(ov_o, ov_p) > noise else f"{'(in noise)':>16}"
        print(f"{f'{B2} x {n2}, d={d}, m={depth}':<20}{1e3 * t[0]:>8.3f}{1e3 * t[1]:>8.3f}{1e3 * ov_o:>10.3f}"
              f"{1e3 * t[2]:>10.3f}{1e3 * t[3]:>8.3f}{1e3 * ov_p:>10.3f}{ratio}{1e3 * t[4]:>16.3f}", flush=True)
    print()

    import jax
    import jax.numpy as jnp

    import roughpaths.jax as rpj

    jax.config.update("jax_enable_x64", True)
    try:
        import pysiglib.jax_api as psj
        psj.sig(jnp.zeros((2, 4, 3)), 2)
    except Exception as exc:                    # the FFI plugin may not load with this jax
        psj = None
        print(f"(pysiglib's JAX API did not load: {type(exc).__name__}: {str(exc)[:100]})")
    print("3. JAX, jitted forward + backward (value_and_grad of sum(sig * G)), depth 3, ms; ratio = ours / pysiglib")
    print(f"{'case':<22}{'ours':>10}{'numpy':>10}{'overhead':>10}{'host floor':>12}{'pysiglib':>10}{'ratio':>8}")
    for B3, n3, d in ((1, 8, 3), (B, n, 3), (B, n, 8)) if "3" in args.sections else ():
        xn = np.cumsum(rng.standard_normal((B3, n3, d)), axis=1) / np.sqrt(n3)
        gn = rng.standard_normal((B3, rp.sigdim(d, 3)))
        xj, gj = jnp.asarray(xn), jnp.asarray(gn)
        ours = jax.jit(jax.value_and_grad(lambda p: jnp.sum(rpj.signature(p, 3) * gj)))
        f_o = lambda: jax.block_until_ready(ours(xj))
        f_n = lambda: (rp.signature(xn, 3), rp.signature_vjp(xn, 3, gn))
        dim = rp.sigdim(d, 3)
        noop = rpj.differentiable(lambda p: np.zeros(p.shape[:-2] + (dim,)), lambda p, g: np.zeros(p.shape),
                                  lambda batch, cores: batch + (dim,), names=("paths",), core=(2,))
        floor = jax.jit(jax.value_and_grad(lambda p: jnp.sum(noop(p) * gj)))
        fns = [f_o, f_n, lambda: jax.block_until_ready(floor(xj))]
        if psj is not None:
            peer = jax.jit(jax.value_and_grad(lambda p: jnp.sum(psj.sig(p, 3, n_jobs=-1) * gj)))
            fns.append(lambda: jax.block_until_ready(peer(xj)))
        t = cpu_medians(fns, args.repeats)
        name = f"{B3} x {n3}, d={d}"
        ffi = f"{1e3 * t[3]:>10.3f}{t[0] / t[3]:>8.2f}" if psj is not None else f"{'-':>10}{'-':>8}"
        print(f"{name:<22}{1e3 * t[0]:>10.3f}{1e3 * t[1]:>10.3f}{1e3 * (t[0] - t[1]):>10.3f}{1e3 * t[2]:>12.3f}{ffi}",
              flush=True)


if __name__ == "__main__":
    main()
