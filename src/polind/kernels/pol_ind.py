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
stuck from zero force (:ref:`guide-pol-ind-varying-load`).  An element is
in contact while its height is above the separation (``delta_j > 0``).

A step that changes the load *and* moves (:func:`load_step`) does all of
that in one pass over the elements with the GMS update (after a pass for
the decay factors): the shares ``alpha_j`` and ``1/alpha_j`` are computed
in the loops from the capacities ``W_j`` and not stored, and the scalar
:data:`TABLE_STALE` says that the table's share rows lag its capacities row
until a step at an unchanged load brings them up to date
(:func:`refresh_shares`).  The forces are those of
:func:`set_load` followed by the GMS step, to rounding.

A ball on a flat (:ref:`guide-measured-surfaces-ball`) makes the nominal
area follow the load, ``A0 = pi (3 N R_b / (4 E*))^(2/3)``.  Everything
that scales with ``A0`` is linear in it (the statistical load scale, the
element counts ``n_j``, a measured map's summit weights), so with
``r = A0(N) / A0(N_t) = (N / N_t)^(2/3)``, ``N_t`` the load the table was
built at (:data:`BALL_LOAD`), the separation at ``N`` is the one that solves
``N_t``'s surface at ``N / r`` and every element row is ``r`` times that
surface's row (:func:`area_ratio`, :func:`statistical_capacities`).  Without a ball
``r`` is exactly 1 and nothing changes, to the bit.

The separation and the element rows at a new load come from a *capacities
function* (:func:`surface_capacities` and its two kinds); the functions
named ``..._with`` take one as their first argument, so that the
elastic-plastic step (:mod:`polind.kernels.pol_ind_plastic`) is this step
with its own, and the Hertzian step compiles to what it was.

Arrays
------
``scalars``: the GMS slots of :mod:`polind.kernels.elements` (0-6) and the
slots below; the ones marked *work* change as the model steps.
``table`` rows: the GMS rows (stiffness, weight, 1/weight), a row of
capacities (the ``W_j`` at the current load) and three work rows: two rows
of the elements' decay factors and the weights they were computed from
(:func:`decay_row`).  ``state``: element forces, slip directions, element
heights, element counts (``n`` each) and the load the table was built for.

The decay factors
-----------------
``exp(-C h / (alpha_j g))`` per slipping element, most of a step's cost: the
steps and the read-only trial keep the last two rows (:func:`decay_row`), the
same numbers to the bit (a moving :class:`polind.Body` step of the default
model took about 40 % less time).
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.elements import (ATTRACTION, ELEMENT_CAPACITY, ELEMENT_INVERSE,
                                     ELEMENT_STIFFNESS, STRIBECK_EXPONENT, STRIBECK_SHAPE,
                                     STRIBECK_VELOCITY, VISCOUS, decay_factors,
                                     element_properties, element_sum, given_decay,
                                     gms_decayed_element, gms_force, gms_step_scaled,
                                     gms_trial_scaled, stuck_stiffness)
from polind.kernels.fastexp import decay_exp
from polind.kernels.separation import (DIRECT, RELATIVE_TOLERANCE, direct_lower_bound,
                                       newton_iteration, predicted_start,
                                       statistical_separation_only)
from polind.kernels.special import IVE, KVE
from polind.kernels.stribeck import sign, stribeck_curve

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
#: Scalar slot (work): 1 while the weight rows lag the capacities (:func:`load_step`).
TABLE_STALE = 24
#: Scalar slot: a ball on a flat's table load ``N_t`` [N] (its nominal area follows the
#: load, :func:`area_ratio`); 0 without a ball.
BALL_LOAD = 25
#: Scalar slots (work): the ``-C h`` and the ``g`` each of the table's two :data:`DECAY`
#: rows was computed for (at ``DECAY_KEYS + 2 e`` and ``+ 2 e + 1``), and the row used
#: last (:func:`decay_row`).
DECAY_KEYS = 26
DECAY_NEWEST = 30
#: Scalar slots of the Hertzian step.
N_SCALARS = 31

ELEMENT_SCRATCH = 3       # table row of capacities W_j [N] at the current load
#: Two table rows (work): decay factors ``exp(-C h / (alpha_j g))`` (:func:`decay_row`).
DECAY = 4
#: Table row (work): the ``1/alpha_j`` the :data:`DECAY` rows were computed from.
DECAY_INVERSE = 6
N_ROWS = 7


@jit(inline="always")
def area_ratio(scalars, normal_load):
    """``(r, N / r)`` of a ball on a flat, ``r = A0(N) / A0(N_t) = (N / N_t)^(2/3)``; or ``(1, N)``.

    The nominal area of a ball's Hertz contact is ``pi (3 N R_b / (4 E*))^(2/3)``
    (:ref:`guide-measured-surfaces-ball`); ``N_t`` is :data:`BALL_LOAD`, the
    load the table (and the surface in the scalars) was built at, and
    ``N / r`` the load to solve that surface at.  Without a ball ``N`` is
    passed on untouched: no division on the way to the separation.
    """
    table_load = scalars[BALL_LOAD]
    if table_load == 0.0:
        return 1.0, normal_load
    ratio = (normal_load / table_load) ** (2.0 / 3.0)
    return ratio, normal_load / ratio


@jit(inline="always")
def statistical_capacities(scalars, table, state, normal_load):
    """Solve a statistical surface's separation and evaluate the stiffness and capacity rows there.

    Returns ``d``.  The separation is
    :func:`polind.kernels.separation.statistical_separation_only` (the
    inverse of its fast ``N(d)``, no array passed; a direct surface has
    :func:`direct_capacities`).  Stores nothing else: the caller updates the
    weights and the elements.  With a ball (:func:`area_ratio` ``r``) the
    surface of the scalars, built at the table load, is solved at ``N / r``
    and the rows are ``r`` times its rows: ``r`` scales ``G*`` for the
    stiffnesses and ``mu_s`` for the capacities, both linear in them (without
    a ball both products are by exactly 1 and the load is solved as given).
    ``N(d)`` and its slope serve only a direct surface's next start: NaN here.
    """
    n = table.shape[1]
    heights = state[2 * n:3 * n]
    counts = state[3 * n:4 * n]
    ratio, load = area_ratio(scalars, normal_load)
    separation = statistical_separation_only(
        load, scalars[LOWER], scalars[UPPER], scalars[LOAD_SCALE], scalars[HEIGHT_STD],
        scalars[ADDRESSES + KVE], scalars[ADDRESSES + IVE])
    element_properties(heights, counts, separation, scalars[RADIUS], scalars[E_STAR],
                       scalars[G_STAR] * ratio, scalars[STATIC_COEFFICIENT] * ratio,
                       table[ELEMENT_STIFFNESS], table[ELEMENT_SCRATCH])
    scalars[LOAD_VALUE] = math.nan
    scalars[LOAD_SLOPE] = math.nan
    return separation


@jit(inline="always")
def row_load_scales(scalars, ratio):
    """``N`` per ``sum W_j`` (``mu_s`` times the load), ``dN/dd`` per ``sum k_j`` (``~ delta^(1/2)``)."""
    sqrt_radius = math.sqrt(scalars[RADIUS])
    stiffness_scale = 8.0 * (scalars[G_STAR] * ratio) * sqrt_radius
    capacity_scale = (scalars[STATIC_COEFFICIENT] * ratio) * (4.0 / 3.0) * scalars[E_STAR] * \
        sqrt_radius
    return scalars[HERTZ] / capacity_scale, -1.5 * scalars[HERTZ] / stiffness_scale


@jit(inline="always")
def load_from_rows(table, load_per_capacity, slope_per_stiffness):
    """``(N(d), dN/dd)`` from the element rows at ``d`` (:func:`row_load_scales`)."""
    return (load_per_capacity * element_sum(table[ELEMENT_SCRATCH]),
            slope_per_stiffness * element_sum(table[ELEMENT_STIFFNESS]))


@jit(inline="always")
def direct_rows_surface(d, evaluation):
    """``(N(d), dN/dd)`` of a direct surface from its rows at ``d``, which it fills."""
    scalars, table, heights, counts, ratio, load_per_capacity, slope_per_stiffness = evaluation
    element_properties(heights, counts, d, scalars[RADIUS], scalars[E_STAR],
                       scalars[G_STAR] * ratio, scalars[STATIC_COEFFICIENT] * ratio,
                       table[ELEMENT_STIFFNESS], table[ELEMENT_SCRATCH])
    return load_from_rows(table, load_per_capacity, slope_per_stiffness)


@jit(inline="always")
def direct_capacities(scalars, table, state, normal_load):
    """:func:`statistical_capacities` of a direct surface: each Newton evaluation fills the rows.

    The elements are the summits, so the evaluation of ``N(d)`` is the pass
    over the rows (:func:`direct_rows_surface`), vectorised: 2.7 µs against
    4.0 µs per load on a 1,014-summit map; ``d`` moves by rounding (another
    summation order).  The elastic-plastic step does the same (within yield: this)."""
    n = table.shape[1]
    ratio, load = area_ratio(scalars, normal_load)
    evaluation = (scalars, table, state[2 * n:3 * n], state[3 * n:4 * n], ratio) + \
        row_load_scales(scalars, ratio)
    separation, value, slope, _, last = newton_iteration(
        direct_rows_surface, RELATIVE_TOLERANCE, load,
        predicted_start(scalars[SEPARATION], scalars[LOAD_VALUE], scalars[LOAD_SLOPE], load),
        direct_lower_bound(load, state[2 * n:3 * n], state[3 * n:4 * n], scalars[HERTZ]),
        scalars[UPPER], evaluation)
    if last != separation:      # an earlier d was better (the bracket down to adjacent doubles)
        direct_rows_surface(separation, evaluation)
    scalars[LOAD_VALUE] = value
    scalars[LOAD_SLOPE] = slope
    return separation


@jit(inline="always")
def surface_capacities(scalars, table, state, normal_load):
    """:func:`statistical_capacities` or :func:`direct_capacities`, by the model's surface.

    The *capacities function* of the Hertzian step: given the load, it
    solves the separation, fills the stiffness and capacity rows and returns
    ``d``.  An elastic-plastic model passes its own
    (:func:`polind.kernels.pol_ind_plastic.plastic_capacities`) to the
    functions below that take one.
    """
    if scalars[SURFACE_KIND] == DIRECT:
        return direct_capacities(scalars, table, state, normal_load)
    return statistical_capacities(scalars, table, state, normal_load)


@jit(inline="always")
def share_rows(table):
    """Weights ``alpha_j = W_j (1 / sum W)`` and ``1 / alpha_j = sum W / W_j`` from the capacities.

    Two loops that each write one array, so that LLVM vectorises both; out
    of contact (``W = 0``) ``1/alpha = inf``: such an element never relaxes.
    """
    breakaway = table[ELEMENT_SCRATCH]
    weight = table[ELEMENT_CAPACITY]
    inverse_weight = table[ELEMENT_INVERSE]
    total = element_sum(breakaway)
    reciprocal = 1.0 / total
    for j in range(breakaway.shape[0]):
        weight[j] = breakaway[j] * reciprocal
    for j in range(breakaway.shape[0]):
        capacity = breakaway[j]
        inverse_weight[j] = total / capacity if capacity > 0.0 else math.inf


@jit(inline="always")
def refresh_shares(scalars, table):
    """Bring the weight rows up to the capacities row after :func:`load_step`."""
    share_rows(table)
    scalars[TABLE_STALE] = 0.0


@jit(inline="always")
def set_load(scalars, table, state, normal_load):
    """Re-evaluate the element table at a new normal load [N] (:ref:`guide-pol-ind-varying-load`).

    :func:`set_load_with` the Hertzian :func:`surface_capacities`.
    """
    set_load_with(surface_capacities, scalars, table, state, normal_load)


@jit(inline="always")
def element_at_load(force, slip, height, previous_separation, limit):
    """One element brought to a new load: ``(force, slip direction)``.

    Out of contact before (its height not above the previous separation) or
    now (its new capacity ``limit = alpha_j mu_s N`` is 0), it starts stuck
    (slip direction 0; as a product: a select here stops the vectoriser);
    its force is clipped to ``[-limit, limit]`` (0 out of contact).  The one
    rule of :func:`set_load_with` and :func:`fresh_elements`.
    """
    slip = slip * (1.0 if (height > previous_separation) & (limit > 0.0) else 0.0)
    return min(max(force, -limit), limit), slip


@jit(inline="always")
def set_load_with(capacities, scalars, table, state, normal_load):
    """Re-evaluate the element table at a new normal load [N] with a capacities function.

    The separation and the element stiffnesses and capacities
    (``capacities``, e.g. :func:`surface_capacities`); then one pass over
    the elements that writes the weights as :func:`share_rows` computes them
    and brings each element to the load (:func:`element_at_load`).  One
    pass instead of three (the two of :func:`share_rows`, then the
    elements'): measured on a 1,014-element measured map, 1.5 µs against
    2.2 µs per load, the same values.
    """
    n = table.shape[1]
    heights = state[2 * n:3 * n]
    previous_separation = scalars[SEPARATION]
    separation = capacities(scalars, table, state, normal_load)
    breakaway = table[ELEMENT_SCRATCH]
    weight = table[ELEMENT_CAPACITY]
    inverse_weight = table[ELEMENT_INVERSE]
    total = element_sum(breakaway)
    reciprocal = 1.0 / total
    capacity_scale = scalars[STATIC_COEFFICIENT] * normal_load
    element_force = state[:n]
    slip_direction = state[n:2 * n]
    for j in range(n):
        capacity = breakaway[j]
        alpha = capacity * reciprocal
        weight[j] = alpha
        inverse_weight[j] = total / capacity if capacity > 0.0 else math.inf
        element_force[j], slip_direction[j] = element_at_load(
            element_force[j], slip_direction[j], heights[j], previous_separation,
            alpha * capacity_scale)
    scalars[CURRENT_LOAD] = normal_load
    scalars[SEPARATION] = separation
    scalars[TABLE_STALE] = 0.0


@jit
def set_load_apart(scalars, table, state, normal_load):
    """:func:`set_load`, compiled apart: a step keeps only its moving path inline (:func:`load_step`)."""
    set_load(scalars, table, state, normal_load)


@jit(inline="always")
def fresh_elements(element_force, slip_direction, stiffness, breakaway, heights,
                   previous_separation, total, reciprocal, static_force, capacity_scale,
                   direction, displacement, decay_rate, factors):
    """:func:`set_load`'s element updates and :func:`polind.kernels.elements.gms_elements`, fused.

    The weights come from the capacities ``W_j`` in the loop
    (``alpha_j = W_j / sum W``, ``1/alpha_j = sum W / W_j``) instead of
    from the table's rows, which this loop does not write.  Two passes:
    the decay factors into ``factors``
    (:func:`polind.kernels.elements.decay_factors` of those ``1/alpha_j``),
    then the resets, clips and the GMS update with them; each pass writes
    at most two arrays, so LLVM vectorises both, and two plain loops ran
    faster than one with the exponential inside.  ``static_force`` is
    ``mu_s N``, ``capacity_scale`` ``g(v)``; the rest as in
    ``gms_elements``.  Returns the sum of the element forces.
    """
    for i in range(element_force.shape[0]):
        breakaway_force = breakaway[i]
        inverse = total / breakaway_force if breakaway_force > 0.0 else math.inf
        factors[i] = decay_exp(decay_rate * inverse)
    result = 0.0
    for i in range(element_force.shape[0]):
        alpha = breakaway[i] * reciprocal
        limit = alpha * static_force
        force, slip = element_at_load(element_force[i], slip_direction[i], heights[i],
                                      previous_separation, limit)
        force, slip = gms_decayed_element(force, slip, stiffness[i], alpha, capacity_scale,
                                          direction, displacement, factors[i])
        element_force[i] = force
        slip_direction[i] = slip
        result += force
    return result


@jit(inline="always")
def forget_decay_rows(scalars):
    """Mark both :data:`DECAY` rows as holding no kept factors (:func:`decay_row`)."""
    for key in range(DECAY_KEYS, DECAY_KEYS + 4):
        scalars[key] = math.nan


@jit(inline="always")
def load_step_with(capacities, scalars, table, state, step, displacement, step_velocity,
                   sample_velocity, normal_load):
    """A moving step at a new normal load: :func:`set_load` and the GMS step, fused.

    The separation and the capacities (``capacities``, e.g.
    :func:`statistical_capacities`) as :func:`set_load` computes them, then
    the elements (:func:`fresh_elements`, its decay factors into a
    :data:`DECAY` row, which then holds no kept factors); the weight rows are
    left stale (:data:`TABLE_STALE`).
    """
    n = table.shape[1]
    previous_separation = scalars[SEPARATION]
    separation = capacities(scalars, table, state, normal_load)
    breakaway = table[ELEMENT_SCRATCH]
    total = element_sum(breakaway)
    reciprocal = 1.0 / total
    static_force = scalars[STATIC_COEFFICIENT] * normal_load
    g = stribeck_curve(step_velocity, scalars[KINETIC_COEFFICIENT] * normal_load, static_force,
                       scalars[STRIBECK_VELOCITY], scalars[STRIBECK_EXPONENT],
                       scalars[STRIBECK_SHAPE])
    # The factors go to a decay row, which then holds no kept factors (decay_row).
    forget_decay_rows(scalars)
    total_force = fresh_elements(state[:n], state[n:2 * n], table[ELEMENT_STIFFNESS], breakaway,
                                 state[2 * n:3 * n], previous_separation, total, reciprocal,
                                 static_force, g, sign(step_velocity), displacement,
                                 -scalars[ATTRACTION] * step / g, table[DECAY])
    scalars[CURRENT_LOAD] = normal_load
    scalars[SEPARATION] = separation
    scalars[TABLE_STALE] = 1.0
    return total_force + scalars[VISCOUS] * sample_velocity


@jit
def direct_load_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                     normal_load):
    """:func:`load_step_with` for a direct surface (compiled apart, see :func:`load_step`)."""
    return load_step_with(direct_capacities, scalars, table, state, step, displacement,
                          step_velocity, sample_velocity, normal_load)


@jit
def statistical_load_step(scalars, table, state, step, displacement, step_velocity,
                          sample_velocity, normal_load):
    """:func:`load_step_with` for a statistical surface (compiled apart, see :func:`load_step`)."""
    return load_step_with(statistical_capacities, scalars, table, state, step, displacement,
                          step_velocity, sample_velocity, normal_load)


@jit(inline="always")
def load_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
              normal_load):
    """:func:`load_step_with` for the model's surface.

    Each kind's step is a function of its own, compiled apart: with the
    two kinds merged after the separation, the statistical step cost about
    25 ns more (measured with the default 64 elements, about 200 ns against
    225), and inlined into :func:`pol_ind_step` the two made it the longest
    compile of a cold process.
    """
    if scalars[SURFACE_KIND] == DIRECT:
        return direct_load_step(scalars, table, state, step, displacement, step_velocity,
                                sample_velocity, normal_load)
    return statistical_load_step(scalars, table, state, step, displacement, step_velocity,
                                 sample_velocity, normal_load)


@jit
def pol_ind_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                 normal_load):
    """The GMS law with ``g(v) = N [mu_k + (mu_s - mu_k) shape(v)]`` (:ref:`guide-pol-ind-law`).

    A moving step at a new load is :func:`load_step` (fused); the rest is
    :func:`settled_step`.
    """
    return step_with(load_step, set_load_apart, scalars, table, state, step, displacement,
                     step_velocity, sample_velocity, normal_load)


@jit(inline="always")
def step_with(load_step_function, set_load_function, scalars, table, state, step, displacement,
              step_velocity, sample_velocity, normal_load):
    """:func:`pol_ind_step` with its load step and its set-load function given.

    The Hertzian step passes :func:`load_step` and :func:`set_load_apart`;
    an elastic-plastic one its own (:mod:`polind.kernels.pol_ind_plastic`).
    """
    if normal_load != scalars[CURRENT_LOAD] and step_velocity != 0.0:
        return load_step_function(scalars, table, state, step, displacement, step_velocity,
                                  sample_velocity, normal_load)
    return settled_step_with(set_load_function, scalars, table, state, step, displacement,
                             step_velocity, sample_velocity, normal_load)


@jit
def decay_row(scalars, table, step, g):
    """A row of decay factors ``exp(-C h / (alpha_j g))`` for a step ``h`` [s] at ``g`` [N].

    Computed (:func:`polind.kernels.elements.decay_factors`) into one of the
    table's two :data:`DECAY` rows, and kept there with what it was computed
    from (``-C h`` and ``g`` in the scalars, the ``1/alpha_j`` row in the
    table); a step with the same three takes the kept row instead of
    computing the exponentials again.  The body's implicit solve steps the
    elements at several velocities per sample (its trials, then the commit),
    and above a few Stribeck velocities ``g`` is ``mu_k N`` to the bit: one
    row then serves every trial and the commit, and the next samples too.
    Two rows, because a constant time step ``h`` is not one number: the
    steps between sample times ``t_0 + n h`` rounded to doubles take two
    values within each binade of ``t`` (the one less recently used is
    replaced).  A row is a function of those inputs only, checked in full
    (the whole ``1/alpha_j`` row), so the forces are the same as computing
    the factors every time, to the bit, whatever changed the table in
    between.  Compiled apart: one function for the steps and the trials
    that call it.
    """
    numerator = -scalars[ATTRACTION] * step
    inverse_weight = table[ELEMENT_INVERSE]
    kept = table[DECAY_INVERSE]
    changed = 0
    for j in range(kept.shape[0]):
        changed += 0 if kept[j] == inverse_weight[j] else 1
    if changed == 0:
        for entry in range(2):
            key = DECAY_KEYS + 2 * entry
            if numerator == scalars[key] and g == scalars[key + 1]:
                scalars[DECAY_NEWEST] = entry
                return table[DECAY + entry]
        entry = 1 - int(scalars[DECAY_NEWEST])     # the one used less recently
    else:
        # New weights: neither row holds their factors.
        for j in range(kept.shape[0]):
            kept[j] = inverse_weight[j]
        forget_decay_rows(scalars)
        entry = 0
    factors = table[DECAY + entry]
    decay_factors(inverse_weight, numerator / g, factors)
    scalars[DECAY_KEYS + 2 * entry] = numerator
    scalars[DECAY_KEYS + 2 * entry + 1] = g
    scalars[DECAY_NEWEST] = entry
    return factors


@jit
def settled_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                 normal_load):
    """The table brought to the load first (:func:`set_load_apart`, or the stale weights), then the GMS step.

    Also the whole step of the one-degree-of-freedom templates
    (the runners ``integrate`` and ``body`` of :mod:`polind.kernels.template`), which call it at two
    places (trial and commit) and see a new load only at the first trial of
    a sample: inlining :func:`load_step` there twice costs seconds of
    compilation and saves nothing.  Its forces are :func:`load_step`'s to
    rounding.
    """
    return settled_step_with(set_load_apart, scalars, table, state, step, displacement,
                             step_velocity, sample_velocity, normal_load)


@jit(inline="always")
def settled_step_with(set_load_function, scalars, table, state, step, displacement,
                      step_velocity, sample_velocity, normal_load):
    """:func:`settled_step` with the function that brings the table to a new load given."""
    if normal_load != scalars[CURRENT_LOAD]:
        set_load_function(scalars, table, state, normal_load)
    elif scalars[TABLE_STALE] != 0.0:
        refresh_shares(scalars, table)
    n = table.shape[1]
    return gms_step_scaled(given_decay, decay_row, scalars, table, state[:n], state[n:2 * n],
                           step, displacement, step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit
def pol_ind_force(scalars, table, state, sample_velocity, normal_load):
    return force_with(set_load_apart, scalars, table, state, sample_velocity, normal_load)


@jit(inline="always")
def force_with(set_load_function, scalars, table, state, sample_velocity, normal_load):
    """The force at a state, the table first brought to the load by ``set_load_function``."""
    if normal_load != scalars[CURRENT_LOAD]:
        set_load_function(scalars, table, state, normal_load)
    return gms_force(scalars, table, state, sample_velocity, normal_load)


@jit
def pol_ind_tangent(scalars, table, state, step):
    """``polind.kernels.elements.gms_tangent`` written out (called: a third of a second of
    a cold process, a second compiled function for the one sum)."""
    n = table.shape[1]
    return step * stuck_stiffness(table[ELEMENT_STIFFNESS], state[n:2 * n]) + scalars[VISCOUS]


@jit
def pol_ind_trial_step(scalars, table, state, out, keep, step, displacement, step_velocity,
                       sample_velocity, normal_load):
    """The read-only trial (:func:`polind.kernels.contract.no_trial`) at the table's load.

    At the load the table was last brought to, the step is the GMS step of
    the table (:func:`settled_step_with`): ``(F, dF/dw, written)`` from
    :func:`polind.kernels.elements.gms_trial_scaled` (the new element
    forces and slip directions in ``out``, to be taken with ``keep``), after the weight
    rows are brought up to date if a step left them stale, as the step would
    (the writes, to the table and its decay factors (:func:`decay_row`), are
    the step's own).  At another load
    ``(NaN, NaN, -1)``: the caller steps a copy, as without a trial.
    Serves the Hertzian and the elastic-plastic steps alike (the same
    arrays at the table's load); a fixed-load run has its own, without the
    upkeep (:func:`polind.kernels.pol_ind_fixed.fixed_load_trial_step`).
    """
    if normal_load != scalars[CURRENT_LOAD]:
        return math.nan, math.nan, -1
    if scalars[TABLE_STALE] != 0.0:
        refresh_shares(scalars, table)
    n = table.shape[1]
    return gms_trial_scaled(given_decay, decay_row, scalars, table, state[:n], state[n:2 * n],
                            out, keep, step, displacement, step_velocity, sample_velocity,
                            scalars[KINETIC_COEFFICIENT] * normal_load,
                            scalars[STATIC_COEFFICIENT] * normal_load)
