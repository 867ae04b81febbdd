"""One-degree-of-freedom systems (:ref:`guide-systems`): :func:`simulate_system`.

A body of mass ``m`` driven by a spring ``k_d`` pulled at ``v_d`` and/or an
applied force, against the friction force ``F`` of any polind model::

    m a = k_d (v_d t - x) + offset + rate t + amplitude sin(2 pi frequency t) - F

This module validates the system (one validator for a :class:`System` built
in Python and for a ``[system]`` file, driven by the declarations of
:data:`FILE_KEYS`), packs the model's parameters and state into
the flat arrays of :mod:`polind.kernels.dynamics` (which holds the integrator
and explains the scheme) and wraps the result.  The friction force of the
result is the model's own along the body's path: the model state is advanced
exactly as ``polind.simulate(model, res.t, x=res.x)`` advances it, and with
``method="euler"`` the forces are equal from the second sample on.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, fields

import numpy as np

from polind.errors import InputError, describe
from polind.kernels import dynamics as dynamics_kernel
from polind.models import FrictionModel, State
from polind.simulation import as_samples, check_finite_output, summary_repr
from polind.validation import check_number

__all__ = ["System", "SystemResult", "load_system", "simulate_system"]

METHODS = {"bdf2": dynamics_kernel.BDF2, "euler": dynamics_kernel.EULER}

# Steps per kernel call: long runs report progress between chunks.
_CHUNK = 1 << 16


@dataclass(frozen=True)
class _Key:
    """A key of a ``[system]`` file: the :class:`System` field it sets, the range of its
    value (a bound of :func:`polind.validation.check_number`) and whether a file that
    has the key's table must give it (else it takes the field's default)."""

    field: str
    bound: str = "any"
    required: bool = False


#: The declarations every check of a system follows, keyed by the ``[system]`` file's
#: dotted key (``spring_drive.stiffness`` is ``[system.spring_drive] stiffness``).
_KEYS = {
    "mass": _Key("mass", "positive", required=True),
    "duration": _Key("duration", "positive", required=True),
    "time_step": _Key("time_step", "positive", required=True),
    "spring_drive.stiffness": _Key("spring_stiffness", "nonnegative", required=True),
    "spring_drive.velocity": _Key("drive_velocity", required=True),
    "force.offset": _Key("offset"),
    "force.rate": _Key("rate"),
    "force.amplitude": _Key("amplitude"),
    "force.frequency": _Key("frequency", "nonnegative"),
}
#: The drive tables of a ``[system]`` file; a file needs at least one.
_DRIVES = ("spring_drive", "force")


def _owner(key) -> str:
    """Who a value belongs to in a message: the system, and the file key when it differs."""
    field = _KEYS[key].field
    return "the system" if field == key else f"the system (key '{key}' of a [system] file)"


#: What a system run keeps per sample: t, x, v, F and F_applied (float64) [bytes].
BYTES_PER_SAMPLE = 40


@dataclass(frozen=True)
class System:
    """A one-degree-of-freedom system (:ref:`guide-systems`; the ``[system]`` file, :ref:`formats-system`).

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
        # The one check of every value, whether it came from Python or from a file.
        for key, declared in _KEYS.items():
            value = check_number(_owner(key), declared.field, getattr(self, declared.field),
                                 declared.bound)
            object.__setattr__(self, declared.field, value)
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
FILE_KEYS = {key: declared.field for key, declared in _KEYS.items()}


class _Missing:
    """The value of a required key a file does not give (refused by :func:`system_from_keys`)."""

    def __repr__(self):
        return "<missing>"


_MISSING = _Missing()


def system_from_keys(values) -> System:
    """A :class:`System` from dotted ``[system]`` file keys (:data:`FILE_KEYS`).

    The keys a file has (:func:`file_keys_of`): each known, the required
    ones given, a drive table present; absent optional keys default.  Each
    value is then checked by :class:`System`, so that a value gets the same
    message from a file as from Python.
    """
    for key, value in values.items():
        if key in _DRIVES:
            raise InputError(f"The '{key}' table of [system] must be a table of keys "
                             f"([system.{key}]). Got {describe(value)} instead.")
        if key not in _KEYS:
            raise InputError(f"Unknown key '{key}' in [system]; expected one of: "
                             f"{', '.join(_KEYS)}.")
    tables = {key.rpartition(".")[0] for key in values} - {""}
    for key, declared in _KEYS.items():
        table = key.rpartition(".")[0]
        if declared.required and (not table or table in tables) \
                and values.get(key, _MISSING) is _MISSING:
            raise InputError(f"Missing key '{key}' in [system].")
    if not tables & set(_DRIVES):
        raise InputError("The [system] table has no drive; expected a [system.spring_drive] "
                         "or a [system.force] table (or both).")
    return System(**{_KEYS[key].field: value for key, value in values.items()})


def load_system(path) -> System:
    """Read a ``[system]`` file (TOML, or JSON; :ref:`formats-system`) into a :class:`System`.

    Errors raise :class:`polind.InputError` naming the file and the key; a
    bad value has the message :class:`System` gives in Python, after the
    file's name.
    """
    from polind import io

    table = io.read_system_file(path)
    try:
        return system_from_keys(file_keys_of(table))
    except InputError as error:
        raise InputError(f"{os.fspath(path)}: {error}") from None


def file_keys_of(table) -> dict:
    """The dotted keys of a ``[system]`` table as :func:`polind.io.read_system_file` reads it.

    Nothing is checked here (:func:`system_from_keys` does).  The keys of
    the tables the file has, each sub-table's keys dotted, with the
    defaults of that table's absent optional keys (a key of an absent table
    is not there to set); a sub-table that is not a table stays one key.
    Integers are floats, as a :class:`System` holds them.
    """
    values = {}
    for key, value in table.items():
        if key in _DRIVES and isinstance(value, dict):
            values.update({f"{key}.{inner}": _float(item) for inner, item in value.items()})
        else:
            values[key] = value if key in _DRIVES else _float(value)
    defaults = {item.name: item.default for item in fields(System)}
    for key, declared in _KEYS.items():
        table_name, dotted, _ = key.rpartition(".")
        if key not in values and (not dotted or isinstance(table.get(table_name), dict)):
            values[key] = _MISSING if declared.required else defaults[declared.field]
    return values


def _float(value):
    """A TOML integer as a float (a bigger one than a float holds is left for the check)."""
    if isinstance(value, int) and not isinstance(value, bool):
        try:
            return float(value)
        except OverflowError:
            return value
    return value


@dataclass
class SystemResult:
    """The result of :func:`simulate_system`.

    Attributes
    ----------
    t, x, v : ndarray
        Time [s], position [m] and velocity [m/s] of the body at every sample.
    force : ndarray
        Friction force [N] (the sign convention of :ref:`guide-conventions`).  For a Coulomb or
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

    def __repr__(self):
        return summary_repr(self, {"x": "m", "v": "m/s", "force": "N", "applied": "N"})


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
    """Simulate a body with friction driven by a spring and/or a force (:ref:`guide-systems`).

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
    kernel = model.step_kernel(final_state, fixed_load=True)

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
    check_finite_output(model, t, (("friction force", force), ("position", x),
                                   ("velocity", v)))
    return SystemResult(t=t, x=x, v=v, force=force, applied=applied, final_state=final_state)
