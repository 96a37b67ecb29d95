"""Benchmark: signatures, log-signatures and their gradients against pysiglib and iisignature.

Everything is timed in one run on the same data. The machine is shared and noisy: medians of
interleaved calls and same-run ratios are what this prints.

First table (issue 22): every cell against pysiglib 4.0 in both modes, one thread (our
``numba.set_num_threads(1)`` against ``n_jobs=1``, CPU time ``time.process_time``) and all threads
(our default threads against ``n_jobs=-1``, wall time); each time is the median of ``--repeats``
interleaved pairs (ours, peer, ours, peer, ... each timed call right after an untimed call of the
same function). Cases: (d) 64 paths x 256 points, d = 8, depths 2-4; (e) 4 x 64, d = 20, depths
2-3; (f) one path of 1000 points, d = 3, depth 4 (and (f') four of them); (g) one 10 x 4 path at
depth 8; (h) 16 x 256, d = 6, depth 4; for the signature, the log-signature (Lyndon basis,
pysiglib ``method=2``) and their vector-Jacobian products (pysiglib: ``sig_backprop`` after
``sig``, and ``sig_to_log_sig_backprop`` in between for the log). Each signature row also prints a
floor: the FLOPs of the Horner update (:func:`horner_flops` per segment, times the segments) at
the rate this machine sustains for a vectorised multiply-add sweep in L1, or one pass over the
paths and the signatures at its copy bandwidth, whichever is larger; "vs floor" is our one-thread
time over it. "err/iisig" is the largest difference from iisignature relative to the largest
entry (the gradients of iisignature agree to about 1e-7 only).

Then the cases of the earlier runs: (a) one path of 100,000 points in d = 3; (b) 1,000 paths of
1,000 points, d = 3; (c) 32 paths of 1,000 points, d = 5; levels 2..5, all threads, with
iisignature (single-threaded); the gradient at depth 4 on (b); ``logsignature`` of a 10 x 3 path
at depth 10 in a fresh process; level 2 on (a) beside a CPU-bound process; bitwise equality of
results with 1 and 2 threads.

Last section, streams and words (issue 41; alone with ``--only-streams``): on a Brownian path of 10^6
points in d = 2 (step 1e-3) at depth 4, the error of S(s, t) for windows of 10, 1000 and 10^5 steps
against the direct signature of the sub-path, per level and relative to the level's largest entry, for
the prefixes-and-inverse answer S(0,s)^{-1} ⊗ S(0,t) and for ``SignatureStream`` (the tree of block
signatures); the stream's build and query times for several block sizes against direct signatures of the
sub-paths; ``windowed_signature`` against a batched direct computation; ``signature_coefficients``
against the full signature and iisignature.

Width sweep (issue 41, ``--sweep``, alone): every alphabet size d = 2..20 at depths 2..6, batches of
16 x 256 and 64 x 256 points (a Brownian walk scaled by 1/16), signature and log-signature (and, with
``--sweep-kinds``, the signature's VJP), ours against pysiglib ``n_jobs=1`` (one thread, CPU time) and
``n_jobs=-1`` (all threads, wall time), medians of interleaved pairs, printing the ratios and, at the
end, the cells above 1.0 (one thread) and 1.1 (parallel). Cells whose signature exceeds
``--sweep-max-sigdim`` floats per path (default 2e6; d = 20 at depth 5, d >= 12 at depth 6) are
skipped and listed. ``--sweep-d 2,6-9``, ``--sweep-depths 3,4``, ``--sweep-batches 16`` and
``--sweep-kinds sig,logsig,sig vjp`` select a subset; ``--sweep-modes 1`` runs the one-thread mode only.
A timed sample of a small cell is a loop of calls lasting about 2 ms (divided back to one call), timed in at
least 11 interleaved pairs. ``--sweep-general`` runs it with the kernels general in d only: the run-time
variant of the lane and the blocked kernels everywhere (no compile-time ``d`` or depth), to show what the
variants add.

Large cells and the machine: on a virtual machine that gives freed memory back to its host (Linux's free page
reporting; this project's machines do), a write to memory the process has not touched lately costs up to
about 2 ms a MB, charged to whichever library allocates next. Cells whose signatures take several MB a path
then move by 30-100 % between runs for both libraries (16 x 256 at d = 11, depth 6: pysiglib 1430 ms in one
sweep, 3112 in another; 64 x 256 at d = 12, depth 5, log-signature: ours 0.98 of pysiglib in a whole sweep, its
signature 0.45 in the same sweep). Time such a cell alone (``--sweep-d``, ``--sweep-depths``) before reading much
into one sweep's ratio.

``--bars`` is the done-when of issue 41 in one run: the peer table (d)-(h), the cases (a)-(c) and the width sweep
(with its options), in one process, then every cell against its bar (1.0 on one thread, 1.1 with all threads) and
the cells above it.

``--fixed-cost`` prints only the cost of a call on tiny inputs (one path of 8 points in d = 2, 3 at
depths 2-3, and 32 x 128 in d = 3), where the Python around the kernels is most of the time: ours,
iisignature and pysiglib on one thread, CPU time, medians of interleaved calls, and the ratios.

Usage: ``python benchmarks/bench_signatures.py [--repeats 5] [--quick] [--cells d,e] [--kinds sig,logsig]
[--depths 3,4] [--only-streams] [--sweep [--sweep-d 2-20] [--sweep-depths 2-6] [--sweep-batches 16,64]
[--sweep-kinds sig,logsig] [--sweep-modes 1,n] [--sweep-max-sigdim 2e6] [--sweep-general]] [--bars]
[--fixed-cost]`` (the cells, kinds and depths select peer-table cells and skip the rest).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np
from _timing import median_time as _median_time


def median_time(fn, repeats: int) -> float:
    t0 = time.perf_counter()
    fn()                                      # warm-up
    if time.perf_counter() - t0 > 2.0:        # very slow cell: fewer repeats
        repeats = min(repeats, 3)
    return _median_time(fn, repeats)


def interleaved_medians(fns, repeats: int) -> list:
    """Median wall times of several functions timed in turn (ours, peer, peer, ours, ...).

    On a shared machine a burst of load then hits every library of a cell alike, instead of
    whichever happened to be running. Each timed call directly follows an untimed call of the same
    function, so that it finds its own data in the caches as in a loop of calls (a call right
    after another library's measured up to 2x slower for small cells).
    """
    slow = False
    for fn in fns:
        t0 = time.perf_counter()
        fn()
        slow |= time.perf_counter() - t0 > 2.0
    repeats = min(repeats, 3) if slow else repeats
    times = [[] for _ in fns]
    for _ in range(max(1, repeats)):
        for i, fn in enumerate(fns):
            if not slow:
                fn()
            t0 = time.perf_counter()
            fn()
            times[i].append(time.perf_counter() - t0)
    return [float(np.median(t)) for t in times]


DEPTH10 = r"""
import time, tracemalloc, numpy as np
from roughpaths import logsigdim, logsignature
x = np.cumsum(np.random.default_rng(0).standard_normal((10, 3)), 0)
t_start = time.perf_counter()
logsignature(x[:3], 3)                     # load the compiled kernels (not the depth-10 map)
t_load = time.perf_counter() - t_start
tracemalloc.start()
t0 = time.perf_counter(); logsignature(x, 10); t1 = time.perf_counter()
peak = tracemalloc.get_traced_memory()[1]
tracemalloc.stop()
t2 = time.perf_counter(); logsignature(x, 10); t3 = time.perf_counter()
t4 = time.perf_counter(); logsigdim(2, 60); t5 = time.perf_counter()
hwm = [int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmHWM")][0]
print(t1 - t0, t3 - t2, peak, hwm, t5 - t4, t_load)
"""

IISIG10 = r"""
import time, numpy as np, iisignature
x = np.cumsum(np.random.default_rng(0).standard_normal((10, 3)), 0)
t0 = time.perf_counter(); p = iisignature.prepare(3, 10); iisignature.logsig(x, p); t1 = time.perf_counter()
hwm = [int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmHWM")][0]
print(t1 - t0, hwm)
"""


def _run(code: str) -> list:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    return [float(v) for v in out.stdout.split()]


def horner_flops(d: int, m: int) -> int:
    """Floating-point operations of one Horner segment update ``S <- S ⊗ exp(D)`` at depth ``m``."""
    f = d                                                      # level 1
    for lev in range(2, m + 1):
        f += d + sum(d ** j + d ** (j + 1) for j in range(1, lev - 1)) + d ** (lev - 1) + 2 * d ** lev
    return f


def machine_rates() -> tuple:
    """(flop/s of a vectorised multiply-add sweep in L1, bytes/s of one pass over a large array)."""
    import numba

    @numba.njit(cache=True)
    def sweep(y, x, reps):
        for _ in range(reps):
            for p in range(x.shape[0]):
                y[p] += x[p] * 1e-9
    y, x = np.zeros(2048), np.ones(2048)
    sweep(y, x, 1)
    t0 = time.process_time()
    sweep(y, x, 20000)
    flops = 2 * 2048 * 20000 / (time.process_time() - t0)
    big = np.ones(2 ** 23)
    out = np.empty_like(big)
    t0 = time.process_time()
    for _ in range(5):
        np.copyto(out, big)
    bandwidth = 5 * 2 * big.nbytes / (time.process_time() - t0)
    return flops, bandwidth


def paired(fns, repeats: int, clock) -> list:
    """Medians of interleaved timings (ours, peer, ours, peer, ...), each after an untimed call.

    A call of 50 ms or more is not preceded by an untimed call (its data do not fit in the caches a
    previous call could have warmed) and one of a second or more is timed in at most 3 pairs: the
    heaviest cells of the width sweep otherwise took most of its hour. Each sample starts after a 1 ms pause:
    our worker threads watch for a next job for about 0.1 ms after one (``roughpaths._threads``), and must not
    spend the peer's time.
    """
    first = []
    for fn in fns:
        t0 = time.perf_counter()
        fn()
        first.append(time.perf_counter() - t0)
    heavy = max(first) >= 0.05
    repeats = min(repeats, 3) if max(first) >= 1.0 else repeats
    times = [[] for _ in fns]
    for _ in range(max(1, repeats)):
        for i, fn in enumerate(fns):
            time.sleep(1e-3)
            if not heavy:
                fn()
            t0 = clock()
            fn()
            times[i].append(clock() - t0)
    return [float(np.median(t)) for t in times]


def fixed_cost_section(args) -> None:
    """The fixed cost of a call: tiny inputs, where the Python around the kernels is most of the time.

    One thread for everybody (``numba.set_num_threads(1)``, ``n_jobs=1``), CPU time, medians of
    ``100 * --repeats`` interleaved calls (ours, iisignature, pysiglib, ...), in microseconds.
    """
    import iisignature
    import numba
    import pysiglib

    import roughpaths as rp

    numba.set_num_threads(1)
    rng = np.random.default_rng(7)
    reps = 100 * args.repeats
    print(f"Fixed cost per call, one thread, CPU-time medians of {reps} interleaved calls, us; load average "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'case':<24}{'kind':<18}{'ours':>8}{'iisig':>8}{'pysiglib':>10}{'/iisig':>8}{'/pysiglib':>10}")
    for b, n, d, m in ((1, 8, 2, 3), (1, 8, 3, 3), (1, 8, 3, 2), (32, 128, 3, 3)):
        x = np.cumsum(rng.standard_normal((b, n, d)), axis=1) / np.sqrt(n)
        g = rng.standard_normal((b, rp.sigdim(d, m)))
        gl = rng.standard_normal((b, rp.logsigdim(d, m)))
        prep = iisignature.prepare(d, m)
        pysiglib.prepare_log_sig(d, m, method=2)
        rows = [("signature", lambda: rp.signature(x, m), lambda: iisignature.sig(x, m),
                 lambda: pysiglib.sig(x, m, n_jobs=1)),
                ("signature_vjp", lambda: rp.signature_vjp(x, m, g), lambda: iisignature.sigbackprop(g, x, m),
                 lambda: pysiglib.sig_backprop(x, pysiglib.sig(x, m, n_jobs=1), g, m, n_jobs=1)),
                ("logsignature", lambda: rp.logsignature(x, m), lambda: iisignature.logsig(x, prep),
                 lambda: pysiglib.log_sig(x, m, method=2, n_jobs=1)),
                ("logsignature_vjp", lambda: rp.logsignature_vjp(x, m, gl),
                 lambda: iisignature.logsigbackprop(gl, x, prep), None)]
        for kind, ours, iis, peer in rows:
            fns = [ours, iis] + ([peer] if peer is not None else [])
            t = [1e6 * v for v in paired(fns, reps, time.process_time)]
            tp = f"{t[2]:>10.1f}" if peer is not None else f"{'-':>10}"
            rp_ = f"{t[0] / t[2]:>10.2f}" if peer is not None else f"{'-':>10}"
            print(f"{f'{b} x {n}, d={d}, m={m}':<24}{kind:<18}{t[0]:>8.1f}{t[1]:>8.1f}{tp}{t[0] / t[1]:>8.2f}{rp_}",
                  flush=True)


def peer_table(cases: dict, args, rng) -> None:
    """Every cell, ours against pysiglib: one thread (CPU time) and all threads (wall time)."""
    import iisignature
    import numba
    import pysiglib

    from roughpaths import logsignature, logsignature_vjp, signature, signature_vjp

    threads = numba.get_num_threads()
    flops, bandwidth = machine_rates()
    print(f"machine: multiply-add sweep in L1 {flops / 1e9:.2f} GFLOP/s (one thread), one pass over memory "
          f"{bandwidth / 1e9:.1f} GB/s")
    print("floor = max(Horner FLOPs / that rate, bytes of the paths and the signatures / that bandwidth), one "
          "thread; 'vs floor' = our 1-thread time / floor\n")
    head = (f"{'case':<24}{'what':<9}{'lvl':>4}{'ours 1t':>10}{'peer 1t':>10}{'ratio 1t':>9}"
            f"{'ours ' + str(threads) + 't':>10}{'peer -1':>10}{'ratio':>7}{'floor':>9}{'vs floor':>9}{'err/iisig':>10}")
    print("time ratio = ours / pysiglib (below 1: ours faster); ms; 1t: numba.set_num_threads(1) against "
          f"n_jobs=1, CPU time; {threads}t: our default threads against n_jobs=-1, wall time")
    print(head)
    ratios = []
    for name, (x, depths, kinds) in cases.items():
        nb = int(np.prod(x.shape[:-2]))
        n, d = x.shape[-2:]
        for m in depths:
            sig_ii = iisignature.sig(x, m)
            g = rng.standard_normal(sig_ii.shape)
            g1 = np.concatenate([np.zeros(g.shape[:-1] + (1,)), g], axis=-1)
            gl = rng.standard_normal(x.shape[:-2] + (iisignature.logsiglength(d, m),))
            pysiglib.prepare_log_sig(d, m, method=2)
            prep = iisignature.prepare(d, m) if {"logsig", "log vjp"} & set(kinds) else None

            def peer_log_vjp(jobs):
                s = pysiglib.sig(x, m, scalar_term=True, n_jobs=jobs)
                gs = pysiglib.sig_to_log_sig_backprop(s, gl, d, m, method=2, n_jobs=jobs)
                return pysiglib.sig_backprop(x, s, gs, m, n_jobs=jobs)

            cells = {
                "sig": (lambda: signature(x, m), lambda j: pysiglib.sig(x, m, n_jobs=j),
                        lambda: sig_ii),
                "logsig": (lambda: logsignature(x, m), lambda j: pysiglib.log_sig(x, m, method=2, n_jobs=j),
                           lambda: iisignature.logsig(x, prep)),
                "sig vjp": (lambda: signature_vjp(x, m, g),
                            lambda j: pysiglib.sig_backprop(x, pysiglib.sig(x, m, scalar_term=True, n_jobs=j), g1,
                                                            m, n_jobs=j),
                            lambda: iisignature.sigbackprop(g, x, m)),
                "log vjp": (lambda: logsignature_vjp(x, m, gl), peer_log_vjp,
                            lambda: iisignature.logsigbackprop(gl, x, prep)),
            }
            for kind in kinds:
                ours, peer, ref = cells[kind]
                numba.set_num_threads(1)
                try:
                    t_o1, t_p1 = paired((ours, lambda: peer(1)), args.repeats, time.process_time)
                    got = ours()
                finally:
                    numba.set_num_threads(threads)
                t_on, t_pn = paired((ours, lambda: peer(-1)), args.repeats, time.perf_counter)
                want = ref()
                err = float(np.max(np.abs(got - want)) / max(1.0, float(np.max(np.abs(want)))))
                floor = ""
                if kind == "sig":
                    fl = max(nb * (n - 1) * horner_flops(d, m) / flops, 8 * (x.size + sig_ii.size) / bandwidth)
                    floor = f"{1e3 * fl:>9.3f}{t_o1 / fl:>9.1f}"
                else:
                    floor = f"{'':>9}{'':>9}"
                print(f"{name:<24}{kind:<9}{m:>4}{1e3 * t_o1:>10.3f}{1e3 * t_p1:>10.3f}{t_o1 / t_p1:>9.2f}"
                      f"{1e3 * t_on:>10.3f}{1e3 * t_pn:>10.3f}{t_on / t_pn:>7.2f}{floor}{err:>10.1e}", flush=True)
                ratios.append((f"{name} depth {m} {kind}", t_o1 / t_p1, t_on / t_pn))
    print()
    return ratios


def earlier_cases(cases: dict, args) -> list:
    """The cases (a)-(c) of the earlier runs, levels 2-5, signature and log-signature, all threads (wall time),
    against pysiglib and iisignature; returns ``(cell, ratio to pysiglib)``."""
    import iisignature
    import pysiglib

    from roughpaths import logsignature, signature

    ratios = []
    print("the cases of the earlier runs (all threads, wall time)")
    print("time ratio = ours / peer (below 1: ours faster)\n")
    head = (f"{'case':<22}{'lvl':>4}{'':>2}{'ours':>10}{'pysiglib':>10}{'iisig':>10}"
            f"{'ratio/pysiglib':>16}{'ratio/iisig':>13}{'max |ours-iisig|':>18}")
    for kind in ("signature", "log-signature"):
        print(kind)
        print(head)
        for name, x in cases.items():
            d = x.shape[-1]
            for m in (2, 3, 4, 5):
                if kind == "signature":
                    ours = lambda: signature(x, m)
                    peer = lambda: pysiglib.sig(x, m, n_jobs=-1)
                    ii = lambda: iisignature.sig(x, m)
                else:
                    pysiglib.prepare_log_sig(d, m, method=2)
                    prep = iisignature.prepare(d, m)
                    ours = lambda: logsignature(x, m)
                    peer = lambda: pysiglib.log_sig(x, m, method=2, n_jobs=-1)
                    ii = lambda: iisignature.logsig(x, prep)
                t_o, t_p, t_i = interleaved_medians((ours, peer, ii), args.repeats)
                ref = ii()
                err = float(np.max(np.abs(ours() - ref)) / max(1.0, float(np.max(np.abs(ref)))))
                ratios.append((f"{name} depth {m} {kind}", t_o / t_p))
                print(f"{name:<22}{m:>4}{'':>2}{1e3 * t_o:>10.2f}{1e3 * t_p:>10.2f}{1e3 * t_i:>10.2f}"
                      f"{t_o / t_p:>16.2f}{t_o / t_i:>13.2f}{err:>18.1e}", flush=True)
        print()
    return ratios


def bars(table: list, earlier: list, sweep: list) -> None:
    """Issue 41's done-when over one run's cells: every one-thread ratio <= 1.0 and every all-threads one <= 1.1
    (the cases (a)-(c) are timed with all threads only)."""
    one = [(r, c) for c, r, _ in table + sweep if r is not None]
    many = [(r, c) for c, _, r in table + sweep if r is not None] + [(r, c) for c, r in earlier]
    over1 = sorted(((r, c) for r, c in one if r > 1.0), reverse=True)
    over_n = sorted(((r, c) for r, c in many if r > 1.1), reverse=True)
    print(f"done-when bars, this run (load average at the end {os.getloadavg()[0]:.1f}): {len(one)} one-thread cells, "
          f"worst {max(one)[0]:.2f} ({max(one)[1]}); {len(many)} all-threads cells, worst {max(many)[0]:.2f} "
          f"({max(many)[1]})")
    print(f"  above 1.0 on one thread ({len(over1)}): {'; '.join(f'{c} {r:.2f}' for r, c in over1) or 'none'}")
    print(f"  above 1.1 with all threads ({len(over_n)}): {'; '.join(f'{c} {r:.2f}' for r, c in over_n) or 'none'}")


def _int_list(text: str) -> list:
    """``'2,5-7'`` -> ``[2, 5, 6, 7]``."""
    out = []
    for part in text.split(","):
        part = part.strip()
        if "-" in part:
            lo, hi = part.split("-")
            out.extend(range(int(lo), int(hi) + 1))
        elif part:
            out.append(int(part))
    return out


def width_sweep(args) -> None:
    """Issue 41: ours against pysiglib for every d = 2..20 at depths 2..6, one thread and all threads."""
    import numba
    import pysiglib

    from roughpaths import logsignature, signature, signature_vjp

    if args.sweep_general:            # before any call: the engine's plans are cached per shape
        from roughpaths.signatures import _blocked, _lanes

        _lanes.lane_key = lambda d, m: (0, 0)
        _blocked.block_key = _blocked.runtime_key
        print("kernels general in d only: the run-time variants of the lane and blocked kernels")
    threads = numba.get_num_threads()
    ds = _int_list(args.sweep_d)
    depths = _int_list(args.sweep_depths)
    batches = _int_list(args.sweep_batches)
    kinds = [k.strip() for k in args.sweep_kinds.split(",") if k.strip()]
    modes = {m.strip() for m in args.sweep_modes.split(",")}
    rng = np.random.default_rng(41)

    def looped(fns):
        """Each function called often enough that one timed sample takes about 2 ms (small cells are noisy)."""
        t0 = time.perf_counter()
        fns[0]()
        reps = max(1, min(50, int(2e-3 / max(time.perf_counter() - t0, 1e-6))))
        return [(lambda f=f: [f() for _ in range(reps)]) for f in fns], reps

    def timed(fns, clock):
        many, reps = looped(fns)        # samples of ~2 ms (reps > 1) get at least 11 pairs: the noisiest cells
        return [t / reps for t in paired(many, max(args.repeats, 11) if reps > 1 else args.repeats, clock)]

    print(f"width sweep: numba threads {threads}, load average {os.getloadavg()[0]:.1f}, median of "
          f"{args.repeats} interleaved pairs; ms; ratio = ours / pysiglib (1t: set_num_threads(1) against "
          f"n_jobs=1, CPU time; {threads}t: default threads against n_jobs=-1, wall time)")
    print(f"{'batch':>8}{'d':>4}{'lvl':>4}  {'what':<9}{'ours 1t':>10}{'peer 1t':>10}{'ratio 1t':>9}"
          f"{'ours ' + str(threads) + 't':>10}{'peer -1':>10}{'ratio':>7}")
    skipped, over1, over_n, worst, ratios = [], [], [], [], []
    for nb in batches:
        for d in ds:
            x = np.cumsum(rng.standard_normal((nb, 256, d)), axis=-2) / 16
            for m in depths:
                dim = sum(d ** k for k in range(1, m + 1))
                if dim > args.sweep_max_sigdim:
                    skipped.append(f"{nb}x256 d={d} depth {m} (sigdim {dim:.3g})")
                    continue
                g = rng.standard_normal((nb, dim))
                g1 = np.concatenate([np.zeros((nb, 1)), g], axis=-1)
                if "logsig" in kinds and m > 1:
                    pysiglib.prepare_log_sig(d, m, method=2)
                cells = {
                    "sig": (lambda: signature(x, m), lambda j: pysiglib.sig(x, m, n_jobs=j)),
                    "logsig": (lambda: logsignature(x, m), lambda j: pysiglib.log_sig(x, m, method=2, n_jobs=j)),
                    "sig vjp": (lambda: signature_vjp(x, m, g),
                                lambda j: pysiglib.sig_backprop(x, pysiglib.sig(x, m, scalar_term=True, n_jobs=j),
                                                                g1, m, n_jobs=j)),
                }
                for kind in kinds:
                    ours, peer = cells[kind]
                    row = f"{str(nb) + 'x256':>8}{d:>4}{m:>4}  {kind:<9}"
                    if "1" in modes:
                        numba.set_num_threads(1)
                        try:
                            t_o1, t_p1 = timed((ours, lambda: peer(1)), time.process_time)
                        finally:
                            numba.set_num_threads(threads)
                        r1 = t_o1 / t_p1
                        ratios.append((f"sweep {nb}x256 d={d} depth {m} {kind}", r1, None))
                        row += f"{1e3 * t_o1:>10.3f}{1e3 * t_p1:>10.3f}{r1:>9.2f}"
                        worst.append((r1, f"{nb}x256 d={d} depth {m}", kind))
                        if r1 > 1.0:
                            over1.append(f"{nb}x256 d={d} depth {m} {kind}: {r1:.2f}")
                    else:
                        row += f"{'':>28}"
                    if "n" in modes:
                        t_on, t_pn = timed((ours, lambda: peer(-1)), time.perf_counter)
                        rn = t_on / t_pn
                        ratios.append((f"sweep {nb}x256 d={d} depth {m} {kind}", None, rn))
                        row += f"{1e3 * t_on:>10.3f}{1e3 * t_pn:>10.3f}{rn:>7.2f}"
                        if rn > 1.1:
                            over_n.append(f"{nb}x256 d={d} depth {m} {kind}: {rn:.2f}")
                    print(row, flush=True)
    print(f"\nload average at the end: {' '.join(f'{v:.1f}' for v in os.getloadavg())} (1, 5, 15 min)")
    if skipped:
        print(f"skipped (sigdim > {args.sweep_max_sigdim:.3g} floats per path): {'; '.join(skipped)}")
    print(f"cells above 1.0 on one thread ({len(over1)}): {'; '.join(over1) if over1 else 'none'}")
    print(f"cells above 1.1 in parallel mode ({len(over_n)}): {'; '.join(over_n) if over_n else 'none'}")
    if worst:
        r, where, kind = max(worst)
        print(f"worst one-thread ratio: {r:.2f} ({where} {kind})")
    print()
    return ratios


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="smaller sizes (smoke test)")
    parser.add_argument("--only-peer-table", action="store_true", help="print the pysiglib table only")
    parser.add_argument("--cells", default="", help="peer-table cases to run, by letter (e.g. 'd,e,h'); "
                        "implies --only-peer-table")
    parser.add_argument("--kinds", default="", help="peer-table kinds to run (e.g. 'sig,log vjp')")
    parser.add_argument("--depths", default="", help="peer-table depths to run (e.g. '3,4')")
    parser.add_argument("--only-streams", action="store_true", help="print the streams-and-words section only")
    parser.add_argument("--sweep", action="store_true", help="run the width sweep only (d = 2..20, depths 2..6)")
    parser.add_argument("--sweep-d", default="2-20", help="sweep alphabet sizes (e.g. '2,6-9')")
    parser.add_argument("--sweep-depths", default="2-6", help="sweep depths (e.g. '3,4')")
    parser.add_argument("--sweep-batches", default="16,64", help="sweep batch sizes of 256-point paths")
    parser.add_argument("--sweep-kinds", default="sig,logsig", help="sweep kinds: sig, logsig, sig vjp")
    parser.add_argument("--sweep-modes", default="1,n", help="sweep modes: 1 (one thread), n (all threads)")
    parser.add_argument("--sweep-general", action="store_true",
                        help="sweep with the run-time (general in d) kernel variants only")
    parser.add_argument("--sweep-max-sigdim", type=float, default=2e6,
                        help="skip sweep cells with more signature floats per path")
    parser.add_argument("--bars", action="store_true",
                        help="issue 41's done-when in one run: the peer table, the cases (a)-(c) and the width sweep, "
                             "then every cell against its bar")
    parser.add_argument("--fixed-cost", action="store_true",
                        help="print the per-call cost on small inputs only (against iisignature and pysiglib)")
    args = parser.parse_args()
    if args.fixed_cost:
        fixed_cost_section(args)
        return
    if args.sweep:
        width_sweep(args)
        return
    if args.only_streams:
        streams_section(args)
        return

    import iisignature
    import numba
    import pysiglib

    from roughpaths import logsignature, logsignature_vjp, signature, signature_vjp

    rng = np.random.default_rng(12345)
    s = 10 if args.quick else 1
    cases = {
        "(a) 1 x 100000, d=3": np.cumsum(rng.standard_normal((100_000 // s, 3)), axis=0) / 300,
        "(b) 1000 x 1000, d=3": np.cumsum(rng.standard_normal((1_000 // s, 1_000, 3)), axis=-2) / 30,
        "(c) 32 x 1000, d=5": np.cumsum(rng.standard_normal((32, 1_000 // s, 5)), axis=-2) / 30,
    }
    wide = {
        "(d) 64 x 256, d=8": (np.cumsum(rng.standard_normal((64, 256, 8)), axis=-2) / 16, (2, 3, 4),
                              ("sig", "logsig", "sig vjp", "log vjp")),
        "(e) 4 x 64, d=20": (np.cumsum(rng.standard_normal((4, 64, 20)), axis=-2) / 8, (2, 3),
                             ("sig", "logsig", "sig vjp", "log vjp")),
        "(f) 1 x 1000, d=3": (np.cumsum(rng.standard_normal((1, 1000, 3)), axis=-2) / 30, (4,),
                              ("sig", "logsig", "sig vjp", "log vjp")),
        "(f') 4 x 1000, d=3": (np.cumsum(rng.standard_normal((4, 1000, 3)), axis=-2) / 30, (4,),
                               ("sig", "logsig")),
        "(g) 1 x 10, d=4": (np.cumsum(rng.standard_normal((1, 10, 4)), axis=-2) / 3, (8,),
                            ("sig", "logsig", "log vjp")),
        "(h) 16 x 256, d=6": (np.cumsum(rng.standard_normal((16, 256, 6)), axis=-2) / 16, (4,),
                              ("sig", "logsig", "sig vjp")),
    }
    if args.cells:
        keep = {c.strip() for c in args.cells.split(",")}
        wide = {k: v for k, v in wide.items() if k[1:k.index(")")] in keep}
        args.only_peer_table = True
    if args.kinds or args.depths:
        kinds = {k.strip() for k in args.kinds.split(",")} if args.kinds else None
        depths = {int(m) for m in args.depths.split(",")} if args.depths else None
        wide = {k: (x, tuple(m for m in ms if depths is None or m in depths),
                    tuple(c for c in cs if kinds is None or c in kinds)) for k, (x, ms, cs) in wide.items()}
    threads = numba.get_num_threads()
    print(f"numba threads {threads}, cpu count {os.cpu_count()}, load average {os.getloadavg()[0]:.1f}, "
          f"median of {args.repeats} interleaved pairs; times in ms\n")
    table = peer_table(wide, args, rng)
    if args.only_peer_table and not args.bars:
        return
    earlier = earlier_cases(cases, args)
    if args.bars:
        bars(table, earlier, width_sweep(args))
        return

    # gradients, depth 4 on (b)
    x = cases["(b) 1000 x 1000, d=3"]
    g = rng.standard_normal(x.shape[:-2] + (iisignature.siglength(3, 4),))
    gl = rng.standard_normal(x.shape[:-2] + (iisignature.logsiglength(3, 4),))
    prep = iisignature.prepare(3, 4)
    t_o = median_time(lambda: signature_vjp(x, 4, g), args.repeats)
    t_i = median_time(lambda: iisignature.sigbackprop(g, x, 4), args.repeats)
    g1 = np.concatenate([np.zeros(g.shape[:-1] + (1,)), g], axis=-1)
    t_p = median_time(lambda: pysiglib.sig_backprop(x, pysiglib.sig(x, 4, scalar_term=True, n_jobs=-1), g1, 4,
                                                    n_jobs=-1), args.repeats)
    t_ol = median_time(lambda: logsignature_vjp(x, 4, gl), args.repeats)
    t_il = median_time(lambda: iisignature.logsigbackprop(gl, x, prep), args.repeats)
    print("gradient (vector-Jacobian product w.r.t. the points), depth 4, case (b)")
    print(f"  signature: ours {1e3 * t_o:.1f} ms, pysiglib sig+sig_backprop {1e3 * t_p:.1f} ms, "
          f"iisignature sigbackprop {1e3 * t_i:.1f} ms; time ratio ours/pysiglib {t_o / t_p:.2f}, "
          f"ours/iisignature {t_o / t_i:.2f}")
    print(f"  log-signature: ours {1e3 * t_ol:.1f} ms, iisignature logsigbackprop {1e3 * t_il:.1f} ms; "
          f"time ratio ours/iisignature {t_ol / t_il:.2f}\n")

    # depth-10 log-signature, fresh processes
    first, again, peak, rss, t_witt, t_load = _run(DEPTH10)
    t_ii, rss_ii = _run(IISIG10)
    print("logsignature of a 10 x 3 path at depth 10 (fresh process)")
    print(f"  ours: first call {first:.3f} s (builds the sparse Lyndon map), repeat call {1e3 * again:.1f} ms, "
          f"peak traced memory {peak / 2**20:.0f} MiB, process peak RSS {rss / 2**20:.0f} MiB "
          f"(includes numba/LLVM); loading the compiled kernels before it took {t_load:.2f} s")
    print(f"  iisignature prepare + logsig: {t_ii:.3f} s, process peak RSS {rss_ii / 2**20:.0f} MiB")
    print(f"  logsigdim(2, 60) (Witt's formula): {1e6 * t_witt:.0f} us\n")

    # busy machine: level 2 on (a) with a CPU-bound process beside it
    xa = cases["(a) 1 x 100000, d=3"]
    burner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.2)
        t_par = median_time(lambda: signature(xa, 2), max(args.repeats, 9))
        numba.set_num_threads(1)
        t_one = median_time(lambda: signature(xa, 2), max(args.repeats, 9))
    finally:
        numba.set_num_threads(threads)
        burner.kill()
        burner.wait()
    t_ii2 = median_time(lambda: iisignature.sig(xa, 2), args.repeats)
    print("level 2 on (a) with one CPU-bound process running beside it")
    print(f"  ours, {threads} threads: {1e3 * t_par:.3f} ms; ours, 1 thread: {1e3 * t_one:.3f} ms "
          f"(time ratio {t_par / t_one:.2f}); iisignature once the extra process stopped: {1e3 * t_ii2:.2f} ms\n")

    # thread-count independence
    same = []
    for name, x in cases.items():
        for m in (2, 3):
            numba.set_num_threads(1)
            one = signature(x, m), logsignature(x, m)
            numba.set_num_threads(threads)
            many = signature(x, m), logsignature(x, m)
            same.append(one[0].tobytes() == many[0].tobytes() and one[1].tobytes() == many[1].tobytes())
    print(f"results with 1 thread and with {threads} threads bitwise identical (cases a-c, levels 2-3, "
          f"sig and logsig): {all(same)}")
    print(f"load average at the end: {' '.join(f'{v:.1f}' for v in os.getloadavg())} (1, 5, 15 min)\n")
    streams_section(args)


def streams_section(args) -> None:
    """Issue 41: the rounding of sub-interval signatures (prefixes and inverse against the stream's tree),
    the stream's costs, windowed signatures and chosen words."""
    import math

    import iisignature

    import roughpaths as rp

    rng = np.random.default_rng(41)
    n, d, m = (10 ** 5 if args.quick else 10 ** 6), 2, 4
    x = np.concatenate([np.zeros((1, d)), rng.normal(scale=1e-3, size=(n - 1, d)).cumsum(axis=0)])
    off = np.cumsum([0] + [d ** k for k in range(1, m + 1)])
    print(f"streams: Brownian path of {n} points, d = {d}, step 1e-3, depth {m}")
    print("  error of S(s, t) against signature(x[s:t+1]), per level, relative to the level's largest entry "
          "(max over 20 windows in the second half)")
    print(f"  {'window':>8}{'level':>7}{'|S_k| (max)':>14}{'prefixes+inverse':>19}{'stream (tree)':>16}")
    stream = rp.SignatureStream(x, m)
    for w in (10, 1000, 10 ** 5 // (10 if args.quick else 1)):
        s = rng.integers(n // 2, n - 1 - w, size=20)
        t = s + w
        direct = np.stack([rp.signature(x[a:b + 1], m) for a, b in zip(s, t)])
        inverse = rp.tensor_product(rp.tensor_inverse(np.stack([rp.signature(x[:a + 1], m) for a in s]), d),
                                    np.stack([rp.signature(x[:b + 1], m) for b in t]), d)
        tree = stream.signature(s, t)
        for k in range(m):
            lv = slice(off[k], off[k + 1])
            scale = np.max(np.abs(direct[:, lv]), axis=1)
            e_inv = np.max(np.max(np.abs(inverse[:, lv] - direct[:, lv]), axis=1) / scale)
            e_tree = np.max(np.max(np.abs(tree[:, lv] - direct[:, lv]), axis=1) / scale)
            print(f"  {w:>8}{k + 1:>7}{float(np.max(scale)):>14.2e}{e_inv:>19.1e}{e_tree:>16.1e}")
    print(f"  (the inverse loses about (|X_0s| / |X_st|)^k eps: here |X_0s| ~ {np.abs(x[n // 2:]).max():.1f})")

    print("\n  SignatureStream costs (10^4 random queries [s, t], one call)")
    s = rng.integers(0, n // 2, size=10_000)
    t = s + rng.integers(0, n // 2, size=10_000)
    for block in (8, 32, 128):
        t0 = time.perf_counter()
        st = rp.SignatureStream(x, m, block=block)
        t_build = time.perf_counter() - t0
        t0 = time.perf_counter()
        st.signature(s, t)
        t_query = time.perf_counter() - t0
        nodes, count = 0, -(-(n - 1) // block)          # the tree's nodes: ceil(n_blocks / 2**j) at level j
        while True:
            nodes += count
            if count == 1:
                break
            count = -(-count // 2)
        stored = nodes * rp.sigdim(d, m) * 8
        print(f"  block {block:>4}: build {t_build:.2f} s, stored {stored / 2**20:.1f} MiB, "
              f"{1e6 * t_query / s.size:.0f} us per query")
    t0 = time.perf_counter()
    for a, b in zip(s[:20], t[:20]):
        rp.signature(x[a:b + 1], m)
    print(f"  direct signature of the sub-path: {1e6 * (time.perf_counter() - t0) / 20:.0f} us per query "
          f"(mean length {np.mean(t[:20] - s[:20]):.0f} steps)")

    xs = rng.normal(size=(10 ** 5 // (10 if args.quick else 1), 3)).cumsum(axis=0) * 0.01
    for length in (16, 256):
        t0 = time.perf_counter()
        got = rp.windowed_signature(xs, 3, length)
        t_ours = time.perf_counter() - t0
        idx = np.arange(got.shape[0])[:, None] + np.arange(length + 1)
        t0 = time.perf_counter()
        want = rp.signature(xs[idx], 3)
        t_direct = time.perf_counter() - t0
        err = float(np.max(np.abs(got - want)) / np.max(np.abs(want)))
        print(f"\n  windowed_signature, sliding windows of {length} steps over {xs.shape[0]} points, d = 3, "
              f"depth 3: {t_ours:.2f} s; gathered windows through signature: {t_direct:.2f} s; "
              f"largest difference {err:.1e} of the largest entry")

    xw = rng.normal(size=(n, 3)).cumsum(axis=0) * 1e-3
    words = [tuple(rng.integers(0, 3, size=4)) for _ in range(10)]
    rp.signature_coefficients(xw[:10], words)
    t0 = time.perf_counter()
    coef = rp.signature_coefficients(xw, words)
    t_w = time.perf_counter() - t0
    t0 = time.perf_counter()
    full = rp.signature(xw, 4)
    t_full = time.perf_counter() - t0
    t0 = time.perf_counter()
    iisignature.sig(xw, 4)
    t_ii = time.perf_counter() - t0
    pos = [sum(d3 for d3 in (3, 9, 27)) + sum(c * 3 ** (3 - j) for j, c in enumerate(w)) for w in words]
    err = float(np.max(np.abs(coef - full[pos])) / np.max(np.abs(full[39:])))
    print(f"\n  signature_coefficients: 10 words of length 4 along {n} points, d = 3: {1e3 * t_w:.0f} ms; "
          f"full depth-4 signature {1e3 * t_full:.0f} ms (iisignature {1e3 * t_ii:.0f} ms); "
          f"largest difference {err:.1e} of level 4's largest entry")
    tr = rng.normal(size=(1000, 1000, 3))
    t0 = time.perf_counter()
    for f in (rp.lead_lag, rp.time_augment, rp.basepoint, rp.invisibility_reset):
        f(tr)
    print(f"\n  the four transforms on 1000 x 1000 x 3: {1e3 * (time.perf_counter() - t0):.0f} ms in all")


if __name__ == "__main__":
    main()
