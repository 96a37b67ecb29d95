"""The signature engine's driver (private): input checks, the split of the work, and the layout.

Shared by :mod:`roughpaths.signatures.signature` and :mod:`roughpaths.signatures.gradients`. The
kernels store words with the first letter fastest (the *reversed* layout); results are returned in
row-major order: by a permutation of the output (:func:`_reversed_to_rowmajor`), or, where the path is
smaller than its signature, by running the kernels on the path negated and reversed in time, whose
reversed-layout signature is the row-major one of the path (:func:`_signature_flat`).

A small input's cost is this module's Python, not the kernels': what depends on the shape only (the work
units, the kernels, the thread ranges: :func:`_parts_plan`) is decided once per shape, a float64 array is
taken as it is, and a single range calls its kernel directly (one path of 8 points in d = 3 at depth 3:
9 us for the signature, 18 us for its gradient, against 16 and 39 before these trims).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .. import _threads
from ..algebra.flat import level_offsets
from ..algebra.tensor import logsigdim, sigdim
from ..validation import as_float_array, check_memory, check_positive_int
from . import _blocked, _lanes, _layout
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


#: Below 2 _MIN_CHUNK segments, a path with d <= 4 at depth <= 4 is cut into up to LANES chunks of at
#: least this many segments (when that makes more than _FEW chunks), so that a lone path (or a few)
#: fills a lane group instead of leaving lanes empty (a lone 1000 x 3 path at depth 4: 0.13 ms instead
#: of 0.31). The price, the glue and the copy-out of 8x more units, is about 10% on large batches of
#: such paths (measured on 200 x 1000 x 3); at d = 5 or depth 5 it grows, and those paths stay whole.
_LANE_CHUNK = 100


def _horner_chunks(n: int, d: int, depth: int) -> int:
    """Work units per path for the depth >= 3 kernels: a function of ``n``, ``d`` and ``depth`` only."""
    if n - 1 >= 2 * _MIN_CHUNK or d > 4 or depth > 4:
        return _n_chunks(n, _MAX_CHUNKS, _MIN_CHUNK)
    c = (n - 1) // _LANE_CHUNK
    # at most _FEW chunks would not fill a lane group (they run alone): the path stays whole
    return min(_lanes.LANES, c) if c > _FEW else 1


def _n_chunks(n: int, target: int, min_chunk: int) -> int:
    """Chunks per path: a function of the path length ``n`` only, so that a member's arithmetic does not
    depend on its neighbours."""
    if n - 1 < 2 * min_chunk:
        return 1
    return max(1, min(target, (n - 1) // min_chunk))


@lru_cache(maxsize=64)
def _units(nb: int, n: int, nchunks: int) -> tuple:
    """``(path, first point, last point)`` of every work unit, path-major."""
    seg = -(-(n - 1) // nchunks)
    ub = np.repeat(np.arange(nb, dtype=np.int64), nchunks)
    lo = np.minimum(np.tile(np.arange(nchunks, dtype=np.int64), nb) * seg, n - 1)
    return ub, lo, np.minimum(lo + seg, n - 1)


_F64 = np.dtype(np.float64)


def _kernel_array(a: np.ndarray, shape: tuple) -> np.ndarray:
    """``a`` reshaped to ``shape``, float64, C-contiguous and writeable (copied only if needed).

    numba compiles (and caches) a kernel once per argument type, and a read-only or strided array is
    another type: every array a kernel receives goes through here, so the kernels compiled at install
    time (``tools/warm_kernels.py``) are the ones every call finds.
    """
    if a.dtype == _F64 and a.flags.carray:          # already so (np.require's argument handling: ~1 us)
        return a.reshape(shape)
    return np.require(a.reshape(shape), dtype=np.float64, requirements=["C", "W"])


#: Arrays of at most this many floats are scanned for NaN/inf by summing them as Python floats (a NaN or inf
#: entry makes the sum NaN or inf, and Python's float sum neither warns nor raises), ~1 us sooner than
#: ``np.isfinite`` on a lone short path; a finite sum that overflowed is scanned again by ``np.isfinite``.
_SUM_SCAN = 48


def _all_finite(a: np.ndarray) -> bool:
    """``True`` if the float64 array ``a`` holds no NaN or inf."""
    if a.size <= _SUM_SCAN and math.isfinite(sum(a.ravel().tolist())):
        return True
    return bool(np.logical_and.reduce(np.isfinite(a), axis=None))      # ndarray.all without its Python wrapper


@lru_cache(maxsize=512)
def _sigdim(d: int, depth: int) -> int:
    """:func:`roughpaths.sigdim`, cached (its argument checks cost more than a small signature)."""
    return int(sigdim(d, depth))


@lru_cache(maxsize=512)
def _logsigdim(d: int, depth: int) -> int:
    """:func:`roughpaths.logsigdim`, cached (its argument checks and Witt's sums cost ~15 us a call)."""
    return int(logsigdim(d, depth))


def _check_depth(depth) -> int:
    if type(depth) is int and depth >= 1:          # the usual case, without the numbers.Integral check
        return depth
    return check_positive_int(depth, "depth")


#: Requests below this many bytes are not checked against the available memory.
_SMALL_REQUEST = 64 * 2 ** 20


def _check_fits(batch: int, d: int, depth: int, *, log: bool = False, n: int = 0) -> None:
    """Refuse, before allocating, a request whose working arrays would not fit in memory.

    The signature needs about 3 arrays of ``batch * sigdim`` floats (result, chunk partials,
    layout permutation); the log-signature 2 more (its coordinates; the logs of the few rows each thread holds at a
    time, :func:`roughpaths.algebra.flat.log_lyndon_flat`) plus the sparse Lyndon map, whose
    top level holds at most ``n_m * 2**(m-1)`` entries (12 bytes each while it is built). Paths of
    ``n`` points cut into ``c > 1`` work units (:func:`_horner_chunks`) add the units' signatures,
    ``batch * c * sigdim`` floats (twice with ``log``: the gradients' units' cotangents too).
    """
    need = _need_bytes(batch, d, depth, log, n)
    if need <= _SMALL_REQUEST:                  # always fits: skip reading /proc/meminfo
        return
    dim = _sigdim(d, depth)
    what = "logsignature" if log else "signature"
    check_memory(need, f"depth={depth} with d={d} and {batch} path(s): the {what} (sigdim({d}, {depth}) = "
                 f"{float(dim):.3g} floats per path)", "lower depth, process the batch in smaller pieces, or use "
                 "fewer dimensions")


@lru_cache(maxsize=256)
def _need_bytes(batch: int, d: int, depth: int, log: bool, n: int) -> int:
    """The estimate of :func:`_check_fits` (cached: it costs about a microsecond, a small signature's tenth)."""
    dim = _sigdim(d, depth)
    need = 8 * dim * max(batch, 1) * (5 if log else 3) + 8 * dim * 64
    chunks = _horner_chunks(n, d, depth) if depth >= 3 and n >= 2 else 1
    if chunks > 1:                              # the units' signatures (and with log the gradients' cotangents)
        need += 8 * dim * max(batch, 1) * chunks * (2 if log else 1)
    if log and depth > 1 and d > 1:
        need += 12 * min(_logsigdim(d, depth) * 2 ** (depth - 1), 4 * dim)
    return need


def _check_paths(paths, *, finite: bool = True) -> np.ndarray:
    """Validated float64 paths; ``finite=False`` leaves NaN/inf to :func:`_finite_or_raise` where it can."""
    if type(paths) is np.ndarray and paths.dtype == _F64 and paths.ndim >= 2:
        x = paths                                   # what as_float_array returns for it, without its checks
    else:
        x = as_float_array(paths, "paths", min_ndim=2, allow_nonfinite=True)
    if x.shape[-2] < 1:
        raise ValueError(f"paths needs at least one point along axis -2 (shape (..., n, d)), got shape "
                         f"{x.shape}.")
    if x.shape[-1] < 1:
        raise ValueError(f"paths needs at least one coordinate along the last axis (shape (..., n, d)), "
                         f"got shape {x.shape}.")
    if (finite or x.shape[-2] == 1 or x.shape[-1] == 1) and not _all_finite(x):
        # a lone point does not enter the output, nor (d = 1, level 2 = ½ X²) an interior point
        as_float_array(x, "paths")                  # raises, naming the first non-finite point
    return x


def _abs_sum(a: np.ndarray) -> float:
    """``sum |a|`` of a float64 array: NaN if it holds a NaN, inf if an inf (or if the sum overflows)."""
    if a.size <= _SUM_SCAN:
        return sum(map(abs, a.ravel().tolist()))
    return float(np.add.reduce(np.abs(a), axis=None))


def _finite_or_raise(out: np.ndarray, x: np.ndarray, depth: int, what: str = "signature") -> np.ndarray:
    """Return ``out`` if it is finite; else raise the input check's error if the input holds NaN/inf, and if it
    does not (the result overflowed float64), an error naming the size of the paths and the fix.

    At depth >= 2 and d >= 2 every point of a path of two or more points enters the output
    (through the increments on both sides of it, and NaN/inf never cancel), so a non-finite
    input always gives a non-finite output: scanning the small output replaces scanning the whole
    path on every call. When the input is the smaller array (short paths at high depth) it is scanned
    instead, by ``A = sum |x|``: a NaN or inf makes it non-finite, and a finite ``A`` bounds every path's
    length by ``L <= 2 A``, so level ``k`` of the signature by ``L**k / k!`` and of its logarithm (``depth``
    terms of tensor powers) by ``(depth L)**k``; only inputs too large for that bound to stay below ``1e290``
    have their output scanned as well.
    """
    if x.size < out.size:
        total = _abs_sum(x)
        if total <= 10.0 ** (290.0 / depth) / (2.0 * depth):      # finite, and too small to overflow
            return out
        as_float_array(x, "paths")                  # raises, naming the first non-finite point
        if _all_finite(out):
            return out
    elif _all_finite(out):
        return out
    else:
        as_float_array(x, "paths")
    _overflow(x, depth, what)


def _overflow(x: np.ndarray, depth: int, what: str):
    """Raise: the ``what`` of the finite ``paths`` ``x`` at ``depth`` left float64."""
    top = float(np.max(np.abs(x), initial=0.0))
    raise ValueError(f"the depth-{depth} {what} of paths (finite, values up to {top:.3g} in absolute value) "
                     f"overflows float64 (inf or nan): its level k grows like the k-th power of a path's length. "
                     f"Rescale the paths (e.g. divide them by their length or standard deviation; the level-k terms "
                     f"scale by c**k when the paths do by c) or lower depth.")


#: From this width on every unit runs alone (:func:`_blocked.block_units`, the same bits as the lanes):
#: the one-unit rows over the first letters fill whole packed rows (d = 8: one) and its blocked top level
#: beats the lanes' per-segment one. Below it, d = 6, 7 run on lanes (variants compiled for (6, 3) and (7, 3))
#: where the ``LANES`` signatures take at most :data:`_LANE_BYTES` (depth 3): measured at 16 x 256 points,
#: depth 3, one thread, 24-29 / 34 ns a segment (the run-time ``d`` lanes: 48 / 67; alone: 68 / 95; pysiglib:
#: 61 / 89).
_WIDE = 8
#: A lane group with at most this many units runs them one at a time instead (the empty lanes of a
#: group cost as much as full ones; one unit alone costs about a quarter of a group, measured at d = 3).
_FEW = 2


#: From d = 4, units whose LANES signatures take more than this many bytes also run alone: measured on
#: 32-200 paths, d = 4 at depth 5 ran 3x faster alone (the one-unit kernel is compiled for d = 4), d = 5 at
#: depth 5 0-11 % faster; d = 2, 3 stay faster on lanes at every depth tried (up to 10 and 7).
_LANE_BYTES = 64 * 1024


def _split_units(nunits: int, d: int, depth: int) -> tuple:
    """``(lane groups, first unit run alone)``: units ``0 .. LANES * groups - 1`` run on lanes, the rest alone.

    Either kernel gives the same bits, so the split may depend on the batch."""
    if d >= _WIDE or (d >= 4 and 8 * _lanes.LANES * _sigdim(d, depth) > _LANE_BYTES):
        return 0, 0
    groups, rest = divmod(nunits, _lanes.LANES)
    if rest > _FEW:
        groups += 1
    return groups, min(nunits, groups * _lanes.LANES)


#: A unit run alone with at most this many segments runs the plain one-unit kernel (:func:`_lanes.scalar_units`),
#: not the blocked one (:func:`_blocked.block_units`): the same bits (:func:`alone_kernel`).
_SHORT_UNIT = 7


def alone_kernel(n: int, d: int, depth: int):
    """The kernel of the work units that run alone, for paths of ``n`` points in ``d`` at ``depth`` (a function of
    the shape only, as every choice of the engine; either kernel gives the same bits).

    Units of at most :data:`_SHORT_UNIT` segments with ``3 <= d <= 10`` run the plain kernel: its compile costs
    1.3-1.9 s against 3.8-4.5 s for the blocked kernel (cold, empty cache, one process each, d = 3, 5, 8), the
    larger part of a lone short path's first call, and it runs as fast there: one path of 4 / 8 points, one thread,
    CPU time, interleaved, d = 3..10 at depths 3..5, 0.61-0.80 / 0.81-1.06 times the blocked kernel's time (1-25 us
    a call). From 16 points the blocked kernel is faster (1.0-1.9x at 16 points, up to 3.2x at 128). It keeps
    d = 2 (the plain kernel's rows are a quarter of a packed row: 1.3-2.6x slower at 8 points), (6, 4) (a blocked
    variant with a compile-time ``d`` and depth: 1.2-1.4x) and d >= 11 (d = 12, 16, 20 at 8 points: 0.85-1.52x).
    """
    segments = (n - 1) // _horner_chunks(n, d, depth)
    if segments <= _SHORT_UNIT and 3 <= d <= 10 and (d, depth) != (6, 4):
        return _lanes.scalar_units(d)
    return _blocked.block_units(d, depth)


@lru_cache(maxsize=64)
def _parts_plan(nb: int, n: int, d: int, depth: int, nchunks: int) -> tuple:
    """What :func:`_reversed_parts` runs for a ``(nb, n, d)`` batch: a function of the shape only, made once.

    ``(units, offsets, (units, sigdim), lane kernel or None, its ranges, first unit alone, one-unit
    kernel or None, its ranges)``; the ranges are :func:`roughpaths._threads.ranges`' (lists, not to be changed).
    """
    dim = _sigdim(d, depth)
    nunits = nb * nchunks
    # per segment: 1.5 d^m for the top level's products, 12 a level for the loops' control (2-3x the first term
    # at d = 2, depth 5: 64 x 256 such paths take 0.22-0.36 ms, on two threads 18-27 % less since the workers
    # watch for jobs (load 1.3-1.8); before, waking them cost about as much as it saved)
    per_unit = (n / nchunks) * (1.5 * d ** depth + 12 * depth)
    # split from _threads.SPLIT_WORK (about 0.12 ms here, a unit ~0.23 ns), half the threads' default: since idle
    # workers wait for the next job without the GIL, a split pays from about 0.1 ms (the benchmark's protocol, 5
    # interleaved process pairs, 16 x 256 paths: d = 3 at depth 4 and d = 6 at depth 3, 0.15-0.25 ms serial, split
    # 0.82-0.93 and 0.73-0.91 of it; d = 4 at depth 3, 0.09 ms, even)
    ngroups, first_alone = _split_units(nunits, d, depth)
    lanes = _lanes.lane_groups(d, depth) if ngroups else None
    alone = alone_kernel(n, d, depth) if first_alone < nunits else None
    return (_units(nb, n, nchunks), level_offsets(d, depth), (nunits, dim),
            lanes, _threads.ranges(ngroups, per_unit * _lanes.LANES, _threads.SPLIT_WORK),
            first_alone, alone, _threads.ranges(nunits - first_alone, per_unit, _threads.SPLIT_WORK))


def _reversed_parts(x: np.ndarray, depth: int, nchunks: int) -> np.ndarray:
    """Signature (reversed layout) of every work unit of a ``(B, n, d)`` batch, shape ``(units, sigdim)``."""
    (ub, ulo, uhi), off, shape, lanes, lane_ranges, first_alone, alone, alone_ranges = _parts_plan(
        *x.shape, depth, nchunks)
    part = np.empty(shape)
    if lanes is not None:
        _threads.run(lambda lo, hi: lanes(x, ub, ulo, uhi, depth, off, lo, hi, part), lane_ranges, merge=True)
    if alone is not None:
        _threads.run(lambda lo, hi: alone(x, ub, ulo, uhi, depth, off, first_alone + lo, first_alone + hi, part),
                     alone_ranges, merge=True)
    return part


def _level2_flat(x: np.ndarray, *, log: bool) -> np.ndarray:
    """Level-2 signatures ``(B, d + d*d)`` of a validated ``(B, n >= 2, d)`` batch, or with ``log`` the
    level-2 log-signatures in the Lyndon basis ``(B, d + d(d-1)/2)`` (increment, Lévy areas)."""
    nb, n, d = x.shape
    nchunks = _n_chunks(n, _MAX_CHUNKS_L2, _MIN_CHUNK_L2)
    part = np.empty((nb * nchunks, d + d * (d - 1) // 2))
    # half a unit per multiply-add: a unit takes about 0.2 ns on one core (one thread, CPU: 16 x 256 paths at d = 13,
    # 346k units, 67-74 us; 64 x 256 at d = 8, 524k units, 131-135 us), as the deeper kernels' (~0.23 ns), so
    # SPLIT_WORK means about 0.1 ms here too (the benchmark's protocol, 4 interleaved process pairs, split at
    # SPLIT_WORK against serial before: 64 x 256 paths at d = 8, 9, 10: 0.86-0.91, 0.81-0.83, 0.68-0.72 of the
    # time (0.15-0.21 ms serial); 16 x 256 at d = 17, 19, 20, two lane groups: 0.78-1.04, 0.78-0.97, 0.76-0.83)
    per_task = (n / nchunks) * d * d / 2
    groups = nb // _lanes.LANES if d >= _l2.LANE_WIDTH else 0      # same bits either way
    if groups:
        _threads.run(lambda lo, hi: _l2.sig2_lane_tasks(x, nchunks, lo, hi, part),
                     _threads.ranges(groups * nchunks, per_task * _lanes.LANES, _threads.SPLIT_WORK), merge=True)
    first = groups * _lanes.LANES * nchunks
    tasks = _l2.sig2_tasks(d)
    _threads.run(lambda lo, hi: tasks(x, nchunks, first + lo, first + hi, part),
                 _threads.ranges(nb * nchunks - first, per_task, _threads.SPLIT_WORK), merge=True)
    return (_l2.logsig2_glue if log else _l2.sig2_glue)(part, nb, nchunks, d)


#: Outputs of at most this many floats are permuted by numpy's gather (no kernel call, no threads).
_SMALL_PERMUTE = 2 ** 14


def _signature_flat(x: np.ndarray, depth: int) -> np.ndarray:
    """Signatures of a validated ``(B, n, d)`` C-contiguous batch, shape ``(B, sigdim)``."""
    nb, n, d = x.shape
    if nb == 0 or n == 1:
        return np.zeros((nb, _sigdim(d, depth)))
    if depth == 1:
        with np.errstate(over="ignore"):            # an overflow is refused with its fix (_finite_or_raise)
            return x[:, -1, :] - x[:, 0, :]
    if depth == 2:
        return _level2_flat(x, log=False)
    nchunks = _horner_chunks(n, d, depth)
    # Word reversal w -> w* is an anti-automorphism that fixes every exp(Δ), so S(x)_w = S(y)_{w*} for the
    # path y = -x reversed in time (increments Δ_n, ..., Δ_1). The reversed layout stores S(y)_{w*} where the
    # row-major one stores S(x)_w: the kernels' output for y is x's signature in row-major order. Where the
    # path is the smaller array, one pass over it replaces the permutation of the output; the choice depends
    # on (n, d, depth) only, so a member's bits do not depend on its batch.
    flipped = n * d < _sigdim(d, depth)
    _, out = _reversed_signature(np.negative(x[:, ::-1, :]) if flipped else x, depth, nchunks)
    if flipped:
        return out
    perm = _reversed_to_rowmajor(d, depth)
    if out.size <= _SMALL_PERMUTE:
        return out.take(perm, axis=1)               # out[:, perm], in C order and ~1 us sooner
    res = np.empty_like(out)
    _threads.run(lambda lo, hi: _layout.to_rowmajor(out, perm, level_offsets(d, depth), depth, lo, hi, res),
                 _threads.ranges(nb, 4 * perm.shape[0]), merge=True)
    return res


def _reversed_signature(x: np.ndarray, depth: int, nchunks: int) -> tuple:
    """``(parts, signatures)`` in the reversed layout: those of the work units (:func:`_reversed_parts`) and
    of the paths (the units glued by Chen; the same array when ``nchunks == 1``)."""
    part = _reversed_parts(x, depth, nchunks)
    if nchunks == 1:
        return part, part
    return part, _lanes.lane_glue(part, x.shape[0], nchunks, depth, level_offsets(x.shape[2], depth))


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
