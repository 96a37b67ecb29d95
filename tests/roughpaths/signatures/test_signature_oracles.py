"""Claim: ``signature`` / ``logsignature`` equal the independent oracles iisignature and esig.

* ``signature(paths, m)`` equals ``iisignature.sig(paths, m)`` and ``esig.stream2sig(path, m)[1:]``
  to 1e-12 on random paths (several d, depths, batch shapes; long paths cut into parallel chunks);
* ``logsignature(paths, m)`` equals ``iisignature.logsig(paths, prepare(d, m))`` (Lyndon basis,
  default method) to 1e-12, and the basis is ``iisignature.basis``;
* the expanded log-signature equals esig's log-signature re-expanded from esig's own (Hall)
  basis keys, an independent route through a different Lie basis;
* level 2 equals ``RoughPath.from_path(...).increment/area`` over the whole grid;
* ``rough_path_signature`` is the canonical extension: it reproduces the piecewise-linear signature
  for a piecewise-linear lift and the rough path's own increment and area at levels 1 and 2.

Paths are scaled so that coordinates are O(1): absolute 1e-12 is then a relative test.
"""

import itertools

import esig
import iisignature
import numpy as np
import pytest
from _oracles import parse_bracket

from roughpaths import (RoughPath, logsignature, lyndon_basis, rough_path_signature, sigdim, signature,
                        tensor_exp, tensor_log, tensor_product)
from roughpaths.signatures import _lanes as _sig_lanes
from roughpaths.signatures import _level2 as _sig_level2
from roughpaths.signatures._engine import _reversed_to_rowmajor, _units

TOL = 1e-12


def _paths(rng, shape, n, d):
    return np.cumsum(rng.standard_normal(shape + (n, d)) / np.sqrt(n), axis=-2) + rng.standard_normal(shape + (1, d))


CASES = [(2, 1), (2, 2), (2, 3), (2, 5), (3, 2), (3, 3), (3, 4), (4, 2), (4, 3), (5, 3)]


@pytest.mark.parametrize("d,m", CASES)
@pytest.mark.parametrize("batch", [(), (3,), (2, 2)])
def test_signature_matches_iisignature(rng, d, m, batch):
    x = _paths(rng, batch, 17, d)
    ours = signature(x, m)
    ref = iisignature.sig(x, m)
    assert ours.shape == ref.shape == batch + (sigdim(d, m),)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=TOL)


@pytest.mark.parametrize("d,m", [(2, 3), (3, 4), (4, 2)])
def test_signature_matches_esig(rng, d, m):
    x = _paths(rng, (3,), 12, d)
    ours = signature(x, m)
    for p, s in zip(x, ours):
        ref = np.asarray(esig.stream2sig(p, m))
        assert ref[0] == 1.0
        np.testing.assert_allclose(s, ref[1:], rtol=0, atol=TOL)


def test_level2_is_not_transposed(rng):
    """The oracle comparison catches a transposed area (so entry [i, j] is the word (i, j))."""
    x = _paths(rng, (), 9, 3)
    s = signature(x, 2)
    a = s[3:].reshape(3, 3)
    ref = iisignature.sig(x, 2)
    np.testing.assert_allclose(s, ref, atol=TOL)
    wrong = np.concatenate([s[:3], a.T.reshape(-1)])
    assert np.max(np.abs(wrong - ref)) > 1e-3


@pytest.mark.parametrize("d,m", [(2, 2), (2, 4), (3, 3), (3, 4), (4, 3), (2, 6)])
@pytest.mark.parametrize("batch", [(), (4,)])
def test_logsignature_matches_iisignature(rng, d, m, batch):
    x = _paths(rng, batch, 15, d)
    prep = iisignature.prepare(d, m)
    assert lyndon_basis(d, m) == list(iisignature.basis(prep))
    ref = iisignature.logsig(x, prep)
    ours = logsignature(x, m)
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, rtol=0, atol=TOL)
    # The Lyndon-basis coordinates are not the Lyndon-word coefficients of the expanded log: where
    # the unit-triangular change of basis is not the identity, reading them off naively fails.
    if (d, m) in [(3, 3), (3, 4), (2, 6)]:
        expanded = tensor_log(iisignature.sig(x, m), d)
        words = [w for k in range(1, m + 1) for w in itertools.product(range(d), repeat=k)]
        lyndon = [w for w in words if all(w < w[i:] for i in range(1, len(w)))]
        lyndon.sort(key=lambda w: (len(w), w))
        pos = {w: i for i, w in enumerate(words)}
        wrong = expanded[..., [pos[w] for w in lyndon]]
        assert np.max(np.abs(wrong - ours)) > 1e-4


@pytest.mark.parametrize("d,m", [(2, 2), (2, 3), (3, 3), (2, 4), (3, 4)])
def test_logsignature_level2_is_levy_area(rng, d, m):
    x = _paths(rng, (2,), 11, d)
    ls = logsignature(x, m)
    a = RoughPath.from_path(x).levy_area(0.0, 1.0)
    basis = lyndon_basis(d, m)
    for i in range(d):
        for j in range(i + 1, d):
            k = basis.index(f"[{i + 1},{j + 1}]")
            np.testing.assert_allclose(ls[..., k], a[..., i, j], atol=TOL)


# ------------------------------------------------------------------ esig's Hall basis, independently
def _expand_bracket(tree, d):
    """Naive tensor expansion: dict word -> coefficient."""
    if isinstance(tree, int):
        return {(tree,): 1.0}
    a, b = _expand_bracket(tree[0], d), _expand_bracket(tree[1], d)
    out = {}
    for u, cu in a.items():
        for v, cv in b.items():
            out[u + v] = out.get(u + v, 0.0) + cu * cv
            out[v + u] = out.get(v + u, 0.0) - cu * cv
    return out


@pytest.mark.parametrize("d,m", [(2, 4), (3, 3), (3, 4)])
def test_expanded_logsignature_matches_esig_hall_basis(rng, d, m):
    keys = esig.logsigkeys(d, m).split()
    trees = [parse_bracket(k) for k in keys]
    for p in _paths(rng, (2,), 10, d):
        coef = np.asarray(esig.stream2logsig(p, m))
        assert coef.shape == (len(keys),)
        expanded = np.zeros(sigdim(d, m))
        for c, tree in zip(coef, trees):
            for word, w in _expand_bracket(tree, d).items():
                k = len(word)
                idx = sum(d ** j for j in range(1, k)) + sum(l * d ** (k - 1 - i) for i, l in enumerate(word))
                expanded[idx] += c * w
        np.testing.assert_allclose(tensor_log(signature(p, m), d), expanded, rtol=0, atol=TOL)


# ------------------------------------------------------------------ level 2 against RoughPath
@pytest.mark.parametrize("d", [2, 3, 5])
def test_level2_signature_matches_rough_path_area(rng, d):
    x = _paths(rng, (3, 2), 25, d)
    t = np.linspace(0.0, 2.0, 25)
    X = RoughPath.from_path(x, times=t)
    s = signature(x, 2)
    np.testing.assert_allclose(s[..., :d], X.increment(0.0, 2.0), atol=TOL)
    np.testing.assert_allclose(s[..., d:].reshape(x.shape[:-2] + (d, d)), X.area(0.0, 2.0), atol=TOL)


# ------------------------------------------------------------------ long paths: parallel chunks glued by Chen
@pytest.mark.parametrize("m", [2, 4])
@pytest.mark.parametrize("nchunks", [2, 3])
def test_chunked_kernels_match_iisignature(rng, m, nchunks):
    d = 3
    x = _paths(rng, (2,), 1000, d)
    ref = iisignature.sig(x, m)
    xc = np.ascontiguousarray(x)
    if m == 2:
        part = np.empty((2 * nchunks, d + d * (d - 1) // 2))
        _sig_level2.sig2_tasks(d)(xc, nchunks, 0, 2 * nchunks, part)
        got = _sig_level2.sig2_glue(part, 2, nchunks, d)
    else:
        off = np.zeros(m + 2, dtype=np.int64)
        for k in range(1, m + 1):
            off[k + 1] = off[k] + d ** k
        ub, lo, hi = _units(x.shape[0], x.shape[1], nchunks)
        part = np.empty((2 * nchunks, off[m + 1]))
        _sig_lanes.lane_groups(d, m)(xc, ub, lo, hi, m, off, 0, 1, part)
        got = _sig_lanes.lane_glue(part, 2, nchunks, m, off)[:, _reversed_to_rowmajor(d, m)]
    np.testing.assert_allclose(got, ref, rtol=0, atol=TOL)


def test_long_single_path_public_api(rng):
    x = _paths(rng, (), 60_000, 3)          # long enough to take the chunked route when threads > 1
    for m in (2, 3):
        np.testing.assert_allclose(signature(x, m), iisignature.sig(x, m), rtol=0, atol=1e-11)


# ------------------------------------------------------------------ rough-path signature
@pytest.mark.parametrize("d,m", [(2, 4), (3, 3)])
def test_rough_path_signature_of_piecewise_linear_lift(rng, d, m):
    x = _paths(rng, (2,), 13, d)
    np.testing.assert_allclose(rough_path_signature(RoughPath.from_path(x), m), iisignature.sig(x, m),
                               rtol=0, atol=TOL)


@pytest.mark.parametrize("d,m", [(2, 4), (3, 3)])
def test_rough_path_signature_with_levy_areas(rng, d, m):
    n = 7
    inc = rng.standard_normal((2, n, d)) / np.sqrt(n)
    lev = rng.standard_normal((2, n, d, d)) / n
    lev = 0.5 * (lev - np.swapaxes(lev, -1, -2))
    areas = lev + 0.5 * inc[..., :, None] * inc[..., None, :]
    X = RoughPath(inc, areas, kind="geometric")
    got = rough_path_signature(X, m)
    # levels 1, 2 are the rough path's own increment and area (Chen over the grid)
    np.testing.assert_allclose(got[..., :d], X.increment(0.0, 1.0), atol=TOL)
    np.testing.assert_allclose(got[..., d:d + d * d].reshape(2, d, d), X.area(0.0, 1.0), atol=TOL)
    # higher levels: product of exp(x_k + A_k) through the numpy tensor algebra (a separate code path)
    z = np.zeros((2, n, sigdim(d, m)))
    z[..., :d] = inc
    z[..., d:d + d * d] = lev.reshape(2, n, d * d)
    g = tensor_exp(z, d)
    ref = g[:, 0]
    for k in range(1, n):
        ref = tensor_product(ref, g[:, k], d)
    np.testing.assert_allclose(got, ref, rtol=0, atol=TOL)
    # and the step Lévy areas matter at level 3: dropping them changes the answer
    z[..., d:d + d * d] = 0.0
    g0 = tensor_exp(z, d)
    ref0 = g0[:, 0]
    for k in range(1, n):
        ref0 = tensor_product(ref0, g0[:, k], d)
    assert np.max(np.abs(got - ref0)) > 1e-4


# ------------------------------------------------------------------ edge cases and bad input
def test_single_point_has_zero_signature():
    assert np.array_equal(signature(np.ones((4, 1, 3)), 3), np.zeros((4, sigdim(3, 3))))
    assert np.array_equal(logsignature(np.ones((1, 2)), 3), np.zeros(5))


def test_empty_batch():
    assert signature(np.zeros((0, 5, 2)), 3).shape == (0, 14)


@pytest.mark.parametrize("depth", [0, -1])
def test_rejects_depth_below_one(depth):
    with pytest.raises(ValueError, match="depth"):
        signature(np.zeros((3, 2)), depth)
    with pytest.raises(ValueError, match="depth"):
        logsignature(np.zeros((3, 2)), depth)


@pytest.mark.parametrize("depth", [2.0, True, "2"])
def test_rejects_non_integer_depth(depth):
    with pytest.raises(TypeError, match="depth"):
        signature(np.zeros((3, 2)), depth)


@pytest.mark.parametrize("bad", [np.array([[0.0, 1.0], [np.nan, 0.0]]), np.array([[0.0, np.inf]])])
def test_rejects_non_finite(bad):
    with pytest.raises(ValueError, match="paths.*non-finite"):
        signature(bad, 2)


def test_rejects_wrong_shapes_and_dtypes():
    with pytest.raises(ValueError, match="paths"):
        signature(np.zeros(5), 2)
    with pytest.raises(ValueError, match="paths"):
        signature(np.zeros((0, 2)), 2)
    with pytest.raises(TypeError, match="paths"):
        signature(np.zeros((3, 2), dtype=complex), 2)
    with pytest.raises(TypeError, match="paths"):
        signature("abc", 2)


def test_rough_path_signature_rejects_bad_input(rng):
    inc = rng.standard_normal((4, 2))
    with pytest.raises(TypeError, match="RoughPath"):
        rough_path_signature(np.cumsum(inc, 0), 2)
    with pytest.raises(ValueError, match="level-1"):
        rough_path_signature(RoughPath(inc), 2)
    ito = RoughPath(inc, 0.5 * inc[:, :, None] * inc[:, None, :] - 0.125 * np.eye(2), kind="ito")
    with pytest.raises(ValueError, match="geometric"):
        rough_path_signature(ito, 3)
    with pytest.raises(ValueError, match="depth"):
        rough_path_signature(RoughPath.from_path(np.cumsum(inc, 0)), 0)
