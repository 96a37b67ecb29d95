"""Claim: ``signature_kernel`` is the untruncated signature inner product, computed by the second-order
Goursat scheme of pysiglib/sigkernel on the dyadically refined grid; its Gram matrices, broadcasting and
VJPs (exact for the discretised kernel) are right, bitwise independent of threads and batch.

Oracles: the truncated signature inner product ``1 + <S(x), S(y)>`` at depth 12 (the PDE converges to it
like ``4**-dyadic_order``, fitted slope); a naive full-grid reimplementation of the scheme written here;
pysiglib (to 1e-8 relative, only where importable); central finite differences for the gradients.
"""

import numba
import numpy as np
import pytest

import roughpaths as rp
from roughpaths import _threads
from _oracles import naive_signature_kernel as _naive_kernel


def _paths(shape, seed, scale=0.4):
    return np.random.default_rng(seed).normal(size=shape).cumsum(axis=-2) * scale


@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("sigma", [None, 0.8])
def test_matches_naive_scheme(order, sigma):
    x, y = _paths((4, 5, 3), 1), _paths((4, 7, 3), 2)
    sk = None if sigma is None else rp.RBFKernel(sigma)
    got = rp.signature_kernel(x, y, dyadic_order=order, static_kernel=sk)
    want = [_naive_kernel(x[i], y[i], order, sigma) for i in range(4)]
    np.testing.assert_allclose(got, want, rtol=1e-13)


def test_converges_to_truncated_signature_inner_product():
    x, y = _paths((3, 5, 2), 5, 0.5), _paths((3, 6, 2), 6, 0.5)
    exact = 1 + np.sum(rp.signature(x, 12) * rp.signature(y, 12), axis=-1)
    orders = np.arange(1, 6)
    errs = [np.abs(rp.signature_kernel(x, y, dyadic_order=int(o)) - exact).max() for o in orders]
    slope = np.polyfit(orders, np.log2(errs), 1)[0]
    assert -2.6 < slope < -1.6, (slope, errs)        # second order in the step: 4**-dyadic_order
    assert errs[-1] < 2e-4


def test_linear_scale_is_path_scaling():
    x, y = _paths((2, 6, 2), 7), _paths((2, 5, 2), 8)
    a = rp.signature_kernel(x, y, dyadic_order=1, static_kernel=rp.LinearKernel(1.7))
    b = rp.signature_kernel(1.7 * x, 1.7 * y, dyadic_order=1)
    np.testing.assert_allclose(a, b, rtol=1e-13)


def test_gram_broadcasting_and_trivial_paths():
    X, Y = _paths((2, 3, 5, 2), 9), _paths((1, 4, 6, 2), 10)
    K = rp.signature_kernel_gram(X, Y, dyadic_order=1)
    assert K.shape == (2, 3, 4)
    pair = rp.signature_kernel(X[:, :, None], Y[:, None], dyadic_order=1)
    np.testing.assert_array_equal(K, pair)
    k = rp.signature_kernel(X[0, 0], Y[0, 1])
    assert np.shape(k) == () and k == rp.signature_kernel_gram(X[0], Y[0])[0, 1]
    assert rp.signature_kernel(X[0, 0, :1], Y[0, 1]) == 1.0          # a single point: S = 1
    assert rp.signature_kernel_gram(X[:, :0], Y).shape == (2, 0, 4)


def _fd(f, a, h=1e-6):
    g = np.zeros_like(a)
    for idx in np.ndindex(a.shape):
        e = np.zeros_like(a)
        e[idx] = h
        g[idx] = (f(a + e) - f(a - e)) / (2 * h)
    return g


@pytest.mark.parametrize("order,sigma", [(0, None), (2, None), (1, 0.7)])
def test_vjp_matches_finite_differences(order, sigma):
    x, y = _paths((2, 4, 2), 11), _paths((2, 5, 2), 12)
    w = np.array([0.7, -1.3])
    kw = dict(dyadic_order=order, static_kernel=None if sigma is None else rp.RBFKernel(sigma))
    gx, gy = rp.signature_kernel_vjp(x, y, w, **kw)
    np.testing.assert_allclose(gx, _fd(lambda a: w @ rp.signature_kernel(a, y, **kw), x), rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(gy, _fd(lambda a: w @ rp.signature_kernel(x, a, **kw), y), rtol=1e-6, atol=1e-8)


def test_gram_vjp_matches_finite_differences_and_broadcast_vjp():
    X, Y = _paths((3, 4, 2), 13), _paths((2, 3, 2), 14)
    W = np.random.default_rng(15).normal(size=(3, 2))
    gX, gY = rp.signature_kernel_gram_vjp(X, Y, W, dyadic_order=1)
    np.testing.assert_allclose(gX, _fd(lambda a: np.sum(W * rp.signature_kernel_gram(a, Y, dyadic_order=1)), X),
                               rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(gY, _fd(lambda a: np.sum(W * rp.signature_kernel_gram(X, a, dyadic_order=1)), Y),
                               rtol=1e-6, atol=1e-8)
    # one x against a batch of y: the cotangent of x sums over the batch
    gx, gy = rp.signature_kernel_vjp(X[0], Y, W[0], dyadic_order=1)
    gX0, _ = rp.signature_kernel_gram_vjp(X[:1], Y, W[:1], dyadic_order=1)
    np.testing.assert_allclose(gx, gX0[0], rtol=1e-12)
    assert gy.shape == Y.shape


def test_bitwise_independent_of_threads_and_batch(monkeypatch):
    X, Y = _paths((20, 9, 3), 16), _paths((7, 11, 3), 17)
    monkeypatch.setattr(_threads, "SERIAL_WORK", 1)      # split even this small job
    monkeypatch.setattr(_threads, "RANGE_WORK", 1)
    before = numba.get_num_threads()
    results = []
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            K = rp.signature_kernel_gram(X, Y, dyadic_order=1, static_kernel=rp.RBFKernel(1.5))
            g = rp.signature_kernel_gram_vjp(X, Y, np.ones((20, 7)), dyadic_order=1)
            results.append((K, g))
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1][0], results[1][1][0])
    alone = rp.signature_kernel(X[13], Y[5], dyadic_order=1, static_kernel=rp.RBFKernel(1.5))
    assert alone == results[0][0][13, 5]
    gx, gy = rp.signature_kernel_vjp(X[13], Y[5], 1.0, dyadic_order=1)
    gx_b, gy_b = rp.signature_kernel_vjp(X[10:14], Y[2:6], np.array([0.0, 0.0, 0.0, 1.0]), dyadic_order=1)
    np.testing.assert_array_equal(gx, gx_b[3])
    np.testing.assert_array_equal(gy, gy_b[3])


@pytest.mark.parametrize("order,sigma", [(0, None), (2, None), (1, 0.9), (3, None)])
def test_matches_pysiglib(order, sigma):
    pysiglib = pytest.importorskip("pysiglib")
    x, y = _paths((6, 12, 3), 18, 0.3), _paths((6, 9, 3), 19, 0.3)
    ours = rp.signature_kernel(x, y, dyadic_order=order, static_kernel=None if sigma is None else rp.RBFKernel(sigma))
    # pysiglib's RBFKernel(s) is exp(-|u - v|^2 / s): s = 2 sigma^2
    theirs = pysiglib.sig_kernel(x, y, dyadic_order=order,
                                 static_kernel=None if sigma is None else pysiglib.RBFKernel(2 * sigma ** 2))
    np.testing.assert_allclose(ours, theirs, rtol=1e-8)


def test_vjp_matches_pysiglib():
    pysiglib = pytest.importorskip("pysiglib")
    x, y = _paths((4, 10, 3), 20, 0.3), _paths((4, 8, 3), 21, 0.3)
    w = np.array([1.0, -0.5, 2.0, 0.3])
    ours = rp.signature_kernel_vjp(x, y, w, dyadic_order=2)
    theirs = pysiglib.sig_kernel_backprop(w, x, y, dyadic_order=2, left_deriv=True, right_deriv=True)
    for a, b in zip(ours, theirs):
        np.testing.assert_allclose(a, b, rtol=1e-8, atol=1e-12 * np.abs(b).max())


@pytest.mark.parametrize("call,match", [
    (lambda: rp.signature_kernel(np.zeros((4, 2)), np.zeros((4, 3))), "d=2 coordinates.*y has d=3"),
    (lambda: rp.signature_kernel(np.zeros((4, 2)), np.zeros((4, 2)), dyadic_order=-1), "dyadic_order"),
    (lambda: rp.signature_kernel(np.zeros((4, 2)), np.zeros((4, 2)), dyadic_order=1.5), "dyadic_order"),
    (lambda: rp.signature_kernel(np.zeros((4, 2)), np.zeros((4, 2)), dyadic_order=40), "dyadic_order <= 20"),
    (lambda: rp.signature_kernel(np.array([[0.0, np.nan], [1.0, 2.0]]), np.zeros((4, 2))), "x contains 1 non-finite"),
    (lambda: rp.signature_kernel(np.zeros(4), np.zeros((4, 1))), "x must have at least 2 axes"),
    (lambda: rp.signature_kernel(np.zeros((3, 4, 2)), np.zeros((2, 4, 2))), "batch axes of x"),
    (lambda: rp.signature_kernel_gram(np.zeros((4, 2)), np.zeros((3, 4, 2))), "X must have at least 3 axes"),
    (lambda: rp.signature_kernel(np.zeros((4, 2)), np.zeros((4, 2)), static_kernel="rbf"), "RBFKernel"),
    (lambda: rp.RBFKernel(0.0), "sigma"),
    (lambda: rp.LinearKernel(-1.0), "scale"),
    (lambda: rp.signature_kernel_vjp(np.zeros((2, 4, 2)), np.zeros((2, 4, 2)), np.ones(3)), "grad_output"),
    (lambda: rp.signature_kernel_gram_vjp(np.zeros((2, 4, 2)), np.zeros((3, 4, 2)), np.ones((3, 2))),
     r"expected \(2, 3\)"),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises((ValueError, TypeError), match=match):
        call()
