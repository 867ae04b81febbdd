"""Step kernels of the memoryless models (:ref:`guide-static-models`): Coulomb and Stribeck.

They follow the stepping contract of :mod:`polind.kernels.contract` with an
empty state: the force at a sample is a function of the velocity reported
there.  ``scalars`` holds the Stribeck curve in the slots below (Coulomb is
the curve with ``Fs = Fc``, for which ``g`` is constant).
"""

from __future__ import annotations

from polind.kernels import jit
from polind.kernels.stribeck import sign, stribeck_curve

# Slots of ``scalars``.
VISCOUS = 0            # sigma2 [N s/m]
COULOMB = 1            # Fc [N]
STATIC = 2             # Fs [N]
STRIBECK_VELOCITY = 3  # vs [m/s]
STRIBECK_EXPONENT = 4  # delta
STRIBECK_SHAPE = 5     # polind.kernels.stribeck shape code
N_SCALARS = 6


@jit(fastmath=False)
def memoryless_force(scalars, table, state, sample_velocity, normal_load):
    """``g(v) sgn(v) + sigma2 v`` at the sample's velocity (``sgn(0) = 0``)."""
    g = stribeck_curve(sample_velocity, scalars[COULOMB], scalars[STATIC],
                       scalars[STRIBECK_VELOCITY], scalars[STRIBECK_EXPONENT],
                       scalars[STRIBECK_SHAPE])
    return g * sign(sample_velocity) + scalars[VISCOUS] * sample_velocity


@jit
def memoryless_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                    normal_load):
    """No state: the force at the step's end sample."""
    return memoryless_force(scalars, table, state, sample_velocity, normal_load)


@jit
def memoryless_tangent(scalars, table, state, step):
    """dF/dw away from w = 0: the viscous term only."""
    return scalars[VISCOUS]
