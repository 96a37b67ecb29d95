"""Numba building blocks of compiled XLA FFI handlers (private): raw memory, the call frame, native calls.

:mod:`roughpaths._xla_ffi` makes a Python function an XLA typed-FFI handler with :mod:`ctypes`; a handler
compiled with numba (a ``cfunc`` of the type ``XLA_FFI_Error* (XLA_FFI_CallFrame*)``, e.g.
:mod:`roughpaths.signatures.xla_handlers`) reads the frame itself with these intrinsics: loads and stores
at addresses, the frame's argument and result buffers (checked as :mod:`roughpaths._xla_ffi` checks them),
an ``INTERNAL`` XLA error made by XLA's own ``XLA_FFI_Error_Create``, a call of a C handler through its
address (the Python handler of the same call, to which a compiled handler leaves what it does not take), and
a call of a numba-compiled function through its address (:func:`native_call`, :func:`kernel_address`), so that
a handler runs the very compiled kernels the numpy API runs, without linking (and compiling) them again. The
addresses are this process's, so they reach a cached ``cfunc`` at run time (an attribute of the custom call),
never as constants of its code.

The frame layout is XLA FFI API version 0.1's (``xla/ffi/api/c_api.h``), as in :mod:`roughpaths._xla_ffi`.
Numba's calling convention is the compiling numba's own (``context.call_conv``): the handlers and the kernels
are compiled by the same numba, whose version keys numba's cache. This module imports neither jax nor any
framework.
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["HANDLER", "JIT", "i64", "i32", "u8", "set_i64", "set_i32", "f64p", "f32p", "address", "voidptr", "call",
           "error", "buffer", "native_call", "kernel_address"]

FRAME_SIZE, ARGS_SIZE, ATTRS_SIZE, BUFFER_SIZE = 168, 40, 48, 48
ARGS, RETS, ATTRS = 40, 80, 120                 # offsets of XLA_FFI_Args, XLA_FFI_Rets, XLA_FFI_Attrs in the frame
BUFFER_KIND, ARRAY_ATTR = 1, 1                  # XLA_FFI_ArgType_BUFFER (= RetType), XLA_FFI_AttrType_ARRAY
F32, F64, S64 = 11, 12, 5                       # XLA_FFI_DataType codes
METADATA_EXTENSION, METADATA_SIZE, EXECUTE = 1, 36, 3
_INTERNAL = 13
_ERROR_ARGS_SIZE = 32                           # XLA_FFI_Error_Create_Args
_ERROR_CREATE = 48                              # offset of XLA_FFI_Error_Create in XLA_FFI_Api
_MESSAGE = ("roughpaths: an XLA FFI call of a compiled handler without its parameters (the int64 array attribute "
            "'roughpaths'); this is a bug of roughpaths.jax")

#: The type of an XLA typed-FFI handler, ``XLA_FFI_Error* (XLA_FFI_CallFrame*)``.
HANDLER = types.voidptr(types.voidptr)
#: numba's options for the frame readers and the handlers' helpers.
JIT = dict(cache=True, nogil=True, no_cfunc_wrapper=True, error_model="numpy")


# ------------------------------------------------------------------------------ raw memory
@intrinsic
def i64(typingctx, addr):
    """The int64 at address ``addr``."""
    def codegen(context, builder, sig, args):
        return builder.load(builder.inttoptr(args[0], ir.IntType(64).as_pointer()))
    return types.int64(types.int64), codegen


def _load_intrinsic(bits: int, signed: bool):
    """An intrinsic ``load(addr)``: the ``bits``-bit integer at ``addr``, sign- or zero-extended to an int64."""
    @intrinsic
    def load(typingctx, addr):
        def codegen(context, builder, sig, args):
            v = builder.load(builder.inttoptr(args[0], ir.IntType(bits).as_pointer()))
            return (builder.sext if signed else builder.zext)(v, ir.IntType(64))
        return types.int64(types.int64), codegen
    return load


#: The int32 at an address, as an int64; the byte at an address, as an int64.
i32, u8 = _load_intrinsic(32, True), _load_intrinsic(8, False)


@intrinsic
def set_i64(typingctx, addr, value):
    """Store the int64 ``value`` at ``addr``."""
    def codegen(context, builder, sig, args):
        builder.store(args[1], builder.inttoptr(args[0], ir.IntType(64).as_pointer()))
        return context.get_dummy_value()
    return types.none(types.int64, types.int64), codegen


@intrinsic
def set_i32(typingctx, addr, value):
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


f64p = _pointer_intrinsic(types.float64, ir.DoubleType())
f32p = _pointer_intrinsic(types.float32, ir.FloatType())


@intrinsic
def address(typingctx, p):
    """A ``void*`` as an int64."""
    def codegen(context, builder, sig, args):
        return builder.ptrtoint(args[0], ir.IntType(64))
    return types.int64(types.voidptr), codegen


@intrinsic
def voidptr(typingctx, addr):
    """An int64 as a ``void*`` (the handler's result)."""
    def codegen(context, builder, sig, args):
        return builder.inttoptr(args[0], ir.IntType(8).as_pointer())
    return types.voidptr(types.int64), codegen


@intrinsic
def call(typingctx, fn, arg):
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


@njit(**JIT)
def error(frame):
    """An ``INTERNAL`` XLA_FFI_Error saying :data:`_MESSAGE`, made by XLA's ``XLA_FFI_Error_Create`` (0 without
    an API)."""
    api = i64(frame + 16) if i64(frame) >= 24 else 0
    if api == 0 or i64(api + _ERROR_CREATE) == 0:
        return 0
    return _create_error(i64(api + _ERROR_CREATE))


@njit(**JIT)
def buffer(frame, rets, i, count):
    """The address of the XLA_FFI_Buffer ``i`` of the frame's arguments (``rets`` 0) or results (1), or 0 if
    they are not ``count`` buffers or it is not a non-empty float32 or float64 buffer."""
    base = frame + (RETS if rets else ARGS)
    if i64(base) < ARGS_SIZE or i64(base + 16) != count:
        return 0
    kinds, bufs = i64(base + 24), i64(base + 32)
    if kinds == 0 or bufs == 0 or i32(kinds + 4 * i) != BUFFER_KIND:
        return 0
    b = i64(bufs + 8 * i)
    if b == 0 or i64(b) < BUFFER_SIZE or i64(b + 24) == 0:
        return 0
    dtype = i32(b + 16)
    if (dtype != F32 and dtype != F64) or i64(b + 32) < 1 or i64(b + 40) == 0:
        return 0
    return b


# ------------------------------------------------------------------------------ numba-compiled functions by address
def native_call(typingctx, expected, addr, args):
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

