"""Step kernels of the memoryless models (:ref:`guide-static-models`): Coulomb and Stribeck.

They follow the stepping contract of :mod:`polind.kernels.contract` with an
empty state: the force at a sample is a function of the velocity reported
there.  ``scalars`` holds the Stribeck curve in the slots below (Coulomb is
the curve with ``Fs = Fc``, for which ``g`` is constant).
"""

from __future__ import annotations

from polind.kernels import jit
from polind.kernels.contract import run_motion, run_steps
from polind.kernels.dynamics import advance_body_template, integrate_system_template
from polind.kernels.stribeck import sign, stribeck_curve

# Slots of ``scalars``.
VISCOUS = 0            # sigma2 [N s/m]
COULOMB = 1            # Fc [N]
STATIC = 2             # Fs [N]
STRIBECK_VELOCITY = 3  # vs [m/s]
STRIBECK_EXPONENT = 4  # delta
STRIBECK_SHAPE = 5     # polind.kernels.stribeck shape code
N_SCALARS = 6


@jit(inline="always")
def memoryless_force(scalars, table, state, sample_velocity, normal_load):
    """``g(v) sgn(v) + sigma2 v`` at the sample's velocity (``sgn(0) = 0``)."""
    g = stribeck_curve(sample_velocity, scalars[COULOMB], scalars[STATIC],
                       scalars[STRIBECK_VELOCITY], scalars[STRIBECK_EXPONENT],
                       scalars[STRIBECK_SHAPE])
    return g * sign(sample_velocity) + scalars[VISCOUS] * sample_velocity


@jit(inline="always")
def memoryless_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                    normal_load):
    """No state: the force at the step's end sample."""
    return memoryless_force(scalars, table, state, sample_velocity, normal_load)


@jit(inline="always")
def memoryless_tangent(scalars, table, state, step):
    """dF/dw away from w = 0: the viscous term only."""
    return scalars[VISCOUS]


@jit
def memoryless_path(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                    loads, constant_load, lo, hi, first, out_force):
    """:func:`polind.kernels.contract.run_steps` specialised to the memoryless step."""
    run_steps(memoryless_step, memoryless_force, scalars, table, state, step, displacement,
              step_velocity, sample_velocity, loads, constant_load, lo, hi, first, out_force)


@jit
def memoryless_motion(scalars, table, state, source_t, source_motion, t, motion, by_velocity,
                      start_position, start_velocity, continuing, position, velocity, loads,
                      constant_load, lo, hi, first, out_force):
    """:func:`polind.kernels.contract.run_motion` specialised to the memoryless models."""
    return run_motion(memoryless_step, memoryless_force, scalars, table, state, source_t, source_motion, t,
                      motion, by_velocity, start_position, start_velocity, continuing,
                      position, velocity, loads, constant_load, lo, hi, first, out_force)


@jit
def memoryless_integrate(arguments):
    """:func:`polind.kernels.dynamics.integrate_system_template` specialised to the memoryless models (cacheable)."""
    integrate_system_template(memoryless_step, memoryless_tangent, arguments)


@jit
def memoryless_body(arguments):
    """:func:`polind.kernels.dynamics.advance_body_template` specialised to the memoryless models (cacheable)."""
    advance_body_template(memoryless_step, memoryless_tangent, arguments)
