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
from polind.kernels.buffer import (BODY, BODY_SIZE, CLOCK, CLOCK_SIZE, FORCE, FORCE_SCALE,
                                   LAST_LOAD, MASS, MEMORYLESS, METHOD, MOUNT, POSITION,
                                   REST_CAPACITY, TIME, VELOCITY, RefusedSample, buffer_entry,
                                   copied, step_buffer)
from polind.kernels.buffer import NUMPY_REALS as _NP
from polind.kernels.mount import N_MOUNT
from polind.models import FrictionModel, State
from polind.models.kernel import RIGID
from polind.models.state import BODY_KEY
from polind.validation import check_number

__all__ = ["Stepper", "Body"]

_INF, _NAN = math.inf, math.nan
# The relative error a Body's time step may take from the rounding of its absolute time.
_STEP_TOLERANCE = 1e-6
_F64, _F32 = np.float64, np.float32      # NumPy scalars: what indexing an array gives


def _lost_step(time, time_step, step):
    """The InputError of a time step that the body's time rounds away (floats: a NumPy scalar's
    repr is not its number)."""
    return InputError(f"The 'time_step' of Body ({float(time_step)!r} s) is lost in its time "
                      f"{float(time)!r} s: a step there is {float(step)!r} s in double "
                      f"precision; expected a time step of at least {1e6 * math.ulp(time):.3g} "
                      f"s at that time, or a state whose time starts nearer 0.")


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
    state.check_entries(model)               # with the Body's history, popped below
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
        # Fast path: a float or a NumPy scalar (as its float()), checked with comparisons only.
        if type(normal_load) is float and 0.0 < normal_load < _INF:
            load = normal_load
        elif not 0.0 < (load := float(normal_load) if type(normal_load) in _NP else _NAN) < _INF:
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


def _viewing(kernel, buffer, views):
    """``kernel`` with its arrays the ``views`` of a step buffer, the mount's copied there too."""
    import dataclasses

    scalars, table, state, scratch = views
    mount = buffer[MOUNT:MOUNT + N_MOUNT]
    if kernel.mount is None:
        mount[:] = RIGID
    else:
        mount[:] = kernel.mount
    twin = dataclasses.replace(kernel, scalars=scalars, table=table, state=state,
                               mount=None if kernel.mount is None else mount)
    twin.scratch = scratch
    return twin


def _buffered(kernel):
    """``(buffer, kernel)``: a step buffer with the arrays of ``kernel``, and ``kernel`` on it."""
    buffer, views = step_buffer(kernel.scalars, kernel.table, kernel.state,
                                kernel.scratch.shape[0])
    return buffer, _viewing(kernel, buffer, views)


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
                                     f"state is given. Got {describe(given)} instead.")
        self._model = model
        self._template = start
        # The kernel's arrays and the current sample in one buffer (polind.kernels.buffer):
        # a sample crosses into numba as that buffer and three floats.
        self._buffer, self._kernel = _buffered(model.step_kernel(start, varying_load=True))
        kernel = self._kernel
        self._load = float(kernel.normal_load)
        self._check_load = LoadCheck(model, start, "Stepper")
        if kernel.mount is None:
            self._by_position = buffer_entry(kernel.runners.stepper_position, 3)
            self._by_velocity = None        # compiled (or loaded) at the first sample by velocity
        else:
            # A mounted contact (series spring, load scaling) runs one-sample paths.
            self._path = np.zeros((6, 2))
            self._path_load = kernel.normal_load
            mounted = self._mounted_sample      # on floats: its arithmetic runs in Python
            self._by_position = lambda buffer, t, x, load: mounted(float(t), float(x), None, load)
            self._by_velocity = lambda buffer, t, v, load: mounted(float(t), None, float(v), load)
        sample = self._buffer[TIME:FORCE + 1]
        if state is not None:
            sample[:] = state.time, state.position, state.velocity, state.force
        else:
            sample[:] = time, position, velocity, kernel.first_force(velocity)

    @property
    def force(self) -> float:
        return float(self._buffer[FORCE])

    @property
    def time(self) -> float:
        return float(self._buffer[TIME])

    @property
    def position(self) -> float:
        return float(self._buffer[POSITION])

    @property
    def velocity(self) -> float:
        return float(self._buffer[VELOCITY])

    @property
    def kernel(self):
        """The model's :class:`~polind.models.kernel.StepKernel`, advanced by this stepper."""
        return self._kernel

    @property
    def state(self) -> State:
        return _state_of(self._model, self._template, self._kernel.state, self.time,
                         self.position, self.velocity, self.force)

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
        # Floats and NumPy scalars cross as they are, ints as float(); _checked names a refusal.
        try:
            kind = type(t)
            if kind is not float and kind is not _F64 and kind is not _F32 and kind not in _NP:
                t = float(t) if kind is int else check_number("Stepper.advance", "t", t)
            if v is None:
                motion, kind = x, type(x)
                if kind is not float and kind is not _F64 and kind is not _F32 and kind not in _NP:
                    motion = float(x) if kind is int else self._checked(t, x, v)[1]
                by = self._by_position
            else:
                motion, kind = v, type(v)
                if x is not None or kind is not float and kind is not _F64 and \
                        kind is not _F32 and kind not in _NP:
                    motion = float(v) if x is None and kind is int else self._checked(t, x, v)[2]
                by = self._by_velocity
                if by is None:      # compiled (or loaded) at the first sample by velocity
                    by = self._by_velocity = buffer_entry(self._kernel.runners.stepper_velocity,
                                                          3)
            if normal_load is None:
                return by(self._buffer, t, motion, self._load)
            if not self._check_load.takes_load and not self._check_load.warned:
                self._checked(t, x, v)          # named before the warning, as before
            try:
                load = self._check_load(normal_load)
            except InputError:
                self._motion(*self._checked(t, x, v))   # a bad time or motion is named first
                raise
            return by(self._buffer, t, motion, load)
        except (RefusedSample, OverflowError):      # (OverflowError: an int beyond a double)
            pass
        self._motion(*self._checked(t, x, v))   # raises the InputError of the refused sample
        raise AssertionError("Stepper.advance: a refused sample without an InputError")

    def _checked(self, t, x, v):
        """``(t, x, v)``, each not a float checked as check_number does, in advance's order."""
        if type(t) is not float:
            t = check_number("Stepper.advance", "t", t)
        if v is None and type(x) is float or x is None and type(v) is float:
            return t, x, v
        self._step_to(t)
        if (x is None) == (v is None):
            raise InputError(f"Give Stepper.advance exactly one of 'x' and 'v'. Got "
                             f"{'neither' if x is None else 'both'}.")
        return (t, check_number("Stepper.advance", "x", x), v) if v is None else \
            (t, x, check_number("Stepper.advance", "v", v))

    def _step_to(self, t):
        """The step from the current time to ``t``; an InputError if ``t`` is not after it."""
        time = float(self._buffer[TIME])
        step = t - time
        if not 0.0 < step < _INF:
            raise InputError(f"The 't' of Stepper.advance must be finite and after the current "
                             f"time {time!r}. Got {t!r} instead.")
        return step

    def _motion(self, t, x, v):
        """``(step, displacement, step_velocity, sample_velocity, position)`` of a sample by
        :meth:`advance`'s rules in the arithmetic of the compiled sample
        (:func:`polind.kernels.buffer.stepper_sample`); an InputError for one it refuses."""
        step = self._step_to(t)
        position = float(self._buffer[POSITION])
        if v is None:
            displacement = x - position
            step_velocity = sample_velocity = displacement / step
            position = x
        else:
            step_velocity = 0.5 * (float(self._buffer[VELOCITY]) + v)
            displacement = step_velocity * step
            position, sample_velocity = position + displacement, v
        if step_velocity - step_velocity != 0.0 or position - position != 0.0:  # inf or nan
            name, value, what = ("x", x, "step velocity") if v is None else ("v", v, "position")
            raise InputError(f"The '{name}' of Stepper.advance must be finite, with a finite "
                             f"{what}. Got {name} = {value!r} at t = {t!r}.")
        return step, displacement, step_velocity, sample_velocity, position

    def _mounted_sample(self, t, x, v, load):
        """One sample of a mounted contact (:func:`polind.kernels.series.mounted_sample`)."""
        from polind.kernels.series import mounted_sample

        try:
            step, displacement, step_velocity, sample_velocity, position = self._motion(t, x, v)
        except InputError:
            raise RefusedSample from None       # named by advance, as a compiled refusal
        kernel = self._kernel
        force = mounted_sample(kernel.runners, kernel.mount, kernel.scalars, kernel.table,
                               kernel.state, kernel.scratch, self._path, step, displacement,
                               step_velocity, sample_velocity, self._path_load, load)
        self._path_load = load
        self._buffer[TIME:FORCE + 1] = t, position, sample_velocity, force
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
        # The kernel's arrays, the body's and its numbers in one buffer (polind.kernels.buffer):
        # a step crosses into numba as that buffer and two floats.
        self._attach(*_buffered(model.step_kernel(start, varying_load=True)))
        kernel = self._kernel
        self._model = model
        self._template = start
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
            self._body[:] = position, velocity, velocity, velocity, 0.0, friction
            # [t_0, n, h]: the current time is t_0 + n h (polind.kernels.dynamics.clock_step).
            self._clock[:] = start_time, 0.0, time_step
        else:
            self._restore(history, time_step, start_time)
        step = (self._clock[0] + time_step) - self._clock[0]
        if not abs(step - time_step) <= _STEP_TOLERANCE * time_step:
            raise _lost_step(self._clock[0], time_step, step)
        self._bind()

    def _restore(self, history, time_step, start_time):
        """Continue the body whose ``state`` carried ``history`` (:func:`carried_history`)."""
        kernel = self._kernel
        self._body[:] = history[1], history[2], history[4], history[5], history[6], history[3]
        self._last_load = float(history[7])
        if self._last_load != kernel.normal_load:
            # The kernel arrays at the load the model was last brought to (the state is there).
            kernel.force(kernel.scalars, kernel.table, kernel.state.copy(), float(history[2]),
                         self._last_load)
        if history[10] == time_step:
            self._clock[:] = history[8], history[9], time_step
        else:
            self._clock[:] = start_time, 0.0, time_step
        if kernel.mount is not None and history.shape[0] == len(HISTORY) + 3:
            kernel.mount[_MOUNT_WORK] = history[len(HISTORY):]

    def _attach(self, buffer, kernel):
        """Take ``buffer`` and ``kernel`` (its arrays views into it, :func:`_buffered`)."""
        self._buffer = buffer
        self._kernel = kernel
        self._body = buffer[BODY:BODY + BODY_SIZE]
        self._clock = buffer[CLOCK:CLOCK + CLOCK_SIZE]
        # The mount, or the rigid one of a contact with nothing around it (which nothing
        # writes: polind.models.kernel.RIGID's values).
        self._mount = buffer[MOUNT:MOUNT + N_MOUNT]

    @property
    def _last_load(self):
        """The normal load the model was last brought to [N] (its kernel arrays are at it)."""
        return float(self._buffer[LAST_LOAD])

    @_last_load.setter
    def _last_load(self, load):
        self._buffer[LAST_LOAD] = load

    def _bind(self):
        """The body's numbers into its buffer, and the compiled step that takes the buffer."""
        kernel = self._kernel
        runners = kernel.runners
        mounted = kernel.mount is not None
        buffer = self._buffer
        buffer[MEMORYLESS] = 1.0 if self._memoryless else 0.0
        buffer[REST_CAPACITY] = self._rest_capacity
        buffer[FORCE_SCALE] = float(kernel.force_scale)
        buffer[METHOD] = self._method
        buffer[MASS] = self._mass
        self._own_load = float(kernel.normal_load)
        self._advance = buffer_entry(
            runners.mounted_body_buffer if mounted else runners.body_buffer, 2)
        # compiled(): the runner that takes the arrays one by one (views of the buffer).
        self._function = runners.mounted_body_advance if mounted else runners.body_advance
        self._arguments = (self._memoryless, self._rest_capacity, float(kernel.force_scale),
                           self._mount, kernel.scalars, kernel.table, kernel.state,
                           kernel.scratch, self._method, self._mass, self._clock, self._body)

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
        twin = object.__new__(Body)
        twin.__dict__.update(self.__dict__)
        buffer, views = copied(self._buffer)
        twin._attach(buffer, _viewing(self._kernel, buffer, views))
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
        # A force as Stepper.advance takes a time.  The compiled step (polind.kernels.buffer.
        # body_sample) refuses a non-finite force or a lost step; a new load is brought to the
        # model's real state first there (its force function): the solver's trials run on a copy.
        try:
            kind = type(applied_force)
            if kind is not float and kind is not _F64 and kind is not _F32 and kind not in _NP:
                applied_force = float(applied_force) if kind is int else \
                    check_number("Body.step", "applied_force", applied_force)
            if normal_load is None:
                return self._advance(self._buffer, self._own_load, applied_force)
            if kind is not float and not -_INF < float(applied_force) < _INF:   # named first
                check_number("Body.step", "applied_force", applied_force)
            try:
                load = self._check_load(normal_load)
            except InputError:
                if not -_INF < applied_force < _INF:    # named first, beside a bad load
                    raise self._refusal(applied_force) from None
                raise
            return self._advance(self._buffer, load, applied_force)
        except (RefusedSample, OverflowError):      # (OverflowError: an int beyond a double)
            pass
        if type(applied_force) is not float:     # raises for a non-finite one
            applied_force = check_number("Body.step", "applied_force", applied_force)
        raise self._refusal(applied_force)

    def _refusal(self, applied_force):
        """The InputError of a step the compiled step refused: the force's, or a lost step's."""
        if not -_INF < applied_force < _INF:
            return InputError(f"The 'applied_force' of Body.step must be finite. "
                              f"Got {describe(applied_force)} instead.")
        steps = self._clock[1]
        return _lost_step(self._time_at(steps), self._time_step,
                          self._time_at(steps + 1) - self._time_at(steps))


#: The variable ``"body"`` of :attr:`Body.state`, in this order (then, behind a series
#: spring, its force, the contact's position and the contact's velocity).
HISTORY = ("time", "position", "velocity", "force", "previous_velocity", "step_velocity",
           "history", "last_load", "start_time", "steps", "time_step")
_MOUNT_WORK = slice(6, 9)     # polind.kernels.mount: SPRING_FORCE .. CONTACT_VELOCITY


def carried_history(state):
    """The body history a state carries (its ``"body"`` variable), or None.

    Only a history of the state's own sample counts (its time, position,
    velocity and force): a state that moved on since (``simulate`` from it)
    carries a stale one, which is ignored.
    """
    history = state.variables.get(BODY_KEY) if isinstance(state, State) else None
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
                         f"carries a Body's history. Got {describe(given)} instead.")
    return own
