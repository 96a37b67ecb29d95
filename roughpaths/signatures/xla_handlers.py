"""Compiled XLA FFI handlers of the signature and its VJP: :mod:`roughpaths.jax`'s fast path (not a user API).

:mod:`roughpaths._xla_ffi` runs every host call of :mod:`roughpaths.jax` in Python (the frame read
with :mod:`ctypes`, the buffers wrapped as numpy arrays, the numpy API called): about 0.04 ms of
fixed cost for a jitted forward plus backward before any work, twice pysiglib's whole step on a lone
short path. This module compiles, with numba, two handlers (:func:`handler`: the signature's forward
and backward passes) that read the call frame themselves and run the numpy API's own compiled
one-unit kernels on XLA's buffers:

* **What they take**: what the numpy API runs one work unit at a time on one thread, with the one-unit
  kernels (:func:`roughpaths.signatures._engine.alone_kernel`, :mod:`roughpaths.signatures._vjp`): depth >= 3,
  ``d <= 7``, ``n >= 2`` points, a path short enough to be one work unit, and at most :func:`plan`'s
  ``most`` paths (2 at d <= 3, where the engine runs lanes from 3 paths on), float32 or float64
  buffers. Every other call, and every call whose values the numpy API refuses (a NaN or inf point
  or cotangent, a signature or gradient that overflows, or that a float32 buffer cannot hold), goes to the
  Python handler of the same call (called through its address), so that errors keep the numpy API's messages.
* **The same numbers**: the numpy API's steps in its order: one unit a path, the kernel variant the
  engine picks for ``(n, d, depth)`` (the very compiled function: its address), the time reversal of a
  path smaller than its signature, the permutations between the row-major and the kernels' reversed
  layout, the increments' cotangent summed into the points as ``(0 + gd[k-1]) - gd[k]``; float64
  throughout, rounded to float32 on the way out where the buffers are float32. The results are
  the bits of ``roughpaths.signature`` and ``roughpaths.signature_vjp``.
* **Per-process addresses at run time**: a cached ``cfunc`` cannot hold this process's addresses, so
  the Python handler's, the kernels' (:func:`kernels`) and that of :data:`CALLS`, with ``d``, the depth
  and ``most``, are one int64 array attribute of the custom call (:data:`ATTRIBUTE`), read from the
  frame. The kernels are called with numba's own calling convention (:func:`roughpaths._xla_native.native_call`) and the
  argument types the numpy API calls them with (:data:`BLOCK_ARGS`, :data:`VJP_ARGS`), so both share one
  compiled function and the handlers do not compile the kernels again. The target names of
  :mod:`roughpaths.jax` are unique to the process, so a program compiled in another process (jax's
  persistent cache, an export) never reaches these handlers with its addresses.
* **No crash on an unexpected frame**: struct sizes, argument kinds, dtypes, ranks and shapes are
  checked the way :mod:`roughpaths._xla_ffi` checks them; what does not fit goes to the Python
  handler, and a frame without this module's attribute gets an ``INTERNAL`` XLA error.
* **Compile cost**: the two handlers are compiled on first use (a traced call they can take) and cached
  on disk by numba: 1.6-2.2 s and 0.9-1.2 s of CPU with an empty cache (two runs; their checks and copies: each
  helper is a small function compiled once; the kernels are not linked in, so not compiled again). A
  cold first ``jax.grad`` step on one path of 8 points (``benchmarks/bench_first_call.py``, "jax step,
  one path"): 24.0 s of CPU against 22.1 s through the Python handler (same session, loaded machine;
  both dominated by the one-unit gradient kernel, then 12-15 s), and 15.1-16.1 s once that kernel compiled
  only its own step variant (4.5-4.9 s); the 16-path "jax step" does not reach the handlers (8.6 s against
  8.7 s).

The frame is read with :mod:`roughpaths._xla_native` (XLA FFI API version 0.1's layout). This module imports neither
jax nor any framework; it lives beside the kernels it runs (a module of :mod:`roughpaths.signatures`, not exported by
it), and :mod:`roughpaths.jax` imports it where it registers its targets.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numba import cfunc, njit, types
from numba.extending import intrinsic

from .._threads import ranges
from .._xla_native import (ARRAY_ATTR, ATTRS, ATTRS_SIZE, EXECUTE, F64, FRAME_SIZE, HANDLER, METADATA_EXTENSION,
                           METADATA_SIZE, S64, address, buffer, call, error, f32p, f64p, i32, i64, kernel_address,
                           native_call, set_i32, set_i64, u8, voidptr)
from . import _vjp
from ._engine import _WIDE, _horner_chunks, _split_units, alone_kernel

__all__ = ["ATTRIBUTE", "CALLS", "handler", "plan", "kernels", "parameters"]

#: The name of the custom call's int64 array attribute: fallback handler, :data:`CALLS`, d, depth, most paths.
ATTRIBUTE = "roughpaths"
_NAME = tuple(ATTRIBUTE.encode("ascii"))
_PARAMS = 7
_BLOCK, _VJP = 5, 6                             # the kernels' entries

#: Calls completed by the compiled handlers (forward, backward), counted without a lock (a count, not a
#: clock: the tests read it to see that the compiled path was taken).
CALLS = np.zeros(2, dtype=np.int64)

#: The most floats (paths and signatures) a compiled call handles; larger calls go to the Python handler,
#: whose memory check they then meet (the numpy API checks requests of 64 MiB and more).
_MOST_FLOATS = 1 << 21


# ------------------------------------------------------------------------------ the call frame
#: The handlers' helpers are compiled as :mod:`roughpaths._xla_native`'s frame readers are (its ``JIT``; numpy's
#: error model: no exception paths in code called from XLA).
_JIT = dict(cache=True, nogil=True, no_cfunc_wrapper=True, error_model="numpy")


@njit(**_JIT)
def _start(frame):
    """``(status, parameters)``: status 0 to compute (``parameters``: the address of :data:`ATTRIBUTE`'s entries),
    1 done (XLA's metadata query, answered: API version 0.1, no traits; or another stage than execution), 2 an
    error (a frame or metadata struct too small, or a frame without this module's parameters)."""
    if i64(frame) < FRAME_SIZE:
        return 2, 0
    ext = i64(frame + 8)
    if ext != 0 and i32(ext + 8) == METADATA_EXTENSION:
        md = i64(ext + 24)
        if md == 0 or i64(md) < METADATA_SIZE:
            return 2, 0
        set_i64(md + 8, 24)                        # XLA_FFI_Api_Version: struct_size, extension_start, 0, 1
        set_i64(md + 16, 0)
        set_i32(md + 24, 0)
        set_i32(md + 28, 1)
        set_i32(md + 32, 0)                        # traits: none
        return 1, 0
    if i32(frame + 32) != EXECUTE:
        return 1, 0
    a = frame + ATTRS                              # one attribute: ATTRIBUTE, an int64 array of _PARAMS entries
    if i64(a) < ATTRS_SIZE or i64(a + 16) != 1:
        return 2, 0
    kinds, names, attrs = i64(a + 24), i64(a + 32), i64(a + 40)
    if kinds == 0 or names == 0 or attrs == 0 or i32(kinds) != ARRAY_ATTR:
        return 2, 0
    span = i64(names)
    if span == 0 or i64(span) == 0 or i64(span + 8) != len(_NAME):
        return 2, 0
    for k in range(len(_NAME)):
        if u8(i64(span) + k) != _NAME[k]:
            return 2, 0
    arr = i64(attrs)
    if arr == 0 or i32(arr) != S64 or i64(arr + 8) != _PARAMS:
        return 2, 0
    p = i64(arr + 16)
    if p == 0 or i64(p) == 0 or i64(p + 8 * _BLOCK) == 0:
        return 2, 0
    return 0, p


@njit(**_JIT)
def _operands(frame, backward, d, m, most):
    """``(B, n, x, g, out)``: the paths' batch size and points, and the addresses of the buffers of the paths,
    the cotangent (``backward`` only; else 0) and the result; ``B == 0``: not a compiled call.

    Forward: paths ``(..., n, d)`` in, ``(..., sigdim)`` out; backward: paths and cotangent ``(..., sigdim)`` in,
    ``(..., n, d)`` out; one dtype, the same leading axes, ``B`` and ``n`` within :func:`plan`'s ``most`` and
    :data:`_MOST_FLOATS`."""
    xb = buffer(frame, 0, 0, 2 if backward else 1)
    gb = buffer(frame, 0, 1, 2) if backward else 0
    ob = buffer(frame, 1, 0, 1)
    if xb == 0 or ob == 0 or (backward and gb == 0):
        return 0, 0, 0, 0, 0
    dtype, rank = i32(xb + 16), i64(xb + 32)
    xdims, odims = i64(xb + 40), i64(ob + 40)
    if rank < 2 or i32(ob + 16) != dtype or i64(ob + 32) != (rank if backward else rank - 1):
        return 0, 0, 0, 0, 0
    if backward and (i32(gb + 16) != dtype or i64(gb + 32) != rank - 1):
        return 0, 0, 0, 0, 0
    nb = 1
    for k in range(rank - 2):
        size = i64(xdims + 8 * k)
        if i64(odims + 8 * k) != size or (backward and i64(i64(gb + 40) + 8 * k) != size):
            return 0, 0, 0, 0, 0
        nb *= size
    n = i64(xdims + 8 * (rank - 2))
    dim = 0
    size = 1
    for _ in range(m):
        size *= d
        dim += size
    if i64(xdims + 8 * (rank - 1)) != d or d < 1 or m < 3 or n < 2 or nb < 1 or nb > most \
            or nb * (n * d + 2 * dim) > _MOST_FLOATS:
        return 0, 0, 0, 0, 0
    if backward:
        if i64(i64(gb + 40) + 8 * (rank - 2)) != dim or i64(odims + 8 * (rank - 2)) != n \
                or i64(odims + 8 * (rank - 1)) != d:
            return 0, 0, 0, 0, 0
    elif i64(odims + 8 * (rank - 2)) != dim:
        return 0, 0, 0, 0, 0
    return nb, n, xb, gb, ob


@njit(**_JIT)
def _load_paths(b, x, flip):
    """The paths of the buffer at ``b`` into the float64 ``(B, n, d)`` array ``x``, reversed in time and negated with
    ``flip``; whether they are all finite."""
    nb, n, d = x.shape
    finite = True
    data = i64(b + 24)
    for u in range(nb):
        for k in range(n):
            kk = n - 1 - k if flip else k
            for i in range(d):
                e = (u * n + kk) * d + i
                v = f64p(data)[e] if i32(b + 16) == F64 else np.float64(f32p(data)[e])
                finite &= v - v == 0.0                  # false for NaN and inf
                x[u, k, i] = -v if flip else v
    return finite


@njit(**_JIT)
def _reversed(r, k, d):
    """The reversed-layout index, within its level ``k``, of the word at row-major index ``r``
    (:func:`roughpaths.signatures._engine._reversed_to_rowmajor`)."""
    w = 0
    for _ in range(k):
        w = w * d + r % d
        r //= d
    return w


@njit(**_JIT)
def _load_cotangent(b, g, off, d, m):
    """The row-major cotangent of the buffer at ``b`` into the float64 ``(B, sigdim)`` array ``g``, in the kernels'
    reversed layout; whether it is all finite."""
    nb, dim = g.shape
    finite = True
    data = i64(b + 24)
    for k in range(1, m + 1):
        ok = off[k]
        for r in range(off[k + 1] - ok):
            w = ok + _reversed(r, k, d)
            for u in range(nb):
                e = u * dim + ok + r
                v = f64p(data)[e] if i32(b + 16) == F64 else np.float64(f32p(data)[e])
                finite &= v - v == 0.0
                g[u, w] = v
    return finite


@njit(**_JIT)
def _fits(a, b, share):
    """Whether every entry of the float64 array ``a`` is at most ``share`` times the largest finite value of the
    buffer at ``b``'s dtype in absolute value (NaN is not). A signature or cotangent that overflowed float64, or that
    float32 cannot hold (it would be stored as inf), does not fit: such calls go to the Python handler, whose numpy
    API and front end refuse them with their messages. ``share = 0.5`` for the points' cotangent, stored as the
    difference of two entries."""
    top = share * (1.7976931348623157e308 if i32(b + 16) == F64 else 3.4028234663852886e38)
    fits = True
    for v in a.ravel():
        fits &= abs(v) <= top
    return fits


@njit(**_JIT)
def _store(b, e, v):
    """``v`` into entry ``e`` of the float32 or float64 buffer at ``b`` (rounded to float32 there)."""
    if i32(b + 16) == F64:
        f64p(i64(b + 24))[e] = v
    else:
        f32p(i64(b + 24))[e] = np.float32(v)


@njit(**_JIT)
def _store_signature(b, part, flipped, off, d, m):
    """The units' signatures (reversed layout; row-major already for flipped paths) into the buffer at ``b``,
    row-major (:func:`roughpaths.signatures._engine._signature_flat`)."""
    nb, dim = part.shape
    for k in range(1, m + 1):
        ok = off[k]
        for r in range(off[k + 1] - ok):
            w = ok + (r if flipped else _reversed(r, k, d))
            for u in range(nb):
                _store(b, u * dim + ok + r, part[u, w])


@njit(**_JIT)
def _store_points(b, gd):
    """The points' cotangent from the increments' ``gd`` ``(B, n - 1, d)`` into the buffer at ``b``, with the
    operations of :func:`roughpaths.signatures.gradients._increments_to_points`: ``(0 + gd[k-1]) - gd[k]``."""
    nb, n1, d = gd.shape
    for u in range(nb):
        for k in range(n1 + 1):
            for i in range(d):
                v = 0.0
                if k > 0:
                    v = v + gd[u, k - 1, i]
                if k < n1:
                    v = v - gd[u, k, i]
                _store(b, (u * (n1 + 1) + k) * d + i, v)


@njit(**_JIT)
def _layout(nb, n, d, m):
    """``(ub, ulo, uhi, offsets)``: one work unit a path (:func:`roughpaths.signatures._engine._units` with one chunk)
    and :func:`roughpaths.algebra.flat.level_offsets`."""
    ub = np.empty(nb, dtype=np.int64)
    ulo = np.empty(nb, dtype=np.int64)
    uhi = np.empty(nb, dtype=np.int64)
    for u in range(nb):
        ub[u] = u
        ulo[u] = 0
        uhi[u] = n - 1
    off = np.zeros(m + 2, dtype=np.int64)
    size = 1
    for k in range(1, m + 1):
        size *= d
        off[k + 1] = off[k] + size
    return ub, ulo, uhi, off


# ------------------------------------------------------------------------------ the engine's kernels
_F8_3D, _F8_2D, _I8_1D = types.float64[:, :, ::1], types.float64[:, ::1], types.int64[::1]
#: The argument types of the one-unit kernels, as the numpy API calls them (so that both call one compiled
#: function): :func:`roughpaths.signatures._engine.alone_kernel`'s ``(x, ub, ulo, uhi, m, offsets, lo, hi, part)``
#: and :func:`roughpaths.signatures._vjp.sig_vjp_units` ``(x, ub, ulo, uhi, m, offsets, part, gunit, lo, hi, gd)``.
BLOCK_ARGS = (_F8_3D, _I8_1D, _I8_1D, _I8_1D, types.int64, _I8_1D, types.int64, types.int64, _F8_2D)
VJP_ARGS = (_F8_3D, _I8_1D, _I8_1D, _I8_1D, types.int64, _I8_1D, _F8_2D, _F8_2D, types.int64, types.int64, _F8_3D)

@intrinsic
def _block_units(typingctx, addr, x, ub, ulo, uhi, m, off, lo, hi, part):
    """The one-unit signature kernel at ``addr`` (:func:`roughpaths.signatures._engine.alone_kernel`'s)."""
    return native_call(typingctx, BLOCK_ARGS, addr, (x, ub, ulo, uhi, m, off, lo, hi, part))


@intrinsic
def _vjp_units(typingctx, addr, x, ub, ulo, uhi, m, off, part, g_rev, lo, hi, gd):
    """The one-unit VJP kernel at ``addr`` (a variant of :func:`roughpaths.signatures._vjp.sig_vjp_units`)."""
    return native_call(typingctx, VJP_ARGS, addr, (x, ub, ulo, uhi, m, off, part, g_rev, lo, hi, gd))


@njit(**_JIT)
def _count(p, k):
    """One more compiled call in :data:`CALLS` ``[k]`` (its address is the parameters' second entry)."""
    calls = i64(p + 8)
    if calls != 0:
        set_i64(calls + 8 * k, i64(calls + 8 * k) + 1)


def _forward(frame_pointer):
    """The forward handler: :func:`roughpaths.signature` of the call's paths into its result buffer."""
    frame = address(frame_pointer)
    status, p = _start(frame)
    if status != 0:
        return voidptr(0 if status == 1 else error(frame))
    d, m = i64(p + 16), i64(p + 24)
    nb, n, xb, _, ob = _operands(frame, np.bool_(False), d, m, i64(p + 32))   # (one compile for both)
    if nb == 0:
        return voidptr(call(i64(p), frame))         # the Python handler: the numpy API (and its errors)
    ub, ulo, uhi, off = _layout(nb, n, d, m)
    flipped = n * d < off[m + 1]                        # S(x)_w = S(-x reversed)_{w*}: row-major out of the kernel
    x = np.empty((nb, n, d))
    part = np.empty((nb, off[m + 1]))
    if not _load_paths(xb, x, flipped) or _block_units(i64(p + 8 * _BLOCK), x, ub, ulo, uhi, m, off, 0, nb, part) \
            or not _fits(part, ob, 1.0):
        return voidptr(call(i64(p), frame))
    _store_signature(ob, part, flipped, off, d, m)
    _count(p, 0)
    return voidptr(0)


def _backward(frame_pointer):
    """The backward handler: :func:`roughpaths.signature_vjp` of the call's paths and cotangent into its result
    buffer."""
    frame = address(frame_pointer)
    status, p = _start(frame)
    if status != 0:
        return voidptr(0 if status == 1 else error(frame))
    d, m, vjp = i64(p + 16), i64(p + 24), i64(p + 8 * _VJP)
    nb, n, xb, gb, ob = _operands(frame, np.bool_(True), d, m, i64(p + 32))
    if nb == 0 or vjp == 0:
        return voidptr(call(i64(p), frame))
    ub, ulo, uhi, off = _layout(nb, n, d, m)
    x = np.empty((nb, n, d))
    g = np.empty((nb, off[m + 1]))
    part = np.empty((nb, off[m + 1]))
    gd = np.zeros((nb, n - 1, d))
    if not _load_paths(xb, x, False) or not _load_cotangent(gb, g, off, d, m) \
            or _block_units(i64(p + 8 * _BLOCK), x, ub, ulo, uhi, m, off, 0, nb, part) \
            or _vjp_units(vjp, x, ub, ulo, uhi, m, off, part, g, 0, nb, gd) or not _fits(gd, ob, 0.5):
        return voidptr(call(i64(p), frame))
    _store_points(ob, gd)
    _count(p, 1)
    return voidptr(0)


_HANDLERS: dict = {}


def handler(direction: str):
    """The compiled ``"forward"`` or ``"backward"`` handler: a numba ``cfunc`` (``.address``, ``.ctypes``) of the
    XLA FFI handler type ``XLA_FFI_Error* (XLA_FFI_CallFrame*)``, compiled (or loaded from numba's cache) on first
    use."""
    h = _HANDLERS.get(direction)
    if h is None:
        h = _HANDLERS[direction] = cfunc(HANDLER, cache=True)(_forward if direction == "forward" else _backward)
    return h


# ------------------------------------------------------------------------------ the plan (Python)
@lru_cache(maxsize=256)
def plan(n: int, d: int, depth: int) -> int:
    """The most paths of ``n`` points in ``d`` at ``depth`` that a compiled call takes (0: none).

    0 where the numpy API runs such a path otherwise than as one work unit of the one-unit kernels
    (depth 1 or 2, ``d >= 8``, a single point, a path cut into chunks): those calls stay with the
    Python handler. Otherwise the most paths the engine runs one unit at a time on one thread (its
    split: :func:`roughpaths.signatures._engine._split_units`, :func:`roughpaths._threads.ranges`);
    a call with more paths goes to the Python handler (the lanes, the threads).
    """
    if depth < 3 or n < 2 or not 1 <= d < _WIDE or _horner_chunks(n, d, depth) != 1:
        return 0
    fwd_work, vjp_work = n * 1.5 * d ** depth, n * 5 * d ** depth       # the engine's per_unit (one chunk)
    most = 0
    for k in range(1, 4097):
        if _split_units(k, d, depth)[0] or len(ranges(k, fwd_work)) > 1 or len(ranges(k, vjp_work)) > 1:
            break
        most = k
    return most


_KERNELS: dict = {}


def kernels(n: int, d: int, depth: int, backward: bool) -> tuple:
    """``(forward, backward)``: the addresses of the one-unit kernels the numpy API runs for paths of ``n`` points
    in ``d`` at ``depth`` (:func:`roughpaths.signatures._engine.alone_kernel`, and with ``backward``
    :func:`roughpaths.signatures._vjp.sig_vjp_units`; else 0), compiled or loaded on first use."""
    forward = alone_kernel(n, d, depth)
    key = (forward, d, depth, backward)
    if key not in _KERNELS:
        block = kernel_address(forward, BLOCK_ARGS)
        _KERNELS[key] = (block, kernel_address(_vjp.sig_vjp_units(d), VJP_ARGS) if backward else 0)
    return _KERNELS[key]


def parameters(fallback: int, d: int, depth: int, most: int, kernels: tuple) -> np.ndarray:
    """The int64 array attribute :data:`ATTRIBUTE` of a compiled call: the Python handler's address, the address
    of :data:`CALLS`, ``d``, the depth, the most paths (:func:`plan`) and the kernels' addresses (:func:`kernels`)."""
    return np.array([fallback, CALLS.ctypes.data, d, depth, most, *kernels], dtype=np.int64)
