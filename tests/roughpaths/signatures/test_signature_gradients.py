"""Claim: ``signature_vjp`` / ``logsignature_vjp`` are the vector–Jacobian products of the signature maps.

For a cotangent ``G``, ``signature_vjp(x, m, G)[k, a] = d <G, S(x)> / d x[k, a]``. Oracles:

* a naive signature written here (Chen products of tensor exponentials on dense level arrays)
  differentiated by the complex step ``Im <G, S(x + i h e_{k,a})> / h`` (exact to rounding, no
  subtraction error);
* central finite differences of ``logsignature`` for the log-signature;
* ``iisignature.sigbackprop`` / ``logsigbackprop`` (which return float32: compared at 1e-5).
"""

import iisignature
import numpy as np
import pytest

from roughpaths import logsigdim, logsignature, logsignature_vjp, sigdim, signature_vjp


def _naive_sig(x, m):
    """Dense levels of the signature of a piecewise-linear path (works for complex input)."""
    d = x.shape[-1]
    levels = [np.zeros((d,) * k, dtype=x.dtype) for k in range(1, m + 1)]
    for a, b in zip(x[:-1], x[1:]):
        dx = b - a
        exp = [dx]
        for k in range(2, m + 1):
            exp.append(np.multiply.outer(exp[-1], dx) / k)
        new = []
        for k in range(1, m + 1):
            t = levels[k - 1] + exp[k - 1]
            for i in range(1, k):
                t = t + np.multiply.outer(levels[i - 1], exp[k - i - 1])
            new.append(t)
        levels = new
    return np.concatenate([lv.reshape(-1) for lv in levels])


def _complex_step_vjp(x, m, g, h=1e-30):
    out = np.zeros(x.shape)
    for k in range(x.shape[0]):
        for a in range(x.shape[1]):
            xc = x.astype(complex)
            xc[k, a] += 1j * h
            out[k, a] = np.dot(g, _naive_sig(xc, m)).imag / h
    return out


@pytest.mark.parametrize("d,m", [(1, 3), (2, 1), (2, 2), (2, 4), (3, 3), (4, 2), (2, 6)])
def test_signature_vjp_equals_complex_step(rng, d, m):
    x = rng.standard_normal((6, d)) * 0.7
    g = rng.standard_normal(sigdim(d, m))
    np.testing.assert_allclose(signature_vjp(x, m, g), _complex_step_vjp(x, m, g), rtol=0, atol=1e-12)


def test_signature_vjp_batch_axes(rng):
    x = rng.standard_normal((2, 3, 5, 2))
    g = rng.standard_normal((2, 3, sigdim(2, 3)))
    got = signature_vjp(x, 3, g)
    assert got.shape == x.shape
    np.testing.assert_allclose(got[1, 2], _complex_step_vjp(x[1, 2], 3, g[1, 2]), atol=1e-12)


def test_signature_vjp_long_chunked_path(rng):
    """A path long enough to be cut into chunks: the chunk cotangents P ▷ (G ◁ Q) are right."""
    x = np.cumsum(rng.standard_normal((1, 2000, 2)), axis=-2) * 0.03
    g = rng.standard_normal((1, sigdim(2, 3)))
    ref = iisignature.sigbackprop(g, x, 3)
    got = signature_vjp(x, 3, g)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-5 * (1 + np.abs(ref).max()))


@pytest.mark.parametrize("d,m", [(2, 3), (3, 4), (4, 3)])
def test_vjp_matches_iisignature_backprop(rng, d, m):
    x = rng.standard_normal((3, 7, d)) * 0.6
    g = rng.standard_normal((3, sigdim(d, m)))
    ref = iisignature.sigbackprop(g, x, m)
    np.testing.assert_allclose(signature_vjp(x, m, g), ref, rtol=0, atol=1e-5 * (1 + np.abs(ref).max()))
    gl = rng.standard_normal((3, logsigdim(d, m)))
    refl = iisignature.logsigbackprop(gl, x, iisignature.prepare(d, m))
    np.testing.assert_allclose(logsignature_vjp(x, m, gl), refl, rtol=0,
                               atol=1e-5 * (1 + np.abs(refl).max()))


@pytest.mark.parametrize("d,m", [(2, 1), (1, 3), (2, 4), (3, 3), (3, 5)])
def test_logsignature_vjp_equals_finite_differences(rng, d, m):
    x = rng.standard_normal((5, d)) * 0.6
    g = rng.standard_normal(logsigdim(d, m))
    h = 1e-6
    fd = np.zeros(x.shape)
    for k in range(x.shape[0]):
        for a in range(d):
            e = np.zeros(x.shape)
            e[k, a] = h
            fd[k, a] = np.dot(g, logsignature(x + e, m) - logsignature(x - e, m)) / (2 * h)
    np.testing.assert_allclose(logsignature_vjp(x, m, g), fd, rtol=0, atol=1e-7)


def test_vjp_bad_grad_shape(rng):
    x = rng.standard_normal((4, 5, 2))
    with pytest.raises(ValueError, match="grad_output"):
        signature_vjp(x, 2, np.zeros((4, 5)))
    with pytest.raises(ValueError, match="grad_output"):
        logsignature_vjp(x, 2, np.zeros((4, 6)))
