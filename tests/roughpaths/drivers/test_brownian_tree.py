"""BrownianTree: Chen across subdivisions, order independence, bounded cache, Brownian law deep in the tree.

Oracles: Chen's identity written out here (``XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t}``); the
exact laws N(0, h) of the increment and Lévy's law of the d = 2 area, whose characteristic function is
``1/cosh(λh/2)`` (CDF of ``A/h``: ``(2/π) arctan(exp(π a))``, variance 1/4, fourth moment 5/16).
"""

import numpy as np
import pytest
from scipy import stats

import roughpaths as rp



def _sech_cdf(a):
    return 2.0 / np.pi * np.arctan(np.exp(np.pi * a))


@pytest.mark.parametrize("dim", [2, 3])
def test_chen_holds_across_random_subdivisions(dim):
    tree = rp.BrownianTree(dim, seed=5, t0=-0.5, t1=2.0, batch_shape=(3, 2))
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(12):
        s, u, t = np.sort(rng.uniform(-0.5, 2.0, 3))
        x1, xx1 = tree.increment(s, u), tree.area(s, u)
        x2, xx2 = tree.increment(u, t), tree.area(u, t)
        x, xx = tree.increment(s, t), tree.area(s, t)
        assert x.shape == (3, 2, dim) and xx.shape == (3, 2, dim, dim)
        worst = max(worst, np.abs(x - x1 - x2).max(),
                    np.abs(xx - (xx1 + xx2 + x1[..., :, None] * x2[..., None, :])).max())
    assert worst < 1e-12
    # geometric: Sym(XX) = ½ X ⊗ X, and the Lévy area is Alt(XX)
    assert np.allclose(xx + np.swapaxes(xx, -1, -2), x[..., :, None] * x[..., None, :], atol=1e-13)
    assert np.allclose(tree.levy_area(s, t), 0.5 * (xx - np.swapaxes(xx, -1, -2)), atol=1e-14)


def test_answers_do_not_depend_on_query_order_or_cache():
    rng = np.random.default_rng(2)
    queries = [tuple(np.sort(rng.uniform(0, 1, 2))) for _ in range(8)]
    a = rp.BrownianTree(2, seed=9, batch_shape=(4,))
    first = [(a.increment(s, t), a.area(s, t)) for s, t in queries]
    b = rp.BrownianTree(2, seed=9, batch_shape=(4,), cache_size=0)          # recomputes from the root
    for s, t in rng.uniform(0, 1, (5, 2)):
        b.area(min(s, t), max(s, t))                                          # unrelated earlier queries
    second = [(b.increment(s, t), b.area(s, t)) for s, t in reversed(queries)][::-1]
    for (x, xx), (y, yy) in zip(first, second):
        assert np.array_equal(x, y) and np.array_equal(xx, yy)
    # a member's path depends on its index only, not on the batch it is drawn with
    c = rp.BrownianTree(2, seed=9, batch_shape=(2,))
    assert np.array_equal(c.area(*queries[0]), first[0][1][:2])
    assert not np.array_equal(rp.BrownianTree(2, seed=10, batch_shape=(4,)).area(*queries[0]), first[0][1])


def test_cache_stays_bounded():
    tree = rp.BrownianTree(2, seed=0, batch_shape=(2,), cache_size=40, resolution=30)
    rng = np.random.default_rng(3)
    for _ in range(60):
        s, t = np.sort(rng.uniform(0, 1, 2))
        tree.area(s, t)
        assert tree.cached_nodes <= 40
    assert tree.cached_nodes == 40
    default = rp.BrownianTree(2, seed=0, batch_shape=(20000,))
    assert 2 <= default.cache_size and default.cache_size * default.node_bytes <= 2 ** 26


def test_rough_path_on_a_grid_matches_the_queries():
    tree = rp.BrownianTree(2, seed=4, batch_shape=(3,))
    times = np.array([0.0, 0.1, 0.37, 0.5, 0.93, 1.0])
    X = tree.rough_path(times)
    assert X.increments.shape == (3, 5, 2) and X.kind == "geometric"
    for k in range(5):
        assert np.array_equal(X.increments[:, k], tree.increment(times[k], times[k + 1]))
        assert np.allclose(X.areas[:, k], tree.area(times[k], times[k + 1]), atol=1e-15)
    assert np.allclose(X.area(0.1, 0.93), tree.area(0.1, 0.93), atol=1e-12)     # RoughPath's own Chen


def test_one_dimension_and_scalar_batch():
    tree = rp.BrownianTree(1, seed=1)
    x, xx = tree.increment(0.2, 0.9), tree.area(0.2, 0.9)
    assert x.shape == (1,) and xx.shape == (1, 1)
    assert np.isclose(xx[0, 0], 0.5 * x[0] ** 2, atol=1e-15) and tree.levy_area(0.2, 0.9)[0, 0] == 0.0
    assert np.array_equal(tree.increment(0.3, 0.3), np.zeros(1))


def _law_checks(P, seed):
    tree = rp.BrownianTree(2, seed=seed, batch_shape=(P,))
    s, t = 0.61803, 0.61803 + 1.5e-3                       # non-dyadic, about depth 9.4
    h = t - s
    x = tree.increment(s, t)
    a = tree.levy_area(s, t)[:, 0, 1] / h
    assert stats.kstest(x.ravel() / np.sqrt(h), "norm").pvalue > 1e-3
    assert stats.kstest(a, _sech_cdf).pvalue > 1e-3
    for k, value in ((2, 0.25), (4, 5.0 / 16.0)):
        m = a ** k
        assert abs(m.mean() - value) < 4 * m.std() / np.sqrt(P), (k, m.mean(), value)
    y = tree.increment(0.3, s)                              # independent increments
    prod = (x * y).sum(axis=1) / np.sqrt(h * (s - 0.3))
    assert abs(prod.mean()) < 4 * prod.std() / np.sqrt(P)


def test_law_on_a_short_nondyadic_interval():
    _law_checks(4000, seed=21)


@pytest.mark.slow
def test_law_on_a_short_nondyadic_interval_full():
    _law_checks(20000, seed=22)


@pytest.mark.slow
@pytest.mark.parametrize("m", [2, 3])
def test_area_law_error_does_not_grow_with_depth(m):
    P = 20000
    tree = rp.BrownianTree(2, seed=30 + m, batch_shape=(P,), polygon_levels=m, cache_size=64)
    ks = {}
    for depth in (1, 5, 10, 20):
        h = 2.0 ** -depth
        j = int(0.61803 / h)
        a = tree.levy_area(j * h, (j + 1) * h)[:, 0, 1] / h
        ks[depth] = stats.kstest(a, _sech_cdf).statistic
    noise = 1.63 / np.sqrt(P)                              # the 1 % point of the KS statistic
    assert max(ks.values()) < noise, ks
    assert ks[20] < ks[1] + 0.5 * noise, ks


def test_bad_input_is_refused_with_the_fix():
    with pytest.raises(ValueError, match="t1"):
        rp.BrownianTree(2, seed=0, t0=1.0, t1=1.0)
    with pytest.raises(ValueError, match="levy_area"):
        rp.BrownianTree(2, seed=0, levy_area=None)
    with pytest.raises(ValueError, match="levy_area"):
        rp.BrownianTree(2, seed=0, levy_area="nope")
    with pytest.raises(ValueError, match="exact"):
        rp.BrownianTree(3, seed=0, levy_area="exact")
    with pytest.raises(ValueError, match="polygon_levels"):
        rp.BrownianTree(2, seed=0, polygon_levels=9)
    with pytest.raises(ValueError, match="resolution"):
        rp.BrownianTree(2, seed=0, resolution=63)
    with pytest.raises(TypeError, match="seed"):
        rp.BrownianTree(2, seed=np.random.default_rng(0))
    tree = rp.BrownianTree(2, seed=0)
    with pytest.raises(ValueError, match="swap"):
        tree.area(0.5, 0.2)
    with pytest.raises(ValueError, match=r"\[t0, t1\]"):
        tree.increment(0.5, 1.5)
    with pytest.raises(TypeError, match="s must be a real number"):
        tree.increment("a", 0.5)
    with pytest.raises(ValueError, match="strictly increasing"):
        tree.rough_path([0.0, 0.5, 0.5])


@pytest.mark.parametrize("dim", [2, 3])
def test_conditional_area_variance_given_the_increment(dim):
    """Lévy: ``E[A_ij² | W] = (h² + h (W_i² + W_j²)) / 12`` on a non-dyadic interval; pairs uncorrelated."""
    P = 3000
    tree = rp.BrownianTree(dim, seed=40 + dim, batch_shape=(P,))
    s, t = 0.2, 0.2 + 0.0123
    h = t - s
    x, a = tree.increment(s, t), tree.levy_area(s, t)
    for i, j in [(0, 1), (1, 2)][:dim - 1]:
        r = (a[:, i, j] ** 2 - (h * h + h * (x[:, i] ** 2 + x[:, j] ** 2)) / 12.0) / h ** 2
        assert abs(r.mean()) < 4 * r.std() / np.sqrt(P), (i, j, r.mean())
    if dim == 3:
        c = a[:, 0, 1] * a[:, 0, 2] / h ** 2
        assert abs(c.mean()) < 4 * c.std() / np.sqrt(P)


def test_compiled_split_matches_the_numpy_reference_and_keeps_chen():
    from roughpaths.drivers._tree_kernels import (polygon_area, reduce_node, refine_segments, refine_segments_fast,
                                                  split_width)

    rng = np.random.default_rng(6)
    for d, n in ((2, 1), (2, 8), (3, 4)):
        w = rng.standard_normal((50, n, d)) * 0.3
        g = rng.standard_normal((50, d, d)) * 0.05
        G = g - np.swapaxes(g, 1, 2)
        z = rng.standard_normal((50, split_width(n, d)))
        ref, fast = refine_segments(w, G, 0.1, z), refine_segments_fast(w, G, 0.1, z)
        for u, v in zip(ref, fast):
            assert np.allclose(u, v, rtol=0, atol=1e-14)
        fine, GL, GR = fast
        assert np.allclose(fine[:, 0::2] + fine[:, 1::2], w, atol=1e-15)
        # Chen, written out: the parent's Lévy area from its polygon and tail, against the children's
        naive = lambda seg: 0.5 * sum(np.einsum("pi,pj->pij", seg[:, k], seg[:, l]) - np.einsum(
            "pi,pj->pij", seg[:, l], seg[:, k]) for k in range(seg.shape[1]) for l in range(k + 1, seg.shape[1]))
        parent = (naive(w) if n > 1 else 0.0) + G
        assert np.allclose(naive(fine) + GL + GR, parent, atol=1e-14)
        assert np.allclose(polygon_area(fine), naive(fine), atol=1e-15)
        W, A = reduce_node(fine[:, n:], GR)                               # a non-contiguous view, as cached
        assert np.allclose(W, fine[:, n:].sum(axis=1), atol=1e-15)
        assert np.allclose(A, naive(fine[:, n:]) + GR, atol=1e-15)


@pytest.mark.parametrize("dim", [2, 3])
def test_select_answers_bitwise_as_the_selected_members(dim):
    tree = rp.BrownianTree(dim, seed=21, batch_shape=(2, 3))
    sub = tree.select([4, 0, -1])
    grid = np.array([0.0, 0.1234, 0.5, 0.71, 1.0])
    W, A = tree.increments_and_levy_areas(grid)
    w, a = sub.increments_and_levy_areas(grid)
    flat_W, flat_A = W.reshape(6, 4, dim), A.reshape(6, 4, dim, dim)
    assert np.array_equal(w, flat_W[[4, 0, 5]]) and np.array_equal(a, flat_A[[4, 0, 5]])
    assert np.array_equal(sub.area(0.3, 0.31), tree.area(0.3, 0.31).reshape(6, dim, dim)[[4, 0, 5]])
    assert sub.batch_shape == (3,)
    with pytest.raises(ValueError, match="outside"):
        tree.select([6])
    with pytest.raises(TypeError, match="integer"):
        tree.select([0.5])


def test_per_path_queries_reach_t1_where_t0_plus_the_span_rounds_below_it():
    """On [1.35, 7.21], 1.35 + (7.21 - 1.35) rounds below 7.21: per-path times (the adaptive steps' walk) are
    checked against [t0, t1] itself, so a query ending at t1 is answered (its increments add up to the whole
    interval's) and one past t1 is still refused."""
    t0, t1 = 1.35, 7.21
    assert t0 + (t1 - t0) < t1
    tree = rp.BrownianTree(2, seed=0, t0=t0, t1=t1, batch_shape=(2,))
    W, _ = tree.increments_and_areas([[t0, 4.0, t1], [t0, 2.5, t1]], [0, 1])
    whole, _ = tree.increments_and_levy_areas([t0, t1])
    np.testing.assert_allclose(W.sum(axis=1), whole[:, 0], rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match=r"times must increase strictly in \[t0, t1\]"):
        tree.increments_and_areas([[t0, 4.0, np.nextafter(t1, np.inf)], [t0, 2.5, t1]], [0, 1])


def test_per_path_queries_walked_on_threads_answer_each_row_as_alone():
    """A per-path query of 300 rows is walked in ranges on numba's threads: every row's answer is bitwise its
    answer asked alone (the naive route, one query per row), whatever the thread count; a bad row in a late range
    is named by its own index."""
    numba = pytest.importorskip("numba")
    from roughpaths.drivers import _tree_members

    P = 300
    tree = rp.BrownianTree(3, seed=5, batch_shape=(P,))
    rng = np.random.default_rng(1)
    cell = 2.0 ** -tree.resolution
    a = rng.uniform(0.0, 0.8, P)
    h = rng.uniform(0.01, 0.1, P)
    times = np.round(np.stack([a, a + h / 2, a + h], axis=1) / cell) * cell
    rows = np.arange(P)
    assert len(_tree_members._walk_parts(P, 2, rows)) > 1          # the query is split
    before = numba.get_num_threads()
    try:
        answers = []
        for threads in (1, numba.config.NUMBA_NUM_THREADS):
            numba.set_num_threads(threads)
            answers.append(rp.BrownianTree(3, seed=5, batch_shape=(P,)).increments_and_areas(times, rows))
    finally:
        numba.set_num_threads(before)
    alone = rp.BrownianTree(3, seed=5, batch_shape=(P,))
    for k in range(0, P, 23):
        w, xx = alone.increments_and_areas(times[k:k + 1], [k])
        for W, XX in answers:
            assert np.array_equal(W[k], w[0]) and np.array_equal(XX[k], xx[0])
    assert all(np.array_equal(x, y) for x, y in zip(answers[0], answers[1]))
    bad = times.copy()
    bad[250, 2] = bad[250, 1]
    with pytest.raises(ValueError, match="row 250 is"):
        tree.increments_and_areas(bad, rows)
