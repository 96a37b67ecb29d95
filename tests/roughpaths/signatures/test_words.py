"""signature_coefficients: chosen words against iisignature.sig's entries and roughpaths.signature's."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import roughpaths as rp


@pytest.fixture
def rng(request):
    """A generator seeded by the test's own id: its numbers do not depend on which tests ran before it."""
    return np.random.default_rng(zlib.crc32(request.node.nodeid.encode()))


def _position(word, d):
    """Row-major position of a word in the flat layout (levels 1..k concatenated)."""
    k = len(word)
    return sum(d ** j for j in range(1, k)) + sum(c * d ** (k - 1 - j) for j, c in enumerate(word))


def test_words_match_iisignature(rng):
    iisignature = pytest.importorskip("iisignature")
    d, depth = 3, 5
    x = rng.normal(size=(2, 2, 40, d)).cumsum(axis=-2) * 0.3
    words = [tuple(rng.integers(0, d, size=k)) for k in (1, 2, 2, 3, 4, 5, 5)] + [(2, 2, 2, 2, 2), (0,)]
    got = rp.signature_coefficients(x, words)
    assert got.shape == (2, 2, len(words))
    full = iisignature.sig(x.reshape(-1, 40, d), depth).reshape(2, 2, -1)
    want = full[..., [_position(w, d) for w in words]]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(full).max())


def test_words_match_the_full_signature_on_a_long_path(rng):
    d, depth, n = 2, 4, 50_001
    x = rng.normal(scale=1e-2, size=(n, d)).cumsum(axis=0)
    words = [(0, 1), (1, 0, 1), (0, 0, 1, 1), (1, 1, 1, 0)]
    full = rp.signature(x, depth)
    got = rp.signature_coefficients(x, words)
    for w, g in zip(words, got):
        start = _position((0,) * len(w), d)
        level = full[start:start + d ** len(w)]                              # the word's level
        assert abs(g - full[_position(w, d)]) <= 1e-11 * np.abs(level).max(), (w, g, full[_position(w, d)])


def test_one_point_gives_zero_and_letters_only_matter_through_their_channels(rng):
    assert np.all(rp.signature_coefficients(np.ones((1, 3)), [(0,), (1, 2)]) == 0.0)
    x = rng.normal(size=(20, 2))
    y = x[:, ::-1]
    np.testing.assert_allclose(rp.signature_coefficients(x, [(0, 1, 1)]), rp.signature_coefficients(y, [(1, 0, 0)]),
                               rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("words, exc, word", [
    ([(0, 3)], ValueError, "letter 3"),
    ([()], ValueError, "empty word"),
    ([], ValueError, "words is empty"),
    ([(0.0, 1)], TypeError, "letter"),
    ([(True,)], TypeError, "letter"),
    ("01", TypeError, "words"),
    (5, TypeError, "words"),
    ([(-1,)], ValueError, "letter -1"),
])
def test_bad_words_are_refused(words, exc, word):
    with pytest.raises(exc, match=word):
        rp.signature_coefficients(np.ones((4, 3)), words)


def test_bad_paths_are_refused():
    with pytest.raises(ValueError, match="paths"):
        rp.signature_coefficients(np.array([[0.0], [np.inf]]), [(0,)])
    with pytest.raises(ValueError, match="paths"):
        rp.signature_coefficients(np.ones(3), [(0,)])
    with pytest.raises(ValueError, match="overflow"):
        rp.signature_coefficients(np.array([[0.0], [1e200]]), [(0, 0)])


def test_the_work_estimate_counts_the_quadratic_cost_of_a_long_word(monkeypatch):
    """A word of length k costs k (k + 1) / 2 multiply-adds a step (the module docstring's
    O(n Σ|w|²)); the estimate counted k, so one long word passed the work budget by a factor k / 2."""
    x = np.zeros((2, 1000, 2))
    word = [(0, 1) * 100]                       # k = 200: 20100 multiply-adds a step
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", str(2 * 1000 * 200 * 10))   # 10 times the old count
    with pytest.raises(ValueError, match="work budget"):
        rp.signature_coefficients(x, word)
    monkeypatch.setenv("ROUGHPATHS_MAX_WORK", str(2 * 1000 * 20100))      # exactly the cost: allowed
    assert np.array_equal(rp.signature_coefficients(x, word), np.zeros((2, 1)))
