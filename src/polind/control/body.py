"""A mass and its contact as one python-control system: :func:`body_system`.

The user guide, :ref:`guide-body-system`.

``body_system(model, mass, dt)`` is :class:`polind.Body` as a discrete-time
:class:`control.NonlinearIOSystem`: input the applied force ``u`` [N], held
over a step; outputs the body's position ``x`` [m], velocity ``v`` [m/s] and
friction force ``F`` [N].  Each update is one implicit step of the
one-degree-of-freedom integrator (:mod:`polind.kernels.dynamics`), the very
compiled step :meth:`polind.Body.step` runs
(:meth:`polind.StepKernel.advance_body`), with the friction solved together
with the momentum equation.  So however stiff the contact, a stuck body holds
exactly still, and a loop closed around the system equals the same loop
around a ``Body`` to rounding (measured: to the last bit).

A friction model coupled to a separate mass (:func:`friction_system` fed the
position of a plant that integrates ``m a = u - F``) is explicit coupling
instead: the friction of one sample acts on the mass over the next.  The
presliding contact is then a spring integrated explicitly, stable only for
``dt < 2 sqrt(m / k)`` (the user guide, :ref:`guide-explicit-coupling`);
with Pol-Ind's ``k`` of about 6e8 N/m and 1 kg that is 80 µs.

The system state
----------------
One float64 vector, everything the step needs (:func:`body_state_names`):
the model's own state (as in :func:`friction_system`), for a mounted model
the three mount states (:data:`MOUNT_STATES`), then :data:`BODY_STATES`:

``position``, ``velocity``
    x_n [m] and v_n [m/s], the body at the current sample.
``previous_velocity``, ``step_velocity``
    v_{n-1} [m/s] and the last step's velocity w_n [m/s]: the BDF2 history
    (and the solver's first guess).
``history``
    1 once a step has been taken (BDF2 may use the history), else 0; a
    memoryless model that sticks clears it, as ``Body`` does.
``friction``
    F_n [N], the friction force at the current sample.
``last_load``
    The normal load [N] the model was last brought to.
``start_time``, ``steps``
    The first sample's time [s] and the steps taken: the current time is
    ``start_time + steps * dt``, and every step lasts
    ``t_{n+1} - t_n`` computed so, exactly as ``Body`` computes it.

A kernel may keep work that is not part of its state (Pol-Ind's separation
at the last load): the system remembers the kernel arrays of the states it
produced itself, as :func:`friction_system` does; from any other state the
kernel is rebuilt from the state (equal to 1e-10 where the load changed).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import control as _ct   # python-control; polind.control says how to install it

from polind.control.friction import (MOUNT_SLOTS, MOUNT_STATES, check_load_input, check_step,
                                     model_state_names)
from polind.dynamics import METHODS, initial_friction
from polind.errors import InputError, describe
from polind.stepper import LoadCheck, check_model, start_state
from polind.validation import check_number

__all__ = ["body_system", "body_state_names", "BODY_STATES", "BodyStep"]

#: The states after the model's own (and the mount's), in this order (module notes).
BODY_STATES = ("position", "velocity", "previous_velocity", "step_velocity", "history",
               "friction", "last_load", "start_time", "steps")

#: The body array of :meth:`polind.StepKernel.advance_body`: the first six BODY_STATES.
_BODY_ARRAY = 6

#: System states whose kernel arrays are remembered (a response moves on).
_REMEMBERED = 8


def body_state_names(model) -> list:
    """The names of :func:`body_system`'s states: the model's, the mount's, :data:`BODY_STATES`."""
    check_model(model, "body_state_names")
    kernel = model.step_kernel(varying_load=True)
    mount = [] if kernel.mount is None else list(MOUNT_STATES)
    return model_state_names(model) + mount + list(BODY_STATES)


def body_system(model, mass, dt, position=0.0, velocity=0.0, state=None, normal_load=False, *,
                method="bdf2", name=None):
    """The mass and its contact as one discrete-time python-control system.

    Parameters
    ----------
    model : FrictionModel
        Any polind model, or a registered model of your own; never mutated.
    mass : float
        m [kg], positive.
    dt : float
        The sampling time [s], positive and finite: the step of the body.
    position, velocity : float, default 0
        The body's initial position [m] and velocity [m/s].
    state : State, optional
        The model's state to start from (default: at rest); its time is the
        first sample's.  As for :class:`polind.Body`, ``position`` and
        ``velocity`` are the body's, not the state's.
    normal_load : bool, default False
        Whether the system has a second input ``"normal_load"`` [N], the
        load at the end of each step (a model that uses a load only, as
        :func:`friction_system`); without it the model's own load.
    method : {"bdf2", "euler"}, default "bdf2"
        The implicit momentum scheme, as :class:`polind.Body`'s.
    name : str, optional
        The system's name in python-control (for ``interconnect``).

    Returns
    -------
    control.NonlinearIOSystem
        Input ``"u"``, the applied force [N] held over the step from sample
        ``k`` to ``k + 1`` (plus ``"normal_load"`` when asked for); outputs
        ``"x"`` [m], ``"v"`` [m/s] and ``"F"`` [N], the body at sample
        ``k``, before the step ``u[k]`` drives: the system is strictly
        proper.  Its states are :func:`body_state_names`; its starting
        state is the attribute ``initial_state`` (pass it as ``X0``).

    Notes
    -----
    Sample ``k`` of ``control.input_output_response(sys, T, U,
    sys.initial_state)`` is ``Body(model, mass, dt, position, velocity,
    state)`` after ``k`` calls of ``body.step(U[k])``: at sample 0 the
    body's starting ``position``, ``velocity`` and ``friction``.  A
    controller that reads ``y[k]`` and sets ``u[k]`` (``interconnect``)
    closes the loop of ``body.step(controller(body.position,
    body.velocity))``; the two agree to 1e-12 however stiff the contact
    (the same compiled step runs in both; measured bit for bit).

    Examples
    --------
    >>> import numpy as np, control, polind
    >>> from polind.control import body_system
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    >>> sys = body_system(model, mass=1.0, dt=1e-3)
    >>> T = 1e-3 * np.arange(4)
    >>> resp = control.input_output_response(sys, T, [0.5, 0.5, 2.0, 2.0], sys.initial_state)
    >>> resp.outputs[0].tolist()         # x: stuck under 0.5 N, then it slides
    [0.0, 0.0, 0.0, 1e-06]
    >>> resp.outputs[2].tolist()         # F: holds 0.5 N, then 1 N
    [0.0, 0.5, 0.5, 1.0]
    """
    check_model(model, "body_system")
    mass = check_number("body_system", "mass", mass, "positive")
    dt = check_step("body_system", dt)
    position = check_number("body_system", "position", position)
    velocity = check_number("body_system", "velocity", velocity)
    if not isinstance(method, str) or method not in METHODS:
        raise InputError(f"The 'method' of body_system must be one of 'bdf2', 'euler'. "
                         f"Got {describe(method)} instead.")
    takes_load = check_load_input("body_system", model, normal_load)
    start = start_state(model, state, "body_system")
    step = BodyStep(model, mass, dt, METHODS[method], takes_load, start)
    x0 = step.initial(position, velocity, start.time if state is not None else 0.0)
    inputs = ["u"] + (["normal_load"] if takes_load else [])
    system = _ct.NonlinearIOSystem(step.update, step.output, inputs=inputs,
                                   outputs=["x", "v", "F"], states=step.names, dt=dt, name=name)
    system.initial_state = x0
    return system


class BodyStep:
    """One sample of :func:`body_system`: the update (a ``Body`` step) and the output.

    Both are pure functions of ``(state, input)``: each update steps copies
    of the kernel arrays.  The kernel arrays of the states this system
    produced are remembered (their warm start), and the last result (a
    response may ask for the same update twice).
    """

    def __init__(self, model, mass, dt, method, takes_load, start):
        self.model = model
        self.mass = mass
        self.dt = dt
        self.method = method
        self.takes_load = takes_load
        self.template = start
        kernel = model.step_kernel(start, varying_load=True)
        self.kernel = kernel
        self.size = kernel.state.shape[0]
        self.extra = 0 if kernel.mount is None else len(MOUNT_STATES)
        self.body = self.size + self.extra
        self.names = (model_state_names(model)
                      + ([] if kernel.mount is None else list(MOUNT_STATES)) + list(BODY_STATES))
        self.memoryless = kernel.rest_capacity is not None
        self.rest_capacity = kernel.rest_capacity if self.memoryless else 0.0
        self.arrays = {}
        self.last_key = None
        self.last = None

    def initial(self, position, velocity, start_time):
        """The starting state vector: a ``Body`` built with these arguments."""
        kernel = self.kernel
        friction = initial_friction(kernel, velocity, 0.0)
        mount = () if kernel.mount is None else kernel.mount[MOUNT_SLOTS]
        body = (position, velocity, velocity, velocity, 0.0, friction)
        vector = np.concatenate((kernel.state, mount, body,
                                 (kernel.normal_load, start_time, 0.0))).astype(np.float64)
        self._remember(vector.tobytes(), (kernel.scalars.copy(), kernel.table.copy(),
                                          LoadCheck(self.model, self.template, "body_system")))
        return vector

    # --- python-control's callbacks ------------------------------------------------------

    def update(self, t, xs, u, params=None):
        return self.advance(xs, u).copy()

    def output(self, t, xs, u, params=None):
        start = self.body
        return np.array([xs[start], xs[start + 1], xs[start + 5]], dtype=np.float64)

    # --- the step -------------------------------------------------------------------------

    def _remember(self, key, arrays):
        self.arrays[key] = arrays
        while len(self.arrays) > _REMEMBERED:
            self.arrays.pop(next(iter(self.arrays)))

    def _arrays_for(self, xs, key):
        """Copies of the kernel arrays at system state ``xs`` (remembered, else rebuilt)."""
        known = self.arrays.get(key)
        if known is None:
            state = self.template.copy()
            self.model.unflatten_state(xs[:self.size], state)
            kernel = self.model.step_kernel(state, varying_load=True)
            last_load = float(xs[self.body + 6])
            if last_load != kernel.normal_load:
                # The arrays at the load the model was last brought to (on a copy:
                # the state vector is already there).
                kernel.force(kernel.scalars, kernel.table, kernel.state.copy(),
                             float(xs[self.body + 1]), last_load)
            known = (kernel.scalars, kernel.table, LoadCheck(self.model, state, "body_system"))
            self._remember(key, known)
        scalars, table, check_load = known
        return scalars.copy(), table.copy(), check_load

    def advance(self, xs, u):
        """The next system state for system state ``xs`` and input ``u``."""
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        u = np.ascontiguousarray(u, dtype=np.float64)
        key = xs.tobytes()
        if self.last_key is not None and self.last_key == (key, u.tobytes()):
            return self.last
        if xs.shape[0] != len(self.names):
            raise InputError(f"The state of this body_system has {len(self.names)} entries. "
                             f"Got {xs.shape[0]}.")
        applied = float(u[0])
        if not math.isfinite(applied):
            raise InputError(f"The 'u' input of body_system (the applied force, N) must be "
                             f"finite. Got {applied!r} instead.")
        scalars, table, check_load = self._arrays_for(xs, key)
        flat = xs[:self.size].copy()
        mount = None
        if self.kernel.mount is not None:
            mount = self.kernel.mount.copy()
            mount[MOUNT_SLOTS] = xs[self.size:self.body]
        kernel = dataclasses.replace(self.kernel, scalars=scalars, table=table, state=flat,
                                     mount=mount)
        body = xs[self.body:self.body + _BODY_ARRAY].copy()
        last_load, start_time, steps = (float(value) for value in xs[self.body + _BODY_ARRAY:])
        load = check_load(float(u[1])) if self.takes_load else kernel.normal_load
        # From here on Body.step's own sequence (polind.stepper.Body.step).
        if load != last_load:
            kernel.force(scalars, table, flat, float(body[1]), load)
            last_load = load
        step = (start_time + (steps + 1.0) * self.dt) - (start_time + steps * self.dt)
        kernel.advance_body(self.memoryless, self.rest_capacity, kernel.force_scale, scalars,
                            table, flat, kernel.scratch, self.method, self.mass, step, applied,
                            body, load)
        carried = () if mount is None else mount[MOUNT_SLOTS]
        following = np.concatenate((flat, carried, body, (last_load, start_time, steps + 1.0)))
        self._remember(following.tobytes(), (scalars, table, check_load))
        self.last_key = (key, u.tobytes())
        self.last = following
        return following
