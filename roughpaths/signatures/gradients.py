r"""Gradients of the signature maps: vector–Jacobian products (the quantities of ``iisignature.sigbackprop``).

:func:`signature_vjp` and :func:`logsignature_vjp` are taken with respect to the path points,
:func:`rough_path_signature_vjp` with respect to the step increments and areas of a level-2 rough
path; layouts and conventions as in :mod:`roughpaths.signatures.signature` (which re-exports these three).
The backward pass runs on the same work units as the forward kernels
(:mod:`roughpaths.signatures._vjp`), so it is bitwise independent of the thread count and of the batch.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import _threads
from ..algebra.flat import level_offsets, lyndon_flat_vjp
from ..validation import as_float_array
from . import _lanes
from . import _level2 as _l2
from . import _rough_vjp, _vjp, _vjp_wide
from ._engine import (_F64, _WIDE, _all_finite, _check_depth, _check_fits, _check_paths, _horner_chunks,
                      _kernel_array, _logsigdim, _reversed_parts, _reversed_signature, _reversed_to_rowmajor, _sigdim,
                      _signature_flat, _split_units, _units)
from .signature import rough_path_signature

__all__ = ["signature_vjp", "logsignature_vjp", "rough_path_signature_vjp"]


def _check_grad(grad_output, batch: tuple, width: int, what: str) -> np.ndarray:
    if (type(grad_output) is np.ndarray and grad_output.dtype == _F64 and grad_output.ndim >= 1
            and _all_finite(grad_output)):
        g = grad_output                             # what as_float_array returns for it, without its checks
    else:
        g = as_float_array(grad_output, "grad_output", min_ndim=1)
    if g.shape != batch + (width,):
        raise ValueError(f"grad_output has shape {g.shape}, expected {batch + (width,)}: the shape of "
                         f"{what}(paths, depth) (batch axes of paths, then {width}).")
    return _kernel_array(g, (-1, width))


def _finite_grad(gx: np.ndarray, x: np.ndarray, g: np.ndarray, depth: int, what: str) -> np.ndarray:
    """``gx``, the VJP of finite ``paths`` ``x`` and ``grad_output`` ``g``, if it is finite; else raise: it overflowed
    (a scan of the points' cotangent, the size of the paths: cheap beside the VJP's ``depth d**depth`` a point)."""
    if _all_finite(gx):
        return gx
    top = float(np.max(np.abs(x), initial=0.0))
    gtop = float(np.max(np.abs(g), initial=0.0))
    raise ValueError(f"the gradient of the depth-{depth} {what} overflows float64 (inf or nan) for finite paths (values "
                     f"up to {top:.3g} in absolute value) and grad_output (up to {gtop:.3g}): the level-k terms grow "
                     f"like the k-th power of a path's length. Rescale the paths (e.g. divide them by their length "
                     f"or standard deviation) or grad_output, or lower depth.")


def _increments_to_points(gd: np.ndarray, n: int) -> np.ndarray:
    """Cotangent of the points from that of the increments ``x_k - x_{k-1}``."""
    gx = np.zeros((gd.shape[0], n, gd.shape[-1]))
    gx[:, 1:] += gd
    gx[:, :-1] -= gd
    return gx


def _signature_vjp_flat(x: np.ndarray, depth: int, g_row: np.ndarray) -> np.ndarray:
    """``(B, n, d)`` cotangent of the points given the row-major ``(B, sigdim)`` cotangent of the signature."""
    nb, n, d = x.shape
    if n == 1 or nb == 0:
        return np.zeros(x.shape)
    if depth == 1:
        gx = np.zeros(x.shape)
        gx[:, -1] += g_row
        gx[:, 0] -= g_row
        return gx
    if depth == 2:                                # closed form, d^2 operations a point
        gx = np.empty(x.shape)
        g2 = _kernel_array(g_row, g_row.shape)
        _threads.run(lambda lo, hi: _l2.sig2_vjp_rows(x, g2, lo, hi, gx), _threads.ranges(nb, n * d * d))
        return gx
    return _signature_vjp_rev(x, depth, g_row.take(_rowmajor_to_reversed(d, depth), axis=1))


@lru_cache(maxsize=None)
def _rowmajor_to_reversed(dim: int, depth: int) -> np.ndarray:
    """Gather index: ``reversed = rowmajor[..., inv]``, the inverse of :func:`_reversed_to_rowmajor` (a gather by
    ``take`` costs half the scatter ``reversed[..., perm] = rowmajor`` on small batches; the same values)."""
    perm = _reversed_to_rowmajor(dim, depth)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(perm.shape[0])
    return inv


@lru_cache(maxsize=64)
def _vjp_plan(nb: int, n: int, d: int, depth: int) -> tuple:
    """What :func:`_signature_vjp_rev` runs for a ``(nb, n, d)`` batch (a function of the shape, made once):
    ``(nchunks, units, offsets, (lane kernel, ranges) or None, (one-unit kernel, first unit, ranges) or None)``."""
    off = level_offsets(d, depth)
    nchunks = _horner_chunks(n, d, depth)
    nunits = nb * nchunks
    per_unit = (n / nchunks) * 5 * d ** depth
    ngroups, first_alone = _split_units(nunits, d, depth)         # the same bits either way
    lanes = (_vjp.sig_vjp_groups(d), _threads.ranges(ngroups, per_unit * _lanes.LANES)) if ngroups else None
    if d >= _WIDE:                                          # every unit alone, the top level in blocks
        alone = (_vjp_wide.sig_vjp_wide(d), 0, _threads.ranges(nunits, per_unit))
    elif first_alone < nunits:
        alone = (_vjp.sig_vjp_units(d), first_alone, _threads.ranges(nunits - first_alone, per_unit))
    else:
        alone = None
    return nchunks, _units(nb, n, nchunks), off, lanes, alone


def _signature_vjp_rev(x: np.ndarray, depth: int, g_rev: np.ndarray, part: np.ndarray | None = None) -> np.ndarray:
    """:func:`_signature_vjp_flat` (``n >= 2``, ``depth >= 3``) for a cotangent ``g_rev`` in the kernels' reversed
    layout; ``part``, the forward signatures of the work units (:func:`_reversed_parts`), if already computed."""
    nb, n, d = x.shape
    nchunks, (ub, ulo, uhi), off, lanes, alone = _vjp_plan(nb, n, d, depth)
    if part is None:
        part = _reversed_parts(x, depth, nchunks)
    gunit = g_rev                               # the cotangent of each unit's signature: its path's, unchunked
    if nchunks > 1:
        gunit = np.empty(part.shape)
        _threads.run(lambda lo, hi: _vjp.unit_cotangents(part, g_rev, nchunks, d, depth, off, lo, hi, gunit),
                     _threads.ranges(part.shape[0], 2.0 * nchunks * part.shape[1]), merge=True)
    gd = np.zeros((nb, n - 1, d))
    if lanes is not None:
        kernel, parts = lanes
        _threads.run(lambda lo, hi: kernel(x, ub, ulo, uhi, depth, off, part, gunit, lo, hi, gd), parts)
    if alone is not None:
        one, first, parts = alone
        _threads.run(lambda lo, hi: one(x, ub, ulo, uhi, depth, off, part, gunit, first + lo, first + hi, gd), parts)
    return _increments_to_points(gd, n)


def signature_vjp(paths, depth: int, grad_output) -> np.ndarray:
    r"""Vector–Jacobian product of :func:`signature` with respect to the path points.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
        As for :func:`signature`.
    depth : int
        Truncation level ``m >= 1``.
    grad_output : array_like, shape ``(..., sigdim(d, m))``
        A cotangent ``G`` of the signature (e.g. the gradient of a loss with respect to it),
        in :func:`signature`'s layout.

    Returns
    -------
    ndarray, shape ``(..., n, d)``
        :math:`\partial \langle G, S(x) \rangle / \partial x`, the same quantity as
        ``iisignature.sigbackprop(G, paths, m)``.

    Notes
    -----
    Backward through Chen's identity segment by segment, last to first: the signature before a
    segment is recovered as :math:`S \otimes \exp(-\Delta)` (nothing of the forward pass is
    stored), the increment's cotangent is the derivative of :math:`\langle S_{prev} \rhd G,
    \exp(\Delta)\rangle`, and :math:`G \leftarrow G \lhd \exp(\Delta)`. Memory is a few
    signatures per path. Long paths are cut into the same chunks as :func:`signature`. At depth 2
    the cotangent has a closed form, ``d^2`` operations a point (``roughpaths.signatures._level2``).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    >>> g = np.zeros(6); g[3] = 1.0                  # gradient of the word (1, 2): ∫ X^1 dX^2
    >>> signature_vjp(x, 2, g)
    array([[-1. , -0.5],
           [ 0.5, -0.5],
           [ 0.5,  1. ]])
    """
    depth = _check_depth(depth)
    x = _check_paths(paths)
    batch, (n, d) = x.shape[:-2], x.shape[-2:]
    g = _check_grad(grad_output, batch, _sigdim(d, depth), "signature")
    flat = _kernel_array(x, (-1, n, d))
    _check_fits(flat.shape[0], d, depth, log=True, n=n)
    return _finite_grad(_signature_vjp_flat(flat, depth, g), x, g, depth, "signature").reshape(x.shape)


def logsignature_vjp(paths, depth: int, grad_output) -> np.ndarray:
    r"""Vector–Jacobian product of :func:`logsignature` with respect to the path points.

    Parameters
    ----------
    paths : array_like, shape ``(..., n, d)``
    depth : int
    grad_output : array_like, shape ``(..., logsigdim(d, m))``
        Cotangent of the Lyndon coordinates returned by :func:`logsignature`.

    Returns
    -------
    ndarray, shape ``(..., n, d)``
        :math:`\partial \langle G, \mathrm{logsig}(x) \rangle / \partial x`, the same quantity as
        ``iisignature.logsigbackprop(G, paths, prepare(d, m))``.

    Notes
    -----
    Chains three transposes: of the Lyndon projection (back substitution with the sparse
    triangular map), of the truncated logarithm (backward through its Horner recursion), and
    :func:`signature_vjp`.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    >>> signature_vjp(x, 2, [0, 0, 0, 0.5, -0.5, 0]) == logsignature_vjp(x, 2, [0, 0, 1.0])
    array([[ True,  True],
           [ True,  True],
           [ True,  True]])
    """
    depth = _check_depth(depth)
    x = _check_paths(paths)
    batch, (n, d) = x.shape[:-2], x.shape[-2:]
    g = _check_grad(grad_output, batch, _logsigdim(d, depth), "logsignature")
    flat = _kernel_array(x, (-1, n, d))
    if depth == 1 or d == 1:
        g_sig = np.zeros((flat.shape[0], _sigdim(d, depth)))
        g_sig[:, :d] = g
        return _finite_grad(_signature_vjp_flat(flat, depth, g_sig), x, g, depth, "log-signature").reshape(x.shape)
    _check_fits(flat.shape[0], d, depth, log=True, n=n)
    off = level_offsets(d, depth)
    perm = _reversed_to_rowmajor(d, depth)
    g_log_rev = lyndon_flat_vjp(g, d, depth).take(_rowmajor_to_reversed(d, depth), axis=1)
    small = depth == 2 or n == 1 or flat.shape[0] == 0      # the general route's special cases
    if small:
        sig_rev = _signature_flat(flat, depth).take(_rowmajor_to_reversed(d, depth), axis=1)
    else:
        # the forward signatures of the work units, computed once: glued for the log's backward pass, and
        # handed to the signature's backward pass (which would otherwise recompute them)
        part, sig_rev = _reversed_signature(flat, depth, _horner_chunks(n, d, depth))
    g_sig_rev = np.empty_like(sig_rev)
    _threads.run(lambda lo, hi: _vjp.log_vjp_rows(sig_rev, g_log_rev, d, depth, off, lo, hi, g_sig_rev),
                 _threads.ranges(sig_rev.shape[0], 2.0 * depth * depth * sig_rev.shape[1]))
    if small:
        gx = _signature_vjp_flat(flat, depth, g_sig_rev.take(perm, axis=1))
    else:
        gx = _signature_vjp_rev(flat, depth, g_sig_rev, part)
    return _finite_grad(gx, x, g, depth, "log-signature").reshape(x.shape)


def rough_path_signature_vjp(X, depth: int, grad_output) -> tuple:
    r"""Vector–Jacobian product of :func:`rough_path_signature` w.r.t. the step increments and areas.

    Parameters
    ----------
    X : RoughPath
        Level 2, geometric (as for :func:`rough_path_signature`).
    depth : int
        Truncation level ``m >= 1``.
    grad_output : array_like, shape ``(*X.batch_shape, sigdim(d, m))``
        Cotangent ``G`` of the signature, in :func:`signature`'s layout.

    Returns
    -------
    g_increments : ndarray, shape ``(*X.batch_shape, N, d)``
        :math:`\partial \langle G, S \rangle / \partial X_{t_k, t_{k+1}}` (``X.increments``).
    g_areas : ndarray, shape ``(*X.batch_shape, N, d, d)``
        :math:`\partial \langle G, S \rangle / \partial \mathbb{X}_{t_k, t_{k+1}}` (``X.areas``).
        The extension depends on an area only through its antisymmetric part (the Lévy area
        :math:`\tfrac12(\mathbb{X} - \mathbb{X}^T)`), so this is antisymmetric.

    Examples
    --------
    >>> import numpy as np
    >>> from roughpaths import RoughPath
    >>> X = RoughPath.from_path(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))
    >>> g = np.zeros(6); g[3] = 1.0                     # the word (1, 2)
    >>> gi, ga = rough_path_signature_vjp(X, 2, g)
    >>> gi                                              # d/d inc_0 of ½ x1 x2 + inc_0^1 inc_1^2
    array([[1. , 0.5],
           [0.5, 1. ]])
    >>> ga[0]
    array([[ 0. ,  0.5],
           [-0.5,  0. ]])
    """
    from ..paths.rough_path import RoughPath

    if not isinstance(X, RoughPath):
        raise TypeError(f"X must be a RoughPath, got {type(X).__name__}.")
    depth = _check_depth(depth)
    sig = rough_path_signature(X, depth)                  # validates level and kind
    d, n, batch = X.dim, X.n_steps, X.batch_shape
    g = _check_grad(grad_output, batch, _sigdim(d, depth), "rough_path_signature")
    perm = _reversed_to_rowmajor(d, depth)
    s_rev = np.empty((g.shape[0], sig.shape[-1]))
    s_rev[:, perm] = sig.reshape((-1, sig.shape[-1]))
    g_rev = np.empty_like(g)
    g_rev[:, perm] = g
    inc = _kernel_array(X.increments, (-1, n, d))
    lev = _kernel_array(X.step_levy_areas, (-1, n, d, d))
    ginc = np.zeros(inc.shape)
    glev = np.zeros(lev.shape)
    off = level_offsets(d, depth)
    _threads.run(lambda lo, hi: _rough_vjp.rough_vjp_rows(inc, lev, s_rev, g_rev, depth, off, lo, hi, ginc, glev),
                 _threads.ranges(inc.shape[0], 4 * n * depth * depth * _sigdim(d, depth)))
    garea = 0.5 * (glev - np.swapaxes(glev, -1, -2))
    return ginc.reshape(batch + (n, d)), garea.reshape(batch + (n, d, d))
