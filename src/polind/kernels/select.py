"""``select``: a choice between two computed floats without a branch.

``a if condition else b`` is a branch in numba's IR: a block of its own for
each side, which numba then carries through every pass (and copies once per
block of the function it is inlined into).  Where both sides are computed
anyway and neither can fail, ``select(condition, a, b)`` is LLVM's
``select`` instruction: the same value, to the bit, and what LLVM makes of
the branch in a vectorised loop anyway, without the blocks.
"""

from __future__ import annotations

from numba import types
from numba.extending import intrinsic

from polind.kernels.interpreted import register_twin


@intrinsic
def select(typingctx, condition, a, b):
    """``a`` where ``condition`` else ``b`` (floats; both already computed)."""
    if not isinstance(condition, types.Boolean):
        return None
    signature = types.float64(types.boolean, types.float64, types.float64)

    def codegen(context, builder, sig, args):
        return builder.select(args[0], args[1], args[2])

    return signature, codegen


def _python_select(condition, a, b):
    """:func:`select` run by Python (:mod:`polind.kernels.interpreted`)."""
    return a if condition else b


register_twin(select, _python_select)
