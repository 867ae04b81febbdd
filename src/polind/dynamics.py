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
from polind.kernels import dynamics as dynamics_kernel
from polind.models import FrictionModel, State
from polind.simulate import as_samples

__all__ = ["System", "SystemResult", "load_system", "simulate_system"]

METHODS = {"bdf2": dynamics_kernel.BDF2, "euler": dynamics_kernel.EULER}

# Steps per kernel call: long runs report progress between chunks.
_CHUNK = 1 << 16

_POSITIVE = ("mass", "duration", "time_step")
_NONNEGATIVE = ("spring_stiffness", "frequency")


#: What a system run keeps per sample: t, x, v, F and F_applied (float64) [bytes].
BYTES_PER_SAMPLE = 40


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
        from polind.resources import check_memory
        check_memory(samples * BYTES_PER_SAMPLE,
                     f"The system's duration / time_step ({samples:.3g} samples)")

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


#: The keys of a ``[system]`` file (dotted: ``spring_drive.stiffness`` is
#: ``[system.spring_drive] stiffness``) and the :class:`System` field each sets.
FILE_KEYS = {
    "mass": "mass", "duration": "duration", "time_step": "time_step",
    "spring_drive.stiffness": "spring_stiffness", "spring_drive.velocity": "drive_velocity",
    "force.offset": "offset", "force.rate": "rate", "force.amplitude": "amplitude",
    "force.frequency": "frequency",
}


def system_from_keys(values) -> System:
    """A :class:`System` from dotted ``[system]`` file keys (:data:`FILE_KEYS`); absent keys default."""
    return System(**{FILE_KEYS[key]: value for key, value in values.items()})


def load_system(path) -> System:
    """Read a ``[system]`` file (TOML, or JSON; INTERFACE.md) into a :class:`System`.

    Errors raise :class:`polind.InputError` naming the file and the key.
    """
    from polind import io

    return system_from_keys(file_keys_of(io.read_system_file(path)))


def file_keys_of(table) -> dict:
    """The dotted keys of a system as :func:`polind.io.read_system_file` reads it.

    Only the keys of the tables the file has (a key of an absent table is not
    there to set).
    """
    values = {key: table[key] for key in ("mass", "duration", "time_step")}
    for name in ("spring_drive", "force"):
        values.update({f"{name}.{key}": value for key, value in (table.get(name) or {}).items()})
    return values


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


def initial_friction(kernel, velocity, applied):
    """The friction force at the first sample: the model's force at its state and velocity.

    A memoryless model at rest holds the applied force up to its
    ``rest_capacity`` (its friction is set-valued there).
    """
    if kernel.rest_capacity is not None and velocity == 0.0:
        return min(max(applied, -kernel.rest_capacity), kernel.rest_capacity)
    return kernel.first_force(velocity)


def _finite(name, value):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value):
        raise InputError(f"The '{name}' of simulate_system must be a finite number. "
                         f"Got {describe(value)} instead.")
    return float(value)


def simulate_system(model: FrictionModel, system: System, *, applied=None, initial_position=0.0,
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
    applied : array_like, optional
        Applied force [N] of every step, held over the step (length: the
        number of samples less one), in place of the system's drive spring
        and force: the run is then the same as a :class:`polind.Body` stepped
        with these forces.  ``res.applied[k]`` is the force applied from
        sample ``k`` on.
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
    t = system.times
    n = t.shape[0]
    applied_steps = np.zeros(0)
    if applied is not None:
        applied_steps = as_samples("applied", applied, n - 1)
    final_state = model.initial_state()
    kernel = model.step_kernel(final_state)

    x = np.empty(n)
    v = np.empty(n)
    force = np.empty(n)
    applied_out = np.empty(n)
    x[0], v[0] = x0, v0
    applied_out[0] = applied_steps[0] if applied is not None else system.applied_force(t[0], x0)
    force[0] = initial_friction(kernel, v0, applied_out[0])

    drive = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0) if applied is not None else (
        system.spring_stiffness, system.drive_velocity, system.offset, system.rate,
        system.amplitude, system.frequency)
    carry = np.array([v0, 0.0])
    memoryless = kernel.rest_capacity is not None
    for start in range(1, n, _CHUNK):
        stop = min(start + _CHUNK, n)
        kernel.integrate_system(
            memoryless, kernel.rest_capacity if memoryless else 0.0, kernel.force_scale,
            kernel.scalars, kernel.table, kernel.state, t, system.mass, *drive, applied_steps,
            METHODS[method], kernel.normal_load, x, v, force, applied_out, start, stop, carry)
        if progress is not None:
            progress(stop - 1, n - 1)

    model.unflatten_state(kernel.state, final_state)
    final_state.time = float(t[-1])
    final_state.position = float(x[-1])
    final_state.velocity = float(v[-1])
    final_state.force = float(force[-1])
    applied = applied_out
    return SystemResult(t=t, x=x, v=v, force=force, applied=applied, final_state=final_state)
