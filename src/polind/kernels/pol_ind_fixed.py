"""The Pol-Ind step of a run that stays at the load its element table was built for.

At its own constant load Pol-Ind is the GMS model of its element table
(:ref:`guide-pol-ind-law`): these functions step that table with the arrays
of :mod:`polind.kernels.pol_ind` and compile neither its separation solver
nor the table's update at a new load (a Pol-Ind model gives them for such a
run: ``fixed_load_step_functions``).  :func:`fixed_load_step` is the step of
the implicit solvers (the body, the series spring), with the decay rows that
their trials share (:func:`polind.kernels.pol_ind.decay_row`);
:func:`fixed_load_path_step` the step of a prescribed path, which computes
each factor in its loop.  The forces are :func:`polind.kernels.pol_ind.pol_ind_step`'s
at that load, to the bit.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.elements import (ELEMENT_STIFFNESS, VISCOUS, computed_decay, element_sum,
                                     given_decay, gms_step_scaled, inverse_row)
from polind.kernels.pol_ind import (CURRENT_LOAD, KINETIC_COEFFICIENT, STATIC_COEFFICIENT,
                                    TABLE_STALE, decay_row, refresh_shares)
# The tangent and the read-only trial of a fixed-load run are the Hertzian step's own; the
# runner module generated for this one (polind.kernels.generate) binds them from here.
from polind.kernels.pol_ind import pol_ind_tangent, pol_ind_trial_step  # noqa: F401


@jit(inline="always")
def load_unchanged(scalars, table, state, normal_load):
    """The set-load function of a run that never leaves the table's load: nothing to bring.

    Reached only if a caller broke that promise (a load other than
    ``scalars[CURRENT_LOAD]``): the stiffness row becomes NaN, so the run
    reports a non-finite force instead of stepping with the wrong table.
    """
    stiffness = table[ELEMENT_STIFFNESS]
    for j in range(stiffness.shape[0]):
        stiffness[j] = math.nan


@jit
def fixed_load_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                    normal_load):
    """The step of a run at the table's own constant load (:ref:`guide-pol-ind-law`).

    :func:`~polind.kernels.pol_ind.settled_step` without a load path (:func:`~polind.kernels.pol_ind.load_step`,
    :func:`~polind.kernels.pol_ind.set_load` neither needed nor compiled: less than half the
    compilation of a cold process); stale weights (:data:`~polind.kernels.pol_ind.TABLE_STALE`) are
    still brought up to date.  :func:`~polind.kernels.pol_ind.pol_ind_step`'s forces at that load,
    bit for bit, for the Hertzian and the elastic-plastic arrays alike.  The
    decay factors come from :func:`~polind.kernels.pol_ind.decay_row`, which keeps them for the
    implicit solvers' trials (:func:`fixed_load_path_step` computes them in
    the loop).
    """
    # pol_ind.settled_step_with(load_unchanged, ...) written out: numba copies an inlined
    # function's whole expanded body at each level it is inlined through, and this level
    # cost a quarter of the step's compilation.
    if normal_load != scalars[CURRENT_LOAD]:
        load_unchanged(scalars, table, state, normal_load)
    elif scalars[TABLE_STALE] != 0.0:
        refresh_shares(scalars, table)
    n = table.shape[1]
    return gms_step_scaled(given_decay, decay_row, scalars, table, state[:n], state[n:2 * n],
                           step, displacement, step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit
def fixed_load_path_step(scalars, table, state, step, displacement, step_velocity,
                         sample_velocity, normal_load):
    """:func:`fixed_load_step` for a prescribed path: each decay factor computed in the loop.

    A prescribed path steps each sample once, so the rows :func:`~polind.kernels.pol_ind.decay_row`
    keeps for the solvers' trials save nothing there; the GMS model's own
    :func:`~polind.kernels.elements.computed_decay` gives the same factors,
    to the bit, without the row's pass and its checks.  The runners of a
    path call it only with the arrays of a fixed-load kernel, fresh from
    ``kernel_arrays`` at the table's load, and that load: a table that is
    stale or at another load (a caller that broke that promise) gives a NaN
    force and no step, instead of :func:`fixed_load_step`'s upkeep
    (:func:`load_unchanged`, :func:`~polind.kernels.pol_ind.refresh_shares`),
    whose loops cost a cold process a third of a second of compilation.
    """
    if normal_load != scalars[CURRENT_LOAD] or scalars[TABLE_STALE] != 0.0:
        return math.nan
    n = table.shape[1]
    return gms_step_scaled(computed_decay, inverse_row, scalars, table, state[:n],
                           state[n:2 * n], step, displacement, step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit
def fixed_load_force(scalars, table, state, sample_velocity, normal_load):
    """``pol_ind_force`` of a run at the table's own constant load (see :func:`fixed_load_step`).

    ``polind.kernels.elements.gms_force`` written out, not called: a fixed-load
    run compiles no other function that calls it, and its own compilation cost a
    quarter of a second.
    """
    if normal_load != scalars[CURRENT_LOAD]:
        load_unchanged(scalars, table, state, normal_load)
    return element_sum(state[:table.shape[1]]) + scalars[VISCOUS] * sample_velocity
