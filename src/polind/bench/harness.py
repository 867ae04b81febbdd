"""The benchmark's harness: the cases, their timing, and the table ``polind bench`` prints.

For each model and element count it times the model's kernel over a
prescribed path (the hot loop: the element update) and, in the same run,
the same work done by the model's plain NumPy loop
(:mod:`polind.bench.references`) — the step loop in Python, the elements
vectorised — and reports element-steps per second and their ratio.  The
forces of the two are compared, so both sides demonstrably do the same work.
Times are the best of a few repeats after a warm-up call (which also loads
numba's cache).

The motion is a sinusoid whose amplitude is large against the element slip
distances, so the elements cycle through stick and slip and every branch of
the element law runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from polind.bench.references import (numpy_dahl, numpy_gms, numpy_leuven, numpy_lugre,
                                     numpy_maxwell_slip, numpy_stribeck)
from polind.errors import InputError
from polind.models import model_from_dict
from polind.simulate import make_path

ELEMENT_COUNTS = (1, 64, 1024)

_STRIBECK = {"coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
             "stribeck_exponent": 2.0}


@dataclass
class BenchRow:
    model: str
    elements: int
    steps: int
    kernel_rate: float      # element-steps per second, numba kernel
    numpy_rate: float       # element-steps per second, plain NumPy loop
    max_difference: float   # max |F_kernel - F_numpy| / max |F|

    @property
    def ratio(self) -> float:
        return self.kernel_rate / self.numpy_rate


def _elements(n, seed=0):
    rng = np.random.default_rng(seed)
    stiffness = 10.0 ** rng.uniform(5.0, 7.0, n)
    slip = 10.0 ** rng.uniform(-7.0, -5.0, n)
    breakaway = stiffness * slip
    return stiffness, breakaway


def _maxwell_slip_table(n):
    stiffness, breakaway = _elements(n)
    return {"stiffness": stiffness.tolist(), "breakaway_force": breakaway.tolist()}


def _gms_table(n):
    stiffness, breakaway = _elements(n)
    return {"stiffness": stiffness.tolist(), "weight": (breakaway / breakaway.sum()).tolist(),
            "attraction": 1e4, **_STRIBECK}


def _leuven_table(n):
    stiffness, breakaway = _elements(n)
    scaled = breakaway * (_STRIBECK["static_force"] / breakaway.sum())
    return {"stiffness": stiffness.tolist(), "breakaway_force": scaled.tolist(),
            "exponent": 2.0, "bristle_damping": 10.0, **_STRIBECK}


def _pol_ind_table(n):
    from polind.models.pol_ind import default_table
    table = default_table()
    table["discretisation"]["elements"] = n
    return table


def bench_path(steps, amplitude=2e-5, frequency=2.0, dt=1e-4):
    t = np.arange(steps) * dt
    return make_path(t, x=amplitude * np.sin(2.0 * np.pi * frequency * t))


def _curve(p):
    return [p[key] for key in ("coulomb_force", "static_force", "stribeck_velocity",
                               "stribeck_exponent")]


def _gms_reference(p, path):
    return numpy_gms(path, np.array(p["stiffness"]), np.array(p["weight"]), p["attraction"],
                     *_curve(p))


@dataclass(frozen=True)
class BenchCase:
    """One benchmarked model: its parameter table at ``n`` elements and its NumPy loop.

    ``table(n)`` gives the ``[model]`` keys besides ``type``; ``reference(model,
    path)`` runs the plain NumPy loop of the same physics; ``elements`` says
    whether the model is run at every element count or once.
    """

    table: object
    reference: object
    elements: bool = False


#: The benchmark's cases, by model type: the models it times and the NumPy loops it
#: times them against (written from the mathematics, not from the kernels).
CASES = {
    "maxwell-slip": BenchCase(_maxwell_slip_table, lambda model, path: numpy_maxwell_slip(
        path, np.array(model.params["stiffness"]), np.array(model.params["breakaway_force"])),
        elements=True),
    "gms": BenchCase(_gms_table, lambda model, path: _gms_reference(model.params, path),
                     elements=True),
    # At its constant load Pol-Ind is the GMS of its element table (user guide, "The
    # rate-state law").
    "pol-ind": BenchCase(_pol_ind_table,
                         lambda model, path: _gms_reference(model.gms_parameters(), path),
                         elements=True),
    "leuven": BenchCase(_leuven_table, lambda model, path: numpy_leuven(
        path, np.array(model.params["stiffness"]), np.array(model.params["breakaway_force"]),
        model.params["exponent"], model.params["bristle_damping"], *_curve(model.params)),
        elements=True),
    "lugre": BenchCase(lambda n: {"bristle_stiffness": 1e5, "bristle_damping": 316.2,
                                  **_STRIBECK},
                       lambda model, path: numpy_lugre(
                           path, model.params["bristle_stiffness"],
                           model.params["bristle_damping"], *_curve(model.params))),
    "dahl": BenchCase(lambda n: {"stiffness": 1e5, "coulomb_force": 1.0},
                      lambda model, path: numpy_dahl(path, model.params["stiffness"],
                                                     model.params["coulomb_force"])),
    "stribeck": BenchCase(lambda n: {"viscous_coefficient": 0.4, **_STRIBECK},
                          lambda model, path: numpy_stribeck(
                              path, *_curve(model.params),
                              model.params["viscous_coefficient"])),
}


def _case(model_type):
    if model_type not in CASES:
        raise InputError(f"The benchmark has no case for the model type '{model_type}'; it "
                         f"benchmarks: {', '.join(CASES)}.")
    return CASES[model_type]


def bench_model(model_type, n):
    """A benchmark model with ``n`` elements (the element count is 1 for single-state models)."""
    return model_from_dict({"model": {"type": model_type, **_case(model_type).table(n)}})


def _numpy_reference(model_type, model, path):
    return _case(model_type).reference(model, path)


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
    and ``numpy_seconds``; the kernel is timed best of ``repeats``.
    """
    model = bench_model(model_type, n)
    elements = n if _case(model_type).elements else 1
    probe = bench_path(20_000)
    model._advance(bench_path(64), model.initial_state(), None)     # compile / load cache
    probe_time, _ = _best_time(lambda: model._advance(probe, model.initial_state(), None), 1)
    steps = _steps_for(kernel_seconds, 20_000, probe_time, 2e4, 5e7)
    path = bench_path(steps)
    kernel_time, _ = _best_time(
        lambda: model._advance(path, model.initial_state(), None), repeats)
    probe_numpy = bench_path(100)
    numpy_probe_time, _ = _best_time(lambda: _numpy_reference(model_type, model, probe_numpy), 1)
    numpy_steps = _steps_for(numpy_seconds, 100, numpy_probe_time, 200, steps)
    short = bench_path(numpy_steps)
    numpy_time, numpy_force = _best_time(lambda: _numpy_reference(model_type, model, short), 1)
    reference = model._advance(short, model.initial_state(), None)
    scale = max(np.max(np.abs(numpy_force)), 1e-300)
    difference = float(np.max(np.abs(reference - numpy_force)) / scale)
    return BenchRow(model_type, elements, steps, steps * elements / kernel_time,
                    numpy_steps * elements / numpy_time, difference)


def cases(models=None):
    """The (model type, element count) pairs the benchmark runs (default: every case)."""
    chosen = models or list(CASES)
    out = []
    for model_type in chosen:
        counts = ELEMENT_COUNTS if _case(model_type).elements else (1,)
        out.extend((model_type, n) for n in counts)
    return out


def format_table(rows):
    lines = [f"{'model':<14}{'elements':>9}{'steps':>11}{'numba el-steps/s':>19}"
             f"{'NumPy el-steps/s':>19}{'ratio':>9}{'max rel diff':>14}"]
    for r in rows:
        lines.append(f"{r.model:<14}{r.elements:>9}{r.steps:>11}{r.kernel_rate:>19.3e}"
                     f"{r.numpy_rate:>19.3e}{r.ratio:>9.0f}{r.max_difference:>14.1e}")
    return "\n".join(lines)
