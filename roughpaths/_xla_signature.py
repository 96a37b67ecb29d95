"""Compiled XLA FFI handlers of the signature and its VJP: :mod:`roughpaths.jax`'s fast path (private).

:mod:`roughpaths._xla_ffi` runs every host call of :mod:`roughpaths.jax` in Python (the frame read
with :mod:`ctypes`, the buffers wrapped as numpy arrays, the numpy API called): about 0.04 ms of
fixed cost for a jitted forward plus backward before any work, twice pysiglib's whole step on a lone
short path. This module compiles, with numba, two handlers (:func:`handler`: the signature's forward
and backward passes) that read the call frame themselves and run the numpy API's own compiled
one-unit kernels on XLA's buffers:

* **What they take**: what the numpy API runs one work unit at a time on one thread, with the one-unit
  kernels of :mod:`roughpaths.signatures._blocked` and :mod:`roughpaths.signatures._vjp`: depth >= 3,
  ``d <= 7``, ``n >= 2`` points, a path short enough to be one work unit, and at most :func:`plan`'s
  ``most`` paths (2 at d <= 3, where the engine runs lanes from 3 paths on), float32 or float64
  buffers. Every other call, and every call whose values the numpy API refuses (a NaN or inf point
  or cotangent), goes to the Python handler of the same call (called through its address), so that
  errors keep the numpy API's messages.
* **The same numbers**: the numpy API's steps in its order: one unit a path, the kernel variant the
  engine picks for ``(d, depth)`` (the very compiled function: its address), the time reversal of a
  path smaller than its signature, the permutations between the row-major and the kernels' reversed
  layout, the increments' cotangent summed into the points as ``(0 + gd[k-1]) - gd[k]``; float64
  throughout, rounded to float32 on the way out where the buffers are float32. The results are
  the bits of ``roughpaths.signature`` and ``roughpaths.signature_vjp``.
* **Per-process addresses at run time**: a cached ``cfunc`` cannot hold this process's addresses, so
  the Python handler's, the kernels' (:func:`kernels`) and that of :data:`CALLS`, with ``d``, the depth
  and ``most``, are one int64 array attribute of the custom call (:data:`ATTRIBUTE`), read from the
  frame. The kernels are called with numba's own calling convention (:func:`_native_call`) and the
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
  both dominated by the one-unit gradient kernel, about 12 s); the 16-path "jax step" does not reach
  the handlers (8.6 s against 8.7 s).

The frame layout is XLA FFI API version 0.1's (``xla/ffi/api/c_api.h``), as in :mod:`roughpaths._xla_ffi`.
This module imports neither jax nor any framework.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from llvmlite import ir
from numba import cfunc, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from ._threads import ranges
from .signatures import _blocked, _vjp
from .signatures._engine import _WIDE, _horner_chunks, _split_units

__all__ = ["ATTRIBUTE", "CALLS", "handler", "plan", "kernels", "parameters"]

#: The name of the custom call's int64 array attribute: fallback handler, :data:`CALLS`, d, depth, most paths.
ATTRIBUTE = "roughpaths"
_NAME = tuple(ATTRIBUTE.encode("ascii"))
_PARAMS = 7
_BLOCK, _VJP = 5, 6                             # the kernels' entries

#: Calls completed by the compiled handlers (forward, backward), counted without a lock (a count, not a
#: clock: the tests read it to see that the compiled path was taken).
CALLS = np.zeros(2, dtype=np.int64)

_FRAME_SIZE, _ARGS_SIZE, _ATTRS_SIZE, _BUFFER_SIZE = 168, 40, 48, 48
_ARGS, _RETS, _ATTRS = 40, 80, 120             # offsets of XLA_FFI_Args, XLA_FFI_Rets, XLA_FFI_Attrs in the frame
_BUFFER_KIND, _ARRAY_ATTR = 1, 1                # XLA_FFI_ArgType_BUFFER (= RetType), XLA_FFI_AttrType_ARRAY
_F32, _F64, _S64 = 11, 12, 5                    # XLA_FFI_DataType codes
_METADATA_EXTENSION, _METADATA_SIZE, _EXECUTE = 1, 36, 3
_INTERNAL = 13
_ERROR_ARGS_SIZE = 32                           # XLA_FFI_Error_Create_Args
_ERROR_CREATE = 48                              # offset of XLA_FFI_Error_Create in XLA_FFI_Api
_MESSAGE = ("roughpaths: an XLA FFI call of a compiled signature handler without its parameters "
            f"(an int64 array attribute {ATTRIBUTE!r} of {_PARAMS} entries); this is a bug of roughpaths.jax")

_HANDLER = types.voidptr(types.voidptr)          # XLA_FFI_Error* (XLA_FFI_CallFrame*)

#: The most floats (paths and signatures) a compiled call handles; larger calls go to the Python handler,
#: whose memory check they then meet (the numpy API checks requests of 64 MiB and more).
_MOST_FLOATS = 1 << 21


# ------------------------------------------------------------------------------ raw memory
@intrinsic
def _i64(typingctx, addr):
    """The int64 at address ``addr``."""
    def codegen(context, builder, sig, args):
        return builder.load(builder.inttoptr(args[0], ir.IntType(64).as_pointer()))
    return types.int64(types.int64), codegen


@intrinsic
def _i32(typingctx, addr):
    """The int32 at address ``addr``, as an int64."""
    def codegen(context, builder, sig, args):
        v = builder.load(builder.inttoptr(args[0], ir.IntType(32).as_pointer()))
        return builder.sext(v, ir.IntType(64))
    return types.int64(types.int64), codegen


@intrinsic
def _u8(typingctx, addr):
    """The byte at address ``addr``, as an int64."""
    def codegen(context, builder, sig, args):
        v = builder.load(builder.inttoptr(args[0], ir.IntType(8).as_pointer()))
        return builder.zext(v, ir.IntType(64))
    return types.int64(types.int64), codegen


@intrinsic
def _set_i64(typingctx, addr, value):
    """Store the int64 ``value`` at ``addr``."""
    def codegen(context, builder, sig, args):
        builder.store(args[1], builder.inttoptr(args[0], ir.IntType(64).as_pointer()))
        return context.get_dummy_value()
    return types.none(types.int64, types.int64), codegen


@intrinsic
def _set_i32(typingctx, addr, value):
    """Store ``value`` as an int32 at ``addr``."""
    def codegen(context, builder, sig, args):
        builder.store(builder.trunc(args[1], ir.IntType(32)), builder.inttoptr(args[0], ir.IntType(32).as_pointer()))
        return context.get_dummy_value()
    return types.none(types.int64, types.int64), codegen


def _pointer_intrinsic(numba_type, llvm_type):
    @intrinsic
    def pointer(typingctx, addr):
        def codegen(context, builder, sig, args):
            return builder.inttoptr(args[0], llvm_type.as_pointer())
        return types.CPointer(numba_type)(types.int64), codegen
    return pointer


_f64p = _pointer_intrinsic(types.float64, ir.DoubleType())
_f32p = _pointer_intrinsic(types.float32, ir.FloatType())


@intrinsic
def _address(typingctx, p):
    """A ``void*`` as an int64."""
    def codegen(context, builder, sig, args):
        return builder.ptrtoint(args[0], ir.IntType(64))
    return types.int64(types.voidptr), codegen


@intrinsic
def _voidptr(typingctx, addr):
    """An int64 as a ``void*`` (the handler's result)."""
    def codegen(context, builder, sig, args):
        return builder.inttoptr(args[0], ir.IntType(8).as_pointer())
    return types.voidptr(types.int64), codegen


@intrinsic
def _call(typingctx, fn, arg):
    """``fn(arg)`` for the address ``fn`` of a C function ``void* (void*)``: an XLA FFI handler, or
    ``XLA_FFI_Error_Create``."""
    def codegen(context, builder, sig, args):
        vp = ir.IntType(8).as_pointer()
        f = builder.inttoptr(args[0], ir.FunctionType(vp, [vp]).as_pointer())
        return builder.ptrtoint(builder.call(f, [builder.inttoptr(args[1], vp)]), ir.IntType(64))
    return types.int64(types.int64, types.int64), codegen


@intrinsic
def _create_error(typingctx, create):
    """``create(&args)`` for the address ``create`` of XLA's ``XLA_FFI_Error_Create``: an ``INTERNAL`` error saying
    :data:`_MESSAGE` (a constant string of the compiled code); the arguments struct lives on the stack."""
    def codegen(context, builder, sig, args):
        i64 = ir.IntType(64)
        fields = cgutils.alloca_once(builder, i64, size=_ERROR_ARGS_SIZE // 8)
        message = builder.ptrtoint(context.insert_const_string(builder.module, _MESSAGE), i64)
        for k, value in enumerate((ir.Constant(i64, _ERROR_ARGS_SIZE), ir.Constant(i64, 0), message,
                                   ir.Constant(i64, _INTERNAL))):         # struct_size, extension_start, message, errc
            builder.store(value, builder.gep(fields, [ir.Constant(i64, k)]))
        vp = ir.IntType(8).as_pointer()
        fn = builder.inttoptr(args[0], ir.FunctionType(vp, [vp]).as_pointer())
        return builder.ptrtoint(builder.call(fn, [builder.bitcast(fields, vp)]), i64)
    return types.int64(types.int64), codegen


# ------------------------------------------------------------------------------ the call frame
_JIT = dict(cache=True, nogil=True, no_cfunc_wrapper=True, error_model="numpy")


@njit(**_JIT)
def _start(frame):
    """``(status, parameters)``: status 0 to compute (``parameters``: the address of :data:`ATTRIBUTE`'s entries),
    1 done (XLA's metadata query, answered: API version 0.1, no traits; or another stage than execution), 2 an
    error (a frame or metadata struct too small, or a frame without this module's parameters)."""
    if _i64(frame) < _FRAME_SIZE:
        return 2, 0
    ext = _i64(frame + 8)
    if ext != 0 and _i32(ext + 8) == _METADATA_EXTENSION:
        md = _i64(ext + 24)
        if md == 0 or _i64(md) < _METADATA_SIZE:
            return 2, 0
        _set_i64(md + 8, 24)                        # XLA_FFI_Api_Version: struct_size, extension_start, 0, 1
        _set_i64(md + 16, 0)
        _set_i32(md + 24, 0)
        _set_i32(md + 28, 1)
        _set_i32(md + 32, 0)                        # traits: none
        return 1, 0
    if _i32(frame + 32) != _EXECUTE:
        return 1, 0
    a = frame + _ATTRS                              # one attribute: ATTRIBUTE, an int64 array of _PARAMS entries
    if _i64(a) < _ATTRS_SIZE or _i64(a + 16) != 1:
        return 2, 0
    kinds, names, attrs = _i64(a + 24), _i64(a + 32), _i64(a + 40)
    if kinds == 0 or names == 0 or attrs == 0 or _i32(kinds) != _ARRAY_ATTR:
        return 2, 0
    span = _i64(names)
    if span == 0 or _i64(span) == 0 or _i64(span + 8) != len(_NAME):
        return 2, 0
    for k in range(len(_NAME)):
        if _u8(_i64(span) + k) != _NAME[k]:
            return 2, 0
    arr = _i64(attrs)
    if arr == 0 or _i32(arr) != _S64 or _i64(arr + 8) != _PARAMS:
        return 2, 0
    p = _i64(arr + 16)
    if p == 0 or _i64(p) == 0 or _i64(p + 8 * _BLOCK) == 0:
        return 2, 0
    return 0, p


@njit(**_JIT)
def _error(frame):
    """An ``INTERNAL`` XLA_FFI_Error saying :data:`_MESSAGE`, made by XLA's ``XLA_FFI_Error_Create`` (0 without
    an API)."""
    api = _i64(frame + 16) if _i64(frame) >= 24 else 0
    if api == 0 or _i64(api + _ERROR_CREATE) == 0:
        return 0
    return _create_error(_i64(api + _ERROR_CREATE))


@njit(**_JIT)
def _buffer(frame, rets, i, count):
    """The address of the XLA_FFI_Buffer ``i`` of the frame's arguments (``rets`` 0) or results (1), or 0 if
    they are not ``count`` buffers or it is not a non-empty float32 or float64 buffer."""
    base = frame + (_RETS if rets else _ARGS)
    if _i64(base) < _ARGS_SIZE or _i64(base + 16) != count:
        return 0
    kinds, bufs = _i64(base + 24), _i64(base + 32)
    if kinds == 0 or bufs == 0 or _i32(kinds + 4 * i) != _BUFFER_KIND:
        return 0
    b = _i64(bufs + 8 * i)
    if b == 0 or _i64(b) < _BUFFER_SIZE or _i64(b + 24) == 0:
        return 0
    dtype = _i32(b + 16)
    if (dtype != _F32 and dtype != _F64) or _i64(b + 32) < 1 or _i64(b + 40) == 0:
        return 0
    return b


@njit(**_JIT)
def _operands(frame, backward, d, m, most):
    """``(B, n, x, g, out)``: the paths' batch size and points, and the addresses of the buffers of the paths,
    the cotangent (``backward`` only; else 0) and the result; ``B == 0``: not a compiled call.

    Forward: paths ``(..., n, d)`` in, ``(..., sigdim)`` out; backward: paths and cotangent ``(..., sigdim)`` in,
    ``(..., n, d)`` out; one dtype, the same leading axes, ``B`` and ``n`` within :func:`plan`'s ``most`` and
    :data:`_MOST_FLOATS`."""
    xb = _buffer(frame, 0, 0, 2 if backward else 1)
    gb = _buffer(frame, 0, 1, 2) if backward else 0
    ob = _buffer(frame, 1, 0, 1)
    if xb == 0 or ob == 0 or (backward and gb == 0):
        return 0, 0, 0, 0, 0
    dtype, rank = _i32(xb + 16), _i64(xb + 32)
    xdims, odims = _i64(xb + 40), _i64(ob + 40)
    if rank < 2 or _i32(ob + 16) != dtype or _i64(ob + 32) != (rank if backward else rank - 1):
        return 0, 0, 0, 0, 0
    if backward and (_i32(gb + 16) != dtype or _i64(gb + 32) != rank - 1):
        return 0, 0, 0, 0, 0
    nb = 1
    for k in range(rank - 2):
        size = _i64(xdims + 8 * k)
        if _i64(odims + 8 * k) != size or (backward and _i64(_i64(gb + 40) + 8 * k) != size):
            return 0, 0, 0, 0, 0
        nb *= size
    n = _i64(xdims + 8 * (rank - 2))
    dim = 0
    size = 1
    for _ in range(m):
        size *= d
        dim += size
    if _i64(xdims + 8 * (rank - 1)) != d or d < 1 or m < 3 or n < 2 or nb < 1 or nb > most \
            or nb * (n * d + 2 * dim) > _MOST_FLOATS:
        return 0, 0, 0, 0, 0
    if backward:
        if _i64(_i64(gb + 40) + 8 * (rank - 2)) != dim or _i64(odims + 8 * (rank - 2)) != n \
                or _i64(odims + 8 * (rank - 1)) != d:
            return 0, 0, 0, 0, 0
    elif _i64(odims + 8 * (rank - 2)) != dim:
        return 0, 0, 0, 0, 0
    return nb, n, xb, gb, ob


@njit(**_JIT)
def _load_paths(b, x, flip):
    """The paths of the buffer at ``b`` into the float64 ``(B, n, d)`` array ``x``, reversed in time and negated with
    ``flip``; whether they are all finite."""
    nb, n, d = x.shape
    finite = True
    data = _i64(b + 24)
    for u in range(nb):
        for k in range(n):
            kk = n - 1 - k if flip else k
            for i in range(d):
                e = (u * n + kk) * d + i
                v = _f64p(data)[e] if _i32(b + 16) == _F64 else np.float64(_f32p(data)[e])
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
    data = _i64(b + 24)
    for k in range(1, m + 1):
        ok = off[k]
        for r in range(off[k + 1] - ok):
            w = ok + _reversed(r, k, d)
            for u in range(nb):
                e = u * dim + ok + r
                v = _f64p(data)[e] if _i32(b + 16) == _F64 else np.float64(_f32p(data)[e])
                finite &= v - v == 0.0
                g[u, w] = v
    return finite


@njit(**_JIT)
def _store(b, e, v):
    """``v`` into entry ``e`` of the float32 or float64 buffer at ``b`` (rounded to float32 there)."""
    if _i32(b + 16) == _F64:
        _f64p(_i64(b + 24))[e] = v
    else:
        _f32p(_i64(b + 24))[e] = np.float32(v)


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
#: function): :func:`roughpaths.signatures._blocked.block_units` ``(x, ub, ulo, uhi, m, offsets, lo, hi, part)``
#: and :func:`roughpaths.signatures._vjp.sig_vjp_units` ``(x, ub, ulo, uhi, nchunks, m, offsets, part, gtot, lo, hi,
#: gd)``.
BLOCK_ARGS = (_F8_3D, _I8_1D, _I8_1D, _I8_1D, types.int64, _I8_1D, types.int64, types.int64, _F8_2D)
VJP_ARGS = (_F8_3D, _I8_1D, _I8_1D, _I8_1D, types.int64, types.int64, _I8_1D, _F8_2D, _F8_2D, types.int64, types.int64,
            _F8_3D)


def _native_call(typingctx, expected, addr, args):
    """``(signature, codegen)`` of an intrinsic calling the numba-compiled function at ``addr`` (its native entry,
    numba's calling convention) with ``args`` of the types ``expected``; the result is 0, or 1 if it raised."""
    if len(args) != len(expected) or any(types.unliteral(a) != e for a, e in zip(args, expected)):
        return None                             # a typing error at compile time, never a call with other types

    def codegen(context, builder, sig, llargs):
        fnty = context.call_conv.get_function_type(types.none, expected)
        fn = builder.inttoptr(llargs[0], fnty.as_pointer())
        status, _ = context.call_conv.call_function(builder, fn, types.none, expected, llargs[1:])
        return builder.zext(builder.not_(status.is_ok), ir.IntType(64))

    return types.int64(types.int64, *expected), codegen


@intrinsic
def _block_units(typingctx, addr, x, ub, ulo, uhi, m, off, lo, hi, part):
    """The one-unit signature kernel at ``addr`` (a variant of :func:`roughpaths.signatures._blocked.block_units`)."""
    return _native_call(typingctx, BLOCK_ARGS, addr, (x, ub, ulo, uhi, m, off, lo, hi, part))


@intrinsic
def _vjp_units(typingctx, addr, x, ub, ulo, uhi, nchunks, m, off, part, g_rev, lo, hi, gd):
    """The one-unit VJP kernel at ``addr`` (a variant of :func:`roughpaths.signatures._vjp.sig_vjp_units`)."""
    return _native_call(typingctx, VJP_ARGS, addr, (x, ub, ulo, uhi, nchunks, m, off, part, g_rev, lo, hi, gd))


def kernel_address(dispatcher, argtypes: tuple) -> int:
    """The address of ``dispatcher``'s native function for ``argtypes`` (compiled, or loaded from numba's cache,
    if this process has not run it yet: what the numpy API's first call would compile).

    The symbol is looked up by name in the whole process, so the name must be the variant's own: a function
    compiled before the variants had their key in their names (:func:`roughpaths._variants._named`), loaded
    from an older cache, may share its name with another variant, and is refused (``RuntimeError``: the calls
    stay with the Python handler until numba compiles it again).
    """
    dispatcher.compile(argtypes)
    cres = dispatcher.overloads[argtypes]
    if cres.fndesc.qualname != dispatcher.py_func.__qualname__ or not cres.fndesc.qualname.endswith("]"):
        raise RuntimeError(f"{cres.fndesc.qualname} was compiled under another name than its variant's")
    return int(cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name))


@njit(**_JIT)
def _count(p, k):
    """One more compiled call in :data:`CALLS` ``[k]`` (its address is the parameters' second entry)."""
    calls = _i64(p + 8)
    if calls != 0:
        _set_i64(calls + 8 * k, _i64(calls + 8 * k) + 1)


def _forward(frame_pointer):
    """The forward handler: :func:`roughpaths.signature` of the call's paths into its result buffer."""
    frame = _address(frame_pointer)
    status, p = _start(frame)
    if status != 0:
        return _voidptr(0 if status == 1 else _error(frame))
    d, m = _i64(p + 16), _i64(p + 24)
    nb, n, xb, _, ob = _operands(frame, np.bool_(False), d, m, _i64(p + 32))   # (one compile for both)
    if nb == 0:
        return _voidptr(_call(_i64(p), frame))         # the Python handler: the numpy API (and its errors)
    ub, ulo, uhi, off = _layout(nb, n, d, m)
    flipped = n * d < off[m + 1]                        # S(x)_w = S(-x reversed)_{w*}: row-major out of the kernel
    x = np.empty((nb, n, d))
    part = np.empty((nb, off[m + 1]))
    if not _load_paths(xb, x, flipped) or _block_units(_i64(p + 8 * _BLOCK), x, ub, ulo, uhi, m, off, 0, nb, part):
        return _voidptr(_call(_i64(p), frame))
    _store_signature(ob, part, flipped, off, d, m)
    _count(p, 0)
    return _voidptr(0)


def _backward(frame_pointer):
    """The backward handler: :func:`roughpaths.signature_vjp` of the call's paths and cotangent into its result
    buffer."""
    frame = _address(frame_pointer)
    status, p = _start(frame)
    if status != 0:
        return _voidptr(0 if status == 1 else _error(frame))
    d, m, vjp = _i64(p + 16), _i64(p + 24), _i64(p + 8 * _VJP)
    nb, n, xb, gb, ob = _operands(frame, np.bool_(True), d, m, _i64(p + 32))
    if nb == 0 or vjp == 0:
        return _voidptr(_call(_i64(p), frame))
    ub, ulo, uhi, off = _layout(nb, n, d, m)
    x = np.empty((nb, n, d))
    g = np.empty((nb, off[m + 1]))
    part = np.empty((nb, off[m + 1]))
    gd = np.zeros((nb, n - 1, d))
    if not _load_paths(xb, x, False) or not _load_cotangent(gb, g, off, d, m) \
            or _block_units(_i64(p + 8 * _BLOCK), x, ub, ulo, uhi, m, off, 0, nb, part) \
            or _vjp_units(vjp, x, ub, ulo, uhi, 1, m, off, part, g, 0, nb, gd):
        return _voidptr(_call(_i64(p), frame))
    _store_points(ob, gd)
    _count(p, 1)
    return _voidptr(0)


_HANDLERS: dict = {}


def handler(direction: str):
    """The compiled ``"forward"`` or ``"backward"`` handler: a numba ``cfunc`` (``.address``, ``.ctypes``) of the
    XLA FFI handler type ``XLA_FFI_Error* (XLA_FFI_CallFrame*)``, compiled (or loaded from numba's cache) on first
    use."""
    h = _HANDLERS.get(direction)
    if h is None:
        h = _HANDLERS[direction] = cfunc(_HANDLER, cache=True)(_forward if direction == "forward" else _backward)
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


def kernels(d: int, depth: int, backward: bool) -> tuple:
    """``(forward, backward)``: the addresses of the one-unit kernels the numpy API runs for ``d`` and ``depth``
    (:func:`roughpaths.signatures._blocked.block_units`, and with ``backward``
    :func:`roughpaths.signatures._vjp.sig_vjp_units`; else 0), compiled or loaded on first use."""
    key = (d, depth, backward)
    if key not in _KERNELS:
        block = kernel_address(_blocked.block_units(d, depth), BLOCK_ARGS)
        _KERNELS[key] = (block, kernel_address(_vjp.sig_vjp_units(d), VJP_ARGS) if backward else 0)
    return _KERNELS[key]


def parameters(fallback: int, d: int, depth: int, most: int, kernels: tuple) -> np.ndarray:
    """The int64 array attribute :data:`ATTRIBUTE` of a compiled call: the Python handler's address, the address
    of :data:`CALLS`, ``d``, the depth, the most paths (:func:`plan`) and the kernels' addresses (:func:`kernels`)."""
    return np.array([fallback, CALLS.ctypes.data, d, depth, most, *kernels], dtype=np.int64)
