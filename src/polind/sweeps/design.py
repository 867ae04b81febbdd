"""The design of a sweep: what it varies, over which values, in which runs.

A :class:`Sweep` holds the base model, the one-degree-of-freedom system or
the prescribed motion every run shares, the metrics to keep
(:mod:`polind.sweeps.metrics`) and the swept parameters: dotted keys into
``[model]`` and ``[system]``, each an :class:`Axis` (a list of values or a
range, linear or logarithmic).  Its :meth:`Sweep.design` is a grid (every
combination, in the order of the keys, the last varying fastest), a Latin
hypercube (:class:`scipy.stats.qmc.LatinHypercube`) or a uniform random
sample, seeded.  :func:`load_sweep` reads the ``[sweep]`` file
(:ref:`formats-sweep`, its keys :data:`SWEEP_KEYS`); every problem is an
:class:`polind.InputError` naming the file and the key.
"""

from __future__ import annotations

import copy
import difflib
import hashlib
import itertools
import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from polind.dynamics import FILE_KEYS, System, file_keys_of, system_from_keys
from polind.errors import InputError, describe
from polind.io import (check_tables, read_document, read_motion_csv,
                       read_system_file)
from polind.models import FrictionModel, model_from_dict, read_model_document
from polind.models.params import Table
from polind.sweeps.metrics import METRICS, NEEDS
from polind.sweeps.runs import RunPlan, file_digest

__all__ = ["METHODS", "SWEEP_KEYS", "SYSTEM_KEYS", "Axis", "Sweep", "is_finite", "is_number",
           "is_whole", "load_sweep"]

#: The designs of a sweep (``sweep.method``).
METHODS = ("grid", "latin-hypercube", "random")

#: The keys of a [system] file (:ref:`formats-system`) and the System fields they set.
SYSTEM_KEYS = FILE_KEYS

#: The keys of a [sweep] table (:ref:`formats-sweep`).
SWEEP_KEYS = ("model", "system", "motion", "metrics", "method", "samples", "seed", "parameters")


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

    def at(self, fraction: float) -> float:
        """The point ``fraction`` (0 to 1) of the way across the range, linear or in log.

        Finite for every finite range: where the width (or the ratio, in log)
        of the range passes the largest double, the ends are weighted instead.
        """
        low, high = self.low, self.high
        if self.log:
            ratio = high / low
            if 0.0 < ratio < math.inf:
                return float(low * ratio ** fraction)
            sign = math.copysign(1.0, low)
            return sign * math.exp((1.0 - fraction) * math.log(abs(low))
                                   + fraction * math.log(abs(high)))
        width = high - low
        if math.isfinite(width):
            return float(low + width * fraction)
        return float((1.0 - fraction) * low + fraction * high)

    def grid(self) -> list:
        """The axis's values on a grid: its ``values``, or ``count`` points over its range."""
        if self.values is not None:
            return list(self.values)
        if self.count == 1:
            return [self.low]
        points = [self.at(k / (self.count - 1)) for k in range(self.count)]
        points[0], points[-1] = self.low, self.high
        return points

    def sample(self, u: np.ndarray) -> list:
        """Values for uniform samples ``u`` in [0, 1): the range (linear or in log) or the list."""
        if self.values is not None:
            n = len(self.values)
            return [self.values[min(int(p * n), n - 1)] for p in u.tolist()]
        return [self.at(p) for p in u.tolist()]


def _model_keys(model: FrictionModel) -> list[str]:
    def walk(entries, prefix):
        for entry in entries:
            if isinstance(entry, Table):
                yield from walk(entry.entries, f"{prefix}{entry.key}.")
            elif entry.kind in ("float", "int", "str", "path"):
                yield f"model.{prefix}{entry.key}"
    return list(walk(model.parameters, ""))


def is_number(value) -> bool:
    """Whether ``value`` is an int or a float (NumPy's too), not a bool."""
    return not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))


def is_finite(value) -> bool:
    """Whether ``value`` is a number that is a finite double (a 400-digit integer is not)."""
    try:
        return is_number(value) and math.isfinite(value)
    except OverflowError:
        return False


def is_whole(value) -> bool:
    """Whether ``value`` is an integer (an int, NumPy's, or a whole finite float), not a bool."""
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, np.integer)):
        return True
    return is_finite(value) and float(value).is_integer()


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
            if kind == "float" and is_finite(value):
                clean.append(float(value))
            elif kind == "int" and is_whole(value) and is_finite(value):
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
            and all(is_finite(b) for b in bounds)):
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
    if count is not None and not (is_whole(count) and count >= 1):
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
        Names in :data:`~polind.sweeps.METRICS`.
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
            document = read_model_document(path)
            where = _Where(path)
        else:
            raise where.error("sweep.model", f"expected a model file; got {describe(model)}")
        try:
            self.model = model_from_dict(document)
        except InputError as error:
            raise InputError(f"{where.name}: {error}") from None
        self.model_table = self.model.to_dict()["model"]
        self.inputs.extend(self.model.files())      # a heights file, a height map

    def _load_drive(self, where, system, motion):
        if (system is None) == (motion is None):
            raise where.error("sweep.system", "expected exactly one of 'system' (a [system] "
                                              "file) and 'motion' (a motion file)")
        self.system = self.motion = self.motion_file = None
        if system is not None:
            if isinstance(system, System):
                self.system = {key: getattr(system, field_name)
                               for key, field_name in SYSTEM_KEYS.items()}
            elif isinstance(system, (str, os.PathLike)):
                path = self._path(system)
                self.inputs.append(path)
                self.system = file_keys_of(read_system_file(path))
                try:
                    system_from_keys(self.system)
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
            self.motion = read_motion_csv(path)
            self.motion_file = path
        else:
            raise where.error("sweep.motion", f"expected a motion file; got {describe(motion)}")

    def _load_design_size(self, where, samples, seed):
        if not (is_whole(seed) and 0 <= seed < 2 ** 64):
            raise where.error("sweep.seed", f"expected a non-negative integer below 2**64; "
                                            f"got {describe(seed)}")
        self.seed = int(seed)
        self.samples = None
        # Checked on a grid too (where it is not used): a wrong value is a mistake all the same.
        if samples is not None and not (is_whole(samples) and samples >= 1):
            raise where.error("sweep.samples", f"expected a positive integer; got "
                                               f"{describe(samples)}")
        if self.method == "grid":
            return
        if samples is None:
            raise where.error("sweep.samples", f"a {self.method} design needs the number of "
                                               "runs; give samples = N")
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
            if kind == "path":
                self.inputs.extend(self._path(value) for value in axes[-1].values)
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

    def file_digests(self) -> dict:
        """The SHA-256 of each file the runs read by name (None: missing or unreadable).

        Keyed by the file as messages show it: the model's own files (a
        heights file, a height map), the files a swept key names, and the
        motion file.  Read afresh at each call: a results table records
        them when it is made and compares them when a sweep resumes it.
        """
        files = list(self.model.files())
        for axis in self.axes:
            if axis.kind == "path":
                files.extend(self._path(value) for value in axis.values)
        if self.motion_file is not None:
            files.append(self.motion_file)
        return {name: file_digest(name) for name in dict.fromkeys(files)}

    def fingerprint(self, digests=None) -> str:
        """A digest of what every run shares: model, system or motion, metrics, polind's version.

        The swept keys' own values in the model and system files do not
        count; a metric counts by its name, unit and definition; a file that
        the model or a swept key names counts by its contents (``digests``,
        default :meth:`file_digests`), not its name.
        """
        digests = self.file_digests() if digests is None else digests
        model = copy.deepcopy(self.model_table)
        for entries, key, value in self.model.files_in(model):
            entries[key] = digests.get(value)
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
        swept_files = {axis.key: {value: digests.get(self._path(value)) for value in axis.values}
                       for axis in self.axes if axis.kind == "path"}
        from polind import __version__

        text = json.dumps({"model": model, "system": system, "motion": motion,
                           "swept_files": swept_files,
                           "metrics": [[metric.name, metric.unit, metric.definition]
                                       for metric in self.metrics],
                           "polind": __version__}, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def record(self) -> dict:
        """What a results table records of the sweep that made it (JSON-able).

        ``fingerprint`` (:meth:`fingerprint`), ``files`` (:meth:`file_digests`),
        ``sweep`` (its name) and ``runs``.
        """
        digests = self.file_digests()
        return {"fingerprint": self.fingerprint(digests), "files": digests,
                "sweep": self.name, "runs": self.runs}

    def plan(self, digests=None) -> RunPlan:
        """What every run needs (:class:`polind.sweeps.runs.RunPlan`).

        ``digests`` (default :meth:`file_digests`, read now) are the SHA-256
        each run checks the files it reads against, before and after it runs:
        those of the record of the results table, so that no row of it comes
        from another version of a file.
        """
        digests = self.file_digests() if digests is None else digests
        files = {os.path.abspath(name): (name, digests.get(name)) for name in self.model.files()}
        for axis in self.axes:
            if axis.kind == "path":
                for value in axis.values:
                    opened = value if os.path.isabs(value) else os.path.join(self.base_dir, value)
                    shown = self._path(value)
                    files[os.path.abspath(opened)] = (shown, digests.get(shown))
        return RunPlan(model=self.model_table, system=self.system, motion=self.motion,
                       keys=self.keys, kinds=tuple(axis.kind for axis in self.axes),
                       metrics=self.metrics, base_dir=self.base_dir, files=files)


def load_sweep(path) -> Sweep:
    """Read a sweep file (TOML, or JSON by extension; :ref:`formats-sweep`).

    Relative file names in it point from the sweep file's directory.  Every
    problem raises :class:`polind.InputError` naming the file and the key.
    """
    name = os.fspath(path)
    document = read_document(path)
    check_tables(name, document, required=("sweep",), allowed=("sweep",))
    table = document["sweep"]
    for key in table:
        if key not in SWEEP_KEYS:
            raise InputError(f"{name}: unknown key 'sweep.{key}'; expected one of: "
                             + ", ".join(f"sweep.{k}" for k in SWEEP_KEYS))
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
