"""Many runs of one friction model over a grid or a sample of its parameters.

The user guide, :ref:`guide-sweeps`; the sweep file, :ref:`formats-sweep`.  The
metrics measure the phenomena (:ref:`guide-phenomena`) on the one-degree-of-freedom
systems (:ref:`guide-systems`).

A sweep file names a model file, a one-degree-of-freedom system or a
prescribed motion, the metrics to keep (:data:`METRICS`) and the
parameters to vary: dotted keys into ``[model]`` and ``[system]``, each a
list of values or a range (linear or logarithmic).  The design is a grid
(every combination, in the order of the keys, the last varying fastest), a
Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`) or a uniform random
sample, seeded.  Each run is a pure function of its parameter values, so a
run's row does not depend on where it ran: local worker threads (the numba
kernels release the GIL), or the workers of an existing Dask distributed
cluster.

The results table (Parquet or CSV) has one row per run: ``run`` (the run's
index in the design), the parameter values, the metrics, ``status`` (``"ok"``
or the run's one-line error) and ``seconds``.  Rows are written as runs
finish; a sweep started again on the same output computes only the runs that
are missing, and refuses an output made by another sweep.

Examples
--------
>>> import polind, tempfile, pathlib
>>> from polind.dynamics import System
>>> model = {"model": {"type": "coulomb", "coulomb_force": 1.0}}
>>> system = System(mass=1.0, duration=1.0, time_step=0.01, spring_stiffness=10.0,
...                 drive_velocity=0.1)
>>> plan = Sweep(model, system=system, metrics=["mean_force", "max_force"],
...              parameters={"model.coulomb_force": {"values": [0.5, 1.0]}})
>>> out = pathlib.Path(tempfile.mkdtemp()) / "results.csv"
>>> summary = polind.sweep(plan, out, workers=1)
>>> summary.table["model.coulomb_force"], summary.table["status"]
([0.5, 1.0], ['ok', 'ok'])
"""

from __future__ import annotations

import contextlib
import copy
import csv
import difflib
import hashlib
import itertools
import json
import math
import os
import sys
import threading
import time
import types
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from io import BytesIO, StringIO

import numpy as np

from polind import io
from polind.dynamics import (BYTES_PER_SAMPLE, FILE_KEYS, System, file_keys_of,
                             simulate_system, system_from_keys)
from polind.errors import InputError, describe
from polind.io import atomic_open, number_text
from polind.models import FrictionModel, model_from_dict
from polind.models.params import Table
from polind.phenomena import cycle_area, velocity_scale, friction_levels
from polind.resources import check_memory
from polind.simulate import simulate

__all__ = ["METRICS", "MAX_RUNS", "Metric", "RunOutput", "Sweep", "SweepInterrupted",
           "SweepSummary", "load_sweep", "plot_results", "read_results", "register_metric",
           "sweep"]

#: A sweep with more runs than this is refused unless the caller confirms
#: (``max_runs=None`` in Python, ``--yes`` on the command line).
MAX_RUNS = 10_000

METHODS = ("grid", "latin-hypercube", "random")

# Between two rewrites of a Parquet output at least this long, and ten times as
# long as the last rewrite took (a long table is rewritten less often).
_FLUSH_SECONDS = 1.0

#: How long to try to reach a Dask scheduler before giving up.
_CONNECT_TIMEOUT = "10s"

#: What a prescribed-motion run holds per sample (t, x, v, F and the step arrays) [bytes].
_MOTION_BYTES_PER_SAMPLE = 64


# --- the metrics ----------------------------------------------------------------------------

@dataclass(frozen=True)
class RunOutput:
    """What one run produced, as a metric sees it.

    Attributes
    ----------
    t, x, v, force : ndarray
        Time [s], position [m], velocity [m/s] and friction force [N].
    applied : ndarray or None
        The force driving the body [N] (the drive spring's plus the applied
        force), or None for a prescribed motion.
    system : System or None
        The run's one-degree-of-freedom system (None for a prescribed motion).
    model : FrictionModel
        The run's model.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    applied: np.ndarray | None
    system: System | None
    model: FrictionModel

    @property
    def second_half(self) -> np.ndarray:
        """The samples of the run's second half (``t >= t0 + (t_end - t0) / 2``), a mask."""
        return self.t >= self.t[0] + 0.5 * (self.t[-1] - self.t[0])


#: What a metric needs beyond a run's force, and how an error message says it.
NEEDS = {
    "any": "",
    "body": "a [system] (a body; not a prescribed motion)",
    "spring": "a [system.spring_drive] table",
    "periodic force": "a [system.force] table",
}


@dataclass(frozen=True)
class Metric:
    """One number computed from a run (a column of the results).

    ``compute(run)`` takes a :class:`RunOutput` and returns a float (NaN
    where the metric is not defined for that run, e.g. no stick-slip);
    ``needs`` is a key of :data:`NEEDS`, checked when a sweep is loaded.
    """

    name: str
    unit: str
    needs: str
    definition: str
    compute: Callable[[RunOutput], float] = field(compare=False)


#: The metrics a sweep can keep, by name (their ``definition``; the documentation's file
#: formats page lists them).
METRICS: dict[str, Metric] = {}


def register_metric(name: str, *, unit: str, definition: str, needs: str = "any"):
    """Add a metric to :data:`METRICS` (a decorator for ``compute(run) -> float``).

    A metric defined in a script reaches Dask workers with the sweep (by
    value, as cloudpickle sends functions of ``__main__``).

    Examples
    --------
    >>> @register_metric("final_position", unit="m", needs="body",
    ...                  definition="x at the last sample")
    ... def final_position(run):
    ...     return float(run.x[-1])
    >>> METRICS["final_position"].unit
    'm'
    >>> del METRICS["final_position"]
    """
    if needs not in NEEDS:
        raise InputError(f"The 'needs' of metric '{name}' must be one of: {', '.join(NEEDS)}. "
                         f"Got {describe(needs)} instead.")

    def add(compute):
        METRICS[name] = Metric(name, unit, needs, definition, compute)
        return compute

    return add


@register_metric("mean_force", unit="N", definition="the mean of the friction force over the "
                                                    "run's samples")
def _mean_force(run):
    return float(np.mean(run.force))


@register_metric("max_force", unit="N", definition="the largest friction force over the run's "
                                                   "samples")
def _max_force(run):
    return float(np.max(run.force))


@register_metric("rms_force", unit="N", definition="the root mean square of the friction force "
                                                   "over the run's samples")
def _rms_force(run):
    return float(np.sqrt(np.mean(run.force * run.force)))


@register_metric("stick_slip_amplitude", unit="N", needs="spring",
                 definition="half the peak-to-peak of the force driving the body (the drive "
                            "spring's) over the second half of the run")
def _stick_slip_amplitude(run):
    return 0.5 * float(np.ptp(run.applied[run.second_half]))


def _slip_times(run) -> np.ndarray:
    """The times at which the body slips in the second half of the run.

    A slip is counted when the drive force falls below the lower quarter of
    its range (over the second half) after having been in its upper quarter:
    the sawtooth of stick-slip gives one per cycle, while the ringing of a
    body that has just stuck (on its contact's presliding stiffness, which
    may cross zero velocity many times a millisecond) gives none.
    """
    late = run.second_half
    t, force = run.t[late], run.applied[late]
    low, high = float(np.min(force)), float(np.max(force))
    if not high > low:
        return t[:0]
    quarter = 0.25 * (high - low)
    level = np.where(force > high - quarter, 1, np.where(force < low + quarter, -1, 0))
    last = np.maximum.accumulate(np.where(level != 0, np.arange(level.size), 0))
    held = level[last]
    return t[np.flatnonzero((held[1:] == -1) & (held[:-1] == 1)) + 1]


@register_metric("stick_slip_period", unit="s", needs="spring",
                 definition="the mean interval between successive slips in the second half "
                            "of the run, a slip being the drive force falling below the lower "
                            "quarter of its range after having been in its upper quarter; NaN "
                            "with fewer than two slips or when the body is never stuck there "
                            "(steady sliding)")
def _stick_slip_period(run):
    if not _stuck_fraction(run) > 0.0:
        return math.nan
    slips = _slip_times(run)
    return float(np.mean(np.diff(slips))) if slips.size >= 2 else math.nan


@register_metric("stuck_fraction", unit="1", needs="spring",
                 definition="the fraction of the samples of the second half of the run at "
                            "which the body is stuck (its speed in the drive's direction below "
                            "0.1 v_d); NaN without a drive velocity")
def _stuck_fraction(run):
    drive = run.system.drive_velocity
    if drive == 0.0:
        return math.nan
    late = run.second_half
    return float(np.mean(math.copysign(1.0, drive) * run.v[late] < 0.1 * abs(drive)))


@register_metric("advance_per_cycle", unit="m", needs="periodic force",
                 definition="the change of the body's cycle-mean position from the next-to-last "
                            "to the last complete cycle of the applied force (cycle k: "
                            "k/f <= t < (k+1)/f); NaN without two complete cycles")
def _advance_per_cycle(run):
    frequency = run.system.frequency
    if frequency <= 0.0:
        return math.nan
    cycle = np.floor(run.t * frequency * (1.0 + 1e-12)).astype(np.int64)
    complete = int(math.floor(float(run.t[-1]) * frequency * (1.0 + 1e-12)))
    if complete < 2:
        return math.nan
    inside = cycle < complete
    means = (np.bincount(cycle[inside], weights=run.x[inside], minlength=complete)
             / np.bincount(cycle[inside], minlength=complete))
    return float(means[-1] - means[-2])


@register_metric("breakaway_force", unit="N", needs="body",
                 definition="the force driving the body at the first sample where its speed "
                            "exceeds the model's Stribeck velocity (1 mm/s for a model without "
                            "one); NaN if it never does")
def _breakaway_force(run):
    threshold = velocity_scale(friction_levels(run.model))
    moving = np.flatnonzero(np.abs(run.v) > threshold)
    return float(run.applied[moving[0]]) if moving.size else math.nan


@register_metric("loop_area", unit="N m/s",
                 definition="the signed area closed integral F dv of the last velocity cycle "
                            "of the second half (between the last two upward crossings of the "
                            "middle of its velocity range), positive when the force is higher "
                            "while the velocity rises (frictional lag); NaN without a cycle")
def _loop_area_metric(run):
    late = run.second_half
    v, force = run.v[late], run.force[late]
    low, high = float(np.min(v)), float(np.max(v))
    if not high > low:
        return math.nan
    middle = 0.5 * (low + high)
    up = np.flatnonzero((v[:-1] < middle) & (v[1:] >= middle)) + 1
    if up.size < 2:
        return math.nan
    start, stop = int(up[-2]), int(up[-1])
    return cycle_area(v[start:stop + 1], force[start:stop + 1])


# --- the system table -----------------------------------------------------------------------

#: The keys of a [system] file (:ref:`formats-system`) and the System fields they set.
#: The dotted keys of a [system] file and the System fields they set.
SYSTEM_KEYS = FILE_KEYS


def _system_of(flat: Mapping) -> System:
    return system_from_keys(flat)


# --- the parameters -------------------------------------------------------------------------

@dataclass(frozen=True)
class Axis:
    """One swept parameter: a dotted key and its values or range.

    ``kind`` is that of the parameter: ``"float"``, ``"int"``, ``"str"`` or
    ``"path"`` (a file, relative to the sweep file).
    """

    key: str
    kind: str
    values: tuple | None = None
    low: float | None = None
    high: float | None = None
    scale: str = "linear"
    count: int | None = None

    @property
    def log(self) -> bool:
        return self.scale == "log"

    @property
    def levels(self) -> int | None:
        """How many values the axis has on a grid (None: a range without ``count``)."""
        return len(self.values) if self.values is not None else self.count

    def grid(self) -> list:
        """The axis's values on a grid: its ``values``, or ``count`` points over its range."""
        if self.values is not None:
            return list(self.values)
        if self.count == 1:
            return [self.low]
        points = []
        for k in range(self.count):
            fraction = k / (self.count - 1)
            if self.log:
                value = self.low * (self.high / self.low) ** fraction
            else:
                value = self.low + (self.high - self.low) * fraction
            points.append(float(value))
        points[0], points[-1] = self.low, self.high
        return points

    def sample(self, u: np.ndarray) -> list:
        """Values for uniform samples ``u`` in [0, 1): the range (linear or in log) or the list."""
        if self.values is not None:
            n = len(self.values)
            return [self.values[min(int(p * n), n - 1)] for p in u.tolist()]
        if self.log:
            return [float(self.low * (self.high / self.low) ** p) for p in u.tolist()]
        return [float(self.low + (self.high - self.low) * p) for p in u.tolist()]


def _model_keys(model: FrictionModel) -> list[str]:
    def walk(entries, prefix):
        for entry in entries:
            if isinstance(entry, Table):
                yield from walk(entry.entries, f"{prefix}{entry.key}.")
            elif entry.kind in ("float", "int", "str", "path"):
                yield f"model.{prefix}{entry.key}"
    return list(walk(model.parameters, ""))


def _is_number(value) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))


class _Where:
    """Builds the one-line messages of a sweep's errors: the file, then the key."""

    def __init__(self, name: str):
        self.name = name

    def error(self, key: str | None, message: str) -> InputError:
        """``file: key 'sweep.method': message``; a key already formatted (``[sweep....``) as is."""
        label = "" if not key else f"{key}: " if key.startswith("[") else f"key '{key}': "
        return InputError(f"{self.name}: {label}{message}")


def _parameter_label(key: str, entry: str | None = None) -> str:
    """How a message names a swept key (and an entry of its table) of [sweep.parameters]."""
    return f'[sweep.parameters] "{key}"' + (f" {entry}" if entry else "")


def _parse_axis(where: _Where, key: str, kind: str, spec, method: str) -> Axis:
    """One entry of [sweep.parameters]: ``{values = [...]}`` or ``{range = [a, b], ...}``."""
    def fail(entry, message):
        return where.error(_parameter_label(key, entry), message)

    if not isinstance(spec, Mapping):
        raise fail(None, f"expected a table such as {{ values = [...] }} or {{ range = [low, "
                         f"high], scale = \"log\", count = N }}; got {describe(spec)}")
    unknown = sorted(set(spec) - {"values", "range", "scale", "count"})
    if unknown:
        raise fail(unknown[0], "unknown key; expected values, or range with scale and count")
    if ("values" in spec) == ("range" in spec):
        raise fail(None, "expected exactly one of 'values' and 'range'")
    if "values" in spec:
        for extra in ("scale", "count"):
            if extra in spec:
                raise fail(extra, "goes with 'range', not with 'values'")
        values = spec["values"]
        if not isinstance(values, (list, tuple)):
            raise fail("values", f"expected a list; got {describe(values)}")
        if not values:
            raise fail("values", "the list is empty; expected at least one value")
        clean = []
        for value in values:
            if kind == "float" and _is_number(value) and math.isfinite(value):
                clean.append(float(value))
            elif kind == "int" and _is_number(value) and float(value).is_integer():
                clean.append(int(value))
            elif kind in ("str", "path") and isinstance(value, str) and value:
                clean.append(value)
            else:
                expected = {"float": "finite numbers", "int": "integers",
                            "str": "non-empty strings", "path": "file names"}[kind]
                raise fail("values", f"expected {expected}; got {describe(value)}")
        return Axis(key, kind, values=tuple(clean))
    if kind != "float":
        takes = "integers" if kind == "int" else "words"
        raise fail("range", f"'{key}' takes {takes}; give its 'values' instead of a range")
    bounds = spec["range"]
    if not (isinstance(bounds, (list, tuple)) and len(bounds) == 2
            and all(_is_number(b) and math.isfinite(b) for b in bounds)):
        raise fail("range", f"expected [low, high], two finite numbers; got {describe(bounds)}")
    low, high = float(bounds[0]), float(bounds[1])
    if not low < high:
        raise fail("range", f"the range [{low!r}, {high!r}] is empty; expected low < high")
    scale = spec.get("scale", "linear")
    if scale not in ("linear", "log"):
        raise fail("scale", f"expected \"linear\" or \"log\"; got {describe(scale)}")
    if scale == "log" and not (low > 0.0 or high < 0.0):
        raise fail("range", f"a log range must not reach or cross zero; got [{low!r}, {high!r}]")
    count = spec.get("count")
    if count is not None and not (_is_number(count) and float(count).is_integer() and count >= 1):
        raise fail("count", f"expected a positive integer; got {describe(count)}")
    if method == "grid" and count is None:
        raise fail("count", "a grid needs the number of points of each range; give count = N")
    return Axis(key, kind, low=low, high=high, scale=scale,
                count=None if count is None else int(count))


# --- the sweep ------------------------------------------------------------------------------

class Sweep:
    """A sweep: the model, the system or motion, the swept parameters, the metrics, the design.

    Parameters
    ----------
    model : FrictionModel, dict, str or os.PathLike
        The base model: a model, a model document (``{"model": {...}}``) or
        a model file.
    system : System, str or os.PathLike, optional
        The one-degree-of-freedom system of every run (a ``[system]`` file
        or a :class:`polind.System`).  Exactly one of ``system`` and ``motion``.
    motion : dict, str or os.PathLike, optional
        A prescribed motion: a motion file (``t`` and ``x`` or ``v``,
        optionally ``normal_load``) or a dict of those arrays.
    parameters : dict
        Dotted key (``"model.attraction"``, ``"system.spring_drive.velocity"``)
        to ``{"values": [...]}`` or ``{"range": [low, high], "scale":
        "linear" | "log", "count": N}`` (``count``: the grid's points).
    metrics : sequence of str
        Names in :data:`METRICS`.
    method : {"grid", "latin-hypercube", "random"}
    samples : int, optional
        Runs of a Latin-hypercube or random design.
    seed : int, default 0
        Seed of a Latin-hypercube or random design.
    name : str
        How error messages name the sweep (the sweep file's path).
    base_dir : str or os.PathLike
        Where relative file names of the sweep point from.
    """

    def __init__(self, model, *, system=None, motion=None, parameters=None, metrics=(),
                 method="grid", samples=None, seed=0, name="the sweep", base_dir="."):
        where = _Where(os.fspath(name))
        self.name = where.name
        # Relative names are shown from where the user pointed (messages), and run from
        # the absolute directory (a worker may have another working directory).
        self._shown_dir = os.fspath(base_dir)
        self.base_dir = os.path.abspath(self._shown_dir)
        self.inputs = []
        self._load_model(where, model)
        self._load_drive(where, system, motion)
        if method not in METHODS:
            raise where.error("sweep.method", f"expected one of: {', '.join(METHODS)}; got "
                                              f"{describe(method)}")
        self.method = method
        self._load_design_size(where, samples, seed)
        self.metrics = self._load_metrics(where, metrics)
        self.axes = self._load_parameters(where, parameters or {})

    # -- pieces of the constructor

    def _path(self, value) -> str:
        """A file named in the sweep, relative to its directory (as shown in messages)."""
        path = os.fspath(value)
        return path if os.path.isabs(path) or self._shown_dir in ("", ".") \
            else os.path.join(self._shown_dir, path)

    def _load_model(self, where, model):
        if isinstance(model, FrictionModel):
            document = model.to_dict()
        elif isinstance(model, Mapping):
            document = copy.deepcopy(dict(model))
        elif isinstance(model, (str, os.PathLike)):
            path = self._path(model)
            self.inputs.append(path)
            document = io.read_model_file(path)
            where = _Where(path)
        else:
            raise where.error("sweep.model", f"expected a model file; got {describe(model)}")
        try:
            self.model = model_from_dict(document)
        except InputError as error:
            raise InputError(f"{where.name}: {error}") from None
        self.model_table = self.model.to_dict()["model"]

    def _load_drive(self, where, system, motion):
        if (system is None) == (motion is None):
            raise where.error("sweep.system", "expected exactly one of 'system' (a [system] "
                                              "file) and 'motion' (a motion file)")
        self.system = self.motion = None
        if system is not None:
            if isinstance(system, System):
                self.system = {key: getattr(system, field_name)
                               for key, field_name in SYSTEM_KEYS.items()}
            elif isinstance(system, (str, os.PathLike)):
                path = self._path(system)
                self.inputs.append(path)
                self.system = file_keys_of(io.read_system_file(path))
                try:
                    _system_of(self.system)
                except InputError as error:
                    raise InputError(f"{path}: {error}") from None
            else:
                raise where.error("sweep.system", f"expected a [system] file; got "
                                                  f"{describe(system)}")
            return
        if isinstance(motion, Mapping):
            self.motion = {key: np.asarray(value, dtype=np.float64)
                           for key, value in motion.items()}
        elif isinstance(motion, (str, os.PathLike)):
            path = self._path(motion)
            self.inputs.append(path)
            self.motion = io.read_motion_csv(path)
        else:
            raise where.error("sweep.motion", f"expected a motion file; got {describe(motion)}")

    def _load_design_size(self, where, samples, seed):
        if not (_is_number(seed) and float(seed).is_integer() and seed >= 0):
            raise where.error("sweep.seed", f"expected a non-negative integer; got "
                                            f"{describe(seed)}")
        self.seed = int(seed)
        self.samples = None
        if self.method == "grid":
            return
        if samples is None:
            raise where.error("sweep.samples", f"a {self.method} design needs the number of "
                                               "runs; give samples = N")
        if not (_is_number(samples) and float(samples).is_integer() and samples >= 1):
            raise where.error("sweep.samples", f"expected a positive integer; got "
                                               f"{describe(samples)}")
        self.samples = int(samples)

    def _load_metrics(self, where, metrics):
        if isinstance(metrics, str) or not isinstance(metrics, (list, tuple)) or not metrics:
            raise where.error("sweep.metrics", f"expected a non-empty list of metric names "
                                               f"({', '.join(METRICS)}); got {describe(metrics)}")
        chosen = []
        for name in metrics:
            if not isinstance(name, str) or name not in METRICS:
                raise where.error("sweep.metrics", f"unknown metric {describe(name)}; expected "
                                                   f"one of: {', '.join(METRICS)}")
            if name in (metric.name for metric in chosen):
                raise where.error("sweep.metrics", f"the metric '{name}' is named twice")
            metric = METRICS[name]
            system = self.system or {}
            present = {"any": True, "body": self.system is not None,
                       "spring": "spring_drive.velocity" in system,
                       "periodic force": "force.frequency" in system}
            if not present[metric.needs]:
                raise where.error("sweep.metrics", f"the metric '{name}' needs "
                                                   f"{NEEDS[metric.needs]}, which this sweep "
                                                   f"does not have")
            chosen.append(metric)
        return tuple(chosen)

    def _load_parameters(self, where, parameters):
        if not isinstance(parameters, Mapping) or not parameters:
            raise where.error("sweep.parameters", "expected a table of the keys to vary, e.g. "
                                                  "\"model.attraction\" = { values = [1e3, 1e4] }")
        axes = []
        for key, spec in parameters.items():
            kind = self._kind_of(where, key)
            axes.append(_parse_axis(where, key, kind, spec, self.method))
        return tuple(axes)

    def _kind_of(self, where, key) -> str:
        """The kind of a swept key; InputError naming it when no run could set it."""
        label = _parameter_label(key)
        root, _, rest = str(key).partition(".")
        if root == "model" and rest:
            declaration = self.model.declaration(rest)
            if declaration is None or isinstance(declaration, Table):
                known = _model_keys(self.model)
                close = difflib.get_close_matches(key, known, n=1)
                hint = f" (did you mean \"{close[0]}\"?)" if close else ""
                raise where.error(label, f"unknown key{hint}; expected a parameter of the "
                                         f"{self.model.type} model: {', '.join(known)}")
            if declaration.kind not in ("float", "int", "str", "path"):
                raise where.error(label, f"'{rest}' is a list; a sweep varies numbers, integers "
                                         f"and words")
            return declaration.kind
        if root == "system" and rest and self.system is not None:
            if rest not in self.system:
                table = rest.partition(".")[0]
                absent = (f" (the system has no [system.{table}] table)"
                          if rest in SYSTEM_KEYS else "")
                raise where.error(label, f"unknown key{absent}; expected one of: "
                                         + ", ".join(f"system.{k}" for k in self.system))
            return "float"
        if self.motion is not None:
            raise where.error(label, "unknown key; expected model.<key> (a sweep over a "
                                     "prescribed motion varies the model only)")
        raise where.error(label, "unknown key; expected model.<key> or system.<key>")

    # -- the design

    @property
    def runs(self) -> int:
        """The number of runs of the design."""
        if self.method == "grid":
            return math.prod(axis.levels for axis in self.axes)
        return self.samples

    def design(self) -> list[tuple]:
        """The parameter values of every run, in run order (one tuple per run)."""
        if self.method == "grid":
            return list(itertools.product(*(axis.grid() for axis in self.axes)))
        rng = np.random.default_rng(self.seed)
        if self.method == "random":
            u = rng.random((self.samples, len(self.axes)))
        else:
            import inspect

            from scipy.stats import qmc

            # The same Generator under either keyword: scipy >= 1.15 names it rng.
            keyword = "rng" if "rng" in inspect.signature(qmc.LatinHypercube).parameters \
                else "seed"
            u = qmc.LatinHypercube(len(self.axes), **{keyword: rng}).random(self.samples)
        columns = [axis.sample(u[:, j]) for j, axis in enumerate(self.axes)]
        return list(zip(*columns))

    @property
    def keys(self) -> tuple[str, ...]:
        return tuple(axis.key for axis in self.axes)

    @property
    def columns(self) -> list[str]:
        """The columns of the results table, in order."""
        return ["run", *self.keys, *(metric.name for metric in self.metrics), "status",
                "seconds"]

    def fingerprint(self) -> str:
        """A digest of what every run shares: model, system or motion, metrics, polind's version.

        The swept keys' own values in the model and system files do not
        count; a metric counts by its name, unit and definition.
        """
        model = copy.deepcopy(self.model_table)
        system = dict(self.system or {})
        for key in self.keys:
            root, _, rest = key.partition(".")
            if root == "system":
                system.pop(rest, None)
                continue
            *parents, last = rest.split(".")
            table = model
            for part in parents:
                table = table.get(part) or {}
            if isinstance(table, dict):
                table.pop(last, None)
        motion = None
        if self.motion is not None:
            digest = hashlib.sha256()
            for key in sorted(self.motion):
                digest.update(key.encode())
                digest.update(np.ascontiguousarray(self.motion[key]).tobytes())
            motion = digest.hexdigest()
        from polind import __version__

        text = json.dumps({"model": model, "system": system, "motion": motion,
                           "metrics": [[metric.name, metric.unit, metric.definition]
                                       for metric in self.metrics],
                           "polind": __version__}, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def plan(self) -> "_Plan":
        return _Plan(model=self.model_table, system=self.system, motion=self.motion,
                     keys=self.keys, kinds=tuple(axis.kind for axis in self.axes),
                     metrics=self.metrics, base_dir=self.base_dir)


_SWEEP_KEYS = ("model", "system", "motion", "metrics", "method", "samples", "seed", "parameters")


def load_sweep(path) -> Sweep:
    """Read a sweep file (TOML, or JSON by extension; :ref:`formats-sweep`).

    Relative file names in it point from the sweep file's directory.  Every
    problem raises :class:`polind.InputError` naming the file and the key.
    """
    from polind.io import check_tables, read_document

    name = os.fspath(path)
    document = read_document(path)
    check_tables(name, document, required=("sweep",), allowed=("sweep",))
    table = document["sweep"]
    for key in table:
        if key not in _SWEEP_KEYS:
            raise InputError(f"{name}: unknown key 'sweep.{key}'; expected one of: "
                             + ", ".join(f"sweep.{k}" for k in _SWEEP_KEYS))
    for key in ("model", "system", "motion"):
        if key in table and not isinstance(table[key], str):
            raise InputError(f"{name}: key 'sweep.{key}': expected a file name; got "
                             f"{describe(table[key])}")
    if "model" not in table:
        raise InputError(f"{name}: missing key 'sweep.model'; expected a model file")
    plan = Sweep(table["model"], system=table.get("system"), motion=table.get("motion"),
                 parameters=table.get("parameters"), metrics=table.get("metrics", ()),
                 method=table.get("method", "grid"), samples=table.get("samples"),
                 seed=table.get("seed", 0), name=name, base_dir=os.path.dirname(name))
    plan.inputs.insert(0, name)
    return plan


# --- one run --------------------------------------------------------------------------------

class _Cancelled(BaseException):
    """The sweep is stopping: a running run gives up at its next progress report."""


@dataclass(frozen=True)
class _Plan:
    """What every run needs (sent once to each Dask worker)."""

    model: dict
    system: dict | None
    motion: dict | None
    keys: tuple
    kinds: tuple
    metrics: tuple
    base_dir: str


def _one_line(error: BaseException) -> str:
    text = " ".join(str(error).split())
    return text if isinstance(error, InputError) else f"{type(error).__name__}: {text}"


def run_one(plan: _Plan, index: int, values: tuple, stop: threading.Event | None = None) -> dict:
    """The row of one run: a pure function of ``plan`` and ``values`` (``stop`` only aborts it)."""
    started = time.perf_counter()
    table = copy.deepcopy(plan.model)
    system = dict(plan.system) if plan.system is not None else None
    row = {"run": index}
    for key, kind, value in zip(plan.keys, plan.kinds, values):
        row[key] = value
        root, _, rest = key.partition(".")
        if root == "system":
            system[rest] = value
            continue
        if kind == "path" and not os.path.isabs(value):
            value = os.path.join(plan.base_dir, value)
        *parents, last = rest.split(".")
        target = table
        for part in parents:
            if target.get(part) is None:
                target[part] = {}
            target = target[part]
        target[last] = value

    def check_stop(done, total):
        if stop is not None and stop.is_set():
            raise _Cancelled

    try:
        model = model_from_dict({"model": table})
        if system is not None:
            body = _system_of(system)
            result = simulate_system(model, body, progress=check_stop)
            output = RunOutput(result.t, result.x, result.v, result.force, result.applied, body,
                               model)
        else:
            motion = plan.motion
            result = simulate(model, motion["t"], x=motion.get("x"), v=motion.get("v"),
                              normal_load=motion.get("normal_load"), progress=check_stop)
            output = RunOutput(result.t, result.x, result.v, result.force, None, None, model)
        for metric in plan.metrics:
            row[metric.name] = float(metric.compute(output))
        row["status"] = "ok"
    except Exception as error:  # noqa: BLE001 - a failed run is a row, and the sweep goes on
        for metric in plan.metrics:
            row[metric.name] = math.nan
        row["status"] = _one_line(error) or type(error).__name__
    row["seconds"] = time.perf_counter() - started
    return row


# --- the results table ----------------------------------------------------------------------

_METADATA_KEY = b"polind.sweep"


class _Results:
    """The output table of a sweep: the rows already there, and the rows added as runs finish.

    CSV rows are appended to the file as they come (a row per line, in the
    order runs finish).  A Parquet file is rewritten whole, atomically, at
    most every :data:`_FLUSH_SECONDS` and at the end, its rows sorted by run;
    its metadata records the sweep's :meth:`Sweep.fingerprint`.
    """

    def __init__(self, path, plan: Sweep, design: list[tuple]):
        self.path = os.fspath(path)
        self.plan = plan
        self.columns = plan.columns
        self.parquet = self.path.lower().endswith(".parquet")
        self.rows: dict[int, dict] = {}
        self.pending: list[dict] = []
        self.last_flush = time.monotonic()
        self.flush_cost = 0.0
        if os.path.exists(self.path):
            self._read(design)

    # -- types of the columns

    def _kinds(self) -> dict:
        kinds = {"run": "int", "status": "str", "seconds": "float"}
        kinds.update({axis.key: ("str" if axis.kind == "path" else axis.kind)
                      for axis in self.plan.axes})
        kinds.update({metric.name: "float" for metric in self.plan.metrics})
        return kinds

    # -- reading what is there

    def _refuse(self, message: str) -> InputError:
        return InputError(f"{self.path}: {message}; the output of another sweep is never mixed "
                          f"with this one's: give another --output, or remove the file to "
                          f"start again")

    def _read(self, design):
        rows = self._read_parquet() if self.parquet else self._read_csv()
        runs = len(design)
        # In run order (a file holds its rows in the order runs finished), so that a
        # mismatch names the same run whatever the engine and its timing were.
        rows.sort(key=lambda numbered: (numbered[1]["run"], numbered[0]))
        for number, row in rows:
            index = row["run"]
            if not 0 <= index < runs:
                raise self._refuse(f"row {number} is run {index}, which {self.plan.name} "
                                   f"does not have ({runs} runs)")
            for key, want in zip(self.plan.keys, design[index]):
                got = row[key]
                same = (math.isclose(got, want, rel_tol=1e-12, abs_tol=0.0)
                        if isinstance(want, float) else got == want)
                if not same:
                    raise self._refuse(f"row {number} (run {index}) has {key} = {got!r} where "
                                       f"{self.plan.name} gives {want!r}")
            self.rows.setdefault(index, row)

    def _read_parquet(self):
        import pyarrow.parquet as pq

        try:
            table = pq.read_table(self.path)
        except Exception as error:  # noqa: BLE001 - any unreadable file is refused the same way
            raise InputError(f"{self.path}: cannot read the existing output ({_one_line(error)}); "
                             f"expected the Parquet table of an earlier run of this sweep") \
                from None
        if table.column_names != self.columns:
            raise self._refuse(f"its columns ({', '.join(table.column_names)}) are not those of "
                               f"{self.plan.name} ({', '.join(self.columns)})")
        metadata = json.loads((table.schema.metadata or {}).get(_METADATA_KEY, b"{}"))
        if metadata.get("fingerprint") != self.plan.fingerprint():
            raise self._refuse(f"it was made from another model, system, motion or metric list "
                               f"than {self.plan.name}")
        columns = table.to_pydict()
        return [(number + 1, {key: columns[key][number] for key in self.columns})
                for number in range(table.num_rows)]

    def _read_csv(self):
        kinds = self._kinds()
        with open(self.path, "rb") as stream:
            data = stream.read()
        if data and not data.endswith(b"\n"):
            # A row cut short by a killed process: it was never a finished row.
            cut = data.rfind(b"\n") + 1
            data = data[:cut]
            with open(self.path, "r+b") as stream:
                stream.truncate(cut)
        if not data:
            return []
        lines = data.decode("utf-8").splitlines()
        reader = csv.reader(lines)
        header = next(reader)
        if header != self.columns:
            raise self._refuse(f"its columns ({', '.join(header)}) are not those of "
                               f"{self.plan.name} ({', '.join(self.columns)})")
        rows = []
        for number, fields in enumerate(reader, start=2):
            if len(fields) != len(header):
                raise self._refuse(f"row {number} has {len(fields)} fields, not {len(header)}")
            row = {}
            try:
                for key, text in zip(header, fields):
                    kind = kinds[key]
                    row[key] = int(text) if kind == "int" else float(text) \
                        if kind == "float" else text
            except ValueError:
                raise self._refuse(f"row {number}, column '{key}': {text!r} is not a "
                                   f"{kinds[key]} number") from None
            rows.append((number, row))
        return rows

    # -- writing

    def add(self, row: dict) -> None:
        self.rows[row["run"]] = row
        self.pending.append(row)
        if not self.parquet:
            self.flush()
        elif time.monotonic() - self.last_flush >= max(_FLUSH_SECONDS, 10.0 * self.flush_cost):
            self.flush()

    def flush(self) -> None:
        """Put every added row in the file."""
        if not self.pending:
            return
        started = time.monotonic()
        if self.parquet:
            self._write_parquet()
        else:
            self._append_csv()
        self.pending = []
        self.last_flush = time.monotonic()
        self.flush_cost = self.last_flush - started

    def _append_csv(self):
        buffer = StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        new = not os.path.exists(self.path) or os.path.getsize(self.path) == 0
        if new:
            writer.writerow(self.columns)
        for row in self.pending:
            writer.writerow([number_text(row[key]) if isinstance(row[key], float)
                             else str(row[key]) for key in self.columns])
        if new:
            io.atomic_write_text(self.path, buffer.getvalue())
            return
        try:
            with open(self.path, "a", encoding="utf-8", newline="\n") as stream:
                stream.write(buffer.getvalue())
        except OSError as error:
            raise InputError(f"{self.path}: cannot write: {error.strerror or error}") from None

    def _write_parquet(self):
        import pyarrow as pa
        import pyarrow.parquet as pq

        types_of = {"int": pa.int64(), "float": pa.float64(), "str": pa.string()}
        kinds = self._kinds()
        metadata = {_METADATA_KEY: json.dumps({
            "fingerprint": self.plan.fingerprint(), "sweep": self.plan.name,
            "runs": self.plan.runs}).encode()}
        schema = pa.schema([(key, types_of[kinds[key]]) for key in self.columns],
                           metadata=metadata)
        ordered = [self.rows[index] for index in sorted(self.rows)]
        table = pa.table({key: [row[key] for row in ordered] for key in self.columns},
                         schema=schema)
        with atomic_open(self.path, binary=True) as stream:
            pq.write_table(table, stream)

    def table(self) -> dict:
        """Every row (those found and those added), sorted by run: column name to list."""
        ordered = [self.rows[index] for index in sorted(self.rows)]
        return {key: [row[key] for row in ordered] for key in self.columns}


def read_results(path) -> dict:
    """A sweep's results table, its rows sorted by run: column name to list.

    Rows of the same run found twice (two sweeps written to one output at
    once) are kept once, the first.  From a CSV, every column but ``run``
    and the words (``status``, word parameters) is read as floats.
    """
    name = os.fspath(path)
    if name.lower().endswith(".parquet"):
        import pyarrow.parquet as pq

        columns = pq.read_table(name).to_pydict()
    else:
        with open(name, newline="", encoding="utf-8") as stream:
            lines = stream.read()
        if not lines.endswith("\n"):
            lines = lines[:lines.rfind("\n") + 1]
        reader = csv.reader(lines.splitlines())
        header = next(reader, ["run"])
        columns = {key: [] for key in header}
        for fields in reader:
            for key, text in zip(header, fields):
                columns[key].append(text)
        for key, values in columns.items():
            if key == "run":
                columns[key] = [int(value) for value in values]
            elif key != "status":
                with contextlib.suppress(ValueError):
                    columns[key] = [float(value) for value in values]
    first = {}
    for position, index in enumerate(columns["run"]):
        first.setdefault(index, position)
    order = [first[index] for index in sorted(first)]
    return {key: [values[position] for position in order] for key, values in columns.items()}


# --- the engines ----------------------------------------------------------------------------

def _run_local(plan: _Plan, todo, workers: int, record, keep) -> None:
    """Every run of ``todo`` (index, values) on ``workers`` threads, each row to ``record``.

    At most two runs per thread wait in the queue.  On any exception here
    (Ctrl-C, a ``record`` that raises) the queued runs are dropped, the
    running ones stop at their next progress report, the rows of the runs
    that finished all the same go to ``keep``, and the exception goes on.
    """
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    stop = threading.Event()
    queue = iter(todo)
    unrecorded = set()
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="polind-sweep")
    try:
        while True:
            for index, values in itertools.islice(queue, 2 * workers - len(unrecorded)):
                unrecorded.add(pool.submit(run_one, plan, index, values, stop))
            if not unrecorded:
                return
            finished, _ = wait(unrecorded, return_when=FIRST_COMPLETED)
            for future in sorted(finished, key=lambda f: f.result()["run"]):
                unrecorded.discard(future)
                record(future.result())
    finally:
        stop.set()
        for future in unrecorded:
            future.cancel()
        pool.shutdown(wait=True)
        for future in unrecorded:
            if not future.cancelled() and future.exception() is None:
                keep(future.result())


def _dask_task(plan, index, values):
    return run_one(plan, index, values)


def _run_dask(plan: _Plan, todo, scheduler, record, keep, lost) -> None:
    """Every run of ``todo`` as a task of an existing Dask cluster; rows to ``record``.

    ``scheduler`` is an address or a ``distributed.Client``.  A task that
    fails outside its run (its worker died) is ``lost``: it is not recorded,
    and running the sweep again computes it.  On any exception here (Ctrl-C)
    the unfinished tasks are cancelled, the rows of finished ones not yet
    recorded go to ``keep``, and the exception goes on.
    """
    import uuid

    try:
        from distributed import Client, as_completed
    except ImportError:  # pragma: no cover - a dependency of polind
        raise InputError("--scheduler needs the 'distributed' package (pip install "
                         "'dask[distributed]')") from None
    own = not isinstance(scheduler, Client)
    if own:
        try:
            client = Client(scheduler, timeout=_CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as error:
            raise InputError(f"cannot reach the Dask scheduler at {scheduler!r} "
                             f"({_one_line(error)}); expected the address of a running "
                             f"cluster, such as tcp://HOST:8786") from None
    else:
        client = scheduler
    tag = uuid.uuid4().hex[:8]
    unrecorded = set()
    try:
        shared = client.scatter(plan, broadcast=True, hash=False)
        unrecorded = {client.submit(_dask_task, shared, index, values, pure=False,
                                    key=f"polind-sweep-{tag}-{index}") for index, values in todo}
        for future in as_completed(list(unrecorded)):
            unrecorded.discard(future)
            if future.status == "finished":
                record(future.result())
            else:
                lost(future)
    finally:
        finished = [future for future in unrecorded if future.status == "finished"]
        client.cancel([future for future in unrecorded if future.status == "pending"])
        for future in sorted(finished, key=lambda f: f.key):
            keep(future.result())
        if own:
            client.close()


# --- the sweep ------------------------------------------------------------------------------

@dataclass
class SweepSummary:
    """What :func:`sweep` did.

    Attributes
    ----------
    path : str
        The results table.
    runs : int
        Runs of the design.
    computed : int
        Runs computed now (the others were already in the table).
    failed : int
        Of those, runs whose status is an error.
    lost : int
        Dask tasks that failed outside their run (not recorded: run again).
    seconds : float
        Wall time of this call [s].
    table : dict
        Every row of the table now, sorted by run: column name to list.
    """

    path: str
    runs: int
    computed: int
    failed: int
    lost: int
    seconds: float
    table: dict = field(repr=False)

    @property
    def existing(self) -> int:
        """Runs found in the table before this call."""
        return len(self.table["run"]) - self.computed


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; every finished row is in its table.

    ``computed`` runs were added by the interrupted call, ``runs`` the whole
    design, ``done`` the rows the table holds now.
    """

    def __init__(self, path, runs, computed, done):
        super().__init__(f"{path}: interrupted with {done} of {runs} runs written")
        self.path, self.runs, self.computed, self.done = path, runs, computed, done


def _check_output(path, plan: Sweep):
    name = os.fspath(path)
    if name == io.STDOUT or not name.lower().endswith((".parquet", ".csv")):
        raise InputError(f"{name}: a sweep's results go to a file whose name ends in .parquet "
                         f"or .csv (so that a second run can find its rows)")
    io.check_output_path(name, plan.inputs)
    if os.path.exists(name) and not os.path.isfile(name):
        raise InputError(f"{name}: not a regular file; expected a .parquet or .csv file")


def _default_workers() -> int:
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def sweep(spec, output, *, workers=None, scheduler=None, max_runs=MAX_RUNS,
          progress=None) -> SweepSummary:
    """Run a sweep; rows go to ``output`` as runs finish; only missing runs are computed.

    Parameters
    ----------
    spec : Sweep, str or os.PathLike
        A :class:`Sweep` or a sweep file (:func:`load_sweep`).
    output : str or os.PathLike
        The results table, ``.parquet`` or ``.csv``.  If it exists, it must
        hold rows of this sweep (else InputError); their runs are not run again.
    workers : int, optional
        Local worker threads; default the number of cores.
    scheduler : str or distributed.Client, optional
        Run on an existing Dask cluster (its address, ``tcp://HOST:PORT``)
        instead of local threads.  Its workers need polind installed.
    max_runs : int or None
        Refuse a design with more runs (None: no limit).
    progress : callable, optional
        ``progress(done, total, failed)`` after each run (``total``: the runs
        this call computes).  An exception it raises stops the sweep as
        Ctrl-C does.

    Returns
    -------
    SweepSummary

    Raises
    ------
    InputError
        A bad sweep, an output of another sweep, too many runs.
    SweepInterrupted
        Ctrl-C (a KeyboardInterrupt): finished rows are in the table.
    """
    started = time.perf_counter()
    plan = spec if isinstance(spec, Sweep) else load_sweep(spec)
    name = os.fspath(output)
    _check_output(name, plan)
    if workers is not None and scheduler is not None:
        raise InputError("give 'workers' (local threads) or 'scheduler' (a Dask cluster), "
                         "not both")
    if workers is not None and (not _is_number(workers) or isinstance(workers, float)
                                or workers < 1):
        raise InputError(f"The number of 'workers' must be a positive integer. Got "
                         f"{describe(workers)} instead.")
    runs = plan.runs
    if max_runs is not None and runs > max_runs:
        raise InputError(f"{plan.name}: the sweep has {runs:,} runs, more than the limit of "
                         f"{max_runs:,}; check the counts of [sweep.parameters] and "
                         f"sweep.samples, or confirm with --yes (max_runs=None in Python)")
    check_memory(runs * (len(plan.axes) + 2) * 64.0, f"{plan.name}: the design ({runs:,} runs)")
    design = plan.design()
    results = _Results(name, plan, design)
    todo = [(index, values) for index, values in enumerate(design) if index not in results.rows]
    threads = _default_workers() if workers is None else int(workers)
    if scheduler is None and todo:
        _check_run_memory(plan, todo, min(threads, len(todo)))
    counts = {"done": 0, "failed": 0, "lost": 0}

    def keep(row):
        results.add(row)
        counts["done"] += 1
        counts["failed"] += row["status"] != "ok"

    def record(row):
        keep(row)
        if progress is not None:
            progress(counts["done"], len(todo), counts["failed"])

    def lost(future):
        counts["lost"] += 1

    if progress is not None:
        progress(0, len(todo), 0)
    try:
        if todo and scheduler is not None:
            _run_dask(plan.plan(), todo, scheduler, record, keep, lost)
        elif todo:
            _run_local(plan.plan(), todo, min(threads, len(todo)), record, keep)
    except KeyboardInterrupt:
        results.flush()
        raise SweepInterrupted(name, runs, counts["done"], len(results.rows)) from None
    finally:
        results.flush()
    return SweepSummary(path=name, runs=runs, computed=counts["done"], failed=counts["failed"],
                        lost=counts["lost"], seconds=time.perf_counter() - started,
                        table=results.table())


def _check_run_memory(plan: Sweep, todo, threads):
    """Refuse before starting when the runs at a time would pass the memory limit."""
    if plan.system is not None:
        samples = 0.0
        positions = {key: j for j, key in enumerate(plan.keys)}
        for _, values in todo:
            duration = values[positions["system.duration"]] if "system.duration" in positions \
                else plan.system["duration"]
            step = values[positions["system.time_step"]] if "system.time_step" in positions \
                else plan.system["time_step"]
            if duration > 0.0 and step > 0.0:
                samples = max(samples, duration / step)
        need = samples * BYTES_PER_SAMPLE
    else:
        samples = float(len(plan.motion["t"]))
        need = samples * _MOTION_BYTES_PER_SAMPLE
    check_memory(threads * need, f"{plan.name}: {threads} runs at a time of up to "
                                 f"{samples:.3g} samples each")


# --- the figure -----------------------------------------------------------------------------

def _numeric_positions(axis: Axis, values: list):
    """Plot coordinates of an axis's values, its tick labels (words), and whether it is log."""
    if axis.kind in ("str", "path"):
        labels = list(dict.fromkeys(axis.values or values))
        return [labels.index(value) for value in values], labels, False
    numbers = [float(value) for value in values]
    positive = bool(numbers) and min(numbers) > 0.0
    log = positive and (axis.log or max(numbers) / min(numbers) >= 100.0)
    return numbers, None, log


def _edges(centres, log):
    centres = np.asarray(centres, dtype=np.float64)
    if centres.size == 1:
        return np.array([centres[0] / 1.5, centres[0] * 1.5]) if log else \
            np.array([centres[0] - 0.5, centres[0] + 0.5])
    work = np.log(centres) if log else centres
    middle = 0.5 * (work[1:] + work[:-1])
    edges = np.concatenate(([2.0 * work[0] - middle[0]], middle, [2.0 * work[-1] - middle[-1]]))
    return np.exp(edges) if log else edges


def plot_results(results, spec, path, *, metrics=None, title=None, dpi=100) -> None:
    """Draw each metric against the swept parameters: a line over one, a map over two.

    Parameters
    ----------
    results : str, os.PathLike or dict
        The results table (a file, or columns as :func:`read_results` gives).
    spec : Sweep or str
        The sweep that made them (its axes say which scale to draw).
    path : str or os.PathLike
        The PNG to write (atomically).
    metrics : sequence of str, optional
        Default: every metric of the sweep.

    Notes
    -----
    With one swept parameter each metric is a line against it.  With two or
    more, a map over the first two: on a grid the cells of the runs whose
    other parameters are at their first value, otherwise one dot per run.
    Grey cells: the metric is undefined there (NaN: no stick-slip, a failed
    run, ...).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plan = spec if isinstance(spec, Sweep) else load_sweep(spec)
    table = read_results(results) if not isinstance(results, Mapping) else results
    names = list(metrics) if metrics is not None else [metric.name for metric in plan.metrics]
    units = {metric.name: metric.unit for metric in plan.metrics}
    rows = len(table["run"])
    failed = sum(status != "ok" for status in table["status"])
    shown = np.ones(rows, dtype=bool)
    note = ""
    x_axis = plan.axes[0]
    y_axis = plan.axes[1] if len(plan.axes) > 1 else None
    if len(plan.axes) > 2 and plan.method == "grid":
        fixed = []
        for axis in plan.axes[2:]:
            first = axis.grid()[0]
            shown &= np.array([value == first for value in table[axis.key]], dtype=bool)
            fixed.append(f"{axis.key} = {first:g}" if isinstance(first, float)
                         else f"{axis.key} = {first}")
        note = "at " + ", ".join(fixed)
    columns = 2 if len(names) == 4 else min(3, len(names))
    lines = math.ceil(len(names) / columns)
    figure, panels = plt.subplots(lines, columns, figsize=(4.6 * columns, 3.7 * lines),
                                  squeeze=False, layout="constrained")
    x_all, x_labels, x_log = _numeric_positions(x_axis, table[x_axis.key])
    x = np.asarray(x_all, dtype=np.float64)[shown]
    if y_axis is not None:
        y_all, y_labels, y_log = _numeric_positions(y_axis, table[y_axis.key])
        y = np.asarray(y_all, dtype=np.float64)[shown]
    for panel, metric in zip(panels.flat, names):
        values = np.asarray(table[metric], dtype=np.float64)[shown]
        label = f"{metric} [{units.get(metric, '')}]"
        if y_axis is None:
            order = np.argsort(x, kind="stable")
            panel.plot(x[order], values[order], marker="o", markersize=3, linewidth=1.2)
            panel.set_ylabel(label)
            panel.set_title(metric, fontsize=10)
        else:
            colours = plt.get_cmap("viridis").with_extremes(bad="0.85")
            if plan.method == "grid":
                x_centres = np.unique(x)
                y_centres = np.unique(y)
                grid = np.full((y_centres.size, x_centres.size), np.nan)
                grid[np.searchsorted(y_centres, y), np.searchsorted(x_centres, x)] = values
                image = panel.pcolormesh(_edges(x_centres, x_log), _edges(y_centres, y_log),
                                         np.ma.masked_invalid(grid), cmap=colours,
                                         shading="flat")
            else:
                panel.scatter(x[np.isnan(values)], y[np.isnan(values)], s=14, color="0.7",
                              marker="x", linewidths=0.8)
                image = panel.scatter(x, y, c=values, s=18, cmap=colours, plotnonfinite=False)
            figure.colorbar(image, ax=panel, label=label)
            panel.set_title(metric, fontsize=10)
            panel.set_ylabel(y_axis.key)
            if y_log:
                panel.set_yscale("log")
            if y_labels is not None:
                panel.set_yticks(range(len(y_labels)), [os.path.basename(v) for v in y_labels])
        panel.set_xlabel(x_axis.key)
        if x_log:
            panel.set_xscale("log")
        if x_labels is not None:
            panel.set_xticks(range(len(x_labels)), [os.path.basename(v) for v in x_labels])
    for panel in list(panels.flat)[len(names):]:
        panel.set_visible(False)
    heading = title or f"{plan.name}: {rows} of {plan.runs} runs"
    extras = [part for part in (note, f"{failed} failed" if failed else "",
                                "grey: undefined" if y_axis is not None else "") if part]
    figure.suptitle(heading + (f" ({'; '.join(extras)})" if extras else ""), fontsize=10)
    buffer = BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    plt.close(figure)
    io.atomic_write_bytes(path, buffer.getvalue())


# ``polind.sweep`` is this module and ``polind.sweep(...)`` runs a sweep: the module is
# callable, whichever of ``import polind.sweep`` and ``polind.sweep`` comes first.
class _CallableModule(types.ModuleType):
    def __call__(self, *args, **kwargs):
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
