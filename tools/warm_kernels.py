"""Compile (and cache on disk) every numba kernel the public functions can reach beyond the main job's.

Run once after an install (``tools/setup_env.sh`` does): numba compiles a kernel the first time it
meets a type signature and caches it, so a user's first call would otherwise wait 10-30 s for the
compiler. The calls below go through the public functions only, at the argument types user calls
produce: every path array reaches the kernels as a C-contiguous, writeable float64 array of rank 3
(leading batch axes are flattened; read-only or strided inputs are copied first, see
``roughpaths.signatures._engine._kernel_array``), depths as Python ints. They cover each kernel
family: the level-2 kernel (short and chunked paths, d <= 5 and wider), the lane kernel (full lane
groups), the one-unit kernel (a lone path, and every d >= 6), long paths cut into chunks and glued,
the log-signature (truncated log, Lyndon projection), the three vector-Jacobian products, and the
tensor-algebra functions they build on; then the signature kernels (Goursat PDE, its adjoint, the
MMD statistics), the Brownian tree's split kernels (d = 2 and 3), and the generic coadjoint kernel of
:mod:`mechanics` (one compiled signature serves every algebra and all three coadjoint schemes; the
so(3)/se(3) kernels are warmed too, with and without areas).

Each kernel specialised on a size (the signature kernels' alphabet sizes and depths, the coadjoint
kernels' schemes) is compiled per variant on its first use (``roughpaths._variants``): the calls below
compile the variants of the shapes above (d = 2, 3 and 6); other sizes compile theirs, a few seconds
each, on a user's first call.

Usage: ``python tools/warm_kernels.py [--part roughpaths|mechanics]`` (prints the time each family took).
``tools/setup_env.sh`` runs the two parts in two processes at once, one on each core. The few kernels both
reach (the Brownian driver's random streams) may be compiled by both; numba replaces its cache files
atomically, so the worst case is an entry compiled once more on a later first call.
"""

from __future__ import annotations

import time

import numpy as np


def warm() -> None:
    import roughpaths as rp

    rng = np.random.default_rng(0)

    def path(*shape):
        return np.cumsum(rng.standard_normal(shape), axis=-2) * 0.1

    lone, wide, batch = path(9, 3), path(2, 7, 6), path(10, 9, 3)
    wide_batch = path(9, 7, 6)                             # d >= 6: lane groups of paths at level 2
    long_path = path(2 * 1024 + 8, 2)                     # cut into chunks (Chen glue)
    long_l2 = path(2 * 8192 + 8, 3)                       # level 2, chunked
    for x in (lone, wide, wide_batch, batch, long_path, lone.tolist(), lone[None, None]):
        for m in (1, 2, 3):
            rp.signature(x, m)
            rp.logsignature(x, m)
    rp.signature(long_l2, 2)
    rp.signature(batch, np.int64(4))
    for x in (lone, wide, batch, long_path):
        for m in (2, 3):
            rp.signature_vjp(x, m, np.ones(np.shape(x)[:-2] + (rp.sigdim(np.shape(x)[-1], m),)))
            rp.logsignature_vjp(x, m, np.ones(np.shape(x)[:-2] + (rp.logsigdim(np.shape(x)[-1], m),)))
    X = rp.RoughPath.from_path(batch)
    for m in (2, 3):
        s = rp.rough_path_signature(X, m)
        rp.rough_path_signature_vjp(X, m, np.ones_like(s))
    s = rp.signature(lone, 3)                             # lone has d = 3
    z = rp.tensor_log(s, dim=3)
    rp.tensor_exp(z, dim=3)
    rp.lyndon_coordinates(z, dim=3)
    rp.p_variation(lone, 2.5)


def warm_signature_kernels() -> None:
    import roughpaths as rp

    x = np.zeros((2, 3, 2))
    rp.signature_kernel(x, x)
    rp.signature_kernel_vjp(x, x, np.ones(2))
    rp.signature_kernel_gram(x, x, static_kernel=rp.RBFKernel(1.0))
    rp.signature_kernel_gram_vjp(x, x, np.ones((2, 2)))
    rp.sig_mmd_test(x, x, seed=0, n_permutations=1)


def warm_tree() -> None:
    import roughpaths as rp

    for d in (2, 3):
        rp.BrownianTree(d, seed=0).area(0.1, 0.3)


def warm_coadjoint() -> None:
    from mechanics import (ImplicitMidpoint, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body,
                           run_ensemble)
    from mechanics.systems.lie_algebra import su2
    from roughpaths import BrownianDriver, solve

    generic = LiePoissonSystem(su2(), np.eye(3), np.eye(3), theta=0.1)
    systems = (generic, rigid_body([1.0, 2.0, 3.0], sigma=0.1),
               heavy_top([1.0, 2.0, 3.0], chi=[0.0, 0.0, 1.0], sigma=0.1))
    for system in systems:
        for levy_area in ("davie", None):
            X = BrownianDriver(system.n_noise, seed=0, dt=0.01, n_steps=2, batch_shape=(2,), levy_area=levy_area)
            for method in (LieEuler(), LieHeun(), ImplicitMidpoint()):
                solve(system, X, np.ones((2, system.dim)), method)
    for system in systems[1:]:      # the streamed statistics (so(3) moments in registers, se(3) generic)
        run_ensemble(system, np.ones(system.dim), dt=0.01, n_steps=4, n_paths=2, seed=0)


PARTS = {
    "roughpaths": (("signatures", warm), ("signature kernels", warm_signature_kernels), ("Brownian tree", warm_tree)),
    "mechanics": (("coadjoint kernels", warm_coadjoint),),
}


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=sorted(PARTS), help="only this part (default: both, one after the other)")
    part = parser.parse_args().part
    for name in ([part] if part else sorted(PARTS, reverse=True)):
        for what, fn in PARTS[name]:
            t0, c0 = time.perf_counter(), time.process_time()
            fn()
            print(f"{what}: compiled and cached in {time.perf_counter() - t0:.1f} s "
                  f"({time.process_time() - c0:.1f} s CPU)", flush=True)


if __name__ == "__main__":
    main()
