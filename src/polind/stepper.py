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
    return state.copy()


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
        if method not in METHODS:
            raise InputError(f"The 'method' of Body must be one of 'bdf2', 'euler'. "
                             f"Got {describe(method)} instead.")
        position = check_number("Body", "position", position)
        velocity = check_number("Body", "velocity", velocity)
        start = start_state(model, state, "Body")
        kernel = model.step_kernel(start, varying_load=True)
        self._model = model
        self._template = start
        self._kernel = kernel
        self._mass = mass
        self._time_step = time_step
        self._method = METHODS[method]
        self._start_time = start.time if state is not None else 0.0
        step = (self._start_time + time_step) - self._start_time
        if not abs(step - time_step) <= _STEP_TOLERANCE * time_step:
            raise _lost_step(self._start_time, time_step, step)
        self._steps = 0
        self._memoryless = kernel.rest_capacity is not None
        self._rest_capacity = kernel.rest_capacity if self._memoryless else 0.0
        self._scratch = kernel.scratch
        self._check_load = LoadCheck(model, start, "Body")
        self._last_load = kernel.normal_load
        friction = initial_friction(kernel, velocity, 0.0)
        # [x_n, v_n, v_{n-1}, w_n, history, friction]: what the next step needs.
        self._body = np.array([position, velocity, velocity, velocity, 0.0, friction])

    def _time_at(self, steps):
        return self._start_time + steps * self._time_step

    @property
    def time(self) -> float:
        return self._time_at(self._steps)

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
        return _state_of(self._model, self._template, self._kernel.state, self.time,
                         self.position, self.velocity, self.friction)

    def step(self, applied_force, normal_load=None):
        """Hold ``applied_force`` [N] over one step; return ``(x, v, F)`` at its end.

        ``normal_load`` [N] is the normal load at the end of the step for
        models that use it (default: the model's own).
        """
        if type(applied_force) is not float:
            applied_force = check_number("Body.step", "applied_force", applied_force)
        elif not -math.inf < applied_force < math.inf:
            raise InputError(f"The 'applied_force' of Body.step must be finite. "
                             f"Got {applied_force!r} instead.")
        kernel = self._kernel
        load = kernel.normal_load if normal_load is None else self._check_load(normal_load)
        if load != self._last_load:
            # Bring the model to the new load on its real state first (the model's
            # force function does that): the solver's trials run on a copy.
            kernel.force(kernel.scalars, kernel.table, kernel.state, float(self._body[1]), load)
            self._last_load = load
        # The step from the sample times as simulate_system computes them.
        step = self._time_at(self._steps + 1) - self._time_at(self._steps)
        if not abs(step - self._time_step) <= _STEP_TOLERANCE * self._time_step:
            raise _lost_step(self._time_at(self._steps), self._time_step, step)
        kernel.advance_body(self._memoryless, self._rest_capacity, kernel.force_scale,
                            kernel.scalars, kernel.table, kernel.state, self._scratch,
                            self._method, self._mass, step, applied_force, self._body, load)
        self._steps += 1
        body = self._body
        return float(body[0]), float(body[1]), float(body[5])
