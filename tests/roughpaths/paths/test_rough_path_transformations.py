"""Transformations of ``RoughPath``: restrict, concatenate, reverse, perturb, indexing, diagnostics.

Claims tested (oracles are naive loops and the level-2 group law written out in this file):

* ``restrict(times)`` returns, on each coarse step, the Chen sum of the fine steps it covers
  (``Σ ΔX`` and ``Σ_k A_k + Σ_{k<l} ΔX_k ⊗ ΔX_l``), its ``x0`` is the trace at ``times[0]``;
* ``concatenate`` continues the trace and its total area obeys Chen across the junction;
* ``reverse``: ``reverse∘reverse = id``; the reversed area over ``[T+t0-t, T+t0-s]`` is the group
  inverse ``-XX_{s,t} + X_{s,t}⊗X_{s,t}`` of the forward one; geometric paths stay geometric (and
  the level-2 signature of the reversed samples from ``iisignature`` agrees);
* ``perturb(s)``: ``area(s, t)`` gains exactly ``s (t - s)`` over every pair, increments unchanged,
  geometricity kept; ``s`` may be batched;
* ``geometric_defect`` is 0 for the piecewise-linear lift and ``½ max dt`` for an Itô-type area;
* ``x0``/``path``, batch indexing (including ``X[..., k]``), and level-1 paths refusing area queries.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from _oracles import naive_area
from roughpaths import RoughPath, chen_defect

iisignature = pytest.importorskip("iisignature")




def general_path(rng, n=10, d=2, batch=()):
    inc = rng.standard_normal(batch + (n, d))
    areas = rng.standard_normal(batch + (n, d, d))
    times = np.concatenate([[0.5], 0.5 + np.cumsum(rng.uniform(0.1, 1.0, n))])
    x0 = rng.standard_normal(batch + (d,))
    return RoughPath(inc, areas, times=times, x0=x0, kind="general")


# ----------------------------------------------------------------------------- restrict
@given(seed=st.integers(0, 2 ** 32 - 1), data=st.data())
def test_restrict_is_chen_sum(seed, data):
    rng = np.random.default_rng(seed)
    X = general_path(rng, n=12, d=2)
    idx = sorted(data.draw(st.lists(st.integers(0, 12), min_size=2, max_size=8, unique=True)))
    R = X.restrict(X.times[idx])
    np.testing.assert_array_equal(R.times, X.times[idx])
    np.testing.assert_allclose(R.x0, X.path[idx[0]], atol=1e-12)
    np.testing.assert_allclose(R.path, X.path[idx], atol=1e-12)
    for m, (a, b) in enumerate(zip(idx[:-1], idx[1:])):
        np.testing.assert_allclose(R.increments[m], X.increments[a:b].sum(0), atol=1e-12)
        np.testing.assert_allclose(R.areas[m], naive_area(X.increments, X.areas, a, b), rtol=1e-12, atol=1e-12)
    assert chen_defect(X, R) < 1e-12


def test_restrict_batched_level1_and_identity(rng):
    X = general_path(rng, n=9, d=3, batch=(2, 2))
    same = X.restrict(X.times)
    np.testing.assert_allclose(same.areas, X.areas, atol=1e-13)
    np.testing.assert_allclose(same.increments, X.increments, atol=1e-13)
    R = X.restrict(X.times[[1, 4, 9]])
    assert R.batch_shape == (2, 2) and R.n_steps == 2
    np.testing.assert_allclose(R.areas[1, 0, 1], naive_area(X.increments[1, 0], X.areas[1, 0], 4, 9), atol=1e-12)
    L = X.to_level1().restrict(X.times[[0, 5, 9]])
    assert L.level == 1
    np.testing.assert_allclose(L.increments[..., 0, :], X.increments[..., 0:5, :].sum(-2), atol=1e-12)
    np.testing.assert_allclose(L.increments[..., 1, :], X.increments[..., 5:9, :].sum(-2), atol=1e-12)
    # a perturbed coarse path has a positive Chen defect w.r.t. the fine one
    s = np.zeros((3, 3))
    s[0, 1], s[1, 0] = 0.3, -0.3
    assert chen_defect(X, R.perturb(s)) > 0.1


# ----------------------------------------------------------------------------- concatenate
def test_concatenate(rng):
    X, Y = general_path(rng, n=5), general_path(rng, n=7)
    Z = X.concatenate(Y)
    assert Z.n_steps == 12 and Z.kind == "general"
    np.testing.assert_allclose(Z.times[:6], X.times)
    np.testing.assert_allclose(np.diff(Z.times[5:]), np.diff(Y.times))
    np.testing.assert_allclose(Z.path[:6], X.path)
    np.testing.assert_allclose(Z.path[5:], Y.path - Y.x0 + X.path[-1], atol=1e-12)   # Y.x0 ignored
    tX, tY = X.times, Y.times
    total = X.area(tX[0], tX[-1]) + Y.area(tY[0], tY[-1]) + np.outer(X.increment(tX[0], tX[-1]),
                                                                     Y.increment(tY[0], tY[-1]))
    np.testing.assert_allclose(Z.area(Z.times[0], Z.times[-1]), total, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(Z.area(Z.times[3], Z.times[9]), naive_area(Z.increments, Z.areas, 3, 9), atol=1e-12)
    G = RoughPath.from_path(rng.standard_normal((4, 2)))
    assert G.concatenate(G).kind == "geometric"
    with pytest.raises(ValueError, match="level-1"):
        X.concatenate(Y.to_level1())
    with pytest.raises(ValueError, match="batch shape"):
        X.concatenate(general_path(rng, n=3, batch=(2,)))
    with pytest.raises(TypeError, match="other"):
        X.concatenate(np.zeros((3, 2)))


# ----------------------------------------------------------------------------- reverse
def test_reverse(rng):
    X = general_path(rng, n=8, d=3, batch=(2,))
    R = X.reverse()
    RR = R.reverse()
    np.testing.assert_allclose(RR.times, X.times, atol=1e-13)
    np.testing.assert_allclose(RR.increments, X.increments)
    np.testing.assert_allclose(RR.areas, X.areas, atol=1e-12)
    np.testing.assert_allclose(RR.x0, X.x0, atol=1e-12)
    np.testing.assert_allclose(R.path, X.path[:, ::-1], atol=1e-12)
    t, T0, T1 = X.times, X.times[0], X.times[-1]
    for i, j in [(0, 8), (2, 5), (3, 4), (1, 7)]:
        x, a = X.increment(t[i], t[j]), X.area(t[i], t[j])
        inv = -a + x[..., :, None] * x[..., None, :]          # level-2 group inverse
        np.testing.assert_allclose(R.area(T0 + T1 - t[j], T0 + T1 - t[i]), inv, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(R.increment(T0 + T1 - t[j], T0 + T1 - t[i]), -x, atol=1e-12)


def test_reverse_keeps_geometricity(rng):
    vals = np.cumsum(rng.standard_normal((3, 10, 2)), axis=-2)
    X = RoughPath.from_path(vals)
    R = X.reverse()
    assert R.kind == "geometric"
    assert np.max(R.geometric_defect()) < 1e-12
    sig = iisignature.sig(vals[:, ::-1, :], 2)[:, 2:].reshape(3, 2, 2)
    np.testing.assert_allclose(R.area(0.0, 1.0), sig, rtol=1e-11, atol=1e-12)
    # an Itô-type area reverses to a backward-Itô one: no longer labelled "ito"
    dt = X.dt
    I = RoughPath(X.increments, X.areas - 0.5 * dt[:, None, None] * np.eye(2), kind="ito")
    assert I.reverse().kind == "general"


# ----------------------------------------------------------------------------- perturb
@given(seed=st.integers(0, 2 ** 32 - 1), i=st.integers(0, 9), j=st.integers(0, 9))
def test_perturb_shifts_area_by_s_dt(seed, i, j):
    i, j = min(i, j), max(i, j)
    rng = np.random.default_rng(seed)
    vals = np.cumsum(rng.standard_normal((9 + 1, 3)), axis=0)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.1, 1.0, 9))])
    X = RoughPath.from_path(vals, times=times)
    m = rng.standard_normal((3, 3))
    s = m - m.T
    P = X.perturb(s)
    dt = times[j] - times[i]
    np.testing.assert_allclose(P.area(times[i], times[j]), X.area(times[i], times[j]) + s * dt, atol=1e-12)
    np.testing.assert_allclose(P.levy_area(times[i], times[j]), X.levy_area(times[i], times[j]) + s * dt,
                               atol=1e-12)
    np.testing.assert_allclose(P.increments, X.increments)
    assert P.kind == "geometric" and P.geometric_defect() < 1e-12


def test_perturb_batched_and_rejects_symmetric(rng):
    X = RoughPath.from_path(np.cumsum(rng.standard_normal((7, 2)), axis=0))
    J = np.array([[0.0, 1.0], [-1.0, 0.0]])
    sb = np.array([0.0, 1.0, -2.0])[:, None, None] * J
    P = X.perturb(sb)
    assert P.batch_shape == (3,)
    np.testing.assert_allclose(P.area(0.0, 1.0), X.area(0.0, 1.0) + sb)
    Xb = RoughPath.from_path(np.cumsum(rng.standard_normal((3, 7, 2)), axis=-2))
    np.testing.assert_allclose(Xb.perturb(sb).area(0.0, 0.5), Xb.area(0.0, 0.5) + 0.5 * sb, atol=1e-12)
    with pytest.raises(ValueError, match="antisymmetric"):
        X.perturb(np.eye(2))
    with pytest.raises(ValueError, match="antisymmetric"):
        X.perturb(J + 0.1 * np.ones((2, 2)))
    with pytest.raises(ValueError, match="s"):
        Xb.perturb(np.stack([J, J]))                    # batch (2,) vs (3,)


# ----------------------------------------------------------------------------- diagnostics etc.
def test_geometric_defect_and_kind(rng):
    vals = np.cumsum(rng.standard_normal((2, 6, 2)), axis=-2)
    t = np.array([0.0, 0.1, 0.3, 0.4, 0.8, 1.0])
    X = RoughPath.from_path(vals, times=t)
    np.testing.assert_allclose(X.geometric_defect(), 0.0, atol=1e-14)
    ito = X.areas - 0.5 * X.dt[:, None, None] * np.eye(2)
    I = RoughPath(X.increments, ito, times=t, kind="ito")
    assert I.geometric_defect().shape == (2,)
    np.testing.assert_allclose(I.geometric_defect(), 0.5 * 0.4)
    assert RoughPath(X.increments, X.areas, times=t).kind == "geometric"
    assert RoughPath(X.increments, ito, times=t).kind == "general"
    with pytest.raises(ValueError, match="geometric"):
        RoughPath(X.increments, ito, times=t, kind="geometric")


def test_x0_and_path(rng):
    vals = rng.standard_normal((2, 5, 3))
    X = RoughPath.from_path(vals)
    np.testing.assert_allclose(X.x0, vals[:, 0])
    np.testing.assert_allclose(X.path, vals, atol=1e-14)
    Y = RoughPath.from_increments(np.diff(vals, axis=-2), x0=[1.0, 2.0, 3.0])
    np.testing.assert_allclose(Y.path, vals - vals[:, :1] + [1.0, 2.0, 3.0], atol=1e-14)
    Z = RoughPath.from_increments(np.diff(vals, axis=-2))
    np.testing.assert_allclose(Z.x0, 0.0)
    np.testing.assert_allclose(Z.times, np.linspace(0, 1, 5))
    assert (X.dim, X.n_steps, X.batch_shape, X.level) == (3, 4, (2,), 2)
    assert Y.level == 1 and Y.kind is None


def test_batch_indexing(rng):
    X = general_path(rng, n=6, d=2, batch=(3, 4))
    t = X.times
    for index in [1, (2, 3), slice(1, 3), (..., 2), (slice(None), [0, 3]), np.array([True, False, True])]:
        Y = X[index]
        ref_area = np.moveaxis(np.moveaxis(X.area(t[1], t[5]), (-2, -1), (0, 1))[(slice(None),) * 2 + (
            index if isinstance(index, tuple) else (index,))], (0, 1), (-2, -1))
        np.testing.assert_allclose(Y.area(t[1], t[5]), ref_area)
        assert Y.n_steps == 6 and Y.dim == 2
    assert X[..., 2].batch_shape == (3,)
    np.testing.assert_allclose(X[..., 2].path, X.path[:, 2])
    np.testing.assert_allclose(X[1].x0, X.x0[1])
    with pytest.raises(IndexError):
        X[0, 0][0]
    with pytest.raises(IndexError):
        X[5]


def test_level1_refuses_area_queries(rng):
    X = RoughPath.from_path(rng.standard_normal((5, 2))).to_level1()
    assert X.level == 1 and X.areas is None
    for call in (lambda: X.area(0.0, 1.0), lambda: X.levy_area(0.0, 1.0), lambda: X.step_levy_areas,
                 lambda: X.perturb(np.zeros((2, 2))), lambda: X.geometric_defect()):
        with pytest.raises(ValueError, match="level-2"):
            call()
    np.testing.assert_allclose(X.increment(0.0, 1.0), X.path[-1] - X.path[0])
