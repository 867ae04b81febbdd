"""The performance benchmark behind ``polind bench`` and ``benchmarks/``.

For each model and element count it times the model's kernel over a
prescribed path (the hot loop: the element update) and, in the same run,
the same work done by a plain NumPy loop — the step loop in Python, the
elements vectorised — and reports element-steps per second and their ratio.
The NumPy loops are written from the equations of the user guide, not from the
kernels, and their
forces are compared with the kernel's, so both sides demonstrably do the
same work.  Times are the best of a few repeats after a warm-up call (which
also loads numba's cache).

The motion is a sinusoid whose amplitude is large against the element slip
distances, so the elements cycle through stick and slip and every branch of
the element law runs.

:func:`run_ratios` adds rows that are ratios of two timings taken in the same
run (the figures the user-loop API is held to): :class:`polind.Stepper`
against a bare Python-to-numba call, :func:`polind.simulation` end to end
against bare numba loops written here from the user guide's equations, and the
Pol-Ind model
under a varying against a constant normal load.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.kernels import jit
from polind.models import model_from_dict
from polind.models.base import STATE_OFFSET, TABLE_OFFSET, page_placed
from polind.simulation import make_path
from polind.models.static import stribeck_curve

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


# --- plain NumPy references (step loop in Python, elements vectorised) ----------------

def numpy_maxwell_slip(path, stiffness, breakaway):
    force = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        force = np.clip(force + stiffness * path.displacement[k], -breakaway, breakaway)
        out[k] = force.sum()
    return out


def numpy_gms(path, stiffness, weight, attraction, fc, fs, vs, delta):
    force = np.zeros_like(stiffness)
    slip = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        v = path.step_velocity[k]
        if v == 0.0:
            out[k] = force.sum()
            continue
        g = stribeck_curve(v, fc, fs, vs, delta)
        direction = np.sign(v)
        capacity = weight * g
        target = direction * capacity
        relaxed = target + (force - target) * np.exp(-attraction * path.step[k] / (weight * g))
        trial = force + stiffness * path.displacement[k]
        slipping = (slip == direction) | (direction * force >= capacity)
        crosses = direction * trial >= capacity
        force = np.where(slipping, relaxed, np.where(crosses, target, trial))
        slip = np.where(slipping | crosses, direction, 0.0)
        out[k] = force.sum()
    return out


def numpy_lugre(path, sigma0, sigma1, fc, fs, vs, delta):
    z = 0.0
    out = np.empty(path.t.shape[0])
    for k in range(path.t.shape[0]):
        if k > 0 and path.step_velocity[k] != 0.0:
            v = path.step_velocity[k]
            g = stribeck_curve(v, fc, fs, vs, delta)
            steady = np.sign(v) * g / sigma0
            z = steady + (z - steady) * np.exp(-sigma0 * abs(v) * path.step[k] / g)
        v = path.sample_velocity[k]
        g = stribeck_curve(v, fc, fs, vs, delta)
        out[k] = sigma0 * z + sigma1 * (v - sigma0 * abs(v) * z / g)
    return out


def numpy_dahl(path, sigma0, fc):
    force = 0.0
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        dx = path.displacement[k]
        if dx != 0.0:
            s = np.sign(dx)
            force = s * fc - (s * fc - force) * np.exp(-sigma0 * abs(dx) / fc)
        out[k] = force
    return out


def numpy_leuven(path, stiffness, breakaway, exponent, sigma1, fc, fs, vs, delta):
    """Backward Euler on the Leuven state equation (:ref:`guide-leuven`), brentq per step."""
    from scipy.optimize import brentq

    force = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    bound = breakaway.sum()
    for k in range(1, path.t.shape[0]):
        v, h = path.step_velocity[k], path.step[k]
        dz = 0.0
        if v != 0.0:
            s = np.sign(v) * stribeck_curve(v, fc, fs, vs, delta)

            def residual(increment):
                r = np.clip(force + stiffness * increment, -breakaway, breakaway).sum() / s
                return increment - v * h * (1.0 - np.sign(r) * abs(r) ** exponent)

            reach = abs(v * h) * (1.0 + (bound / abs(s)) ** exponent) * 1.000001
            dz = brentq(residual, -reach, reach, xtol=1e-300, rtol=1e-15)
        force = np.clip(force + stiffness * dz, -breakaway, breakaway)
        out[k] = force.sum() + sigma1 * dz / h
    return out


def numpy_stribeck(path, fc, fs, vs, delta, sigma2):
    out = np.empty(path.t.shape[0])
    for k in range(path.t.shape[0]):
        v = path.sample_velocity[k]
        out[k] = np.sign(v) * stribeck_curve(v, fc, fs, vs, delta) + sigma2 * v
    return out


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


@dataclass
class SeparationRow:
    asperities: int
    build_seconds: float     # sampling and sorting the heights (once per surface)
    solve_seconds: float     # one cold separation solve at the default load
    evaluations: int
    relative_residual: float


def run_separation(asperities=1_000_000, normal_load=100.0, seed=0):
    """Time the iterative method (:ref:`guide-pol-ind-separation`) on a directly summed surface.

    The surface of the default Pol-Ind parameters with ``asperities`` seeded
    Gaussian summits; the solve is timed cold (first solve on the surface),
    best of three fresh surfaces.
    """
    from polind.contact import DirectSurface, effective_moduli, solve_separation
    from polind.models.pol_ind import default_table

    table = default_table()
    surface_params = table["surface"]
    e_star, g_star = effective_moduli(210e9, 0.3, 210e9, 0.3)
    density = asperities / surface_params["nominal_area"]
    build = solve = np.inf
    for _ in range(3):
        start = time.perf_counter()
        surface = DirectSurface.from_seed(density, surface_params["nominal_area"],
                                          surface_params["height_std"],
                                          surface_params["asperity_radius"], e_star, g_star,
                                          seed=seed)
        middle = time.perf_counter()
        separation, evaluations = solve_separation(surface, normal_load, full_output=True)
        end = time.perf_counter()
        build = min(build, middle - start)
        solve = min(solve, end - middle)
    residual = abs(surface.normal_load(separation) - normal_load) / normal_load
    return SeparationRow(asperities, build, solve, int(evaluations), float(residual))


# --- ratios measured within one run --------------------------------------------------
#
# The machine the figures are taken on is shared, and absolute rates vary by 2x between
# runs; a ratio of two timings taken in the same run, interleaved, varies much less.
# Each row below times two things round-robin (one after the other, ``rounds`` times,
# after a warm-up call of each that also compiles or loads numba's cache) and keeps the
# best time of each.  The references are deliberately bare numba loops, written here
# from the user guide's equations: they are what a user would write by hand for one model
# and one kind of
# motion, with nothing else (no validation, no path preparation, no state object).

@dataclass
class RatioRow:
    name: str            # what is compared with what
    value: float         # the measured ratio
    target: float
    at_most: bool        # the target is an upper bound (a cost) or a lower bound (a speed)
    detail: str = ""     # the two timings, and how far the two sides' forces agree

    @property
    def met(self) -> bool:
        return self.value <= self.target if self.at_most else self.value >= self.target


def _interleaved(functions, rounds):
    """Best time [s] of each function over ``rounds`` round-robin passes, after a warm-up."""
    for function in functions:
        function()
    best = [np.inf] * len(functions)
    for _ in range(rounds):
        for i, function in enumerate(functions):
            start = time.perf_counter()
            function()
            best[i] = min(best[i], time.perf_counter() - start)
    return best


def _relative_difference(a, b):
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


# The references, compiled with the kernels' own numba options (polind.kernels.jit).

@jit
def bare_call(value):
    """The cheapest Python-to-numba call: one float in, the same float out."""
    return value


@jit
def bare_maxwell_slip(x, stiffness, slip, z, out):
    """Maxwell-slip on positions: ``z_i = clip(z_i + dx, -D_i, D_i)``, ``F = sum k_i z_i``."""
    out[0] = 0.0
    for k in range(1, x.shape[0]):
        dx = x[k] - x[k - 1]
        force = 0.0
        for i in range(z.shape[0]):
            zi = min(max(z[i] + dx, -slip[i]), slip[i])
            z[i] = zi
            force += stiffness[i] * zi
        out[k] = force


@jit
def bare_lugre(t, x, sigma0, sigma1, sigma2, fc, fs, vs, out):
    """LuGre's exact exponential step (:ref:`guide-lugre`) on positions, Stribeck exponent 2.

    ``z <- z_ss + (z - z_ss) exp(-sigma0 |v| h / g(v))``, ``z_ss = sgn(v) g(v) / sigma0``,
    ``F = sigma0 z + sigma1 dz/dt + sigma2 v`` with ``dz/dt = v - sigma0 |v| z / g(v)``.
    """
    z = 0.0
    for k in range(1, x.shape[0]):
        h = t[k] - t[k - 1]
        v = (x[k] - x[k - 1]) / h
        ratio = v / vs
        g = fc + (fs - fc) * math.exp(-ratio * ratio)
        if v != 0.0:
            steady = (g if v > 0.0 else -g) / sigma0
            z = steady + (z - steady) * math.exp(-sigma0 * abs(v) * h / g)
        out[k] = sigma0 * z + sigma1 * (v - sigma0 * abs(v) * z / g) + sigma2 * v


@jit
def plain_gms(t, x, stiffness, weight, attraction, fc, fs, vs, delta, force, slip, out):
    """GMS (:ref:`guide-gms`) as first written: a branch per element, math.exp per slipping one.

    A stuck element follows ``F_i + k_i dx`` until it reaches ``alpha_i g(v)``
    (then it sits there and slips); a slipping one relaxes exactly,
    ``T + (F_i - T) exp(-C h / (alpha_i g))``, ``T = sgn(v) alpha_i g(v)``.
    """
    out[0] = 0.0
    for k in range(1, x.shape[0]):
        h = t[k] - t[k - 1]
        dx = x[k] - x[k - 1]
        v = dx / h
        total = 0.0
        if v == 0.0:
            for i in range(force.shape[0]):
                total += force[i]
            out[k] = total
            continue
        g = fc + (fs - fc) * math.exp(-abs(v / vs) ** delta)
        direction = 1.0 if v > 0.0 else -1.0
        for i in range(force.shape[0]):
            capacity = weight[i] * g
            target = direction * capacity
            f = force[i]
            if slip[i] == direction or direction * f >= capacity:
                f = target + (f - target) * math.exp(-attraction * h / capacity)
                slip[i] = direction
            else:
                f = f + stiffness[i] * dx
                if direction * f >= capacity:
                    f = target
                    slip[i] = direction
                else:
                    slip[i] = 0.0
            force[i] = f
            total += f
        out[k] = total


def stepper_call_ratio(model, calls=20_000, rounds=7):
    """``Stepper.advance`` per call over a bare Python-to-numba call; ``(ratio, detail)``.

    Both loops run over the same Python lists with the same ``zip`` (the loop's
    own cost is on both sides): one calls ``advance(t, x=x)`` along the
    benchmark's sinusoid, the other ``bare_call(x)``.
    """
    from polind.stepper import Stepper

    path = bench_path(calls + 1)
    times, positions = path.t[1:].tolist(), path.x[1:].tolist()

    def bare():
        call = bare_call
        for _, x in zip(times, positions):
            call(x)

    def stepper():
        advance = Stepper(model).advance
        for t, x in zip(times, positions):
            advance(t, x=x)

    bare_time, stepper_time = _interleaved([bare, stepper], rounds)
    return stepper_time / bare_time, (f"{stepper_time / calls * 1e9:.0f} ns vs "
                                      f"{bare_time / calls * 1e9:.0f} ns per call")


def _simulate_ratio(model, reference, samples, rounds):
    """``reference_time / simulate_time`` on the benchmark sinusoid; ``(ratio, detail)``.

    ``reference(t, x)`` runs the bare loop and returns its forces, which are
    compared with ``simulate``'s (from sample 1 on).
    """
    from polind.simulation import simulate

    path = bench_path(samples)
    t, x = path.t, path.x
    forces = {}

    def run_reference():
        forces["reference"] = reference(t, x)

    def run_simulate():
        forces["simulate"] = simulate(model, t, x=x).force

    reference_time, simulate_time = _interleaved([run_reference, run_simulate], rounds)
    difference = _relative_difference(forces["simulate"][1:], forces["reference"][1:])
    return reference_time / simulate_time, (
        f"{reference_time * 1e3:.1f} ms vs {simulate_time * 1e3:.1f} ms on {samples:.0e} "
        f"samples, forces agree to {difference:.0e}")


def maxwell_slip_simulate_ratio(n, samples, rounds=5):
    """A bare Maxwell-slip loop over ``simulate`` on ``n`` elements: ``(ratio, detail)``."""
    model = bench_model("maxwell-slip", n)
    p = model.params
    # Placed in their pages as simulate's arrays are (page_placed): else the bare loop
    # runs up to 1.5 times slower, or 1.8 times, as NumPy happens to place them.
    stiffness = page_placed(p["stiffness"], TABLE_OFFSET)
    slip = page_placed(np.array(p["breakaway_force"]) / stiffness, TABLE_OFFSET)

    def reference(t, x):
        out = np.empty(x.shape[0])
        bare_maxwell_slip(x, stiffness, slip, page_placed(np.zeros(n), STATE_OFFSET), out)
        return out

    return _simulate_ratio(model, reference, samples, rounds)


def lugre_simulate_ratio(samples=1_000_000, rounds=5):
    """LuGre's bare exact-exponential loop over ``simulate``: ``(ratio, detail)``."""
    model = bench_model("lugre", 1)
    p = model.params
    if p["stribeck_exponent"] != 2.0 or p["stribeck_shape"] != "exponential":
        raise ValueError("bare_lugre is written for the exponential Stribeck curve, exponent 2")

    def reference(t, x):
        out = np.empty(x.shape[0])
        bare_lugre(t, x, p["bristle_stiffness"], p["bristle_damping"],
                   p["viscous_coefficient"], p["coulomb_force"], p["static_force"],
                   p["stribeck_velocity"], out)
        return out

    return _simulate_ratio(model, reference, samples, rounds)


def gms_simulate_ratio(model, gms, samples=50_000, rounds=3):
    """A plain GMS loop (math.exp per slipping element) over ``simulate``: ``(ratio, detail)``.

    ``gms`` is the model's GMS parameter set: a GMS model's own ``params``, or
    a Pol-Ind model's ``gms_parameters()`` (at its constant load Pol-Ind *is*
    GMS with its element table, :ref:`guide-pol-ind-law`).
    """
    stiffness = page_placed(gms["stiffness"], TABLE_OFFSET)   # (as maxwell_slip_simulate_ratio)
    weight = page_placed(gms["weight"], TABLE_OFFSET)
    if gms["stribeck_shape"] != "exponential" or gms["viscous_coefficient"] != 0.0:
        raise ValueError("plain_gms is written for the exponential Stribeck curve, no sigma2")

    def reference(t, x):
        out = np.empty(x.shape[0])
        plain_gms(t, x, stiffness, weight, gms["attraction"], gms["coulomb_force"],
                  gms["static_force"], gms["stribeck_velocity"], gms["stribeck_exponent"],
                  page_placed(np.zeros(stiffness.shape[0]), STATE_OFFSET),
                  page_placed(np.zeros(stiffness.shape[0]), STATE_OFFSET + 1024), out)
        return out

    return _simulate_ratio(model, reference, samples, rounds)


def varying_load_ratios(samples=100_000, calls=10_000, body_steps=3_000, rounds=3):
    """The default Pol-Ind model under ``100 N (0.75 + 0.25 sin)`` vs its constant 100 N.

    Per-sample cost ratio (varying / constant) in ``simulate`` (the benchmark
    sinusoid), :class:`polind.Stepper` (the same motion, sample by sample) and
    :class:`polind.Body` (pushed by ``20 N sin(2 pi 2 t)`` at 1 kHz: it sticks
    and slips).  The load changes at every sample, so every sample re-solves
    the separation and re-evaluates the element table
    (:ref:`guide-pol-ind-varying-load`).
    Returns ``{"simulate" | "Stepper" | "Body": (ratio, detail)}``.
    """
    from polind.models.pol_ind import default_table
    from polind.simulation import simulate
    from polind.stepper import Body, Stepper

    model = model_from_dict({"model": default_table()})
    out = {}

    def load_at(t):
        return 100.0 * (0.75 + 0.25 * np.sin(2.0 * np.pi * 5.0 * t))

    path = bench_path(samples)
    loads = load_at(path.t)
    constant, varying = _interleaved(
        [lambda: simulate(model, path.t, x=path.x),
         lambda: simulate(model, path.t, x=path.x, normal_load=loads)], rounds)
    out["simulate"] = (varying / constant, f"{varying / samples * 1e9:.0f} ns vs "
                                           f"{constant / samples * 1e9:.0f} ns per sample")

    times, positions = path.t[1:calls + 1].tolist(), path.x[1:calls + 1].tolist()
    step_loads = loads[1:calls + 1].tolist()

    def stepper_constant():
        advance = Stepper(model).advance
        for t, x, _ in zip(times, positions, step_loads):
            advance(t, x=x)

    def stepper_varying():
        advance = Stepper(model).advance
        for t, x, load in zip(times, positions, step_loads):
            advance(t, x=x, normal_load=load)

    constant, varying = _interleaved([stepper_constant, stepper_varying], rounds)
    out["Stepper"] = (varying / constant, f"{varying / calls * 1e9:.0f} ns vs "
                                          f"{constant / calls * 1e9:.0f} ns per call")

    body_times = np.arange(1, body_steps + 1) * 1e-3
    pushes = (20.0 * np.sin(2.0 * np.pi * 2.0 * body_times)).tolist()
    body_loads = load_at(body_times).tolist()

    def body_constant():
        step = Body(model, time_step=1e-3).step
        for push, _ in zip(pushes, body_loads):
            step(push)

    def body_varying():
        step = Body(model, time_step=1e-3).step
        for push, load in zip(pushes, body_loads):
            step(push, normal_load=load)

    constant, varying = _interleaved([body_constant, body_varying], rounds)
    out["Body"] = (varying / constant, f"{varying / body_steps * 1e6:.1f} µs vs "
                                       f"{constant / body_steps * 1e6:.1f} µs per step")
    return out


def run_ratios(progress=None):
    """Every ratio row (about half a minute); ``progress(row)`` is called after each."""
    rows = []

    def add(name, result, target, at_most):
        rows.append(RatioRow(name, result[0], target, at_most, result[1]))
        if progress is not None:
            progress(rows[-1])

    for label, model_type, n, target in (("LuGre", "lugre", 1, 5.0),
                                         ("GMS, 64 elements", "gms", 64, 8.0)):
        add(f"Stepper.advance / bare numba call: {label}",
            stepper_call_ratio(bench_model(model_type, n)), target, True)
    add("bare loop / simulate: Maxwell-slip, 64 elements",
        maxwell_slip_simulate_ratio(64, 1_000_000), 0.7, False)
    add("bare loop / simulate: Maxwell-slip, 1024 elements",
        maxwell_slip_simulate_ratio(1024, 200_000), 1.0, False)
    add("bare loop / simulate: LuGre", lugre_simulate_ratio(), 1.0, False)
    gms, pol_ind = bench_model("gms", 1024), bench_model("pol-ind", 1024)
    add("plain math.exp loop / simulate: GMS, 1024 elements",
        gms_simulate_ratio(gms, gms.params), 5.0, False)
    add("plain math.exp loop / simulate: Pol-Ind, 1024 elements",
        gms_simulate_ratio(pol_ind, pol_ind.gms_parameters()), 5.0, False)
    for where, result in varying_load_ratios().items():
        add(f"varying / constant load: Pol-Ind (64) in {where}", result, 2.0, True)
    return rows


def format_ratios(rows):
    lines = [f"{'ratio (same run)':<58}{'measured':>9}{'target':>10}{'':>6}  detail"]
    for r in rows:
        target = f"{'<=' if r.at_most else '>='} {r.target:g}"
        lines.append(f"{r.name:<58}{r.value:>9.3g}{target:>10}{'met' if r.met else 'NOT':>6}"
                     f"  {r.detail}")
    return "\n".join(lines)


# --- measured surfaces -------------------------------------------------------------------

@dataclass
class TopographyRow:
    size: int                # points along each side of the map
    summits: int
    analyse_seconds: float   # read (.npy), levelled, summits and curvatures
    model_seconds: float     # Pol-Ind on the map: surface built, separation, element table
    elements: int            # elements of that table (summits in contact)


#: Pixel size of the benchmark's height maps [m].
MAP_PIXEL = 0.5e-6


def random_height_map(size, missing=0.0, seed=0):
    """A tilted Gaussian random surface of ``size`` x ``size`` points [m].

    Gaussian autocorrelation of 8 pixels, rms 0.5 µm, tilt 1e-3 and -2e-3 at
    a pixel of :data:`MAP_PIXEL`; a fraction ``missing`` of the points
    blanked (NaN) at random.  NumPy alone, in single precision where it can.
    """
    rng = np.random.default_rng(seed)
    q = 2.0 * np.pi * np.fft.fftfreq(size)
    q_half = 2.0 * np.pi * np.fft.rfftfreq(size)
    filter_ = np.exp(-(q[:, None] ** 2 + q_half[None, :] ** 2) * 8.0).astype(np.float32)
    spectrum = np.fft.rfft2(rng.standard_normal((size, size), dtype=np.float32)) * filter_
    heights = np.fft.irfft2(spectrum, s=(size, size)).astype(np.float64)
    heights *= 0.5e-6 / heights.std()
    index = np.arange(size, dtype=np.float64) * MAP_PIXEL
    heights += 1e-3 * index[:, None] - 2e-3 * index[None, :]
    if missing > 0:
        heights[rng.random((size, size)) < missing] = np.nan
    return heights


def run_topography(size=4096, normal_load=1.0):
    """Time a ``size`` x ``size`` height map from file to summits, and a Pol-Ind model on it.

    The map (a NumPy Gaussian random surface, pixel 0.5 µm) is written as
    ``.npy`` to a temporary directory; the analysis (reading, levelling,
    summits, curvatures) is timed once, cold, as ``polind topography`` runs
    it; then a Pol-Ind model with ``[model.surface] topography`` on the same
    file is built at ``normal_load`` (the map read and analysed again, the
    direct surface sorted, the separation solved, the element table built).
    """
    import tempfile

    from polind.models.pol_ind import default_table
    from polind.topography import load_measured_surface
    from polind.models import model_from_dict

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "map.npy")
        np.save(path, random_height_map(size))
        start = time.perf_counter()
        measured = load_measured_surface(path, pixel_size=(MAP_PIXEL, MAP_PIXEL))
        middle = time.perf_counter()
        table = default_table()
        table.update(normal_load=normal_load, discretisation={},
                     surface={"topography": path, "pixel_size": [MAP_PIXEL, MAP_PIXEL]})
        elements = len(model_from_dict({"model": table}).element_table())
        end = time.perf_counter()
    return TopographyRow(size, measured.summits, middle - start, end - middle, elements)


# --- big files: `polind simulate` end to end (issue 14) -----------------------------------

#: The big-file case: a 4-element Maxwell-slip model along a motion CSV of 1e7 samples
#: (423 MB), run as the command line runs it.
BIG_FILE_SAMPLES = 10_000_000
BIG_FILE_MODEL = """\
[model]
type = "maxwell-slip"
stiffness = [1e5, 5e4, 2e4, 1e4]
breakaway_force = [0.2, 0.3, 0.25, 0.25]
viscous_coefficient = 0.0
"""
#: Its targets (issue 14): wall time [s] and peak resident memory [bytes].
BIG_FILE_TARGET_SECONDS = 8.0
BIG_FILE_TARGET_PEAK_BYTES = 1e9


def big_motion(samples):
    """``(t, x)``: a sinusoidal displacement (10 µm, 5 Hz) sampled at 100 kHz, jittered in t."""
    k = np.arange(samples, dtype=np.float64)
    t = k * 1e-5 + 1e-7 * np.sin(k)               # strictly increasing, 17 digits each
    return t, 1e-5 * np.sin(2.0 * np.pi * 5.0 * t)


def write_big_motion_csv(path, t, x, rows_per_chunk=100_000):
    """``t,x`` with every number in 17 significant digits, by NumPy and Python alone (so that
    the same file serves any version of polind)."""
    with open(path, "w", encoding="ascii") as stream:
        stream.write("t,x\n")
        for start in range(0, t.shape[0], rows_per_chunk):
            chunk = np.column_stack((t[start:start + rows_per_chunk],
                                     x[start:start + rows_per_chunk]))
            stream.write(("%.17g,%.17g\n" * chunk.shape[0]) % tuple(chunk.ravel().tolist()))


def polind_command():
    """The ``polind`` script beside this Python, else ``python -m polind``."""
    import sys
    from pathlib import Path

    script = Path(sys.executable).with_name("polind")
    return [str(script)] if script.exists() else [sys.executable, "-m", "polind"]


# Runs a command and prints its wall time, CPU time, peak RSS and exit status.  A child's
# peak RSS counts the memory of the process it was forked from (until its exec), so the
# command is started from this small process, not from the benchmark's own.
_MEASURE = """\
import json, os, subprocess, sys, time
started = time.perf_counter()
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
child.returncode = os.waitstatus_to_exitcode(status)
print(json.dumps([time.perf_counter() - started, usage.ru_utime + usage.ru_stime,
                  usage.ru_maxrss * 1024, child.returncode]))
"""


def run_measured(command):
    """``(wall seconds, CPU seconds, peak RSS bytes, exit status, stderr)`` of one subprocess."""
    import json
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", _MEASURE, *command], capture_output=True,
                          text=True, errors="replace")
    if done.returncode != 0:
        return 0.0, 0.0, 0, done.returncode, done.stderr
    seconds, cpu, peak, status = json.loads(done.stdout.strip().splitlines()[-1])
    return seconds, cpu, peak, status, done.stderr


@dataclass
class BigFileRow:
    samples: int
    input_bytes: int
    output_bytes: int
    seconds: float           # wall time of the `polind simulate` process
    cpu_seconds: float       # its user and system CPU time
    peak_bytes: int          # its peak resident memory

    @property
    def met(self) -> bool:
        return (self.seconds <= BIG_FILE_TARGET_SECONDS
                and self.peak_bytes <= BIG_FILE_TARGET_PEAK_BYTES)


def run_big_files(samples=BIG_FILE_SAMPLES, folder=None, progress=None) -> BigFileRow:
    """Time ``polind simulate MODEL -i MOTION.csv -o OUT.csv`` of :data:`BIG_FILE_MODEL`.

    The motion (:func:`big_motion`, ``samples`` rows) is written into a
    temporary directory (in ``folder`` if given; not timed), a run on its
    first 100 rows fills numba's cache, and then the whole run is one
    subprocess: its wall and CPU time and peak resident memory (``os.wait4``)
    are the row.  ``progress(text)`` is told what is being done.  The
    command's failure is an InputError with its message.
    """
    import tempfile
    from pathlib import Path

    from polind.resources import check_memory

    check_memory(16.0 * samples, f"The big-file case's motion ({samples:.3g} samples)")
    try:
        with tempfile.TemporaryDirectory(prefix="polind-bench-", dir=folder) as scratch:
            return _run_big_files(Path(scratch), samples, progress)
    except OSError as error:
        where = folder if folder is not None else tempfile.gettempdir()
        raise InputError(f"{where}: cannot hold the big-file case's files (about "
                         f"{128 * samples / 1e9:.2g} GB): {error.strerror or error}; expected a "
                         f"directory with that much free space (TMPDIR chooses it).") from None


def _run_big_files(scratch, samples, progress):
    model = scratch / "maxwell_slip.toml"
    model.write_text(BIG_FILE_MODEL)
    t, x = big_motion(samples)
    if progress is not None:
        progress(f"writing a motion of {samples:.3g} samples")
    motion = scratch / "motion.csv"
    write_big_motion_csv(motion, t, x)
    small = scratch / "small.csv"
    write_big_motion_csv(small, t[:100], x[:100])
    del t, x
    output = scratch / "out.csv"
    command = polind_command() + ["simulate", str(model), "-i"]
    for path in (small, motion):                          # the first: numba's cache
        if progress is not None and path == motion:
            progress("running polind simulate")
        seconds, cpu, peak, status, stderr = run_measured(command + [str(path), "-o",
                                                                       str(output)])
        if status != 0:
            raise InputError(f"polind simulate of the big-file case exited {status}: "
                             f"{' '.join(stderr.split())}")
    return BigFileRow(samples, motion.stat().st_size, output.stat().st_size, seconds, cpu, peak)


def format_big_files(row: BigFileRow) -> str:
    return (f"polind simulate, 4-element Maxwell-slip, {row.samples:.3g}-sample CSV in and out "
            f"({row.input_bytes / 1e6:.0f} MB in, {row.output_bytes / 1e6:.0f} MB out): "
            f"{row.seconds:.2f} s ({row.cpu_seconds:.2f} s of CPU), peak "
            f"{row.peak_bytes / 1e6:.0f} MB; target {BIG_FILE_TARGET_SECONDS:g} s and "
            f"{BIG_FILE_TARGET_PEAK_BYTES / 1e6:.0f} MB: {'met' if row.met else 'NOT met'}")
