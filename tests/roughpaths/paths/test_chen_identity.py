"""Chen's identity for the two-parameter queries of ``RoughPath``.

Claims tested:

* for every grid triple ``s < u < t``: ``XX_{s,t} = XX_{s,u} + XX_{u,t} + X_{s,u} ⊗ X_{u,t}`` and
  ``X_{s,t} = X_{s,u} + X_{u,t}`` (random per-step increments and *non-geometric* per-step areas);
* ``area(s, t)`` equals the iterated-sum definition ``Σ_k A_k + Σ_{k<l} ΔX_k ⊗ ΔX_l`` written as a
  naive double loop; for piecewise-linear paths (``A_k = ½ ΔX_k ⊗ ΔX_k``) it equals the level-2
  signature of ``iisignature`` (entry ``[i, j]`` ↔ word ``(i, j)``);
* ``levy_area`` is ``½(XX - XXᵀ)`` *with* the ½ (the L-shaped path has Lévy area ½, not 1) and
  matches ``iisignature.logsig``'s level-2 Lyndon coordinate.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from _oracles import naive_area
from roughpaths import RoughPath

iisignature = pytest.importorskip("iisignature")




@st.composite
def data_and_triple(draw):
    n = draw(st.integers(2, 12))
    d = draw(st.integers(1, 3))
    seed = draw(st.integers(0, 2 ** 32 - 1))
    i, k, j = sorted(draw(st.lists(st.integers(0, n), min_size=3, max_size=3, unique=True)))
    return n, d, seed, i, k, j


@given(data_and_triple())
def test_chen_on_random_triples(case):
    n, d, seed, i, k, j = case
    rng = np.random.default_rng(seed)
    inc, areas = rng.standard_normal((n, d)), rng.standard_normal((n, d, d))
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.0, n))])
    X = RoughPath(inc, areas, times=times, kind="general")
    s, u, t = times[i], times[k], times[j]
    lhs = X.area(s, t)
    rhs = X.area(s, u) + X.area(u, t) + np.outer(X.increment(s, u), X.increment(u, t))
    np.testing.assert_allclose(lhs, rhs, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(X.increment(s, t), X.increment(s, u) + X.increment(u, t), atol=1e-12)
    np.testing.assert_allclose(lhs, naive_area(inc, areas, i, j), rtol=1e-12, atol=1e-12)
    # the wrong order of the cross term must fail whenever it matters
    wrong = X.area(s, u) + X.area(u, t) + np.outer(X.increment(u, t), X.increment(s, u))
    cross = np.outer(X.increment(s, u), X.increment(u, t))
    if np.max(np.abs(cross - cross.T)) > 1e-6:
        assert not np.allclose(lhs, wrong, atol=1e-9)


def test_area_matches_naive_and_iisignature_for_piecewise_linear(rng):
    vals = np.cumsum(rng.standard_normal((4, 9, 3)), axis=-2)
    t = np.linspace(0.0, 2.0, 9)
    X = RoughPath.from_path(vals, times=t)
    for i in range(9):
        for j in range(i + 1, 9):
            got = X.area(t[i], t[j])
            assert got.shape == (4, 3, 3)
            sig = iisignature.sig(vals[:, i:j + 1, :], 2)[:, 3:].reshape(4, 3, 3)
            np.testing.assert_allclose(got, sig, rtol=1e-11, atol=1e-12)
            for b in range(4):
                inc = np.diff(vals[b], axis=0)
                half = 0.5 * inc[:, :, None] * inc[:, None, :]
                np.testing.assert_allclose(got[b], naive_area(inc, half, i, j), rtol=1e-12, atol=1e-12)


def test_vectorised_queries(rng):
    vals = np.cumsum(rng.standard_normal((2, 11, 2)), axis=-2)
    X = RoughPath.from_path(vals)
    s = np.array([[0.0, 0.1], [0.3, 0.5]])
    t = np.array([[1.0, 0.4], [0.3, 0.9]])
    a = X.area(s, t)
    assert a.shape == (2, 2, 2, 2, 2)
    for q in np.ndindex(2, 2):
        np.testing.assert_allclose(a[(slice(None),) + q], X.area(s[q], t[q]), atol=1e-14)
    assert X.increment(s, t).shape == (2, 2, 2, 2)
    np.testing.assert_allclose(X.area(0.3, 0.3), 0.0)


def test_levy_area_has_the_half():
    X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), times=[0.0, 1.0, 2.0])
    np.testing.assert_allclose(X.area(0.0, 2.0), [[0.5, 1.0], [0.0, 0.5]])
    A = X.levy_area(0.0, 2.0)
    np.testing.assert_allclose(A, [[0.0, 0.5], [-0.5, 0.0]])
    assert not np.allclose(A, [[0.0, 1.0], [-1.0, 0.0]])     # the paper's eq. (LevyArea) without ½


def test_levy_area_matches_iisignature_logsig(rng):
    vals = np.cumsum(rng.standard_normal((3, 12, 2)), axis=-2)
    X = RoughPath.from_path(vals)
    prep = iisignature.prepare(2, 2)
    logsig = iisignature.logsig(vals, prep)               # Lyndon basis: (1, 2, [1,2])
    A = X.levy_area(X.times[0], X.times[-1])
    np.testing.assert_allclose(A[:, 0, 1], logsig[:, 2], rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(A, -np.swapaxes(A, -1, -2), atol=1e-15)
    # step_levy_areas: zero on linear pieces, and the Alt part of general per-step areas
    np.testing.assert_allclose(X.step_levy_areas, 0.0, atol=1e-15)
    a = rng.standard_normal((5, 2, 2))
    Y = RoughPath(rng.standard_normal((5, 2)), a, kind="general")
    np.testing.assert_allclose(Y.step_levy_areas, 0.5 * (a - np.swapaxes(a, -1, -2)))
