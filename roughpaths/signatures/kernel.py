r"""Signature kernels ``k(x, y) = <S(x), S(y)>`` of piecewise-linear paths, their Gram matrices and gradients.

The untruncated signature inner product solves the Goursat PDE
:math:`\partial_s\partial_t k = \langle \dot x_s, \dot y_t\rangle\, k`, :math:`k = 1` on the axes (Salvi
et al. 2021). It is solved on the grid of the two paths refined ``2**dyadic_order`` times in each
direction by the second-order explicit scheme that pysiglib 4.0 and sigkernel use (formula in
:mod:`roughpaths.signatures._goursat`), so the three agree to round-off at the same ``dyadic_order``; the
discretisation error falls like ``4**-dyadic_order`` (measured: ``docs/signature-kernels.md``).

- :func:`signature_kernel` ``(x, y)``: ``x`` ``(..., n, d)``, ``y`` ``(..., m, d)``, batch axes broadcast,
  returns ``(...)``.
- :func:`signature_kernel_gram` ``(X, Y)``: ``X`` ``(..., a, n, d)``, ``Y`` ``(..., b, m, d)``, returns
  ``(..., a, b)``.
- :func:`signature_kernel_vjp`, :func:`signature_kernel_gram_vjp`: exact gradients of the *discretised*
  kernels (an adjoint sweep of the same scheme), with respect to the path points.

``static_kernel`` is ``None`` (linear, ``<dx, dy>``), :class:`~roughpaths.LinearKernel` or
:class:`~roughpaths.RBFKernel`. Each pair's value is computed by the same instructions whatever the
batch and the thread count (bitwise: tested).

Overflow. The signature's level ``k`` has norm at most ``L**k / k!`` (``L`` the path's length in the static
kernel's feature space), so ``|k(x, y)| <= I0(2 sqrt(Lx Ly)) <= exp(2 sqrt(Lx Ly))``: paths of length
about 20 already give kernels near ``1e100`` (the probe: Brownian paths scaled by 10 gave ``inf``, by 20
``nan``). Every value of the PDE grid is the kernel of two sub-paths, and an ``inf`` anywhere reaches the
result (``inf`` or ``inf - inf = nan``), so a non-finite kernel or gradient is detected after the sweep and
refused with a ``ValueError`` naming the pair, ``Lx``, ``Ly`` and a ``LinearKernel`` scale that brings
``Lx Ly`` below ``1.2e5`` (kernels below about ``1e300``). Every finite result is returned as before.
Rescaling the grid would not gain a usable answer: a result beyond ``1.8e308`` has no float64 value, and
a result far below an overflowing grid value would be a difference of such numbers with no correct
digit. A static kernel whose scale itself overflows (``RBFKernel(1e-310)``: ``1/sigma = inf``) or scales
the paths beyond float64 (``RBFKernel(1e-308)`` on ``|x| > 1.8``) is refused before the sweep.
"""

from __future__ import annotations

import numpy as np

from .. import _threads
from ..validation import as_float_array, check_memory, check_positive_int, check_work
from . import _goursat
from .static_kernels import _resolve

__all__ = ["signature_kernel", "signature_kernel_gram", "signature_kernel_vjp", "signature_kernel_gram_vjp"]

#: The refinement factor 2**dyadic_order is capped here (the grid of a 2-point pair is then 2**40 cells).
_MAX_ORDER = 20


def _check_order(dyadic_order) -> int:
    try:
        return check_positive_int(dyadic_order, "dyadic_order", minimum=0)
    except (TypeError, ValueError) as exc:
        raise type(exc)(f"{exc} Pass an integer >= 0: each step of both paths is refined 2**dyadic_order "
                        f"times in the PDE grid (0: the paths' own grid; 2 to 4 is typical).") from None


def _check_pair(x, y, names: tuple, axes: int) -> tuple:
    """Validated float64 ``x``, ``y`` with at least ``axes`` axes and the same last axis ``d``."""
    x, y = (as_float_array(arr, name, min_ndim=axes) for arr, name in zip((x, y), names))
    _check_pair_shapes(x.shape, y.shape, names, axes)
    return x, y


def _check_pair_shapes(xs: tuple, ys: tuple, names: tuple, axes: int) -> None:
    """Refuse paths of shapes ``xs``, ``ys`` (at least ``axes`` axes) without a point or a coordinate, or whose
    ``d`` differ (also the JAX front end's check, made on the shapes before tracing)."""
    shape_doc = "(..., n, d)" if axes == 2 else "(..., a, n, d)"
    for shape, name in zip((xs, ys), names):
        if shape[-2] < 1 or shape[-1] < 1:
            raise ValueError(f"{name} must have shape {shape_doc} with at least one point and one coordinate, "
                             f"got shape {tuple(shape)}.")
    if xs[-1] != ys[-1]:
        raise ValueError(f"{names[0]} has d={xs[-1]} coordinates (last axis) but {names[1]} has "
                         f"d={ys[-1]}: both paths must live in the same R^d; select or pad the channels "
                         f"so that {names[0]}.shape[-1] == {names[1]}.shape[-1].")


def _batch(bx: tuple, by: tuple, names: tuple) -> tuple:
    try:
        return tuple(np.broadcast_shapes(bx, by))
    except ValueError:
        raise ValueError(f"the batch axes of {names[0]} {bx} and {names[1]} {by} do not broadcast; give them "
                         f"equal leading axes (or size 1 where one is shared).") from None


def _work(npairs: int, n: int, m: int, order: int) -> float:
    return float(npairs) * (n - 1) * (m - 1) * 4.0 ** order


def _padded(idx: np.ndarray) -> np.ndarray:
    """Pair indices padded to whole lane groups by repeating the last pair (its value is discarded)."""
    L = _goursat.LANES
    pad = (-idx.shape[0]) % L
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    return np.concatenate([idx, np.full(pad, idx[-1], dtype=np.int64)]) if pad else idx


#: Bytes a pair holds in the public calls besides the PDE rows: its two flat indices and their padded copies
#: (``_flat_index(...).ravel()``, :func:`_padded`), 32, and its kernel, 8; the gradients add its cotangent's flat
#: copy, 8 (their per-pair point cotangents are counted apart).
_PAIR_BYTES, _PAIR_BYTES_GRAD = 40.0, 48.0


def _check_size(npairs: int, n: int, m: int, order: int, d: int, grad: bool, *, pairs: bool = False) -> None:
    """Refuse a call whose work or memory is above the budget; ``pairs``: count the per-pair index arrays and
    results too (the public calls check before they build them; the MMD test counts them in its own estimate)."""
    check_work(_work(npairs, n, m, order), f"signature kernel of {npairs} pair(s) of {n} and {m} points at "
               f"dyadic_order={order}", "lower dyadic_order, subsample the paths, or split the batch")
    S = 2 ** order
    per_group = 8.0 * _goursat.LANES * ((m - 1) * S + 1) * (2 + (n + S if grad else 0))
    per_pair = (_PAIR_BYTES_GRAD if grad else _PAIR_BYTES) if pairs else 0.0
    check_memory(per_group * 64 + (8.0 * npairs * (n + m) * d if grad else 0.0) + per_pair * npairs,
                 f"signature kernel{' gradient' if grad else ''} of {npairs} pair(s) at dyadic_order={order} of "
                 f"paths of {n} and {m} points", "lower dyadic_order or split the batch (fewer pairs per call)")


def _feature_length(Z: np.ndarray, rbf: bool) -> float:
    """Length of the piecewise-linear path ``Z (n, d)`` in the static kernel's feature space.

    Linear: ``Σ |z_{t+1} - z_t|``; RBF (``Z`` already divided by σ): ``Σ sqrt(2 - 2 κ(z_t, z_{t+1}))``,
    the distance of consecutive feature vectors. The signature's level ``k`` has norm at most
    ``L**k / k!``, so ``|k(x, y)| <= Σ_k (Lx Ly)**k / (k!)**2 = I0(2 sqrt(Lx Ly)) <= exp(2 sqrt(Lx Ly))``.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        dz = np.diff(Z, axis=0)
        top = np.max(np.abs(dz), axis=-1, initial=0.0)
        safe = np.where((top > 0) & np.isfinite(top), top, 1.0)
        step = np.where(np.isfinite(top), safe * np.sqrt(np.sum((dz / safe[:, None]) ** 2, axis=-1)), np.inf)
        if rbf:
            step = np.sqrt(2.0 - 2.0 * np.exp(-0.5 * step * step))
        return float(np.sum(step))


#: ``Lx * Ly`` below this keeps every kernel (and every value in its PDE grid) below ``exp(2 sqrt(C))``,
#: about ``1e300``: the fix the overflow message proposes.
_SAFE_LENGTH_PRODUCT = 1.2e5


def _finite_or_raise(values: np.ndarray, X, Y, ia, ib, rbf: bool, what: str) -> None:
    """Raise, naming the scale and the fix, if a pair's kernel (or gradient) overflowed float64.

    The Goursat solution of two paths of feature-space lengths ``Lx``, ``Ly`` can be as large as
    ``exp(2 sqrt(Lx Ly))``; beyond ``Lx Ly ~ 1.3e5`` it leaves float64 (``inf``, then ``inf - inf = nan``).
    """
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size == 0:
        return
    k = int(bad[0])
    i, j = int(ia[k]), int(ib[k])
    lx, ly = _feature_length(X[i], rbf), _feature_length(Y[j], rbf)
    root = np.sqrt(lx) * np.sqrt(ly)                   # sqrt(Lx Ly) without overflowing the product
    log10 = 2.0 * root / np.log(10.0)
    if rbf:
        fix = ("use a larger sigma in RBFKernel(sigma) (fewer, shorter steps in feature space) or subsample "
               "the paths")
    else:
        shrink = np.sqrt(_SAFE_LENGTH_PRODUCT) / root if 0 < root < np.inf else 0.0
        fix = (f"scale the paths down: with static_kernel=LinearKernel(scale=s) the lengths are multiplied by s, "
               f"and s <= {shrink:.3g} times the current scale keeps Lx*Ly <= {_SAFE_LENGTH_PRODUCT:.3g} "
               f"(kernels below ~1e300); or normalise the paths (e.g. divide by their length)")
    raise ValueError(f"the signature kernel{'' if what == 'kernel' else ' gradient'} of {bad.size} pair(s) "
                     f"overflows float64 (inf or nan); the first is the pair of paths {i} and {j} (flattened batch "
                     f"indices), whose lengths in the static kernel's feature space (after its scale) are "
                     f"Lx={lx:.3g} and Ly={ly:.3g}: the kernel can grow like exp(2 sqrt(Lx Ly)) = 10^{log10:.3g}; "
                     f"{fix}.")


def _readonly(a: np.ndarray) -> np.ndarray:
    """A read-only view: the Goursat kernels compile one specialisation whether the caller's paths are
    writeable or not (JAX hands read-only arrays; each combination of flags compiled anew, 7-14 s of CPU)."""
    v = a.view()
    v.flags.writeable = False
    return v


def _pairs_kernel(X: np.ndarray, Y: np.ndarray, ia: np.ndarray, ib: np.ndarray, rbf: bool, order: int, *,
                  checked: bool = False) -> np.ndarray:
    """Kernels of the pairs ``(X[ia[k]], Y[ib[k]])`` of validated, scaled ``(A, n, d)``, ``(B, m, d)`` arrays
    (``checked``: the caller checked the sizes already)."""
    npairs, n, m = ia.shape[0], X.shape[1], Y.shape[1]
    out = np.ones(npairs)
    if npairs == 0 or n < 2 or m < 2:
        return out
    if not checked:
        _check_size(npairs, n, m, order, X.shape[2], False)
    ia, ib = _padded(ia), _padded(ib)
    ngroups = ia.shape[0] // _goursat.LANES
    per_group = _work(_goursat.LANES, n, m, order) * 4
    X, Y = _readonly(X), _readonly(Y)
    _threads.run(lambda lo, hi: _goursat.kernel_groups(X, Y, ia, ib, rbf, order, lo, hi, out),
                 _threads.ranges(ngroups, per_group))
    _finite_or_raise(out, X, Y, ia, ib, rbf, "kernel")
    return out


def _pairs_vjp(X, Y, ia, ib, rbf: bool, order: int, gout: np.ndarray) -> tuple:
    """Per-pair cotangents ``(P, n, d)``, ``(P, m, d)`` of the (scaled) points (the caller checked the sizes)."""
    npairs, n, d, m = ia.shape[0], X.shape[1], X.shape[2], Y.shape[1]
    gx, gy = np.zeros((npairs, n, d)), np.zeros((npairs, m, d))
    if npairs == 0 or n < 2 or m < 2:
        return gx, gy
    ia, ib = _padded(ia), _padded(ib)
    X, Y, gout = _readonly(X), _readonly(Y), _readonly(np.ascontiguousarray(gout, dtype=np.float64))
    ngroups = ia.shape[0] // _goursat.LANES
    per_group = _work(_goursat.LANES, n, m, order) * 16
    _threads.run(lambda lo, hi: _goursat.vjp_groups(X, Y, ia, ib, rbf, order, gout, lo, hi, gx, gy),
                 _threads.ranges(ngroups, per_group))
    bad = ~(np.isfinite(gx).all(axis=(1, 2)) & np.isfinite(gy).all(axis=(1, 2)))
    _finite_or_raise(np.where(bad, np.inf, 0.0), X, Y, ia, ib, rbf, "gradient")
    return gx, gy


def _unbroadcast(g: np.ndarray, shape: tuple) -> np.ndarray:
    """Sum ``g`` over the axes along which an array of ``shape`` was broadcast to ``g.shape``."""
    extra = g.ndim - len(shape)
    if extra:
        g = g.sum(axis=tuple(range(extra)))
    axes = tuple(i for i, (s, t) in enumerate(zip(shape, g.shape)) if s == 1 and t != 1)
    return g.sum(axis=axes, keepdims=True) if axes else g


def _flat_index(shape: tuple, batch: tuple, inner: int) -> np.ndarray:
    """Index of the flattened ``shape + (inner,)`` entry that every ``batch + (inner,)`` entry reads."""
    base = np.arange(int(np.prod(shape, dtype=np.int64)) * inner, dtype=np.int64).reshape(shape + (inner,))
    return np.broadcast_to(base, batch + (inner,))


def _check_options(dyadic_order, static_kernel) -> tuple:
    """``(order, rbf, factor)`` of valid ``dyadic_order`` and ``static_kernel``, or a clear error (also the JAX
    front end's check, before tracing)."""
    order = _check_order(dyadic_order)
    if order > _MAX_ORDER:
        raise ValueError(f"dyadic_order={order} refines each step 2**{order} times; use dyadic_order <= "
                         f"{_MAX_ORDER} (the discretisation error falls like 4**-dyadic_order: 2 to 4 is typical).")
    rbf, factor = _resolve(static_kernel)
    if not np.isfinite(factor):           # RBFKernel(sigma) with 1/sigma beyond float64 (sigma < ~5.6e-309)
        raise ValueError(f"static_kernel={static_kernel!r}: the paths are divided by sigma, and 1/sigma overflows "
                         f"float64; pass a sigma of at least 1e-300 (in the units of the paths' values), or "
                         f"rescale the paths.")
    return order, rbf, factor


def _setup(x, y, dyadic_order, static_kernel, names, axes):
    order, rbf, factor = _check_options(dyadic_order, static_kernel)
    x, y = _check_pair(x, y, names, axes)
    for arr, name in zip((x, y), names):
        if factor != 1.0 and arr.size:
            top = float(np.max(np.abs(arr)))
            if not np.isfinite(top * factor):
                raise ValueError(f"static_kernel={static_kernel!r} scales the paths by {factor:.3g}, and "
                                 f"max |{name}| = {top:.3g} times that overflows float64; use a static kernel "
                                 f"of smaller scale (larger sigma) or rescale the paths.")
    return x, y, order, rbf, factor


def _scaled(a: np.ndarray, lead: int, factor: float) -> np.ndarray:
    flat = a.reshape((-1,) + a.shape[a.ndim - lead:]) if a.size else a.reshape((0,) + a.shape[a.ndim - lead:])
    return np.ascontiguousarray(flat * factor if factor != 1.0 else flat)


def kernel_shape(x_shape: tuple, y_shape: tuple, *, gram: bool = False, dyadic_order=0, static_kernel=None) -> tuple:
    """The shape of ``signature_kernel`` (``signature_kernel_gram`` with ``gram``) for paths of these shapes, after the
    checks the shapes and the options decide (a point and a coordinate in each path, one ``d``, broadcasting batch
    axes, ``dyadic_order``, ``static_kernel``). For callers that allocate the result themselves (the JAX front end)."""
    axes = 3 if gram else 2
    names = ("X", "Y") if gram else ("x", "y")
    _check_options(dyadic_order, static_kernel)
    for shape, name in zip((x_shape, y_shape), names):
        if len(shape) < axes:
            raise ValueError(f"{name} must have at least {axes} axes, got shape {tuple(shape)}; add the missing axes "
                             f"(e.g. {name}[None]).")
    _check_pair_shapes(x_shape, y_shape, names, axes)
    batch = _batch(tuple(x_shape[:-axes]), tuple(y_shape[:-axes]), names)
    return batch + ((x_shape[-3], y_shape[-3]) if gram else ())


def signature_kernel(x, y, *, dyadic_order: int = 0, static_kernel=None):
    r"""Signature kernel ``k(x, y) = <S(x), S(y)>`` of pairs of piecewise-linear paths.

    Parameters
    ----------
    x : array_like, shape ``(..., n, d)``
        Paths of ``n`` points in ``R^d`` (finite).
    y : array_like, shape ``(..., m, d)``
        Paths of ``m`` points in the same ``R^d``; the batch axes of ``x`` and ``y`` broadcast.
    dyadic_order : int
        Each step of both paths is refined ``2**dyadic_order`` times in the PDE grid (default 0). The
        error of the scheme falls like ``4**-dyadic_order``; the cost grows like ``4**dyadic_order``.
    static_kernel : None, LinearKernel or RBFKernel
        The kernel on ``R^d`` lifted to paths (``None``: linear, ``<dx, dy>``).

    Returns
    -------
    ndarray, shape ``(...)``
        The kernels (a 0-d ``numpy.float64`` for one pair). A path of a single point has ``k = 1``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [0.3, 0.1]])     # one segment each: S = exp(dx), exp(dy), so
    >>> y = np.array([[0.0, 0.0], [0.2, -0.4]])    # k = sum_j <dx, dy>**j / (j!)**2 with <dx, dy> = 0.02
    >>> exact = sum(0.02 ** j / np.prod(np.arange(1.0, j + 1)) ** 2 for j in range(10))
    >>> k = signature_kernel(x, y, dyadic_order=3)
    >>> round(float(exact), 8), float(abs(k - exact)) < 1e-8       # the scheme's error: 2.8e-9 here
    (1.02010022, True)
    """
    x, y, order, rbf, factor = _setup(x, y, dyadic_order, static_kernel, ("x", "y"), 2)
    batch = _batch(x.shape[:-2], y.shape[:-2], ("x", "y"))
    _check_size(int(np.prod(batch, dtype=np.int64)), x.shape[-2], y.shape[-2], order, x.shape[-1], False, pairs=True)
    ia = _flat_index(x.shape[:-2], batch, 1).ravel()
    ib = _flat_index(y.shape[:-2], batch, 1).ravel()
    out = _pairs_kernel(_scaled(x, 2, factor), _scaled(y, 2, factor), ia, ib, rbf, order, checked=True)
    return out.reshape(batch)[()]


def signature_kernel_gram(X, Y, *, dyadic_order: int = 0, static_kernel=None) -> np.ndarray:
    r"""Gram matrices ``K[..., i, j] = k(X[..., i], Y[..., j])`` of the signature kernel.

    Parameters
    ----------
    X : array_like, shape ``(..., a, n, d)``
        ``a`` paths of ``n`` points.
    Y : array_like, shape ``(..., b, m, d)``
        ``b`` paths of ``m`` points in the same ``R^d``; batch axes (before ``a``, ``b``) broadcast.
    dyadic_order, static_kernel
        As for :func:`signature_kernel`.

    Returns
    -------
    ndarray, shape ``(..., a, b)``

    Examples
    --------
    >>> import numpy as np
    >>> X = np.random.default_rng(0).normal(size=(3, 5, 2)).cumsum(axis=-2) * 0.3
    >>> K = signature_kernel_gram(X, X, dyadic_order=1)
    >>> K.shape, bool(np.allclose(K, K.T)), bool(np.all(np.linalg.eigvalsh(K) > 0))
    ((3, 3), True, True)
    """
    X, Y, order, rbf, factor = _setup(X, Y, dyadic_order, static_kernel, ("X", "Y"), 3)
    batch = _batch(X.shape[:-3], Y.shape[:-3], ("X", "Y"))
    a, b = X.shape[-3], Y.shape[-3]
    _check_size(int(np.prod(batch + (a, b), dtype=np.int64)), X.shape[-2], Y.shape[-2], order, X.shape[-1], False,
                pairs=True)
    ia = np.broadcast_to(_flat_index(X.shape[:-3], batch, a)[..., :, None], batch + (a, b)).ravel()
    ib = np.broadcast_to(_flat_index(Y.shape[:-3], batch, b)[..., None, :], batch + (a, b)).ravel()
    out = _pairs_kernel(_scaled(X, 2, factor), _scaled(Y, 2, factor), ia, ib, rbf, order, checked=True)
    return out.reshape(batch + (a, b))


def _check_grad(grad_output, shape: tuple, fn: str) -> np.ndarray:
    g = as_float_array(grad_output, "grad_output")
    if g.shape != shape:
        raise ValueError(f"grad_output has shape {g.shape}, expected {shape}: the shape of {fn}'s result.")
    return g


def signature_kernel_vjp(x, y, grad_output, *, dyadic_order: int = 0, static_kernel=None) -> tuple:
    r"""Vector–Jacobian product of :func:`signature_kernel` with respect to the points of both paths.

    Exact for the discretised kernel that :func:`signature_kernel` returns (an adjoint sweep of the same
    scheme, not the continuous adjoint PDE).

    Parameters
    ----------
    x, y, dyadic_order, static_kernel
        As for :func:`signature_kernel`.
    grad_output : array_like, shape ``(...)``
        A cotangent of the kernels (the broadcast batch shape).

    Returns
    -------
    grad_x : ndarray, shape of ``x``
    grad_y : ndarray, shape of ``y``
        ``sum(grad_output * dk/dx)`` (summed over the axes along which ``x`` was broadcast), likewise ``y``.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [0.3, 0.1]]); y = np.array([[0.0, 0.0], [0.2, -0.4]])
    >>> gx, gy = signature_kernel_vjp(x, y, 1.0, dyadic_order=3)
    >>> dk = 1 + 0.02 / 2 + 0.02 ** 2 / 12            # d/dc of sum_j c**j / (j!)**2 at c = <dx, dy>
    >>> bool(np.allclose(gx[1], dk * (y[1] - y[0]), rtol=1e-6)), bool(np.allclose(gx[0], -gx[1]))
    (True, True)
    """
    x, y, order, rbf, factor = _setup(x, y, dyadic_order, static_kernel, ("x", "y"), 2)
    batch = _batch(x.shape[:-2], y.shape[:-2], ("x", "y"))
    g = _check_grad(grad_output, batch, "signature_kernel(x, y)")
    _check_size(g.size, x.shape[-2], y.shape[-2], order, x.shape[-1], True, pairs=True)
    ia = _flat_index(x.shape[:-2], batch, 1).ravel()
    ib = _flat_index(y.shape[:-2], batch, 1).ravel()
    gx, gy = _pairs_vjp(_scaled(x, 2, factor), _scaled(y, 2, factor), ia, ib, rbf, order, g.ravel())
    gx = _unbroadcast(gx.reshape(batch + x.shape[-2:]), x.shape) * factor
    gy = _unbroadcast(gy.reshape(batch + y.shape[-2:]), y.shape) * factor
    return np.ascontiguousarray(gx.reshape(x.shape)), np.ascontiguousarray(gy.reshape(y.shape))


def signature_kernel_gram_vjp(X, Y, grad_output, *, dyadic_order: int = 0, static_kernel=None) -> tuple:
    r"""Vector–Jacobian product of :func:`signature_kernel_gram` with respect to the points of ``X`` and ``Y``.

    Parameters
    ----------
    X, Y, dyadic_order, static_kernel
        As for :func:`signature_kernel_gram`.
    grad_output : array_like, shape ``(..., a, b)``
        A cotangent of the Gram matrices.

    Returns
    -------
    grad_X : ndarray, shape of ``X``
    grad_Y : ndarray, shape of ``Y``

    Examples
    --------
    >>> import numpy as np
    >>> X = np.random.default_rng(1).normal(size=(2, 4, 2)) * 0.3
    >>> gX, gY = signature_kernel_gram_vjp(X, X, np.eye(2))       # gradient of k(X0, X0) + k(X1, X1)
    >>> gX.shape, bool(np.allclose(gX, gY))
    ((2, 4, 2), True)
    """
    X, Y, order, rbf, factor = _setup(X, Y, dyadic_order, static_kernel, ("X", "Y"), 3)
    batch = _batch(X.shape[:-3], Y.shape[:-3], ("X", "Y"))
    a, b = X.shape[-3], Y.shape[-3]
    g = _check_grad(grad_output, batch + (a, b), "signature_kernel_gram(X, Y)")
    _check_size(g.size, X.shape[-2], Y.shape[-2], order, X.shape[-1], True, pairs=True)
    ia = np.broadcast_to(_flat_index(X.shape[:-3], batch, a)[..., :, None], batch + (a, b)).ravel()
    ib = np.broadcast_to(_flat_index(Y.shape[:-3], batch, b)[..., None, :], batch + (a, b)).ravel()
    gx, gy = _pairs_vjp(_scaled(X, 2, factor), _scaled(Y, 2, factor), ia, ib, rbf, order, g.ravel())
    gX = gx.reshape(batch + (a, b) + X.shape[-2:]).sum(axis=-3)
    gY = gy.reshape(batch + (a, b) + Y.shape[-2:]).sum(axis=-4)
    gX = _unbroadcast(gX, X.shape) * factor
    gY = _unbroadcast(gY, Y.shape) * factor
    return np.ascontiguousarray(gX.reshape(X.shape)), np.ascontiguousarray(gY.reshape(Y.shape))
