"""Benchmark: Lie algebras of any size — structure constants vs matrices vs plain numpy (issue 37, items 4-5).

Problem, for so(n), n = 3, 4, 8, 12, 16, and su(N), N = 2, 3, 4, 8, 10, 16, 32, 64: the stochastic Lie–Poisson
system with a diagonal Hamiltonian (moments ``1 + U(0, 1)``), double-bracket dissipation θ = 0.3, three dense
random noise vectors ξ_i (non-commuting), dt = 0.01, driven by one precomputed Brownian rough path with its
Lévy area, solved by Lie–Heun; ``μ0`` with components of size ``1/√N``. The noise size ``a`` is the RMS of a
component of the noise part η of the step's Lie-algebra increment σ (``ξ`` components ``a / √(3 dt)``):
``a = 0.3`` (the issue's "0.3 per component") and ``a = 0.01``.

Columns (CPU time per path-step, medians of ``--repeats`` interleaved runs, one thread unless stated):

* ``(a) kernel``: ``LieAlgebra(structure_constants)`` (no basis) through ``solve``: the compiled generic
  kernel; only for ``n <= --max-constants-dim`` (default 66: beyond it the kernel's dense fallback costs ``n³``
  per step at ``a = 0.3`` — so(12) 2.8 ms per path-step — and the constructor's checks take tens of seconds);
* ``(a) dispatched``: ``LieAlgebra(c, basis=E)`` (what ``LieAlgebra.from_matrix_basis`` builds) through
  ``solve``: the solver's cost model may run it on the matrix path;
* ``(b) matrix``: ``solve`` on the :class:`~mechanics.MatrixLieAlgebra` with the isospectral steps forced;
  ``(b) solve``: what ``solve`` does on it (the cost model may run the compiled kernel on its constants);
* ``(c) numpy``: a plain numpy/BLAS Lie–Heun step written here (batched ``np.matmul``, the coordinate maps as
  ``scipy.sparse`` products, a batch-wide Padé scaling and squaring à la ``scipy.linalg.expm``).

Ratios: ``(b)/(c)`` (target ≤ 1.5 at every size and noise), ``(a)/(b)`` (dispatched: target ≤ 1). Then memory
(tracemalloc peak of one solve of the batch), construction time (``LieAlgebra(c)`` with its checks against the
``so``/``su`` constructor), the largest difference (b) − (c) and the Casimir drift of (b); then one thread
against two on the matrix path (four blocks of members; wall, CPU, bitwise).

Usage: ``python benchmarks/bench_lie_algebras.py [--quick] [--repeats R] [--max-constants-dim n] [--threads-only] [--only so16,su16]``.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")       # one BLAS thread: the threads are ours, over members

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from math import factorial  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402
import scipy.sparse as sparse  # noqa: E402

DT, THETA, M_NOISE = 0.01, 0.3, 3
_PADE_THETA = ((3, 1.495585217958292e-2), (5, 2.539398330063230e-1), (7, 9.504178996162932e-1),
               (9, 2.097847961257068e0), (13, 5.371920351148152e0))


def _pade_b(m):
    return [factorial(2 * m - k) * factorial(m) / (factorial(2 * m) * factorial(k) * factorial(m - k))
            for k in range(m + 1)]


_PADE_B = {m: _pade_b(m) for m, _ in _PADE_THETA}


def expm_plain(A):
    """Scaling and squaring with the diagonal Padé approximant, degree and squarings from the batch's largest
    1-norm (Higham 2005), as a plain batched implementation would do."""
    nrm = float(np.max(np.sum(np.abs(A), axis=-2)))
    s = 0
    for m, th in _PADE_THETA:
        if nrm <= th:
            break
    else:
        m = 13
        s = max(0, int(np.ceil(np.log2(nrm / _PADE_THETA[-1][1]))))
        A = A / 2.0 ** s
    b = _PADE_B[m]
    eye = np.eye(A.shape[-1])
    A2 = A @ A
    P = [eye, A2]
    for _ in range(2, m // 2 + 1):
        P.append(P[-1] @ A2)
    U = A @ sum(b[2 * k + 1] * P[k] for k in range(m // 2 + 1))
    V = sum(b[2 * k] * P[k] for k in range(m // 2 + 1))
    R = np.linalg.solve(V - U, V + U)
    for _ in range(s):
        R = R @ R
    return R


class PlainHeun:
    """The isospectral Lie–Heun step in plain numpy (compact algebras with an orthonormal basis)."""

    def __init__(self, system):
        alg = system.algebra
        self.N, self.n, self.dtype = alg.matrix_size, alg.dim, alg.dtype
        E = alg.basis                                                   # (n, N, N), dense, once
        self.S_T = sparse.csr_matrix(E.reshape(self.n, -1)).T.tocsr()   # x -> vec(sum x_i E_i)
        self.ET = sparse.csr_matrix(np.swapaxes(E, 1, 2).reshape(self.n, -1))   # vec(M) -> tr(M E_i)
        self.q, self.theta = system.hamiltonian.q_diagonal, system.theta
        iu, ju = np.triu_indices(system.n_noise, 1)
        self.iu, self.ju = iu, ju
        self.Z = (self.S_T @ np.concatenate([system.xi, system.xi_brackets[iu, ju]]).T).T
        self.shift = (self.S_T @ system.torque_velocity).reshape(self.N, self.N)

    def to_mat(self, x):
        return (self.S_T @ x.T).T.reshape(-1, self.N, self.N)

    def to_dual(self, M):
        return -0.5 * (self.ET @ M.reshape(-1, self.N * self.N).T).real.T

    def w(self, M):
        W = self.to_mat(self.q * self.to_dual(M)) + self.shift
        return W + self.theta * (M @ W - W @ M)

    def run(self, mu0, dX, areas, dts):
        M = self.to_mat(mu0)
        N = self.N
        for k in range(dts.size):
            dt = dts[k]
            coef = np.concatenate([dX[:, k], areas[:, k][:, self.iu, self.ju]], -1)
            eta = (coef @ self.Z).reshape(-1, N, N)
            w0 = self.w(M)
            s0 = w0 * dt + eta
            A1 = M @ s0 - s0 @ M
            Mp = M + A1 + 0.5 * (A1 @ s0 - s0 @ A1)
            sig = 0.5 * (w0 + self.w(Mp)) * dt + eta
            Q = expm_plain(-sig)
            M = Q @ M @ np.conj(np.swapaxes(Q, -1, -2))
            M = 0.5 * (M - np.conj(np.swapaxes(M, -1, -2)))
            if self.dtype.kind == "c":
                M = M - (np.trace(M, axis1=-2, axis2=-1) / N)[:, None, None] * np.eye(N)
        return self.to_dual(M)


def _cpu(fn):
    c0 = time.process_time()
    out = fn()
    return time.process_time() - c0, out


def _interleaved(fns, repeats, slow=1.5):
    """Median CPU time of each function, run interleaved after one warm-up each; and the last results. A function
    whose first timed run takes over ``slow`` seconds (the constants kernel's dense fallback) is timed once."""
    outs = [f() for f in fns]
    times = [[] for _ in fns]
    for r in range(repeats):
        for i, f in enumerate(fns):
            if r and times[i][0] > slow:
                continue
            t, outs[i] = _cpu(f)
            times[i].append(t)
    return [statistics.median(t) for t in times], outs


def _peak(fn):
    tracemalloc.start()
    fn()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def _sizes(quick):
    so_n = (3, 4, 8, 12, 16)
    su_n = (2, 3, 4, 8, 10, 16, 32, 64)
    if quick:
        so_n, su_n = (3, 8), (3, 8, 16)
    return [("so", n) for n in so_n] + [("su", n) for n in su_n]


def _batch(N, quick):
    """(paths, steps) for an algebra on N x N matrices: ~1e7 product flops per timed run (N > 8), at least 8 paths."""
    paths = int(np.clip(2 ** 17 // N ** 3, 8, 512))
    steps = int(np.clip(2 ** 23 // (paths * N ** 3), 4, 40))
    return (max(8, paths // 4), max(4, steps // 2)) if quick else (paths, steps)


def threads_table(sizes, repeats, quick):
    """The matrix path on 1 thread and on 2 (``numba.set_num_threads``; the members run in blocks shared by the
    threads): four blocks of members, a = 0.3, wall and CPU per path-step, and a bitwise check."""
    import mechanics
    import mechanics.integrators.base as coadjoint_base
    from mechanics import LieHeun, LiePoissonSystem, MatrixLieAlgebra
    from mechanics.integrators._isospectral import block_members
    from roughpaths import BrownianDriver, solve

    dispatch = coadjoint_base.choose
    coadjoint_base.choose = lambda system, dts: (system, isinstance(system.algebra, MatrixLieAlgebra))
    print(f"\nthe matrix path, 1 thread against 2 (numba.set_num_threads), four blocks of members, a = 0.3: per "
          f"path-step (us) wall and CPU, medians of {repeats} interleaved runs, and a bitwise check; "
          f"load {os.getloadavg()[0]:.1f} (on a busy machine the wall ratio is what the second core was free for)")
    print(f"{'algebra':8s} {'paths':>6s} {'wall 1':>9s} {'wall 2':>9s} {'wall 2/1':>9s} {'cpu 1':>9s} {'cpu 2':>9s} "
          f"{'bitwise':>8s}")
    try:
        for kind, N in sizes:
            if N < 8:
                continue
            alg = getattr(mechanics, kind)(N)
            P = min(512, 4 * block_members(alg, 10 ** 6))
            K = int(np.clip(2 ** 22 // (P * N ** 3), 2, 16)) // (2 if quick else 1) or 1
            rng = np.random.default_rng(N)
            system = LiePoissonSystem(alg, 1.0 + rng.random(alg.dim),
                                      0.3 / np.sqrt(M_NOISE * DT) * rng.standard_normal((M_NOISE, alg.dim)), theta=THETA)
            mu0 = rng.standard_normal((P, alg.dim)) / np.sqrt(N)
            X = BrownianDriver(M_NOISE, seed=1, dt=DT, n_steps=K, batch_shape=(P,)).rough_path()
            walls, cpus, outs = {1: [], 2: []}, {1: [], 2: []}, {}
            for r in range(repeats + 1):
                for t in (1, 2):
                    numba.set_num_threads(t)
                    w0, c0 = time.perf_counter(), time.process_time()
                    outs[t] = solve(system, X, mu0, LieHeun(), save_at="end").final
                    if r:                                                   # the first round warms up
                        walls[t].append(time.perf_counter() - w0)
                        cpus[t].append(time.process_time() - c0)
            numba.set_num_threads(1)
            w1, w2 = (1e6 * statistics.median(walls[t]) / (P * K) for t in (1, 2))
            c1, c2 = (1e6 * statistics.median(cpus[t]) / (P * K) for t in (1, 2))
            print(f"{alg.name:8s} {P:6d} {w1:9.2f} {w2:9.2f} {w2 / w1:9.2f} {c1:9.2f} {c2:9.2f} "
                  f"{str(bool(np.array_equal(outs[1], outs[2]))):>8s}", flush=True)
    finally:
        coadjoint_base.choose = dispatch


def main():
    import mechanics
    import mechanics.integrators.base as coadjoint_base
    from mechanics import LieAlgebra, LieHeun, LiePoissonSystem, MatrixLieAlgebra
    from roughpaths import BrownianDriver, solve

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--max-constants-dim", type=int, default=66)
    ap.add_argument("--threads-only", action="store_true")
    ap.add_argument("--only", default="", help="comma-separated algebras, e.g. so16,su16 (default: all)")
    a = ap.parse_args()
    numba.set_num_threads(1)
    if a.threads_only:
        threads_table(_sizes(a.quick), a.repeats, a.quick)
        return
    dispatch = coadjoint_base.choose

    def forced_matrix(system, dts):
        return system, isinstance(system.algebra, MatrixLieAlgebra)

    print(f"load {os.getloadavg()[0]:.1f}; CPU time per path-step (us), medians of {a.repeats} interleaved runs, "
          f"one thread; Lie-Heun, dt = {DT}, theta = {THETA}, {M_NOISE} noise vectors, with the Levy area")
    head = (f"{'algebra':8s} {'n':>5s} {'a':>5s} {'paths x steps':>13s} {'(a)kernel':>10s} {'(a)disp':>9s} "
            f"{'(b)matrix':>10s} {'(b)solve':>9s} {'(c)numpy':>9s} {'b/c':>6s} {'a/b':>6s} {'akern/b':>8s} "
            f"{'|b-c|':>8s} {'Cas.drift':>9s}")
    print(head)
    rows, mem_rows = [], []
    only = {x.strip() for x in a.only.split(",") if x.strip()}
    for kind, N in _sizes(a.quick):
        if only and f"{kind}{N}" not in only:
            continue
        t0 = time.process_time()
        alg = getattr(mechanics, kind)(N)
        t_matrix_build = time.process_time() - t0
        n = alg.dim
        P, K = _batch(N, a.quick)
        rng = np.random.default_rng(N)
        mu0 = rng.standard_normal((P, n)) / np.sqrt(N)
        X = BrownianDriver(M_NOISE, seed=1, dt=DT, n_steps=K, batch_shape=(P,)).rough_path()
        areas = 0.5 * (X.areas - np.swapaxes(X.areas, -1, -2))
        dts = np.diff(X.times)
        inertia = 1.0 + rng.random(n)
        xi_unit = rng.standard_normal((M_NOISE, n))
        use_constants = n <= a.max_constants_dim
        if use_constants:
            c = alg.structure_constants
            t0 = time.process_time()
            LieAlgebra(c, name="check")                                 # the constructor with its checks
            t_const_build = time.process_time() - t0
            plain_c = LieAlgebra(c, name=f"{alg.name} constants", casimirs=alg.casimirs, check=False)
            with_basis = LieAlgebra(c, name=f"{alg.name} constants", basis=alg.basis, casimirs=alg.casimirs,
                                    check=False)
        for amp in (0.3, 0.01):
            xi = amp / np.sqrt(M_NOISE * DT) * xi_unit
            sysb = LiePoissonSystem(alg, inertia, xi, theta=THETA)
            plain = PlainHeun(sysb)
            fns = {}
            if use_constants:
                sysa = LiePoissonSystem(plain_c, np.diag(inertia), xi, theta=THETA)
                sysa2 = LiePoissonSystem(with_basis, np.diag(inertia), xi, theta=THETA)
                fns["a_kernel"] = lambda s=sysa, X=X, mu0=mu0: solve(s, X, mu0, LieHeun(), save_at="end").final
                fns["a_disp"] = lambda s=sysa2, X=X, mu0=mu0: solve(s, X, mu0, LieHeun(), save_at="end").final

            def matrix_forced(s=sysb, X=X, mu0=mu0):
                coadjoint_base.choose = forced_matrix
                try:
                    return solve(s, X, mu0, LieHeun(), save_at="end").final
                finally:
                    coadjoint_base.choose = dispatch

            fns["b_matrix"] = matrix_forced
            fns["b_solve"] = lambda s=sysb, X=X, mu0=mu0: solve(s, X, mu0, LieHeun(), save_at="end").final
            fns["c_numpy"] = lambda p=plain, X=X, mu0=mu0, ar=areas, d=dts: p.run(mu0, X.increments, ar, d)
            times, outs = _interleaved(list(fns.values()), a.repeats)
            us = {k: 1e6 * t / (P * K) for k, t in zip(fns, times)}
            res = dict(zip(fns, outs))
            diff = float(np.max(np.abs(res["b_matrix"] - res["c_numpy"])))
            c0, c1 = alg.casimirs(mu0), alg.casimirs(res["b_matrix"])
            scale = alg.casimir_scale(alg.dual_to_matrix(mu0))
            drift = float(np.max(np.abs(c1 - c0) / scale))
            b = min(us["b_matrix"], us["b_solve"])
            fa = lambda k: f"{us[k]:10.2f}" if k in us else f"{'-':>10s}"
            ab = f"{us['a_disp'] / us['b_solve']:6.2f}" if "a_disp" in us else f"{'-':>6s}"
            akb = f"{us['a_kernel'] / us['b_solve']:8.2f}" if "a_kernel" in us else f"{'-':>8s}"
            print(f"{alg.name:8s} {n:5d} {amp:5.2f} {P:6d} x {K:4d} {fa('a_kernel')} {fa('a_disp')[1:]} "
                  f"{us['b_matrix']:10.2f} {us['b_solve']:9.2f} {us['c_numpy']:9.2f} "
                  f"{b / us['c_numpy']:6.2f} {ab} {akb} {diff:8.1e} {drift:9.1e}", flush=True)
            rows.append((alg.name, amp, us))
            if amp == 0.3:
                mem_b = _peak(fns["b_solve"])
                mem_c = _peak(fns["c_numpy"])
                mem_rows.append((alg.name, n, P, mem_b, mem_c, t_matrix_build,
                                 t_const_build if use_constants else None))
    print("\nmemory (tracemalloc peak of one solve of the batch, a = 0.3) and construction time (CPU)")
    print(f"{'algebra':8s} {'n':>5s} {'paths':>6s} {'(b) peak MiB':>13s} {'(c) peak MiB':>13s} "
          f"{'so/su() ms':>11s} {'LieAlgebra(c) ms':>17s}")
    for name, n, P, mb, mc, tb, tc in mem_rows:
        tcs = f"{1e3 * tc:17.1f}" if tc is not None else f"{'skipped':>17s}"
        print(f"{name:8s} {n:5d} {P:6d} {mb / 2 ** 20:13.1f} {mc / 2 ** 20:13.1f} {1e3 * tb:11.1f} {tcs}")
    threads_table([(k, N) for k, N in _sizes(a.quick) if not only or f"{k}{N}" in only], a.repeats, a.quick)
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
