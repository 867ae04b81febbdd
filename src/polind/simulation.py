"""Prescribed motion: :func:`simulate` (the user guide, :ref:`guide-simulate`).

One contract serves every model.  The motion is validated here, cut into
steps at constant velocity (:class:`~polind.models.state.Path`), and handed
to the model's kernel; this module owns the bookkeeping (continuation from
a saved state, the force at the first sample, the final state).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe
from polind.models import FrictionModel, Path, State

__all__ = ["SimulationResult", "simulate", "as_samples", "check_finite_output",
           "warn_ignored_load", "summary_repr", "CHUNK", "BYTES_PER_SAMPLE"]

#: Samples between two progress reports of a long run.
CHUNK = 1 << 18

#: What :func:`simulate` allocates per sample beyond its inputs: t, the motion, the other
#: of x and v, and the force (float64) [bytes].
BYTES_PER_SAMPLE = 32

# Samples per block of step arrays for a mounted model (series spring, load scaling): its
# runs cut the motion into steps one block at a time (the kernel's state carries over), so
# that they hold those arrays for a block, not a run.  Other models need no step arrays.
_BLOCK = 1 << 15


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
        or the model ignores it): the array given, not a copy, when it is
        already a writeable 1-D float64 array.
    final_state : State
        Pass it as ``state=`` to continue the run.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    final_state: State
    normal_load: np.ndarray | None = None

    def __repr__(self):
        return summary_repr(self, {"x": "m", "v": "m/s", "force": "N", "normal_load": "N"})

    def columns(self) -> dict:
        """The samples as ``{"t", "x", "v", "F"}`` arrays: the columns of ``polind simulate``'s
        output (:ref:`formats-results`)."""
        return {"t": self.t, "x": self.x, "v": self.v, "F": self.force}

    def to_frame(self):
        """The samples as a pandas ``DataFrame`` with the columns ``t, x, v, F`` (SI units).

        The columns of ``polind simulate``'s output; pandas is imported here.

        Examples
        --------
        >>> import numpy as np, polind
        >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
        >>> res = polind.simulate(model, np.linspace(0.0, 1.0, 5), v=np.full(5, 1e-3))
        >>> res.to_frame().columns.tolist()
        ['t', 'x', 'v', 'F']
        """
        import pandas

        return pandas.DataFrame(self.columns())

    def to_csv(self, path, progress=None) -> None:
        """Write the samples as ``polind simulate`` does: the header ``t,x,v,F``, full precision.

        Parameters
        ----------
        path : str or os.PathLike
            CSV, or Parquet when the name ends in ``.parquet``; ``-`` is
            standard output.  Written atomically (:func:`polind.io.write_csv_atomic`):
            a directory is refused, an existing file is replaced only once the
            whole table is on disk.
        progress : callable, optional
            ``progress(done, total)`` [rows].
        """
        from polind.io import write_csv_atomic

        write_csv_atomic(path, self.columns(), progress=progress)


def _span(values, unit) -> str:
    """``lo .. hi unit`` of an array (its one value if constant), 4 significant digits."""
    array = np.asarray(values, dtype=np.float64).reshape(-1)
    if array.size == 0:
        return "empty"
    low, high = float(np.min(array)), float(np.max(array))
    text = f"{low:.4g}" if low == high else f"{low:.4g} .. {high:.4g}"
    return f"{text} {unit}".rstrip()


def summary_repr(result, units: dict) -> str:
    """A short repr of a result of samples: the sample count, the range of each array, the
    final state in one phrase -- never the arrays themselves.

    ``units`` maps the result's array attributes (after ``t``) to their units; an
    attribute that is None is left out.
    """
    t = np.asarray(result.t).reshape(-1)
    parts = [f"{t.size} samples", f"t {_span(t, 's')}"]
    parts += [f"{name} {_span(value, unit)}" for name, unit in units.items()
              if (value := getattr(result, name, None)) is not None]
    state = getattr(result, "final_state", None)
    if state is not None:
        count = sum(np.size(value) for value in state.variables.values())
        parts.append(f"final_state {state.model_type} at t = {state.time:.6g} s "
                     f"({count} internal values)")
    return f"{type(result).__name__}({', '.join(parts)})"


def _converted(name, values, length=None, copy=True):
    """A 1-D float64 copy of ``values`` of the given length; InputError naming ``name`` otherwise.

    With ``copy=False`` a writeable C-contiguous float64 array is taken as it is.
    """
    try:
        if np.iscomplexobj(values):
            raise TypeError("complex")
        if copy:
            array = np.array(values, dtype=np.float64, copy=True)
        else:
            array = np.asarray(values, dtype=np.float64)
            if not (array.flags.c_contiguous and array.flags.writeable):
                array = array.copy()
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


def as_samples(name, values, length=None, *, positive=False, copy=True):
    """A finite 1-D float64 copy of ``values``; InputError naming ``name`` otherwise.

    With ``copy=False`` a writeable C-contiguous float64 array is checked and returned as it is.
    """
    array = _converted(name, values, length, copy)
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


def sample_times(t):
    """The sample times as a float64 copy: finite, at least 2, strictly increasing.

    InputError naming the first bad sample otherwise (every driver's check of ``t``).
    """
    return _check_time(_converted("t", t))



def _check_time(t):
    """``t`` if finite, at least 2 and strictly increasing; InputError naming the first bad one."""
    from polind.kernels.contract import NOT_FINITE, NOT_INCREASING, check_times

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
    """A chunk continues a state only from the state's own last sample (:ref:`guide-states`)."""
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


class _SteppedMotion:
    """A prescribed motion, validated and cut into steps at constant velocity a block at a time.

    ``t``, ``x`` and ``sample_velocity`` cover every sample (``x`` or
    ``sample_velocity`` is the converted motion itself).  The step arrays
    ``step``, ``displacement`` and ``step_velocity`` hold one block of
    ``block`` samples: after :meth:`cut` ``(lo, hi)``, entry ``k`` is the step
    that ends at sample ``lo + k``.  A run that walks the blocks in order holds
    three arrays of a block, not of every sample; with ``block=None`` one block
    covers the whole motion (:func:`make_path`).  Constructing it cuts every
    block once, so that a bad motion is refused before anything runs.

    With ``validate=False`` nothing is copied or checked yet: ``source_t``
    and ``source_motion`` are the given arrays (converted only if they are
    not C-contiguous float64 already), and a fused run
    (:func:`polind.kernels.contract.run_motion`) copies them into ``t`` and
    the motion as it checks and runs them, in one pass; :meth:`refuse` then
    names the first error as a full check would.  :meth:`materialise` does
    the copy and the time check at once instead (before cutting blocks).
    """

    def __init__(self, t, x=None, v=None, state=None, block=None, validate=True):
        if (x is None) == (v is None):
            raise InputError("Give exactly one of 'x' (displacement) and 'v' (velocity). Got "
                             + ("both." if x is not None else "neither."))
        self.name = "x" if x is not None else "v"
        given = x if x is not None else v
        if validate:
            self.t = sample_times(t)
            n = self.t.shape[0]
            self.motion = _converted(self.name, given, n)
            self.source_t, self.source_motion = self.t, self.motion
        else:
            self.source_t = _converted("t", t, copy=False)
            n = self.source_t.shape[0]
            if n < 2:
                _check_time(self.source_t)              # its own message
            self.source_motion = _converted(self.name, given, n, copy=False)
            # A source converted here is the run's own copy already.
            self.t = self.source_t if self.source_t is not t else np.empty(n)
            self.motion = self.source_motion if self.source_motion is not given else np.empty(n)
        self.by_velocity = x is None
        if self.by_velocity:
            self.x, self.sample_velocity = np.empty(n), self.motion
        else:
            self.x, self.sample_velocity = self.motion, np.empty(n)
        self._start = (0.0 if state is None else state.position,
                       0.0 if state is None else state.velocity, state is not None)
        self._checked = validate
        if validate:
            self.cut_in_blocks(block)

    def materialise(self):
        """Copy the sources of a ``validate=False`` motion now and check its times."""
        if self._checked:
            return
        if self.t is not self.source_t:
            np.copyto(self.t, self.source_t)
        if self.motion is not self.source_motion:
            np.copyto(self.motion, self.source_motion)
        _check_time(self.t)
        self.source_t, self.source_motion = self.t, self.motion
        self._checked = True

    def cut_in_blocks(self, block=None):
        """Allocate the step arrays of one block and check the whole motion by cutting it."""
        n = self.t.shape[0]
        self.block = n if block is None else min(block, n)
        self.step = np.empty(self.block)
        self.displacement = np.empty(self.block)
        self.step_velocity = np.empty(self.block)
        self._check()

    def blocks(self, lo, hi):
        """``(a, b)`` bounds of the blocks over samples ``lo .. hi - 1``, each starting at the
        previous block's last sample."""
        while True:
            b = min(lo + self.block, hi)
            yield lo, b
            if b >= hi:
                return
            lo = b - 1

    def cut(self, lo, hi):
        """Fill the step arrays for samples ``lo .. hi - 1`` (and ``x``, ``sample_velocity``
        there); return ``cut_path``'s code and the sample it names."""
        from polind.kernels.contract import cut_path

        if lo == 0:
            position, velocity, continuing = self._start
        else:       # continue from the previous block's last sample, as one pass would
            position, velocity, continuing = self.x[lo], self.sample_velocity[lo], True
        m = hi - lo
        code, index = cut_path(self.t[lo:hi], self.motion[lo:hi], self.by_velocity, position,
                               velocity, continuing, self.step[:m], self.displacement[:m],
                               self.step_velocity[:m], self.sample_velocity[lo:hi],
                               self.x[lo:hi])
        return code, lo + index

    def _check(self):
        """The first non-finite motion sample, else the first overflow, is an InputError."""
        from polind.kernels.contract import NOT_FINITE, OVERFLOW

        overflow = None
        for lo, hi in self.blocks(0, self.t.shape[0]):
            code, index = self.cut(lo, hi)
            if code == NOT_FINITE:       # every earlier sample is finite: the first one
                raise _not_finite(self.name, self.motion, index)
            if code == OVERFLOW and overflow is None:
                overflow = index
        if overflow is not None:
            self.refuse(OVERFLOW, overflow)

    def refuse(self, code, index):
        """The InputError of a bad motion found at ``index`` (:func:`cut_path`'s codes).

        A non-finite sample later than an overflow is named first, as one
        pass that checks every sample before the steps would.
        """
        from polind.kernels.contract import BAD_TIME, NOT_FINITE

        motion = self.source_motion
        if not self._checked:              # a fused run stopped: the times come first
            _check_time(self.source_t)
            if code == BAD_TIME:            # cannot happen: check_times agrees with run_motion
                raise InputError(f"The 't' samples are not valid at index {index}.")
        bad = np.flatnonzero(~np.isfinite(motion))
        if code == NOT_FINITE or bad.size:
            raise _not_finite(self.name, motion, bad[0] if bad.size else index)
        what = "step velocities" if self.name == "x" else "integrated displacements"
        raise InputError(f"The '{self.name}' samples overflow: their {what} are not finite "
                         f"from index {index} on. Use SI units (m, m/s, s) of a physical "
                         f"size.")


def make_path(t, x=None, v=None, state=None) -> Path:
    """Cut a prescribed motion into steps at constant velocity (:ref:`guide-simulate-path`).

    With ``x``: the path is linear between samples; the step ending at
    sample k has velocity ``(x[k] - x[k-1]) / (t[k] - t[k-1])``, which is
    also ``v[k]``; ``v[0]`` is the first step's (or, when continuing, the
    velocity of the state's last step).  With ``v``: each step's velocity is
    the mean of its end samples and ``x`` the trapezoidal integral from 0 (or
    from the state's position).
    """
    motion = _SteppedMotion(t, x, v, state)
    return Path(t=motion.t, x=motion.x, step=motion.step, displacement=motion.displacement,
                step_velocity=motion.step_velocity, sample_velocity=motion.sample_velocity)


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
        (polind runs long motions in fixed chunks of :data:`~polind.simulation.CHUNK` samples
        whether or not a callback is given, so results do not depend on it).

    Returns
    -------
    SimulationResult

    Raises
    ------
    InputError
        A bad argument, naming it; a motion whose ``BYTES_PER_SAMPLE``
        per sample would pass the memory limit (:mod:`polind.resources`),
        before anything is allocated; forces that are not all finite
        (``polind.simulation.check_finite_output``, naming the model and the first
        sample).

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
    # Memory: t, x, v and the forces (32 bytes a sample), the load given, and (a
    # mounted model only) step arrays for one block of samples.
    _check_memory(t)
    path = _SteppedMotion(t, x, v, state, validate=False)
    if state is not None:
        path.materialise()
        given = path.motion
        _check_continuation(state, path.t, given if x is not None else None,
                            given if x is None else None)
    load = None
    if normal_load is not None:
        load = as_samples("normal_load", normal_load, path.t.shape[0], positive=True,
                          copy=False)
        if not model.uses_normal_load:
            warn_ignored_load(model)
            load = None
    run_state = state.copy() if state is not None else model.initial_state(load)
    if load is not None:
        model.check_loads(load, run_state)
    force = _advance_in_chunks(model, path, run_state, load, progress)
    if state is not None:
        force[0] = state.force
    check_finite_output(model, path.t, (("friction force", force),))
    run_state.time = float(path.t[-1])
    run_state.position = float(path.x[-1])
    run_state.velocity = float(path.sample_velocity[-1])
    run_state.force = float(force[-1])
    return SimulationResult(t=path.t, x=path.x, v=path.sample_velocity, force=force,
                            final_state=run_state, normal_load=load)


def check_finite_output(model, t, quantities) -> None:
    """Refuse a run whose output is not all finite, whoever wrote the model.

    The one check of every run's output (one ``np.isfinite`` over each
    array): polind's own models give finite forces for every motion they
    accept, a model of one's own may not, and a NaN or an infinity must not
    reach a result, a file or a sweep's row as if it were a force.
    ``quantities`` are ``(name, array)`` pairs (``("friction force", force)``;
    None arrays are skipped), checked in order.  An :class:`~polind.InputError`
    names the quantity, the model (its plugin or class when it is not
    polind's), the first sample that is not finite and its time.
    """
    for quantity, values in quantities:
        if values is None:
            continue
        values = np.asarray(values, dtype=np.float64)
        finite = np.isfinite(values)
        if finite.all():
            continue
        index = int(np.argmin(finite))
        cls = type(model)
        origin = ""
        if cls.__module__.split(".")[0] != "polind":
            from polind.models.registry import model_origin

            text = model_origin(cls)
            origin = f" ({text[:1].lower()}{text[1:]})"
        at = f" at t = {float(t[index]):.6g} s" if index < len(t) else ""
        raise InputError(f"the run's {quantity} is {float(values[index])}{at} (sample "
                         f"{index + 1} of {values.size}): the {model.type} model{origin} gave a "
                         f"value that is not a finite number; expected a finite {quantity} at "
                         f"every sample.")


def _check_memory(t):
    """Refuse a motion whose samples would pass the memory limit, before allocating them."""
    from polind.resources import check_memory

    try:
        samples = len(t)
    except TypeError:
        return                          # not a sequence: the conversion names it
    check_memory(samples * BYTES_PER_SAMPLE, f"A motion of {samples:.3g} samples")


def _advance_in_chunks(model, path, state, load, progress):
    """Run the model's step over the motion, reporting progress every CHUNK samples; return the forces.

    A model with nothing around its contact runs its fused loop
    (:func:`polind.kernels.contract.run_motion`: the steps are cut from the
    samples as it goes, no step arrays); a mounted one runs from step arrays
    cut one block at a time.  A chunk or a block starts at the previous one's
    last sample and the kernel's state carries over, so neither ever changes
    a result.
    """
    from polind.kernels.contract import VALID

    kernel = model.step_kernel(state, load, fixed_load=True)
    n = path.t.shape[0]
    force = np.empty(n)
    fused = kernel.mount is None
    if not fused:
        path.materialise()
        path.cut_in_blocks(_BLOCK)
    start_position, start_velocity, continuing = path._start
    lo = 0
    while True:
        hi = min(lo + CHUNK, n)
        if fused:
            code, index = kernel.run_motion(path.source_t, path.source_motion, path.t,
                                            path.motion, path.by_velocity, start_position,
                                            start_velocity, continuing, path.x,
                                            path.sample_velocity, load, lo, hi, lo == 0, force)
            if code != VALID:
                path.refuse(code, index)
        else:
            for a, b in path.blocks(lo, hi):
                path.cut(a, b)
                m = b - a
                kernel.run(path.step[:m], path.displacement[:m], path.step_velocity[:m],
                           path.sample_velocity[a:b], None if load is None else load[a:b],
                           0, m, a == 0, force[a:b])
        if progress is not None:
            progress(hi, n)
        if hi == n:
            break
        lo = hi - 1
    model.unflatten_state(kernel.state, state)
    return force
