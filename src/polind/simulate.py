"""Prescribed motion: :func:`simulate` (INTERFACE.md, Python).

One contract serves every model.  The motion is validated here, cut into
steps at constant velocity (:class:`~polind.models.base.Path`), and handed
to the model's kernel; this module owns the bookkeeping (continuation from
a saved state, the force at the first sample, the final state).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe
from polind.models import FrictionModel, Path, State

__all__ = ["SimulationResult", "simulate", "as_samples", "warn_ignored_load", "CHUNK"]

#: Samples per kernel call in a long run (bounded memory per call, progress between calls).
CHUNK = 1 << 18


@dataclass
class SimulationResult:
    """The result of :func:`simulate`: samples and the state to continue from.

    Attributes
    ----------
    t, x, v, force : ndarray
        Time [s], displacement [m], velocity [m/s] and friction force [N] at
        every sample, float64, same length.
    normal_load : ndarray or None
        The normal load [N] used at every sample (None when none was given
        or the model ignores it).
    final_state : State
        Pass it as ``state=`` to continue the run.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    final_state: State
    normal_load: np.ndarray | None = None


def _converted(name, values, length=None):
    """A 1-D float64 copy of ``values`` of the given length; InputError naming ``name`` otherwise."""
    try:
        if np.iscomplexobj(values):
            raise TypeError("complex")
        array = np.array(values, dtype=np.float64, copy=True)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"The '{name}' samples must be numbers. Got {describe(values)} "
                         "instead.") from None
    if array.ndim != 1:
        raise InputError(f"The '{name}' samples must be a 1-D array. Got shape {array.shape} "
                         "instead.")
    if length is not None and array.shape[0] != length:
        raise InputError(f"The '{name}' samples must have the length of 't' ({length}). "
                         f"Got {array.shape[0]} instead.")
    return array


def _not_finite(name, array, index):
    return InputError(f"The '{name}' samples must be finite. Got {float(array[index])!r} at "
                      f"index {index} instead.")


def as_samples(name, values, length=None, *, positive=False):
    """A finite 1-D float64 copy of ``values``; InputError naming ``name`` otherwise."""
    array = _converted(name, values, length)
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise _not_finite(name, array, bad[0])
    if positive:
        bad = np.flatnonzero(array <= 0.0)
        if bad.size:
            raise InputError(f"The '{name}' samples must be positive. Got {float(array[bad[0]])!r} at "
                             f"index {bad[0]} instead.")
    return array


def warn_ignored_load(model) -> None:
    """Say (a ``UserWarning``, once per place in the caller's code) that a load signal is ignored."""
    import warnings

    warnings.warn(f"The {model.type} model ignores the normal-load signal: give it a "
                  f"'reference_load' (N) to scale its friction with the load.", UserWarning,
                  stacklevel=3)


def _time(t):
    """The sample times: finite, at least 2, strictly increasing (one compiled pass)."""
    from polind.kernels.contract import NOT_FINITE, NOT_INCREASING, check_times

    t = _converted("t", t)
    code, k = check_times(t)
    if code == NOT_FINITE:
        raise _not_finite("t", t, k)
    if t.shape[0] < 2:
        raise InputError(f"The 't' samples must have at least 2 entries. Got {t.shape[0]} "
                         "instead.")
    if code == NOT_INCREASING:
        raise InputError(f"The 't' samples must be strictly increasing. Got t[{k}] = "
                         f"{float(t[k])!r} after t[{k - 1}] = {float(t[k - 1])!r}.")
    return t


def _check_continuation(state, t, x, v):
    """A chunk continues a state only from the state's own last sample (INTERFACE.md)."""
    def same(a, b):
        return a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b))

    t0 = float(np.asarray(t, dtype=np.float64).reshape(-1)[0])
    if not same(t0, state.time):
        raise InputError(f"The 't' samples of a continued run must start at the state's time "
                         f"{state.time!r} (repeat the previous last sample). Got t[0] = {t0!r}.")
    if x is not None:
        x0 = float(np.asarray(x, dtype=np.float64).reshape(-1)[0])
        if not same(x0, state.position):
            raise InputError(f"The 'x' samples of a continued run must start at the state's "
                             f"position {state.position!r}. Got x[0] = {x0!r}.")
    else:
        v0 = float(np.asarray(v, dtype=np.float64).reshape(-1)[0])
        if not same(v0, state.velocity):
            raise InputError(f"The 'v' samples of a continued run must start at the state's "
                             f"velocity {state.velocity!r}. Got v[0] = {v0!r}.")


def make_path(t, x=None, v=None, state=None) -> Path:
    """Cut a prescribed motion into steps at constant velocity (INTERFACE.md).

    With ``x``: the path is linear between samples; the step ending at
    sample k has velocity ``(x[k] - x[k-1]) / (t[k] - t[k-1])``, which is
    also ``v[k]``; ``v[0]`` is the first step's (or, when continuing, the
    velocity of the state's last step).  With ``v``: each step's velocity is
    the mean of its end samples and ``x`` the trapezoidal integral from 0 (or
    from the state's position).
    """
    if (x is None) == (v is None):
        raise InputError("Give exactly one of 'x' (displacement) and 'v' (velocity). Got "
                         + ("both." if x is not None else "neither."))
    from polind.kernels.contract import NOT_FINITE, OVERFLOW, cut_path

    t = _time(t)
    n = t.shape[0]
    name = "x" if x is not None else "v"
    motion = _converted(name, x if x is not None else v, n)
    step, displacement, step_velocity = np.empty(n), np.empty(n), np.empty(n)
    if x is not None:
        x, sample_velocity = motion, np.empty(n)
    else:
        x, sample_velocity = np.empty(n), motion
    code, index = cut_path(t, motion, x is not motion, 0.0 if state is None else state.position,
                           0.0 if state is None else state.velocity, state is not None, step,
                           displacement, step_velocity, sample_velocity, x)
    if code == NOT_FINITE:
        raise _not_finite(name, motion, index)
    if code == OVERFLOW:
        what = "step velocities" if name == "x" else "integrated displacements"
        raise InputError(f"The '{name}' samples overflow: their {what} are not finite from "
                         f"index {index} on. Use SI units (m, m/s, s) of a physical size.")
    return Path(t=t, x=x, step=step, displacement=displacement, step_velocity=step_velocity,
                sample_velocity=sample_velocity)


def simulate(model: FrictionModel, t, x=None, v=None, *, normal_load=None,
             state: State | None = None, progress=None) -> SimulationResult:
    """Simulate a friction model along a prescribed motion.

    Parameters
    ----------
    model : FrictionModel
        From :func:`polind.load_model` or :func:`polind.model_from_dict`;
        never mutated.
    t : array_like
        Sample times [s], strictly increasing, finite, at least 2.
    x, v : array_like
        Exactly one: displacement [m] (linear between samples) or velocity
        [m/s] (trapezoidal).
    normal_load : array_like, optional
        Normal load [N] at every sample, positive.  ``pol-ind`` uses it
        through its contact mechanics; any other model scales its force by
        ``N / reference_load`` (the load-proportional form of the user guide)
        when it has a ``reference_load``, and otherwise ignores it with a
        ``UserWarning``.  Without it the model's own constant load applies.
    state : State, optional
        A previous result's ``final_state``.  Start the chunk with the
        previous chunk's last sample repeated; the force there equals the
        previous last force, and the split run equals one run (to
        floating-point reassociation).  ``t[0]`` must be the state's time
        and ``x[0]`` its position (or ``v[0]`` its velocity).
    progress : callable, optional
        ``progress(done, total)`` [samples], called as the run advances
        (polind runs long motions in fixed chunks of :data:`CHUNK` samples
        whether or not a callback is given, so results do not depend on it).

    Returns
    -------
    SimulationResult

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                           "coulomb_force": 1.0}})
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> res = polind.simulate(model, t, x=1e-4 * t)
    >>> bool(abs(res.force[-1] - (1 - np.exp(-10.0))) < 1e-12)
    True
    """
    if not isinstance(model, FrictionModel):
        raise InputError(f"The 'model' must be a polind friction model (load_model or "
                         f"model_from_dict). Got {describe(model)} instead.")
    if state is not None:
        if not isinstance(state, State):
            raise InputError(f"The 'state' must be a polind State (a result's final_state or "
                             f"State.from_dict). Got {describe(state)} instead.")
        model.check_state(state)
    path = make_path(t, x, v, state)
    if state is not None:
        _check_continuation(state, path.t, x, v)
    load = None
    if normal_load is not None:
        load = as_samples("normal_load", normal_load, path.t.shape[0], positive=True)
        if not model.uses_normal_load:
            warn_ignored_load(model)
            load = None
    run_state = state.copy() if state is not None else model.initial_state(load)
    if load is not None:
        model.check_loads(load, run_state)
    force = _advance_in_chunks(model, path, run_state, load, progress)
    if state is not None:
        force[0] = state.force
    run_state.time = float(path.t[-1])
    run_state.position = float(path.x[-1])
    run_state.velocity = float(path.sample_velocity[-1])
    run_state.force = float(force[-1])
    return SimulationResult(t=path.t, x=path.x, v=path.sample_velocity, force=force,
                            final_state=run_state, normal_load=load)


def _advance_in_chunks(model, path, state, load, progress):
    """Run the model's step over the path in chunks of CHUNK samples; return the forces.

    The kernel runs once per chunk on the same arrays (a chunk starts at the
    previous chunk's last sample), so the chunking never changes a result.
    """
    kernel = model.step_kernel(state, load)
    n = path.t.shape[0]
    force = np.empty(n)
    lo = 0
    while True:
        hi = min(lo + CHUNK, n)
        kernel.run(path.step, path.displacement, path.step_velocity, path.sample_velocity, load,
                   lo, hi, lo == 0, force)
        if progress is not None:
            progress(hi, n)
        if hi == n:
            break
        lo = hi - 1
    model.unflatten_state(kernel.state, state)
    return force
