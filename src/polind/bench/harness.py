"""The benchmark's harness: the cases, their timing, and the table ``polind bench`` prints.

The cases come from the model registry: every registered model is
benchmarked, a model with elements (``has_elements``) at every count of
:data:`ELEMENT_COUNTS` (``example(elements=n)``), any other once
(``example()``).  For each case it times the model's kernel over a
prescribed path (the hot loop: the element update) and, in the same run, the
same work done by the model's plain NumPy loop
(:func:`polind.bench.references.numpy_reference`) — the step loop in Python,
the elements vectorised — and reports element-steps per second and their
ratio.  The forces of the two are compared, so both sides demonstrably do the
same work.  A model without a NumPy loop (a plugin's, a new one) is timed
all the same; its NumPy column and ratio are "—".  Times are the best of a
few repeats after a warm-up call (which also loads numba's cache).

The motion is a sinusoid whose amplitude is large against the element slip
distances, so the elements cycle through stick and slip and every branch of
the element law runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from polind.bench.references import numpy_reference
from polind.models.registry import load_plugins, model_class
from polind.simulation import make_path

#: The element counts a model with elements is benchmarked at.
ELEMENT_COUNTS = (1, 64, 1024)

#: What the table shows where a model has no NumPy loop.
MISSING = "—"


@dataclass
class BenchRow:
    model: str
    elements: int
    steps: int
    kernel_rate: float                    # element-steps per second, numba kernel
    numpy_rate: float | None = None       # element-steps per second, plain NumPy loop
    max_difference: float | None = None   # max |F_kernel - F_numpy| / max |F|

    @property
    def ratio(self) -> float | None:
        """numba over NumPy, or None without a NumPy loop."""
        return None if self.numpy_rate is None else self.kernel_rate / self.numpy_rate


def bench_path(steps, amplitude=2e-5, frequency=2.0, dt=1e-4):
    """The benchmark's motion: ``steps`` samples of a sinusoid (20 um, 2 Hz) at 10 kHz."""
    t = np.arange(steps) * dt
    return make_path(t, x=amplitude * np.sin(2.0 * np.pi * frequency * t))


def model_types(models=None):
    """The model types to benchmark: ``models``, or every registered one (plugins loaded).

    A name that is not a registered type is an :class:`~polind.InputError`
    listing the registered ones.
    """
    if not models:
        return list(load_plugins())
    for model_type in models:
        model_class(model_type, "for the benchmark")
    return list(models)


def element_counts(model_type):
    """The element counts a type is run at: :data:`ELEMENT_COUNTS` with elements, else (1,)."""
    return ELEMENT_COUNTS if model_class(model_type).has_elements else (1,)


def cases(models=None):
    """The (model type, element count) pairs the benchmark runs (default: every registered type)."""
    return [(model_type, n) for model_type in model_types(models)
            for n in element_counts(model_type)]


def bench_model(model_type, n=1):
    """The model a type is benchmarked as: ``example(elements=n)`` with elements, else
    ``example()``."""
    cls = model_class(model_type, "for the benchmark")
    return cls.example(elements=n) if cls.has_elements else cls.example()


def _best_time(function, repeats):
    best = np.inf
    result = None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def _steps_for(seconds, probe_steps, probe_time, low, high):
    """Steps that take about ``seconds``, judged from a probe run."""
    per_step = max(probe_time, 1e-9) / probe_steps
    return int(min(max(seconds / per_step, low), high))


def run_case(model_type, n, kernel_seconds=0.3, numpy_seconds=1.0, repeats=3):
    """Time one model at ``n`` elements; returns a :class:`BenchRow`.

    Both sides are sized from a probe run to take about ``kernel_seconds``
    and ``numpy_seconds``; the kernel is timed best of ``repeats``.  Without a
    NumPy loop for the model, the row's NumPy rate and difference are None.
    """
    model = bench_model(model_type, n)
    elements = n if type(model).has_elements else 1
    probe = bench_path(20_000)
    model._advance(bench_path(64), model.initial_state(), None)     # compile / load cache
    probe_time, _ = _best_time(lambda: model._advance(probe, model.initial_state(), None), 1)
    steps = _steps_for(kernel_seconds, 20_000, probe_time, 2e4, 5e7)
    path = bench_path(steps)
    kernel_time, _ = _best_time(
        lambda: model._advance(path, model.initial_state(), None), repeats)
    row = BenchRow(model_type, elements, steps, steps * elements / kernel_time)
    reference = numpy_reference(model)
    if reference is None:
        return row
    probe_numpy = bench_path(100)
    numpy_probe_time, _ = _best_time(lambda: reference(probe_numpy), 1)
    numpy_steps = _steps_for(numpy_seconds, 100, numpy_probe_time, 200, steps)
    short = bench_path(numpy_steps)
    numpy_time, numpy_force = _best_time(lambda: reference(short), 1)
    kernel_force = model._advance(short, model.initial_state(), None)
    scale = max(np.max(np.abs(numpy_force)), 1e-300)
    row.numpy_rate = numpy_steps * elements / numpy_time
    row.max_difference = float(np.max(np.abs(kernel_force - numpy_force)) / scale)
    return row


def _cell(value, spec, width):
    return f"{MISSING:>{width}}" if value is None else f"{value:>{width}{spec}}"


def format_table(rows):
    """The rows as the table ``polind bench`` prints, under its header line."""
    lines = [f"{'model':<14}{'elements':>9}{'steps':>11}{'numba el-steps/s':>19}"
             f"{'NumPy el-steps/s':>19}{'ratio':>9}{'max rel diff':>14}"]
    for r in rows:
        lines.append(f"{r.model:<14}{r.elements:>9}{r.steps:>11}{r.kernel_rate:>19.3e}"
                     f"{_cell(r.numpy_rate, '.3e', 19)}{_cell(r.ratio, '.0f', 9)}"
                     f"{_cell(r.max_difference, '.1e', 14)}")
    return "\n".join(lines)
