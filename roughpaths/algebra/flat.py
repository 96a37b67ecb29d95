r"""Flat truncated tensors: the layout shared by the tensor algebra and the signature engine.

An element of the truncated tensor algebra :math:`T^m(\mathbb{R}^d)` without its scalar is a flat
float64 vector of length ``sigdim(d, m) = d + d**2 + ... + d**m``: levels ``1..m`` concatenated,
row-major words (iisignature's layout). ``level_offsets(d, m)[k]`` is the start of level ``k``.

The functions here take C-contiguous ``(B, sigdim)`` batches that the caller has validated, run the
compiled kernels (private to :mod:`roughpaths.algebra`) split over threads by
:mod:`roughpaths._threads`, and return new arrays. They are the low-level door that
:mod:`roughpaths.signatures` uses; users call :func:`roughpaths.tensor_log` and
:func:`roughpaths.lyndon_coordinates`, which check their input first.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import _threads
from . import _kernels as _k
from ._lyndon import lyndon_levels

__all__ = ["level_offsets", "log_flat", "lyndon_flat", "log_lyndon_flat", "lyndon_flat_vjp", "product_flat"]


@lru_cache(maxsize=512)
def level_offsets(dim: int, depth: int) -> np.ndarray:
    """Start of each level in the flat layout: ``off[k]`` for ``k = 1..depth+1`` (``off[1] = 0``).

    Cached and shared by every caller: never write to it. (Left writeable: numba compiles a separate
    kernel for a read-only array.)

    >>> level_offsets(2, 3)[1:]
    array([ 0,  2,  6, 14])
    """
    off = np.zeros(depth + 2, dtype=np.int64)
    for k in range(1, depth + 1):
        off[k + 1] = off[k] + dim ** k
    return off


@lru_cache(maxsize=512)
def _log_work(dim: int, depth: int) -> float:
    """A row's work in :func:`log_flat`, in units of :data:`roughpaths._threads.SPLIT_WORK` (~0.23 ns here): 1.2 a
    multiply-add of the Horner scheme and 300 a level (its loops). Measured per row, one thread: 1.0-1.4 units a
    multiply-add at d = 3-20 (d = 3 at depth 6: 11.5k units, 2.6 us; d = 8 at depth 4: 20.8k; d = 20 at depth 3:
    30.7k), 2.5 at d = 2-3 for depths 4-6 (0.3-0.6 us a row, the loops' cost); the previous estimate, 1.5 a
    coefficient, was 4-14 times low, and 64 rows at d = 3, depth 6 (0.19 ms) ran on one thread."""
    madds = sum(sum(k * dim ** k for k in range(1, depth - n + 2)) for n in range(1, depth))
    return 1.2 * madds + 300.0 * depth


def log_flat(a: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """Row-major ``log(1 + a)`` of a C-contiguous ``(B, sigdim)`` float64 batch (numba, Horner)."""
    off = level_offsets(dim, depth)
    out = np.empty_like(a)
    _threads.run(lambda lo, hi: _k.log_rows(a, dim, depth, off, lo, hi, out),
                 _threads.ranges(a.shape[0], _log_work(dim, depth), _threads.SPLIT_WORK), merge=True)
    return out


def lyndon_flat(z: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """Lyndon coordinates ``(B, logsigdim)`` of a C-contiguous ``(B, sigdim)`` batch of Lie elements."""
    off = level_offsets(dim, depth)
    projections, starts, work = lyndon_levels(dim, depth)
    out = np.empty((z.shape[0], starts[-1]))
    parts = _threads.ranges(z.shape[0], _lyndon_work(work), _threads.SPLIT_WORK)
    _threads.run(lambda lo, hi: _lyndon_block(z[lo:hi], out[lo:hi], dim, depth, off, projections, starts), parts)
    return out


def _lyndon_work(work: float) -> float:
    """A row's work in :func:`lyndon_flat`, in the units of :func:`_log_work`, from ``lyndon_levels``' count: ~5 a
    coordinate or map entry and 150 a row (measured 0.07-5 us a row at d = 2-20: d = 3, depth 6 0.62 us; d = 20,
    depth 3 5.0 us; 4-6 times the count, 10 times at d = 2)."""
    return 5.0 * work + 150.0


def _lyndon_block(z: np.ndarray, out: np.ndarray, dim: int, depth: int, off, projections, starts) -> None:
    """``out[:n]`` <- the Lyndon coordinates of the Lie elements ``z[:n]``, ``n = len(out)``, every level."""
    n = out.shape[0]
    out[:, :dim] = z[:n, :dim]              # level 1: every letter is a Lyndon word, its own coordinate
    for k in range(2, depth + 1):
        lidx, indptr, indices, data = projections[k - 1]
        _k.lyndon_rows(z, off[k], lidx, indptr, indices, data, out, starts[k - 1], 0, n)


#: Bytes of logs a thread of :func:`log_lyndon_flat` holds at once (at least one row).
_LOG_ROWS_BYTES = 8 * 2 ** 20


def log_lyndon_flat(a: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """``lyndon_flat(log_flat(a, dim, depth), dim, depth)`` without the batch of logs: each thread takes the logs of
    its rows a few at a time (:data:`_LOG_ROWS_BYTES`, at least a row) into a scratch and their Lyndon coordinates
    from it. The same kernels on the same rows: the same bits. A batch of logs as large as the signatures was the
    log-signature's largest allocation; memory that a process has not touched before costs its first write (16
    signatures at d = 15, depth 5, 104 MB: the log took 330 ms into a new array, 22 ms into one written before)."""
    off = level_offsets(dim, depth)
    projections, starts, work = lyndon_levels(dim, depth)
    B, width = a.shape[0], int(off[depth + 1])
    out = np.empty((B, starts[-1]))
    step = max(1, _LOG_ROWS_BYTES // (8 * width))

    def rows(lo, hi):
        z = np.empty((min(step, hi - lo), width))
        for r0 in range(lo, hi, step):
            r1 = min(r0 + step, hi)
            _k.log_rows(a[r0:r1], dim, depth, off, 0, r1 - r0, z)
            _lyndon_block(z, out[r0:r1], dim, depth, off, projections, starts)
    _threads.run(rows, _threads.ranges(B, _log_work(dim, depth) + _lyndon_work(work), _threads.SPLIT_WORK), merge=True)
    return out


def lyndon_flat_vjp(gc: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """Cotangent ``(B, sigdim)`` (row-major) of the Lie element, given that of its Lyndon coordinates."""
    off = level_offsets(dim, depth)
    gz = np.zeros((gc.shape[0], int(off[depth + 1])))
    projections, starts, _ = lyndon_levels(dim, depth)
    for k, (lidx, indptr, indices, data) in enumerate(projections, start=1):
        _k.lyndon_vjp(gc, starts[k - 1], lidx, indptr, indices, data, gz, off[k])
    return gz


def product_flat(a: np.ndarray, b: np.ndarray, dim: int, depth: int) -> np.ndarray:
    """Chen product ``(1 + a)(1 + b) - 1`` of float64 ``(..., sigdim)`` batches (broadcast), unchecked: the arithmetic
    of :func:`roughpaths.tensor_product` (which checks its inputs and calls this). Level ``k`` is
    ``b_k + a_k + sum_{0<i<k} a_i (x) b_{k-i}``, added in that order."""
    off = level_offsets(dim, depth)
    batch = np.broadcast_shapes(a.shape[:-1], b.shape[:-1])
    out = []
    for k in range(1, depth + 1):
        c = np.zeros(batch + (dim ** k,))
        c += b[..., off[k]:off[k + 1]]
        c += a[..., off[k]:off[k + 1]]
        for i in range(1, k):
            c += (a[..., off[i]:off[i + 1], None] * b[..., None, off[k - i]:off[k - i + 1]]).reshape(c.shape)
        out.append(c)
    return np.concatenate(out, axis=-1)
