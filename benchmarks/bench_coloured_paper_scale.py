"""Cost of a paper-scale coloured-noise rigid body run (Section 4.2, Figures 4–5: ε = 0.005).

The paper integrates (srbcoloured) with steps far below ε² = 2.5e-5. Here the OU part is sampled
exactly and each grid step carries the Chen-summed level-2 data of B^ε, so grid steps of order ε²
suffice. This script reports

* seconds per path per unit time for the coloured system at ε = 0.005 (paper's A = 0.05 I + Λ,
  σ = 0.05, θ = 1, I = diag(1, 2, 3)), for 1 path and for a batch, with the default grid
  h = ε²/(2‖A‖);
* the accuracy of that step: the same sampled noise integrated on h and on h/8 (Chen restriction
  of a fine lift), pathwise max |ΔΠ| at T;
* the same-run ratio against a step of ε²/100 (the "steps far below ε²" route).

Run: python benchmarks/bench_coloured_paper_scale.py [--T 0.2] [--paths 64]
"""

import argparse

import numpy as np

from _timing import median_time
from roughpaths import paper_coloured_noise_matrices, sample_coloured_noise
from mechanics import LieHeun, rigid_body
from mechanics.limits.wong_zakai import simulate_wong_zakai_rigid_body
from roughpaths import solve


def timed(fn, repeat=3):
    return median_time(fn, repeat)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--T", type=float, default=0.2)
    ap.add_argument("--paths", type=int, default=64)
    ap.add_argument("--eps", type=float, default=0.005)
    a = ap.parse_args()
    A, D = paper_coloured_noise_matrices(0.05)
    eps, sigma = a.eps, 0.05
    h = eps ** 2 / (2 * np.linalg.norm(A, 2))
    kw = dict(T=a.T, systems=("coloured",), save_every=10 ** 9)
    simulate_wong_zakai_rigid_body(A, D, eps, sigma, n_paths=1, rng=np.random.default_rng(0), T=10 * h,
                                   systems=("coloured",))                     # warm-up / JIT cache
    print(f"eps = {eps}, eps^2 = {eps**2:.3g}, grid step h = {h:.3g} (h/eps^2 = {h/eps**2:.3g}), T = {a.T}")
    for P in (1, a.paths):
        t = timed(lambda: simulate_wong_zakai_rigid_body(A, D, eps, sigma, n_paths=P, rng=np.random.default_rng(1), **kw))
        print(f"  {P:5d} path(s): median {t:.3f} s  ->  {t / (P * a.T):.4f} s per path per unit time")
    # the "steps far below eps^2" route: same machinery with h = eps^2/100 (one sub-step each)
    P = 1
    hf = eps ** 2 / 100
    t_far = timed(lambda: simulate_wong_zakai_rigid_body(A, D, eps, sigma, n_paths=P, rng=np.random.default_rng(1),
                                                         h=hf, substeps=1, **kw))
    t_ours = timed(lambda: simulate_wong_zakai_rigid_body(A, D, eps, sigma, n_paths=P, rng=np.random.default_rng(1), **kw))
    print(f"  step eps^2/100: {t_far / a.T:.4f} s per path per unit time; ratio to h = eps^2/(2|A|): "
          f"{t_far / t_ours:.1f}x")
    # accuracy of the grid step: one fine lift (h/8) restricted by Chen to h
    Tacc = min(a.T, 0.05)
    n = int(round(Tacc / h))
    fine = sample_coloured_noise(A, D, eps, np.linspace(0, n * h, 8 * n + 1), rng=np.random.default_rng(2),
                                 batch_shape=(8,))
    coarse = fine.path.restrict(fine.path.times[::8])
    body = rigid_body([1, 2, 3], xi=sigma * np.eye(3), theta=1.0)
    Pf = solve(body, fine.path, [0, 0, 1.0], LieHeun()).states
    Pc = solve(body, coarse, [0, 0, 1.0], LieHeun()).states
    moved = np.max(np.abs(Pf[:, -1] - [0, 0, 1.0]))
    print(f"  accuracy at T = {n*h:.3g}: max |Pi_h - Pi_(h/8)| = {np.max(np.abs(Pf[:, -1] - Pc[:, -1])):.2e} "
          f"(Pi moved by {moved:.2e}); |Pi| error {np.max(np.abs(np.linalg.norm(Pc, axis=-1) - 1)):.1e}")


if __name__ == "__main__":
    main()
