"""The signature engine's driver (private): input checks, the split of the work, and the layout.

Shared by :mod:`roughpaths.signatures.signature` and :mod:`roughpaths.signatures.gradients`. The
kernels store words with the first letter fastest (the *reversed* layout); results are returned in
row-major order (:func:`_reversed_to_rowmajor`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import _threads
from ..algebra.flat import level_offsets
from ..algebra.tensor import logsigdim, sigdim
from ..validation import as_float_array, check_memory, check_positive_int
from . import _lanes
from . import _level2 as _l2

# Work splitting depends on each path's length only (never on the thread count nor on the batch), so
# a member's result is bitwise the same alone or in any batch, on any number of threads. A path of
# n points is cut into min(_MAX_CHUNKS, (n - 1) // _MIN_CHUNK) chunks glued by Chen's identity once
# it has at least 2 _MIN_CHUNK segments (the glue costs ~depth d^depth per chunk, against
# _MIN_CHUNK d^depth for the chunk itself). Small inputs run on the calling thread (_signature_threads).
_MAX_CHUNKS = 64
_MIN_CHUNK = 1024
_MIN_CHUNK_L2 = 8192
_MAX_CHUNKS_L2 = 16


def _n_chunks(n: int, target: int, min_chunk: int) -> int:
    """Chunks per path: a function of the path length ``n`` only, so that a member's arithmetic does not
    depend on its neighbours."""
    if n - 1 < 2 * min_chunk:
        return 1
    return max(1, min(target, (n - 1) // min_chunk))


def _units(nb: int, n: int, nchunks: int) -> tuple:
    """``(path, first point, last point)`` of every work unit, path-major."""
    seg = -(-(n - 1) // nchunks)
    ub = np.repeat(np.arange(nb, dtype=np.int64), nchunks)
    lo = np.minimum(np.tile(np.arange(nchunks, dtype=np.int64), nb) * seg, n - 1)
    return ub, lo, np.minimum(lo + seg, n - 1)


def _check_depth(depth) -> int:
    return check_positive_int(depth, "depth")


#: Requests below this many bytes are not checked against the available memory.
_SMALL_REQUEST = 64 * 2 ** 20


def _check_fits(batch: int, d: int, depth: int, *, log: bool = False) -> None:
    """Refuse, before allocating, a request whose working arrays would not fit in memory.

    The signature needs about 3 arrays of ``batch * sigdim`` floats (result, chunk partials,
    layout permutation); the log-signature 2 more (log, scratch) plus the sparse Lyndon map, whose
    top level holds at most ``n_m * 2**(m-1)`` entries (12 bytes each while it is built).
    """
    dim = sigdim(d, depth)
    need = 8 * dim * max(batch, 1) * (5 if log else 3) + 8 * dim * 64
    if log and depth > 1 and d > 1:
        need += 12 * min(logsigdim(d, depth) * 2 ** (depth - 1), 4 * dim)
    if need <= _SMALL_REQUEST:                  # always fits: skip reading /proc/meminfo
        return
    what = "logsignature" if log else "signature"
    check_memory(need, f"depth={depth} with d={d} and {batch} path(s): the {what} (sigdim({d}, {depth}) = "
                 f"{float(dim):.3g} floats per path)", "lower depth, process the batch in smaller pieces, or use "
                 "fewer dimensions")


def _check_paths(paths, *, finite: bool = True) -> np.ndarray:
    """Validated float64 paths; ``finite=False`` leaves NaN/inf to :func:`_finite_or_raise` where it can."""
    x = as_float_array(paths, "paths", min_ndim=2, allow_nonfinite=True)
    if x.shape[-2] < 1:
        raise ValueError(f"paths needs at least one point along axis -2 (shape (..., n, d)), got shape "
                         f"{x.shape}.")
    if x.shape[-1] < 1:
        raise ValueError(f"paths needs at least one coordinate along the last axis (shape (..., n, d)), "
                         f"got shape {x.shape}.")
    if finite or x.shape[-2] == 1 or x.shape[-1] == 1:
        # a lone point does not enter the output, nor (d = 1, level 2 = ½ X²) an interior point
        as_float_array(x, "paths")
    return x


def _finite_or_raise(out: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Return ``out``; if it holds NaN/inf, first raise the input check's error if the input does.

    At depth >= 2 and d >= 2 every point of a path of two or more points enters the output
    (through the increments on both sides of it, and NaN/inf never cancel), so a non-finite
    input always gives a non-finite output: scanning the small output replaces scanning the whole
    path on every call. A finite input whose signature overflows returns the overflowed values,
    as before.
    """
    if not np.isfinite(out).all():
        as_float_array(x, "paths")
    return out


def _reversed_parts(x: np.ndarray, depth: int, nchunks: int) -> np.ndarray:
    """Signature (reversed layout) of every work unit of a ``(B, n, d)`` batch, shape ``(units, sigdim)``."""
    nb, n, d = x.shape
    units = _units(nb, n, nchunks)
    off = level_offsets(d, depth)
    dim = sigdim(d, depth)
    nunits = nb * nchunks
    part = np.empty((nunits, dim))
    per_unit = (n / nchunks) * 1.5 * d ** depth
    ngroups = -(-nunits // _lanes.LANES)
    _threads.run(lambda lo, hi: _lanes.lane_groups(x, *units, depth, off, lo, hi, part),
                 _threads.ranges(ngroups, per_unit * _lanes.LANES))
    return part


def _signature_flat(x: np.ndarray, depth: int) -> np.ndarray:
    """Signatures of a validated ``(B, n, d)`` C-contiguous batch, shape ``(B, sigdim)``."""
    nb, n, d = x.shape
    if nb == 0 or n == 1:
        return np.zeros((nb, sigdim(d, depth)))
    if depth == 1:
        return x[:, -1, :] - x[:, 0, :]
    if depth == 2:
        nchunks = _n_chunks(n, _MAX_CHUNKS_L2, _MIN_CHUNK_L2)
        part = np.empty((nb * nchunks, d + d * (d - 1) // 2))
        _threads.run(lambda lo, hi: _l2.sig2_tasks(x, nchunks, lo, hi, part),
                     _threads.ranges(nb * nchunks, (n / nchunks) * d * d))
        return _l2.sig2_glue(part, nb, nchunks, d)
    nchunks = _n_chunks(n, _MAX_CHUNKS, _MIN_CHUNK)
    out = _reversed_parts(x, depth, nchunks)
    if nchunks > 1:
        out = _lanes.lane_glue(out, nb, nchunks, depth, level_offsets(d, depth))
    return out[:, _reversed_to_rowmajor(d, depth)]


@lru_cache(maxsize=None)
def _reversed_to_rowmajor(dim: int, depth: int) -> np.ndarray:
    """Gather index: ``rowmajor = reversed[..., perm]`` (kernels store words with the first letter fastest)."""
    parts, start = [], 0
    for k in range(1, depth + 1):
        words = np.indices((dim,) * k).reshape(k, -1)          # row-major enumeration of words
        rev = np.zeros(words.shape[1], dtype=np.intp)
        for j in range(k):
            rev += words[j] * dim ** j
        parts.append(start + rev)
        start += dim ** k
    return np.concatenate(parts)
