"""Tutorial: scale out on a Dask cluster, with the serial run's bits, and watch the progress.

Run with ``python docs/tutorials/scale_out.py`` (``TUTORIAL_SMALL=1`` for reduced sizes and no timing).
Needs the ``dask`` extra: ``pip install -e '.[dask]'``.

``roughpaths.solve`` and ``mechanics.run_ensemble`` take ``executor=``: anything with
``concurrent.futures``' ``submit``, e.g. a thread or process pool, or a Dask cluster's
``client.get_executor()``. They cut the batch of paths into contiguous groups, send each group to the
executor, and put the answers back together in path order. A path's noise depends only on the driver's seed
and the path's index, and a path never affects another, so the result is bitwise the serial one,
whatever the groups, the workers or the cluster.
"""

# %%
import os
import pickle
import time

import numpy as np

import mechanics
import roughpaths as rp

SMALL = os.environ.get("TUTORIAL_SMALL", "") not in ("", "0")
M = 0.3 * np.random.default_rng(3).standard_normal((2, 3, 3))      # two non-commuting linear fields
FIELDS = rp.LinearVectorFields(M)
BODY = mechanics.rigid_body([1.0, 2.0, 3.0], sigma=0.3, theta=0.5)
MU0 = [0.0, 0.6, 0.8]


def driver(paths, steps):
    """Brownian motion with Davie's Lévy areas: path i's noise is a function of (seed, i) alone."""
    return rp.BrownianDriver(2, seed=7, dt=1.0 / steps, n_steps=steps, batch_shape=(paths,), levy_area="davie")


def ensemble(paths, steps, **kw):
    return mechanics.run_ensemble(BODY, MU0, dt=0.01, n_steps=steps, n_paths=paths, seed=11, keep_final=True, **kw)


def same_ensemble(a, b):
    """Every statistic (count, mean, scatter matrix) and every final state bitwise equal."""
    stats = [(a.final, b.final), (a.time_average, b.time_average)]
    return (np.array_equal(a.final_states, b.final_states)
            and all(x.count == y.count and np.array_equal(x.mean, y.mean) and np.array_equal(x.scatter, y.scatter)
                    for x, y in stats))


def load():
    """The 1-minute load average of this machine (what ``uptime`` prints first)."""
    return os.getloadavg()[0]


def cpu_seconds():
    """CPU seconds (user + system) used so far by the process that calls it (run on each worker)."""
    t = os.times()
    return t.user + t.system


def main():
    import distributed

    # %% [markdown]
    # ## 1. What travels to the workers
    # A task is a function and its arguments, pickled. For ``solve`` that is the vector fields, the solver,
    # one group's initial states and one group's driver; a ``BrownianDriver`` group is its seed, its path
    # indices and its time grid (``driver.select``), not its noise: each worker draws the noise of its paths
    # itself, from the same per-path streams as the serial run. A ``RoughPath`` driver travels as arrays,
    # ``d + d²`` numbers per path and step.
    # For ``run_ensemble`` a task is ``(spec, first_path, last_path)``: the system, the initial state, the
    # driver, the method and the observable, and the answer is per-path statistics, not paths.

    # %%
    paths, steps = (64, 200) if SMALL else (512, 2000)
    lazy = driver(paths, steps)
    group = lazy.select(np.arange(0, paths // 4))
    sizes = {"fields": FIELDS, "solver": rp.Davie(), "a lazy driver's group": group,
             "the same group as a RoughPath": group.rough_path()}
    for name, obj in sizes.items():
        print(f"pickled {name}: {len(pickle.dumps(obj)) / 1024:.1f} KiB")
    assert 30 * len(pickle.dumps(group)) < len(pickle.dumps(group.rough_path()))

    # %% [markdown]
    # ## 2. A local cluster: the serial run's bits
    # ``LocalCluster(processes=True)`` starts worker processes on this machine. Each worker runs one task
    # at a time on one thread here (``threads_per_worker=1``), and numba's threads in a worker are set
    # to 1 through its environment, so two workers use the two cores without oversubscribing them.
    # (The reduced run the test suite executes uses workers in this process, ``processes=False``: starting
    # worker processes and importing the library in them takes seconds. The tasks and the bits are the same.)

    # %%
    serial = rp.solve(FIELDS, lazy, np.ones(3), rp.Davie(), save_at="end")
    serial_ens = ensemble(paths, steps // 4, chunk_size=paths // 4)
    where = dict(processes=False) if SMALL else dict(processes=True, env={"NUMBA_NUM_THREADS": "1"})
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None, silence_logs=40,
                                  **where) as cluster, \
            distributed.Client(cluster) as client:
        pool = client.get_executor()
        for chunks in (3, 8):                 # 3 or 8 contiguous groups of members
            split = rp.solve(FIELDS, lazy, np.ones(3), rp.Davie(), save_at="end", executor=pool, chunks=chunks)
            print(f"solve on the local cluster, {split.stats['chunks']} groups: bitwise the serial result:",
                  np.array_equal(split.states, serial.states))
            assert np.array_equal(split.states, serial.states)
        # The groups of run_ensemble are its chunks; the seed of path i does not depend on them.
        for chunk_size in (paths // 8, paths // 2 + 3):
            dist_ens = ensemble(paths, steps // 4, chunk_size=chunk_size, executor=pool)
            print(f"run_ensemble, chunks of {chunk_size}: bitwise the serial result:",
                  same_ensemble(dist_ens, serial_ens))
            assert same_ensemble(dist_ens, serial_ens)

        # %% [markdown]
        # ## 3. A cluster given by its scheduler's address
        # A cluster started elsewhere (``dask scheduler`` on one machine, ``dask worker tcp://host:8786`` on
        # others) is reached by its address: ``Client("tcp://host:8786")``. Here the address is that of the
        # local cluster; nothing else changes. The workers need this package installed (the same version),
        # since only the arguments travel, not the code of the library.

        # %%
        address = cluster.scheduler_address
        with distributed.Client(address) as remote:
            by_address = ensemble(paths, steps // 4, chunk_size=paths // 4, executor=remote.get_executor())
            print(f"run_ensemble through Client({address!r}): bitwise the serial result:",
                  same_ensemble(by_address, serial_ens))
            assert same_ensemble(by_address, serial_ens)

            # %% [markdown]
            # ## 4. Progress on long work
            # ``progress=True`` draws a bar on standard error (``tqdm`` if installed, else one line updated in
            # place); a callable receives ``ProgressRecord(done, total, elapsed, eta)``. ``run_ensemble``
            # reports per chunk, in paths; ``solve`` per block of steps (per group with an executor), in
            # member-steps; an adaptive solve per accepted step, in time reached. The numbers do not change.

            # %%
            seen = []
            watched = ensemble(paths, steps // 4, chunk_size=paths // 4, executor=remote.get_executor(),
                               progress=seen.append)
            for r in seen:
                print(f"  {r.done:4.0f}/{r.total:.0f} paths after {r.elapsed:5.2f} s, about {r.eta:5.2f} s left")
            assert same_ensemble(watched, serial_ens) and seen[-1].done == paths and seen[-1].eta == 0.0

        # %% [markdown]
        # ## 5. Speed-up on two cores
        # Wall times of the same work, serial (numba on one thread and on two) and on the two-worker cluster,
        # after a warm-up run that loads the compiled kernels in every worker; the best of three rounds, the
        # three ways interleaved. Beside them the CPU time used (this process serially; the workers' on the
        # cluster) and the load average: other work on the same cores slows every column, and when the load
        # exceeds the cores, two workers get less than two cores. ``solve`` with vector fields written in
        # numpy pays a fixed cost per step and per call, whatever the number of paths: every group pays it
        # again, so few large groups (one per worker) are the cheap cut; compare 2 and 16 groups.

        # %%
        if not SMALL:
            import numba

            def workers_cpu():
                return sum(client.run(cpu_seconds).values())

            def measure(fn, cpu):
                c0, w0 = cpu(), time.perf_counter()
                fn()
                return time.perf_counter() - w0, cpu() - c0

            big = driver(2048, steps)
            jobs = {
                f"solve, 2048 paths x {steps} steps (Davie, linear fields), 2 groups": (
                    lambda **kw: rp.solve(FIELDS, big, np.ones(3), rp.Davie(), save_at="end", **kw),
                    dict(executor=pool, chunks=2)),
                f"solve, 2048 paths x {steps} steps (Davie, linear fields), 16 groups": (
                    lambda **kw: rp.solve(FIELDS, big, np.ones(3), rp.Davie(), save_at="end", **kw),
                    dict(executor=pool, chunks=16)),
                f"run_ensemble, 16384 paths x {steps} steps (rigid body, LieHeun), 8 chunks": (
                    lambda **kw: ensemble(16384, steps, **kw), dict(executor=pool, chunk_size=2048)),
            }
            threads = numba.get_num_threads()
            for name, (job, spread) in jobs.items():
                job(**spread)                                    # warm-up: every worker loads its kernels
                best = {}
                for _ in range(3):
                    numba.set_num_threads(1)
                    runs = {"serial, 1 thread": measure(job, time.process_time)}
                    numba.set_num_threads(threads)
                    runs[f"serial, {threads} threads"] = measure(job, time.process_time)
                    runs["cluster, 2 workers"] = measure(lambda: job(**spread), workers_cpu)
                    for key, (wall, cpu) in runs.items():
                        best[key] = min(best.get(key, (np.inf, 0.0)), (wall, cpu))
                print(f"{name} (load average {load():.1f}):")
                for key, (wall, cpu) in best.items():
                    print(f"  {key:20s} wall {wall:6.2f} s, CPU {cpu:6.2f} s, "
                          f"speed-up {best['serial, 1 thread'][0] / wall:.2f}x")

if __name__ == "__main__":      # the cluster's worker processes import this file again: run only once
    main()
