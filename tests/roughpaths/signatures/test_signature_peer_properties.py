"""Properties that the signature peers' own test suites check, restated against our API.

Each test names the peer suite whose property it mirrors (in our words and code, not theirs):

* iisignature (``tests/test_sig.py``): Chen's identity for concatenated paths; the log-signature of a
  straight segment is its increment; ``logsigdim`` follows Witt's formula.
* signatory (``test/signature/``): the signature of the reversed path is the inverse of the signature; a
  repeated sample point, or an extra point on a straight segment, does not change the signature.
* pySigLib (``tests/``): the shuffle identity, the product of two coordinates being the sum over the
  shuffles of their words.

Conventions: our flat layout drops the scalar level 0 and stores levels ``1..m`` word by word in
lexicographic order, as iisignature does (``sig[..., word]``, word ``(i, j)`` at ``d + i d + j``);
signatory and pySigLib include level 0 by default in some calls: where a peer differs, the test says so.
"""

import itertools

import numpy as np
from hypothesis import given, settings, strategies as st

import roughpaths as rp

DEPTH = 4


def _coord(sig, word, d):
    """Coordinate of ``word`` (tuple of letters) in our flat layout (levels 1..m, lexicographic)."""
    offset = sum(d ** k for k in range(1, len(word)))
    return sig[..., offset + int(np.ravel_multi_index(word, (d,) * len(word)))]


paths = st.integers(2, 8).flatmap(lambda n: st.integers(1, 3).flatmap(
    lambda d: st.lists(st.floats(-1, 1), min_size=n * d, max_size=n * d).map(
        lambda v: np.array(v).reshape(n, d))))


@settings(max_examples=30, deadline=None)
@given(x=paths, cut=st.integers(0, 100))
def test_chen_concatenation_iisignature(x, cut):
    """iisignature: sig(x) = sig(x[:k+1]) ⊗ sig(x[k:])."""
    k = cut % (x.shape[0] - 1) if x.shape[0] > 2 else 1
    k = max(1, min(k, x.shape[0] - 1))
    d = x.shape[1]
    whole = rp.signature(x, DEPTH)
    joined = rp.tensor_product(rp.signature(x[:k + 1], DEPTH), rp.signature(x[k:], DEPTH), d)
    np.testing.assert_allclose(joined, whole, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(x=paths)
def test_reversal_is_the_inverse_signatory(x):
    """signatory: sig(reversed x) = sig(x)^{-1} (level 0 implicit here, explicit in signatory)."""
    d = x.shape[1]
    np.testing.assert_allclose(rp.signature(x[::-1], DEPTH), rp.tensor_inverse(rp.signature(x, DEPTH), d),
                               atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(x=paths, where=st.integers(0, 100), frac=st.floats(0.0, 1.0))
def test_repeated_and_collinear_points_change_nothing_signatory(x, where, frac):
    """signatory: a repeated point, or a point inside a straight segment, leaves the signature unchanged."""
    k = where % (x.shape[0] - 1)
    repeated = np.insert(x, k, x[k], axis=0)
    inside = np.insert(x, k + 1, x[k] + frac * (x[k + 1] - x[k]), axis=0)
    s = rp.signature(x, DEPTH)
    np.testing.assert_allclose(rp.signature(repeated, DEPTH), s, atol=1e-12)
    np.testing.assert_allclose(rp.signature(inside, DEPTH), s, atol=1e-12)


def test_logsignature_of_a_segment_is_its_increment_iisignature():
    """iisignature: logsig of a two-point path = (increment, 0, ..., 0) in the Lyndon basis."""
    x = np.array([[0.3, -1.2, 2.0], [1.1, 0.4, -0.5]])
    ls = rp.logsignature(x, DEPTH)
    np.testing.assert_allclose(ls[:3], x[1] - x[0], atol=1e-15)
    np.testing.assert_allclose(ls[3:], 0.0, atol=1e-15)


def test_logsigdim_is_witts_formula_iisignature():
    """iisignature: the number of Lyndon words of length k over d letters is (1/k) Σ_{j | k} μ(j) d^{k/j}."""
    def mobius(n):
        out, p, m = 1, 2, n
        while p * p <= m:
            if m % p == 0:
                m //= p
                if m % p == 0:
                    return 0
                out = -out
            p += 1
        return -out if m > 1 else out

    for d in (1, 2, 3, 5):
        for m in (1, 2, 3, 4, 5):
            witt = sum(sum(mobius(j) * d ** (k // j) for j in range(1, k + 1) if k % j == 0) // k
                       for k in range(1, m + 1))
            assert rp.logsigdim(d, m) == witt == len(rp.lyndon_basis(d, m)), (d, m)


@settings(max_examples=30, deadline=None)
@given(x=paths)
def test_shuffle_identity_pysiglib(x):
    """pySigLib: <S, u><S, v> = Σ_{w ∈ u ⧢ v} <S, w>, here for |u| = 1, 2 and |v| = 1, 2."""
    d = x.shape[1]
    s = rp.signature(x, DEPTH)
    letters = range(d)
    for u in itertools.chain(((i,) for i in letters), itertools.product(letters, repeat=2)):
        for v in itertools.chain(((j,) for j in letters), itertools.product(letters, repeat=2)):
            total = 0.0
            n = len(u) + len(v)
            for pos in itertools.combinations(range(n), len(u)):   # positions of u's letters in w
                w, iu, iv = [], iter(u), iter(v)
                for p in range(n):
                    w.append(next(iu) if p in pos else next(iv))
                total += _coord(s, tuple(w), d)
            np.testing.assert_allclose(_coord(s, u, d) * _coord(s, v, d), total, atol=1e-11)
