"""Claim: the truncated tensor algebra operations satisfy the group axioms, and signatures are group-like.

Property tests (hypothesis) on random elements of :math:`T^{(m)}(\\mathbb{R}^d)`:

* the Chen product is associative, not commutative, and ``tensor_inverse`` is a two-sided inverse;
* ``exp ∘ log = id`` on ``1 + T`` and ``log ∘ exp = id`` on ``T_0`` (elements without scalar part);
* Chen's identity: the signature of a concatenation is the product of the signatures;
* reversing a path inverts its signature;
* the log-signature is a Lie element: its level 2 is antisymmetric and it equals its own
  expansion from Lyndon coordinates (which a non-Lie element does not);
* the shuffle identity ``S^i S^j = S^{ij} + S^{ji}``, ``S^i S^{jk} = S^{ijk} + S^{jik} + S^{jki}``
  (an independent check that signatures are group-like, written with naive loops here);
* the level-2 truncation agrees with :mod:`roughpaths.algebra.level2` (product, inverse, exp, log).
"""

import itertools

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from roughpaths import level2_exp, level2_inv, level2_log, level2_mul, signature
from roughpaths import (from_level2, from_lyndon_coordinates, lyndon_coordinates,
                                       sigdim, tensor_exp, tensor_inverse, tensor_log, tensor_product,
                                       to_level2)

TOL = 1e-10

dims = st.sampled_from([1, 2, 3])
depths = st.integers(min_value=1, max_value=4)
seeds = st.integers(min_value=0, max_value=2**32 - 1)
scales = st.sampled_from([0.1, 1.0, 2.0])


def _elements(seed, d, m, count, batch=(), scale=1.0):
    rng = np.random.default_rng(seed)
    return [scale * rng.standard_normal(batch + (sigdim(d, m),)) for _ in range(count)]


def _path(seed, n, d, scale=1.0):
    rng = np.random.default_rng(seed)
    return scale * np.cumsum(rng.standard_normal((n, d)), axis=0) / np.sqrt(n)


def _close(a, b, tol=TOL):
    scale = 1.0 + max(float(np.max(np.abs(a))), float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


@given(seed=seeds, d=dims, m=depths, scale=scales)
def test_associativity(seed, d, m, scale):
    a, b, c = _elements(seed, d, m, 3, batch=(2,), scale=scale)
    _close(tensor_product(tensor_product(a, b, d), c, d), tensor_product(a, tensor_product(b, c, d), d))


@given(seed=seeds, d=dims, m=depths, scale=scales)
def test_inverse_is_two_sided(seed, d, m, scale):
    (a,) = _elements(seed, d, m, 1, batch=(3,), scale=scale)
    inv = tensor_inverse(a, d)
    _close(tensor_product(a, inv, d), np.zeros_like(a))
    _close(tensor_product(inv, a, d), np.zeros_like(a))


def test_product_is_not_commutative():
    """A swapped product would break Chen: the test of Chen below distinguishes the two orders."""
    a, b = _elements(1, 2, 2, 2)
    assert np.max(np.abs(tensor_product(a, b, 2) - tensor_product(b, a, 2))) > 1e-3


@given(seed=seeds, d=dims, m=depths, scale=scales)
def test_exp_log_are_inverse(seed, d, m, scale):
    a, z = _elements(seed, d, m, 2, batch=(2,), scale=scale)
    _close(tensor_exp(tensor_log(a, d), d), a, 1e-9)
    _close(tensor_log(tensor_exp(z, d), d), z, 1e-9)


@given(seed=seeds, d=st.sampled_from([2, 3]), m=depths, n1=st.integers(1, 8), n2=st.integers(1, 8))
def test_chen_identity(seed, d, m, n1, n2):
    x = _path(seed, n1 + n2, d)
    whole = signature(x, m)
    first, second = signature(x[:n1 + 1], m), signature(x[n1:], m)
    _close(tensor_product(first, second, d), whole)


@given(seed=seeds, d=st.sampled_from([2, 3]), m=depths, n=st.integers(2, 12))
def test_reversal_gives_inverse(seed, d, m, n):
    x = _path(seed, n, d)
    _close(signature(x[::-1], m), tensor_inverse(signature(x, m), d))


@given(seed=seeds, d=st.sampled_from([2, 3]), m=st.integers(2, 4), n=st.integers(2, 12))
def test_logsignature_is_lie(seed, d, m, n):
    x = _path(seed, n, d)
    log = tensor_log(signature(x, m), d)
    lev2 = log[d:d + d * d].reshape(d, d)
    _close(lev2 + lev2.T, np.zeros((d, d)))
    _close(from_lyndon_coordinates(lyndon_coordinates(log, d), d, m), log)


def test_non_lie_element_fails_the_lie_check():
    d, m = 2, 2
    z = np.zeros(sigdim(d, m))
    z[d + 0] = 1.0                               # e1 ⊗ e1: symmetric, not in the free Lie algebra
    assert np.max(np.abs(from_lyndon_coordinates(lyndon_coordinates(z, d), d, m) - z)) > 0.5


def _word_index(word, d):
    k = len(word)
    return sum(d ** j for j in range(1, k)) + sum(l * d ** (k - 1 - i) for i, l in enumerate(word))


def _shuffles(u, v):
    """All shuffles of the words u and v (with multiplicity), naively."""
    if not u:
        return [v]
    if not v:
        return [u]
    return [(u[0],) + w for w in _shuffles(u[1:], v)] + [(v[0],) + w for w in _shuffles(u, v[1:])]


@given(seed=seeds, d=st.sampled_from([2, 3]), n=st.integers(2, 10))
def test_shuffle_identity(seed, d, n):
    x = _path(seed, n, d, scale=1.5)
    s = signature(x, 3)

    def S(word):
        return s[_word_index(word, d)]

    for u_len, v_len in [(1, 1), (1, 2)]:
        for u in itertools.product(range(d), repeat=u_len):
            for v in itertools.product(range(d), repeat=v_len):
                rhs = sum(S(w) for w in _shuffles(u, v))
                assert abs(S(u) * S(v) - rhs) <= 1e-11 * (1.0 + abs(rhs))


def test_shuffle_identity_sees_a_transposed_area():
    """Swapping level 2 for its transpose keeps S^i S^j = S^{ij} + S^{ji} but breaks the (1, 2) shuffles."""
    d = 2
    x = _path(7, 6, d, scale=1.5)
    s = signature(x, 3)
    bad = s.copy()
    bad[d:d + d * d] = s[d:d + d * d].reshape(d, d).T.reshape(-1)
    u, v = (0,), (0, 1)
    rhs = sum(bad[_word_index(w, d)] for w in _shuffles(u, v))
    assert abs(bad[_word_index(u, d)] * bad[_word_index(v, d)] - rhs) > 1e-3


@given(seed=seeds, d=st.sampled_from([1, 2, 3]), m=st.integers(2, 4), scale=scales)
def test_level2_truncation_agrees_with_level2_module(seed, d, m, scale):
    a, b, z = _elements(seed, d, m, 3, batch=(2,), scale=scale)
    xa, aa = to_level2(a, d)
    xb, ab = to_level2(b, d)
    for got, ref in [
        (tensor_product(a, b, d), from_level2(*level2_mul(xa, aa, xb, ab))),
        (tensor_inverse(a, d), from_level2(*level2_inv(xa, aa))),
        (tensor_log(a, d), from_level2(*level2_log(xa, aa))),
        (tensor_exp(z, d), from_level2(*level2_exp(*to_level2(z, d)))),
    ]:
        _close(got[..., :d + d * d], ref)


def test_level2_roundtrip_and_bad_input():
    x, a = np.array([1.0, 2.0]), np.arange(4.0).reshape(2, 2)
    flat = from_level2(x, a)
    x2, a2 = to_level2(flat, 2)
    assert np.array_equal(x2, x) and np.array_equal(a2, a)
    with pytest.raises(ValueError, match="not d \\+ d\\*\\*2"):
        tensor_product(np.zeros(5), np.zeros(5), 2)
    with pytest.raises(ValueError, match="same depth"):
        tensor_product(np.zeros(6), np.zeros(14), 2)
    with pytest.raises(ValueError, match="depth >= 2"):
        to_level2(np.zeros(3), 3)
    with pytest.raises(ValueError, match="non-finite"):
        tensor_log(np.full(6, np.nan), 2)
    with pytest.raises(TypeError, match="dim"):
        tensor_exp(np.zeros(6), 2.0)


@pytest.mark.parametrize("batch", [(0,), (3, 0)])
def test_group_operations_on_an_empty_batch_axis(batch):
    """An empty batch axis gives an empty result of the same batch shape (reshapes to ``-1`` could not
    infer the size of an empty array and raised)."""
    d, m = 2, 3
    z = np.zeros(batch + (sigdim(d, m),))
    for got in (tensor_product(z, z, d), tensor_inverse(z, d), tensor_exp(z, d), tensor_log(z, d)):
        assert got.shape == batch + (14,)
    assert lyndon_coordinates(z, d).shape == batch + (5,)                # 2 + 1 + 2 Lyndon words
    assert from_lyndon_coordinates(np.zeros(batch + (5,)), d, m).shape == batch + (14,)
