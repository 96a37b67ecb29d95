"""Claim: the Lyndon helpers work at d = 1, where the free Lie algebra is the line spanned by ``'1'``.

Over one letter the only Lyndon word is ``(0,)`` (printed ``'1'``): there is no Lyndon word of length
``k >= 2``, ``logsigdim(1, m) = 1`` and a Lie element of :math:`T^{(m)}(\\mathbb{R})` is ``(x, 0, ..., 0)``.
:func:`roughpaths.lyndon_coordinates` and :func:`roughpaths.from_lyndon_coordinates` must treat the empty
levels as empty (they used to fail on them: "need at least one array to concatenate", "blocks must be
2-D"), and agree with :func:`roughpaths.logsignature`, which already handled d = 1.

Mirrors iisignature's ``test_logsig`` round-trip checks (logsig against the log of ``sig``, and back
through the exponential) at d = 1. Where our convention differs: ``iisignature.prepare(1, m)`` refuses
d = 1 ("dimension must be at least 2"), so iisignature is the oracle only for the signature
(``iisignature.sig`` accepts d = 1); esig's ``stream2logsig``, which accepts d = 1, is the oracle for
the log-signature.
"""

import math

import esig
import iisignature
import numpy as np
import pytest

from roughpaths import (from_lyndon_coordinates, logsigdim, logsignature, lyndon_basis, lyndon_coordinates,
                        sigdim, signature, tensor_exp, tensor_log)

DEPTHS = [1, 2, 3, 4, 6]


def test_the_reported_cases():
    np.testing.assert_array_equal(lyndon_coordinates([3.0, 0.0], 1), [3.0])
    np.testing.assert_array_equal(from_lyndon_coordinates([3.0], 1, 2), [3.0, 0.0])


@pytest.mark.parametrize("m", DEPTHS)
def test_basis_and_dimensions(m):
    assert lyndon_basis(1, m) == ["1"]
    assert logsigdim(1, m) == 1
    assert sigdim(1, m) == m


@pytest.mark.parametrize("m", DEPTHS)
def test_round_trip_against_iisignature_and_esig(rng, m):
    path = np.cumsum(rng.standard_normal((7, 1)), axis=0)
    x = path[-1, 0] - path[0, 0]
    sig = iisignature.sig(path, m)                                    # oracle: x^k / k!
    np.testing.assert_allclose(sig, [x ** k / math.factorial(k) for k in range(1, m + 1)], rtol=1e-12)
    np.testing.assert_allclose(signature(path, m), sig, rtol=1e-12, atol=1e-12)
    log = tensor_log(sig, 1)
    coords = lyndon_coordinates(log, 1)
    assert coords.shape == (1,)
    np.testing.assert_allclose(coords, [x], rtol=1e-12)
    np.testing.assert_allclose(coords, logsignature(path, m), rtol=1e-12)
    np.testing.assert_allclose(coords, np.asarray(esig.stream2logsig(path, m))[-1:], rtol=1e-12)
    expanded = from_lyndon_coordinates(coords, 1, m)
    np.testing.assert_allclose(expanded, np.r_[x, np.zeros(m - 1)], rtol=0, atol=1e-12 * (1 + abs(x)) ** m)
    np.testing.assert_allclose(tensor_exp(expanded, 1), sig, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("m", DEPTHS)
def test_batched_round_trip(rng, m):
    c = rng.standard_normal((3, 2, 1))
    expanded = from_lyndon_coordinates(c, 1, m)
    assert expanded.shape == (3, 2, m)
    np.testing.assert_array_equal(expanded[..., 1:], 0.0)
    np.testing.assert_allclose(lyndon_coordinates(expanded, 1), c, rtol=0, atol=0)
