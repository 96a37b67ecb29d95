"""Compile (and cache on disk) the numba kernels of a user's first tries, so they do not wait for the compiler.

Run once after an install (``tools/setup_env.sh`` does): numba compiles a kernel the first time it
meets a type signature and caches it. The calls below go through the public functions only, at the
argument types user calls produce: every path array reaches the kernels as a C-contiguous, writeable
float64 array of rank 3 (leading batch axes are flattened; read-only or strided inputs are copied first,
see ``roughpaths.signatures._engine._kernel_array``), depths as Python ints.

Compile time is the install's budget, so the list is short: batches of d = 2 and 3 paths (signature,
log-signature, both gradients, depths 2-4), the signature kernels (Goursat PDE, its adjoint, the MMD
statistics), the Brownian tree (d = 2, 3), and the coadjoint kernels of Lie–Heun (so(3), se(3), a
user algebra, with and without areas; the streamed ensemble; su(2), so(3), se(3) members on steps of their own). Each
kernel specialised on a size or a scheme is compiled per variant on its first use (``roughpaths._variants``):
everything else (other alphabet sizes, lone or long chunked paths, Lie–Euler and the implicit midpoint rule)
compiles its own variant on a user's first call, a few seconds each (``benchmarks/bench_first_call.py``).

``--more`` adds what the test suite reaches besides (lone, wide and long chunked paths, the rough-path
signature, the tensor algebra, p-variation, Lie–Euler and the midpoint rule, the coadjoint schemes on rough
paths built from arrays, the midpoint rule in six dimensions, the compile-time variants the oracle and
bit-equality tests reach, the matrix algebras of Proposition 2.1's tests, the norms, a corrected ensemble on worker
processes): ``tools/setup_env.sh`` passes it when it installs the test extra, so those compiles happen at
set-up on both cores, not inside the tests (where both xdist workers may compile the same kernel). ``SUITE_PROFILE`` (``tests/conftest.py``) and
``tools/suite_profile.py`` list what the suite still compiles.

Usage: ``python tools/warm_kernels.py [--part roughpaths|mechanics] [--more]`` (prints the time each family
took).
``tools/setup_env.sh`` runs the two parts in two processes at once, one on each core (before ``./test.sh``), or
one after the other in a background process while ``./run.sh``'s main job compiles its own kernels. The few
kernels two processes reach (the Brownian driver's random streams) may be compiled by both; numba replaces its
cache files atomically, so the worst case is an entry compiled once more on a later first call.
"""

from __future__ import annotations

import time

import numpy as np


def _walk(rng, *shape):
    """Random-walk paths of ``shape`` (points along axis -2), steps of size about 0.1."""
    return np.cumsum(rng.standard_normal(shape), axis=-2) * 0.1


def warm() -> None:
    """The signature kernels of a first try: batches of d = 2 and d = 3 paths at depths 2-4, the
    log-signature, and both gradients.

    Kept small on purpose (compile time is the install's budget): other alphabet sizes, lone paths, long
    paths cut into chunks and the rough-path signature compile their own variants on first use, a few
    seconds each (``benchmarks/bench_first_call.py`` measures them).
    """
    import roughpaths as rp
    from roughpaths.validation import parallel_ranges

    parallel_ranges(lambda lo, hi: None, 2, 1)      # with two threads or more: the workers' watch loop
    rng = np.random.default_rng(0)
    for d in (3, 2):
        x = _walk(rng, 16, 100, d)
        for m in (2, 3, 4):
            rp.signature(x, m)
            rp.logsignature(x, m)
        for m in (2, 3):
            rp.signature_vjp(x, m, np.ones((16, rp.sigdim(d, m))))
            rp.logsignature_vjp(x, m, np.ones((16, rp.logsigdim(d, m))))


def warm_more_signatures() -> None:
    """For the test suite (``--more``): lone, wide (d = 6) and long chunked paths, the rough-path signature and
    its gradient, the tensor-algebra kernels, the p-variation and the compiled XLA handlers of
    :mod:`roughpaths.jax` (``roughpaths.signatures.xla_handlers``: 2-3 s of CPU; they import no jax), which the tests
    reach."""
    import roughpaths as rp

    rng = np.random.default_rng(0)
    lone, wide, wide_batch = _walk(rng, 9, 3), _walk(rng, 2, 7, 6), _walk(rng, 9, 7, 6)
    long_path = _walk(rng, 2 * 1024 + 8, 2)
    for x in (lone, wide, wide_batch, long_path):
        for m in (2, 3):
            rp.signature(x, m)
            rp.logsignature(x, m)
            rp.signature_vjp(x, m, np.ones(np.shape(x)[:-2] + (rp.sigdim(np.shape(x)[-1], m),)))
            rp.logsignature_vjp(x, m, np.ones(np.shape(x)[:-2] + (rp.logsigdim(np.shape(x)[-1], m),)))
    rp.signature(lone, 4)                                  # the one-unit kernel's run-time variant (depth 3: its own)
    rp.signature(_walk(rng, 2 * 8192 + 8, 3), 2)           # level 2, chunked
    rp.signature(_walk(rng, 9, 700, 7), 3)                 # the lanes' (7, 3) variant
    rp.signature(_walk(rng, 9, 700, 1), 3)                 # the lanes' run-time variant (d = 1 reaches it)
    rp.signature(_walk(rng, 2, 39, 3), 9)                  # the one-unit kernel in place at a run-time d
    rp.signature(_walk(rng, 2, 39, 4), 7)                  # the one-unit kernel in place at d = 4 (a test's variant)
    X = rp.RoughPath.from_path(_walk(rng, 10, 9, 3))
    for m in (2, 3):
        s = rp.rough_path_signature(X, m)
        rp.rough_path_signature_vjp(X, m, np.ones_like(s))
    z = rp.tensor_log(rp.signature(lone, 3), dim=3)
    rp.tensor_exp(z, dim=3)
    rp.lyndon_coordinates(z, dim=3)
    rp.p_variation(lone, 2.5)
    from roughpaths.signatures import xla_handlers                   # roughpaths.jax's compiled handlers (numba only)

    for direction in ("forward", "backward"):
        xla_handlers.handler(direction)


def warm_more_variants() -> None:
    """For the test suite (``--more``): the compile-time variants its oracle and bit-equality tests reach and a
    user's first tries do not (measured with ``SUITE_PROFILE`` on a cold cache after the rest of the warm-up:
    86 s of compilation inside the tests, 42 s of it the one-unit reference kernel). The lane kernels of
    d = 2 at depth 5, d = 4 at depth 3 and (5, 3); the one-unit kernels (6, 4), (8, 4) and d = 4 at depth 8;
    the level-2 kernels of d = 4, 5; and :func:`~roughpaths.signatures._lanes.scalar_units`, the per-segment
    kernel the tests hold the others to (private: the tests call it directly; the engine runs it for lone paths
    of at most 8 points, the JAX tests' one-path calls), for d = 2, 3, 5, 6."""
    import roughpaths as rp
    from roughpaths.algebra.flat import level_offsets
    from roughpaths.signatures import _lanes
    from roughpaths.signatures._engine import _units

    rng = np.random.default_rng(0)
    for d, m in ((2, 5), (4, 3), (5, 3)):                 # lanes (16 paths: two full lane groups)
        rp.signature(_walk(rng, 16, 20, d), m)
    rp.signature_vjp(_walk(rng, 16, 20, 4), 3, np.ones((16, rp.sigdim(4, 3))))
    for d, m in ((6, 4), (8, 4)):                          # one unit at a time, compile-time width and depth
        rp.signature(_walk(rng, 2, 20, d), m)
    rp.logsignature(_walk(rng, 2, 6, 4), 8)
    for d in (4, 5):
        rp.signature(_walk(rng, 3, 20, d), 2)
    for d in (2, 3, 5, 6):
        x = _walk(rng, 3, 10, d)
        units = _units(3, 10, 2)
        off = level_offsets(d, 3)
        _lanes.scalar_units(d)(x, *units, 3, off, 0, 6, np.empty((6, off[4])))


def warm_more_drivers() -> None:
    """For the test suite (``--more``): the Brownian driver with every Lévy-area method at d = 2 and 3 (the
    tests sample with each; the default's kernels are the main job's), a few seconds of CPU each."""
    import roughpaths as rp

    for d in (2, 3):
        for area in (None, "davie", "foster", "exact", "fourier", "mrongowius-rossler", "wiktorsson"):
            if area == "exact" and d != 2:
                continue
            rp.BrownianDriver(d, seed=0, dt=0.01, n_steps=4, batch_shape=(2,), levy_area=area).rough_path()


def warm_more_norms() -> None:
    """For the test suite (``--more``): the Hölder and p-variation kernels of levels 1 and 2 (each test worker
    compiled them again, about 6 s of CPU)."""
    import roughpaths as rp

    t = np.linspace(0.0, 1.0, 9)
    X = rp.RoughPath.from_path(np.sin(np.outer(t, [1.0, 2.0, 3.0])), times=t)
    for f in (rp.holder_seminorm, rp.area_holder_seminorm, rp.rough_path_holder_norm):
        f(X, 0.4)
    rp.holder_seminorm(X.path, 0.4, times=t)
    for f in (rp.p_variation, rp.area_p_variation, rp.rough_path_p_variation):
        f(X, 2.5)
    rp.p_variation(X, 2.5, return_partition=True)


def warm_more_gradients() -> None:
    """For the test suite (``--more``): the backward kernels of lone paths at d = 4 and d = 1, and of wide
    alphabets cut into blocks (d = 20, and d = 8: the smallest width that runs alone). Each is one variant of 15-25 s of CPU (a lone d = 1 gradient: 25 s,
    load ~8), which the suite otherwise compiles inside its tests. Run in the other process than
    :func:`warm_more_signatures` (balance)."""
    import roughpaths as rp

    rng = np.random.default_rng(0)
    for shape in ((9, 4), (6, 1), (2, 37, 20), (2, 37, 8)):
        x = _walk(rng, *shape)
        rp.signature_vjp(x, 3, np.ones(shape[:-2] + (rp.sigdim(shape[-1], 3),)))


def warm_more_coadjoint() -> None:
    """For the test suite (``--more``): Lie–Euler and the implicit midpoint rule on so(3), se(3) and a user
    algebra, and the kernels of the rare steps past the vectorised exponential (a member with a huge state); every scheme on the rough paths a user builds (a level-1 path, increments with areas, a path's
    lift), whose arrays reach the so(3) and se(3) kernels writeable or read-only in other combinations than
    a driver's (each combination is a specialisation of its own, 6-8 s of CPU); the midpoint rule's
    six-dimensional variant of the generic kernel (se(3) from its constants, so(4))."""
    from mechanics import ImplicitMidpoint, LieEuler, LieHeun, LiePoissonSystem, heavy_top, rigid_body
    from mechanics.systems.lie_algebra import LieAlgebra, se3, su2
    from roughpaths import BrownianDriver, RoughPath, solve

    rigid, top = rigid_body([1.0, 2.0, 3.0], sigma=0.1), heavy_top([1.0, 2.0, 3.0], chi=[0.0, 0.0, 1.0], sigma=0.1)
    for system in (LiePoissonSystem(su2(), np.eye(3), np.eye(3), theta=0.1), rigid, top):
        X = BrownianDriver(system.n_noise, seed=0, dt=0.01, n_steps=2, batch_shape=(2,))
        wild = np.ones((2, system.dim))
        wild[1] *= 1e8                 # a step past the vectorised exponential: the rare-step kernels
        for method in (LieEuler(), LieHeun(), ImplicitMidpoint()):
            # a tame solve first: a process decides on its first solve which variant a kernel starts with
            # (._soa_rows.starts_full), so this compiles the vectorised one, and the wild solve the other
            solve(system, X, np.ones((2, system.dim)), method)
            solve(system, X, wild, method, on_failure="mask")
    rng = np.random.default_rng(0)
    times = np.linspace(0.0, 0.02, 3)
    for system in (rigid, top):
        dw = 0.1 * rng.standard_normal((2, 2, system.n_noise))
        sym = 0.5 * dw[..., :, None] * dw[..., None, :]
        lift = RoughPath.from_path(np.concatenate([np.zeros((2, 1, system.n_noise)), np.cumsum(dw, 1)], 1),
                                   times=times)
        paths = (RoughPath.from_increments(dw, times=times), RoughPath.from_increments(dw, sym, times=times), lift,
                 RoughPath(lift.increments, sym - lift.step_levy_areas, times=times), lift.restrict(times[::2]))
        for X in paths:
            for method in (LieEuler(), LieHeun(), ImplicitMidpoint()):
                solve(system, X, np.ones((2, system.dim)), method)
    se3c = LiePoissonSystem(LieAlgebra(se3().structure_constants, name="se3 (constants)"), np.diag(np.arange(1.0, 7.0)),
                            0.3 * rng.standard_normal((3, 6)), theta=0.1)
    solve(se3c, BrownianDriver(3, seed=0, dt=0.01, n_steps=2, batch_shape=(2,)), np.ones((2, 6)), ImplicitMidpoint())
    from mechanics import su                  # the midpoint rule at a dimension read from the arrays (su(3), n = 8)
    su3 = LiePoissonSystem(LieAlgebra(su(3).structure_constants, name="su3 (constants)"), np.ones(8),
                           0.3 * rng.standard_normal((3, 8)), theta=0.1)
    solve(su3, BrownianDriver(3, seed=0, dt=0.01, n_steps=2, batch_shape=(2,)), np.ones((2, 8)), ImplicitMidpoint())
    for system in (se3c, su3):     # the midpoint rule on members with steps of their own, dimensions 6 and 8
        ImplicitMidpoint().step(system, np.ones((2, system.dim)), np.zeros((2, 1)), np.full((2, 1), 0.01),
                                np.zeros((2, 3)), np.zeros((2, 3, 3)))
    su2_system = LiePoissonSystem(su2(), np.eye(3), np.eye(3), theta=0.1)
    for system in (su2_system, rigid, top):    # su(2), so(3), se(3) members on steps of their own (adaptive solves)
        for method in (LieEuler(), ImplicitMidpoint()):
            method.step(system, np.ones((2, system.dim)), np.zeros((2, 1)), np.full((2, 1), 0.01), np.zeros((2, 3)),
                        np.zeros((2, 3, 3)))


def warm_more_matrix_algebras() -> None:
    """For the test suite (``--more``): the generic coadjoint kernel on su(3) and so(5) with Lie–Euler at
    θ = 0, and the midpoint rule's variant with a bounded chord iteration, on rough paths built from arrays
    (Proposition 2.1's and the isospectral tests; 11 s of compilation inside them)."""
    from mechanics import ChordConvergenceError, ImplicitMidpoint, LieEuler, LiePoissonSystem, so, su
    from roughpaths import RoughPath, brownian_rough_path, solve

    rng = np.random.default_rng(0)
    for g in (su(3), so(5)):
        vals = np.cumsum(rng.standard_normal((3, 241, 4)) * 0.06, axis=1)
        fine = RoughPath.from_path(vals, times=np.linspace(0.0, 1.0, 241))
        s = rng.standard_normal((4, 4))
        system = LiePoissonSystem(g, np.linspace(0.7, 1.8, g.dim), 0.3 * rng.standard_normal((4, g.dim)), theta=0.0)
        solve(system, fine.restrict(fine.times[::4]).perturb(s - s.T), np.ones(g.dim), LieEuler())
    system = LiePoissonSystem(su(3), 0.05 + rng.random(8), 0.3 * rng.standard_normal((2, 8)), theta=2.0)
    X = brownian_rough_path(np.linspace(0.0, 1.0, 3), dim=2, rng=np.random.default_rng(3))
    try:
        solve(system, X, 20.0 * rng.standard_normal(8), ImplicitMidpoint(max_iter=3))
    except ChordConvergenceError:
        pass


def warm_more_ensembles() -> None:
    """For the test suite (``--more``): a streamed rigid-body ensemble with a Lévy-area correction, here and on a
    worker process, whose arrays arrive unpickled (other specialisations: compiled inside the workers of a test
    of the executors, 7 s)."""
    from concurrent.futures import ProcessPoolExecutor

    from mechanics import rigid_body, run_ensemble

    corrected = rigid_body([1.0, 2.0, 3.0], sigma=0.4, s=np.array([[0, 0, 1.0], [0, 0, 0], [-1.0, 0, 0]]), theta=0.5)
    with ProcessPoolExecutor(max_workers=1) as ex:
        for executor in (None, ex):
            run_ensemble(corrected, [0.0, 0.0, 1.0], dt=0.01, n_steps=60, n_paths=70, seed=0, burn_in=20,
                         record_every=15, keep_final=True, executor=executor)


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
        tree = rp.BrownianTree(d, seed=0, batch_shape=(2,))
        tree.area(0.1, 0.3)
        tree.increments_and_areas([[0.1, 0.3], [0.2, 0.4]], [0, 1])      # the per-member walk (adaptive steps)
    # the adaptive loop's compiled bookkeeping and PIController's kernel (steps per member)
    rp.solve(rp.LinearVectorFields(np.array([[[0.0, 1.0], [-1.0, 0.0]], [[0.5, 0.0], [0.0, -0.5]]])),
             rp.BrownianTree(2, seed=0, batch_shape=(2,)), np.ones(2), rp.Davie(), step_control=rp.PIController(0.1, 0.1))


def warm_coadjoint() -> None:
    from mechanics import LieHeun, LiePoissonSystem, heavy_top, rigid_body, run_ensemble
    from mechanics.systems.lie_algebra import su2
    from roughpaths import BrownianDriver, solve

    generic = LiePoissonSystem(su2(), np.eye(3), np.eye(3), theta=0.1)
    systems = (generic, rigid_body([1.0, 2.0, 3.0], sigma=0.1),
               heavy_top([1.0, 2.0, 3.0], chi=[0.0, 0.0, 1.0], sigma=0.1))
    for system in systems:          # the default areas (the coadjoint kernels are the same without areas)
        X = BrownianDriver(system.n_noise, seed=0, dt=0.01, n_steps=2, batch_shape=(2,))
        solve(system, X, np.ones((2, system.dim)), LieHeun())        # the other schemes: on first use
    for system in systems[1:]:      # the streamed statistics (so(3) moments in registers, se(3) generic)
        run_ensemble(system, np.ones(system.dim), dt=0.01, n_steps=4, n_paths=2, seed=0)
    for system in systems:          # su(2), so(3), se(3) members each on a step of its own (adaptive solves)
        LieHeun().step(system, np.ones((2, system.dim)), np.zeros((2, 1)), np.full((2, 1), 0.01), np.zeros((2, 3)),
                       np.zeros((2, 3, 3)))


PARTS = {
    "roughpaths": (("signatures", warm), ("signature kernels", warm_signature_kernels), ("Brownian tree", warm_tree)),
    "mechanics": (("coadjoint kernels", warm_coadjoint),),
}
#: with ``--more`` (``tools/setup_env.sh`` when it installs the test extra): what the test suite reaches besides
MORE = {"roughpaths": (("more signatures", warm_more_signatures), ("more drivers", warm_more_drivers),
                       ("signature variants of the tests", warm_more_variants), ("norms", warm_more_norms)),
        "mechanics": (("more coadjoint schemes", warm_more_coadjoint),
                      ("more signature gradients", warm_more_gradients),
                      ("matrix algebras of the tests", warm_more_matrix_algebras),
                      ("corrected ensembles of the tests", warm_more_ensembles))}


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=sorted(PARTS), help="only this part (default: both, one after the other)")
    parser.add_argument("--more", action="store_true", help="also what the test suite reaches")
    args = parser.parse_args()
    for name in ([args.part] if args.part else sorted(PARTS, reverse=True)):
        for what, fn in PARTS[name] + (MORE[name] if args.more else ()):
            t0, c0 = time.perf_counter(), time.process_time()
            fn()
            print(f"{what}: compiled and cached in {time.perf_counter() - t0:.1f} s "
                  f"({time.process_time() - c0:.1f} s CPU)", flush=True)


if __name__ == "__main__":
    main()
