"""A friction model as a python-control system: :func:`friction_system`.

The user guide, :ref:`guide-python-control`.  (A mass and its contact as one
system is :mod:`polind.control.body`.)

``polind.control.friction_system(model, dt)`` wraps any polind model (or a
registered model of your own) as a discrete-time
:class:`control.NonlinearIOSystem`, to be connected to plants and
controllers with python-control's ``interconnect``, ``feedback`` and
``input_output_response``.  Each sample runs the model's own compiled step
(the stepping contract of :mod:`polind.kernels.contract`) with the
arithmetic of :func:`polind.simulate` and :class:`polind.Stepper`, so a
response equals ``simulate``'s on the same samples.

python-control is an optional dependency: ``pip install polind[control]``.
``import polind`` never imports this module.

The system state
----------------
One float64 vector: the model's own state (``model.flat_state``, its
variables in ``state_keys`` order, named ``"<variable>[<i>]"``), then what a
step needs besides it:

``position``
    x [m] at the previous sample (with input ``"v"``: its trapezoidal
    integral, as ``simulate`` computes it).
``velocity``
    v [m/s] at the previous sample (with input ``"x"``: the previous step's
    velocity).
``started``
    0 before the first sample, 1 after: the first sample has no step
    before it.

A mounted model (a ``[model.compliance]`` spring, or a ``reference_load``:
the user guide's "Series compliance" and "Normal load for every model")
carries three more states between its own and ``position``
(:data:`MOUNT_STATES`): the spring's force [N], the contact's position
[m] and its last step velocity [m/s].

:func:`initial_state` builds the vector (a model at rest, or a saved
:class:`polind.State` to continue from).
"""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np

import control as _ct   # python-control; polind.control says how to install it

from polind.errors import InputError, describe
from polind.stepper import check_model, LoadCheck, start_state
from polind.validation import check_number

__all__ = ["friction_system", "initial_state", "state_names", "model_state_names", "mounted",
           "check_step", "check_flag", "check_load_input", "CARRIED_STATES", "MOUNT_STATES",
           "MOUNT_SLOTS"]

#: The states after the model's own, in this order (see the module notes).
CARRIED_STATES = ("position", "velocity", "started")

#: The states of a mounted model between its own and :data:`CARRIED_STATES`.
MOUNT_STATES = ("spring_force", "contact_position", "contact_velocity")


#: The mount's work slots (:mod:`polind.kernels.mount`), in :data:`MOUNT_STATES` order.
MOUNT_SLOTS = [6, 7, 8]


def mounted(model) -> bool:
    """Whether the model runs mounted (a series spring, or a load scaling)."""
    return model.series_stiffness < math.inf or model.reference_load is not None


def check_step(owner, dt) -> float:
    """The sampling time ``dt`` [s] of a system, checked: a positive finite number."""
    if isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(float(dt)) and float(dt) > 0.0):
        raise InputError(f"The 'dt' of {owner} must be a positive finite number "
                         f"(the sampling time, s). Got {describe(dt)} instead.")
    return float(dt)


def check_flag(owner, name, value) -> bool:
    """A true/false argument, checked (``True``/``False`` only)."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"The '{name}' of {owner} must be True or False. "
                         f"Got {describe(value)} instead.")
    return bool(value)


def check_load_input(owner, model, normal_load) -> bool:
    """Whether a system gets a ``normal_load`` input: asked for, and the model uses a load."""
    if check_flag(owner, "normal_load", normal_load) and not model.uses_normal_load:
        raise InputError(f"The 'normal_load' of {owner} asks for a normal-load input, but the "
                         f"{model.type} model does not use a normal load; expected "
                         f"normal_load=False, or a model with a 'reference_load' (the user "
                         f"guide, 'Normal load for every model').")
    return bool(normal_load)

INPUTS = ("x", "v")

#: System states whose kernel arrays are remembered (the recent ones suffice:
#: a response evaluates each state's output and update, then moves on).
_REMEMBERED = 8


def model_state_names(model) -> list:
    """The names of the model's flat state: ``"<variable>[<i>]"``, in ``state_keys`` order."""
    rest = model.initial_state()
    keys = model.state_keys if model.state_keys is not None else tuple(rest.variables)
    names = []
    for key in keys:
        size = np.size(rest.variables[key])
        names.extend(f"{key}[{i}]" for i in range(size))
    return names


def state_names(model) -> list:
    """The names of the system's states: the model's variables, then :data:`CARRIED_STATES`."""
    check_model(model, "state_names")
    return model_state_names(model) + (list(MOUNT_STATES) if mounted(model) else []) \
        + list(CARRIED_STATES)


def initial_state(model, state=None, *, position=None, velocity=None) -> np.ndarray:
    """The system state ``X0`` to start a :func:`friction_system` response from.

    Parameters
    ----------
    model : FrictionModel
        The model the system was built for.
    state : State, optional
        Continue from a saved state (a ``simulate`` result's
        ``final_state``).  The state's sample is then the one *before* the
        response's first sample: the system's output at its sample ``k``
        equals ``simulate(model, t, ..., state=state).force[k + 1]`` for
        ``t = state.time + dt * arange(n + 1)`` (the chunk that repeats the
        state's sample first).
    position : float, optional
        Without ``state``: the starting position [m] (default 0).  It
        matters with input ``"v"`` only (the start of the integrated
        position); with ``"x"`` the first input sample is the position.
    velocity : float, optional
        Without ``state``: the velocity [m/s] at the first sample (default
        0).  With input ``"x"`` the output at sample 0 is the model's force
        at rest at this velocity: pass ``(x[1] - x[0]) / dt`` to get
        ``simulate``'s (which reports the first step's velocity there).

    Returns
    -------
    ndarray
        float64, ``len(state_names(model))`` entries (see the module notes).

    Examples
    --------
    >>> import polind
    >>> from polind.control import initial_state
    >>> model = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                           "coulomb_force": 1.0}})
    >>> initial_state(model).tolist()    # friction, position, velocity, started
    [0.0, 0.0, 0.0, 0.0]
    """
    check_model(model, "initial_state")
    if state is not None:
        if position is not None or velocity is not None:
            raise InputError("Give initial_state either a 'state' or 'position'/'velocity', "
                             "not both: a state carries its own.")
        flat = model.flat_state(start_state(model, state, "initial_state"))
        expected = model.flat_state(model.initial_state()).shape[0]
        if flat.shape[0] != expected:
            raise InputError(f"The state of the {model.type} model has {flat.shape[0]} entries; "
                             f"its friction_system has {expected}.")
        carried = (state.position, state.velocity, 1.0)
        start = state
    else:
        flat = model.flat_state(model.initial_state())
        carried = (0.0 if position is None else check_number("initial_state", "position",
                                                             position),
                   0.0 if velocity is None else check_number("initial_state", "velocity",
                                                             velocity),
                   0.0)
        start = model.initial_state()
        start.position = carried[0]
    mount = ()
    if mounted(model):
        from polind.kernels.mount import CONTACT_POSITION, CONTACT_VELOCITY, SPRING_FORCE
        array = model.mount_array(start, True)
        mount = (array[SPRING_FORCE], array[CONTACT_POSITION], array[CONTACT_VELOCITY])
    return np.concatenate((np.asarray(flat, dtype=np.float64), np.array(mount, dtype=float),
                           np.array(carried, dtype=float)))


def friction_system(model, dt, input="x", normal_load=False, *, name=None):
    """The friction model as a discrete-time python-control ``NonlinearIOSystem``.

    Parameters
    ----------
    model : FrictionModel
        Any polind model (``load_model``, ``model_from_dict``, or a
        registered model of your own); never mutated.
    dt : float
        The sampling time [s], positive and finite: every step lasts ``dt``.
    input : {"x", "v"}, default "x"
        The motion input: position x [m] (linear path between samples, step
        velocity ``(x[k] - x[k-1]) / dt``) or velocity v [m/s] (each step at
        the mean of its end velocities, position its trapezoidal integral),
        as in :func:`polind.simulate`.
    normal_load : bool, default False
        Whether the system has a second input ``"normal_load"`` [N], the
        normal load at each sample.  Only for a model that uses one
        (``model.uses_normal_load``: Pol-Ind, each sample's load at most the
        model's own ``normal_load``, within the surface's range; a model with
        a ``reference_load``, any positive load); for any other model it is
        an :class:`~polind.InputError`.  Without it the model runs at its own
        load (``model.constant_load``).
    name : str, optional
        The system's name in python-control (for ``interconnect``).

    Returns
    -------
    control.NonlinearIOSystem
        Inputs ``[input]``, plus ``"normal_load"`` when asked for; output
        ``"F"``, the friction force [N]; states as
        :func:`state_names` (the model's state, then ``position``,
        ``velocity``, ``started``), ``X0`` from :func:`initial_state`.

    Notes
    -----
    *Timing.*  The output at sample ``k`` is the force after the step that
    ends at sample ``k``, so it depends on that sample's input: the system
    has direct feedthrough (in a feedback loop, the plant's output must not
    depend on its input at the same sample).  The state update takes the
    same step.  ``control.input_output_response(sys, T, U, X0)`` with
    ``T = t0 + dt * arange(n)`` gives ``simulate(model, T, x=U)``'s forces
    (or ``v=U``; ``normal_load=`` the load row) to 1e-12 relative, sample 0
    with input ``"x"`` aside (below).  Every step lasts ``dt``, where
    ``simulate`` takes the differences of ``T``: they agree to rounding.

    *Sample 0.*  Started from a model at rest (``started = 0``), the first
    output is the model's force at its state at a velocity, and no step is
    taken: with input ``"v"`` at ``v[0]``, ``simulate``'s force exactly;
    with input ``"x"`` at the ``velocity`` of ``X0`` (default 0), where
    ``simulate`` reports the first step's velocity, which a causal system
    cannot know.  A model whose force at rest does not depend on the
    velocity (Dahl, Maxwell-slip or GMS without viscous term) gives the
    same force; otherwise pass ``initial_state(model, velocity=(x[1] -
    x[0]) / dt)`` for ``simulate``'s.

    *Normal load.*  The model's kernel is laid out for its own normal load
    (a Pol-Ind element table; or for the table load of the state ``X0``
    comes from), the largest a sample may take.  ``simulate`` with a
    ``normal_load`` array lays it out for the array's largest load: the two
    agree when that is the model's load.

    *Warm start.*  A model's kernel may keep work that is not part of its
    state (Pol-Ind keeps the separation of the last normal load, the start
    of the next solve).  The system remembers it for the states it has
    produced itself, so a response equals ``simulate`` run at once; from
    any other state (``X0``, a perturbed state) the kernel starts as
    ``simulate`` continuing from a saved state does, equal to 1e-10.

    Examples
    --------
    >>> import numpy as np, control, polind
    >>> from polind.control import friction_system, initial_state
    >>> model = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                           "coulomb_force": 1.0}})
    >>> sys = friction_system(model, dt=1e-3)
    >>> T = 1e-3 * np.arange(101)
    >>> resp = control.input_output_response(sys, T, 1e-4 * T, initial_state(model))
    >>> force = polind.simulate(model, T, x=1e-4 * T).force
    >>> bool(np.allclose(resp.outputs, force, rtol=1e-12, atol=0.0))
    True
    """
    check_model(model, "friction_system")
    dt = check_step("friction_system", dt)
    if not isinstance(input, str) or input not in INPUTS:
        raise InputError(f"The 'input' of friction_system must be 'x' (position) or 'v' "
                         f"(velocity). Got {describe(input)} instead.")
    takes_load = check_load_input("friction_system", model, normal_load)
    step = _SampleStep(model, dt, input, takes_load)
    inputs = [input] + (["normal_load"] if takes_load else [])
    return _ct.NonlinearIOSystem(step.update, step.output, inputs=inputs, outputs=["F"],
                                 states=state_names(model), dt=dt, name=name)


class _KernelArrays:
    """The kernel arrays (``scalars``, ``table``) at one system state, and its load check."""

    __slots__ = ("scalars", "table", "check_load")

    def __init__(self, scalars, table, check_load):
        self.scalars, self.table, self.check_load = scalars, table, check_load


class _SampleStep:
    """One sample of the system: the update and the output, from the same step.

    Both are pure functions of ``(state, input)`` (the system's contract):
    every call steps copies of the arrays.  Two small memories make them
    cheap and exact: the last result (a response asks for the output and the
    update of the same state and input in turn), and the kernel arrays of
    the states this system produced (their warm start, see
    :func:`friction_system`).
    """

    def __init__(self, model, dt, mode, takes_load):
        self.model = model
        self.dt = dt
        self.by_position = mode == "x"
        self.mode = mode
        self.template = model.initial_state()
        functions = model.step_functions()
        self.step = functions.step
        self.force = functions.force
        self.tangent = functions.tangent
        self.runners = functions.runner_module()
        self.size = model.flat_state(self.template).shape[0]
        self.constant_load = float(model.constant_load)
        self.takes_load = takes_load
        # A mounted model steps through its kernel's mounted runner, with the
        # mount's work slots carried in the system state.
        self.mount = model.mount_array(self.template, True) if mounted(model) else None
        self.extra = 0 if self.mount is None else len(MOUNT_STATES)
        self.arrays = OrderedDict()
        self.last_key = None
        self.last = None

    # --- python-control's callbacks ------------------------------------------------------

    def update(self, t, xs, u, params=None):
        return self.advance(xs, u)[0].copy()

    def output(self, t, xs, u, params=None):
        return np.array([self.advance(xs, u)[1]])

    # --- the step -------------------------------------------------------------------------

    def _arrays_for(self, xs, key):
        """Copies of the kernel arrays at system state ``xs`` (remembered, else built)."""
        known = self.arrays.get(key)
        if known is None:
            state = self.template.copy()
            self.model.unflatten_state(xs[:self.size], state)
            kernel = self.model.step_kernel(state)
            check = LoadCheck(self.model, state, "friction_system") if self.takes_load \
                else None
            known = _KernelArrays(kernel.scalars, kernel.table, check)
            self._remember(key, known)
        return known.scalars.copy(), known.table.copy(), known.check_load

    def _remember(self, key, arrays):
        self.arrays[key] = arrays
        self.arrays.move_to_end(key)
        while len(self.arrays) > _REMEMBERED:
            self.arrays.popitem(last=False)

    def _step(self, scalars, table, flat, mount, displacement, step_velocity, sample_velocity,
              load):
        if mount is None:
            return self.step(scalars, table, flat, self.dt, displacement, step_velocity,
                             sample_velocity, load)
        from polind.kernels.series import mounted_sample
        # The load of the sample before is not part of the system state (NaN): the
        # runner brings the model to this step's load first.
        return mounted_sample(self.runners, mount, scalars, table, flat,
                              np.empty(2 * flat.shape[0]), np.zeros((6, 2)), self.dt,
                              displacement, step_velocity, sample_velocity, math.nan, load)

    def advance(self, xs, u):
        """``(next system state, force)`` for system state ``xs`` and input ``u``."""
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        u = np.ascontiguousarray(u, dtype=np.float64)
        key = xs.tobytes()
        if self.last_key is not None and self.last_key[0] == key \
                and self.last_key[1] == u.tobytes():
            return self.last
        expected = self.size + self.extra + len(CARRIED_STATES)
        if xs.shape[0] != expected:
            raise InputError(f"The state of this friction_system has {expected} entries. "
                             f"Got {xs.shape[0]}.")
        motion = float(u[0])
        if not math.isfinite(motion):
            raise InputError(f"The '{self.mode}' input of friction_system must be finite. "
                             f"Got {motion!r} instead.")
        scalars, table, check_load = self._arrays_for(xs, key)
        load = check_load(float(u[1])) if self.takes_load else self.constant_load
        flat = xs[:self.size].copy()
        mount = None
        if self.mount is not None:
            mount = self.mount.copy()
            mount[MOUNT_SLOTS] = xs[self.size:self.size + self.extra]
        position, velocity, started = (float(value) for value in xs[self.size + self.extra:])
        if started == 0.0:
            # The first sample: no step before it, the force at the state.
            if not self.by_position:
                velocity = motion
            from polind.kernels.mount import first_force
            force = first_force(self.force, mount, scalars, table, flat, velocity, load)
            if self.by_position:
                position = motion
        elif self.by_position:
            displacement = motion - position
            step_velocity = displacement / self.dt
            if not math.isfinite(step_velocity):
                raise InputError(f"The 'x' input of friction_system must give a finite step "
                                 f"velocity. Got x = {motion!r} after {position!r}.")
            force = self._step(scalars, table, flat, mount, displacement, step_velocity,
                               step_velocity, load)
            position, velocity = motion, step_velocity
        else:
            step_velocity = 0.5 * (velocity + motion)
            displacement = step_velocity * self.dt
            position = position + displacement
            if not math.isfinite(position):
                raise InputError(f"The 'v' input of friction_system must give a finite "
                                 f"position. Got v = {motion!r} at position {position!r}.")
            force = self._step(scalars, table, flat, mount, displacement, step_velocity, motion,
                               load)
            velocity = motion
        carried = () if mount is None else mount[MOUNT_SLOTS]
        following = np.concatenate((flat, carried, (position, velocity, 1.0)))
        self._remember(following.tobytes(), _KernelArrays(scalars, table, check_load))
        self.last_key = (key, u.tobytes())
        self.last = (following, float(force))
        return self.last
