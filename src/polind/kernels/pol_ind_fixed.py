"""The Pol-Ind step of a run that stays at the load its element table was built for.

At its own constant load Pol-Ind is the GMS model of its element table
(:ref:`guide-pol-ind-law`): these functions step that table with the arrays
of :mod:`polind.kernels.pol_ind` and compile neither its separation solver
nor the table's update at a new load (a Pol-Ind model gives them for such a
run: ``fixed_load_step_functions``).  :func:`fixed_load_step` is the step of
the implicit solvers (the body, the series spring), with the decay rows that
their trials share (:func:`polind.kernels.pol_ind.decay_row`);
:func:`fixed_load_path_step` the step of a prescribed path, which computes
each factor in its loop; :func:`fixed_load_trial_step` the solvers' read-only
trial.  The forces are :func:`polind.kernels.pol_ind.pol_ind_step`'s at that
load, to the bit.

The promise
-----------
A fixed-load kernel's arrays come fresh from the model's ``kernel_arrays``
at the table's own load (its weight rows up to date), and every function
here is passed that load: no step of the run changes either.  So none of
them keeps the table up (the load update, the weight rows after one:
:func:`polind.kernels.pol_ind.refresh_shares`), whose loops cost a cold
process about a third of a second of compilation for each function that
inlined them.  A caller that broke the promise (another load, a stale table)
gets NaN and no step (the trial: ``(NaN, NaN, -1)``), never a force from the
wrong table.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.elements import (VISCOUS, computed_decay, element_sum, given_decay,
                                     gms_step_scaled, gms_trial_scaled, inverse_row)
from polind.kernels.pol_ind import (CURRENT_LOAD, KINETIC_COEFFICIENT, STATIC_COEFFICIENT,
                                    TABLE_STALE, decay_row)
# The tangent of a fixed-load run is the Hertzian step's own; the runner module generated
# for this one (polind.kernels.generate) binds it from here.
from polind.kernels.pol_ind import pol_ind_tangent  # noqa: F401


@jit(inline="always")
def broken_promise(scalars, normal_load):
    """Whether a call breaks the fixed-load promise (see the module notes)."""
    return normal_load != scalars[CURRENT_LOAD] or scalars[TABLE_STALE] != 0.0


@jit
def fixed_load_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                    normal_load):
    """The step of a run at the table's own constant load (:ref:`guide-pol-ind-law`).

    :func:`~polind.kernels.pol_ind.settled_step` without a load path
    (:func:`~polind.kernels.pol_ind.load_step` and
    :func:`~polind.kernels.pol_ind.set_load` neither needed nor compiled:
    less than half the compilation of a cold process) and without the
    upkeep of the table (the module notes);
    :func:`~polind.kernels.pol_ind.pol_ind_step`'s forces at that load,
    bit for bit, for the Hertzian and the elastic-plastic arrays alike.  The
    decay factors come from :func:`~polind.kernels.pol_ind.decay_row`,
    which keeps them for the implicit solvers' trials
    (:func:`fixed_load_path_step` computes them in the loop).
    """
    if broken_promise(scalars, normal_load):
        return math.nan
    n = table.shape[1]
    return gms_step_scaled(given_decay, decay_row, scalars, table, state[:n], state[n:2 * n],
                           step, displacement, step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit
def fixed_load_path_step(scalars, table, state, step, displacement, step_velocity,
                         sample_velocity, normal_load):
    """:func:`fixed_load_step` for a prescribed path: each decay factor computed in the loop.

    A prescribed path steps each sample once, so the rows
    :func:`~polind.kernels.pol_ind.decay_row` keeps for the solvers' trials
    save nothing there; the GMS model's own
    :func:`~polind.kernels.elements.computed_decay` gives the same factors,
    to the bit, without the row's pass and its checks.
    """
    if broken_promise(scalars, normal_load):
        return math.nan
    n = table.shape[1]
    return gms_step_scaled(computed_decay, inverse_row, scalars, table, state[:n],
                           state[n:2 * n], step, displacement, step_velocity, sample_velocity,
                           scalars[KINETIC_COEFFICIENT] * normal_load,
                           scalars[STATIC_COEFFICIENT] * normal_load)


@jit
def fixed_load_trial_step(scalars, table, state, out, keep, step, displacement, step_velocity,
                          sample_velocity, normal_load):
    """The read-only trial of :func:`fixed_load_step` (:func:`polind.kernels.contract.no_trial`).

    :func:`~polind.kernels.pol_ind.pol_ind_trial_step` without the upkeep of
    the table (the module notes): ``(F, dF/dw, written)`` from
    :func:`polind.kernels.elements.gms_trial_scaled`, the decay factors from
    :func:`~polind.kernels.pol_ind.decay_row`.
    """
    if broken_promise(scalars, normal_load):
        return math.nan, math.nan, -1
    n = table.shape[1]
    return gms_trial_scaled(given_decay, decay_row, scalars, table, state[:n], state[n:2 * n],
                            out, keep, step, displacement, step_velocity, sample_velocity,
                            scalars[KINETIC_COEFFICIENT] * normal_load,
                            scalars[STATIC_COEFFICIENT] * normal_load)


@jit(fastmath=False)
def fixed_load_force(scalars, table, state, sample_velocity, normal_load):
    """``pol_ind_force`` of a run at the table's own constant load (see :func:`fixed_load_step`).

    ``polind.kernels.elements.gms_force`` written out, not called: a fixed-load
    run compiles no other function that calls it, and its own compilation cost a
    quarter of a second.
    """
    if broken_promise(scalars, normal_load):
        return math.nan
    return element_sum(state[:table.shape[1]]) + scalars[VISCOUS] * sample_velocity
