"""Packed float64 registers for the lane kernels (private).

A :data:`row` is a value of :data:`LANES` float64 held in vector registers (LLVM
``<LANES x double>``; two AVX registers for 8 lanes). :func:`vload` / :func:`vstore` move a row
from / to ``LANES`` consecutive elements of a C-contiguous 1-d float64 array (element index, no
bounds check, no negative-index wrap-around: callers pass valid indices). :func:`vadd`,
:func:`vmul` and :func:`vsplat` are the element-wise arithmetic.

Why: numba switches LLVM's SLP vectoriser off and its loop vectoriser does not handle the
``LANES``-iteration loops once they are unrolled, so lane loops written in plain numba compile to
scalar ``vmulsd``/``vaddsd`` (checked in the assembly). These intrinsics emit ``vmulpd``/``vaddpd``
on ``ymm`` registers directly.

Arithmetic is element-wise and rounded per operation (``fmul``, ``fadd``; no fused multiply-add,
no fast-math flags): every lane gets exactly the IEEE operations of the scalar code it replaces,
whatever the other lanes hold. There are no operations across lanes.
"""

from __future__ import annotations

from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic, models, register_model

__all__ = ["LANES", "row", "vload", "vstore", "vadd", "vmul", "vsplat"]

#: Work units computed side by side (one per lane).
LANES = 8
_VEC = ir.VectorType(ir.DoubleType(), LANES)


class _RowType(types.Type):
    def __init__(self):
        super().__init__(name=f"Row{LANES}xf64")


#: numba type of a row of LANES float64 (a value, kept in registers).
row = _RowType()


@register_model(_RowType)
class _RowModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VEC)


def _ptr(context, builder, arrty, arr, idxty, idx):
    ary = context.make_array(arrty)(context, builder, arr)
    i = context.cast(builder, idx, idxty, types.intp)
    return builder.bitcast(builder.gep(ary.data, [i], inbounds=True), _VEC.as_pointer())


def _flat_f8(a) -> bool:
    return isinstance(a, types.Array) and a.dtype == types.float64 and a.ndim == 1 and a.layout == "C"


@intrinsic
def vload(typingctx, a, i):
    """``a[i:i+LANES]`` as a row."""
    if not (_flat_f8(a) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, sig, args):
        return builder.load(_ptr(context, builder, sig.args[0], args[0], sig.args[1], args[1]), align=8)
    return row(a, i), codegen


@intrinsic
def vstore(typingctx, a, i, v):
    """``a[i:i+LANES] = v``."""
    if not (_flat_f8(a) and isinstance(i, types.Integer) and v == row):
        return None

    def codegen(context, builder, sig, args):
        builder.store(args[2], _ptr(context, builder, sig.args[0], args[0], sig.args[1], args[1]), align=8)
        return context.get_dummy_value()
    return types.void(a, i, v), codegen


def _elementwise(op: str):
    """An intrinsic ``f(v, w)``: the element-wise IEEE operation ``op`` (``fadd``, ``fsub``, ``fmul``) of two rows."""
    @intrinsic
    def f(typingctx, v, w):
        if not (v == row and w == row):
            return None

        def codegen(context, builder, sig, args):
            return getattr(builder, op)(args[0], args[1])
        return row(v, w), codegen
    return f


vadd = _elementwise("fadd")      # v + w
vsub = _elementwise("fsub")      # v - w: the IEEE v + (-w), the same bits as adding the negated row
vmul = _elementwise("fmul")      # v * w


@intrinsic
def vsplat(typingctx, x):
    """The row with every lane equal to the scalar ``x``."""
    if not isinstance(x, types.Float):
        return None

    def codegen(context, builder, sig, args):
        c = context.cast(builder, args[0], sig.args[0], types.float64)
        v = builder.insert_element(ir.Constant(_VEC, ir.Undefined), c, ir.Constant(ir.IntType(32), 0))
        mask = ir.Constant(ir.VectorType(ir.IntType(32), LANES), [0] * LANES)
        return builder.shuffle_vector(v, ir.Constant(_VEC, ir.Undefined), mask)
    return row(x), codegen
