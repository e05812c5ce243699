"""Single machine instructions numba does not offer, as numba intrinsics (LLVM's own
operations, so they compile on every target LLVM knows).

``trailing_zeros``: the lowest set bit's number (cttz). ``prefetch_row`` and
``prefetch_row_for_write``: ask for the cache line of ``array[row, 0]`` ahead of
use (a hint: no fault, no effect on results). The tile tests read and write
their rays through a permutation, which the hardware's stride prefetchers
cannot follow (tracing/tile_tests.py).
"""

from __future__ import annotations

from typing import Any

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


def _cttz(typingctx, value):
    """The number of zero bits below the lowest set bit of a nonzero integer: LLVM's
    cttz, one instruction (a row's live bins: walking the set bits skips the dead
    ones without a test each; a de Bruijn table lookup made the tile tests 10 %
    slower)."""
    if not isinstance(value, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        return builder.cttz(args[0], ir.Constant(ir.IntType(1), 0))

    return value(value), codegen


trailing_zeros: Any = intrinsic(_cttz)


def _prefetch(for_write: int):
    def typer(typingctx, array, row):
        if not (isinstance(array, types.Array) and isinstance(row, types.Integer)):
            return None

        def codegen(context, builder, signature, args):
            array_type = signature.args[0]
            data = context.make_array(array_type)(context, builder, args[0])
            first = [context.cast(builder, args[1], signature.args[1], types.intp)]
            first += [context.get_constant(types.intp, 0)] * (array_type.ndim - 1)
            pointer = cgutils.get_item_pointer(context, builder, array_type, data, first)
            bytes_pointer = ir.IntType(8).as_pointer()
            i32 = ir.IntType(32)
            prefetch = cgutils.get_or_insert_function(
                builder.module,
                ir.FunctionType(ir.VoidType(), [bytes_pointer, i32, i32, i32]),
                "llvm.prefetch.p0",
            )
            # (address, read 0 / write 1, keep in every cache level: 3, data cache: 1)
            flags = [ir.Constant(i32, for_write), ir.Constant(i32, 3), ir.Constant(i32, 1)]
            builder.call(prefetch, [builder.bitcast(pointer, bytes_pointer), *flags])
            return context.get_dummy_value()

        return types.void(array, row), codegen

    return typer


prefetch_row: Any = intrinsic(_prefetch(0))
prefetch_row_for_write: Any = intrinsic(_prefetch(1))
