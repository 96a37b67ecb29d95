r"""JAX front end: the library's signatures and signature kernels as differentiable JAX functions.

``import roughpaths.jax as rpj`` (needs the ``jax`` extra: ``pip install 'roughpaths-mechanics[jax]'``;
``import roughpaths`` alone never imports jax). Each function is a :func:`jax.custom_vjp` whose
forward and backward passes are host calls of the library's numpy API and its vector–Jacobian
product (the same pairs as :mod:`roughpaths.torch`); there is no second implementation. On the CPU
backend a host call is an XLA FFI custom call (``jax.ffi.ffi_call``) of a handler made with
:mod:`ctypes` (``roughpaths._xla_ffi``), which wraps XLA's buffers as numpy arrays and calls the numpy
function; small :func:`signature` calls go to compiled handlers instead (``roughpaths.signatures.xla_handlers``:
numba C callbacks that read XLA's call frame and run the numpy API's own compiled kernels, the same
bits; see **Cost**); elsewhere, or where a handler cannot be registered, a :func:`jax.pure_callback`.
They work under ``jax.jit``, ``jax.vmap`` and ``jax.grad``
(and their compositions):

* **vmap** is one batched call, not a loop: the calls are declared with
  ``vmap_method="broadcast_all"``, so a mapped axis arrives as a leading batch axis, which the numpy
  API takes as it takes any batch axis.
* **Precision.** float32 (JAX's default) and float64 (with ``jax_enable_x64``) inputs; the
  computation is float64 either way and the result is rounded to the input's dtype. Integer and
  half-precision inputs are refused with a ``TypeError``.
* **Devices.** The numpy API runs on the host; on an accelerator the call is a ``pure_callback``
  and JAX copies the arrays to the host and back (correct, but the copy costs what it costs).
* **Errors.** An error of the numpy API (a non-finite point, say) is raised by JAX where the result
  is waited for, as a ``JaxRuntimeError`` whose message is the numpy API's. What the shapes and the
  options decide (the batch axes, the depth and the memory a signature would take, the kernels' ``d``,
  ``dyadic_order`` and ``static_kernel``) is checked when the call is made or traced, with the numpy API's
  ``ValueError`` or ``TypeError``: XLA allocates the result before the host call runs.
* **Gradients.** First order (reverse mode): ``jax.grad``, ``jax.vjp``, ``jax.jacrev``. Forward mode
  (``jax.jvp``, ``jacfwd``) and second derivatives are not defined for a ``custom_vjp`` of a host call.
* **Cost.** A jitted forward plus backward (``value_and_grad``, two custom calls), CPU time on a loaded
  2-core machine, against pysiglib's XLA FFI calls into compiled C++ timed in the same process
  (``benchmarks/bench_frameworks.py`` prints the same comparison; medians of 11 interleaved pairs, two
  runs): one path of 8 points in d = 3 at depth 3, 0.021-0.023 against 0.017-0.018 ms (1.24-1.27x).
  Such calls go to the compiled handlers (``roughpaths.signatures.xla_handlers``): paths the numpy API runs as
  single work units (depth >= 3, d <= 7, up to a few hundred points) and at most as many as it runs
  one at a time (2 at d <= 3; any number where the signature is too large for its lanes), float32 or
  float64; they hand every other call, and every NaN or inf, to the Python handler. Through the
  Python handler the same step cost 0.075-0.088 ms (4.2-5.3x), above its "host floor" of 0.036-0.040 ms
  (the same XLA program with Python host functions that only allocate zero results). Larger calls
  keep the Python handler, whose fixed cost they amortise: 32 paths of 128 points 1.1-1.2x (1.6-1.7x
  in the runs of the code before, within the noise of this loaded machine), in d = 8 0.8x. Batch
  many paths into one call (``vmap`` does). First ``jax.grad`` step in a new process: about 0.2 s
  CPU of XLA compiles (and ``import jax`` about 1.1 s); the compiled handlers, on the first call they
  take, 2.5-3.4 s CPU of numba compiles (cached on disk), beside the kernels the numpy API compiles
  for any first call (a lone path's gradient kernels: about 9 s at d = 3, 4.5 s of it the one-unit
  backward kernel).

The path transforms :func:`lead_lag`, :func:`time_augment`, :func:`basepoint` and
:func:`invisibility_reset` are :mod:`roughpaths.signatures.transforms`'s, written in ``jax.numpy``
(indexing and concatenation, no callback): JAX traces, jits and differentiates them itself (any order,
forward mode included).

Examples
--------
>>> import jax, jax.numpy as jnp
>>> import roughpaths.jax as rpj
>>> x = jnp.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
>>> rpj.signature(x, 2)                        # the L-shaped path: area ∫ X¹ dX² = 1
Array([1. , 1. , 0.5, 1. , 0. , 0.5], dtype=float32)
>>> jax.grad(lambda x: rpj.signature(x, 2)[3])(x)
Array([[-1. , -0.5],
       [ 0.5, -0.5],
       [ 0.5,  1. ]], dtype=float32)
"""

from __future__ import annotations

import ctypes
import math
import os
from functools import partial

import numpy as np
import jax
import jax.numpy as jnp

import roughpaths as _rp
from roughpaths._frontends import batch_broadcast, batch_shape, check_times_batch, rounded, sum_to
from roughpaths._xla_ffi import host_handler
from roughpaths.signatures.kernel import kernel_shape
from roughpaths.signatures.signature import signature_shape

__all__ = ["signature", "logsignature", "signature_kernel", "signature_kernel_gram", "differentiable", "lead_lag",
           "time_augment", "basepoint", "invisibility_reset"]


def _as_jax(x, name: str):
    """``x`` as a JAX array (or tracer) of float32 or float64, with a clear error otherwise."""
    if isinstance(x, (str, bytes)) or x is None:
        raise TypeError(f"{name} must be an array of floats, got {type(x).__name__}; pass a jax or numpy array.")
    x = jnp.asarray(x)
    if x.dtype not in (jnp.float32, jnp.float64):
        raise TypeError(f"{name} has dtype {x.dtype}; roughpaths.jax takes float32 or float64 arrays: pass "
                        f"{name}.astype(jnp.float32) (or float64 with jax_enable_x64).")
    return x


_TARGETS: list = []                     # the registered handlers, alive as long as XLA's registry
#: Target names are unique to the process: a compiled program (jax's persistent compilation cache, an
#: export) names its custom calls, and another process's target of the same name may be another function.
_PREFIX = f"roughpaths_host_{os.urandom(6).hex()}_"


def _host_call(host, register: bool = True, compiled=None):
    """``call(result_shape_dtypes, *args)`` computing ``host(*numpy arrays) -> tuple of arrays`` on the host.

    On the CPU backend an XLA FFI custom call of a ctypes handler (:mod:`roughpaths._xla_ffi`),
    registered once per function; on other backends, or where this jax cannot register the handler,
    a ``jax.pure_callback`` (the same results; about 0.1 ms more per call, and JAX copies device
    arrays to the host and back). Under ``vmap`` one batched call, with the mapped axes in front of
    every operand. ``register=False``: always the callback (a function built for one call only, whose
    target XLA would keep for the life of the process). ``compiled(*args)``, asked when a call is
    traced: ``(target, attribute)``, a compiled handler (:func:`_compiled_target`) to call instead and
    ``attribute(fallback)``, its keyword attributes given the address of this call's Python handler
    (which it hands what it does not take), or ``None``.
    """
    name = f"{_PREFIX}{len(_TARGETS)}" if register else None
    try:
        if name is not None:
            handler = host_handler(host)
            jax.ffi.register_ffi_target(name, jax.ffi.pycapsule(handler), platform="cpu", api_version=1)
            _TARGETS.append(handler)
    except Exception:                        # noqa: BLE001 -- no (or a changed) XLA FFI: the host callback
        name = None

    def call(result, *args):
        if name is not None and jax.default_backend() == "cpu":
            fast = compiled(*args) if compiled is not None else None
            if fast is not None:                # (kept alive in _TARGETS with the handler: its address stays valid)
                target, attribute = fast
                fallback = ctypes.cast(handler, ctypes.c_void_p).value
                return jax.ffi.ffi_call(target, result, vmap_method="broadcast_all")(*args, **attribute(fallback))
            return jax.ffi.ffi_call(name, result, vmap_method="broadcast_all")(*args)
        callback = host if isinstance(result, tuple) else lambda *arrays: host(*arrays)[0]
        return jax.pure_callback(callback, result, *args, vmap_method="broadcast_all")

    return call


#: The compiled handlers' target names by direction (``"forward"``, ``"backward"``), or None where one could not be
#: compiled or registered (those calls stay with the Python handler).
_COMPILED: dict = {}


def _compiled_target(direction: str):
    """The XLA target name of the compiled ``direction`` signature handler (:mod:`roughpaths.signatures.xla_handlers`),
    compiled (or loaded from numba's cache) and registered on first use; ``None`` if that fails."""
    if direction not in _COMPILED:
        name = None
        try:
            from roughpaths.signatures import xla_handlers

            handler = xla_handlers.handler(direction)
            name = f"{_PREFIX}compiled_signature_{direction}"
            jax.ffi.register_ffi_target(name, jax.ffi.pycapsule(handler.ctypes), platform="cpu", api_version=1)
            _TARGETS.append(handler)
        except Exception:                    # noqa: BLE001 -- no compiler, no FFI: the Python handler
            name = None
        _COMPILED[direction] = name
    return _COMPILED[direction]


def _signature_compiled(params: dict, dtype):
    """``(forward, backward)``: :func:`_host_call`'s ``compiled`` choosers for :func:`signature`'s calls.

    A call goes to a compiled handler where :func:`roughpaths.signatures.xla_handlers.plan` covers its paths'
    ``(n, d, depth)`` and the paths traced (the batch axes that are not ``vmap``'s) are at most its
    ``most``; the handler checks the rest (``vmap``'s axes, the values) when it runs, and hands what it
    does not take to the Python handler.
    """
    depth = params["depth"]
    if type(depth) is not int:
        return None

    def chooser(direction):
        def choose(x, *rest):
            from roughpaths.signatures import xla_handlers as xs

            if x.ndim < 2:
                return None
            n, d = x.shape[-2:]
            most = xs.plan(n, d, depth)
            if not 1 <= math.prod(x.shape[:-2]) <= most:
                return None
            target = _compiled_target(direction)
            if target is None:
                return None
            try:
                kernels = xs.kernels(n, d, depth, direction == "backward")
            except Exception:                # noqa: BLE001 -- the kernels did not compile: the Python handler
                return None
            return target, lambda fallback: {xs.ATTRIBUTE: xs.parameters(fallback, d, depth, most, kernels)}
        return choose

    return chooser("forward"), chooser("backward")


def differentiable(forward, vjp, out_shape, *, names: tuple, core: tuple, label: str = "the function"):
    """Build a differentiable, jit- and vmap-able JAX function from a numpy map and its vector–Jacobian product.

    Parameters
    ----------
    forward : callable
        ``forward(*arrays, **params) -> ndarray`` on float64 numpy arrays, batched over leading axes.
    vjp : callable
        ``vjp(*arrays, grad_output, **params)``: the cotangent of each array (one array, or a tuple).
    out_shape : callable
        ``out_shape(batch, cores, **params) -> tuple``: the result's shape given the broadcast batch
        shape and the trailing (core) shapes of the inputs.
    names : tuple of str
        The arguments' names, for error messages.
    core : tuple of int
        How many trailing axes of each input are not batch axes; the batch axes broadcast.
    label : str
        The function's name in error messages (a float32 result or gradient beyond float32's range is refused).

    Returns
    -------
    callable
        ``f(*arrays, **params)``, in the inputs' floating dtype (computed in float64).

    Examples
    --------
    >>> import jax, jax.numpy as jnp
    >>> square = differentiable(lambda a: a ** 2, lambda a, g: 2 * a * g, lambda b, c: b + c[0],
    ...                         names=("a",), core=(0,))
    >>> jax.grad(lambda a: square(a).sum())(jnp.array([3.0]))
    Array([6.], dtype=float32)
    """
    return _differentiable(forward, vjp, out_shape, names, core, label=label)


def _differentiable(forward, vjp, out_shape, names: tuple, core: tuple, compiled=None, label: str = "the function"):
    """:func:`differentiable`, whose host calls may go to compiled handlers: ``compiled(params, dtype)`` gives the
    choosers (forward, backward) of :func:`_host_call`'s ``compiled``, or ``None``."""
    fix = f"jax.config.update('jax_enable_x64', True) and {names[0]}.astype(jnp.float64)"

    def build(params: dict, dtype, register: bool = True):
        def forward_host(*arrs):
            if len(arrs) == 1:                      # one input: nothing to broadcast
                arrays = (np.asarray(arrs[0], dtype=np.float64),)
            else:
                arrays = batch_broadcast([np.asarray(a, dtype=np.float64) for a in arrs], core)
            return (rounded(forward(*arrays, **params), dtype, f"the result of {label}", names, fix),)

        def backward_host(*arrs):
            *arrs, g = arrs
            g = np.asarray(g, dtype=np.float64)
            if len(arrs) == 1:
                a, = arrs
                grad = vjp(np.asarray(a, dtype=np.float64), g, **params)
                return (rounded(sum_to(np.asarray(grad), a.shape), dtype, _grad(label, names[0]), names, fix),)
            shapes = [a.shape for a in arrs]        # as received: with vmap's axes in front
            arrays = batch_broadcast([np.asarray(a, dtype=np.float64) for a in arrs], core)
            grads = tuple(vjp(*arrays, g, **params))
            return tuple(rounded(sum_to(np.asarray(gr), s), dtype, _grad(label, n), names, fix)
                         for gr, s, n in zip(grads, shapes, names))

        hooks = compiled(params, dtype) if compiled is not None and register else None
        forward_call = _host_call(forward_host, register, hooks[0] if hooks else None)
        backward_call = _host_call(backward_host, register, hooks[1] if hooks else None)

        @jax.custom_vjp
        def f(*args):
            batch = np.broadcast_shapes(*(a.shape[:a.ndim - c] for a, c in zip(args, core)))
            cores = [a.shape[a.ndim - c:] for a, c in zip(args, core)]
            return forward_call(jax.ShapeDtypeStruct(tuple(out_shape(batch, cores, **params)), dtype), *args)

        def f_fwd(*args):
            return f(*args), args

        def f_bwd(args, g):
            return tuple(backward_call(tuple(jax.ShapeDtypeStruct(a.shape, a.dtype) for a in args), *args, g))

        f.defvjp(f_fwd, f_bwd)
        return jax.jit(f)

    cache = {}

    def apply(*xs, **params):
        xs = [_as_jax(x, n) for x, n in zip(xs, names)]
        batch = batch_shape([x.shape for x in xs], core, names)      # the ranks and the batch axes, named
        dtype = jnp.result_type(*xs)
        xs = [x.astype(dtype) for x in xs]
        out_shape(batch, [x.shape[x.ndim - c:] for x, c in zip(xs, core)], **params)   # checks, before tracing
        key = (tuple(sorted(params.items())), np.dtype(dtype).name)
        try:
            f = cache.get(key)
        except TypeError:                            # an unhashable parameter: no reuse
            return build(params, dtype, register=False)(*xs)
        if f is None:
            f = cache[key] = build(params, dtype)
        return f(*xs)

    return apply


def _grad(label: str, name: str) -> str:
    return f"the gradient of {label} with respect to {name}"


def _paths_core(cores, name="paths"):
    (n, d), = cores
    if n < 1 or d < 1:
        raise ValueError(f"{name} needs shape (..., n, d) with n >= 1 and d >= 1, got trailing shape {(n, d)}.")
    return d


def _signature_shape(batch: tuple, cores: list, depth, *, log: bool) -> tuple:
    """The result's shape, after the numpy API's depth and memory checks: XLA allocates the result buffer before
    the host call runs, so a request the numpy API would refuse must be refused here, before it is traced."""
    _paths_core(cores)
    return signature_shape(tuple(batch) + tuple(cores[0]), depth, log=log)


_signature = _differentiable(lambda x, depth: _rp.signature(x, depth),
                             lambda x, g, depth: _rp.signature_vjp(x, depth, g),
                             partial(_signature_shape, log=False), ("paths",), (2,), _signature_compiled, "signature")
_logsignature = differentiable(lambda x, depth: _rp.logsignature(x, depth),
                               lambda x, g, depth: _rp.logsignature_vjp(x, depth, g),
                               partial(_signature_shape, log=True), names=("paths",), core=(2,), label="logsignature")


def _kernel_shape(batch: tuple, cores: list, *, gram: bool, dyadic_order, static_kernel) -> tuple:
    """The kernels' shape, after the numpy API's checks of what is known before tracing (the options, a point and
    a coordinate in each path, the same ``d``): refused with its ``ValueError`` or ``TypeError`` there, not at run
    time as a ``JaxRuntimeError``."""
    return kernel_shape(tuple(batch) + tuple(cores[0]), tuple(batch) + tuple(cores[1]), gram=gram,
                        dyadic_order=dyadic_order, static_kernel=static_kernel)


_kernel = differentiable(lambda x, y, **kw: _rp.signature_kernel(x, y, **kw),
                         lambda x, y, g, **kw: _rp.signature_kernel_vjp(x, y, g, **kw),
                         partial(_kernel_shape, gram=False), names=("x", "y"), core=(2, 2), label="signature_kernel")
_gram = differentiable(lambda x, y, **kw: _rp.signature_kernel_gram(x, y, **kw),
                       lambda x, y, g, **kw: _rp.signature_kernel_gram_vjp(x, y, g, **kw),
                       partial(_kernel_shape, gram=True), names=("X", "Y"), core=(3, 3), label="signature_kernel_gram")


def signature(paths, depth: int):
    r"""Differentiable :func:`roughpaths.signature` of ``(..., n, d)`` arrays → ``(..., sigdim(d, depth))``.

    Backward: :func:`roughpaths.signature_vjp`. float32 or float64 in, the same dtype out (computed in float64).

    Examples
    --------
    >>> import jax, jax.numpy as jnp
    >>> x = jnp.zeros((5, 4, 10, 3))
    >>> jax.jit(signature, static_argnums=1)(x, 3).shape          # batch axes as in the numpy API
    (5, 4, 39)
    >>> jax.vmap(lambda p: signature(p, 3))(x).shape               # one batched callback, not a loop
    (5, 4, 39)
    """
    return _signature(paths, depth=depth)


def logsignature(paths, depth: int):
    r"""Differentiable :func:`roughpaths.logsignature` (Lyndon coordinates) of ``(..., n, d)`` arrays.

    Backward: :func:`roughpaths.logsignature_vjp`. float32 or float64 in, the same dtype out (computed in float64).

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> logsignature(jnp.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 2)   # increment (1, 1), Lévy area ½
    Array([1. , 1. , 0.5], dtype=float32)
    """
    return _logsignature(paths, depth=depth)


def signature_kernel(x, y, *, dyadic_order: int = 0, static_kernel=None):
    r"""Differentiable ``roughpaths.signature_kernel``: ``x`` ``(..., n, d)``, ``y`` ``(..., m, d)`` → ``(...)``.

    The batch axes of ``x`` and ``y`` broadcast; the keywords are passed through unchanged (they are
    static under ``jit``). Backward: ``roughpaths.signature_kernel_vjp``.
    """
    return _kernel(x, y, dyadic_order=dyadic_order, static_kernel=static_kernel)


def signature_kernel_gram(X, Y, *, dyadic_order: int = 0, static_kernel=None):
    r"""Differentiable ``roughpaths.signature_kernel_gram``: ``X`` ``(..., a, n, d)``, ``Y`` ``(..., b, m, d)`` → ``(..., a, b)``.

    Backward: ``roughpaths.signature_kernel_gram_vjp``.
    """
    return _gram(X, Y, dyadic_order=dyadic_order, static_kernel=static_kernel)


# ------------------------------------------------------------------------------ path transforms
def _paths_array(paths, name: str = "paths"):
    """``paths`` as a floating JAX array ``(..., n, d)`` with ``n, d >= 1``, or a clear error."""
    x = _as_jax(paths, name)
    if x.ndim < 2 or x.shape[-2] < 1 or x.shape[-1] < 1:
        raise ValueError(f"{name} must have shape (..., n, d) with n >= 1 and d >= 1, got shape {x.shape}.")
    return x


def lead_lag(paths):
    r"""Differentiable :func:`roughpaths.lead_lag` in ``jax.numpy``: ``(..., n, d)`` → ``(..., 2n - 1, 2d)``.

    Point ``2k`` is ``(x_k, x_k)``, point ``2k + 1`` is ``(x_{k+1}, x_k)`` (lead channels first).

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> lead_lag(jnp.array([[0.0], [1.0], [3.0]])).T
    Array([[0., 1., 1., 3., 3.],
           [0., 0., 1., 1., 3.]], dtype=float32)
    """
    x = _paths_array(paths)
    k = np.arange(2 * x.shape[-2] - 1)
    return jnp.concatenate([x[..., (k + 1) // 2, :], x[..., k // 2, :]], axis=-1)


def time_augment(paths, times=None):
    r"""Differentiable :func:`roughpaths.time_augment`: time as the first channel, ``(..., n, d)`` → ``(..., n, d + 1)``.

    ``times`` (shape ``(n,)`` or ``(..., n)``) defaults to ``t_k = k / (n - 1)``; given times are not
    checked for increase here (they may be traced values): check them before, or use the numpy function.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> time_augment(jnp.array([[5.0], [7.0], [6.0]]))
    Array([[0. , 5. ],
           [0.5, 7. ],
           [1. , 6. ]], dtype=float32)
    """
    x = _paths_array(paths)
    n = x.shape[-2]
    if times is None:
        # the grid is a constant: divided in numpy (float64, then rounded to the paths' dtype, which is the
        # correctly rounded k / (n - 1) in float32 too), not in XLA, which turns the division by a constant
        # into a product with its reciprocal and gave other times than numpy and torch (n = 7: t_2 differed)
        t = jnp.asarray((np.arange(n) / max(n - 1, 1)).astype(x.dtype))
    else:
        t = _times_array(times).astype(x.dtype)
    if t.ndim < 1 or t.shape[-1] != n:
        raise ValueError(f"times must have {n} entries on its last axis (one per point), got shape {t.shape}.")
    check_times_batch(tuple(t.shape), tuple(x.shape))
    return jnp.concatenate([jnp.broadcast_to(t, x.shape[:-1])[..., None], x], axis=-1)


def _times_array(times):
    """``time_augment``'s ``times`` as a JAX array (or tracer) of real numbers: integers too, as the numpy and torch
    functions take them (they are cast to the paths' dtype)."""
    if isinstance(times, (str, bytes)) or times is None:
        raise TypeError(f"times must be an array of real numbers, got {type(times).__name__}; pass a jax or numpy "
                        f"array of the points' times.")
    t = jnp.asarray(times)
    if t.dtype.kind not in "biuf":
        raise TypeError(f"times has dtype {t.dtype}; pass real times (floats or integers).")
    return t


def basepoint(paths):
    r"""Differentiable :func:`roughpaths.basepoint`: the origin prepended, ``(..., n, d)`` → ``(..., n + 1, d)``.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> basepoint(jnp.array([[1.0, 2.0]]))
    Array([[0., 0.],
           [1., 2.]], dtype=float32)
    """
    x = _paths_array(paths)
    return jnp.concatenate([jnp.zeros_like(x[..., :1, :]), x], axis=-2)


def invisibility_reset(paths):
    r"""Differentiable :func:`roughpaths.invisibility_reset`: ``(..., n, d)`` → ``(..., n + 2, d + 1)``.

    Points ``(1, x_k)``, then ``(0, x_{n-1})``, then ``(0, 0)``.

    Examples
    --------
    >>> import jax.numpy as jnp
    >>> invisibility_reset(jnp.array([[1.0, 2.0], [3.0, 4.0]]))
    Array([[1., 1., 2.],
           [1., 3., 4.],
           [0., 3., 4.],
           [0., 0., 0.]], dtype=float32)
    """
    x = _paths_array(paths)
    seen = jnp.concatenate([jnp.ones_like(x[..., :1]), x], axis=-1)
    off = jnp.concatenate([jnp.zeros_like(x[..., -1:, :1]), x[..., -1:, :]], axis=-1)
    return jnp.concatenate([seen, off, jnp.zeros_like(seen[..., :1, :])], axis=-2)
