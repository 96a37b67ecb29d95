"""The cost of the default Lévy areas (``levy_area="auto"``) against Davie's, and against the code before.

1. **Sampling.** Million path-steps per CPU second of ``BrownianDriver(d, ..., levy_area=M).blocks()``
   (increments and areas; 1000 paths x 1000 steps, ``h = 1e-3``) for ``d = 2, 3, 5`` and every method:
   ``auto`` (the default: exact for ``d = 2``, Mrongowius–Rößler at per-step L² error ``h^1.5`` for
   ``d >= 3``), ``davie``, ``exact``, ``mrongowius-rossler``, ``wiktorsson``; and the ratio
   default / Davie. Issue target: at most 3x Davie's cost at ``d = 3``.
2. **Rigid body.** ns of CPU time per path-step of ``solve(rigid_body, BrownianDriver(3, ...), mu0,
   LieHeun())`` (1000 paths x 2000 steps, ``dt = 1e-3``, the problem of ``bench_rigid_body.py``) with
   the default areas and with Davie's, and the ratio. Issue target: at most 2.5x.

Each number is the median of ``--repeats`` runs, the methods interleaved (after one warm-up run that
compiles), CPU time (``time.process_time``): the machine is shared. With ``--against DIR`` (a checkout
of an earlier commit, e.g. ``git worktree add /tmp/old <commit>``), every measurement runs in a fresh
subprocess for both trees in turn, and both columns are printed (the before/after table of a change,
from one run); a method the earlier tree does not know prints ``-``.

The normals bound the samplers: drawing one costs ~7.6 ns here, and per path-step the methods draw
``d`` (increment) plus: ``davie`` ``d + d(d-1)/2``; ``exact`` (``d = 2``) 1; Mrongowius–Rößler
``2dn + d + d(d-1)/2`` with ``n = ceil(√d h^{-1/2} / (√12 π))`` terms for the error ``h^{1.5}``
(``n = 6`` at ``d = 3``, ``h = 1e-3``: 45 normals against Davie's 9).

Usage: ``python benchmarks/bench_default_areas.py [--quick] [--repeats R] [--against DIR]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

METHODS = ("auto", "davie", "exact", "mrongowius-rossler", "wiktorsson")
INERTIA = (1.0, 2.0, 3.0)
THETA, SIGMA, DT = 1.0, 0.05, 1e-3


def _sample(d, method, paths, steps):
    from roughpaths import BrownianDriver

    t0 = time.process_time()
    for _ in BrownianDriver(d, seed=1, dt=1e-3, n_steps=steps, batch_shape=(paths,), levy_area=method).blocks():
        pass
    return time.process_time() - t0


def _rigid(method, paths, steps):
    import numpy as np

    from mechanics import LieHeun, rigid_body
    from roughpaths import BrownianDriver, solve

    rb = rigid_body(np.array(INERTIA), sigma=SIGMA, theta=THETA)
    t0 = time.process_time()
    drv = BrownianDriver(3, seed=2, dt=DT, n_steps=steps, batch_shape=(paths,), levy_area=method)
    solve(rb, drv, np.array([0.0, 0.0, 1.0]), LieHeun(), save_at="end")
    return time.process_time() - t0


def _one(job):
    """Run one measurement ``job = (kind, d, method, paths, steps)`` in this process: seconds or None."""
    kind, d, method, paths, steps = job
    try:
        return _sample(d, method, paths, steps) if kind == "sample" else _rigid(method, paths, steps)
    except (ValueError, TypeError):
        return None                              # a method this tree does not know (or refuses for d)


def _in_tree(tree, job):
    """``_one(job)`` in a fresh interpreter importing the library from ``tree`` (warm-up included)."""
    code = (f"import sys, json; sys.path.insert(0, {tree!r}); sys.path.insert(0, {os.path.dirname(__file__)!r}); "
            f"import bench_default_areas as b; job = {job!r}; b._one(job); print(json.dumps(b._one(job)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ,
                         "PYTHONPATH": tree}, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="small sizes (smoke run, numbers not meaningful)")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--against", metavar="DIR", help="a checkout of an earlier commit, timed in the same run")
    args = p.parse_args(argv)
    paths, steps, rb_steps = (100, 100, 200) if args.quick else (1000, 1000, 2000)
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = {"now": here} if not args.against else {"before": os.path.abspath(args.against), "now": here}
    jobs = [("sample", d, m, paths, steps) for d in (2, 3, 5) for m in METHODS if not (m == "exact" and d > 2)]
    jobs += [("rigid", 3, m, paths, rb_steps) for m in ("auto", "davie")]
    times = {(t, j): [] for t in trees for j in jobs}
    if not args.against:
        for j in jobs:
            _one(j)                                   # warm-up: compile
    t_start = time.perf_counter()
    for _ in range(max(1, args.repeats)):
        for j in jobs:
            for t, tree in trees.items():
                times[(t, j)].append(_in_tree(tree, j) if args.against else _one(j))
    med = {k: _median(v) for k, v in times.items()}
    cols = list(trees)
    print(f"1. sampling, million path-steps per CPU second ({paths} paths x {steps} steps, h = 1e-3; median of "
          f"{args.repeats}, interleaved)")
    print("| d | levy_area | " + " | ".join(cols) + (" | now / before |" if args.against else " | cost / davie |"))
    print("|---|---|" + "---|" * (len(cols) + 1))
    for j in [j for j in jobs if j[0] == "sample"]:
        rate = {t: (None if med[(t, j)] is None else paths * steps / med[(t, j)] / 1e6) for t in cols}
        cells = [("-" if rate[t] is None else f"{rate[t]:.2f}") for t in cols]
        if args.against:
            extra = "-" if None in rate.values() else f"{rate['now'] / rate['before']:.1f}x"
        else:
            dav = med[("now", ("sample", j[1], "davie", paths, steps))]
            extra = f"{med[('now', j)] / dav:.2f}x" if med[("now", j)] else "-"
        print(f"| {j[1]} | {j[2]} | " + " | ".join(cells) + f" | {extra} |")
    print(f"\n2. rigid body, LieHeun, ns of CPU time per path-step ({paths} paths x {rb_steps} steps, dt = {DT:g})")
    print("| levy_area | " + " | ".join(cols) + " |")
    print("|---|" + "---|" * len(cols))
    for j in [j for j in jobs if j[0] == "rigid"]:
        print(f"| {j[2]} | " + " | ".join("-" if med[(t, j)] is None else f"{med[(t, j)] / (paths * rb_steps) * 1e9:.0f}"
                                          for t in cols) + " |")
    for t in cols:
        a, d_ = med[(t, ("rigid", 3, "auto", paths, rb_steps))], med[(t, ("rigid", 3, "davie", paths, rb_steps))]
        if a and d_:
            print(f"{t}: rigid body with the default areas / with Davie's = {a / d_:.2f}x (target <= 2.5x)")
        s3 = med[(t, ("sample", 3, "auto", paths, steps))]
        s3d = med[(t, ("sample", 3, "davie", paths, steps))]
        if s3 and s3d:
            print(f"{t}: default-area sampling at d = 3 / Davie's = {s3 / s3d:.2f}x (target <= 3x)")
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
