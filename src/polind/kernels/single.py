"""Kernels of the single-state models: Dahl, LuGre, Leuven (the user guide, :ref:`guide-models`).

Arrays are indexed by the sample a step ends at (index 0: the initial state).
``step`` is the step length h [s], ``displacement`` its increment [m],
``step_velocity`` its (constant) velocity, ``sample_velocity`` the velocity
reported at the sample (used by the rate terms of the output force).
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.contract import block_views, cut_sample
from polind.kernels.elements import (element_sum, elastic_stiffness, maxwell_slip_elements,
                                     maxwell_slip_trial)
from polind.kernels.fastexp import decay_exp
from polind.kernels.stribeck import (exact_exp, power_ratio, sign, stribeck_curve,
                                     stribeck_level)


@jit(inline="always")
def dahl_deficit(deficit, distance, rate, exponent):
    """Exact solution of ``du/ds = -rate |u|^alpha sgn(u)`` after a distance ``s >= 0``.

    ``u = 1 - F sgn(v) / Fc`` is the normalised distance to saturation and
    ``s = |dx|``; :ref:`guide-dahl` in the travelled distance.  ``alpha = 1`` is
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


# --- Dahl: scalars [sigma0, Fc, alpha], state [F] ----------------------------------------

DAHL_STIFFNESS = 0
DAHL_COULOMB = 1
DAHL_EXPONENT = 2


@jit
def dahl_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
              normal_load):
    """Dahl over one increment, exactly (the equation depends on the travelled distance only)."""
    force = state[0]
    direction = sign(displacement)
    if direction != 0.0:
        coulomb_force = scalars[DAHL_COULOMB]
        deficit = 1.0 - force * direction / coulomb_force
        deficit = dahl_deficit(deficit, abs(displacement),
                               scalars[DAHL_STIFFNESS] / coulomb_force, scalars[DAHL_EXPONENT])
        force = direction * coulomb_force * (1.0 - deficit)
        state[0] = force
    return force


@jit(fastmath=False)
def dahl_force(scalars, table, state, sample_velocity, normal_load):
    return state[0]


@jit
def dahl_tangent(scalars, table, state, step):
    return scalars[DAHL_STIFFNESS] * step


# --- LuGre: scalars below, state [z] ------------------------------------------------------

LUGRE_VISCOUS = 0      # sigma2 [N s/m]
LUGRE_STIFFNESS = 1    # sigma0 [N/m]
LUGRE_DAMPING = 2      # sigma1 [N s/m]
LUGRE_COULOMB = 3
LUGRE_STATIC = 4
LUGRE_STRIBECK_VELOCITY = 5
LUGRE_STRIBECK_EXPONENT = 6
LUGRE_STRIBECK_SHAPE = 7
N_LUGRE_SCALARS = 8


@jit(inline="always")
def _lugre_curve(scalars, velocity):
    return stribeck_curve(velocity, scalars[LUGRE_COULOMB], scalars[LUGRE_STATIC],
                          scalars[LUGRE_STRIBECK_VELOCITY], scalars[LUGRE_STRIBECK_EXPONENT],
                          scalars[LUGRE_STRIBECK_SHAPE])


@jit(inline="always")
def lugre_relaxation(stiffness, velocity, g):
    """``(z_ss, r)``: the steady deflection ``sgn(v) g / sigma0`` and the rate ``sigma0 |v| / g``.

    LuGre's state equation at a constant velocity is ``dz/dt = v - r z``,
    i.e. ``z`` relaxes towards ``z_ss`` as ``exp(-r t)`` (:ref:`guide-lugre`).
    """
    return sign(velocity) * g / stiffness, stiffness * abs(velocity) / g


@jit(inline="always")
def lugre_output(z, velocity, rate, stiffness, damping, viscous):
    """``sigma0 z + sigma1 dz/dt + sigma2 v`` with ``dz/dt = v - r z`` (:func:`lugre_relaxation`)."""
    return stiffness * z + damping * (velocity - rate * z) + viscous * velocity


@jit(inline="always")
def _lugre_force_at(scalars, z, velocity):
    """The output at a sample's velocity (its own curve and rate)."""
    stiffness = scalars[LUGRE_STIFFNESS]
    steady, rate = lugre_relaxation(stiffness, velocity, _lugre_curve(scalars, velocity))
    return lugre_output(z, velocity, rate, stiffness, scalars[LUGRE_DAMPING],
                        scalars[LUGRE_VISCOUS])


@jit(fastmath=False)
def lugre_force(scalars, table, state, sample_velocity, normal_load):
    return _lugre_force_at(scalars, state[0], sample_velocity)


@jit
def lugre_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
               normal_load):
    """LuGre over one step with the exact exponential update (:ref:`guide-lugre`).

    ``z <- z_ss + (z - z_ss) exp(-r h)`` at the step's velocity; the
    output's ``dz/dt`` is the state equation at the sample (the state after
    the step, the sample's velocity).
    """
    z = state[0]
    stiffness = scalars[LUGRE_STIFFNESS]
    steady, rate = lugre_relaxation(stiffness, step_velocity, _lugre_curve(scalars, step_velocity))
    if step_velocity != 0.0:
        z = steady + (z - steady) * exact_exp(-rate * step)
        state[0] = z
    if sample_velocity != step_velocity:   # with x given they are equal: one curve, not two
        return _lugre_force_at(scalars, z, sample_velocity)
    return lugre_output(z, sample_velocity, rate, stiffness, scalars[LUGRE_DAMPING],
                        scalars[LUGRE_VISCOUS])


@jit
def lugre_tangent(scalars, table, state, step):
    return scalars[LUGRE_STIFFNESS] * step + scalars[LUGRE_DAMPING] + scalars[LUGRE_VISCOUS]


#: Samples a LuGre motion block prepares at once (:func:`lugre_block`).
LUGRE_BLOCK = 512


def lugre_blocks(scalars, by_velocity):
    """Whether a motion runs in LuGre's blocks: positions, a Stribeck exponent of 1 or 2.

    Plain Python: the runner asks it before it calls :func:`lugre_block`.
    """
    exponent = scalars[LUGRE_STRIBECK_EXPONENT]
    return not by_velocity and (exponent == 2.0 or exponent == 1.0)


@jit
def lugre_block(scalars, table, state, source_t, source_motion, t, motion, velocity, out_force,
                a, hi):
    """The samples ``a .. hi - 1`` of a motion in blocks of two passes: ``hi``, or ``-a`` of a bad block.

    The blocked motion of LuGre (:mod:`polind.kernels.template`, where
    :func:`lugre_blocks`).  The exact step's two exponentials (the Stribeck
    curve ``g(w)`` and the decay ``exp(-r h)``) depend on the path only, not
    on the state ``z``: for each block of :data:`LUGRE_BLOCK` samples, a
    first pass with no dependence between samples copies and checks the
    samples and computes the step velocities, ``z_ss``, ``r`` and the decays
    (:func:`lugre_relaxation`, with the vectorisable
    :func:`~polind.kernels.fastexp.decay_exp`), which the compiler turns into
    SIMD code; the second runs the recurrence ``z <- z_ss + (z - z_ss)
    decay`` and the output (:func:`lugre_output`) alone.  A block with a bad
    sample stops the run with the state as the blocks before it left it, and
    returns minus its first sample (``a >= 1``).
    """
    stiffness = scalars[LUGRE_STIFFNESS]
    damping = scalars[LUGRE_DAMPING]
    viscous = scalars[LUGRE_VISCOUS]
    coulomb = scalars[LUGRE_COULOMB]
    static = scalars[LUGRE_STATIC]
    stribeck_velocity = scalars[LUGRE_STRIBECK_VELOCITY]
    shape = scalars[LUGRE_STRIBECK_SHAPE]
    squared = scalars[LUGRE_STRIBECK_EXPONENT] == 2.0
    steady = np.empty(LUGRE_BLOCK)
    decay = np.empty(LUGRE_BLOCK)
    rate = np.empty(LUGRE_BLOCK)
    while a < hi:
        b, t_in, x_in, t_out, x_out, w_out, f_out = block_views(
            source_t, source_motion, t, motion, velocity, out_force, a, hi, LUGRE_BLOCK)
        m = b - a
        bad = 0
        for i in range(m):
            h, dx, w, ok = cut_sample(t_in, x_in, t_out, x_out, i)
            w_out[i] = w
            bad += 0 if ok else 1
            g = stribeck_level(decay_exp, power_ratio(w, stribeck_velocity, squared), coulomb,
                               static, shape)
            steady[i], rate[i] = lugre_relaxation(stiffness, w, g)
            decay[i] = decay_exp(-rate[i] * h)
        if bad != 0:
            return -a
        z = state[0]
        for i in range(m):
            w = w_out[i]
            if w != 0.0:
                z = steady[i] + (z - steady[i]) * decay[i]
            f_out[i] = lugre_output(z, w, rate[i], stiffness, damping, viscous)
        state[0] = z
        a = b
    return hi


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


# --- Leuven: scalars below, table rows [k_i, W_i], state [F_i, z, dz/dt] ----------------

LEUVEN_VISCOUS = 0
LEUVEN_EXPONENT = 1    # n
LEUVEN_DAMPING = 2     # sigma1
LEUVEN_COULOMB = 3
LEUVEN_STATIC = 4
LEUVEN_STRIBECK_VELOCITY = 5
LEUVEN_STRIBECK_EXPONENT = 6
LEUVEN_STRIBECK_SHAPE = 7
LEUVEN_CAPACITY = 8    # sum W_i [N]
N_LEUVEN_SCALARS = 9


@jit
def leuven_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                normal_load):
    """Modified Leuven model (:ref:`guide-leuven`) with an implicit (backward Euler) step.

    The state equation ``dz/dt = v (1 - sgn(Fh/s)|Fh/s|^n)`` is stiff when
    the hysteresis elements are stiff, so each step solves the backward-Euler
    equation for the increment ``dz`` by a safeguarded Newton iteration
    (bracket, Newton step, bisection fallback): unconditionally stable and
    first-order accurate in the step.  ``Fh`` is the Maxwell-slip structure
    driven by ``z``, advanced exactly for the increment.  The output force is
    ``Fh + sigma1 dz/dt + sigma2 v`` with the step's dz/dt.
    """
    n = table.shape[1]
    element_force = state[:n]
    stiffness = table[0]
    breakaway_force = table[1]
    exponent = scalars[LEUVEN_EXPONENT]
    increment = 0.0
    if step_velocity != 0.0:
        g = stribeck_curve(step_velocity, scalars[LEUVEN_COULOMB], scalars[LEUVEN_STATIC],
                           scalars[LEUVEN_STRIBECK_VELOCITY], scalars[LEUVEN_STRIBECK_EXPONENT],
                           scalars[LEUVEN_STRIBECK_SHAPE])
        target = sign(step_velocity) * g
        travel = step_velocity * step
        # |Fh| <= sum W bounds |r|, hence the root lies within this bracket.
        reach = abs(travel) * (1.0 + (scalars[LEUVEN_CAPACITY] / g) ** exponent) * 1.000001 \
            + 1e-300
        low = -reach
        high = reach
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
    else:
        hysteresis = element_sum(element_force)
    rate = increment / step
    state[n] += increment
    state[n + 1] = rate
    return hysteresis + scalars[LEUVEN_DAMPING] * rate + scalars[LEUVEN_VISCOUS] * sample_velocity


@jit(fastmath=False)
def leuven_force(scalars, table, state, sample_velocity, normal_load):
    n = table.shape[1]
    return (element_sum(state[:n]) + scalars[LEUVEN_DAMPING] * state[n + 1]
            + scalars[LEUVEN_VISCOUS] * sample_velocity)


@jit
def leuven_tangent(scalars, table, state, step):
    n = table.shape[1]
    return (step * elastic_stiffness(table[0], state[:n], table[1]) + scalars[LEUVEN_DAMPING]
            + scalars[LEUVEN_VISCOUS])
