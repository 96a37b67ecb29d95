"""``roughpaths.jax``: the numpy signatures as ``custom_vjp`` functions over an XLA FFI host call.

Claims: with x64 the values are the numpy API's to 1e-12, eagerly, under ``jit`` and under ``vmap``
(which calls the numpy function once, with the mapped axis in front, not once per element); float32
in gives float32 out; ``jax.test_util.check_grads`` (reverse mode, float64) passes and the
gradients are the numpy VJPs, also under ``jit(vmap(grad))``; a few gradient steps lower a loss;
integer inputs are refused; the call is an XLA custom call (not a ``pure_callback``), an error raised by the
numpy API reaches the caller with its message, and where the FFI target cannot be registered the
``pure_callback`` fallback (also on other backends than the CPU) gives the same values and gradients. The signature-kernel wrappers are checked the same way (values, batch
broadcasting, ``check_grads``, jit/vmap, gradient steps).
"""

from __future__ import annotations

import importlib.util
import math
import os
import re
import subprocess
import sys

from functools import partial

import numpy as np
import pytest

import roughpaths as rp

if os.environ.get("CI") and importlib.util.find_spec("jax") is None:
    raise ImportError("jax is not installed under CI=true; ./test.sh installs the jax extra")
jax = pytest.importorskip("jax", reason="the jax extra is not installed (pip install -e '.[jax]')")
rpj = pytest.importorskip("roughpaths.jax")
import jax.numpy as jnp  # noqa: E402
from jax.test_util import check_grads  # noqa: E402



@pytest.fixture
def x64():
    """jax_enable_x64 for one test, restored afterwards (it is process-wide)."""
    old = jax.config.read("jax_enable_x64")
    jax.config.update("jax_enable_x64", True)
    yield
    jax.config.update("jax_enable_x64", old)


def _paths(shape, seed=0):
    return np.random.default_rng(seed).standard_normal(shape).cumsum(axis=-2) * 0.5


@pytest.mark.parametrize("name, depth", [("signature", 3), ("logsignature", 4)])
def test_eager_jit_vmap_equal_numpy(x64, name, depth):
    x = _paths((4, 7, 3))
    want = getattr(rp, name)(x, depth)
    fn = getattr(rpj, name)
    for got in (fn(x, depth), jax.jit(fn, static_argnums=1)(x, depth), jax.vmap(lambda p: fn(p, depth))(x),
                jax.jit(jax.vmap(lambda p: fn(p, depth)))(x)):
        assert got.dtype == jnp.float64 and got.shape == want.shape
        np.testing.assert_allclose(np.asarray(got), want, rtol=0, atol=1e-12)


def test_vmap_is_one_batched_call(monkeypatch):
    calls = []
    real = rp.signature
    monkeypatch.setattr(rp, "signature", lambda x, depth: calls.append(x.shape) or real(x, depth))
    out = jax.vmap(jax.vmap(lambda p: rpj.signature(p, 2)))(jnp.zeros((3, 5, 4, 2)))
    assert out.shape == (3, 5, 6) and calls == [(3, 5, 4, 2)]


def test_float32_in_float32_out():
    x = _paths((3, 6, 2)).astype(np.float32)
    got = rpj.signature(x, 3)
    assert got.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(got), rp.signature(x, 3), rtol=1e-6, atol=1e-6)
    g = jax.grad(lambda p: rpj.logsignature(p, 3).sum())(jnp.asarray(x))
    assert g.dtype == jnp.float32 and g.shape == x.shape


@pytest.mark.parametrize("name, depth", [("signature", 2), ("signature", 4), ("logsignature", 3)])
def test_check_grads_and_numpy_vjp(x64, name, depth):
    x = jnp.asarray(_paths((2, 5, 2), seed=1))
    fn = getattr(rpj, name)
    check_grads(lambda p: fn(p, depth), (x,), order=1, modes=["rev"])
    g = np.random.default_rng(2).standard_normal(fn(x, depth).shape)
    want = getattr(rp, name + "_vjp")(np.asarray(x), depth, g)
    got = jax.vjp(lambda p: fn(p, depth), x)[1](jnp.asarray(g))[0]
    np.testing.assert_allclose(np.asarray(got), want, rtol=0, atol=1e-12)
    per_path = jax.jit(jax.vmap(jax.grad(lambda p, gi: jnp.vdot(fn(p, depth), gi))))(x, jnp.asarray(g))
    np.testing.assert_allclose(np.asarray(per_path), want, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["signature", "logsignature"])
def test_gradient_steps_lower_a_loss(name):
    fn = getattr(rpj, name)
    target = fn(_paths((6, 2), seed=3), 3)
    loss = jax.jit(lambda p: jnp.sum((fn(p, 3) - target) ** 2))
    x = jnp.asarray(_paths((6, 2), seed=4), dtype=jnp.float32)
    first = loss(x)
    step = jax.jit(lambda p: p - 0.02 * jax.grad(loss)(p))
    for _ in range(15):
        x = step(x)
    assert loss(x) < 0.5 * first, (float(first), float(loss(x)))


@pytest.mark.parametrize("bad, exc, words", [
    (np.zeros((3, 2), dtype=np.int32), TypeError, ["int32", "float32 or float64"]),
    ("paths", TypeError, ["array of floats"]),
    (np.zeros(3), ValueError, ["at least 2 axes"]),
])
def test_bad_input_is_refused(bad, exc, words):
    with pytest.raises(exc) as info:
        rpj.signature(bad, 2)
    for w in words:
        assert w in str(info.value)


@pytest.mark.parametrize("name", ["signature", "logsignature"])
def test_a_request_beyond_the_memory_budget_is_refused_before_xla_allocates_its_result(monkeypatch, name):
    # XLA allocates the result buffer before the host call (where the numpy API checks the memory) runs: depth 12 in
    # d = 4 (2.2e7 floats a path) was traced, its result allocated, and refused only then, as a JaxRuntimeError (at
    # depth 30, 1.5e16 bytes, XLA's own RESOURCE_EXHAUSTED, naming neither depth nor a fix)
    monkeypatch.setenv("ROUGHPATHS_MAX_BYTES", str(256 * 2 ** 20))
    x = jnp.zeros((1, 3, 4))
    fn = getattr(rpj, name)
    for call in (lambda: fn(x, 12), lambda: jax.jit(lambda p: fn(p, 12)).lower(x)):
        with pytest.raises(ValueError, match=r"depth=12 with d=4 .* would take .*lower depth") as info:
            call()
        assert not isinstance(info.value, jax.errors.JaxRuntimeError)
    with pytest.raises(ValueError, match=r"depth=30 with d=3 .* would take .* TiB"):
        fn(jnp.zeros((2, 5, 3)), 30)
    assert fn(x, 3).shape == (1, (rp.sigdim if name == "signature" else rp.logsigdim)(4, 3))


def test_the_call_is_an_xla_custom_call():
    hlo = jax.jit(lambda p: rpj.signature(p, 2)).lower(jnp.zeros((3, 4, 2))).as_text()
    assert "roughpaths_host_" in hlo and "callback" not in hlo.lower(), hlo


def test_target_names_are_unique_to_the_process():
    """A compiled program names its custom calls (jax's persistent compilation cache keys on it): another
    process must not find a different function under the same name."""
    code = ("import jax.numpy as jnp, roughpaths.jax as rpj, jax\n"
            "print(jax.jit(lambda p: rpj.signature(p, 2)).lower(jnp.zeros((3, 4, 2))).as_text())")
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert other.returncode == 0, other.stderr
    ours = jax.jit(lambda p: rpj.signature(p, 2)).lower(jnp.zeros((3, 4, 2))).as_text()
    name = re.compile(r"roughpaths_host_\w+")
    assert name.search(ours) and name.search(other.stdout)
    assert name.search(ours).group() != name.search(other.stdout).group()


def test_numpy_errors_reach_the_caller():
    with pytest.raises(Exception, match="non-finite") as info:
        jax.block_until_ready(rpj.signature(jnp.full((3, 4, 2), jnp.nan), 2))
    assert "ValueError" in str(info.value)


def test_an_unexpected_error_reaches_the_caller_with_its_traceback():
    def broken(a):
        raise RuntimeError("kernel exploded")
    bad = rpj.differentiable(broken, lambda a, g: g, lambda b, c: b + c[0], names=("a",), core=(0,))
    with pytest.raises(Exception, match="kernel exploded") as info:
        jax.block_until_ready(bad(jnp.ones(3)))
    assert "Traceback" in str(info.value) and "broken" in str(info.value)
    wrong = rpj.differentiable(lambda a: a[:-1], lambda a, g: g, lambda b, c: b + c[0], names=("a",), core=(0,))
    with pytest.raises(Exception, match=r"a result of shape \(2,\) for a buffer of shape \(3,\)"):
        jax.block_until_ready(wrong(jnp.ones(3)))


@pytest.mark.parametrize("why", ["no FFI target registers", "another backend"])
def test_callback_fallback(x64, monkeypatch, why):
    if why == "another backend":
        monkeypatch.setattr(jax, "default_backend", lambda: "gpu")
    else:
        def refuse(*args, **kwargs):
            raise RuntimeError("no FFI here")
        monkeypatch.setattr(jax.ffi, "register_ffi_target", refuse)
    square = rpj.differentiable(lambda a: a ** 2, lambda a, g: 2 * a * g, lambda b, c: b + c[0],
                                names=("a",), core=(0,))
    x = jnp.array([1.0, -2.0, 3.0])
    assert "callback" in jax.jit(square).lower(x).as_text().lower()
    np.testing.assert_array_equal(np.asarray(jax.jit(square)(x)), [1.0, 4.0, 9.0])
    np.testing.assert_array_equal(np.asarray(jax.grad(lambda a: square(a).sum())(x)), [2.0, -4.0, 6.0])
    np.testing.assert_array_equal(np.asarray(jax.vmap(jax.grad(lambda a: square(a).sum()))(x[:, None])),
                                  [[2.0], [-4.0], [6.0]])


# ------------------------------------------------------------------ signature kernels
def test_kernel_broadcasting_and_batched_gram(x64):
    x, y = jnp.asarray(_paths((3, 5, 2), seed=5)), jnp.asarray(_paths((6, 2), seed=6))   # y broadcasts
    k = jax.jit(lambda a, b: rpj.signature_kernel(a, b, dyadic_order=2))(x, y)
    assert k.shape == (3,)
    np.testing.assert_allclose(np.asarray(k), rp.signature_kernel(np.asarray(x), np.asarray(y), dyadic_order=2),
                               rtol=1e-13)
    check_grads(lambda a, b: rpj.signature_kernel(a, b), (x, y), order=1, modes=["rev"])
    X, Y = jnp.asarray(_paths((2, 3, 4, 2), seed=7)), jnp.asarray(_paths((2, 5, 6, 2), seed=8))
    assert jax.vmap(rpj.signature_kernel_gram)(X, Y).shape == (2, 3, 5)
    check_grads(lambda a, b: rpj.signature_kernel_gram(a, b), (X, Y), order=1, modes=["rev"])


def test_kernels_equal_numpy_jit_vmap_and_check_grads(x64):
    x, y = _paths((2, 5, 2), seed=9), _paths((2, 4, 2), seed=10)
    X, Y = _paths((3, 5, 2), seed=11), _paths((2, 4, 2), seed=12)
    for order in (0, 1):
        want = rp.signature_kernel(x, y, dyadic_order=order)
        for got in (rpj.signature_kernel(x, y, dyadic_order=order),
                    jax.jit(lambda a, b: rpj.signature_kernel(a, b, dyadic_order=order))(x, y),
                    jax.vmap(lambda a, b: rpj.signature_kernel(a, b, dyadic_order=order))(x, y)):
            np.testing.assert_allclose(np.asarray(got), want, rtol=0, atol=1e-12)
        got = jax.jit(lambda a, b: rpj.signature_kernel_gram(a, b, dyadic_order=order))(X, Y)
        np.testing.assert_allclose(np.asarray(got), rp.signature_kernel_gram(X, Y, dyadic_order=order), rtol=0,
                                   atol=1e-12)
    check_grads(lambda a, b: rpj.signature_kernel(a, b, dyadic_order=1), (jnp.asarray(x), jnp.asarray(y)),
                order=1, modes=["rev"])
    check_grads(lambda a, b: rpj.signature_kernel_gram(a, b), (jnp.asarray(X), jnp.asarray(Y)), order=1,
                modes=["rev"])


def test_kernel_gradient_steps_lower_a_loss():
    """Gradient steps on the kernel distance k(x,x) - 2 k(x,y) + k(y,y) (dyadic order 2: at order 0 and these
    increments the discretised kernel is not a distance and plain steps diverge)."""
    y = jnp.asarray(_paths((4, 6, 2), seed=13), dtype=jnp.float32)
    kern = partial(rpj.signature_kernel, dyadic_order=2)
    loss = jax.jit(lambda p: jnp.sum(kern(p, p) - 2 * kern(p, y) + kern(y, y)))
    x = jnp.asarray(_paths((4, 6, 2), seed=14), dtype=jnp.float32)
    losses = [float(loss(x))]
    for _ in range(10):
        x = x - 0.01 * jax.grad(loss)(x)
        losses.append(float(loss(x)))
    assert np.all(np.diff(losses) < 0) and losses[-1] < 0.7 * losses[0], losses


def test_host_functions_get_fresh_views_of_the_buffers(x64):
    # the FFI handler reuses its views of XLA's buffers: what a host function does to its argument's
    # shape must not reach the next call
    def forward(a):
        out = a.sum(axis=-1)
        a.shape = (-1,)                      # a rude host function
        return out

    f = rpj.differentiable(forward, lambda a, g: np.broadcast_to(g[..., None], a.shape).copy(),
                           lambda batch, cores: batch + cores[0][:1], names=("a",), core=(2,))
    x = jnp.asarray(_paths((2, 4, 3)))            # float64: the host function gets the view itself, not a copy
    g = jax.jit(lambda a: f(a))
    for _ in range(3):
        np.testing.assert_allclose(np.asarray(g(x)), np.asarray(x).sum(axis=-1), rtol=1e-12)


# ------------------------------------------------------------------ compiled handlers of the signature
def _calls():
    from roughpaths.signatures import xla_handlers
    return xla_handlers.CALLS.copy()


def _step(depth):
    """A jitted value and gradient of <signature(x, depth), G> (the forward and the backward call)."""
    return jax.jit(jax.value_and_grad(lambda p, g: jnp.sum(rpj.signature(p, depth) * g)))


# paths smaller than their signature (run reversed in time) and larger (30 x 3, 40 x 1: the layout permuted);
# kernel variants that tools/warm_kernels.py --more compiles (one-unit gradients of d = 1, 3, 4, 6, 7)
@pytest.mark.parametrize("shape, depth", [((8, 3), 3), ((1, 8, 3), 3), ((2, 5, 3), 4), ((2, 30, 3), 3),
                                          ((2, 40, 1), 3), ((1, 2, 1), 5), ((3, 6, 4), 5), ((2, 1, 6, 6), 4),
                                          ((1, 9, 7), 3)])
@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_compiled_handlers_give_the_numpy_bits(shape, depth, dtype):
    """Where the compiled handlers run (paths the numpy API runs as single work units; the counter says they
    did), the signature and its gradient are the numpy API's to the bit (float64), or its results rounded to
    float32, under jit, eagerly and under vmap (whose axis the handler meets at run time)."""
    old = jax.config.read("jax_enable_x64")
    jax.config.update("jax_enable_x64", dtype == "float64")
    try:
        x = _paths(shape, seed=21).astype(dtype)
        G = np.random.default_rng(22).standard_normal(shape[:-2] + (rp.sigdim(shape[-1], depth),)).astype(dtype)
        want = rp.signature(x.astype(np.float64), depth).astype(dtype)
        want_g = rp.signature_vjp(x.astype(np.float64), depth, G.astype(np.float64)).astype(dtype)
        before = _calls()
        value, grad = _step(depth)(x, G)
        assert np.array_equal(np.asarray(grad), want_g) and grad.dtype == dtype
        assert np.array_equal(np.asarray(rpj.signature(x, depth)), want)
        assert np.array_equal(np.asarray(jax.jit(lambda p: rpj.signature(p, depth))(x)), want)
        assert np.all(_calls() - before == [3, 1]), "the compiled handlers were not called"
        if len(shape) > 2:
            before = _calls()
            per_path = jax.vmap(jax.grad(lambda p, g: jnp.sum(rpj.signature(p, depth) * g)))
            assert np.array_equal(np.asarray(jax.jit(jax.vmap(lambda p: rpj.signature(p, depth)))(x)), want)
            assert np.array_equal(np.asarray(jax.jit(per_path)(x, G)), want_g)
            from roughpaths.signatures.xla_handlers import plan
            if math.prod(shape[:-2]) <= plan(*shape[-2:], depth):     # (not where the numpy API runs lanes)
                assert np.all(_calls() - before == [1, 1])          # (grad alone: XLA drops the unused forward)
    finally:
        jax.config.update("jax_enable_x64", old)


def test_what_the_compiled_handlers_leave_gives_the_numpy_values(x64):
    """Calls the compiled handlers do not take (more paths than the numpy API runs one at a time, found at trace
    time or, under vmap, at run time; depth 2; d = 8) go to the Python handler: the same values."""
    cases = [(_paths((5, 8, 3)), 3, jax.jit), (_paths((8, 3)), 2, jax.jit), (_paths((1, 6, 8)), 3, jax.jit),
             (_paths((6, 8, 3)), 3, lambda f: jax.jit(jax.vmap(f)))]
    for x, depth, wrap in cases:
        before = _calls()
        got = wrap(lambda p: rpj.signature(p, depth))(x)
        assert np.array_equal(np.asarray(got), rp.signature(x, depth))
        assert np.all(_calls() == before)


@pytest.mark.parametrize("where", ["a point", "the cotangent"])
def test_compiled_handlers_leave_errors_to_the_numpy_api(x64, where):
    """A NaN that the numpy API refuses is refused with its message (the compiled handler hands the call on)."""
    x, G = _paths((8, 3), seed=23), np.ones(rp.sigdim(3, 3))
    if where == "a point":
        x[3, 1] = np.nan
    else:
        G[3] = np.nan
    expected = ("paths contains 1 non-finite value" if where == "a point"
                else "grad_output contains 1 non-finite value")
    with pytest.raises(Exception, match=expected):
        jax.block_until_ready(_step(3)(x, G))
    if where == "a point":
        with pytest.raises(Exception, match=expected):
            jax.block_until_ready(rpj.signature(x, 3))
    x[3] = np.inf
    with pytest.raises(Exception, match="non-finite"):
        jax.block_until_ready(_step(3)(x, np.ones(rp.sigdim(3, 3))))


def test_compiled_handlers_leave_an_overflow_to_the_numpy_api(x64):
    """Finite paths whose signature (or gradient) leaves float64 are refused by the numpy API; the compiled
    handlers stored the overflowed values (inf) instead of handing the call on."""
    x = _paths((8, 3), seed=24) * 1e110                             # level 3 ~ 1e330
    before = _calls()
    with pytest.raises(Exception, match="depth-3 signature of paths .* overflows float64"):
        jax.block_until_ready(jax.jit(lambda p: rpj.signature(p, 3))(x))
    x = _paths((8, 3), seed=24) * 1e60                              # level 3 fits, the gradient ~ 1e120 * 1e200
    G = np.full(rp.sigdim(3, 3), 1e200)
    with pytest.raises(Exception, match="gradient of the depth-3 signature overflows float64"):
        jax.block_until_ready(_step(3)(x, G))
    assert _calls()[1] == before[1]


def test_a_compiled_handler_without_its_parameters_returns_an_error():
    """A call of a compiled handler without (or with another) attribute is refused with an XLA error, not a crash:
    without the parameters there is no Python handler to hand it to."""
    target = rpj._compiled_target("forward")
    assert target is not None
    x = jnp.asarray(_paths((8, 3)), dtype=jnp.float32)
    result = jax.ShapeDtypeStruct((rp.sigdim(3, 3),), jnp.float32)
    for attributes in ({}, {"other": np.zeros(7, dtype=np.int64)}, {"roughpaths": np.zeros(3, dtype=np.int64)}):
        with pytest.raises(Exception, match="compiled handler without its parameters"):
            jax.block_until_ready(jax.ffi.ffi_call(target, result)(x, **attributes))


def test_kernel_variants_have_their_own_symbols():
    """The compiled handlers call a kernel by the address of its symbol, looked up by name: the variants of one
    kernel factory must not share a name (two variants compiled in two processes and loaded from numba's cache
    did, and the lookup found the other variant: a write past the signature, then a crash)."""
    from roughpaths.signatures import xla_handlers
    from roughpaths.signatures import _blocked, _lanes

    addresses = {key: xla_handlers.kernel_address(_blocked._block_units_kernel(*key), xla_handlers.BLOCK_ARGS)
                 for key in [(0, 0, 0), (0, 3, 3), (6, 4, 1), (4, 0, 0)]}
    assert len(set(addresses.values())) == 4
    names = {key: _blocked._block_units_kernel(*key).overloads[xla_handlers.BLOCK_ARGS].fndesc.llvm_func_name
             for key in addresses}
    assert len(set(names.values())) == 4
    assert xla_handlers.kernels(200, 7, 4, False)[0] == addresses[0, 0, 0]         # the engine's blocked kernels
    assert xla_handlers.kernels(200, 7, 3, False)[0] == addresses[0, 3, 3]
    assert xla_handlers.kernels(8, 7, 3, False)[0] == xla_handlers.kernel_address(     # a short path: the plain one
        _lanes.scalar_units(7), xla_handlers.BLOCK_ARGS)


@pytest.mark.parametrize("call, exc, words", [
    (lambda x, y: rpj.signature_kernel(x, y[:2]), ValueError, ["batch axes of x (3,), y (2,)", "broadcast"]),
    (lambda x, y: rpj.signature_kernel_gram(x[None], y[None, :2, :, :1]), ValueError, ["d=2", "d=1"]),
    (lambda x, y: rpj.signature_kernel(x, y[..., :1]), ValueError, ["x has d=2", "y has d=1"]),
    (lambda x, y: rpj.signature_kernel(x, y, dyadic_order=-1), ValueError, ["dyadic_order must be >= 0"]),
    (lambda x, y: rpj.signature_kernel(x, y, static_kernel="rbf"), TypeError, ["static_kernel must be", "RBFKernel"]),
    (lambda x, y: rpj.signature_kernel(x[0, 0], y), ValueError, ["x must have at least 2 axes", "x[None]"]),
])
def test_kernel_arguments_are_refused_when_called_not_at_run_time(call, exc, words):
    # what the shapes and the options decide is refused with the numpy API's error when the function is called
    # (or traced): a batch mismatch gave numpy's anonymous "shape mismatch", a d mismatch or a bad option a
    # JaxRuntimeError at run time
    x, y = jnp.asarray(_paths((3, 5, 2), seed=1)), jnp.asarray(_paths((3, 4, 2), seed=2))
    for run in (lambda: call(x, y), lambda: jax.jit(call).lower(x, y)):
        with pytest.raises(exc) as info:
            run()
        assert not isinstance(info.value, jax.errors.JaxRuntimeError)
        for w in words:
            assert w in str(info.value), str(info.value)


def test_the_numpy_api_inside_a_jax_transform_names_the_jax_function():
    x = jnp.asarray(_paths((5, 2)))
    for call in (lambda p: rp.signature(p, 2), lambda p: rp.signature_kernel(p, p)):
        with pytest.raises(TypeError, match="roughpaths.jax function of the same name"):
            jax.jit(call)(x)


@pytest.mark.parametrize("name", ["signature", "logsignature"])
@pytest.mark.parametrize("jit", [False, True])
def test_a_float32_result_or_gradient_beyond_float32s_range_is_refused(name, jit):
    """Computed in float64 (finite) and rounded to float32, a result or gradient beyond 3.4e38 came back as inf
    (from the host call and from the compiled handlers alike)."""
    f = getattr(rpj, name)
    wrap = jax.jit if jit else (lambda g: g)
    x = jnp.asarray(_paths((2, 6, 2), seed=25) * 1e14, dtype=jnp.float32)
    with pytest.raises(Exception, match=rf"result of {name} overflows float32.*Rescale paths.*jax_enable_x64"):
        jax.block_until_ready(wrap(lambda p: f(p, 3))(x))
    assert np.all(np.isfinite(np.asarray(f(x / 1e14, 3))))
    x = jnp.asarray(_paths((2, 6, 2), seed=25) * 1e10, dtype=jnp.float32)
    assert np.all(np.isfinite(np.asarray(f(x, 3))))
    G = jnp.full(f(x, 3).shape, 1e20, dtype=jnp.float32)
    with pytest.raises(Exception, match=rf"gradient of {name} with respect to paths overflows float32"):
        jax.block_until_ready(wrap(jax.grad(lambda p: jnp.sum(f(p, 3) * G)))(x))
