"""``roughpaths.torch``: the numpy signatures as torch autograd functions.

Claims: the forward values are the numpy API's (1e-12 in float64, float32 rounding in float32);
the gradients pass ``torch.autograd.gradcheck`` (central differences, float64) and are the numpy
VJPs; a few Adam steps through each function lower a loss; bad tensors (non-tensor, meta device,
integer or half dtype, mixed dtypes) are refused with the fix named. The signature-kernel wrappers
are checked the same way (values, keywords, batch broadcasting, gradcheck, Adam steps).
"""

from __future__ import annotations

import importlib.util
import os

import numpy as np
import pytest

import roughpaths as rp

if os.environ.get("CI") and importlib.util.find_spec("torch") is None:
    raise ImportError("torch is not installed under CI=true; ./test.sh installs the torch extra")
torch = pytest.importorskip("torch", reason="the torch extra is not installed (pip install -e '.[torch]')")
rpt = pytest.importorskip("roughpaths.torch")



def _paths(shape, seed=0):
    return np.random.default_rng(seed).standard_normal(shape).cumsum(axis=-2) * 0.5


@pytest.mark.parametrize("name, depth", [("signature", 1), ("signature", 3), ("logsignature", 2),
                                         ("logsignature", 4)])
def test_forward_equals_numpy(name, depth):
    x = _paths((2, 3, 7, 3))
    got = getattr(rpt, name)(torch.from_numpy(x), depth)
    want = getattr(rp, name)(x, depth)
    assert got.dtype == torch.float64 and got.shape == want.shape
    np.testing.assert_allclose(got.numpy(), want, rtol=0, atol=1e-12)
    got32 = getattr(rpt, name)(torch.from_numpy(x).float(), depth)
    assert got32.dtype == torch.float32
    np.testing.assert_allclose(got32.numpy(), getattr(rp, name)(x.astype(np.float32), depth), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("name, depth", [("signature", 2), ("signature", 4), ("logsignature", 3)])
def test_gradcheck_and_numpy_vjp(name, depth):
    x = torch.from_numpy(_paths((2, 5, 2), seed=1)).requires_grad_()
    fn = getattr(rpt, name)
    assert torch.autograd.gradcheck(lambda p: fn(p, depth), (x,), eps=1e-6, atol=1e-7)
    g = np.random.default_rng(2).standard_normal(fn(x, depth).shape)
    fn(x, depth).backward(torch.from_numpy(g))
    want = getattr(rp, name + "_vjp")(x.detach().numpy(), depth, g)
    np.testing.assert_allclose(x.grad.numpy(), want, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["signature", "logsignature"])
def test_adam_steps_lower_a_loss(name):
    """Move a path so that its depth-3 (log-)signature approaches another path's."""
    fn = getattr(rpt, name)
    target = fn(torch.from_numpy(_paths((6, 2), seed=3)), 3)
    x = torch.from_numpy(_paths((6, 2), seed=4)).float().requires_grad_()
    opt = torch.optim.Adam([x], lr=0.05)
    losses = []
    for _ in range(15):
        opt.zero_grad()
        loss = ((fn(x, 3) - target.float()) ** 2).sum()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert x.grad.dtype == torch.float32
    assert losses[-1] < 0.5 * losses[0], losses


def test_no_grad_and_second_derivative():
    x = torch.from_numpy(_paths((4, 2))).requires_grad_()
    with torch.no_grad():
        assert not rpt.signature(x, 2).requires_grad
    (g,) = torch.autograd.grad(rpt.signature(x, 2).sum(), x, create_graph=True)
    with pytest.raises(RuntimeError, match="first derivatives only.*create_graph=True"):
        g.sum().backward()


@pytest.mark.parametrize("call", [lambda x: rpt.signature(x, 3), lambda x: rpt.logsignature(x, 3),
                                  lambda x: rpt.signature_kernel(x, 0.5 * x),
                                  lambda x: rpt.signature_kernel_gram(x[None], x[None])])
def test_a_gradient_penalty_is_refused_not_silently_constant(call):
    # a gradient penalty (WGAN-GP, input-gradient regularisation) differentiates the gradient again; with a
    # constant cotangent (a fixed linear read-out) the gradient came back as a plain tensor, and the penalty's
    # dependence on x was silently dropped: loss.backward() ran and gave the gradient of the first term only
    x = torch.from_numpy(_paths((5, 2), seed=3) * 0.3).requires_grad_()
    out = call(x)
    w = torch.from_numpy(np.random.default_rng(4).standard_normal(tuple(out.shape)))   # fixed read-out
    loss = (out * w).sum()
    (g,) = torch.autograd.grad(loss, x, create_graph=True)
    assert g.requires_grad
    with pytest.raises(RuntimeError, match="first derivatives only"):
        (loss + (g ** 2).sum()).backward()
    x.grad = None
    (g,) = torch.autograd.grad((call(x) * w).sum(), x)          # without create_graph: a plain gradient
    assert not g.requires_grad and torch.isfinite(g).all()


@pytest.mark.parametrize("make, exc, words", [
    (lambda: np.zeros((3, 2)), TypeError, ["paths must be a torch.Tensor", "torch.as_tensor"]),
    (lambda: torch.zeros(3, 2, device="meta"), ValueError, ["meta", "CPU"]),
    (lambda: torch.zeros(3, 2, dtype=torch.int64), TypeError, ["torch.int64", "paths.double()"]),
    (lambda: torch.zeros(3, 2, dtype=torch.float16), TypeError, ["torch.float16", "float32 or float64"]),
])
def test_bad_tensors_are_refused(make, exc, words):
    with pytest.raises(exc) as info:
        rpt.signature(make(), 2)
    for w in words:
        assert w in str(info.value)


# ------------------------------------------------------------------ signature kernels
def test_kernel_broadcasting_and_batched_gram():
    x = torch.from_numpy(_paths((3, 5, 2), seed=5)).requires_grad_()
    y = torch.from_numpy(_paths((6, 2), seed=6)).requires_grad_()        # broadcast against x's batch
    k = rpt.signature_kernel(x, y, dyadic_order=2)
    assert k.shape == (3,)
    np.testing.assert_allclose(k.detach().numpy(), rp.signature_kernel(x.detach().numpy(), y.detach().numpy(),
                                                                       dyadic_order=2), rtol=1e-13)
    assert torch.autograd.gradcheck(lambda a, b: rpt.signature_kernel(a, b), (x, y))
    X = torch.from_numpy(_paths((2, 3, 4, 2), seed=7)).requires_grad_()
    Y = torch.from_numpy(_paths((2, 5, 6, 2), seed=8)).requires_grad_()
    assert rpt.signature_kernel_gram(X, Y).shape == (2, 3, 5)
    assert torch.autograd.gradcheck(lambda a, b: rpt.signature_kernel_gram(a, b), (X, Y))




def test_kernels_equal_numpy_and_gradcheck():
    x, y = _paths((2, 5, 2), seed=9), _paths((2, 4, 2), seed=10)
    X, Y = _paths((3, 5, 2), seed=11), _paths((2, 4, 2), seed=12)
    for order in (0, 1):
        got = rpt.signature_kernel(torch.from_numpy(x), torch.from_numpy(y), dyadic_order=order)
        np.testing.assert_allclose(got.numpy(), rp.signature_kernel(x, y, dyadic_order=order), rtol=0, atol=1e-12)
        got = rpt.signature_kernel_gram(torch.from_numpy(X), torch.from_numpy(Y), dyadic_order=order)
        np.testing.assert_allclose(got.numpy(), rp.signature_kernel_gram(X, Y, dyadic_order=order), rtol=0,
                                   atol=1e-12)
    tx, ty = torch.from_numpy(x).requires_grad_(), torch.from_numpy(y).requires_grad_()
    assert torch.autograd.gradcheck(lambda a, b: rpt.signature_kernel(a, b, dyadic_order=1), (tx, ty))
    tX, tY = torch.from_numpy(X).requires_grad_(), torch.from_numpy(Y).requires_grad_()
    assert torch.autograd.gradcheck(lambda a, b: rpt.signature_kernel_gram(a, b), (tX, tY))


def test_kernel_adam_steps_lower_a_loss():
    """Pull a batch of paths towards a reference in the kernel's distance k(x,x) - 2 k(x,y) + k(y,y)."""
    y = torch.from_numpy(_paths((4, 6, 2), seed=13)).float()
    x = torch.from_numpy(_paths((4, 6, 2), seed=14)).float().requires_grad_()
    opt = torch.optim.Adam([x], lr=0.05)
    losses = []
    for _ in range(10):
        opt.zero_grad()
        loss = (rpt.signature_kernel(x, x) - 2 * rpt.signature_kernel(x, y)).sum()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert losses[-1] < losses[0], losses


@pytest.mark.parametrize("name, depth", [("signature", 2), ("signature", 3), ("logsignature", 3)])
def test_backward_leaves_the_cotangent_unchanged(name, depth):
    # the library's VJPs receive torch's cotangent without a protective copy: they must only read it
    x = torch.from_numpy(_paths((3, 7, 2))).requires_grad_()
    out = getattr(rpt, name)(x, depth)
    g = torch.from_numpy(np.random.default_rng(1).standard_normal(tuple(out.shape)))
    before = g.clone()
    out.backward(g)
    assert torch.equal(g, before)


def test_an_overflowing_signature_is_refused_not_returned_as_inf_or_nan():
    x = torch.from_numpy(_paths((3, 6, 2), seed=5) * 1e110).requires_grad_()
    with pytest.raises(ValueError, match="overflows float64.*Rescale the paths"):
        rpt.signature(x, 3)
    with pytest.raises(ValueError, match="overflows float64.*Rescale the paths"):
        rpt.logsignature(x, 3)


def test_kernel_batch_axes_that_do_not_broadcast_are_named():
    x = torch.from_numpy(_paths((3, 5, 2), seed=1))
    with pytest.raises(ValueError, match=r"batch axes of x \(3,\), y \(2,\) do not broadcast"):
        rpt.signature_kernel(x, x[:2])
    with pytest.raises(ValueError, match=r"batch axes of X \(3,\), Y \(2,\) do not broadcast"):
        rpt.signature_kernel_gram(x[:, None], x[:2, None])


@pytest.mark.parametrize("transform", [lambda f: torch.func.vmap(f), lambda f: torch.func.jacrev(f),
                                       lambda f: torch.func.grad(lambda z: f(z).sum())])
def test_torch_func_transforms_are_refused_with_the_fix(transform):
    # torch's own error spoke of a missing setup_context staticmethod, which the caller cannot add
    x = torch.from_numpy(_paths((4, 6, 2)))
    with pytest.raises(TypeError, match="torch.func transform.*Batch with leading axes"):
        transform(lambda z: rpt.signature(z, 2))(x)
    with pytest.raises(TypeError, match="torch.func transform"):
        transform(lambda z: rpt.signature_kernel(z, z))(x)
    assert torch.func.vmap(rpt.lead_lag)(x).shape == (4, 11, 4)      # the transforms are torch operations


def test_the_numpy_api_given_a_tensor_in_a_graph_names_the_differentiable_function():
    # torch's own advice, ".detach().numpy()", would silently drop the gradient the caller is after
    x = torch.from_numpy(_paths((5, 2))).requires_grad_()
    for call in (lambda: rp.signature(x, 2), lambda: rp.lead_lag(x)):
        with pytest.raises(TypeError, match=r"roughpaths.torch function of the same name.*paths.detach\(\).numpy\(\)"):
            call()


@pytest.mark.parametrize("name", ["signature", "logsignature"])
def test_a_float32_result_beyond_float32s_range_is_refused_not_returned_as_inf(name):
    # computed in float64 (finite, ~1e42) and rounded to float32: it came back as inf without an error
    f = getattr(rpt, name)
    x = torch.tensor(_paths((2, 6, 2), seed=6) * 1e14, dtype=torch.float32, requires_grad=True)
    with pytest.raises(ValueError, match=rf"result of {name} overflows float32.*Rescale paths.*paths\.double\(\)"):
        f(x, 3)
    assert torch.isfinite(f(x.double(), 3)).all()                   # float64 holds it
    assert torch.isfinite(f(x / 1e14, 3)).all()


def test_a_float32_gradient_beyond_float32s_range_is_refused_not_returned_as_inf():
    x = torch.tensor(_paths((2, 6, 2), seed=6) * 1e10, dtype=torch.float32, requires_grad=True)
    s = rpt.signature(x, 3)
    assert torch.isfinite(s).all()
    with pytest.raises(ValueError, match=r"gradient of signature with respect to paths overflows float32.*double"):
        s.backward(torch.full_like(s, 1e20))
    x64 = x.detach().double().requires_grad_()
    s64 = rpt.signature(x64, 3)
    s64.backward(torch.full_like(s64, 1e20))
    assert torch.isfinite(x64.grad).all() and x64.grad.abs().max() > 3.5e38


def test_a_float32_kernel_beyond_float32s_range_is_refused():
    x = torch.tensor(_paths((4, 2), seed=7) * 1e3, dtype=torch.float32)
    with pytest.raises(ValueError, match=r"result of signature_kernel overflows float32.*x and y"):
        rpt.signature_kernel(x, x)
