r"""The Brownian driver's random stream is a function of (seed, path index, area method) only.

Claims tested (``roughpaths.BrownianDriver``):

* **Stream definition**, against plain numpy: path ``i``'s increments are the normals of
  ``Generator(PCG64(SeedSequence(seed, spawn_key=(i, 0))))`` times ``√h``, and its areas are
  built, by a naive per-step reimplementation written here, from the normals of the stream
  ``(i, 1)`` (bridge, space-time and Davie normals per step, in this order);
* **invariance**: the same bits whatever the block size, the subset of paths generated together
  (``select``), the order of the subset, or the process (a process pool);
* increments do not depend on the area method, substeps or kind;
* the numba streams equal the numpy fallback; bad arguments raise naming the argument.
"""

from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from roughpaths import BrownianDriver, RoughPath, solve
from roughpaths.drivers._random import PathStreams, standard_normal_into


def _gen(seed, key):
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=key)))


def _naive_areas(W, h, z_all, m, davie, ito):
    """Per-step loop: W (N, d), h (N,), z_all the area normals of one path (flat)."""
    N, d = W.shape
    out = np.empty((N, d, d))
    pos = 0
    for k in range(N):
        delta = h[k] / m
        if m > 1:
            z = z_all[pos:pos + m * d].reshape(m, d)
            pos += m * d
            w = np.sqrt(delta) * (z - z.mean(axis=0)) + W[k] / m
        else:
            w = W[k][None, :]
        H = np.sqrt(delta / 12.0) * z_all[pos:pos + m * d].reshape(m, d)
        pos += m * d
        A = np.zeros((d, d))
        for a in range(m):
            A += np.outer(H[a], w[a]) - np.outer(w[a], H[a])
            for b in range(a + 1, m):
                A += 0.5 * (np.outer(w[a], w[b]) - np.outer(w[b], w[a]))
        if davie:
            iu = np.triu_indices(d, 1)
            lam = z_all[pos:pos + iu[0].size] * h[k] / np.sqrt(12.0 * m)
            pos += iu[0].size
            A[iu] += lam
            A[iu[1], iu[0]] -= lam
        out[k] = A + 0.5 * np.outer(W[k], W[k]) - (0.5 * h[k] * np.eye(d) if ito else 0.0)
    return out, pos


def _sub(method, m):
    """substeps is refused for methods it does not apply to."""
    return m if method in ("davie", "foster") else None


@pytest.mark.parametrize("method, m, kind", [("davie", 1, "stratonovich"), ("foster", 3, "stratonovich"),
                                             ("davie", 2, "ito"), (None, 1, "stratonovich")])
def test_stream_definition_against_numpy(method, m, kind):
    times = np.array([0.0, 0.1, 0.35, 0.4, 1.0, 1.5])
    d, seed = 3, 2024
    drv = BrownianDriver(d, seed=seed, times=times, batch_shape=(2, 2), levy_area=method, substeps=_sub(method, m),
                         kind=kind)
    X = drv.rough_path()
    h = np.diff(times)
    for i in range(4):
        W = _gen(seed, (i, 0)).standard_normal((5, d)) * np.sqrt(h)[:, None]
        np.testing.assert_array_equal(X.increments.reshape(4, 5, d)[i], W)
        if method is None:
            assert X.areas is None
            continue
        n_area = 5 * ((m * d if m > 1 else 0) + m * d + (3 if method == "davie" else 0))
        ref, used = _naive_areas(W, h, _gen(seed, (i, 1)).standard_normal(n_area), m, method == "davie",
                                 kind == "ito")
        assert used == n_area
        np.testing.assert_allclose(X.areas.reshape(4, 5, d, d)[i], ref, rtol=1e-12, atol=1e-15)
    assert X.kind == (None if method is None else ("geometric" if kind == "stratonovich" else "ito"))


@pytest.mark.parametrize("method, m", [("davie", 1), ("davie", 4), ("foster", 1), ("foster", 3), ("exact", 1),
                                       (None, 1)])
def test_bitwise_invariant_under_blocks_and_selection(method, m):
    drv = BrownianDriver(2, seed=np.random.SeedSequence(99), dt=0.01, n_steps=23, batch_shape=(3, 4),
                         levy_area=method, substeps=_sub(method, m))
    X = drv.rough_path()
    flat_inc = X.increments.reshape(12, 23, 2)
    for K in (1, 5, 23, 100):
        blocks = list(drv.blocks(K))
        assert [b.times[0] for b in blocks] == list(drv.times[::K][:len(blocks)])
        np.testing.assert_array_equal(np.concatenate([b.increments for b in blocks], axis=-2), X.increments)
        if method is not None:
            np.testing.assert_array_equal(np.concatenate([b.areas for b in blocks], axis=-3), X.areas)
        # each block starts where the previous one ended
        for b0, b1 in zip(blocks, blocks[1:]):
            np.testing.assert_allclose(b1.x0, b0.x0 + b0.increments.sum(axis=-2), atol=1e-14)
    for paths in ([7, 0, 11], slice(2, 9, 3), range(5, 12), np.array([-1])):
        sub = drv.select(paths)
        idx = np.arange(12)[paths] if not isinstance(paths, np.ndarray) else np.array([11])
        Y = sub.rough_path()
        assert sub.batch_shape == (idx.size,)
        np.testing.assert_array_equal(Y.increments, flat_inc[idx])
        if method is not None:
            np.testing.assert_array_equal(Y.areas, X.areas.reshape(12, 23, 2, 2)[idx])
    # select of a select keys the original indices
    np.testing.assert_array_equal(drv.select([5, 6, 7]).select([2]).rough_path().increments, flat_inc[[7]])


def test_increments_do_not_depend_on_area_options_or_kind():
    base = BrownianDriver(3, seed=5, dt=0.1, n_steps=6, batch_shape=(2,), levy_area=None).rough_path()
    for kw in (dict(levy_area="davie"), dict(levy_area="foster", substeps=5), dict(kind="ito")):
        X = BrownianDriver(3, seed=5, dt=0.1, n_steps=6, batch_shape=(2,), **kw).rough_path()
        np.testing.assert_array_equal(X.increments, base.increments)
    other = BrownianDriver(3, seed=6, dt=0.1, n_steps=6, batch_shape=(2,), levy_area=None).rough_path()
    assert not np.array_equal(other.increments, base.increments)


def _chunk(args):
    drv, lo, hi = args
    return drv.select(range(lo, hi)).rough_path().areas


def test_process_pool_gives_the_serial_bits():
    drv = BrownianDriver(3, seed=31, dt=0.02, n_steps=17, batch_shape=(10,), levy_area="foster", substeps=2)
    with ProcessPoolExecutor(2) as ex:
        parts = list(ex.map(_chunk, [(drv, 0, 4), (drv, 4, 7), (drv, 7, 10)]))
    np.testing.assert_array_equal(np.concatenate(parts), drv.rough_path().areas)


def test_solve_consumes_the_driver_like_its_rough_path():
    from roughpaths import Davie, LinearVectorFields
    rng = np.random.default_rng(0)
    fields = LinearVectorFields(0.3 * rng.standard_normal((2, 2, 2)))
    drv = BrownianDriver(2, seed=3, dt=0.01, n_steps=40, batch_shape=(5,))
    a = solve(fields, drv, np.ones(2), Davie(), block_steps=7)
    b = solve(fields, drv.rough_path(), np.ones(2), Davie())
    np.testing.assert_array_equal(a.states, b.states)
    assert a.stats["n_blocks"] == 6


def test_numba_streams_equal_numpy_fallback_and_raw_normals_equal_numpy():
    ss = np.random.SeedSequence([3, 2**40 + 1], spawn_key=(4,))
    keys = np.array([[0, 1], [17, 0], [2**31, 1]])
    fast, slow = PathStreams(ss, keys), PathStreams(ss, keys, _force_numpy=True)
    a, b = np.empty((3, 5001)), np.empty((3, 5001))
    fast.fill(a[:, :2000])
    fast.fill(a[:, 2000:])
    slow.fill(b)
    np.testing.assert_array_equal(a, b)
    g = _gen([3, 2**40 + 1], (4, 17, 0))
    np.testing.assert_array_equal(a[1], g.standard_normal(5001))
    for bg in (np.random.PCG64, np.random.SFC64, np.random.MT19937):
        r1, r2 = np.random.Generator(bg(8)), np.random.Generator(bg(8))
        out = np.empty((7, 1001))
        standard_normal_into(r1, out)
        np.testing.assert_array_equal(out, r2.standard_normal((7, 1001)))
        assert r1.random() == r2.random()           # same end state


@pytest.mark.parametrize("kw, exc, word", [
    (dict(seed=np.random.default_rng(0), dt=0.1, n_steps=3), TypeError, "seed"),
    (dict(seed=-1, dt=0.1, n_steps=3), ValueError, "seed"),
    (dict(seed=1.5, dt=0.1, n_steps=3), TypeError, "seed"),
    (dict(seed=1), ValueError, "times"),
    (dict(seed=1, dt=0.1), ValueError, "n_steps"),
    (dict(seed=1, dt=0.1, n_steps=3, times=[0, 1]), ValueError, "times"),
    (dict(seed=1, dt=-0.1, n_steps=3), ValueError, "dt"),
    (dict(seed=1, dt=0.1, n_steps=0), ValueError, "n_steps"),
    (dict(seed=1, times=[0.0, 0.5, 0.5]), ValueError, "times"),
    (dict(seed=1, dt=0.1, n_steps=3, levy_area="wiktorson"), ValueError, "levy_area"),
    (dict(seed=1, dt=0.1, n_steps=3, substeps=0), ValueError, "substeps"),
    (dict(seed=1, dt=0.1, n_steps=3, kind="strat"), ValueError, "kind"),
    (dict(seed=1, dt=0.1, n_steps=3, batch_shape=(-2,)), ValueError, "batch_shape"),
    (dict(seed=1, dt=0.1, n_steps=3, batch_shape=(2,), x0=np.zeros((3, 2))), ValueError, "x0"),
])
def test_bad_arguments_name_the_argument(kw, exc, word):
    with pytest.raises(exc, match=word):
        BrownianDriver(2, **kw)


def test_sizes_are_checked_before_allocating():
    # ~10^17 bytes of path on a grid of 10^5 steps (a 10^9-step grid alone would take 16 GB here)
    drv = BrownianDriver(3, seed=0, dt=1e-9, n_steps=10**5, batch_shape=(10**10,))
    with pytest.raises(ValueError, match="GiB"):
        drv.rough_path()
    huge = BrownianDriver(3, seed=0, dt=0.1, n_steps=2, batch_shape=(10**14,))
    with pytest.raises(ValueError, match="fewer paths"):
        next(huge.blocks())
    with pytest.raises(ValueError, match="paths"):
        BrownianDriver(2, seed=0, dt=0.1, n_steps=2, batch_shape=(3,)).select([0, 3])
    with pytest.raises(TypeError, match="paths"):
        BrownianDriver(2, seed=0, dt=0.1, n_steps=2, batch_shape=(3,)).select([0.5])
    with pytest.raises(ValueError, match="max_steps"):
        next(BrownianDriver(2, seed=0, dt=0.1, n_steps=2).blocks(0))


@pytest.mark.parametrize("method, m", [("davie", 2), (None, 1)])
def test_numpy_fallback_driver_gives_the_same_bits(monkeypatch, method, m):
    import roughpaths.drivers._random as rnd
    kw = dict(seed=12, dt=0.1, n_steps=9, batch_shape=(3,), levy_area=method, substeps=_sub(method, m))
    fast = BrownianDriver(2, **kw).rough_path()
    monkeypatch.setattr(rnd, "_FAST_OK", [False])
    slow_blocks = list(BrownianDriver(2, **kw).blocks(4))
    np.testing.assert_array_equal(np.concatenate([b.increments for b in slow_blocks], axis=-2), fast.increments)
    if method is not None:
        np.testing.assert_array_equal(np.concatenate([b.areas for b in slow_blocks], axis=-3), fast.areas)


def test_one_shot_wrappers_sample_the_driver_stream():
    from roughpaths import brownian_increments_and_areas, brownian_rough_path
    times = [0.0, 0.3, 0.5, 1.0]
    X = brownian_rough_path(times, 2, 17, batch_shape=(3,), levy_area="foster", substeps=2)
    Y = BrownianDriver(2, seed=17, times=times, batch_shape=(3,), levy_area="foster", substeps=2).rough_path()
    np.testing.assert_array_equal(X.areas, Y.areas)
    rng, twin = np.random.default_rng(5), np.random.default_rng(5)
    dW, XX = brownian_increments_and_areas(rng, 4, 0.25, 3, batch_shape=(2,))
    seed = np.random.SeedSequence([int(v) for v in twin.integers(0, 2**63, size=2, dtype=np.int64)])
    Z = BrownianDriver(3, seed=seed, dt=0.25, n_steps=4, batch_shape=(2,)).rough_path()
    np.testing.assert_array_equal(dW, Z.increments)
    np.testing.assert_array_equal(XX, Z.areas)
    assert rng.random() == twin.random()           # the wrapper advanced rng by exactly two draws


def test_error_controlled_methods_refuse_substeps_and_other_methods_refuse_an_error_target():
    with pytest.raises(ValueError, match="levy_area_error"):
        BrownianDriver(2, seed=1, dt=0.1, n_steps=3, levy_area="mrongowius-rossler", substeps=4)
    with pytest.raises(ValueError, match="levy_area_error applies"):
        BrownianDriver(2, seed=1, dt=0.1, n_steps=3, levy_area="davie", levy_area_error=1e-3)


# numpy's own seeding (a small batch) and the seeding kernel, on one-word keys and on keys past 2^32 (the
# kernel's row-by-row branch)
@pytest.mark.parametrize("first", [0, 2**33 + 5])
@pytest.mark.parametrize("n_keys", [3, 40])
def test_stream_states_are_numpy_pcg64_states(n_keys, first):
    ss = np.random.SeedSequence(2**70 + 9, spawn_key=(5,))
    keys = np.stack([first + np.arange(n_keys) * 7919, np.arange(n_keys) % 3], axis=1)
    states = PathStreams(ss, keys).states
    for j in (0, n_keys // 2, n_keys - 1):
        st = np.random.PCG64(np.random.SeedSequence(2**70 + 9, spawn_key=(5, *map(int, keys[j])))).state["state"]
        got = [int(v) for v in states[j]]
        assert (got[0] << 64) | got[1] == st["state"] and (got[2] << 64) | got[3] == st["inc"]
