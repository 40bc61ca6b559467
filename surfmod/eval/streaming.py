"""Non-temporal ("streaming") stores for compiled kernels whose output is far larger
than the caches.

An ordinary store first reads the cache line it writes into (read for ownership) and
later writes it back, so filling a 216 MB array moves about twice its size through
memory and evicts everything else from the caches.  A non-temporal store goes to the
write-combining buffers and from there to memory in whole lines: on this project's
reference machine a compiled loop fills such an array about 2.5 times faster with them
(``benchmarks/bench_eval.py`` prints both floors).  They pay off only for output the
caller will not read back at once, so callers use them above a size threshold, and only
into memory already paged in: the kernel zeroes a fresh page through the caches when it
is first touched, and ordinary stores then hit those lines
(:func:`surfmod.eval.local.surface_grid` streams into a caller's array only).

The stores are LLVM ``store`` instructions with ``!nontemporal`` metadata, emitted
through numba intrinsics: x86-64 compiles the 16-byte vector form to ``movntpd``, other
targets to their own non-temporal pair store or to a plain store.  Non-temporal stores
are weakly ordered, so a kernel ends its streaming with :func:`fence`.

>>> import numpy as np
>>> from numba import njit
>>> @njit
... def fill(out):  # out[1:5] = 1, 2, 3, 4, in pairs from the first 16-byte boundary
...     start = 1 if aligned_16(out, 1) else 2
...     if start == 2:
...         out[1] = 1.0
...     for i in range(start, 5, 2):
...         stream_pair(out, i, float(i), float(i + 1))
...     fence()
>>> out = np.zeros(7); fill(out); out[:5]
array([0., 1., 2., 3., 4.])
"""

from __future__ import annotations

from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

_DOUBLE_PAIR = ir.VectorType(ir.DoubleType(), 2)
_I32 = ir.IntType(32)


@intrinsic
def stream_pair(typingctx, array, index, first, second):
    """Store ``first, second`` at ``array[index], array[index + 1]`` of a contiguous
    float64 array with one non-temporal 16-byte store; ``array[index]`` must lie on a
    16-byte boundary (:func:`aligned_16`)."""
    sig = types.void(array, index, first, second)

    def codegen(context, builder, signature, args):
        data, at, x0, x1 = args
        ary = context.make_array(signature.args[0])(context, builder, data)
        pair = builder.insert_element(ir.Constant(_DOUBLE_PAIR, ir.Undefined), x0, ir.Constant(_I32, 0))
        pair = builder.insert_element(pair, x1, ir.Constant(_I32, 1))
        target = builder.bitcast(builder.gep(ary.data, [at]), _DOUBLE_PAIR.as_pointer())
        store = builder.store(pair, target, align=16)
        store.set_metadata("nontemporal", builder.module.add_metadata([ir.Constant(_I32, 1)]))
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def _address(typingctx, array, index):
    """The address of ``array[index]`` (a contiguous array) as an unsigned integer."""
    sig = types.uint64(array, index)

    def codegen(context, builder, signature, args):
        data, at = args
        ary = context.make_array(signature.args[0])(context, builder, data)
        return builder.ptrtoint(builder.gep(ary.data, [at]), ir.IntType(64))

    return sig, codegen


@intrinsic
def fence(typingctx):
    """A full memory fence (``mfence`` on x86-64): the streamed stores before it are
    visible to every thread before any memory access after it."""
    sig = types.void()

    def codegen(context, builder, signature, args):
        builder.fence("seq_cst")
        return context.get_dummy_value()

    return sig, codegen


@njit(cache=True, inline="always")
def aligned_16(array, index):
    """Whether ``array[index]`` of a contiguous float64 array lies on a 16-byte boundary."""
    return _address(array, index) % 16 == 0
