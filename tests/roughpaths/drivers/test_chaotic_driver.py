"""ChaoticDriver, the built-in maps and observable_orbits (roughpaths.drivers.chaotic).

Claims: the cat map is iterated exactly on the lattice (against Python-integer arithmetic); the driver's
increments and areas are the piecewise-linear lift of the fast sums (against a naive double loop); the
numbers do not depend on the block size or on select; the expected Lévy area of the lift is
``t Alt(E) − n⁻¹ Alt(Σ m C(m))`` exactly (closed form from a grid quadrature of the correlations); the
Lorenz-63 map is RK4 of the flow; bad input is refused with a message naming the argument.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import roughpaths
from roughpaths import ChaoticDriver, ChaoticMap, cat_map, lorenz63_map, observable_orbits

CAT = ((2, 1), (1, 1))


def _v(y):
    """Two sine observables (mean zero): v¹ at k = (1, 0) and A²q = (3, 2), v² at Ak = (2, 1) and q = (0, 1)."""
    t = 2 * np.pi * y
    return np.stack([np.sin(t[..., 0]) + 0.5 * np.sin(3 * t[..., 0] + 2 * t[..., 1]),
                     np.sin(2 * t[..., 0] + t[..., 1]) + np.sin(t[..., 1])], axis=-1)


def _cat_int(a: int, b: int, steps: int):
    """The cat map on Python integers mod 2^64 (the oracle of the uint64 lattice arithmetic)."""
    out = []
    for _ in range(steps):
        out.append((a, b))
        a, b = (2 * a + b) % 2**64, (a + b) % 2**64
    return out


def test_cat_map_is_exact_lattice_arithmetic():
    T = cat_map()
    s0 = T.sample(np.random.default_rng(3), 4)
    assert s0.dtype == np.uint64 and s0.shape == (4, 2)
    buf = np.empty((4, 300, 2), dtype=np.uint64)
    nxt = T.orbit(s0.copy(), 300, buf)                      # the powers A^j at once
    st = s0.copy()
    for j in range(300):                                    # and the in-place step
        assert np.array_equal(buf[:, j], st)
        st = T.step(st)
    assert np.array_equal(nxt, st)
    for p in range(4):
        ref = _cat_int(int(s0[p, 0]), int(s0[p, 1]), 301)
        assert [tuple(int(x) for x in r) for r in buf[p]] == ref[:300]
        assert (int(nxt[p, 0]), int(nxt[p, 1])) == ref[300]
    # a general SL(2, Z) matrix with a negative entry (two's complement) against Python integers
    G = cat_map(((3, -1), (1, 0)))
    s = np.array([[12345678901234567, 2**63 + 5]], dtype=np.uint64)
    a, b = int(s[0, 0]), int(s[0, 1])
    for _ in range(50):
        s = G.step(s)
        a, b = (3 * a - b) % 2**64, a % 2**64
    assert (int(s[0, 0]), int(s[0, 1])) == (a, b)


def _naive_lift(n, m, N, P, seed):
    """Increments and areas from the orbits by the definition (double loop over the fast steps)."""
    T = cat_map()
    s = T.sample(np.random.default_rng(np.random.SeedSequence(seed)), P)
    inc, area = np.zeros((P, N, 2)), np.zeros((P, N, 2, 2))
    for p in range(P):
        orb = _cat_int(int(s[p, 0]), int(s[p, 1]), N * m)
        y = np.array(orb, dtype=np.float64) / 2.0**64
        dl = _v(y) / math.sqrt(n)
        for k in range(N):
            d = dl[k * m:(k + 1) * m]
            inc[p, k] = d.sum(axis=0)
            for i in range(m):
                area[p, k] += 0.5 * np.outer(d[i], d[i])
                for j in range(i + 1, m):
                    area[p, k] += np.outer(d[i], d[j])
    return inc, area


def test_lift_is_the_piecewise_linear_iterated_sum():
    n, dt, N, P = 200, 0.05, 6, 3
    drv = ChaoticDriver(cat_map(), _v, n, seed=7, dt=dt, n_steps=N, batch_shape=(P,))
    X = drv.rough_path()
    inc, area = _naive_lift(n, 10, N, P, 7)
    assert X.kind == "geometric" and X.dim == 2 and drv.fast_steps_per_step == 10
    np.testing.assert_allclose(X.increments, inc, rtol=0, atol=1e-13)
    np.testing.assert_allclose(X.areas, area, rtol=0, atol=1e-13)
    # the lift is geometric per step, and its area over [0, T] (Chen) is the naive double sum
    np.testing.assert_allclose(X.geometric_defect(), 0.0, atol=1e-14)
    whole = X.area(0.0, N * dt)
    naive = np.zeros((P, 2, 2))
    for p in range(P):
        flat = inc[p]
        for k in range(N):
            naive[p] += area[p, k] + np.outer(flat[:k].sum(axis=0), flat[k])
    np.testing.assert_allclose(whole, naive, atol=1e-12)


def test_blocks_select_and_long_steps_change_nothing_but_rounding():
    kw = dict(seed=2, dt=0.1, n_steps=7, batch_shape=(5,))
    drv = ChaoticDriver(cat_map(), _v, 300, **kw)
    X = drv.rough_path()
    Y = np.concatenate([b.areas for b in drv.blocks(max_steps=2)], axis=1)
    np.testing.assert_allclose(Y, X.areas, rtol=0, atol=1e-13)
    sub = drv.select([3, 1]).rough_path()
    np.testing.assert_allclose(sub.areas, X.areas[[3, 1]], rtol=0, atol=1e-13)
    np.testing.assert_allclose(sub.increments, X.increments[[3, 1]], rtol=0, atol=1e-13)
    # a block budget smaller than one grid step: each step is cut into pieces joined by Chen
    tiny = ChaoticDriver(cat_map(), _v, 300, block_bytes=2000, **kw)
    assert tiny._chunk < tiny.fast_steps_per_step
    Z = tiny.rough_path()
    np.testing.assert_allclose(Z.increments, X.increments, rtol=0, atol=1e-12)
    np.testing.assert_allclose(Z.areas, X.areas, rtol=0, atol=1e-12)
    # observable_orbits sees the same orbits as the driver (same seed, same sampler)
    vals = observable_orbits(cat_map(), _v, 30, seed=2, batch_shape=(5,))
    np.testing.assert_allclose(vals[:, :30].sum(axis=1) / math.sqrt(300), X.increments[:, 0], atol=1e-13)


def _grid_correlations(max_lag, N=256):
    """C(m) = ∫ v ⊗ v∘T^m dy by the N×N grid average (exact for these trigonometric v at small lags:
    the grid is invariant under A, and no image (Aᵀ)^m k, m ≤ 4, of a frequency aliases mod N onto ±k')."""
    g = (np.arange(N) / N)
    y = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    A = np.array(CAT)
    out, z = [], y.copy()
    for _ in range(max_lag + 1):
        out.append(np.einsum("pa,pb->ab", _v(y), _v(z)) / y.shape[0])
        z = (z @ A.T) % 1.0
    return np.array(out)


def test_levy_area_of_the_lift_grows_at_the_closed_form_rate():
    C = _grid_correlations(4)
    assert np.allclose(C[3:], 0.0, atol=1e-12)                      # finite-range correlations
    E = C[1:].sum(axis=0)
    alt = lambda a: 0.5 * (a - a.T)                                  # noqa: E731
    assert abs(alt(E)[0, 1]) > 0.1                                  # the example has a Lévy drift
    n, P = 100, 4000
    drv = ChaoticDriver(cat_map(), _v, n, seed=11, dt=0.1, n_steps=10, batch_shape=(P,))
    X = drv.rough_path()
    for t in (0.5, 1.0):
        N = int(round(n * t))
        # E[Σ_{i<j<N} v_i ⊗ v_j]/n = Σ_m (N − m) C(m)/n, exactly (stationary start)
        pred = alt(sum((N - m) * C[m] for m in range(1, 3)) / n)[0, 1]
        a = X.levy_area(0.0, t)[:, 0, 1]
        se = a.std(ddof=1) / math.sqrt(P)
        assert abs(a.mean() - pred) < 4 * se, (t, a.mean(), pred, se)
        assert abs(a.mean()) > 6 * se                                  # distinguishable from "no area"
    # the symmetric part is ½ X⊗X (geometric): mean ½ n⁻¹ Σ_{i,j<N} C(j − i), C(−m) = C(m)ᵀ, → ½ Σ t
    N = n
    cov = (N * C[0] + sum((N - m) * (C[m] + C[m].T) for m in range(1, 3))) / n
    xx = X.increment(0.0, 1.0)
    sym = 0.5 * np.einsum("pi,pj->pij", xx, xx)
    se = sym.std(axis=0, ddof=1) / math.sqrt(P)
    assert np.all(np.abs(sym.mean(axis=0) - 0.5 * cov) < 4 * se)


def test_lorenz_map_is_rk4_of_the_flow():
    L = lorenz63_map(0.01, spinup=2.0)
    y0 = L.initial_states(np.random.default_rng(0), 3)
    y1 = L.step(y0.copy())

    def f(t, u):
        x, y, z = u
        return [10 * (y - x), x * (28 - z) - y, x * y - 8 / 3 * z]

    for p in range(3):
        ref = solve_ivp(f, (0, 0.01), y0[p], rtol=1e-12, atol=1e-12).y[:, -1]
        np.testing.assert_allclose(y1[p], ref, rtol=0, atol=1e-6 * np.abs(ref).max())
    # the symmetry (x, y, z) -> (-x, -y, z) commutes with the map (hence odd observables have mean 0)
    flip = np.array([-1.0, -1.0, 1.0])
    np.testing.assert_allclose(L.step(y0 * flip), y1 * flip, rtol=1e-15, atol=1e-12)


def test_the_driver_feeds_solve_and_the_norms():
    drv = ChaoticDriver(cat_map(), _v, 100, seed=1, dt=0.05, n_steps=20, batch_shape=(3,))
    V = roughpaths.LinearVectorFields(np.stack([np.array([[0.0, -1.0], [1.0, 0.0]]), np.eye(2) * 0.1]))
    y_drv = roughpaths.solve(V, drv, np.array([1.0, 0.0]), save_at="end").final
    y_rp = roughpaths.solve(V, drv.rough_path(), np.array([1.0, 0.0]), save_at="end").final
    np.testing.assert_allclose(y_drv, y_rp, rtol=1e-12, atol=1e-14)
    assert np.all(np.isfinite(roughpaths.rough_path_p_variation(drv.rough_path(), 2.5)))


def test_bad_input_is_refused_with_the_fix():
    with pytest.raises(ValueError, match=r"n \* dt must be a positive integer"):
        ChaoticDriver(cat_map(), _v, 100, seed=0, dt=0.015, n_steps=3)
    with pytest.raises(TypeError, match="fast_map must be a ChaoticMap"):
        ChaoticDriver(lambda y: y, _v, 100, seed=0, dt=0.01, n_steps=3)
    with pytest.raises(TypeError, match="observable must be a callable"):
        ChaoticDriver(cat_map(), np.eye(2), 100, seed=0, dt=0.01, n_steps=3)
    with pytest.raises(ValueError, match="observable returned shape"):
        ChaoticDriver(cat_map(), lambda y: y[..., 0], 100, seed=0, dt=0.01, n_steps=3)
    with pytest.raises(ValueError, match="non-finite"):
        ChaoticDriver(cat_map(), lambda y: np.full(y.shape, np.nan), 100, seed=0, dt=0.01, n_steps=3)
    with pytest.raises(ValueError, match="uniform grid"):
        ChaoticDriver(cat_map(), _v, 100, seed=0, times=[0.0, 0.01, 0.03])
    with pytest.raises(ValueError, match="work budget"):
        ChaoticDriver(cat_map(), _v, 10**9, seed=0, dt=1.0, n_steps=10**4, batch_shape=(1000,))
    with pytest.raises(ValueError, match="det = ±1 and |trace| > 2"):
        cat_map(((1, 1), (0, 1)))
    with pytest.raises(ValueError, match="2x2 integer matrix"):
        cat_map(((2.0, 1.0), (1.0, 1.0)))
    bad = ChaoticMap(lambda y: y, lambda rng, P: rng.random((P, 3)), dim=2, name="bad sampler")
    with pytest.raises(ValueError, match=r"must return \(4, 2\)"):
        ChaoticDriver(bad, _v, 10, seed=0, dt=0.1, n_steps=2, batch_shape=(4,))
    shrink = ChaoticMap(lambda y: y[:1], lambda rng, P: rng.random((P, 2)), dim=2)
    with pytest.raises(ValueError, match="must keep the shape"):
        ChaoticDriver(shrink, _v, 10, seed=0, dt=0.5, n_steps=2, batch_shape=(4,)).rough_path()
    with pytest.raises(TypeError, match="step must be a callable"):
        ChaoticMap(3, lambda rng, P: None, dim=1)
    with pytest.raises(ValueError, match="diverged"):
        lorenz63_map(1.0, spinup=50.0).initial_states(np.random.default_rng(0), 2)
    with pytest.raises(ValueError, match="spin-up"):
        lorenz63_map(0.01, spinup=1e12).initial_states(np.random.default_rng(0), 2)
    with pytest.raises(ValueError, match="memory budget"):
        observable_orbits(cat_map(), _v, 10**7, seed=0, batch_shape=(10**6,))
    with pytest.raises(TypeError, match="seed must be an int"):
        ChaoticDriver(cat_map(), _v, 10, seed=np.random.default_rng(0), dt=0.1, n_steps=2)


def test_a_batch_of_several_axes_is_the_flat_batch_reshaped():
    # the initial points were kept flat (P, k) while blocks() and select() broadcast them to batch_shape + (k,):
    # any batch of two or more axes failed with a bare numpy broadcast error
    kw = dict(seed=4, dt=0.1, n_steps=3)
    flat = ChaoticDriver(cat_map(), _v, 100, batch_shape=(6,), **kw).rough_path()
    drv = ChaoticDriver(cat_map(), _v, 100, batch_shape=(2, 3), **kw)
    X = drv.rough_path()
    assert X.batch_shape == (2, 3)
    assert drv.initial_state().shape == (2, 3, 2)
    np.testing.assert_array_equal(X.increments.reshape(6, 3, 2), flat.increments)
    np.testing.assert_array_equal(X.areas.reshape(6, 3, 2, 2), flat.areas)
    sub = drv.select([4, 0]).rough_path()
    np.testing.assert_array_equal(sub.increments, flat.increments[[4, 0]])
    empty = ChaoticDriver(cat_map(), _v, 100, batch_shape=(0, 3), **kw).rough_path()
    assert empty.increments.shape == (0, 3, 3, 2)


def test_the_orbits_memory_counts_the_observables_dimension(monkeypatch):
    # the estimate of observable_orbits took d = 8 whatever the observable returned: 10 orbits x 100 steps of a
    # 1000-component observable (8 MB) passed a 1 MB budget
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**6))
    wide = lambda y: np.repeat(np.sin(2 * np.pi * y), 500, axis=-1)    # noqa: E731 - d = 1000
    with pytest.raises(ValueError, match="orbits .* memory budget"):
        observable_orbits(cat_map(), wide, 100, seed=0, batch_shape=(10,))


def test_the_drivers_memory_counts_the_observables_values_at_the_initial_points(monkeypatch):
    # the first evaluation of the observable at the P initial points (a P x d array) was not estimated: 1000
    # orbits of a 1000-component observable (8 MB of values) passed a 1 MB budget (the initial points, 80 kB)
    import tracemalloc

    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(10**6))
    wide = lambda y: np.repeat(np.sin(2 * np.pi * y), 500, axis=-1)    # noqa: E731 - d = 1000
    tracemalloc.start()
    try:
        with pytest.raises(ValueError, match=r"observable's values at the 1000 initial points \(1000 x 1000\) would "
                                             r"take 7.63 MiB, more than the memory budget .*; use fewer orbits"):
            ChaoticDriver(cat_map(), wide, 10, seed=0, dt=0.1, n_steps=2, batch_shape=(1000,))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 10**6, peak                                        # refused before the values exist


def test_a_non_unimodular_matrix_is_refused_even_when_int64_wraps():
    # det [[2^32, 1], [-1, 2^32]] = 2^64 + 1 wrapped to 1 in int64: the matrix passed as det = ±1
    with pytest.raises(ValueError, match="det = ±1"):
        cat_map([[2**32, 1], [-1, 2**32]])


def test_an_overflowing_number_of_fast_steps_is_refused():
    # n * dt = 1e300 * 1e10 overflows to inf: round(inf) raised Python's bare OverflowError
    with pytest.raises(ValueError, match=r"n \* dt must be a positive integer.*inf"):
        ChaoticDriver(cat_map(), _v, 1e300, seed=0, dt=1e10, n_steps=2)


def test_an_observable_of_complex_or_text_values_is_refused():
    # complex values lost their imaginary part with only numpy's ComplexWarning (a silent wrong driver); text
    # raised numpy's bare 'could not convert string to float'
    with pytest.raises(TypeError, match="observable must return real numbers.*complex"):
        observable_orbits(cat_map(), lambda y: np.exp(2j * np.pi * y), 3, seed=1, batch_shape=(2,))
    with pytest.raises(TypeError, match="observable must return real numbers"):
        ChaoticDriver(cat_map(), lambda y: np.full(y.shape, "a"), 10, seed=0, dt=0.1, n_steps=2)
