"""Claim: the wide (d >= 6) and small-batch kernels equal iisignature and give batch-independent bits.

* ``signature`` / ``logsignature`` equal ``iisignature.sig`` / ``logsig`` to 1e-12 at d = 6, 8, 20
  (the one-unit kernel that every d >= 6 runs) and depths 2..8 where the sizes stay small, and on the lane
  kernel where the top level's rows are 4 KiB apart (d = 2 at depth 8, d = 4 at depth 4);
* ``signature_vjp`` / ``logsignature_vjp`` equal ``iisignature.sigbackprop`` / ``logsigbackprop``
  at d = 6, 8 and (depth 2, the closed-form level-2 kernel) 20;
* a path computed alone equals, bit for bit, the same path inside batches of 1..10 members (which
  move it between the lane kernel and the one-unit kernel), for the signature and its VJP.
* both layout routes (the time-reversed input, and the permutation of the output) equal iisignature
  on either side of their threshold ``n d = sigdim``; level 2 at d >= 6 in lane groups of paths, chunked,
  with a member left over, equals iisignature and each member alone.

Oracle: iisignature (an independent C++ implementation), and the public function on the single member.
"""

import iisignature
import numpy as np
import pytest

from roughpaths import logsigdim, logsignature, logsignature_vjp, sigdim, signature, signature_vjp

TOL = 1e-12


def _paths(rng, b, n, d):
    return np.cumsum(rng.standard_normal((b, n, d)) / np.sqrt(n), axis=-2)


SIG_CASES = [(6, 2), (6, 3), (6, 4), (6, 5), (6, 6), (8, 2), (8, 3), (8, 4), (8, 5), (20, 2), (20, 3),
             (2, 8), (3, 8), (4, 4)]     # (2, 8), (4, 4): three paths on lanes, rows of the top level 4 KiB apart


@pytest.mark.parametrize("d,m", SIG_CASES)
def test_wide_signature_matches_iisignature(rng, d, m):
    x = _paths(rng, 3, 5 if d ** m > 10 ** 4 else 9, d)
    np.testing.assert_allclose(signature(x, m), iisignature.sig(x, m), rtol=0, atol=TOL)


@pytest.mark.parametrize("d,m", [(6, 2), (6, 3), (6, 4), (8, 2), (8, 3), (20, 2), (4, 8)])
def test_wide_logsignature_matches_iisignature(rng, d, m):
    x = _paths(rng, 2, 6, d)
    ref = iisignature.logsig(x, iisignature.prepare(d, m))
    # at depth 8 a Lyndon coordinate is a sum of many O(1) terms that cancel: both libraries round
    # them differently by about 1e-12
    np.testing.assert_allclose(logsignature(x, m), ref, rtol=0, atol=TOL if m < 8 else 1e-11)


@pytest.mark.parametrize("d,m", [(6, 3), (8, 3), (6, 4), (8, 2), (20, 2)])
def test_wide_vjp_matches_iisignature(rng, d, m):
    x = rng.standard_normal((2, 5, d)) * 0.5
    g = rng.standard_normal((2, sigdim(d, m)))
    ref = iisignature.sigbackprop(g, x, m)
    np.testing.assert_allclose(signature_vjp(x, m, g), ref, rtol=0, atol=1e-5 * (1 + np.abs(ref).max()))
    gl = rng.standard_normal((2, logsigdim(d, m)))
    refl = iisignature.logsigbackprop(gl, x, iisignature.prepare(d, m))
    np.testing.assert_allclose(logsignature_vjp(x, m, gl), refl, rtol=0,
                               atol=1e-5 * (1 + np.abs(refl).max()))


@pytest.mark.parametrize("d,m", [(3, 4), (8, 3), (8, 2)])
def test_member_bits_do_not_depend_on_the_batch_size(rng, d, m):
    x = _paths(rng, 10, 12, d)
    g = rng.standard_normal((10, sigdim(d, m)))
    alone = signature(x[:1], m)[0]
    alone_vjp = signature_vjp(x[:1], m, g[:1])[0]
    for b in range(1, 11):
        assert signature(x[:b], m)[0].tobytes() == alone.tobytes(), b
        assert signature_vjp(x[:b], m, g[:b])[0].tobytes() == alone_vjp.tobytes(), b
    # the last member of a batch of 9 (alone in its lane group) is as computed alone
    assert signature(x[:9], m)[8].tobytes() == signature(x[8:9], m)[0].tobytes()


@pytest.mark.parametrize("d,m", [(6, 4), (7, 3), (8, 3), (8, 4), (20, 3)])
def test_wide_vjp_matches_central_differences_of_iisignature(rng, d, m):
    # the wide kernels (d >= 6: fused Horner step, dot products in four sums, tails at d = 6, 7)
    # against a directional derivative of an independent forward signature: <vjp, v> equals
    # (<g, sig(x + h v)> - <g, sig(x - h v)>) / 2h up to O(h^2) and rounding
    x = _paths(rng, 2, 6, d)
    v = rng.standard_normal(x.shape)
    g = rng.standard_normal((2, sigdim(d, m)))
    h = 1e-5
    fd = (np.sum(g * iisignature.sig(x + h * v, m), axis=-1)
          - np.sum(g * iisignature.sig(x - h * v, m), axis=-1)) / (2 * h)
    got = np.sum(signature_vjp(x, m, g) * v, axis=(-2, -1))
    np.testing.assert_allclose(got, fd, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("n", [62, 63, 64])
def test_both_layout_routes_match_iisignature(rng, n):
    """d = 2, depth 6 (sigdim 126): paths with n d < 126 go through the time-reversed input (whose
    reversed-layout signature is the row-major one), the others through the permutation."""
    x = _paths(rng, 3, n, 2)
    np.testing.assert_allclose(signature(x, 6), iisignature.sig(x, 6), rtol=0, atol=TOL)
    np.testing.assert_array_equal(signature(x[1:2], 6)[0], signature(x, 6)[1])


def test_wide_level2_lane_groups_with_chunks_and_a_tail(rng):
    """d >= 6 level 2: 9 paths run as one lane group of 8 and one path alone; a path of 16 500 points is
    cut into 2 chunks. Equal to iisignature, and every member equal bit for bit to itself alone."""
    x = _paths(rng, 9, 16_500, 6)
    s = signature(x, 2)
    np.testing.assert_allclose(s, iisignature.sig(x, 2), rtol=0, atol=1e-11)
    ls = logsignature(x, 2)
    for b in (0, 7, 8):
        np.testing.assert_array_equal(signature(x[b:b + 1], 2)[0], s[b])
        np.testing.assert_array_equal(logsignature(x[b:b + 1], 2)[0], ls[b])


@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_empty_batch_has_the_shapes_of_the_layouts(m):
    # an empty batch (0 paths) gives empty results of the documented widths (depth >= 3 used to fail on a reshape)
    x = np.zeros((0, 5, 3))
    assert signature(x, m).shape == (0, sigdim(3, m))
    assert logsignature(x, m).shape == (0, logsigdim(3, m))
    assert signature_vjp(x, m, np.zeros((0, sigdim(3, m)))).shape == (0, 5, 3)
    assert logsignature_vjp(x, m, np.zeros((0, logsigdim(3, m)))).shape == (0, 5, 3)


def test_results_do_not_depend_on_the_input_layout(rng):
    # float64 C arrays are taken as they are, other layouts and dtypes converted: the same values either way
    # (iisignature's sigbackprop answers in float32: compared to 1e-5)
    x = _paths(rng, 4, 9, 3)
    g = rng.standard_normal((4, sigdim(3, 3)))
    for xi in (x, np.asfortranarray(x), x.astype(np.float32), x[::-1][::-1], x.tolist()):
        xr = np.asarray(xi, dtype=np.float64)
        np.testing.assert_allclose(signature(xi, 3), iisignature.sig(xr, 3), rtol=0, atol=TOL)
        ref = iisignature.sigbackprop(g, xr, 3)
        np.testing.assert_allclose(signature_vjp(xi, 3, g), ref, rtol=0, atol=1e-5 * (1 + np.abs(ref).max()))
        assert np.array_equal(signature_vjp(xi, 3, g), signature_vjp(np.ascontiguousarray(xr), 3, g))
