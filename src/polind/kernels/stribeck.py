"""The Stribeck curve g(v) (:ref:`guide-stribeck-curve`), as a scalar kernel.

``shape`` is an integer code so kernels stay free of Python objects:
:data:`EXPONENTIAL` for ``g = Fc + (Fs - Fc) exp(-|v/vs|^delta)`` and
:data:`RATIONAL` for ``g = Fc + (Fs - Fc) / (1 + |v/vs|^delta)``.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.select import select

EXPONENTIAL = 0
RATIONAL = 1
SHAPE_CODES = {"exponential": EXPONENTIAL, "rational": RATIONAL}


#: Below this ``exp`` is exactly 0.0 (``exp(-745.14)`` is below half the least subnormal).
EXP_ZERO = -746.0


@jit(inline="always")
def exact_exp(x):
    """``math.exp``, as a function a template can take (:func:`stribeck_level`).

    0.0 below :data:`EXP_ZERO` without calling libm: the same value, but
    libm reports that underflow through ``errno`` (about 0.1 µs), and a
    Stribeck curve far above its Stribeck velocity underflows at every step.
    """
    return 0.0 if x < EXP_ZERO else math.exp(x)


@jit(inline="always")
def power_ratio(v, stribeck_velocity, squared):
    """``|v/vs|^delta`` for ``delta = 2`` (``squared``) or 1: a product, no ``pow``."""
    ratio = abs(v / stribeck_velocity)
    return select(squared, ratio * ratio, ratio)


@jit(inline="always")
def stribeck_ratio(v, stribeck_velocity, exponent):
    """``|v/vs|^delta``; a product for the usual exponents (pow costs more than a LuGre step)."""
    if (exponent == 2.0) | (exponent == 1.0):
        return power_ratio(v, stribeck_velocity, exponent == 2.0)
    return abs(v / stribeck_velocity) ** exponent


@jit(inline="always")
def stribeck_level(exp_function, ratio, coulomb_force, static_force, shape):
    """g [N] from ``ratio = |v/vs|^delta``; ``exp_function`` is :func:`exact_exp` or a fast one."""
    if shape == RATIONAL:
        decay = 1.0 / (1.0 + ratio)
    else:
        decay = exp_function(-ratio)
    return coulomb_force + (static_force - coulomb_force) * decay


@jit(inline="always")
def stribeck_curve(v, coulomb_force, static_force, stribeck_velocity, exponent, shape):
    """g(v) [N]: the steady-sliding friction magnitude at velocity v [m/s]."""
    return stribeck_level(exact_exp, stribeck_ratio(v, stribeck_velocity, exponent),
                          coulomb_force, static_force, shape)


@jit(inline="always")
def stribeck_slope(v, coulomb_force, static_force, stribeck_velocity, exponent, shape):
    """``dg/dv`` [N s/m] of :func:`stribeck_curve` at ``v != 0`` (0 for ``Fs = Fc``).

    With ``r = |v/vs|^delta``, ``dr/dv = delta r / v``: ``g' = -(Fs - Fc)
    exp(-r) delta r / v`` for the exponential shape and ``-(Fs - Fc) delta r
    / (v (1 + r)^2)`` for the rational one.
    """
    ratio = stribeck_ratio(v, stribeck_velocity, exponent)
    if shape == RATIONAL:
        decay = 1.0 / (1.0 + ratio)
        decay = decay * decay
    else:
        decay = exact_exp(-ratio)
    return -(static_force - coulomb_force) * decay * exponent * ratio / v


@jit(inline="always")
def sign(v):
    """sgn with sgn(0) = 0 (:ref:`guide-conventions`).

    Branches, not selects (:mod:`polind.kernels.select`): with selects it
    compiled a little faster, but LuGre's motion loop ran 8 % slower.
    """
    if v > 0.0:
        return 1.0
    if v < 0.0:
        return -1.0
    return 0.0
