"""Claim: the Lyndon basis labels name their words unambiguously for every d, and say what they differ in.

Mirrors iisignature's basis checks (``iisignature.basis`` against the words of ``logsig``) at
d >= 10. Where our convention differs: iisignature prints every letter from 10 on as ``'?'``
(so from d = 11 on two basis elements can share a label, e.g. ``'[1,?]'`` for ``[1,10]`` and
``[1,11]``); :func:`roughpaths.lyndon_basis` prints the decimal number (``'[1,10]'``), which a parser
reads back unambiguously because every letter is delimited by ``[``, ``,``, ``]`` or the string's
ends. The tests check:

* replacing every letter >= 10 in our labels by ``'?'`` gives iisignature's labels exactly (same
  words, same order, same bracketing), and for d <= 9 the labels are equal;
* our labels are distinct and parse back to the Lyndon word and its standard bracketing;
* the log-signature coordinates agree with ``iisignature.logsig`` at d = 10, 11, 12;
* the docstring states the difference (it used to say letters are printed "as iisignature does").
"""

import re

import iisignature
import numpy as np
import pytest
from _oracles import parse_bracket

from roughpaths import logsignature, lyndon_basis


def _as_iisignature(label):
    return re.sub(r"\d+", lambda m: m.group() if int(m.group()) <= 9 else "?", label)


def _parse(label):
    """Nested tuples of 1-based letters from a label (the shared parser, letters kept 1-based)."""
    return parse_bracket(label, first_letter=0)


def _flatten(t):
    return (t,) if isinstance(t, int) else _flatten(t[0]) + _flatten(t[1])


def _standard_bracketing(w):
    """Standard factorisation written independently: the right factor is the smallest proper suffix."""
    if len(w) == 1:
        return w[0]
    i = min(range(1, len(w)), key=lambda j: w[j:])
    return (_standard_bracketing(w[:i]), _standard_bracketing(w[i:]))


@pytest.mark.parametrize("d,m", [(10, 1), (10, 2), (10, 3), (11, 2), (12, 3), (3, 4), (9, 2)])
def test_labels_are_iisignatures_with_the_numbers_kept(d, m):
    ours = lyndon_basis(d, m)
    ref = list(iisignature.basis(iisignature.prepare(d, m)))
    assert [_as_iisignature(s) for s in ours] == ref
    if d <= 9:
        assert ours == ref


def test_iisignature_labels_collide_from_d_11():
    ref = list(iisignature.basis(iisignature.prepare(11, 2)))
    assert ref[9] == ref[10] == "?"
    assert len(set(ref)) < len(ref)
    assert lyndon_basis(10, 1)[-1] == "10"
    assert lyndon_basis(11, 2)[-3:] == ["[9,10]", "[9,11]", "[10,11]"]


@pytest.mark.parametrize("d,m", [(10, 3), (11, 3), (13, 2), (2, 6)])
def test_labels_are_unambiguous(d, m):
    labels = lyndon_basis(d, m)
    assert len(set(labels)) == len(labels)
    words = []
    for label in labels:
        tree = _parse(label)
        word = _flatten(tree)
        assert all(1 <= a <= d for a in word)
        assert tree == _standard_bracketing(word)
        assert all(word < word[i:] for i in range(1, len(word)))          # a Lyndon word
        words.append(word)
    assert words == sorted(words, key=lambda w: (len(w), w))


@pytest.mark.parametrize("d,m", [(10, 2), (11, 3), (12, 2)])
def test_coordinates_match_iisignature(rng, d, m):
    x = np.cumsum(rng.standard_normal((2, 6, d)), axis=-2) / 3.0
    np.testing.assert_allclose(logsignature(x, m), iisignature.logsig(x, iisignature.prepare(d, m)),
                               rtol=0, atol=1e-10)


def test_docstring_states_the_difference():
    doc = lyndon_basis.__doc__
    assert "'?'" in doc and "'[1,10]'" in doc
