"""One-degree-of-freedom systems (MODELS.md 8): :func:`simulate_system`.

A body of mass ``m`` driven by a spring ``k_d`` pulled at ``v_d`` and/or an
applied force, against the friction force ``F`` of any polind model::

    m a = k_d (v_d t - x) + offset + rate t + amplitude sin(2 pi frequency t) - F

This module validates the system, packs the model's parameters and state into
the flat arrays of :mod:`polind.kernels.dynamics` (which holds the integrator
and explains the scheme) and wraps the result.  The friction force of the
result is the model's own along the body's path: the model state is advanced
exactly as ``polind.simulate(model, res.t, x=res.x)`` advances it, and with
``method="euler"`` the forces are equal from the second sample on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from polind.errors import InputError, describe
from polind.kernels import dynamics as kernel
from polind.kernels.stribeck import SHAPE_CODES
from polind.models import FrictionModel, State
from polind.simulate import simulate

__all__ = ["System", "SystemResult", "load_system", "simulate_system"]

METHODS = {"bdf2": kernel.BDF2, "euler": kernel.EULER}

# Steps per kernel call: long runs report progress between chunks.
_CHUNK = 1 << 16

_POSITIVE = ("mass", "duration", "time_step")
_NONNEGATIVE = ("spring_stiffness", "frequency")


#: Most output samples a system run may ask for (5 float64 arrays: 4 GB).
MAX_SAMPLES = 1e8


@dataclass(frozen=True)
class System:
    """A one-degree-of-freedom system (MODELS.md 8; the ``[system]`` file of INTERFACE.md).

    Parameters
    ----------
    mass : float
        m [kg], positive.
    duration : float
        Length of the run [s], positive.
    time_step : float
        Output sample spacing and integration step [s], positive, at most
        ``duration``.
    spring_stiffness : float, default 0
        k_d [N/m] of the drive spring, non-negative.
    drive_velocity : float, default 0
        v_d [m/s], the velocity at which the spring's far end is pulled.
    offset, rate, amplitude, frequency : float, default 0
        The applied force ``offset + rate t + amplitude sin(2 pi frequency t)``:
        N, N/s, N and Hz (non-negative).

    Examples
    --------
    >>> from polind.dynamics import System
    >>> system = System(mass=1.0, duration=1.0, time_step=0.25, spring_stiffness=2.0,
    ...                 drive_velocity=0.1, offset=0.5)
    >>> system.times
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    >>> system.applied_force(0.5, 0.01)      # 2 (0.1 * 0.5 - 0.01) + 0.5
    0.58
    """

    mass: float
    duration: float
    time_step: float
    spring_stiffness: float = 0.0
    drive_velocity: float = 0.0
    offset: float = 0.0
    rate: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0

    def __post_init__(self):
        for item in fields(self):
            value = getattr(self, item.name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer,
                                                                 np.floating)):
                raise InputError(f"The '{item.name}' parameter of the system must be a number. "
                                 f"Got {describe(value)} instead.")
            if not math.isfinite(value):
                raise InputError(f"The '{item.name}' parameter of the system must be finite. "
                                 f"Got {describe(value)} instead.")
            if item.name in _POSITIVE and not value > 0.0:
                raise InputError(f"The '{item.name}' parameter of the system must be positive. "
                                 f"Got {describe(value)} instead.")
            if item.name in _NONNEGATIVE and not value >= 0.0:
                raise InputError(f"The '{item.name}' parameter of the system must be "
                                 f"non-negative. Got {describe(value)} instead.")
            object.__setattr__(self, item.name, float(value))
        if self.time_step > self.duration:
            raise InputError(f"The 'time_step' parameter of the system must not exceed its "
                             f"duration ({self.duration!r}). Got {self.time_step!r} instead.")
        samples = self.duration / self.time_step
        if samples > MAX_SAMPLES:
            raise InputError(f"The 'duration' / 'time_step' of the system asks for {samples:.3g} "
                             f"samples; expected at most {MAX_SAMPLES:.0e} (five arrays of them "
                             f"are kept in memory).")

    @property
    def times(self) -> np.ndarray:
        """The sample times [s]: every ``time_step`` from 0 up to ``duration``."""
        steps = int(math.floor(self.duration / self.time_step * (1.0 + 1e-12)))
        return np.arange(steps + 1, dtype=np.float64) * self.time_step

    def applied_force(self, t, x):
        """F_applied(t, x) [N]: the drive spring's force plus the applied force."""
        t = np.asarray(t, dtype=np.float64)
        force = (self.spring_stiffness * (self.drive_velocity * t - np.asarray(x, np.float64))
                 + self.offset + self.rate * t
                 + self.amplitude * np.sin(2.0 * np.pi * self.frequency * t))
        return float(force) if force.ndim == 0 else force


def load_system(path) -> System:
    """Read a ``[system]`` file (TOML, or JSON; INTERFACE.md) into a :class:`System`.

    Errors raise :class:`polind.InputError` naming the file and the key.
    """
    from polind import io

    table = io.read_system_file(path)
    drive = table.get("spring_drive") or {}
    force = table.get("force") or {}
    return System(mass=table["mass"], duration=table["duration"], time_step=table["time_step"],
                  spring_stiffness=drive.get("stiffness", 0.0),
                  drive_velocity=drive.get("velocity", 0.0),
                  offset=force.get("offset", 0.0), rate=force.get("rate", 0.0),
                  amplitude=force.get("amplitude", 0.0), frequency=force.get("frequency", 0.0))


@dataclass
class SystemResult:
    """The result of :func:`simulate_system`.

    Attributes
    ----------
    t, x, v : ndarray
        Time [s], position [m] and velocity [m/s] of the body at every sample.
    force : ndarray
        Friction force [N] (MODELS.md 0 sign convention).  For a Coulomb or
        Stribeck body at rest it is the static force that holds it.
    applied : ndarray
        F_applied(t, x) [N]: the drive spring's force plus the applied force.
    final_state : State
        The friction model's state at the last sample (pass it to
        :func:`polind.simulate` to continue along a prescribed motion).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    applied: np.ndarray
    final_state: State


# --- packing a model into the kernel's arrays -------------------------------------------

_FAMILY = {"coulomb": kernel.MEMORYLESS, "stribeck": kernel.MEMORYLESS, "dahl": kernel.DAHL,
           "lugre": kernel.LUGRE, "maxwell-slip": kernel.MAXWELL_SLIP, "gms": kernel.GMS,
           "pol-ind": kernel.GMS, "leuven": kernel.LEUVEN}

# The model-state variables in the order the kernel lays them out.
_STATE_KEYS = {kernel.MEMORYLESS: (), kernel.DAHL: ("friction",),
               kernel.LUGRE: ("deflection",), kernel.MAXWELL_SLIP: ("element_force",),
               kernel.GMS: ("element_force", "slip_direction"),
               kernel.LEUVEN: ("element_force", "deflection", "deflection_rate")}


def _stribeck_slots(scalars, coulomb, static, velocity, exponent, shape):
    scalars[kernel.COULOMB] = coulomb
    scalars[kernel.STATIC] = static
    scalars[kernel.STRIBECK_VELOCITY] = velocity
    scalars[kernel.STRIBECK_EXPONENT] = exponent
    scalars[kernel.STRIBECK_SHAPE] = SHAPE_CODES[shape]
    scalars[kernel.FORCE_SCALE] = max(coulomb, static)


def _stribeck_of(p):
    return (p["coulomb_force"], p["static_force"], p["stribeck_velocity"],
            p["stribeck_exponent"], p["stribeck_shape"])


def _element_table(stiffness, capacity, weights=False):
    stiffness = np.asarray(stiffness, dtype=np.float64)
    capacity = np.asarray(capacity, dtype=np.float64)
    table = np.zeros((kernel.N_ELEMENT_ROWS, stiffness.shape[0]))
    table[kernel.ELEMENT_STIFFNESS] = stiffness
    table[kernel.ELEMENT_CAPACITY] = capacity
    if weights:   # an element without load (alpha = 0) never carries force: 1/alpha = inf
        table[kernel.ELEMENT_INVERSE] = np.divide(1.0, capacity, where=capacity > 0.0,
                                                  out=np.full_like(capacity, np.inf))
    return table


def _pack_model(model: FrictionModel):
    """``(family, scalars, elements)``: the model's parameters for the kernel."""
    p = model.params
    if model.type not in _FAMILY:
        raise NotImplementedError(f"simulate_system does not know the '{model.type}' model.")
    family = _FAMILY[model.type]
    scalars = np.zeros(kernel.N_SCALARS)
    elements = np.zeros((kernel.N_ELEMENT_ROWS, 0))
    scalars[kernel.VISCOUS] = p.get("viscous_coefficient", 0.0)
    if model.type == "coulomb":
        # Coulomb is the Stribeck curve with Fs = Fc (g is then constant).
        _stribeck_slots(scalars, p["coulomb_force"], p["coulomb_force"], 1.0, 1.0, "exponential")
    elif model.type in ("stribeck", "lugre"):
        _stribeck_slots(scalars, *_stribeck_of(p))
        scalars[kernel.STIFFNESS] = p.get("bristle_stiffness", 0.0)
        scalars[kernel.DAMPING] = p.get("bristle_damping", 0.0)
    elif model.type == "dahl":
        scalars[kernel.STIFFNESS] = p["stiffness"]
        scalars[kernel.COULOMB] = p["coulomb_force"]
        scalars[kernel.EXPONENT] = p["exponent"]
        scalars[kernel.FORCE_SCALE] = p["coulomb_force"]
    elif model.type == "maxwell-slip":
        elements = _element_table(p["stiffness"], p["breakaway_force"])
        scalars[kernel.FORCE_SCALE] = float(np.sum(p["breakaway_force"]))
    elif model.type in ("gms", "pol-ind"):
        gms = p if model.type == "gms" else model.gms_parameters()
        _stribeck_slots(scalars, *_stribeck_of(gms))
        scalars[kernel.ATTRACTION] = gms["attraction"]
        elements = _element_table(gms["stiffness"], gms["weight"], weights=True)
    else:  # leuven
        _stribeck_slots(scalars, *_stribeck_of(p))
        scalars[kernel.EXPONENT] = p["exponent"]
        scalars[kernel.DAMPING] = p["bristle_damping"]
        elements = _element_table(p["stiffness"], p["breakaway_force"])
    return family, scalars, np.ascontiguousarray(elements)


def _pack_state(family, state: State, n_elements):
    keys = _STATE_KEYS[family]
    parts = [np.asarray(state.variables[key], dtype=np.float64).reshape(-1) for key in keys]
    flat = np.concatenate(parts) if parts else np.zeros(0)
    expected = {kernel.GMS: 2 * n_elements, kernel.MAXWELL_SLIP: n_elements,
                kernel.LEUVEN: n_elements + 2}.get(family, len(keys))
    if flat.shape[0] != expected:  # a model whose state the kernel does not know
        raise RuntimeError(f"simulate_system cannot lay out the state of a {state.model_type} "
                           f"model ({', '.join(state.variables)}).")
    return flat


def _unpack_state(family, flat, state: State):
    offset = 0
    for key in _STATE_KEYS[family]:
        size = np.size(state.variables[key])
        state.variables[key] = np.array(flat[offset:offset + size])
        offset += size


def _finite(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value):
        raise InputError(f"The '{name}' of simulate_system must be a finite number. "
                         f"Got {describe(value)} instead.")
    return float(value)


def simulate_system(model: FrictionModel, system: System, *, initial_position=0.0,
                    initial_velocity=0.0, method="bdf2", progress=None) -> SystemResult:
    """Simulate a body with friction driven by a spring and/or a force (MODELS.md 8).

    Each step moves the body at a constant velocity ``w`` solved from the
    implicit momentum equation, with the friction force at the end of the
    step computed by the model's own exact update at ``w`` (see
    :mod:`polind.kernels.dynamics`): stable for stiff element springs
    (``k h^2 / m`` of 1e6 and more), a body at rest stays exactly at rest
    (only a model's own drift, such as LuGre's, moves it), and a Coulomb or
    Stribeck body sticks exactly while the force on it is at most ``Fs``.

    Parameters
    ----------
    model : FrictionModel
        Any polind model (never mutated); it starts from its virgin state.
        A Pol-Ind model runs at its constant ``normal_load``.
    system : System
        Mass, drive and sampling (:func:`load_system` reads one from a file).
    initial_position : float, default 0
        x at t = 0 [m].
    initial_velocity : float, default 0
        v at t = 0 [m/s].
    method : {"bdf2", "euler"}, default "bdf2"
        The implicit momentum scheme, both L-stable: BDF2, second order (the
        friction's rate terms ``sigma2 v`` and LuGre's ``sigma1 dz/dt`` are
        taken at the body's velocity), or backward Euler, first order (the
        body's velocity is the step velocity ``(x[k] - x[k-1]) / h``).
    progress : callable, optional
        Called as ``progress(done, total)`` (steps) during long runs.

    Returns
    -------
    SystemResult
        ``t, x, v, force, applied`` (float64, one entry per sample) and
        ``final_state``.  The model state follows the body's path ``x``
        exactly as in ``polind.simulate(model, t, x=x)``; with
        ``method="euler"`` the forces of the models with state are equal to
        its forces from ``force[1]`` on.  ``force[0]`` is the model's force
        at its initial state and the initial velocity.

    Examples
    --------
    >>> import polind
    >>> from polind.dynamics import System, simulate_system
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    >>> system = System(mass=1.0, duration=10.0, time_step=0.01, spring_stiffness=2.0,
    ...                 drive_velocity=0.1)
    >>> res = simulate_system(model, system)
    >>> float(res.x[res.t < 4.9].max())   # stuck while 0.2 t < 1 N: not a nanometre of creep
    0.0
    """
    if not isinstance(model, FrictionModel):
        raise InputError(f"The 'model' must be a polind friction model (load_model or "
                         f"model_from_dict). Got {describe(model)} instead.")
    if not isinstance(system, System):
        raise InputError(f"The 'system' must be a polind.System (or load_system's result). "
                         f"Got {describe(system)} instead.")
    if method not in METHODS:
        raise InputError(f"The 'method' of simulate_system must be one of 'bdf2', 'euler'. "
                         f"Got {describe(method)} instead.")
    x0 = _finite("initial_position", initial_position)
    v0 = _finite("initial_velocity", initial_velocity)
    family, scalars, elements = _pack_model(model)
    final_state = model.initial_state()
    state = _pack_state(family, final_state, elements.shape[1])

    t = system.times
    n = t.shape[0]
    x = np.empty(n)
    v = np.empty(n)
    force = np.empty(n)
    applied = np.empty(n)
    x[0], v[0] = x0, v0
    applied[0] = system.applied_force(t[0], x0)
    # The model's own force at its initial state and velocity (INTERFACE.md sample 0).
    force[0] = simulate(model, t[:2], v=np.array([v0, v0])).force[0]
    if family == kernel.MEMORYLESS and v0 == 0.0:
        static = scalars[kernel.STATIC]
        force[0] = min(max(applied[0], -static), static)

    carry = np.array([v0, 0.0])
    for start in range(1, n, _CHUNK):
        stop = min(start + _CHUNK, n)
        kernel.integrate_system(family, scalars, elements, state, t, system.mass,
                                system.spring_stiffness, system.drive_velocity, system.offset,
                                system.rate, system.amplitude, system.frequency, METHODS[method],
                                x, v, force, applied, start, stop, carry)
        if progress is not None:
            progress(stop - 1, n - 1)

    _unpack_state(family, state, final_state)
    final_state.time = float(t[-1])
    final_state.position = float(x[-1])
    final_state.velocity = float(v[-1])
    final_state.force = float(force[-1])
    return SystemResult(t=t, x=x, v=v, force=force, applied=applied, final_state=final_state)
