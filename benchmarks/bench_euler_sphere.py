"""Benchmark: Zeitlin's model of Euler on the sphere, time per step across N (issue 38, item 5).

Rows, for N = 32, 64, 128, 256 (one path, complex128):

* ``inverse_laplacian``: the stream matrix P = Delta_N^{-1} W (one block-tridiagonal LAPACK solve, O(N^2));
* ``laplacian``: Delta_N P, elementwise, O(N^2);
* ``midpoint step``: a plain-numpy isospectral midpoint step for dW/dt = [B(W), W], B = P / hbar (physical
  time): fixed-point iterations W~ = W + h/2 [B, W~] + h^2/4 B W~ B (each one Laplacian solve and three
  N x N products, BLAS), stopped at a relative change <= 1e-12, then W' = (I + hB/2) W~ (I - hB/2). The step
  h is chosen so that h |B|_2 = 0.25 at every N (the iteration count is then about the same); the table
  gives the iterations per step and the time per iteration too.

Anchor (deterministic, published): Cifani, Viviani and Modin (J. Comput. Phys. 2023, arXiv 2206.05466) ran
N = 4096 at about 0.55 s per step on about 2500 cores, i.e. 1375 core-s per step; scaled by N^3 that is
about 42 core-ms per step at N = 128 (0.66 ms at 32, 5.2 ms at 64, 336 ms at 256). Our column is CPU time
(time.process_time: all threads of this process), so per core; medians of interleaved repeats. The machine
is shared: the load average is printed with the table.

* ``LieHeun (solve)``: the library's strong-order-1 scheme with the Lévy area, one step of
  ``roughpaths.solve(zeitlin_system(N, s=...), X, W0, mechanics.LieHeun())`` on one Brownian rough path with its
  areas (three non-commuting SALT modes, ``s^{12} = 1``): two drift evaluations (two Laplacian solves, four
  products), the noise and area matrices, one exponential of an N x N skew-Hermitian matrix and the conjugation
  (O(N^3), BLAS), through the public entry point (validation and coordinate maps included, the driver's
  sampling excluded). Target (issue 38): N = 128 <= 20 ms per step. The last column is the peak resident
  memory of the process after the largest N (bounded: the solver holds a few N x N matrices per path,
  never anything of size dim(su(N))^2).

Beyond the paper: the paper has no fluid model; this is the library's extension to Zeitlin's Euler on the sphere.

Usage: ``python benchmarks/bench_euler_sphere.py [--sizes 32,64,128,256] [--repeats R] [--threads=K]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

# Per-core figures: BLAS on one thread unless --threads=K is given (set before numpy loads OpenBLAS; an
# OpenBLAS thread spinning on a loaded machine would count as CPU time).
_THREADS = next((a.split("=", 1)[1] for a in sys.argv[1:] if a.startswith("--threads=")), "1")
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, _THREADS)

import numpy as np  # noqa: E402

import resource  # noqa: E402

import mechanics  # noqa: E402
import roughpaths  # noqa: E402
from mechanics.sphere import coefficients_to_matrix, hbar, inverse_laplacian, laplacian, zeitlin_system  # noqa: E402

ANCHOR_CORE_SECONDS_4096 = 0.55 * 2500  # core-seconds per step at N = 4096 (published figures)


def initial_vorticity(N: int, rng: np.random.Generator, lmax: int = 24) -> np.ndarray:
    """A smooth random real field (degrees 1..min(lmax, N-1), amplitude ~ 1/l), as an su(N) element."""
    L = min(lmax, N - 1) + 1
    omega = np.zeros(L * L, dtype=np.complex128)
    for l in range(1, L):
        omega[l * (l + 1)] = rng.standard_normal() / l
        for m in range(1, l + 1):
            c = (rng.standard_normal() + 1j * rng.standard_normal()) / (l * np.sqrt(2.0))
            omega[l * (l + 1) + m] = c
            omega[l * (l + 1) - m] = (-1) ** m * np.conj(c)
    return coefficients_to_matrix(omega, N)


def midpoint_step(W: np.ndarray, h: float, kappa: float, tol: float = 1e-12, max_iter: int = 100):
    """One isospectral midpoint step (plain numpy); returns (W', iterations)."""
    scale = np.abs(W).max()
    Wt = W
    for it in range(1, max_iter + 1):
        B = kappa * inverse_laplacian(Wt)
        BW = B @ Wt
        new = W + 0.5 * h * (BW - Wt @ B) + 0.25 * h * h * (BW @ B)
        done = np.abs(new - Wt).max() <= tol * scale
        Wt = new
        if done:
            break
    B = kappa * inverse_laplacian(Wt)
    BW = B @ Wt
    return Wt + 0.5 * h * (BW - Wt @ B) - 0.25 * h * h * (BW @ B), it


def heun_setup(N: int, W: np.ndarray, steps: int, h: float, seed: int = 38):
    """The system with the Lévy-area correction, the state as coordinates and one Brownian rough path."""
    system = zeitlin_system(N, amplitudes=0.1, s=np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    y0 = system.algebra.matrix_to_dual(W)
    X = roughpaths.brownian_rough_path(np.linspace(0.0, steps * h, steps + 1), 3, np.random.default_rng(seed))
    return system, y0, X


def cpu_median(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return float(statistics.median(times))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="32,64,128,256")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=3, help="midpoint steps per timed run")
    parser.add_argument("--threads", default="1", help="BLAS threads (read before numpy is imported)")
    args = parser.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    rng = np.random.default_rng(38)
    states = {}
    for N in sizes:
        W = initial_vorticity(N, rng)
        kappa = 1.0 / hbar(N)
        norm_b = np.linalg.norm(kappa * inverse_laplacian(W), 2)
        h = 0.25 / norm_b
        states[N] = (W, kappa, h)
        inverse_laplacian(W), laplacian(W), midpoint_step(W, h, kappa)  # warm caches (factors, BLAS)
    heun = {N: heun_setup(N, states[N][0], args.steps, states[N][2]) for N in sizes}
    for N in sizes:
        system, y0, X = heun[N]
        roughpaths.solve(system, X, y0, mechanics.LieHeun(), save_at="end")     # warm (first-call costs)
    rows = {N: {"solve": [], "lap": [], "step": [], "iters": [], "heun": []} for N in sizes}
    for _ in range(args.repeats):  # interleaved: one round over every size per repeat
        for N in sizes:
            W, kappa, h = states[N]
            rows[N]["solve"].append(cpu_median(lambda: inverse_laplacian(W), 5))
            rows[N]["lap"].append(cpu_median(lambda: laplacian(W), 5))
            iters = []

            def run():
                state = W
                for _ in range(args.steps):
                    state, k = midpoint_step(state, h, kappa)
                    iters.append(k)

            rows[N]["step"].append(cpu_median(run, 1) / args.steps)
            rows[N]["iters"].append(float(np.mean(iters)))
            system, y0, X = heun[N]
            rows[N]["heun"].append(cpu_median(lambda: roughpaths.solve(system, X, y0, mechanics.LieHeun(),
                                                                         save_at="end"), 1) / args.steps)
    load = os.getloadavg()
    print(f"# Zeitlin's Euler on the sphere, one path, CPU time per call (median of {args.repeats} interleaved "
          f"repeats); load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; BLAS threads "
          f"{os.environ.get('OPENBLAS_NUM_THREADS')}")
    print("| N | inverse_laplacian | laplacian | midpoint step (plain numpy) | iterations/step | per iteration | "
          "LieHeun with area (solve) | anchor (core-ms/step, N^3-scaled) | midpoint / anchor | LieHeun / anchor |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for N in sizes:
        r = rows[N]
        solve, lap, step = (statistics.median(r[k]) for k in ("solve", "lap", "step"))
        iters = statistics.median(r["iters"])
        heun_step = statistics.median(r["heun"])
        anchor = ANCHOR_CORE_SECONDS_4096 * (N / 4096.0) ** 3
        print(f"| {N} | {solve * 1e3:.3f} ms | {lap * 1e3:.3f} ms | {step * 1e3:.2f} ms | {iters:.1f} | "
              f"{step / (iters + 1) * 1e3:.2f} ms | {heun_step * 1e3:.2f} ms | {anchor * 1e3:.2f} | "
              f"{step / anchor:.2f} | {heun_step / anchor:.2f} |")
    print(f"# peak resident memory of the process: {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")


if __name__ == "__main__":
    main()
