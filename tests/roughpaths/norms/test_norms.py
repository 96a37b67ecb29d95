"""Hölder and p-variation norms of rough paths, and the inhomogeneous Hölder distance.

Claims tested (``roughpaths.norms``):

* on a linear path ``t ↦ t v`` on ``[0, T]``: ``‖X‖_α = |v| T^{1-α}``, ``‖XX‖_{2α} = ½|v|² T^{2-2α}``
  (Frobenius), ``‖X‖_{p-var} = |v| T`` and ``‖XX‖_{p/2-var} = ½|v|² T²`` for every ``p >= 1``;
* on an L-shaped path the level-2 quantities equal a brute force over all pairs using the closed
  form of ``XX_{s,t}`` (which has the off-diagonal area ``(1-s)(t-1)`` in entry [0, 1] only);
* the exact p-variation equals the maximum over *all* partitions enumerated naively (random paths,
  several ``p``), with and without pruning, and hits the known optimum on zig-zag paths;
* Hölder quantities equal a naive double loop over pairs using the iterated-sum definition of the
  area (not Chen's identity);
* ``ρ_α(X, X) = 0``, symmetry, triangle inequality, ``ρ_α(X, X.perturb(s)) = |s|_F sup (t-s)^{1-2α}``;
* batching, array input and invalid arguments.
"""

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from roughpaths import (area_holder_seminorm, area_p_variation, holder_distance,
                              holder_seminorm, p_variation, rough_path_holder_norm,
                              rough_path_p_variation)
from _oracles import naive_area
from roughpaths import RoughPath


# ----------------------------------------------------------------------------- naive oracles


def naive_holder(inc, areas, times, alpha):
    n = inc.shape[0]
    m1 = m2 = 0.0
    for i in range(n):
        for j in range(i + 1, n + 1):
            h = times[j] - times[i]
            m1 = max(m1, np.linalg.norm(inc[i:j].sum(0)) / h ** alpha)
            if areas is not None:
                m2 = max(m2, np.linalg.norm(naive_area(inc, areas, i, j)) / h ** (2 * alpha))
    return m1, m2


def all_partitions(npts):
    """Every partition 0 = k_0 < ... < k_m = npts - 1 as a list of indices."""
    inner = range(1, npts - 1)
    for r in range(npts - 1):
        for comb in itertools.combinations(inner, r):
            yield (0,) + comb + (npts - 1,)


def brute_pvar(path, p):
    return max(sum(np.linalg.norm(path[b] - path[a]) ** p for a, b in zip(k[:-1], k[1:]))
               for k in all_partitions(path.shape[0])) ** (1 / p)


def brute_area_pvar(inc, areas, p):
    return max(sum(np.linalg.norm(naive_area(inc, areas, a, b)) ** (p / 2) for a, b in zip(k[:-1], k[1:]))
               for k in all_partitions(inc.shape[0] + 1)) ** (2 / p)


def random_general_path(rng, n, d, batch=()):
    """Random increments and random (non-geometric) areas on a random non-uniform grid."""
    inc = rng.standard_normal(batch + (n, d))
    areas = rng.standard_normal(batch + (n, d, d))
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 1.0, n))])
    return RoughPath(inc, areas, times=times, kind="general")


# ----------------------------------------------------------------------------- linear path
@pytest.mark.parametrize("uniform", [True, False])
def test_linear_path_closed_forms(rng, uniform):
    v, T = np.array([3.0, -4.0, 12.0]), 2.5          # |v| = 13
    t = np.linspace(0, T, 41) if uniform else np.sort(np.concatenate([[0, T], rng.uniform(0, T, 39)]))
    X = RoughPath.from_path(np.outer(t, v), times=t)
    for alpha in (0.3, 0.5, 0.75, 1.0):
        assert holder_seminorm(X, alpha) == pytest.approx(13 * T ** (1 - alpha), rel=1e-12)
        assert holder_seminorm(X.path, alpha, times=t) == pytest.approx(13 * T ** (1 - alpha), rel=1e-12)
        assert area_holder_seminorm(X, alpha) == pytest.approx(0.5 * 169 * T ** (2 - 2 * alpha), rel=1e-12)
        assert rough_path_holder_norm(X, alpha) == pytest.approx(
            13 * T ** (1 - alpha) + np.sqrt(0.5 * 169) * T ** (1 - alpha), rel=1e-12)
    for p in (1.0, 1.5, 2.0, 2.5, 7.0):
        assert p_variation(X, p) == pytest.approx(13 * T, rel=1e-12)
        assert area_p_variation(X, p) == pytest.approx(0.5 * 169 * T ** 2, rel=1e-12)
        assert rough_path_p_variation(X, p) == pytest.approx(13 * T + np.sqrt(0.5 * 169) * T, rel=1e-12)
        val, mask = p_variation(X, p, return_partition=True)
        if p > 1:   # strictly superadditive: the single interval is the unique optimum
            assert mask.sum() == 2 and mask[0] and mask[-1]


# ----------------------------------------------------------------------------- L-shaped path
def l_shape_area(s, t):
    """Closed form XX_{s,t} of the path (0,0) -> (1,0) -> (1,1) at unit speed, s <= t in [0, 2]."""
    if t <= 1:
        return np.array([[0.5 * (t - s) ** 2, 0.0], [0.0, 0.0]])
    if s >= 1:
        return np.array([[0.0, 0.0], [0.0, 0.5 * (t - s) ** 2]])
    a, b = 1 - s, t - 1
    return np.array([[0.5 * a * a, a * b], [0.0, 0.5 * b * b]])


def test_l_shape_area_norms():
    m = 5
    t = np.linspace(0.0, 2.0, 2 * m + 1)
    pts = np.where(t[:, None] <= 1, np.stack([t, 0 * t], 1), np.stack([np.ones_like(t), t - 1], 1))
    X = RoughPath.from_path(pts, times=t)
    assert np.allclose(X.area(0.0, 2.0), [[0.5, 1.0], [0.0, 0.5]])
    for alpha in (0.35, 0.5, 0.9):
        want = max(np.linalg.norm(l_shape_area(t[i], t[j])) / (t[j] - t[i]) ** (2 * alpha)
                   for i in range(t.size) for j in range(i + 1, t.size))
        assert area_holder_seminorm(X, alpha) == pytest.approx(want, rel=1e-12)
    for p in (2.0, 2.5, 3.0):
        want = max(sum(np.linalg.norm(l_shape_area(t[a], t[b])) ** (p / 2) for a, b in zip(k[:-1], k[1:]))
                   for k in all_partitions(t.size)) ** (2 / p)
        assert area_p_variation(X, p) == pytest.approx(want, rel=1e-12)


# ----------------------------------------------------------------------------- zig-zags
def test_zigzag_1d_all_points_optimal():
    a, n = 0.7, 9
    x = (a * (np.arange(n + 1) % 2))[:, None]          # 0, a, 0, a, ...
    for p in (1.0, 2.0, 3.5):
        val, mask = p_variation(x, p, return_partition=True)
        assert val == pytest.approx(n ** (1 / p) * a, rel=1e-12)
        assert mask.all()


def test_zigzag_with_small_backstep():
    x = np.array([[0.0], [2.0], [1.0], [3.0]])
    v1, m1 = p_variation(x, 1.0, return_partition=True)
    v3, m3 = p_variation(x, 3.0, return_partition=True)
    assert v1 == pytest.approx(5.0) and m1.all()
    assert v3 == pytest.approx(3.0) and m3.tolist() == [True, False, False, True]
    # p = 2: the full partition and the single jump tie at 9 (2² + 1² + 2² = 3²)
    assert p_variation(x, 2.0) == pytest.approx(3.0)


def test_zigzag_2d_flat():
    """Points (k, ±ε): p = 1 keeps every point, p = 2 takes the single chord of length n."""
    n, eps = 8, 0.1
    pts = np.stack([np.arange(n + 1.0), eps * (-1.0) ** np.arange(n + 1)], axis=1)
    assert p_variation(pts, 1.0) == pytest.approx(n * np.sqrt(1 + 4 * eps ** 2), rel=1e-12)
    v, mask = p_variation(pts, 2.0, return_partition=True)
    assert v == pytest.approx(n, rel=1e-12)
    assert mask.sum() == 2


# ----------------------------------------------------------------------------- brute force
@pytest.mark.parametrize("p", [1.0, 1.3, 2.0, 2.7, 4.0])
def test_p_variation_matches_enumeration(rng, p):
    for npts in (2, 3, 6, 10):
        path = np.cumsum(rng.standard_normal((npts, 2)), axis=0)
        want = brute_pvar(path, p)
        assert p_variation(path, p) == pytest.approx(want, rel=1e-12)
        assert p_variation(path, p, prune=False) == pytest.approx(want, rel=1e-12)
        val, mask = p_variation(path, p, return_partition=True)
        idx = np.flatnonzero(mask)
        got = sum(np.linalg.norm(path[b] - path[a]) ** p for a, b in zip(idx[:-1], idx[1:])) ** (1 / p)
        assert got == pytest.approx(want, rel=1e-12)   # the mask is an optimal partition


@pytest.mark.parametrize("p", [1.0, 2.0, 2.5, 3.3])
def test_area_p_variation_matches_enumeration(rng, p):
    for n in (1, 4, 8):
        X = random_general_path(rng, n, 2)
        want = brute_area_pvar(X.increments, X.areas, p)
        val, mask = area_p_variation(X, p, return_partition=True)
        assert val == pytest.approx(want, rel=1e-12)
        idx = np.flatnonzero(mask)
        got = sum(np.linalg.norm(naive_area(X.increments, X.areas, a, b)) ** (p / 2)
                  for a, b in zip(idx[:-1], idx[1:])) ** (2 / p)
        assert got == pytest.approx(want, rel=1e-12)


@given(seed=st.integers(0, 2 ** 32 - 1), p=st.floats(1.0, 6.0), drift=st.floats(0.0, 3.0))
def test_pruning_never_changes_p_variation(seed, p, drift):
    rng = np.random.default_rng(seed)
    path = np.cumsum(rng.standard_normal((3, 150, 2)) + drift * np.array([1.0, 0.0]), axis=-2)
    a, b = p_variation(path, p), p_variation(path, p, prune=False)
    np.testing.assert_allclose(a, b, rtol=1e-12)


@given(seed=st.integers(0, 2 ** 32 - 1), alpha=st.floats(0.05, 1.0), drift=st.floats(0.0, 5.0),
       uniform=st.booleans())
def test_pruning_never_changes_holder(seed, alpha, drift, uniform):
    rng = np.random.default_rng(seed)
    n = 150
    t = np.linspace(0.0, 2.0, n) if uniform else np.cumsum(rng.uniform(0.01, 1.0, n))
    path = np.cumsum(rng.standard_normal((2, n, 2)) * np.sqrt(np.gradient(t))[:, None]
                     + drift * np.array([1.0, 0.0]) / n, axis=-2)
    a, b = holder_seminorm(path, alpha, times=t), holder_seminorm(path, alpha, times=t, prune=False)
    np.testing.assert_allclose(a, b, rtol=1e-12)


@pytest.mark.parametrize("uniform", [True, False])
def test_holder_matches_naive_double_loop(rng, uniform):
    n, d = 12, 3
    X = random_general_path(rng, n, d)
    if uniform:
        X = RoughPath(X.increments, X.areas, times=np.linspace(1.0, 4.0, n + 1), kind="general")
    Y = random_general_path(rng, n, d)
    Y = RoughPath(Y.increments, Y.areas, times=X.times, kind="general")
    for alpha in (0.3, 0.45, 1.0):
        m1, m2 = naive_holder(X.increments, X.areas, X.times, alpha)
        assert holder_seminorm(X, alpha) == pytest.approx(m1, rel=1e-12)
        assert holder_seminorm(X, alpha, prune=False) == pytest.approx(m1, rel=1e-12)
        assert area_holder_seminorm(X, alpha) == pytest.approx(m2, rel=1e-12)
        assert rough_path_holder_norm(X, alpha) == pytest.approx(m1 + np.sqrt(m2), rel=1e-12)
        d1, d2 = naive_holder(X.increments - Y.increments, np.zeros_like(X.areas), X.times, alpha)
        dd2 = max(np.linalg.norm(naive_area(X.increments, X.areas, i, j) - naive_area(Y.increments, Y.areas, i, j))
                  / (X.times[j] - X.times[i]) ** (2 * alpha) for i in range(n) for j in range(i + 1, n + 1))
        assert holder_distance(X, Y, alpha) == pytest.approx(d1 + dd2, rel=1e-12)


# ----------------------------------------------------------------------------- distance
def test_distance_axioms(rng):
    X, Y, Z = (random_general_path(rng, 15, 2) for _ in range(3))
    Y = RoughPath(Y.increments, Y.areas, times=X.times, kind="general")
    Z = RoughPath(Z.increments, Z.areas, times=X.times, kind="general")
    for alpha in (0.35, 0.5):
        assert holder_distance(X, X, alpha) == 0.0
        assert holder_distance(X, Y, alpha) == pytest.approx(holder_distance(Y, X, alpha), rel=1e-13)
        assert holder_distance(X, Z, alpha) <= holder_distance(X, Y, alpha) + holder_distance(Y, Z, alpha) + 1e-12
    # inhomogeneous: distance to the zero path is ‖X‖_α + ‖XX‖_{2α} (no square root)
    O = RoughPath(np.zeros_like(X.increments), np.zeros_like(X.areas), times=X.times)
    assert holder_distance(X, O, 0.4) == pytest.approx(
        holder_seminorm(X, 0.4) + area_holder_seminorm(X, 0.4), rel=1e-12)


@pytest.mark.parametrize("alpha", [0.3, 0.5, 0.7])
def test_distance_to_perturbation_closed_form(rng, alpha):
    t = np.sort(np.concatenate([[0.0, 3.0], rng.uniform(0, 3.0, 30)]))
    X = RoughPath.from_path(np.cumsum(rng.standard_normal((t.size, 3)), 0), times=t)
    s = np.array([[0.0, 1.0, -2.0], [-1.0, 0.0, 0.5], [2.0, -0.5, 0.0]])
    if alpha < 0.5:
        sup = t[-1] ** (1 - 2 * alpha)
    elif alpha > 0.5:
        sup = np.min(np.diff(t)) ** (1 - 2 * alpha)
    else:
        sup = 1.0
    want = np.linalg.norm(s) * sup
    assert holder_distance(X, X.perturb(s), alpha) == pytest.approx(want, rel=1e-12)
    # batched s: one distance per perturbation, each scaling with |s|
    sb = np.array([0.0, 0.5, 2.0])[:, None, None] * s
    np.testing.assert_allclose(holder_distance(X, X.perturb(sb), alpha), [0.0, 0.5 * want, 2 * want], rtol=1e-12)
    np.testing.assert_allclose(holder_distance(X.perturb(sb), X, alpha), [0.0, 0.5 * want, 2 * want], rtol=1e-12)


# ----------------------------------------------------------------------------- batching and input
def test_batched_equals_per_path(rng):
    X = random_general_path(rng, 9, 2, batch=(2, 3))
    Y = random_general_path(rng, 9, 2, batch=(3,))
    Y = RoughPath(Y.increments, Y.areas, times=X.times, kind="general")
    funcs = [lambda Z: holder_seminorm(Z, 0.4), lambda Z: area_holder_seminorm(Z, 0.4),
             lambda Z: rough_path_holder_norm(Z, 0.4), lambda Z: p_variation(Z, 2.2),
             lambda Z: area_p_variation(Z, 2.2), lambda Z: rough_path_p_variation(Z, 2.2)]
    for f in funcs:
        got = f(X)
        assert got.shape == (2, 3)
        for i, j in np.ndindex(2, 3):
            assert got[i, j] == pytest.approx(f(X[i, j]), rel=1e-13)
    dist = holder_distance(X, Y, 0.4)
    assert dist.shape == (2, 3)
    for i, j in np.ndindex(2, 3):
        assert dist[i, j] == pytest.approx(holder_distance(X[i, j], Y[j], 0.4), rel=1e-13)
    # arrays of samples give the same level-1 norms as the RoughPath; x0 plays no role
    path = X.path + 5.0
    np.testing.assert_allclose(holder_seminorm(path, 0.4, times=X.times), holder_seminorm(X, 0.4), rtol=1e-12)
    np.testing.assert_allclose(p_variation(path, 2.2), p_variation(X, 2.2), rtol=1e-12)
    mask = p_variation(X, 2.2, return_partition=True)[1]
    assert mask.shape == (2, 3, 10) and mask[..., 0].all() and mask[..., -1].all()


def test_bad_arguments(rng):
    X = RoughPath.from_path(rng.standard_normal((6, 2)))
    for bad in (0.0, -0.1, 1.5, np.nan):
        with pytest.raises(ValueError, match="alpha"):
            holder_seminorm(X, bad)
    for bad in (True, "0.5", None):
        with pytest.raises(TypeError, match="alpha"):
            rough_path_holder_norm(X, bad)
    for bad in (0.5, 0.99, np.inf):
        with pytest.raises(ValueError, match="p"):
            p_variation(X, bad)
    with pytest.raises(ValueError, match="times is required"):
        holder_seminorm(X.path, 0.5)
    with pytest.raises(ValueError, match="times"):
        holder_seminorm(X, 0.5, times=X.times)
    with pytest.raises(ValueError, match="times"):
        holder_seminorm(X.path, 0.5, times=X.times[::-1])
    with pytest.raises(ValueError, match="times"):
        p_variation(X.path, 2.0, times=X.times[:-1])
    with pytest.raises(ValueError, match="X"):
        p_variation(np.array([[np.nan, 0.0], [1.0, 1.0]]), 2.0)
    with pytest.raises(TypeError, match="X"):
        p_variation(X.path.astype(complex), 2.0)
    with pytest.raises(TypeError, match="RoughPath"):
        area_holder_seminorm(X.path, 0.5)
    with pytest.raises(ValueError, match="level-1"):
        area_p_variation(X.to_level1(), 2.5)
    with pytest.raises(ValueError, match="level-1"):
        holder_distance(X, X.to_level1(), 0.4)
    with pytest.raises(ValueError, match="max_points"):
        holder_seminorm(X, 0.5, max_points=5)
    assert holder_seminorm(X, 0.5, max_points=None) > 0
    Z = RoughPath.from_path(X.path, times=np.linspace(0, 2, 6))
    with pytest.raises(ValueError, match="same time grid"):
        holder_distance(X, Z, 0.4)
    W = RoughPath.from_path(rng.standard_normal((6, 3)))
    with pytest.raises(ValueError, match="dimension"):
        holder_distance(X, W, 0.4)
    B2 = RoughPath.from_path(rng.standard_normal((2, 6, 2)))
    B3 = RoughPath.from_path(rng.standard_normal((3, 6, 2)))
    with pytest.raises(ValueError, match="batch shapes of X"):
        holder_distance(B2, B3, 0.4)


@pytest.mark.parametrize("scale", [1e-170, 1e-100, 1e100, 1e160, 1e300])
def test_level1_norms_are_homogeneous_at_extreme_scales(scale):
    """|cX|_α = c|X|_α and |cX|_{p-var} = c|X|_{p-var}: no overflow to inf, no underflow to 0."""
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 1.0, 80)
    x = np.cumsum(rng.standard_normal((3, 80, 2)), axis=-2)
    ref_h, ref_p = holder_seminorm(x, 0.4, times=t), p_variation(x, 2.5)
    np.testing.assert_allclose(holder_seminorm(x * scale, 0.4, times=t) / scale, ref_h, rtol=1e-14)
    np.testing.assert_allclose(p_variation(x * scale, 2.5) / scale, ref_p, rtol=1e-14)


@pytest.mark.parametrize("scale", [1e-140, 1e-60, 1e60, 1e140])
def test_level2_norms_are_homogeneous_under_dilation(scale):
    """Dilation δ_c(x, a) = (cx, c²a): every homogeneous norm scales by c (areas by c²)."""
    rng = np.random.default_rng(6)
    x = np.cumsum(rng.standard_normal((2, 60, 2)), axis=-2)
    X, Y = RoughPath.from_path(x), RoughPath.from_path(x * scale)
    np.testing.assert_allclose(rough_path_holder_norm(Y, 0.4) / scale, rough_path_holder_norm(X, 0.4), rtol=1e-13)
    np.testing.assert_allclose(area_holder_seminorm(Y, 0.4) / scale**2, area_holder_seminorm(X, 0.4), rtol=1e-13)
    np.testing.assert_allclose(area_p_variation(Y, 2.5) / scale**2, area_p_variation(X, 2.5), rtol=1e-13)
    s = np.array([[0.0, 1.0], [-1.0, 0.0]])
    np.testing.assert_allclose(holder_distance(Y, Y.perturb(s * scale**2), 0.3) / scale**2,
                               holder_distance(X, X.perturb(s), 0.3), rtol=1e-13)


@pytest.mark.parametrize("span", [1e-300, 1e-30, 1e30, 1e300])
def test_holder_norms_rescale_with_the_clock(span):
    """Reparametrising t -> span·t divides the α-Hölder seminorm by span^α (area: span^{2α})."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 1.0, 50)
    x = np.cumsum(rng.standard_normal((50, 2)), axis=0)
    X, Y = RoughPath.from_path(x, times=t), RoughPath.from_path(x, times=t * span)
    np.testing.assert_allclose(holder_seminorm(Y, 0.5) * span**0.5, holder_seminorm(X, 0.5), rtol=1e-13)
    np.testing.assert_allclose(area_holder_seminorm(Y, 0.5) * span, area_holder_seminorm(X, 0.5), rtol=1e-13)
