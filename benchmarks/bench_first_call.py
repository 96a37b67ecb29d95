"""Benchmark: the first call of each public signature function in a fresh process (target <= 2 s).

Run after the install-time warm-up (``python tools/warm_kernels.py``, which ``tools/setup_env.sh``
runs), so that numba's on-disk cache holds the compiled kernels: the first call then only loads them.
Each cell is a new Python process that imports ``roughpaths`` (timed apart) and times one call, at the
shapes and depths of a user's first try (wall time, the user's wait). Pass ``--warm`` to run the
warm-up first.

Usage: ``python benchmarks/bench_first_call.py [--warm]``
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

CALLS = {
    "signature(x, 4)": "rp.signature(x, 4)",
    "signature(x, 2)": "rp.signature(x, 2)",
    "signature(x6, 3), d = 6": "rp.signature(x6, 3)",
    "logsignature(x, 4)": "rp.logsignature(x, 4)",
    "signature_vjp(x, 4, g)": "rp.signature_vjp(x, 4, np.ones((16, rp.sigdim(3, 4))))",
    "logsignature_vjp(x, 4, g)": "rp.logsignature_vjp(x, 4, np.ones((16, rp.logsigdim(3, 4))))",
    "rough_path_signature(X, 3)": "rp.rough_path_signature(rp.RoughPath.from_path(x), 3)",
    "rough_path_signature_vjp(X, 3, g)": ("rp.rough_path_signature_vjp(rp.RoughPath.from_path(x), 3, "
                                          "np.ones((16, rp.sigdim(3, 3))))"),
}

CODE = r"""
import time
t0 = time.perf_counter()
import numpy as np
import roughpaths as rp
t1 = time.perf_counter()
rng = np.random.default_rng(0)
x = np.cumsum(rng.standard_normal((16, 100, 3)), axis=1) * 0.1
x6 = np.cumsum(rng.standard_normal((4, 50, 6)), axis=1) * 0.1
t2 = time.perf_counter()
CALL
t3 = time.perf_counter()
CALL
t4 = time.perf_counter()
print(t1 - t0, t3 - t2, t4 - t3)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--warm", action="store_true", help="run tools/warm_kernels.py first")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if args.warm:
        subprocess.run([sys.executable, os.path.join(root, "tools", "warm_kernels.py")], check=True)
    print("first call of each public function in a fresh process (after the warm-up); wall time, s")
    print(f"{'call':<36}{'import':>9}{'first call':>12}{'second call':>13}  target <= 2 s")
    worst = 0.0
    for name, call in CALLS.items():
        out = subprocess.run([sys.executable, "-c", CODE.replace("CALL", call)], capture_output=True, text=True,
                             check=True, env=dict(os.environ))
        t_imp, t_first, t_second = (float(v) for v in out.stdout.split())
        worst = max(worst, t_first)
        print(f"{name:<36}{t_imp:>9.2f}{t_first:>12.2f}{t_second:>13.4f}  {'met' if t_first <= 2 else 'NOT met'}",
              flush=True)
    print(f"slowest first call: {worst:.2f} s")


if __name__ == "__main__":
    main()
