r"""PyTorch front end: the library's signatures and signature kernels as differentiable torch operations.

``import roughpaths.torch as rpt`` (needs the ``torch`` extra: ``pip install 'roughpaths-mechanics[torch]'``;
``import roughpaths`` alone never imports torch). Each function is a :class:`torch.autograd.Function`
whose forward pass calls the library's numpy API and whose backward pass calls its vector–Jacobian
product; there is no second implementation:

* :func:`signature`: forward :func:`roughpaths.signature`, backward :func:`roughpaths.signature_vjp`;
* :func:`logsignature`: :func:`roughpaths.logsignature`, :func:`roughpaths.logsignature_vjp`;
* :func:`signature_kernel`: ``roughpaths.signature_kernel``, ``roughpaths.signature_kernel_vjp``;
* :func:`signature_kernel_gram`: ``roughpaths.signature_kernel_gram``, ``roughpaths.signature_kernel_gram_vjp``.

The path transforms :func:`lead_lag`, :func:`time_augment`, :func:`basepoint` and
:func:`invisibility_reset` are :mod:`roughpaths.signatures.transforms`'s, written in torch operations
(indexing and concatenation): they run on any device and in any floating dtype, and torch differentiates
them itself (any order, ``torch.func`` included).

Shapes, layouts and conventions are those of the numpy functions (``(..., n, d)`` paths, the
``iisignature`` layout, the Lyndon basis). What the wrappers add, and what they do not:

* **Devices.** The kernels run on the CPU: a CUDA or MPS tensor is refused with a ``ValueError``
  saying to pass ``x.cpu()`` (and to move the result back with ``.to(device)``), a meta tensor (no
  data) likewise; nothing is copied between devices behind the caller's back.
* **Precision.** float32 and float64 tensors are accepted. The computation is always float64 (the
  kernels are float64 only): a float32 input is widened, the result (and the gradient) rounded back
  to float32, so float32 in gives float32 out, about as accurate as float32 can hold. Other dtypes
  (integers, float16, bfloat16, complex) are refused with a ``TypeError`` naming the fix.
* **Gradients.** First derivatives only: the backward pass is not itself differentiable. A gradient
  taken with ``create_graph=True`` (a gradient penalty, a Hessian) is marked so that differentiating it
  raises a ``RuntimeError`` saying so, whatever the cotangent that reached the function (a constant one
  too, as from ``.sum()``: no silent zero second derivative), and
  ``torch.func`` transforms (``vmap``, ``grad``, ``jacrev``) are not supported (refused with a ``TypeError``
  naming the fix); batch with leading axes instead, which runs as one call of the compiled kernels.
* **Cost.** The forward converts the tensors to numpy once, without a copy (float64) or with one
  cast (float32, whose float64 copy is kept for the backward), and the result back without a copy;
  the backward reuses those arrays, and the library's own VJPs get torch's cotangent without a copy
  (they only read it). A step (forward plus ``backward``) of one path of 8 points in d = 3, CPU time on
  a loaded 2-core machine (load 3.4-3.6, medians of 6 alternating process pairs against the code
  before this trim): 0.083 ms at depth 2 (0.121 before), 0.101 ms at depth 3 (0.160), of which the
  bare numpy calls are 0.019 / 0.033 ms (0.040 / 0.068: their own fixed cost was cut too). What is
  left above them, 0.064 / 0.068 ms, is mostly torch's: an identity ``torch.autograd.Function`` step
  costs 0.040 ms there, and a bare ``Function`` around the same two numpy calls with no checks or
  conversions 0.050 / 0.055 ms above the calls; the wrapper's own share is 0.013-0.014 ms (0.019-0.027
  before; 32 paths of 128 points at depth 2: 0.014, 0.027 before). pysiglib's torch API pays an
  overhead of the same size (``benchmarks/bench_frameworks.py`` prints both, and their ratio, in one run).

Examples
--------
>>> import torch
>>> import roughpaths.torch as rpt
>>> x = torch.tensor([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]], dtype=torch.float64, requires_grad=True)
>>> s = rpt.signature(x, 2)                    # the L-shaped path: area ∫ X¹ dX² = 1
>>> s
tensor([1.0000, 1.0000, 0.5000, 1.0000, 0.0000, 0.5000], dtype=torch.float64,
       grad_fn=<_SignatureBackward>)
>>> s[3].backward()
>>> x.grad
tensor([[-1.0000, -0.5000],
        [ 0.5000, -0.5000],
        [ 0.5000,  1.0000]], dtype=torch.float64)
"""

from __future__ import annotations

import numpy as np
import torch
from torch._C import _functions as _autograd_functions

import roughpaths as _rp
from roughpaths.validation import as_float_array
from roughpaths._frontends import batch_broadcast, batch_shape, check_times_batch, rounded, sum_to

__all__ = ["signature", "logsignature", "signature_kernel", "signature_kernel_gram", "differentiable", "lead_lag",
           "time_augment", "basepoint", "invisibility_reset"]

_DTYPES = (torch.float32, torch.float64)


def _check_tensor(t, name: str) -> None:
    """Refuse anything but a CPU tensor of float32 or float64, with a clear error."""
    if not isinstance(t, torch.Tensor):
        raise TypeError(f"{name} must be a torch.Tensor, got {type(t).__name__}; wrap it with "
                        f"torch.as_tensor({name}), or call the numpy API (roughpaths.signature, ...) on arrays directly.")
    if t.dtype not in _DTYPES:
        raise TypeError(f"{name} has dtype {t.dtype}; roughpaths.torch takes float32 or float64 tensors: pass "
                        f"{name}.double() (or {name}.float()).")
    if not t.is_cpu:
        if t.is_meta:
            raise ValueError(f"{name} is a meta tensor (a shape without data); roughpaths.torch computes on CPU "
                             f"data: pass a CPU tensor (torch.empty_like({name}, device='cpu') filled with the values).")
        raise ValueError(f"{name} is on device {t.device}; roughpaths.torch runs its compiled kernels on the CPU: "
                         f"pass {name}.cpu() (and move the result back with .to({name}.device)).")


def _is_functorch_wrapped(t: torch.Tensor) -> bool:
    """Whether ``t`` is a tensor of a ``torch.func`` transform (its wrappers have no data numpy could read)."""
    try:
        return bool(torch._C._functorch.is_functorch_wrapped_tensor(t))
    except AttributeError:                       # (a torch without that query: torch's own error follows)
        return False


def _numpy64(t: torch.Tensor) -> np.ndarray:
    """The float64 numpy view of a checked CPU tensor (a float32 one: a float64 copy)."""
    a = t.detach().numpy()
    return a if t.dtype == torch.float64 else a.astype(np.float64)


def _tensor(a: np.ndarray, dtype, label: str, names: tuple, wrt: str | None = None) -> torch.Tensor:
    """A float64 numpy result as a tensor of ``dtype`` (no copy for a float64 result torch can wrap); a float32 one
    that overflows float32 is refused (:func:`roughpaths._frontends.rounded`) naming the result of ``label`` (its
    gradient with respect to ``wrt``) and the inputs ``names``; the message is built only then."""
    if dtype != torch.float64:
        what = _grad_what(label, wrt) if wrt is not None else _result_what(label)
        return torch.from_numpy(rounded(a, np.float32, what, names, f"{names[0]}.double()"))
    if a.dtype != np.float64 or not a.flags.writeable:
        a = np.array(a, dtype=np.float64)
    try:
        return torch.from_numpy(a)
    except ValueError:                       # negative strides
        return torch.from_numpy(a.copy())


def differentiable(forward, vjp, *, names: tuple, core: tuple, label: str):
    """Build a differentiable torch function from a numpy forward map and its vector–Jacobian product.

    Parameters
    ----------
    forward : callable
        ``forward(*arrays, **params) -> ndarray``, on float64 numpy arrays.
    vjp : callable
        ``vjp(*arrays, grad_output, **params)``: the cotangent of each array (one array, or a tuple of
        them for several inputs).
    names : tuple of str
        The tensor arguments' names, for error messages.
    core : tuple of int
        How many trailing axes of each input are not batch axes (``2`` for ``(..., n, d)`` paths);
        the batch axes of several inputs are broadcast against each other.
    label : str
        The name of the autograd node (``grad_fn=<labelBackward>``).

    Returns
    -------
    callable
        ``f(*tensors, **params) -> torch.Tensor`` in the inputs' dtype (float32 or float64; computed
        in float64), differentiable once with respect to every tensor.

    Examples
    --------
    >>> import numpy as np, torch
    >>> square = differentiable(lambda a: a ** 2, lambda a, g: 2 * a * g, names=("a",), core=(0,), label="Square")
    >>> a = torch.tensor([3.0], requires_grad=True)
    >>> square(a).sum().backward()
    >>> a.grad
    tensor([6.])
    """
    return _function(forward, vjp, names=names, core=core, label=label, grad_readonly=True)


#: The public function of each autograd node of this module, for error messages (others: their label).
_PUBLIC = {"_Signature": "signature", "_LogSignature": "logsignature", "_SignatureKernel": "signature_kernel",
           "_SignatureKernelGram": "signature_kernel_gram"}


def _result_what(label: str) -> str:
    return f"the result of {_PUBLIC.get(label, label)}"


def _grad_what(label: str, name: str) -> str:
    return f"the gradient of {_PUBLIC.get(label, label)} with respect to {name}"


def _second_derivative_message(label: str) -> str:
    return (f"roughpaths.torch gives first derivatives only: a gradient through <{label}Backward> was taken with "
            f"create_graph=True (a gradient penalty, a Hessian), but its backward pass runs in numpy and is not "
            f"differentiable, so that gradient cannot be differentiated again. Take the gradient without "
            f"create_graph=True, or compute the second-order term another way (e.g. finite differences of the "
            f"gradient).")


def _function(forward, vjp, *, names: tuple, core: tuple, label: str, grad_readonly: bool):
    """:func:`differentiable`; ``grad_readonly=False`` for a ``vjp`` known not to write to its ``grad_output``
    (the library's own: a read-only cotangent would be copied by the numpy API's input check, ~1-2 us)."""

    def _forward(ctx, params, *tensors):
        # checked by apply() below: CPU tensors of one float dtype
        arrays = [_numpy64(tensors[0])] if len(tensors) == 1 else batch_broadcast([_numpy64(t) for t in tensors], core)
        out = forward(*arrays, **params)
        ctx.params, ctx.arrays = params, arrays
        ctx.save_for_backward(*tensors)           # torch's check that no input was modified in place
        return _tensor(out, tensors[0].dtype, label, names)

    def _compute_backward(ctx, grad):
        tensors = ctx.saved_tensors               # (raises if an input was modified in place since)
        g = grad.detach().numpy()
        if grad_readonly:
            g.flags.writeable = False             # torch's memory: the VJP takes its own copy if it must
        grads = vjp(*ctx.arrays, g if g.dtype == np.float64 else g.astype(np.float64), **ctx.params)
        if len(tensors) == 1:                     # (one input: no generator, no zip)
            t = tensors[0]
            return None, (_tensor(sum_to(np.asarray(grads), tuple(t.shape)), t.dtype, label, names, names[0])
                          if ctx.needs_input_grad[1] else None)
        grads = tuple(grads)
        return (None,) + tuple(_tensor(sum_to(np.asarray(gr), tuple(t.shape)), t.dtype, label, names, n)
                               if need else None
                               for gr, t, n, need in zip(grads, tensors, names, ctx.needs_input_grad[1:]))

    def _backward(ctx, grad):
        if not torch.is_grad_enabled():
            return _compute_backward(ctx, grad)   # the usual case
        # create_graph=True: the gradients are constants to autograd (the VJP runs in numpy), but they depend on
        # the inputs. torch's once_differentiable marks them only when the cotangent requires grad, so the
        # gradient of sig.sum() (a constant cotangent) came out as a plain tensor and a penalty built from it
        # was silently differentiated as a constant. Every gradient is marked: differentiating it raises.
        with torch.no_grad():
            grads = _compute_backward(ctx, grad)
        marked = [k for k, g in enumerate(grads) if g is not None]
        if not marked:
            return grads
        err = _autograd_functions.DelayedError(_second_derivative_message(label), len(marked))
        out = err(*[grads[k].detach().requires_grad_() for k in marked])
        out = (out,) if isinstance(out, torch.Tensor) else tuple(out)
        grads = list(grads)
        for k, g in zip(marked, out):
            grads[k] = g
        return tuple(grads)

    fn = type(label, (torch.autograd.Function,),
              {"forward": staticmethod(_forward), "backward": staticmethod(_backward)})

    def apply(*tensors, **params):
        for t, n in zip(tensors, names):
            _check_tensor(t, n)          # refuse a wrong device or dtype before autograd sees it
            if _is_functorch_wrapped(t):
                raise TypeError(f"{n} is a tensor inside a torch.func transform (vmap, grad, jacrev, ...); the "
                                f"roughpaths.torch functions run their kernels in numpy and support torch.autograd "
                                f"only. Batch with leading axes instead of vmap (one call of the compiled kernels) "
                                f"and take gradients with loss.backward() or torch.autograd.grad.")
        if len(tensors) > 1:
            if len({t.dtype for t in tensors}) > 1:
                dtypes = {t.dtype for t in tensors}
                raise TypeError(f"{' and '.join(names)} have different dtypes {sorted(map(str, dtypes))}; "
                                f"convert them to one (e.g. .double()).")
            batch_shape([tuple(t.shape) for t in tensors], core, names)   # refused naming them, before autograd
        return fn.apply(params, *tensors)

    return apply


# signature_vjp and logsignature_vjp only read their cotangent (gathers, and kernels that read it)
_signature = _function(lambda x, depth: _rp.signature(x, depth),
                       lambda x, g, depth: _rp.signature_vjp(x, depth, g),
                       names=("paths",), core=(2,), label="_Signature", grad_readonly=False)
_logsignature = _function(lambda x, depth: _rp.logsignature(x, depth),
                          lambda x, g, depth: _rp.logsignature_vjp(x, depth, g),
                          names=("paths",), core=(2,), label="_LogSignature", grad_readonly=False)
_kernel = differentiable(lambda x, y, **kw: _rp.signature_kernel(x, y, **kw),
                         lambda x, y, g, **kw: _rp.signature_kernel_vjp(x, y, g, **kw),
                         names=("x", "y"), core=(2, 2), label="_SignatureKernel")
_gram = differentiable(lambda x, y, **kw: _rp.signature_kernel_gram(x, y, **kw),
                       lambda x, y, g, **kw: _rp.signature_kernel_gram_vjp(x, y, g, **kw),
                       names=("X", "Y"), core=(3, 3), label="_SignatureKernelGram")


def signature(paths: torch.Tensor, depth: int) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.signature` of CPU tensors ``(..., n, d)`` → ``(..., sigdim(d, depth))``.

    Backward: :func:`roughpaths.signature_vjp`. float32 or float64 in, the same dtype out (computed in float64).

    Examples
    --------
    >>> import torch
    >>> x = torch.zeros(4, 10, 3, requires_grad=True)       # float32 in, float32 out
    >>> signature(x, 3).shape, signature(x, 3).dtype
    (torch.Size([4, 39]), torch.float32)
    """
    return _signature(paths, depth=depth)


def logsignature(paths: torch.Tensor, depth: int) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.logsignature` (Lyndon coordinates) of CPU tensors ``(..., n, d)``.

    Backward: :func:`roughpaths.logsignature_vjp`. float32 or float64 in, the same dtype out (computed in float64).

    Examples
    --------
    >>> import torch
    >>> logsignature(torch.tensor([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]), 2)   # increment (1, 1), Lévy area ½
    tensor([1.0000, 1.0000, 0.5000])
    """
    return _logsignature(paths, depth=depth)


def signature_kernel(x: torch.Tensor, y: torch.Tensor, *, dyadic_order: int = 0, static_kernel=None) -> torch.Tensor:
    r"""Differentiable ``roughpaths.signature_kernel``: ``x`` ``(..., n, d)``, ``y`` ``(..., m, d)`` → ``(...)``.

    The batch axes of ``x`` and ``y`` broadcast; the keywords are passed through unchanged. Backward:
    ``roughpaths.signature_kernel_vjp``. float32 or float64 in, the same dtype out (computed in float64).
    """
    return _kernel(x, y, dyadic_order=dyadic_order, static_kernel=static_kernel)


def signature_kernel_gram(X: torch.Tensor, Y: torch.Tensor, *, dyadic_order: int = 0,
                          static_kernel=None) -> torch.Tensor:
    r"""Differentiable ``roughpaths.signature_kernel_gram``: ``X`` ``(..., a, n, d)``, ``Y`` ``(..., b, m, d)`` → ``(..., a, b)``.

    Backward: ``roughpaths.signature_kernel_gram_vjp``. float32 or float64 in, the same dtype out
    (computed in float64).
    """
    return _gram(X, Y, dyadic_order=dyadic_order, static_kernel=static_kernel)


# ------------------------------------------------------------------------------ path transforms
def _paths_tensor(paths, name: str = "paths") -> torch.Tensor:
    """``paths`` as a floating tensor ``(..., n, d)`` with ``n, d >= 1``, or a clear error."""
    if not isinstance(paths, torch.Tensor):
        raise TypeError(f"{name} must be a torch.Tensor, got {type(paths).__name__}; wrap it with "
                        f"torch.as_tensor({name}), or call roughpaths.{{lead_lag, ...}} on numpy arrays.")
    if not paths.is_floating_point():
        raise TypeError(f"{name} has dtype {paths.dtype}; the transforms take floating tensors: pass {name}.double().")
    if paths.ndim < 2 or paths.shape[-2] < 1 or paths.shape[-1] < 1:
        raise ValueError(f"{name} must have shape (..., n, d) with n >= 1 and d >= 1, got shape {tuple(paths.shape)}.")
    return paths


def lead_lag(paths: torch.Tensor) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.lead_lag` in torch operations: ``(..., n, d)`` → ``(..., 2n - 1, 2d)``.

    Point ``2k`` is ``(x_k, x_k)``, point ``2k + 1`` is ``(x_{k+1}, x_k)`` (lead channels first).

    Examples
    --------
    >>> import torch
    >>> lead_lag(torch.tensor([[0.0], [1.0], [3.0]])).T
    tensor([[0., 1., 1., 3., 3.],
            [0., 0., 1., 1., 3.]])
    """
    x = _paths_tensor(paths)
    k = torch.arange(2 * x.shape[-2] - 1, device=x.device)
    return torch.cat([x[..., (k + 1) // 2, :], x[..., k // 2, :]], dim=-1)


def time_augment(paths: torch.Tensor, times=None) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.time_augment`: time as the first channel, ``(..., n, d)`` → ``(..., n, d + 1)``.

    ``times`` (shape ``(n,)`` or ``(..., n)``, strictly increasing) defaults to ``t_k = k / (n - 1)``.

    Examples
    --------
    >>> import torch
    >>> time_augment(torch.tensor([[5.0], [7.0], [6.0]]))
    tensor([[0.0000, 5.0000],
            [0.5000, 7.0000],
            [1.0000, 6.0000]])
    """
    x = _paths_tensor(paths)
    n = x.shape[-2]
    if times is None:
        t = torch.arange(n, dtype=x.dtype, device=x.device) / max(n - 1, 1)
    else:
        t = _times_tensor(times, x)
        if t.ndim < 1 or t.shape[-1] != n:
            raise ValueError(f"times must have {n} entries on its last axis (one per point), got shape {tuple(t.shape)}.")
        if n > 1 and not bool(torch.all(t[..., 1:] > t[..., :-1])):
            where = tuple(int(i) for i in torch.nonzero(~(t[..., 1:] > t[..., :-1]))[0])
            raise ValueError(f"times must be strictly increasing along its last axis, but at index {where} it goes from "
                             f"{float(t[where])!r} to {float(t[where[:-1] + (where[-1] + 1,)])!r} (in {x.dtype}); sort "
                             f"the points by time and drop repeated times.")
        check_times_batch(tuple(t.shape), tuple(x.shape))
    return torch.cat([t.expand(x.shape[:-1]).unsqueeze(-1), x], dim=-1)


def _times_tensor(times, x: torch.Tensor) -> torch.Tensor:
    """``time_augment``'s ``times`` as a finite tensor of the paths' dtype and device (a tensor keeps its graph), with
    the numpy function's checks: real numbers (integers too), no NaN or inf."""
    if isinstance(times, torch.Tensor):
        if times.is_complex():
            raise TypeError(f"times must be real, got a complex tensor of dtype {times.dtype}; pass times.real if the "
                            f"imaginary part is zero.")
        t = times.to(dtype=x.dtype, device=x.device)
        if not bool(torch.isfinite(t).all()):
            first = tuple(int(i) for i in torch.nonzero(~torch.isfinite(t))[0])
            raise ValueError(f"times contains {int((~torch.isfinite(t)).sum())} non-finite value(s) (NaN or inf, "
                             f"in {x.dtype}), the first at index {first}; remove or interpolate them before calling.")
        return t
    return torch.as_tensor(as_float_array(times, "times"), dtype=x.dtype, device=x.device)


def basepoint(paths: torch.Tensor) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.basepoint`: the origin prepended, ``(..., n, d)`` → ``(..., n + 1, d)``.

    Examples
    --------
    >>> import torch
    >>> basepoint(torch.tensor([[1.0, 2.0]]))
    tensor([[0., 0.],
            [1., 2.]])
    """
    x = _paths_tensor(paths)
    return torch.cat([torch.zeros_like(x[..., :1, :]), x], dim=-2)


def invisibility_reset(paths: torch.Tensor) -> torch.Tensor:
    r"""Differentiable :func:`roughpaths.invisibility_reset`: ``(..., n, d)`` → ``(..., n + 2, d + 1)``.

    Points ``(1, x_k)``, then ``(0, x_{n-1})``, then ``(0, 0)``.

    Examples
    --------
    >>> import torch
    >>> invisibility_reset(torch.tensor([[1.0, 2.0], [3.0, 4.0]]))
    tensor([[1., 1., 2.],
            [1., 3., 4.],
            [0., 3., 4.],
            [0., 0., 0.]])
    """
    x = _paths_tensor(paths)
    seen = torch.cat([torch.ones_like(x[..., :1]), x], dim=-1)
    off = torch.cat([torch.zeros_like(x[..., -1:, :1]), x[..., -1:, :]], dim=-1)
    return torch.cat([seen, off, torch.zeros_like(seen[..., :1, :])], dim=-2)
