"""Kernels of the single-state models: Dahl (MODELS.md 2), LuGre (3), Leuven (6).

Arrays are indexed by the sample a step ends at (index 0: the initial state).
``step`` is the step length h [s], ``displacement`` its increment [m],
``step_velocity`` its (constant) velocity, ``sample_velocity`` the velocity
reported at the sample (used by the rate terms of the output force).
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.elements import maxwell_slip_elements, maxwell_slip_trial, element_sum
from polind.kernels.stribeck import sign, stribeck_curve


@jit(inline="always")
def dahl_deficit(deficit, distance, rate, exponent):
    """Exact solution of ``du/ds = -rate |u|^alpha sgn(u)`` after a distance ``s >= 0``.

    ``u = 1 - F sgn(v) / Fc`` is the normalised distance to saturation and
    ``s = |dx|``; MODELS.md 2 in the travelled distance.  ``alpha = 1`` is
    the exponential of the closed form; ``alpha < 1`` reaches ``u = 0`` in a
    finite distance and stays there; ``alpha > 1`` decays algebraically.
    """
    if deficit == 0.0 or distance == 0.0:
        return deficit
    magnitude = abs(deficit)
    if exponent == 1.0:
        magnitude = magnitude * math.exp(-rate * distance)
    elif exponent < 1.0:
        power = 1.0 - exponent
        remaining = magnitude ** power - power * rate * distance
        magnitude = remaining ** (1.0 / power) if remaining > 0.0 else 0.0
    else:
        power = exponent - 1.0
        magnitude = (magnitude ** (-power) + power * rate * distance) ** (-1.0 / power)
    return magnitude if deficit > 0.0 else -magnitude


@jit
def dahl_run(displacement, stiffness, coulomb_force, exponent, state, out_force):
    """Dahl over a path.  ``state[0]`` is the friction force F (the model's only state)."""
    force = state[0]
    rate = stiffness / coulomb_force
    out_force[0] = force
    for k in range(1, displacement.shape[0]):
        dx = displacement[k]
        direction = sign(dx)
        if direction != 0.0:
            deficit = 1.0 - force * direction / coulomb_force
            deficit = dahl_deficit(deficit, abs(dx), rate, exponent)
            force = direction * coulomb_force * (1.0 - deficit)
        out_force[k] = force
    state[0] = force


@jit
def lugre_run(step, step_velocity, sample_velocity, bristle_stiffness, bristle_damping,
              coulomb_force, static_force, stribeck_velocity, stribeck_exponent, shape,
              state, out_force):
    """LuGre over a path with the exact exponential update of MODELS.md 3.

    ``state[0]`` is the bristle deflection z [m].  The output force at sample
    k is ``sigma0 z + sigma1 dz/dt`` with ``dz/dt = v - sigma0 |v| z / g(v)``
    evaluated at the sample's state and velocity (the viscous term
    ``sigma2 v`` is added by the caller).
    """
    z = state[0]
    for k in range(step.shape[0]):
        if k > 0:
            velocity = step_velocity[k]
            if velocity != 0.0:
                g = stribeck_curve(velocity, coulomb_force, static_force, stribeck_velocity,
                                   stribeck_exponent, shape)
                steady = sign(velocity) * g / bristle_stiffness
                z = steady + (z - steady) * math.exp(-bristle_stiffness * abs(velocity) * step[k] / g)
        v = sample_velocity[k]
        g = stribeck_curve(v, coulomb_force, static_force, stribeck_velocity,
                           stribeck_exponent, shape)
        rate = v - bristle_stiffness * abs(v) * z / g
        out_force[k] = bristle_stiffness * z + bristle_damping * rate
    state[0] = z


@jit(inline="always")
def _leuven_residual(increment, element_force, stiffness, breakaway_force,
                     travel, target, exponent):
    """Backward-Euler residual ``G(dz) = dz - v h (1 - sgn(r)|r|^n)``, ``r = Fh(z+dz)/s(v)``.

    Returns ``(G, dG/d(dz))``.  G is strictly increasing (slope >= 1), so the
    root is unique.
    """
    hysteresis, tangent = maxwell_slip_trial(element_force, stiffness, breakaway_force, increment)
    ratio = hysteresis / target
    magnitude = abs(ratio)
    powered = magnitude ** exponent
    residual = increment - travel * (1.0 - (powered if ratio >= 0.0 else -powered))
    slope_power = exponent * magnitude ** (exponent - 1.0) if magnitude > 0.0 else (
        1.0 if exponent == 1.0 else 0.0)
    slope = 1.0 + travel * slope_power * tangent / target
    return residual, slope


@jit
def leuven_run(step, step_velocity, stiffness, breakaway_force, exponent,
               bristle_damping, coulomb_force, static_force, stribeck_velocity,
               stribeck_exponent, shape, element_force, state, out_force):
    """Modified Leuven model (MODELS.md 6) with an implicit (backward Euler) step.

    The state equation ``dz/dt = v (1 - sgn(Fh/s)|Fh/s|^n)`` is stiff when
    the hysteresis elements are stiff, so each step solves the backward-Euler
    equation for the increment ``dz`` by a safeguarded Newton iteration
    (bracket, Newton step, bisection fallback): unconditionally stable and
    first-order accurate in the step.  ``Fh`` is the Maxwell-slip structure
    driven by ``z``, advanced exactly for the increment.  ``state[0]`` is z,
    ``state[1]`` the last output's dz/dt.  The output force is
    ``Fh + sigma1 dz/dt`` with the step's dz/dt (the viscous term is added by
    the caller).
    """
    z = state[0]
    rate = state[1]
    hysteresis = element_sum(element_force)
    out_force[0] = hysteresis + bristle_damping * rate
    total_capacity = 0.0
    for i in range(breakaway_force.shape[0]):
        total_capacity += breakaway_force[i]
    for k in range(1, step.shape[0]):
        velocity = step_velocity[k]
        h = step[k]
        increment = 0.0
        if velocity != 0.0:
            g = stribeck_curve(velocity, coulomb_force, static_force, stribeck_velocity,
                               stribeck_exponent, shape)
            target = sign(velocity) * g
            travel = velocity * h
            # |Fh| <= sum W bounds |r|, hence the root lies within this bracket.
            reach = abs(travel) * (1.0 + (total_capacity / g) ** exponent) * 1.000001 + 1e-300
            low = -reach
            high = reach
            increment = 0.0
            tolerance = 2e-15 * reach
            for _ in range(200):
                residual, slope = _leuven_residual(increment, element_force, stiffness,
                                                   breakaway_force, travel, target, exponent)
                if abs(residual) <= tolerance:
                    break
                if residual > 0.0:
                    high = increment
                else:
                    low = increment
                if high - low <= tolerance:
                    break
                candidate = increment - residual / slope
                if not (low < candidate < high) or not (slope > 0.0):
                    candidate = 0.5 * (low + high)
                increment = candidate
            hysteresis = maxwell_slip_elements(element_force, stiffness, breakaway_force, increment)
        rate = increment / h
        z += increment
        out_force[k] = hysteresis + bristle_damping * rate
    state[0] = z
    state[1] = rate
