"""The Stribeck curve g(v) (:ref:`guide-stribeck-curve`), as a scalar kernel.

``shape`` is an integer code so kernels stay free of Python objects:
:data:`EXPONENTIAL` for ``g = Fc + (Fs - Fc) exp(-|v/vs|^delta)`` and
:data:`RATIONAL` for ``g = Fc + (Fs - Fc) / (1 + |v/vs|^delta)``.
"""

from __future__ import annotations

import math

from polind.kernels import jit

EXPONENTIAL = 0
RATIONAL = 1
SHAPE_CODES = {"exponential": EXPONENTIAL, "rational": RATIONAL}


@jit(inline="always")
def stribeck_curve(v, coulomb_force, static_force, stribeck_velocity, exponent, shape):
    """g(v) [N]: the steady-sliding friction magnitude at velocity v [m/s]."""
    ratio = abs(v / stribeck_velocity)
    # A product for the usual exponents: pow costs more than the rest of a LuGre step.
    if exponent == 2.0:
        ratio = ratio * ratio
    elif exponent != 1.0:
        ratio = ratio ** exponent
    if shape == RATIONAL:
        decay = 1.0 / (1.0 + ratio)
    else:
        decay = math.exp(-ratio)
    return coulomb_force + (static_force - coulomb_force) * decay


@jit(inline="always")
def sign(v):
    """sgn with sgn(0) = 0 (:ref:`guide-conventions`)."""
    if v > 0.0:
        return 1.0
    if v < 0.0:
        return -1.0
    return 0.0
