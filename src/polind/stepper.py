"""A friction model in the user's own loop: :class:`Stepper` and :class:`Body`.

Both run the model's own step function (the stepping contract of the user
guide, :mod:`polind.kernels.contract`) one sample at a time, with the same
arithmetic as :func:`polind.simulate` and :func:`polind.simulate_system`:

* :class:`Stepper` is a prescribed motion fed sample by sample (a position
  or a velocity per call) and gives the friction force at each sample,
  equal to ``simulate`` on the same samples;
* :class:`Body` is a mass with friction under an applied force that the
  user's controller computes, advanced by the implicit step of
  :func:`polind.simulate_system`, so a stuck body holds exactly still however
  stiff the model's elements.

Checks are the lightest that keep bad input out: a value that is not a
finite real number, a time that does not increase, a load the model cannot
take, all raise :class:`polind.InputError`.
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError, describe
from polind.kernels import compiled_entry
from polind.models import FrictionModel, State
from polind.validation import check_number

__all__ = ["Stepper", "Body"]

_INF = math.inf
# The relative error a Body's time step may take from the rounding of its absolute time.
_STEP_TOLERANCE = 1e-6


def _lost_step(time, time_step, step):
    """The InputError of a time step that the body's absolute time rounds away."""
    return InputError(f"The 'time_step' of Body ({time_step!r} s) is lost in its time "
                      f"{time!r} s: a step there is {step!r} s in double precision; expected a "
                      f"time step of at least {1e6 * math.ulp(time):.3g} s at that time, or a "
                      f"state whose time starts nearer 0.")


def check_model(model, owner):
    if not isinstance(model, FrictionModel):
        raise InputError(f"The 'model' of {owner} must be a polind friction model (load_model "
                         f"or model_from_dict). Got {describe(model)} instead.")


def start_state(model, state, owner):
    if state is None:
        return model.initial_state()
    if not isinstance(state, State):
        raise InputError(f"The 'state' of {owner} must be a polind State (a result's "
                         f"final_state or State.from_dict). Got {describe(state)} instead.")
    model.check_state(state)
    start = state.copy()
    start.variables.pop(BODY_KEY, None)      # a Body's history (Body reads it on its own)
    return start


class LoadCheck:
    """The normal loads a model accepts, checked per sample without building arrays.

    A model that ignores a load signal (no ``reference_load``) says so once
    (a ``UserWarning``) and runs at its own constant load.
    """

    def __init__(self, model, state, owner):
        self.model = model
        self.state = state
        self.owner = owner
        self.takes_load = model.uses_normal_load
        self.constant = float(model.constant_load)
        self.bounds = model.load_bounds(state) if model.takes_normal_load else (0.0, math.inf)
        self.warned = False

    def __call__(self, normal_load):
        # Fast path: a plain float, checked with comparisons only.
        if type(normal_load) is float and 0.0 < normal_load < math.inf:
            load = normal_load
        else:
            load = check_number(self.owner, "normal_load", normal_load, "positive")
        if not self.takes_load:
            if not self.warned:
                from polind.simulation import warn_ignored_load
                warn_ignored_load(self.model)
                self.warned = True
            return self.constant
        low, high = self.bounds
        if not low <= load <= high:
            self.model.check_loads(np.array([load]), self.state)
        return load


def _state_of(model, template, flat, time, position, velocity, force):
    state = template.copy()
    model.unflatten_state(flat, state)
    state.time, state.position, state.velocity, state.force = time, position, velocity, force
    return state


class Stepper:
    """A friction model advanced one sample at a time along a prescribed motion.

    ``advance`` follows the rules of :func:`polind.simulate` exactly: with
    ``x`` the path is linear between samples (step velocity
    ``(x - x_prev) / (t - t_prev)``); with ``v`` the step's velocity is the
    mean of its end velocities and the position its trapezoidal integral.
    So ``[Stepper(model, velocity=res.v[0]).force] + [advance(t[k], x=x[k])
    for k >= 1]`` equals ``simulate(model, t, x=x).force`` (the same
    compiled step runs in both).

    Parameters
    ----------
    model : FrictionModel
        Any polind model, or a registered model of your own; never mutated.
    state : State, optional
        Continue from a saved state (a result's ``final_state``): time,
        position, velocity and force are then the state's.
    time, position : float, default 0
        The first sample [s] and [m] of a stepper without state (with a
        state, its own; a value given beside it must agree).
    velocity : float, default 0
        The velocity [m/s] at the first sample.  Only the first
        ``force`` depends on it (its rate terms); :func:`polind.simulate`
        with ``x`` reports the first step's velocity there, which a stepper
        cannot know before the step: pass it here to get that force too.

    Attributes
    ----------
    force : float
        The friction force [N] at the current sample.
    time, position, velocity : float
        The current sample [s], [m], [m/s].
    state : State
        The model's state at the current sample, as ``simulate``'s
        ``final_state`` (a copy).

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 1.0]}})
    >>> stepper = polind.Stepper(model)
    >>> [round(stepper.advance(t, x=x), 12) for t, x in [(1.0, 2e-6), (2.0, 0.0)]]
    [1.2, -1.0]
    """

    def __init__(self, model, state=None, time=0.0, position=0.0, velocity=0.0):
        check_model(model, "Stepper")
        time = check_number("Stepper", "time", time)
        position = check_number("Stepper", "position", position)
        velocity = check_number("Stepper", "velocity", velocity)
        start = start_state(model, state, "Stepper")
        if state is not None:
            # A state carries its own sample: other values than the defaults must agree.
            for name, given, own in (("time", time, state.time),
                                     ("position", position, state.position),
                                     ("velocity", velocity, state.velocity)):
                if given != 0.0 and given != own:
                    raise InputError(f"The '{name}' of Stepper is the state's ({own!r}) when a "
                                     f"state is given. Got {given!r} instead.")
        self._model = model
        self._template = start
        kernel = model.step_kernel(start, varying_load=True)
        self._kernel = kernel
        # A mounted contact (series spring, load scaling) runs one-sample paths; the
        # bare one its compiled step for these arrays and floats, called without
        # numba's per-call type dispatch (advance passes exactly these types).
        self._path = None if kernel.mount is None else np.zeros((6, 2))
        self._step = None if self._path is not None else compiled_entry(
            kernel.step, kernel.scalars, kernel.table, kernel.state, 1.0, 1.0, 1.0, 1.0,
            float(kernel.normal_load))
        self._path_load = kernel.normal_load
        self._scalars, self._table, self._flat = kernel.scalars, kernel.table, kernel.state
        self._load = kernel.normal_load
        self._check_load = LoadCheck(model, start, "Stepper")
        if state is not None:
            self._time, self._position = state.time, state.position
            self._velocity, self._force = state.velocity, state.force
        else:
            self._time, self._position, self._velocity = time, position, velocity
            self._force = kernel.first_force(self._velocity)

    @property
    def force(self) -> float:
        return self._force

    @property
    def time(self) -> float:
        return self._time

    @property
    def position(self) -> float:
        return self._position

    @property
    def velocity(self) -> float:
        return self._velocity

    @property
    def kernel(self):
        """The model's :class:`~polind.models.kernel.StepKernel`, advanced by this stepper."""
        return self._kernel

    @property
    def state(self) -> State:
        return _state_of(self._model, self._template, self._flat, self._time, self._position,
                         self._velocity, self._force)

    def advance(self, t, x=None, v=None, normal_load=None) -> float:
        """Advance to the sample at time ``t`` [s]; return the friction force there [N].

        Parameters
        ----------
        t : float
            The new sample's time [s], after the current one.
        x, v : float
            Exactly one: the position [m] at ``t`` (linear path from the
            current sample) or the velocity [m/s] at ``t`` (trapezoidal).
        normal_load : float, optional
            The normal load [N] at ``t`` (models that use it; default: the
            model's own).
        """
        # Fast path: plain floats, checked with comparisons only.
        if type(t) is not float:
            t = check_number("Stepper.advance", "t", t)
        step = t - self._time
        if not 0.0 < step < _INF:
            raise InputError(f"The 't' of Stepper.advance must be finite and after the current "
                             f"time {self._time!r}. Got {t!r} instead.")
        if v is None:
            if x is None:
                raise InputError("Give Stepper.advance exactly one of 'x' and 'v'. Got neither.")
            if type(x) is not float:
                x = check_number("Stepper.advance", "x", x)
            displacement = x - self._position
            step_velocity = displacement / step
            if step_velocity - step_velocity != 0.0:      # inf or nan
                raise InputError(f"The 'x' of Stepper.advance must be finite, with a finite step "
                                 f"velocity. Got x = {x!r} at t = {t!r}.")
            sample_velocity = step_velocity
            position = x
        else:
            if x is not None:
                raise InputError("Give Stepper.advance exactly one of 'x' and 'v'. Got both.")
            if type(v) is not float:
                v = check_number("Stepper.advance", "v", v)
            step_velocity = 0.5 * (self._velocity + v)
            displacement = step_velocity * step
            position = self._position + displacement
            if position - position != 0.0:                # inf or nan
                raise InputError(f"The 'v' of Stepper.advance must be finite, with a finite "
                                 f"position. Got v = {v!r} at t = {t!r}.")
            sample_velocity = v
        load = self._load if normal_load is None else self._check_load(normal_load)
        if self._path is None:
            force = self._step(self._scalars, self._table, self._flat, step, displacement,
                               step_velocity, sample_velocity, load)
        else:
            force = self._mounted_step(step, displacement, step_velocity, sample_velocity, load)
        self._time, self._position, self._velocity, self._force = t, position, \
            sample_velocity, force
        return force


    def _mounted_step(self, step, displacement, step_velocity, sample_velocity, load):
        """One step of a mounted contact (:func:`polind.kernels.series.mounted_sample`)."""
        from polind.kernels.series import mounted_sample

        kernel = self._kernel
        force = mounted_sample(kernel.runners, kernel.mount, kernel.scalars, kernel.table,
                               kernel.state, kernel.scratch, self._path, step, displacement,
                               step_velocity, sample_velocity, self._path_load, load)
        self._path_load = load
        return force


class Body:
    """A mass with friction, stepped by the user's controller (:ref:`guide-body`).

    ``step(applied_force)`` holds the applied force over one step of
    ``time_step`` and advances the body by the implicit step of
    :func:`polind.simulate_system` (BDF2 by default): the friction force at
    the end of the step is the model's own exact update at the step's
    velocity, solved together with the momentum equation, so a stuck body
    stays exactly still (friction equals the applied force) however stiff the
    model's elements.  A sequence of ``step`` calls gives the same positions,
    velocities and forces as ``simulate_system(model, system,
    applied=forces)`` (the same compiled step).

    Parameters
    ----------
    model : FrictionModel
        Any polind model; never mutated.
    mass : float, default 1
        m [kg], positive.
    time_step : float, default 1e-3
        h [s], positive.
    position, velocity : float, default 0
        Initial position [m] and velocity [m/s].
    state : State, optional
        The model's state to start from (default: at rest); its time is the
        body's starting time.
    method : {"bdf2", "euler"}, default "bdf2"
        The implicit momentum scheme (see :func:`polind.simulate_system`).

    Attributes
    ----------
    time, position, velocity : float
        The body at the current sample [s], [m], [m/s].
    friction : float
        The friction force [N] at the current sample (before the first step:
        the model's force at its state and the initial velocity; a
        memoryless model at rest gives 0 there).
    state : State
        The model's state at the current sample (a copy).

    Examples
    --------
    >>> import polind
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    >>> body = polind.Body(model, mass=1.0, time_step=1e-3)
    >>> body.step(0.5)                     # below Fc: stuck, friction holds the force
    (0.0, 0.0, 0.5)
    """

    def __init__(self, model, mass=1.0, time_step=1e-3, position=0.0, velocity=0.0,
                 state=None, method="bdf2"):
        from polind.dynamics import METHODS, initial_friction

        check_model(model, "Body")
        mass = check_number("Body", "mass", mass, "positive")
        time_step = check_number("Body", "time_step", time_step, "positive")
        if not isinstance(method, str) or method not in METHODS:
            raise InputError(f"The 'method' of Body must be one of 'bdf2', 'euler'. "
                             f"Got {describe(method)} instead.")
        history = carried_history(state)
        if history is not None:
            position = _agrees("position", position, history[1])
            velocity = _agrees("velocity", velocity, history[2])
        position = check_number("Body", "position", 0.0 if position is None else position)
        velocity = check_number("Body", "velocity", 0.0 if velocity is None else velocity)
        start = start_state(model, state, "Body")
        kernel = model.step_kernel(start, varying_load=True)
        self._model = model
        self._template = start
        self._kernel = kernel
        self._mass = mass
        self._time_step = time_step
        self._method = METHODS[method]
        self._memoryless = kernel.rest_capacity is not None
        self._rest_capacity = kernel.rest_capacity if self._memoryless else 0.0
        self._check_load = LoadCheck(model, start, "Body")
        start_time = start.time if state is not None else 0.0
        if history is None:
            self._last_load = kernel.normal_load
            friction = initial_friction(kernel, velocity, 0.0)
            # [x_n, v_n, v_{n-1}, w_n, history, friction]: what the next step needs.
            self._body = np.array([position, velocity, velocity, velocity, 0.0, friction])
            # [t_0, n, h]: the current time is t_0 + n h (polind.kernels.dynamics.clock_step).
            self._clock = np.array([start_time, 0.0, time_step])
        else:
            self._restore(history, time_step, start_time)
        step = (self._clock[0] + time_step) - self._clock[0]
        if not abs(step - time_step) <= _STEP_TOLERANCE * time_step:
            raise _lost_step(self._clock[0], time_step, step)
        self._bind()

    def _restore(self, history, time_step, start_time):
        """Continue the body whose ``state`` carried ``history`` (:func:`carried_history`)."""
        kernel = self._kernel
        self._body = np.array([history[1], history[2], history[4], history[5], history[6],
                               history[3]])
        self._last_load = float(history[7])
        if self._last_load != kernel.normal_load:
            # The kernel arrays at the load the model was last brought to (the state is there).
            kernel.force(kernel.scalars, kernel.table, kernel.state.copy(), float(history[2]),
                         self._last_load)
        if history[10] == time_step:
            self._clock = np.array([history[8], history[9], time_step])
        else:
            self._clock = np.array([start_time, 0.0, time_step])
        if kernel.mount is not None and history.shape[0] == len(HISTORY) + 3:
            kernel.mount[_MOUNT_WORK] = history[len(HISTORY):]

    def _bind(self):
        """The compiled step and its arguments, bound once (``step`` passes these types)."""
        from polind.models.kernel import RIGID

        kernel = self._kernel
        runners = kernel.runners
        mounted = kernel.mount is not None
        self._arguments = (self._memoryless, self._rest_capacity, float(kernel.force_scale),
                           kernel.mount if mounted else RIGID, kernel.scalars, kernel.table,
                           kernel.state, kernel.scratch, self._method, self._mass, self._clock,
                           self._body)
        function = runners.mounted_body_advance if mounted else runners.body_advance
        self._function = function
        self._advance = compiled_entry(function, *self._arguments, float(kernel.normal_load),
                                       0.0)

    def _time_at(self, steps):
        return self._clock[0] + steps * self._time_step

    @property
    def time(self) -> float:
        return float(self._time_at(self._clock[1]))

    @property
    def position(self) -> float:
        return float(self._body[0])

    @property
    def velocity(self) -> float:
        return float(self._body[1])

    @property
    def friction(self) -> float:
        return float(self._body[5])

    @property
    def state(self) -> State:
        """The model's state at the current sample, with the body's history (a copy).

        Its variable ``"body"`` (``polind.stepper.HISTORY``, then a mounted contact's
        spring force, contact position and contact velocity) is what the next
        step needs besides the model's state: a ``Body`` built from this
        state continues this one bit for bit.
        """
        state = _state_of(self._model, self._template, self._kernel.state, self.time,
                          self.position, self.velocity, self.friction)
        body, clock = self._body, self._clock
        history = [state.time, body[0], body[1], body[5], body[2], body[3], body[4],
                   self._last_load, clock[0], clock[1], clock[2]]
        if self._kernel.mount is not None:
            history += list(self._kernel.mount[_MOUNT_WORK])
        state.variables[BODY_KEY] = np.array(history, dtype=np.float64)
        return state

    def copy(self) -> "Body":
        """An independent body at the same sample (its arrays copied): for rollouts."""
        import dataclasses

        twin = object.__new__(Body)
        twin.__dict__.update(self.__dict__)
        kernel = self._kernel
        twin._kernel = dataclasses.replace(
            kernel, scalars=kernel.scalars.copy(), table=kernel.table.copy(),
            state=kernel.state.copy(), mount=None if kernel.mount is None else kernel.mount.copy())
        twin._body = self._body.copy()
        twin._clock = self._clock.copy()
        twin._check_load = LoadCheck(self._model, self._template, "Body")
        twin._bind()
        return twin

    def compiled(self):
        """This body's step for a loop of your own compiled with numba: ``(step, arguments)``.

        ``x, v, F = step(*arguments, applied_force)`` in an ``@njit`` function
        is :meth:`step` at the model's own normal load, bit for bit, on this
        body's own arrays: the body advances (its ``time``, ``position``,
        ``state``, ... follow).  ``step`` is the model's runner
        ``body_advance`` (:mod:`polind.kernels.template`); a step that the
        body's absolute time rounds away returns NaNs and changes nothing.
        (:ref:`guide-body-compiled`).
        """
        kernel = self._kernel
        if self._last_load != kernel.normal_load:
            # Back to the model's own load, as the next step() without a load would.
            kernel.force(kernel.scalars, kernel.table, kernel.state, float(self._body[1]),
                         kernel.normal_load)
            self._last_load = kernel.normal_load
        return self._function, self._arguments + (float(kernel.normal_load),)

    def step(self, applied_force, normal_load=None):
        """Hold ``applied_force`` [N] over one step; return ``(x, v, F)`` at its end.

        ``normal_load`` [N] is the normal load at the end of the step for
        models that use it (default: the model's own).
        """
        if type(applied_force) is not float:
            applied_force = check_number("Body.step", "applied_force", applied_force)
        elif not -_INF < applied_force < _INF:
            raise InputError(f"The 'applied_force' of Body.step must be finite. "
                             f"Got {applied_force!r} instead.")
        if normal_load is None:
            load = self._kernel.normal_load
        else:
            load = self._check_load(normal_load)
        if load != self._last_load:
            # Bring the model to the new load on its real state first (the model's
            # force function does that): the solver's trials run on a copy.
            kernel = self._kernel
            kernel.force(kernel.scalars, kernel.table, kernel.state, float(self._body[1]), load)
            self._last_load = load
        x, v, friction = self._advance(*self._arguments, load, applied_force)
        if x != x and self._lost():
            steps = self._clock[1]
            raise _lost_step(self._time_at(steps), self._time_step,
                             self._time_at(steps + 1) - self._time_at(steps))
        return x, v, friction

    def _lost(self):
        steps = self._clock[1]
        step = self._time_at(steps + 1) - self._time_at(steps)
        return not abs(step - self._time_step) <= _STEP_TOLERANCE * self._time_step


#: The variable ``"body"`` of :attr:`Body.state`, in this order (then, behind a series
#: spring, its force, the contact's position and the contact's velocity).
HISTORY = ("time", "position", "velocity", "force", "previous_velocity", "step_velocity",
           "history", "last_load", "start_time", "steps", "time_step")
BODY_KEY = "body"
_MOUNT_WORK = slice(6, 9)     # polind.kernels.mount: SPRING_FORCE .. CONTACT_VELOCITY


def carried_history(state):
    """The body history a state carries (its ``"body"`` variable), or None.

    Only a history of the state's own sample counts (its time, position,
    velocity and force): a state that moved on since (``simulate`` from it)
    carries a stale one, which is ignored.
    """
    if not isinstance(state, State):
        return None
    history = state.variables.get(BODY_KEY)
    if history is None:
        return None
    history = np.asarray(history, dtype=np.float64).reshape(-1)
    if history.shape[0] not in (len(HISTORY), len(HISTORY) + 3):
        raise InputError(f"The state's '{BODY_KEY}' entry (a Body's history) has "
                         f"{history.shape[0]} numbers; expected {len(HISTORY)}, or "
                         f"{len(HISTORY) + 3} for a model with [model.compliance].")
    own = (state.time, state.position, state.velocity, state.force)
    if tuple(float(value) for value in history[:4]) != tuple(float(value) for value in own):
        return None
    return history


def _agrees(name, given, own):
    """A Body's ``position``/``velocity`` beside a state with a history: the history's.

    0 (the default) or None is "not given", as for :class:`Stepper`'s state.
    """
    own = float(own)
    if given is not None and given != 0.0 and given != own:
        raise InputError(f"The '{name}' of Body is the state's ({own!r}) when the state "
                         f"carries a Body's history. Got {given!r} instead.")
    return own
