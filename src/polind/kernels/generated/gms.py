"""The runners of gms (polind.kernels.elements), generated from polind.kernels.template.

Do not edit: ``python -m polind.kernels.generate`` writes this file again.
"""

from polind.kernels import jit
from polind.kernels.contract import no_block as model_block
from polind.kernels.contract import no_blocks as model_blocks
from polind.kernels.elements import gms_trial_step as model_trial
from polind.kernels.elements import gms_step as model_step
from polind.kernels.elements import gms_force as model_force
from polind.kernels.elements import gms_tangent as model_tangent
from polind.kernels.elements import gms_step as model_settled
from polind.kernels.elements import gms_step as model_path_step
from polind.kernels.contract import no_load_change as model_load
from polind.kernels.buffer import body_sample, stepper_sample  # noqa: E402
from polind.kernels.contract import run_motion, run_steps  # noqa: E402
from polind.kernels.dynamics import (advance_body_with, bare_commit, bare_trial,  # noqa: E402
                                     body_advance_with, body_batch_with,
                                     body_step as body_step_with, integrate_system_with)
from polind.kernels.series import (contact_trial, mounted_commit,  # noqa: E402
                                   mounted_step_with, mounted_trial, run_mounted_with)


@jit
def path(scalars, table, state, step, displacement, step_velocity, sample_velocity, loads,
         constant_load, lo, hi, first, out_force):
    """:func:`polind.kernels.contract.run_steps` with the model's functions."""
    run_steps(model_path_step, model_force, scalars, table, state, step, displacement,
              step_velocity, sample_velocity, loads, constant_load, lo, hi, first, out_force)


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


@jit
def spring_trial(memoryless, mount, scalars, table, state, scratch, velocity, step,
                 sample_slope, sample_offset, normal_load, keep):
    """The spring's solve's trial: :func:`polind.kernels.series.contact_trial` of the model."""
    return contact_trial(model_step, model_tangent, model_trial, memoryless, mount, scalars,
                         table, state, scratch, velocity, step, sample_slope, sample_offset,
                         normal_load, keep)


@jit
def mounted_step(mount, scalars, table, state, scratch, step, displacement, step_velocity,
                 sample_velocity, normal_load):
    """:func:`polind.kernels.series.mounted_step_with` of the model: ``(F, du, w)``."""
    return mounted_step_with(spring_trial, model_step, model_tangent, mount, scalars, table,
                             state, scratch, step, displacement, step_velocity, sample_velocity,
                             normal_load)


@jit
def mounted_path(mount, scalars, table, state, scratch, step_length, displacement,
                 step_velocity, sample_velocity, loads, constant_load, lo, hi, out_force):
    """:func:`polind.kernels.series.run_mounted_with` of :func:`mounted_step` and ``model_load``."""
    run_mounted_with(mounted_step, model_load, mount, scalars, table, state, scratch,
                     step_length, displacement, step_velocity, sample_velocity, loads,
                     constant_load, lo, hi, out_force)


@jit
def mounted_body_trial(memoryless, mount, scalars, table, state, scratch, velocity, step,
                       sample_slope, sample_offset, normal_load, keep):
    """The body solver's trial of the mounted contact (:func:`polind.kernels.series.mounted_trial`)."""
    return mounted_trial(mounted_step, model_tangent, memoryless, mount, scalars, table, state,
                         scratch, velocity, step, sample_slope, sample_offset, normal_load,
                         keep)


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
