"""One run of a sweep: the row of a run, a pure function of its plan and its values.

:class:`RunPlan` is what every run of a sweep shares (the model and system
tables or the motion, the swept keys, the metrics), sent once to each Dask
worker; :func:`run_one` sets a run's values in copies of those tables,
simulates the system (:func:`polind.simulate_system`) or the prescribed
motion (:func:`polind.simulate`) and computes the metrics
(:mod:`polind.sweeps.metrics`).  A run that fails is a row all the same, its
``status`` the one-line error (:func:`one_line`), so that a sweep goes on.
"""

from __future__ import annotations

import copy
import math
import os
import threading
import time
from dataclasses import dataclass

from polind.dynamics import simulate_system, system_from_keys
from polind.errors import InputError
from polind.models import model_from_dict
from polind.simulation import simulate
from polind.sweeps.metrics import RunOutput

__all__ = ["RunPlan", "one_line", "run_one"]


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


def one_line(error: BaseException) -> str:
    """An error on one line: its message (after its type's name unless an InputError)."""
    text = " ".join(str(error).split())
    return text if isinstance(error, InputError) else f"{type(error).__name__}: {text}"


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

    try:
        model = model_from_dict({"model": table})
        if system is not None:
            body = system_from_keys(system)
            result = simulate_system(model, body, progress=check_stop)
            output = RunOutput(result.t, result.x, result.v, result.force, result.applied, body,
                               model)
        else:
            motion = plan.motion
            result = simulate(model, motion["t"], x=motion.get("x"), v=motion.get("v"),
                              normal_load=motion.get("normal_load"), progress=check_stop)
            output = RunOutput(result.t, result.x, result.v, result.force, None, None, model)
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
    row["seconds"] = time.perf_counter() - started
    return row
