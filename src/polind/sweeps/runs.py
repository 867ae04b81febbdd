"""One run of a sweep: the row of a run, a pure function of its plan and its values.

:class:`RunPlan` is what every run of a sweep shares (the model and system
tables or the motion, the swept keys, the metrics), sent once to each Dask
worker; :func:`run_one` sets a run's values in copies of those tables,
simulates the system (:func:`polind.simulate_system`) or the prescribed
motion (:func:`polind.simulate`) and computes the metrics
(:mod:`polind.sweeps.metrics`).  A run that fails is a row all the same, its
``status`` the one-line error (:func:`one_line`), so that a sweep goes on;
so is a run whose output is not finite (NaN or inf from a model, whoever
wrote it), its status naming the quantity, the sample and the model.

Every file a run reads by name (a ``heights_file``, a ``topography`` map, a
swept file) is checked against the SHA-256 recorded when the sweep started
(:attr:`RunPlan.files`), before the run and again after it: a run that may
have read another version of a file gives no row but a :data:`CHANGED` entry
naming the file, and the engine stops the sweep on it
(:mod:`polind.sweeps.engine`), so that the rows of one table never mix two
versions of an input.
"""

from __future__ import annotations

import copy
import hashlib
import math
import os
import threading
import time
from dataclasses import dataclass, field

from polind.dynamics import simulate_system, system_from_keys
from polind.errors import InputError
from polind.models import model_from_dict
from polind.simulation import check_finite_output, simulate
from polind.sweeps.metrics import RunOutput

__all__ = ["CHANGED", "RunPlan", "file_digest", "one_line", "run_one"]

#: The key of a run's row that names an input file found changed since the sweep started
#: (such a row is not a result: the engine stops the sweep instead of recording it).
CHANGED = "changed"


class _Cancelled(BaseException):
    """The sweep is stopping: a running run gives up at its next progress report."""


@dataclass(frozen=True)
class RunPlan:
    """What every run needs (sent once to each Dask worker)."""

    model: dict
    system: dict | None
    motion: dict | None
    keys: tuple
    kinds: tuple
    metrics: tuple
    base_dir: str
    #: The files a run may read by name: absolute path to (the name messages show, the
    #: SHA-256 recorded when the sweep started, None if it could not be read then).
    files: dict = field(default_factory=dict)


def file_digest(name):
    """The SHA-256 (hex) of a file's contents, read a MiB at a time; None if it cannot be read."""
    digest = hashlib.sha256()
    try:
        with open(name, "rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
    except OSError:
        return None
    return digest.hexdigest()


def _changed_file(plan: RunPlan, model) -> tuple:
    """``(name, None)`` of a file the run reads whose contents are not those recorded, or
    ``(None, message)`` of one that cannot be read now, or ``(None, None)``."""
    for path in model.files():
        entry = plan.files.get(os.path.abspath(path))
        if entry is None:
            continue
        name, recorded = entry
        now = file_digest(path)
        if now is None and recorded is not None:
            return None, (f"{name}: cannot be read now (it could when the sweep started); "
                          f"expected the file the sweep started with")
        if now != recorded:
            return name, None
    return None, None


def _check_finite(output: RunOutput, model) -> None:
    """InputError naming the first quantity of a run's output that is NaN or infinite (the
    drivers' own check, :func:`polind.simulation.check_finite_output`, over all it wrote)."""
    check_finite_output(model, output.t, (
        ("friction force", output.force), ("driving force", output.applied),
        ("position", output.x), ("velocity", output.v), ("time", output.t)))


def one_line(error: BaseException) -> str:
    """An error on one line: its message (after its type's name unless an InputError)."""
    text = " ".join(str(error).split())
    return text if isinstance(error, InputError) else f"{type(error).__name__}: {text}"


def _simulate(plan: RunPlan, model, system, progress) -> RunOutput:
    """The output of one run: the system's (a body) or the prescribed motion's."""
    if system is not None:
        body = system_from_keys(system)
        result = simulate_system(model, body, progress=progress)
        return RunOutput(result.t, result.x, result.v, result.force, result.applied, body, model)
    motion = plan.motion
    result = simulate(model, motion["t"], x=motion.get("x"), v=motion.get("v"),
                      normal_load=motion.get("normal_load"), progress=progress)
    return RunOutput(result.t, result.x, result.v, result.force, None, None, model)


def run_one(plan: RunPlan, index: int, values: tuple,
            stop: threading.Event | None = None) -> dict:
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

    def changed(name):
        row[CHANGED] = name
        row["status"] = f"{name}: changed since the sweep started"
        row["seconds"] = time.perf_counter() - started
        return row

    model = None
    try:
        model = model_from_dict({"model": table})
        name, unreadable = _changed_file(plan, model)
        if name is not None:
            return changed(name)
        if unreadable is not None:
            raise InputError(unreadable)
        output = _simulate(plan, model, system, check_stop)
        _check_finite(output, model)
        for metric in plan.metrics:
            value = float(metric.compute(output))
            if math.isinf(value):
                # NaN says "not defined for this run"; an infinity is no number at all.
                raise InputError(f"the metric '{metric.name}' is {value} (beyond double "
                                 f"precision); expected a finite value")
            row[metric.name] = value
        row["status"] = "ok"
    except Exception as error:  # noqa: BLE001 - a failed run is a row, and the sweep goes on
        for metric in plan.metrics:
            row[metric.name] = math.nan
        row["status"] = one_line(error) or type(error).__name__
    if model is not None:
        name, _ = _changed_file(plan, model)    # it may have read another version meanwhile
        if name is not None:
            return changed(name)
    row["seconds"] = time.perf_counter() - started
    return row
