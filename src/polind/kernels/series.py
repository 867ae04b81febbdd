"""A mounted contact (:mod:`polind.kernels.mount`): the series spring solved per step.

Series compliance (the user guide, "Series compliance")
-------------------------------------------------------
The prescribed displacement ``x`` is that of the far end of a spring of
stiffness ``k_s``; the contact moves by ``u`` and at every sample::

    F = k_s (x - u) = F_contact(u)

Over a step ``x`` advances by ``dx`` and the contact by ``du = h w`` at the
constant contact velocity ``w``, with the model's own exact update at ``w``.
With ``F_prev`` the spring's force at the previous sample, the step solves::

    k_s h w + F_contact(w) = F_prev + k_s dx

which is the implicit equation of a body with ``inertia = k_s h`` and a
known right-hand side (:func:`polind.kernels.dynamics.solve_step`, the same
safeguarded secant/bisection search with the model's tangent).  Where the
contact force is non-decreasing in ``u`` (the Maxwell-slip family) the root
is unique and, ``F_contact`` being piecewise linear in ``w`` there, found
exactly; where it can fall (a Stribeck dip) the search starts from ``w =
0`` and brackets outwards, i.e. it takes a root near the previous ``u``.  A
memoryless contact holds (``w = 0``, ``F = F_prev + k_s dx``) while that
force is within its ``g(0)``.  The contact's rate terms (``sigma2 v``,
LuGre's ``sigma1 dz/dt``) are taken at the contact velocity ``w``.
``k_s = inf`` is the rigid mount: the model's own step, unchanged.

The force reported at a sample is the contact's, which equals the spring's
``k_s (x - u)`` to the solver's tolerance (``1e-13`` of the force scale).
The first sample of a run reports the spring's force of the state (0 for a
model at rest): the spring carries what the contact carries.

The templates here take the model's functions as arguments and are inlined
into each model's runners (:mod:`polind.kernels.template`): its
``mounted_step`` (:func:`mounted_step_with`, the spring's solve, compiled on
its own), ``mounted_path`` (:func:`run_mounted_with`) and the body of a
mounted contact, all kept in numba's on-disk cache like the model's other
runners.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.contract import sample_load
from polind.kernels.dynamics import solve_step
from polind.kernels.mount import (CONTACT_POSITION, CONTACT_VELOCITY, FORCE_SCALE, MEMORYLESS,
                                  REST_CAPACITY, SPRING_FORCE, STIFFNESS, contact_step,
                                  load_ratio, scaled_force)


@jit(inline="always")
def contact_trial(step_function, tangent_function, trial_function, memoryless, mount, scalars,
                  table, state, scratch, velocity, step, sample_slope, sample_offset,
                  normal_load, keep):
    """``(F_contact(w), dF/dw, written, exact)`` of the scaled contact, ``state`` untouched.

    From the model's read-only ``trial_function`` where it answers
    (:func:`polind.kernels.contract.no_trial`, given ``scratch`` and
    ``keep``; ``exact``: its ``dF/dw``), else from its step on a copy of
    ``state`` (in ``scratch``) and the model's tangent there; ``written`` as in
    :func:`polind.kernels.dynamics.solve_step`.
    """
    sample_velocity = velocity if memoryless else sample_slope * velocity + sample_offset
    force, tangent, written = trial_function(scalars, table, state, scratch, keep, step,
                                             velocity * step, velocity, sample_velocity,
                                             normal_load)
    answered = written >= 0
    if not answered:
        n = state.shape[0]
        written = n
        work = scratch[:n]
        for i in range(n):  # a loop: `work[:] = state` compiles NumPy's shape-error message (5 s)
            work[i] = state[i]
        force = step_function(scalars, table, work, step, velocity * step, velocity,
                              sample_velocity, normal_load)
        tangent = tangent_function(scalars, table, work, step)
    return (scaled_force(mount, force, sample_velocity, normal_load),
            load_ratio(mount, normal_load) * tangent, written, answered)


@jit(inline="always")
def mounted_step_with(spring_trial, step_function, tangent_function, mount, scalars, table, state,
                      scratch, step, displacement, step_velocity, sample_velocity, normal_load):
    """One step of the mounted contact: ``(F, du, w)``; ``state`` advanced, ``mount`` untouched.

    ``displacement`` and ``step_velocity`` are the far end's (``x``);
    ``scratch`` holds at least one state for the spring's solve;
    ``spring_trial`` is :func:`contact_trial` with the model's functions
    bound (the solver's ``trial``, :func:`polind.kernels.dynamics.solve_step`).  A model's
    runners compile it on its own (their ``mounted_step``), called by the
    other templates below as their ``mounted_step`` argument: inlined into
    the body's solver it would put one solver inside another and multiply
    the compile time.
    """
    stiffness = mount[STIFFNESS]
    if stiffness == math.inf:
        force = contact_step(step_function, mount, scalars, table, state, step, displacement,
                             step_velocity, sample_velocity, normal_load)
        return force, displacement, step_velocity
    known = mount[SPRING_FORCE] + stiffness * displacement
    velocity, held, trial_force, written = solve_step(
        spring_trial, tangent_function, mount[MEMORYLESS] != 0.0,
        mount[REST_CAPACITY], mount[FORCE_SCALE], mount,
        scalars, table, state, scratch, stiffness * step, known, mount[CONTACT_VELOCITY], step,
        mount[CONTACT_POSITION], 1.0, 0.0, normal_load, True)
    if held:
        return known, 0.0, 0.0
    contact_displacement = velocity * step
    if written > 0:
        # The last trial was the accepted step, and kept the state it leaves: take it
        # rather than step again (its force is the step's, summed in its own loop).
        for i in range(written):
            state[i] = scratch[i]
        return trial_force, contact_displacement, velocity
    force = contact_step(step_function, mount, scalars, table, state, step, contact_displacement,
                         velocity, velocity, normal_load)
    return force, contact_displacement, velocity


@jit(inline="always")
def mounted_commit(mounted_step, mount, scalars, table, state, scratch, step, displacement,
                   step_velocity, sample_velocity, normal_load):
    """``mounted_step`` on the real state, remembering the spring's force and the contact.

    ``mounted_step`` is a model's :func:`mounted_step_with` with its
    functions bound.
    """
    force, contact_displacement, contact_velocity = mounted_step(
        mount, scalars, table, state, scratch, step, displacement, step_velocity,
        sample_velocity, normal_load)
    mount[SPRING_FORCE] = force
    mount[CONTACT_POSITION] += contact_displacement
    mount[CONTACT_VELOCITY] = contact_velocity
    return force


@jit(inline="always")
def mounted_trial(mounted_step, tangent_function, memoryless, mount, scalars, table, state,
                  scratch, velocity, step, sample_slope, sample_offset, normal_load, keep):
    """The body solver's trial of a mounted contact: ``(F(w), dF/dw, 0, False)``, spring and contact.

    ``mounted_step`` as in :func:`mounted_commit`; ``tangent_function`` is
    the model's.  ``scratch`` holds two states: the trial's and, behind it,
    the spring's solve.  The tangent of the spring (``k_s h``) in series
    with the contact's (the model's tangent: not ``exact``).  ``keep`` is
    not used: the body steps its accepted velocity again (``written`` is 0).
    """
    n = state.shape[0]
    work = scratch[:n]
    for i in range(n):      # a loop: `work[:] = state` compiles NumPy's shape-error message (5 s)
        work[i] = state[i]
    sample_velocity = velocity if memoryless else sample_slope * velocity + sample_offset
    force, contact_displacement, contact_velocity = mounted_step(
        mount, scalars, table, work, scratch[n:], step, velocity * step, velocity,
        sample_velocity, normal_load)
    tangent = load_ratio(mount, normal_load) * tangent_function(scalars, table, work, step)
    spring = mount[STIFFNESS] * step
    if spring < math.inf:
        total = spring + tangent
        tangent = spring * tangent / total if total > 0.0 else 0.0
    return force, tangent, 0, False


@jit(inline="always")
def run_mounted_with(mounted_step, load_function, mount, scalars, table, state, scratch,
                     step_length, displacement, step_velocity, sample_velocity, loads,
                     constant_load, lo, hi, out_force):
    """:func:`polind.kernels.contract.run_steps` for a mounted contact, samples ``lo + 1 .. hi - 1``.

    ``mounted_step`` as in :func:`mounted_commit`; ``load_function`` is the
    model's ``load`` (its ``force``, or
    :func:`polind.kernels.contract.no_load_change`).  Sample ``lo`` is
    taken as done: the first sample of a run is Python's
    (:func:`polind.kernels.mount.first_force`), so this loop compiles no
    ``force`` of its own.
    """
    previous_load = sample_load(loads, constant_load, lo)
    for k in range(lo + 1, hi):
        load = sample_load(loads, constant_load, k)
        if load != previous_load:
            # Bring the model to the new load on its real state first (a model
            # whose element table follows the load, Pol-Ind, clips and restarts
            # its elements there): the spring's trials run on copies.
            load_function(scalars, table, state, sample_velocity[k - 1], load)
            previous_load = load
        out_force[k] = mounted_commit(mounted_step, mount, scalars, table, state, scratch,
                                      step_length[k], displacement[k], step_velocity[k],
                                      sample_velocity[k], load)


def mounted_sample(runners, mount, scalars, table, state, scratch, path, step, displacement,
                   step_velocity, sample_velocity, previous_load, normal_load):
    """One sample of a mounted contact, called from Python: a one-step path of its runners.

    ``runners`` are the model's (:mod:`polind.kernels.template`); ``path`` is
    a (6, 2) float64 work array; ``previous_load`` the load of the sample
    before (NaN if unknown: the model is then brought to ``normal_load``
    first, as :func:`run_mounted_with` does whenever the load changes).
    Returns the force [N]; ``state`` and ``mount`` are advanced.
    """
    path[0, 1], path[1, 1], path[2, 1], path[3, 1] = step, displacement, step_velocity, \
        sample_velocity
    path[4, 0], path[4, 1] = previous_load, normal_load
    runners.mounted_path(mount, scalars, table, state, scratch, path[0], path[1], path[2],
                         path[3], path[4], normal_load, 0, 2, path[5])
    return float(path[5, 1])
