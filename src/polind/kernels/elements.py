"""The element machinery of the Maxwell-slip family.

One set of element kernels serves every model built from elements in
parallel: Maxwell-slip itself, the hysteresis force of the Leuven model, GMS,
and the Pol-Ind model (GMS elements whose stiffness and weight come from the
asperity mechanics).  The state of every element is its force ``F_i``; a
GMS-type element also carries its slip direction (``+1``/``-1`` while it slips
in that direction, ``0`` while it sticks).

Both element laws are integrated *exactly* over a step at constant velocity:

* Maxwell-slip (rate independent): ``F_i <- clip(F_i + k_i dx, -W_i, W_i)``,
  the exact response to a monotone displacement increment.
* GMS (rate-state): stuck elements follow ``F_i + k_i dx``; slipping ones
  relax as ``T + (F_i - T) exp(-C h / (alpha_i g(v)))`` with
  ``T = alpha_i sgn(v) g(v)``.  A stuck element that reaches its capacity
  inside the step crosses at ``F_i = T`` and, since the slip law relaxes
  towards ``T``, stays there for the rest of the step: splitting the step at
  the crossing gives exactly ``T``.  A stuck element that is already beyond
  its capacity at the start of a step (the capacity ``alpha_i g(v)`` fell
  because the velocity changed) slips from the start.

The loops are written branch-free over contiguous arrays so LLVM vectorises
them; the exponential is :func:`polind.kernels.fastexp.decay_exp`.

The models are in the user guide: :ref:`guide-maxwell-slip`, :ref:`guide-gms`,
:ref:`guide-leuven`, :ref:`guide-pol-ind-elements` and :ref:`guide-pol-ind-law`.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.contract import block_views, cut_sample
from polind.kernels.fastexp import decay_exp
from polind.kernels.select import select
from polind.kernels.stribeck import sign, stribeck_curve, stribeck_slope


# Called from Python (ElementTable) as well as from the kernels below, so not
# inlined; without fastmath, as it was compiled in polind.contact (bit for bit).
@jit(fastmath=False)
def element_properties(heights, counts, d, R, E_star, G_star, mu_s, out_k, out_W):
    """Stiffness and break-away force of fixed-height elements at separation ``d``.

    ``out_k[j] = n_j 8 G* sqrt(R delta_j)`` and
    ``out_W[j] = n_j mu_s (4/3) E* sqrt(R) delta_j^(3/2)`` with
    ``delta_j = heights[j] - d``; an element with ``delta_j <= 0`` is out of
    contact and gets ``k = W = 0``.  Arrays and floats only, compiled with
    numba, for use inside stepping kernels.

    Parameters
    ----------
    heights : numpy.ndarray
        Element heights ``h_j`` [m].
    counts : numpy.ndarray
        Asperities per element ``n_j`` [-].
    d : float
        Separation [m].
    R : float
        Summit radius [m].
    E_star, G_star : float
        Effective moduli [Pa].
    mu_s : float
        Static friction coefficient [-].
    out_k : numpy.ndarray
        Output: element stiffnesses [N/m], same length as ``heights``.
    out_W : numpy.ndarray
        Output: element break-away forces [N].
    """
    sqrt_R = math.sqrt(R)
    stiffness_scale = 8.0 * G_star * sqrt_R
    capacity_scale = mu_s * (4.0 / 3.0) * E_star * sqrt_R
    # Branch-free (delta clamped at 0 gives k = W = 0 exactly), so LLVM vectorises
    # the loop: 0.7 us against 1.0-1.6 us for 1,014 elements with the branch.
    for j in range(heights.size):
        delta = max(heights[j] - d, 0.0)
        root = math.sqrt(delta)
        out_k[j] = counts[j] * stiffness_scale * root
        out_W[j] = counts[j] * capacity_scale * delta * root


@jit(inline="always")
def maxwell_slip_element(force, stiffness, breakaway_force, displacement):
    """One Maxwell-slip element after an increment: ``clip(F + k dx, -W, W)``."""
    return min(max(force + stiffness * displacement, -breakaway_force), breakaway_force)


@jit(inline="always")
def maxwell_slip_elements(element_force, stiffness, breakaway_force, displacement):
    """Advance Maxwell-slip elements by a monotone increment; return the sum of forces."""
    total = 0.0
    for i in range(element_force.shape[0]):
        force = maxwell_slip_element(element_force[i], stiffness[i], breakaway_force[i],
                                     displacement)
        element_force[i] = force
        total += force
    return total


@jit(inline="always")
def maxwell_slip_trial(element_force, stiffness, breakaway_force, displacement):
    """Sum of Maxwell-slip element forces after an increment, without storing them.

    Also returns the summed stiffness of the elements still elastic (the
    tangent stiffness), for Newton iterations on the increment.
    """
    total = 0.0
    tangent = 0.0
    for i in range(element_force.shape[0]):
        force = element_force[i] + stiffness[i] * displacement
        clipped = min(max(force, -breakaway_force[i]), breakaway_force[i])
        total += clipped
        tangent += stiffness[i] if clipped == force else 0.0
    return total, tangent


@jit(inline="always")
def element_sum(element_force):
    total = 0.0
    for i in range(element_force.shape[0]):
        total += element_force[i]
    return total


@jit(inline="always")
def computed_decay(inverse_weight, decay_rate, i):
    """Element ``i``'s decay factor ``exp(decay_rate / alpha_i)``, computed from the
    ``1/alpha`` row (:func:`gms_elements`'s ``factor`` of a step that keeps no factors)."""
    return decay_exp(decay_rate * inverse_weight[i])


@jit(inline="always")
def given_decay(decay, decay_rate, i):
    """Element ``i``'s decay factor from a row of them (:func:`decay_factors`; ``decay_rate``
    is not used): :func:`gms_elements`'s ``factor`` of a step with kept factors."""
    return decay[i]


@jit(inline="always")
def gms_elements(factor, element_force, slip_direction, stiffness, weight, factors,
                 capacity_scale, direction, displacement, decay_rate):
    """Advance GMS elements over one step at constant velocity; return the sum of forces.

    Parameters
    ----------
    factor : function
        :func:`computed_decay` (``factors`` is the ``1/alpha`` row) or
        :func:`given_decay` (``factors`` is the row of decay factors,
        :func:`decay_factors`): element ``i``'s factor is
        ``factor(factors, decay_rate, i)``, the same number either way.
    capacity_scale : float
        ``g(v)`` [N]; element ``i`` slips at ``alpha_i g(v)``.
    direction : float
        ``sgn(v)``, nonzero.
    displacement : float
        ``v h`` [m].
    decay_rate : float
        ``-C h / g(v)``; element ``i`` relaxes by ``exp(decay_rate / alpha_i)``.
    """
    total = 0.0
    for i in range(element_force.shape[0]):
        force, slip = gms_decayed_element(element_force[i], slip_direction[i], stiffness[i],
                                          weight[i], capacity_scale, direction, displacement,
                                          factor(factors, decay_rate, i))
        element_force[i] = force
        slip_direction[i] = slip
        total += force
    return total


@jit(inline="always")
def gms_decayed_element(force, slip, stiffness, weight, capacity_scale, direction,
                        displacement, decay):
    """One GMS element over one step (:func:`gms_elements`): its new force and slip direction.

    ``decay`` is its factor ``exp(-C h / (alpha_i g))``.  Branch-free (selects),
    so that a loop over elements vectorises.
    """
    capacity = weight * capacity_scale
    target = direction * capacity
    relaxed = target + (force - target) * decay
    trial = force + stiffness * displacement
    slipping = (slip == direction) | (direction * force >= capacity)
    crosses = direction * trial >= capacity
    new_force = select(slipping, relaxed, select(crosses, target, trial))
    return new_force, select(slipping | crosses, direction, 0.0)


@jit(inline="always")
def gms_element_slope(force, slip, weight, inverse, capacity_scale, direction, decay):
    """One element's share of ``dF/dw`` through ``g(w)``: ``(a, b)`` of :func:`gms_kept_elements`.

    The element as :func:`gms_decayed_element` steps it: in slip it relaxes
    to ``T + (F - T) e`` with ``T = sgn(v) alpha g`` and ``e = exp(-C h /
    (alpha g))``, whose derivative in ``g`` is ``a + b C h / g^2`` with ``a
    = sgn(v) alpha (1 - e)`` and ``b = (F - T) e / alpha``; an element that
    crosses its capacity in the step ends at ``T`` (``a = sgn(v) alpha``,
    ``b = 0``); one that sticks does not depend on ``g``.  ``inverse`` is
    ``1 / alpha`` (``inf`` out of contact, where ``e = 0`` and ``b = 0``).
    """
    capacity = weight * capacity_scale
    target = direction * capacity
    slipping = (slip == direction) | (direction * force >= capacity)
    relaxing = (force - target) * decay
    a = direction * weight * select(slipping, 1.0 - decay, 1.0)
    b = select(decay > 0.0, relaxing * inverse, 0.0)
    return a, select(slipping, b, 0.0)


@jit(inline="always")
def gms_kept_elements(factor, element_force, slip_direction, stiffness, weight, factors,
                      capacity_scale, direction, displacement, decay_rate, inverse_weight,
                      out_force, out_slip):
    """:func:`gms_elements` without storing: ``(sum of forces, summed stiffness in stick, A, B)``.

    Each element's new force and slip direction as :func:`gms_elements`
    gives them, written into ``out_force`` and ``out_slip``, not into the
    state (the state a trial's caller may take,
    :func:`polind.kernels.contract.no_trial`); the second sum is what
    :func:`stuck_stiffness` would sum over the elements after the step;
    ``A`` and ``B`` sum the slipping and crossing elements'
    :func:`gms_element_slope` (``inverse_weight`` is the ``1/alpha`` row),
    from which :func:`gms_trial_scaled` takes ``dF/dg``.
    """
    total = 0.0
    stuck = 0.0
    slope_a = 0.0
    slope_b = 0.0
    for i in range(element_force.shape[0]):
        decay = factor(factors, decay_rate, i)
        force, slip = gms_decayed_element(element_force[i], slip_direction[i], stiffness[i],
                                          weight[i], capacity_scale, direction, displacement,
                                          decay)
        a, b = gms_element_slope(element_force[i], slip_direction[i], weight[i],
                                 inverse_weight[i], capacity_scale, direction, decay)
        out_force[i] = force
        out_slip[i] = slip
        total += force
        stuck += select(slip == 0.0, stiffness[i], 0.0)
        slope_a += select(slip != 0.0, a, 0.0)
        slope_b += b
    return total, stuck, slope_a, slope_b


@jit(inline="always")
def decay_factors(inverse_weight, decay_rate, out):
    """``out[i] = exp(decay_rate / alpha_i)``: the factors :func:`computed_decay` gives one by one.

    Each is :func:`computed_decay`'s, so that :func:`gms_elements` with these
    factors (:func:`given_decay`) gives what it gives computing them, to the bit.
    """
    for i in range(out.shape[0]):
        out[i] = computed_decay(inverse_weight, decay_rate, i)


# --- the stepping contract (polind.kernels.contract) of the element models ---------------
#
# Maxwell-slip: scalars [sigma2], table rows [k_i, W_i], state [F_i].
# GMS:          scalars [sigma2, C, Fc, Fs, vs, delta, shape],
#               table rows [k_i, alpha_i, 1/alpha_i], state [F_i, slip direction_i].

VISCOUS = 0            # sigma2 [N s/m], every element model
ATTRACTION = 1         # C [N/s] (GMS)
COULOMB = 2            # Fc [N] (GMS)
STATIC = 3             # Fs [N] (GMS)
STRIBECK_VELOCITY = 4  # vs [m/s] (GMS)
STRIBECK_EXPONENT = 5  # delta (GMS)
STRIBECK_SHAPE = 6     # shape code (GMS)
N_GMS_SCALARS = 7

ELEMENT_STIFFNESS = 0  # k_i [N/m]
ELEMENT_CAPACITY = 1   # W_i [N] (Maxwell-slip) or alpha_i (GMS)
ELEMENT_INVERSE = 2    # 1 / alpha_i (GMS)


@jit(inline="always")
def elastic_stiffness(stiffness, element_force, capacity):
    """Summed stiffness of the elements strictly inside their capacity (a tangent)."""
    total = 0.0
    for i in range(stiffness.shape[0]):
        total += stiffness[i] if abs(element_force[i]) < capacity[i] else 0.0
    return total


@jit(inline="always")
def stuck_stiffness(stiffness, slip_direction):
    """Summed stiffness of the GMS elements in stick (a tangent)."""
    total = 0.0
    for i in range(stiffness.shape[0]):
        total += select(slip_direction[i] == 0.0, stiffness[i], 0.0)
    return total


@jit
def maxwell_slip_step(scalars, table, state, step, displacement, step_velocity,
                      sample_velocity, normal_load):
    """Maxwell-slip: ``F_i <- clip(F_i + k_i dx, -W_i, W_i)``; ``F = sum F_i + sigma2 v``.

    See :ref:`guide-maxwell-slip`.
    """
    total = maxwell_slip_elements(state, table[ELEMENT_STIFFNESS], table[ELEMENT_CAPACITY],
                                  displacement)
    return total + scalars[VISCOUS] * sample_velocity


@jit(fastmath=False)
def maxwell_slip_force(scalars, table, state, sample_velocity, normal_load):
    return element_sum(state) + scalars[VISCOUS] * sample_velocity


@jit
def maxwell_slip_tangent(scalars, table, state, step):
    return step * elastic_stiffness(table[ELEMENT_STIFFNESS], state,
                                    table[ELEMENT_CAPACITY]) + scalars[VISCOUS]


@jit
def maxwell_slip_trial_step(scalars, table, state, out, keep, step, displacement, step_velocity,
                            sample_velocity, normal_load):
    """The read-only trial (:func:`polind.kernels.contract.no_trial`) of Maxwell-slip.

    ``(F, tangent, written)``: the force :func:`maxwell_slip_step` returns
    and ``maxwell_slip_tangent`` of the state it leaves, in one pass
    over the elements.  The new element forces go to ``out`` (the caller's
    scratch), keep or not, as in
    :func:`gms_trial_scaled`; ``written`` is their number with ``keep``, else 0.
    """
    stiffness = table[ELEMENT_STIFFNESS]
    capacity = table[ELEMENT_CAPACITY]
    total = 0.0
    elastic = 0.0
    for i in range(state.shape[0]):
        force = maxwell_slip_element(state[i], stiffness[i], capacity[i], displacement)
        out[i] = force
        total += force
        elastic += stiffness[i] if abs(force) < capacity[i] else 0.0
    written = state.shape[0] if keep else 0
    return (total + scalars[VISCOUS] * sample_velocity, step * elastic + scalars[VISCOUS],
            written)


#: Samples a Maxwell-slip motion block cuts at once (:func:`maxwell_slip_block`).
MOTION_BLOCK = 256


def maxwell_slip_blocks(scalars, by_velocity):
    """Whether a motion runs in Maxwell-slip's blocks: along positions (plain Python)."""
    return not by_velocity


@jit
def maxwell_slip_block(scalars, table, state, source_t, source_motion, t, motion, velocity,
                       out_force, a, hi):
    """The samples ``a .. hi - 1`` of a motion in blocks, two samples a pass: ``hi``, or ``-a``.

    The blocked motion of Maxwell-slip (:mod:`polind.kernels.template`, along
    positions).  Each block's :data:`MOTION_BLOCK` samples are first copied,
    checked and cut into steps in a pass with no dependence between samples;
    the elements are then advanced two samples per pass over them
    (:func:`maxwell_slip_element` twice, each sample's sum kept), so each
    element's stiffness, capacity and force are loaded once for two steps.
    The forces are those of one sample at a time, summed in another order
    (within a few ulp).  A block with a bad sample stops the run with the
    state as the blocks before it left it, and returns minus its first
    sample (``a >= 1``).
    """
    stiffness = table[ELEMENT_STIFFNESS]
    capacity = table[ELEMENT_CAPACITY]
    viscous = scalars[VISCOUS]
    n = stiffness.shape[0]
    element_force = state[:n]
    displacement = np.empty(MOTION_BLOCK + 1)
    while a < hi:
        b, t_in, x_in, t_out, x_out, w_out, f_out = block_views(
            source_t, source_motion, t, motion, velocity, out_force, a, hi, MOTION_BLOCK)
        m = b - a
        bad = 0
        for i in range(m):
            h, dx, w, ok = cut_sample(t_in, x_in, t_out, x_out, i)
            w_out[i] = w
            displacement[i] = dx
            bad += 0 if ok else 1
        if bad != 0:
            return -a
        if m % 2 == 1:
            # An odd last sample is paired with a step of zero (which moves no element),
            # so every sample's force comes from the one loop below, whichever place it
            # has in a pair: a run cut into chunks gives the same bits as one run.
            displacement[m] = 0.0
        i = 0
        while i < m:
            first_step = displacement[i]
            second_step = displacement[i + 1]
            first_total = 0.0
            second_total = 0.0
            for j in range(n):
                limit = capacity[j]
                k = stiffness[j]
                force = maxwell_slip_element(element_force[j], k, limit, first_step)
                first_total += force
                force = maxwell_slip_element(force, k, limit, second_step)
                second_total += force
                element_force[j] = force
            f_out[i] = first_total + viscous * w_out[i]
            if i + 1 < m:
                f_out[i + 1] = second_total + viscous * w_out[i + 1]
            i += 2
        a = b
    return hi


@jit(inline="always")
def inverse_row(scalars, table, step, g):
    """The ``1/alpha`` row: the ``factors`` of :func:`computed_decay` (the GMS model's own)."""
    return table[ELEMENT_INVERSE]


@jit(inline="always")
def gms_step_scaled(factor, factor_row, scalars, table, element_force, slip_direction, step,
                    displacement, step_velocity, sample_velocity, coulomb_force, static_force):
    """One GMS step (:ref:`guide-gms`) with the given Stribeck levels; the element-model core.

    A step with zero velocity changes nothing (``sgn(0) = 0``: no stick
    growth, no slip relaxation) and keeps every element's mode.  The
    elements' decay factors are ``factor(factor_row(scalars, table, step,
    g), -C h / g, i)`` (:func:`gms_elements`): :func:`computed_decay` of
    :func:`inverse_row` computes each in the loop; a model that keeps them
    between steps gives :func:`given_decay` of its row
    (:func:`polind.kernels.pol_ind.decay_row`): the same numbers, to the bit.
    """
    if step_velocity == 0.0:
        total = element_sum(element_force)
    else:
        g = stribeck_curve(step_velocity, coulomb_force, static_force,
                           scalars[STRIBECK_VELOCITY], scalars[STRIBECK_EXPONENT],
                           scalars[STRIBECK_SHAPE])
        total = gms_elements(factor, element_force, slip_direction, table[ELEMENT_STIFFNESS],
                             table[ELEMENT_CAPACITY], factor_row(scalars, table, step, g), g,
                             sign(step_velocity), displacement,
                             -scalars[ATTRACTION] * step / g)
    return total + scalars[VISCOUS] * sample_velocity


@jit
def gms_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
             normal_load):
    n = table.shape[1]
    return gms_step_scaled(computed_decay, inverse_row, scalars, table, state[:n],
                           state[n:2 * n], step, displacement, step_velocity, sample_velocity,
                           scalars[COULOMB], scalars[STATIC])


@jit(fastmath=False)
def gms_force(scalars, table, state, sample_velocity, normal_load):
    return element_sum(state[:table.shape[1]]) + scalars[VISCOUS] * sample_velocity


@jit
def gms_tangent(scalars, table, state, step):
    n = table.shape[1]
    return step * stuck_stiffness(table[ELEMENT_STIFFNESS], state[n:2 * n]) + scalars[VISCOUS]


@jit(inline="always")
def gms_trial_scaled(factor, factor_row, scalars, table, element_force, slip_direction, out,
                     keep, step, displacement, step_velocity, sample_velocity, coulomb_force,
                     static_force):
    """:func:`gms_step_scaled` without storing: ``(F, dF/dw, written)``.

    The force the step returns and its derivative in the step velocity
    ``w``, in one pass over the elements (:func:`gms_kept_elements`; the
    decay factors as in :func:`gms_step_scaled`): ``gms_tangent``'s stuck
    stiffness of the state it leaves, plus, where ``g(w)`` is not flat, the
    slipping and crossing elements' dependence on ``g``
    (:func:`gms_element_slope`) times ``g'(w)``.  The new element forces and
    slip directions go to ``out`` (``2 n`` entries, the layout of the
    state), with ``keep`` or not; ``written = 2 n`` with ``keep``, else 0;
    a step with zero velocity changes nothing (``written = 0``), and its
    tangent is the state's own.
    """
    stiffness = table[ELEMENT_STIFFNESS]
    n = element_force.shape[0]
    written = 0
    if step_velocity == 0.0:
        total = element_sum(element_force)
        tangent = step * stuck_stiffness(stiffness, slip_direction)
    else:
        velocity_scale = scalars[STRIBECK_VELOCITY]
        exponent = scalars[STRIBECK_EXPONENT]
        shape = scalars[STRIBECK_SHAPE]
        g = stribeck_curve(step_velocity, coulomb_force, static_force, velocity_scale, exponent,
                           shape)
        factors = factor_row(scalars, table, step, g)
        decay_rate = -scalars[ATTRACTION] * step / g
        # One loop, keep or not: the new state always goes to `out` (the caller's
        # scratch), and is the caller's to take only with `keep`.  A second loop
        # without the stores cost each trial kernel 0.9 s of compilation (two
        # vectorised loops) and saved no measurable time per trial.
        written = 2 * n if keep else 0
        total, stuck, slope_a, slope_b = gms_kept_elements(
            factor, element_force, slip_direction, stiffness, table[ELEMENT_CAPACITY],
            factors, g, sign(step_velocity), displacement, decay_rate,
            table[ELEMENT_INVERSE], out[:n], out[n:2 * n])
        tangent = step * stuck
        g_slope = stribeck_slope(step_velocity, coulomb_force, static_force, velocity_scale,
                                 exponent, shape)
        if g_slope != 0.0:
            tangent += g_slope * (slope_a - decay_rate / g * slope_b)
    return total + scalars[VISCOUS] * sample_velocity, tangent + scalars[VISCOUS], written


@jit
def gms_trial_step(scalars, table, state, out, keep, step, displacement, step_velocity,
                   sample_velocity, normal_load):
    """The read-only trial of GMS (:func:`polind.kernels.contract.no_trial`)."""
    n = table.shape[1]
    return gms_trial_scaled(computed_decay, inverse_row, scalars, table, state[:n],
                            state[n:2 * n], out, keep, step, displacement, step_velocity,
                            sample_velocity, scalars[COULOMB], scalars[STATIC])
