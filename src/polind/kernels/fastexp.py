"""A vectorisable exponential for the element loops.

``math.exp`` is an opaque libm call that LLVM will not vectorise, which makes
the GMS / Pol-Ind element update (one exponential per element per step,
:ref:`guide-gms`) cost about 4 ns per element.  This version is plain
arithmetic: Cody–Waite range reduction ``x = n ln2 + r`` with ``|r| <= ln2/2``,
a degree-13 Taylor polynomial for ``exp(r)`` and the factor ``2**n`` built
from its IEEE-754 bit pattern, so the loop vectorises (about 0.7 ns per
element on AVX-512).

It is meant for ``x <= 0`` (decay factors).  Accuracy (tested against
``numpy.exp`` in ``tests/test_kernels.py``): absolute error below 2e-16, and
relative error below ``2e-16 (1 + |x|)``.  The relative error grows with
``|x|`` because the element kernels are compiled with reassociation allowed
(for their vectorised sums), which lets LLVM merge the two-part ``ln 2`` of
the range reduction; where that matters, ``exp(x)`` is below ``1e-30`` and
the decay factor multiplies a force difference, so the force error stays
below 2e-16 of that difference.  ``x < -708`` returns exactly 0 (the true
value is below 3.3e-308), and ``x = -inf`` returns 0.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

from polind.kernels import jit

_LOG2E = 1.4426950408889634
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_LOWEST = -708.0
# 2**52 + 1023: ``n + _SCALE_BIAS`` (n an integer, -1021 <= n for x >= -708) is a float,
# exactly, whose low mantissa bits are n + 1023, the biased exponent of 2**n.
_SCALE_BIAS = 4503599627370496.0 + 1023.0


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once (LLVM's ``llvm.fma``: a fused multiply-add, always).

    The kernels are compiled without the ``contract`` flag, so the compiler
    never decides by itself where to fuse: where it does decide, a kernel
    loaded from numba's cache can round differently from the same kernel
    compiled in the process (one unit in the last place, measured on LuGre),
    and a run would depend on whether its process found a warm cache.  The
    hot polynomial fuses by this instead, the same way in every build.
    """
    signature = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, sig, args):
        double = ir.DoubleType()
        function = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(double, [double, double, double]), "llvm.fma.f64")
        return builder.call(function, args)

    return signature, codegen


@intrinsic
def power_of_two(typingctx, biased):
    """``2**n`` from ``biased = n + 2**52 + 1023`` (a float, exactly): its low mantissa bits, shifted.

    The low bits of ``biased``'s mantissa are ``n + 1023``, the biased exponent
    of ``2**n``: shifted 52 places up, they are ``2**n``'s bit pattern.  Two
    bit casts and a shift, written in LLVM directly: NumPy's scalar ``view``
    does the same but compiles two implementations into every kernel.
    """
    signature = types.float64(types.float64)

    def codegen(context, builder, sig, args):
        bits = builder.bitcast(args[0], ir.IntType(64))
        shifted = builder.shl(bits, ir.Constant(ir.IntType(64), 52))
        return builder.bitcast(shifted, ir.DoubleType())

    return signature, codegen


@jit(inline="always")
def decay_exp(x):
    """exp(x) for x <= 0, vectorisable; 0 below -708."""
    underflow = x < _LOWEST
    x = max(x, _LOWEST)
    n = np.floor(x * _LOG2E + 0.5)
    r = (x - n * _LN2_HI) - n * _LN2_LO
    p = 1.0 / 6227020800.0
    p = fma(p, r, 1.0 / 479001600.0)
    p = fma(p, r, 1.0 / 39916800.0)
    p = fma(p, r, 1.0 / 3628800.0)
    p = fma(p, r, 1.0 / 362880.0)
    p = fma(p, r, 1.0 / 40320.0)
    p = fma(p, r, 1.0 / 5040.0)
    p = fma(p, r, 1.0 / 720.0)
    p = fma(p, r, 1.0 / 120.0)
    p = fma(p, r, 1.0 / 24.0)
    p = fma(p, r, 1.0 / 6.0)
    p = fma(p, r, 0.5)
    p = fma(p, r, 1.0)
    p = fma(p, r, 1.0)
    # 2**n from its exponent bits, taken from the mantissa of n + 2**52 + 1023 (exact):
    # no float-to-integer conversion, which AVX2 has no vector instruction for.
    return 0.0 if underflow else p * power_of_two(n + _SCALE_BIAS)


@jit
def decay_exp_array(x, out):
    """Elementwise :func:`decay_exp` (for tests and vectorised callers)."""
    for i in range(x.shape[0]):
        out[i] = decay_exp(x[i])
    return out
