"""The Pol-Ind step: GMS elements whose table follows the normal load.

The stepping contract of :mod:`polind.kernels.contract` for the Pol-Ind
model.  At a constant normal load the model *is* GMS with its element table
(:ref:`guide-pol-ind-law`), and the step is the GMS step.  When the normal load of a
sample differs from the last one, the separation ``d`` is re-solved for it
inside the kernel (the iterative method of :ref:`guide-pol-ind-separation`: a statistical
surface from the inverse of its load, one evaluation; a direct one
warm-started from the previous ``d``; :mod:`polind.kernels.separation`), the element
stiffnesses and capacities are re-evaluated at the fixed element heights,
the capacities normalised so that ``sum W_j = mu_s N`` exactly
(``alpha_j = W_j / sum W``), an element force beyond its new capacity is
clipped to it, and an element out of contact (or just back in) restarts
stuck from zero force (:ref:`guide-pol-ind-varying-load`).

Arrays
------
``scalars``: the GMS slots of :mod:`polind.kernels.elements` (0-6) and the
slots below; the ones marked *work* change as the load changes.
``table`` rows: the GMS rows (stiffness, weight, 1/weight) and a scratch
row of capacities.  ``state``: element forces, slip directions, element
heights, element counts (``n`` each) and the load the table was built for.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.contract import run_motion, run_steps
from polind.kernels.dynamics import advance_body_template, integrate_system_template
from polind.kernels.elements import (ELEMENT_CAPACITY, ELEMENT_INVERSE, ELEMENT_STIFFNESS,
                                     element_properties, element_sum, gms_step_scaled,
                                     gms_tangent, gms_force)
from polind.kernels.separation import (DIRECT, direct_lower_bound, newton_separation,
                                       predicted_start, statistical_separation_at)
from polind.kernels.special import IVE, KVE

KINETIC_COEFFICIENT = 7   # mu_k
STATIC_COEFFICIENT = 8    # mu_s
RADIUS = 9                # R [m]
E_STAR = 10               # [Pa]
G_STAR = 11               # [Pa]
CURRENT_LOAD = 12         # work: the load [N] the element rows are evaluated at
SEPARATION = 13           # work: d [m] at that load
LOAD_VALUE = 14           # work: N(d) [N] (warm start of the next solve)
LOAD_SLOPE = 15           # work: dN/dd [N/m]
SURFACE_KIND = 16         # polind.kernels.separation STATISTICAL or DIRECT
LOAD_SCALE = 17           # statistical: (4/3) eta A0 E* sqrt(R) sigma^(3/2) [N]
HEIGHT_STD = 18           # statistical: sigma_a [m]
LOWER = 19                # statistical: lowest separation solved for [m]
UPPER = 20                # highest separation solved for [m]
HERTZ = 21                # direct: (4/3) E* sqrt(R)
ADDRESSES = 22            # two slots: polind.kernels.special.special_addresses()
N_SCALARS = 24

ELEMENT_SCRATCH = 3       # table row of capacities W_j during a load update
N_ROWS = 4


@jit(inline="always")
def set_load(scalars, table, state, normal_load):
    """Re-evaluate the element table at a new normal load [N] (:ref:`guide-pol-ind-varying-load`).

    The separation: a statistical surface by
    :func:`polind.kernels.separation.statistical_separation_at` (one
    evaluation of its fast ``N(d)``, no array passed), a direct one by Newton
    from the step predicted by the previous solution.  Then the elements, in
    short loops that each write one array, so that LLVM vectorises every one
    (one loop writing four arrays needs more run-time overlap checks than it
    makes, and stays scalar): slip directions reset where an element is out
    of contact or just back in, shares ``alpha_j = W_j (1 / sum W)`` and
    ``1 / alpha_j = sum W / W_j`` (one division per element: the divider,
    shared with the square roots of
    :func:`polind.kernels.elements.element_properties`, is what an update
    costs), and forces clipped to the new capacities.  About 150 ns for the
    default 64 elements, a third of it the separation.
    """
    n = table.shape[1]
    heights = state[2 * n:3 * n]
    counts = state[3 * n:4 * n]
    if scalars[SURFACE_KIND] == DIRECT:
        lower = direct_lower_bound(normal_load, heights, counts, scalars[HERTZ])
        start = predicted_start(scalars[SEPARATION], scalars[LOAD_VALUE], scalars[LOAD_SLOPE],
                                normal_load)
        separation, value, slope = newton_separation(
            normal_load, start, lower, scalars[UPPER], scalars[SURFACE_KIND], scalars[LOAD_SCALE],
            scalars[HEIGHT_STD], heights, counts, scalars[HERTZ],
            scalars[ADDRESSES:ADDRESSES + 2])
    else:
        separation, value, slope, _ = statistical_separation_at(
            normal_load, scalars[LOWER], scalars[UPPER], scalars[LOAD_SCALE], scalars[HEIGHT_STD],
            scalars[ADDRESSES + KVE], scalars[ADDRESSES + IVE])
    stiffness = table[ELEMENT_STIFFNESS]
    weight = table[ELEMENT_CAPACITY]
    inverse_weight = table[ELEMENT_INVERSE]
    breakaway = table[ELEMENT_SCRATCH]
    static_coefficient = scalars[STATIC_COEFFICIENT]
    element_properties(heights, counts, separation, scalars[RADIUS], scalars[E_STAR],
                       scalars[G_STAR], static_coefficient, stiffness, breakaway)
    total = element_sum(breakaway)
    reciprocal = 1.0 / total
    capacity_scale = static_coefficient * normal_load
    element_force = state[:n]
    slip_direction = state[n:2 * n]
    for j in range(n):
        # Out of contact before (old alpha_j = 0), or now (new capacity 0): it
        # starts stuck, from zero force (the clip below).  (This second use of
        # the reciprocal also keeps LLVM from turning the products by it
        # below back into divisions, which reassociation would allow.)
        keep = (weight[j] > 0.0) & (breakaway[j] * reciprocal * capacity_scale > 0.0)
        slip_direction[j] = slip_direction[j] if keep else 0.0
    for j in range(n):
        weight[j] = breakaway[j] * reciprocal
    for j in range(n):
        # Out of contact (W = 0): 1/alpha = inf, and it never relaxes.
        capacity = breakaway[j]
        inverse_weight[j] = total / capacity if capacity > 0.0 else math.inf
    for j in range(n):
        capacity = weight[j] * capacity_scale
        element_force[j] = min(max(element_force[j], -capacity), capacity)
    scalars[CURRENT_LOAD] = normal_load
    scalars[SEPARATION] = separation
    scalars[LOAD_VALUE] = value
    scalars[LOAD_SLOPE] = slope


@jit(inline="always")
def pol_ind_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                 normal_load):
    """The GMS law with ``g(v) = N [mu_k + (mu_s - mu_k) shape(v)]`` (:ref:`guide-pol-ind-law`)."""
    if normal_load != scalars[CURRENT_LOAD]:
        set_load(scalars, table, state, normal_load)
    n = table.shape[1]
    return gms_step_scaled(scalars, table, state[:n], state[n:2 * n], step, displacement,
                           step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit(inline="always")
def pol_ind_force(scalars, table, state, sample_velocity, normal_load):
    if normal_load != scalars[CURRENT_LOAD]:
        set_load(scalars, table, state, normal_load)
    return gms_force(scalars, table, state, sample_velocity, normal_load)


@jit(inline="always")
def pol_ind_tangent(scalars, table, state, step):
    return gms_tangent(scalars, table, state, step)


@jit
def pol_ind_path(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                 loads, constant_load, lo, hi, first, out_force):
    """:func:`polind.kernels.contract.run_steps` specialised to Pol-Ind."""
    run_steps(pol_ind_step, pol_ind_force, scalars, table, state, step, displacement,
              step_velocity, sample_velocity, loads, constant_load, lo, hi, first, out_force)


@jit
def pol_ind_motion(scalars, table, state, source_t, source_motion, t, motion, by_velocity,
                   start_position, start_velocity, continuing, position, velocity, loads,
                   constant_load, lo, hi, first, out_force):
    """:func:`polind.kernels.contract.run_motion` specialised to Pol-Ind."""
    return run_motion(pol_ind_step, pol_ind_force, scalars, table, state, source_t, source_motion, t,
                      motion, by_velocity, start_position, start_velocity, continuing,
                      position, velocity, loads, constant_load, lo, hi, first, out_force)


@jit
def pol_ind_integrate(arguments):
    """:func:`polind.kernels.dynamics.integrate_system_template` specialised to Pol-Ind (cacheable)."""
    integrate_system_template(pol_ind_step, pol_ind_tangent, arguments)


@jit
def pol_ind_body(arguments):
    """:func:`polind.kernels.dynamics.advance_body_template` specialised to Pol-Ind (cacheable)."""
    advance_body_template(pol_ind_step, pol_ind_tangent, arguments)
