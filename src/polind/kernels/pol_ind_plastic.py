"""The Pol-Ind step of a model with elastic-plastic asperities (a hardness).

The step of :mod:`polind.kernels.pol_ind` with another *capacities
function* (:func:`plastic_capacities`): when the normal load changes, the
separation is solved on the elastic-plastic surface
(:func:`polind.kernels.plastic_separation.plastic_newton`, warm-started from
the previous sample) and the element rows are re-evaluated with
``k_j = n_j 8 G* a(delta_j)``, ``W_j = n_j mu_s P(delta_j)``
(:func:`polind.kernels.plastic.plastic_element_properties`); everything else
(the weights, the resets and clips, the GMS update) is the Hertzian step's
own code (:ref:`guide-pol-ind-plasticity`), and a ball's nominal area
follows the load as there (:func:`polind.kernels.pol_ind.area_ratio`: the
surface solved at ``N / r``, the rows times ``r``).  A model without a hardness never
runs these functions.

Arrays
------
``scalars``: the slots of :mod:`polind.kernels.pol_ind` (its
:data:`~polind.kernels.pol_ind.N_SCALARS`), then the surface vector of
:mod:`polind.kernels.plastic_separation` from :data:`PLASTIC_SURFACE` on.
``table``: the rows of :mod:`polind.kernels.pol_ind`, then each element's
asperity count ``n_j`` (:data:`ELEMENT_ASPERITIES`) and summit radius ``R_j``
(:data:`ELEMENT_RADIUS`).  ``state``: as :mod:`polind.kernels.pol_ind` (the
element counts there are the Hertz weights ``n_j sqrt(R_j / R)``).
"""

from __future__ import annotations

from polind.kernels import jit
from polind.kernels.elements import ELEMENT_STIFFNESS
from polind.kernels.plastic import plastic_element_properties
from polind.kernels.plastic_separation import (CRITICAL_FACTOR, KIND, PLASTIC_SCALE, SIZE,
                                               YIELD_COEFFICIENT, plastic_iteration,
                                               plastic_lower, plastic_newton)
from polind.kernels.pol_ind import (E_STAR, ELEMENT_SCRATCH, G_STAR, LOAD_SLOPE, LOAD_VALUE,
                                    LOWER, N_ROWS, N_SCALARS, RADIUS, SEPARATION,
                                    STATIC_COEFFICIENT, UPPER, area_ratio, force_with,
                                    load_from_rows, load_step_with, pol_ind_tangent,
                                    pol_ind_trial_step, row_load_scales, set_load_with,
                                    settled_step_with, step_with)
from polind.kernels.separation import DIRECT, predicted_start

__all__ = ["PLASTIC_SURFACE", "N_PLASTIC_SCALARS", "ELEMENT_ASPERITIES", "ELEMENT_RADIUS",
           "N_PLASTIC_ROWS", "plastic_capacities", "plastic_step", "plastic_force", "plastic_path",
           "plastic_motion", "plastic_integrate", "plastic_body"]

#: The scalars' slot where the surface vector of :mod:`polind.kernels.plastic_separation` starts.
PLASTIC_SURFACE = N_SCALARS
N_PLASTIC_SCALARS = N_SCALARS + SIZE

#: The table's row of asperity counts ``n_j``.
ELEMENT_ASPERITIES = N_ROWS
#: The table's row of summit radii ``R_j`` [m].
ELEMENT_RADIUS = N_ROWS + 1
N_PLASTIC_ROWS = N_ROWS + 2


@jit
def plastic_capacities(scalars, table, state, normal_load):
    """Solve the elastic-plastic separation, fill the stiffness and capacity rows; return ``d``.

    The capacities function of the elastic-plastic step (compiled apart:
    the Newton iteration on a quadrature or a sum with jumps is no place for
    inlining).  Bracket: the statistical surface's range, or for a direct
    one the highest element alone carrying the load; start: the Newton step
    predicted from the previous solution.  With a ball the surface of the
    table load is solved at ``N / r`` and the rows are ``r`` times its own
    (:func:`polind.kernels.pol_ind.statistical_capacities`; ``G*`` and ``mu_s``
    scaled, the rows being linear in both).
    """
    ratio, load = area_ratio(scalars, normal_load)
    n = table.shape[1]
    heights = state[2 * n:3 * n]
    weights = state[3 * n:4 * n]
    counts = table[ELEMENT_ASPERITIES]
    radii = table[ELEMENT_RADIUS]
    surface = scalars[PLASTIC_SURFACE:PLASTIC_SURFACE + SIZE]
    lower = plastic_lower(load, scalars[LOWER], surface, heights, counts, radii)
    start = predicted_start(scalars[SEPARATION], scalars[LOAD_VALUE], scalars[LOAD_SLOPE], load)
    if surface[KIND] == DIRECT:
        # As the Hertzian step (polind.kernels.pol_ind.direct_capacities): each Newton
        # evaluation fills the rows and sums them.  A summit beyond yield carries W_j / mu_s
        # as well; its k_j gives the slope only roughly, which the safeguarded iteration
        # takes (the load, not the slope, decides where it stops).
        load_per_capacity, slope_per_stiffness = row_load_scales(scalars, ratio)
        evaluation = (scalars, table, heights, weights, counts, radii, surface, ratio,
                      load_per_capacity, slope_per_stiffness)
        separation, value, slope, _, last = plastic_iteration(
            plastic_rows_surface, load, start, lower, scalars[UPPER], surface, evaluation)
        if last != separation:
            plastic_rows_surface(separation, evaluation)
    else:
        separation, value, slope, _ = plastic_newton(load, start, lower, scalars[UPPER], surface,
                                                     heights, weights, counts, radii)
        plastic_rows(scalars, table, heights, weights, counts, radii, surface, ratio, separation)
    scalars[LOAD_VALUE] = value
    scalars[LOAD_SLOPE] = slope
    return separation


@jit(inline="always")
def plastic_rows(scalars, table, heights, weights, counts, radii, surface, ratio, separation):
    """The stiffness and capacity rows at ``separation`` (:func:`polind.kernels.plastic.plastic_element_properties`)."""
    plastic_element_properties(heights, weights, counts, radii, separation, scalars[RADIUS],
                               scalars[E_STAR], scalars[G_STAR] * ratio,
                               scalars[STATIC_COEFFICIENT] * ratio,
                               surface[CRITICAL_FACTOR], surface[PLASTIC_SCALE],
                               surface[YIELD_COEFFICIENT], table[ELEMENT_STIFFNESS],
                               table[ELEMENT_SCRATCH])


@jit(inline="always")
def plastic_rows_surface(d, evaluation):
    """``(N(d), dN/dd)`` of a direct elastic-plastic surface from its rows at ``d``, which it fills.

    :func:`polind.kernels.pol_ind.direct_rows_surface` with the
    elastic-plastic rows (:func:`plastic_rows`).
    """
    (scalars, table, heights, weights, counts, radii, surface, ratio, load_per_capacity,
     slope_per_stiffness) = evaluation
    plastic_rows(scalars, table, heights, weights, counts, radii, surface, ratio, d)
    return load_from_rows(table, load_per_capacity, slope_per_stiffness)


@jit
def plastic_set_load(scalars, table, state, normal_load):
    """:func:`polind.kernels.pol_ind.set_load_with` :func:`plastic_capacities` (compiled apart)."""
    set_load_with(plastic_capacities, scalars, table, state, normal_load)


@jit
def plastic_load_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                      normal_load):
    """:func:`polind.kernels.pol_ind.load_step_with` :func:`plastic_capacities` (compiled apart)."""
    return load_step_with(plastic_capacities, scalars, table, state, step, displacement,
                          step_velocity, sample_velocity, normal_load)


@jit
def plastic_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                 normal_load):
    """The Pol-Ind step (:func:`polind.kernels.pol_ind.pol_ind_step`) with elastic-plastic asperities."""
    return step_with(plastic_load_step, plastic_set_load, scalars, table, state, step, displacement,
                     step_velocity, sample_velocity, normal_load)


@jit
def plastic_settled_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                         normal_load):
    """:func:`polind.kernels.pol_ind.settled_step` with elastic-plastic asperities."""
    return settled_step_with(plastic_set_load, scalars, table, state, step, displacement,
                             step_velocity, sample_velocity, normal_load)


@jit
def plastic_force(scalars, table, state, sample_velocity, normal_load):
    return force_with(plastic_set_load, scalars, table, state, sample_velocity, normal_load)
