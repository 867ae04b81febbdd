"""What may sit around a model's contact: a normal-load scaling and a series spring.

Any model can be *mounted* (the user guide, "Normal load for every model"
and "Series compliance"): its force scaled by the normal load (the
load-proportional form, for models other than Pol-Ind) and its contact
placed behind a linear spring.  The mount is one float64 array read by the
kernels of :mod:`polind.kernels.series`; its slots are below.  Nothing here
knows which model it carries: the model enters only through its stepping
contract (:mod:`polind.kernels.contract`).

Load scaling
------------
With a reference load ``N0 > 0`` (slot ``REFERENCE_LOAD``; 0 means
none) and the normal load ``N`` of a sample, the model's force ``F`` (with
its viscous part ``sigma2 v``) becomes::

    F_N = (N / N0) (F - sigma2 v) + sigma2 v

while the model's state evolves as it would at ``N0``: every force level and
every stiffness scales with the load, slip distances and velocities do not.
At ``N == N0`` the force is returned untouched (bit for bit).
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.interpreted import call_once

STIFFNESS = 0          # k_s [N/m] of the series spring; inf: none (a rigid mount)
REFERENCE_LOAD = 1     # N0 [N] of the load scaling; 0: none
VISCOUS = 2            # sigma2 [N s/m], the part of the force that does not scale
MEMORYLESS = 3         # 1.0 for a memoryless model (set-valued friction at rest)
REST_CAPACITY = 4      # a memoryless model's g(0) at N0 [N]
FORCE_SCALE = 5        # a typical force [N] (solver tolerances)
SPRING_FORCE = 6       # work: the force through the spring at the last sample [N]
CONTACT_POSITION = 7   # work: the contact's position u at the last sample [m]
CONTACT_VELOCITY = 8   # work: the contact's last step velocity [m/s] (first guess)
N_MOUNT = 9


def make_mount(stiffness=math.inf, reference_load=0.0, viscous=0.0, rest_capacity=None,
               force_scale=1.0, spring_force=0.0, contact_position=0.0, contact_velocity=0.0):
    """The mount array (float64, ``N_MOUNT`` slots) from its values."""
    mount = np.zeros(N_MOUNT)
    mount[STIFFNESS] = stiffness
    mount[REFERENCE_LOAD] = reference_load
    mount[VISCOUS] = viscous
    mount[MEMORYLESS] = 0.0 if rest_capacity is None else 1.0
    mount[REST_CAPACITY] = 0.0 if rest_capacity is None else rest_capacity
    mount[FORCE_SCALE] = force_scale
    mount[SPRING_FORCE] = spring_force
    mount[CONTACT_POSITION] = contact_position
    mount[CONTACT_VELOCITY] = contact_velocity
    return mount


@jit(inline="always")
def load_ratio(mount, normal_load):
    """``N / N0``, or 1 without a reference load."""
    reference = mount[REFERENCE_LOAD]
    if reference > 0.0:
        return normal_load / reference
    return 1.0


@jit(inline="always")
def scaled_force(mount, force, sample_velocity, normal_load):
    """``(N / N0) (F - sigma2 v) + sigma2 v``; ``F`` itself without scaling or at ``N = N0``."""
    reference = mount[REFERENCE_LOAD]
    if reference > 0.0 and normal_load != reference:
        viscous = mount[VISCOUS] * sample_velocity
        return normal_load / reference * (force - viscous) + viscous
    return force


@jit(inline="always")
def contact_step(step_function, mount, scalars, table, state, step, displacement,
                 step_velocity, sample_velocity, normal_load):
    """The model's step at the contact, its force scaled by the load."""
    force = step_function(scalars, table, state, step, displacement, step_velocity,
                          sample_velocity, normal_load)
    return scaled_force(mount, force, sample_velocity, normal_load)


def first_force(force_function, mount, scalars, table, state, sample_velocity, normal_load):
    """The force at a state without moving (a run's first sample) [N]; called from Python.

    Behind a series spring it is the spring's force (0 at rest); else the
    model's ``force`` at ``sample_velocity``, scaled by the load.  ``mount``
    may be None (nothing around the contact).  The first sample of every
    prescribed path (the runners' ``path`` and ``mounted_path`` take the
    samples after it); the force is
    :func:`polind.kernels.interpreted.call_once`'s.
    """
    if mount is not None and mount[STIFFNESS] < math.inf:
        return float(mount[SPRING_FORCE])
    force = call_once(force_function, scalars, table, state, sample_velocity, normal_load)
    if mount is None:
        return float(force)
    return float(scaled_force(mount, force, sample_velocity, normal_load))
