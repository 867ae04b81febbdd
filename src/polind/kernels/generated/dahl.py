"""The runners of dahl (polind.kernels.single), generated from polind.kernels.template.

Do not edit: ``python -m polind.kernels.generate`` writes this file again.
"""

from polind.kernels import jit
from polind.kernels.contract import no_block as model_block
from polind.kernels.contract import no_blocks as model_blocks
from polind.kernels.contract import no_trial as model_trial
from polind.kernels.single import dahl_step as model_step
from polind.kernels.single import dahl_force as model_force
from polind.kernels.single import dahl_tangent as model_tangent
from polind.kernels.single import dahl_step as model_settled
from polind.kernels.single import dahl_step as model_path_step
from polind.kernels.contract import no_load_change as model_load
from polind.kernels.buffer import body_sample, stepper_sample  # noqa: E402
from polind.kernels.contract import run_motion, run_steps  # noqa: E402
from polind.kernels.dynamics import (advance_body_with, bare_commit, bare_trial,  # noqa: E402
                                     body_advance_with, body_batch_with,
                                     body_step as body_step_with, integrate_system_with)
import math  # noqa: E402

from polind.kernels.contract import sample_load  # noqa: E402
from polind.kernels.dynamics import solve_step  # noqa: E402
from polind.kernels.mount import (CONTACT_POSITION, CONTACT_VELOCITY, FORCE_SCALE,  # noqa: E402
                                  MEMORYLESS, REST_CAPACITY, SPRING_FORCE, STIFFNESS,
                                  contact_step, load_ratio, scaled_force)
from polind.kernels.series import mounted_commit  # noqa: E402
from polind.kernels.periodic import periodic_with  # noqa: E402
from polind.kernels.structure import integrate_structure_with  # noqa: E402


@jit
def path(scalars, table, state, step, displacement, step_velocity, sample_velocity, loads,
         constant_load, lo, hi, out_force):
    """:func:`polind.kernels.contract.run_steps` with the model's path step."""
    run_steps(model_path_step, scalars, table, state, step, displacement, step_velocity,
              sample_velocity, loads, constant_load, lo, hi, out_force)


@jit
def motion_samples(scalars, table, state, source_t, source_motion, t, motion, by_velocity,
                   position, velocity, loads, constant_load, lo, hi, out_force):
    """:func:`polind.kernels.contract.run_motion` with the model's step: one sample a pass."""
    return run_motion(model_path_step, scalars, table, state, source_t, source_motion, t,
                      motion, by_velocity, position, velocity, loads, constant_load, lo, hi,
                      out_force)


# The one-sample runners of Stepper and Body take one buffer (polind.kernels.buffer) and a
# few floats, and keep the GIL: a call of a microsecond gains nothing by releasing it.
@jit(fastmath=False, nogil=False)
def stepper_position(buffer, t, x, normal_load):
    """A :class:`polind.Stepper` sample at position ``x`` (:mod:`polind.kernels.buffer`)."""
    return stepper_sample(model_step, buffer, t, x, False, normal_load)


@jit(fastmath=False, nogil=False)
def stepper_velocity(buffer, t, v, normal_load):
    """A :class:`polind.Stepper` sample at velocity ``v`` (:mod:`polind.kernels.buffer`)."""
    return stepper_sample(model_step, buffer, t, v, True, normal_load)


@jit
def trial(memoryless, mount, scalars, table, state, scratch, velocity, step, sample_slope,
          sample_offset, normal_load, keep):
    """The body solver's trial: :func:`polind.kernels.dynamics.bare_trial` of the model."""
    return bare_trial(model_settled, model_tangent, model_trial, memoryless, mount, scalars,
                      table, state, scratch, velocity, step, sample_slope, sample_offset,
                      normal_load, keep)


@jit
def commit(mount, scalars, table, state, scratch, step, displacement, step_velocity,
           sample_velocity, normal_load):
    """The body's accepted step: :func:`polind.kernels.dynamics.bare_commit` of the model."""
    return bare_commit(model_settled, mount, scalars, table, state, scratch, step, displacement,
                       step_velocity, sample_velocity, normal_load)


@jit
def body_step(memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch,
              method, mass, drive_stiffness, step, external, position, velocity,
              previous_velocity, previous_step_velocity, history, normal_load):
    """:func:`polind.kernels.dynamics.body_step` of the model with nothing around its contact."""
    return body_step_with(trial, commit, model_tangent, memoryless, rest_capacity, force_scale,
                          mount, scalars, table, state, scratch, method, mass, drive_stiffness,
                          step, external, position, velocity, previous_velocity,
                          previous_step_velocity, history, normal_load)


@jit
def integrate(arguments):
    """:func:`polind.kernels.dynamics.integrate_system_with` of :func:`body_step`."""
    integrate_system_with(body_step, arguments)


@jit
def body(arguments):
    """:func:`polind.kernels.dynamics.advance_body_with` of :func:`body_step`."""
    advance_body_with(body_step, arguments)


@jit
def body_advance(memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch,
                 method, mass, clock, body, normal_load, applied_force):
    """:func:`polind.kernels.dynamics.body_advance_with` of :func:`body_step`: ``(x, v, F)``."""
    return body_advance_with(body_step, memoryless, rest_capacity, force_scale, mount, scalars,
                             table, state, scratch, method, mass, clock, body, normal_load,
                             applied_force)


@jit
def body_batch(memoryless, rest_capacity, force_scale, mounts, scalars, table, states, scratch,
               method, masses, clock, bodies, applied_forces, normal_load, out):
    """:func:`polind.kernels.dynamics.body_batch_with` of :func:`body_step`."""
    return body_batch_with(body_step, memoryless, rest_capacity, force_scale, mounts, scalars,
                           table, states, scratch, method, masses, clock, bodies,
                           applied_forces, normal_load, out)


@jit(nogil=False)
def body_buffer(buffer, normal_load, applied_force):
    """:func:`body_advance` on a :class:`polind.Body`'s buffer (:mod:`polind.kernels.buffer`)."""
    return body_sample(body_step, model_force, buffer, normal_load, applied_force)


# The mounted contact (polind.kernels.series): these runners are the only users of their
# loops, which are therefore written here rather than inlined from there (numba copies an
# inlined function's IR once per block; a solver one level deeper cost 0.45 s to compile).
@jit
def spring_trial(memoryless, mount, scalars, table, state, scratch, velocity, step,
                 sample_slope, sample_offset, normal_load, keep):
    """The spring's solve's trial: ``(F_contact(w), dF/dw, written, exact)``, ``state`` untouched.

    Of the contact scaled by its load (:mod:`polind.kernels.mount`): from the
    model's read-only ``model_trial`` where it answers
    (:func:`polind.kernels.contract.no_trial`, given ``scratch`` and
    ``keep``; ``exact``: its ``dF/dw``), else from its step on a copy of
    ``state`` (in ``scratch``) and the model's tangent there; ``written`` as in
    :func:`polind.kernels.dynamics.solve_step`.
    """
    sample_velocity = velocity if memoryless else sample_slope * velocity + sample_offset
    force, tangent, written = model_trial(scalars, table, state, scratch, keep, step,
                                          velocity * step, velocity, sample_velocity,
                                          normal_load)
    answered = written >= 0
    if not answered:
        n = state.shape[0]
        written = n
        work = scratch[:n]
        for i in range(n):  # a loop: `work[:] = state` compiles NumPy's shape-error message (5 s)
            work[i] = state[i]
        force = model_step(scalars, table, work, step, velocity * step, velocity,
                           sample_velocity, normal_load)
        tangent = model_tangent(scalars, table, work, step)
    return (scaled_force(mount, force, sample_velocity, normal_load),
            load_ratio(mount, normal_load) * tangent, written, answered)


@jit
def mounted_step(mount, scalars, table, state, scratch, step, displacement, step_velocity,
                 sample_velocity, normal_load):
    """One step of the mounted contact: ``(F, du, w)``; ``state`` advanced, ``mount`` untouched.

    ``displacement`` and ``step_velocity`` are the far end's (``x``);
    ``scratch`` holds at least one state for the spring's solve
    (:func:`polind.kernels.dynamics.solve_step` with :func:`spring_trial`).
    Compiled on its own and called by the runners below: inlined into the
    body's solver it would put one solver inside another and multiply the
    compile time.
    """
    stiffness = mount[STIFFNESS]
    if stiffness == math.inf:
        force = contact_step(model_step, mount, scalars, table, state, step, displacement,
                             step_velocity, sample_velocity, normal_load)
        return force, displacement, step_velocity
    known = mount[SPRING_FORCE] + stiffness * displacement
    velocity, held, trial_force, written = solve_step(
        spring_trial, model_tangent, mount[MEMORYLESS] != 0.0,
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
    force = contact_step(model_step, mount, scalars, table, state, step, contact_displacement,
                         velocity, velocity, normal_load)
    return force, contact_displacement, velocity


@jit
def mounted_path(mount, scalars, table, state, scratch, step_length, displacement,
                 step_velocity, sample_velocity, loads, constant_load, lo, hi, out_force):
    """:func:`path` of the mounted contact, samples ``lo + 1 .. hi - 1``.

    Sample ``lo`` is taken as done: the first sample of a run is Python's
    (:func:`polind.kernels.mount.first_force`), so this loop compiles no
    ``force``.  Where the load changes, ``model_load`` brings the model's
    real state to it first (the model's ``force``, or
    :func:`polind.kernels.contract.no_load_change`).
    """
    previous_load = sample_load(loads, constant_load, lo)
    for k in range(lo + 1, hi):
        load = sample_load(loads, constant_load, k)
        if load != previous_load:
            # Bring the model to the new load on its real state first (a model
            # whose element table follows the load, Pol-Ind, clips and restarts
            # its elements there): the spring's trials run on copies.
            model_load(scalars, table, state, sample_velocity[k - 1], load)
            previous_load = load
        out_force[k] = mounted_commit(mounted_step, mount, scalars, table, state, scratch,
                                      step_length[k], displacement[k], step_velocity[k],
                                      sample_velocity[k], load)


@jit
def mounted_body_trial(memoryless, mount, scalars, table, state, scratch, velocity, step,
                       sample_slope, sample_offset, normal_load, keep):
    """The body solver's trial of the mounted contact: ``(F(w), dF/dw, 0, False)``.

    :func:`mounted_step` on a copy of ``state``: ``scratch`` holds two
    states, the trial's and, behind it, the spring's solve.  The tangent of
    the spring (``k_s h``) in series with the contact's (the model's tangent:
    not ``exact``).  ``keep`` is not used: the body steps its accepted
    velocity again (``written`` is 0).
    """
    n = state.shape[0]
    work = scratch[:n]
    for i in range(n):      # a loop: `work[:] = state` compiles NumPy's shape-error message (5 s)
        work[i] = state[i]
    sample_velocity = velocity if memoryless else sample_slope * velocity + sample_offset
    force, contact_displacement, contact_velocity = mounted_step(
        mount, scalars, table, work, scratch[n:], step, velocity * step, velocity,
        sample_velocity, normal_load)
    tangent = load_ratio(mount, normal_load) * model_tangent(scalars, table, work, step)
    spring = mount[STIFFNESS] * step
    if spring < math.inf:
        total = spring + tangent
        tangent = spring * tangent / total if total > 0.0 else 0.0
    return force, tangent, 0, False


@jit
def mounted_body_commit(mount, scalars, table, state, scratch, step, displacement,
                        step_velocity, sample_velocity, normal_load):
    """The mounted contact's accepted step (:func:`polind.kernels.series.mounted_commit`)."""
    return mounted_commit(mounted_step, mount, scalars, table, state, scratch, step,
                          displacement, step_velocity, sample_velocity, normal_load)


@jit
def mounted_body_step(memoryless, rest_capacity, force_scale, mount, scalars, table, state,
                      scratch, method, mass, drive_stiffness, step, external, position, velocity,
                      previous_velocity, previous_step_velocity, history, normal_load):
    """:func:`body_step` of the contact behind its mount (the spring solved inside each trial)."""
    return body_step_with(mounted_body_trial, mounted_body_commit, model_tangent, memoryless,
                          rest_capacity, force_scale, mount, scalars, table, state, scratch,
                          method, mass, drive_stiffness, step, external, position, velocity,
                          previous_velocity, previous_step_velocity, history, normal_load)


@jit
def mounted_integrate(arguments):
    """:func:`integrate` of the mounted contact."""
    integrate_system_with(mounted_body_step, arguments)


@jit
def mounted_body(arguments):
    """:func:`body` of the mounted contact."""
    advance_body_with(mounted_body_step, arguments)


@jit
def mounted_body_advance(memoryless, rest_capacity, force_scale, mount, scalars, table, state,
                         scratch, method, mass, clock, body, normal_load, applied_force):
    """:func:`body_advance` of the mounted contact."""
    return body_advance_with(mounted_body_step, memoryless, rest_capacity, force_scale, mount,
                             scalars, table, state, scratch, method, mass, clock, body,
                             normal_load, applied_force)


@jit
def mounted_body_batch(memoryless, rest_capacity, force_scale, mounts, scalars, table, states,
                       scratch, method, masses, clock, bodies, applied_forces, normal_load, out):
    """:func:`body_batch` of the mounted contact."""
    return body_batch_with(mounted_body_step, memoryless, rest_capacity, force_scale, mounts,
                           scalars, table, states, scratch, method, masses, clock, bodies,
                           applied_forces, normal_load, out)


@jit(nogil=False)
def mounted_body_buffer(buffer, normal_load, applied_force):
    """:func:`body_buffer` of the mounted contact."""
    return body_sample(mounted_body_step, model_force, buffer, normal_load, applied_force)


@jit
def mounted_solve(memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch,
                  inertia, known, guess, step, position, sample_slope, sample_offset,
                  normal_load):
    """:func:`polind.kernels.dynamics.solve_step` of :func:`mounted_body_trial`: ``(w, held, F, written)``."""
    return solve_step(mounted_body_trial, model_tangent, memoryless, rest_capacity, force_scale,
                      mount, scalars, table, state, scratch, inertia, known, guess, step,
                      position, sample_slope, sample_offset, normal_load, False)


@jit
def mounted_structure(arguments):
    """:func:`polind.kernels.structure.integrate_structure_with` of mounted contacts (rigid or not).

    One runner for every contact: a rigid mount (``k_s = inf``) steps the
    bare contact (:func:`mounted_step`).  A runner of the bare trial as well
    would give a rigid contact the model's read-only trial, at the cost of
    compiling the structure loop twice per model (some 4 s each).
    """
    integrate_structure_with(mounted_body_trial, mounted_body_commit, mounted_solve, arguments)


@jit
def period(arguments):
    """:func:`polind.kernels.periodic.periodic_with` of the mounted contact (rigid or not)."""
    return periodic_with(mounted_body_commit, model_tangent, arguments)
