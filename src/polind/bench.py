"""The performance benchmark behind ``polind bench`` and ``benchmarks/``.

For each model and element count it times the model's kernel over a
prescribed path (the hot loop: the element update) and, in the same run,
the same work done by a plain NumPy loop — the step loop in Python, the
elements vectorised — and reports element-steps per second and their ratio.
The NumPy loops are written from MODELS.md, not from the kernels, and their
forces are compared with the kernel's, so both sides demonstrably do the
same work.  Times are the best of a few repeats after a warm-up call (which
also loads numba's cache).

The motion is a sinusoid whose amplitude is large against the element slip
distances, so the elements cycle through stick and slip and every branch of
the element law runs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from polind.models import model_from_dict
from polind.simulate import make_path
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


def bench_model(model_type, n):
    """A benchmark model with ``n`` elements (the element count is 1 for single-state models)."""
    stiffness, breakaway = _elements(n)
    table = {"type": model_type}
    if model_type == "maxwell-slip":
        table.update(stiffness=stiffness.tolist(), breakaway_force=breakaway.tolist())
    elif model_type == "gms":
        table.update(stiffness=stiffness.tolist(), weight=(breakaway / breakaway.sum()).tolist(),
                     attraction=1e4, **_STRIBECK)
    elif model_type == "leuven":
        scaled = breakaway * (_STRIBECK["static_force"] / breakaway.sum())
        table.update(stiffness=stiffness.tolist(), breakaway_force=scaled.tolist(), exponent=2.0,
                     bristle_damping=10.0, **_STRIBECK)
    elif model_type == "lugre":
        table.update(bristle_stiffness=1e5, bristle_damping=316.2, **_STRIBECK)
    elif model_type == "stribeck":
        table.update(viscous_coefficient=0.4, **_STRIBECK)
    elif model_type == "dahl":
        table.update(stiffness=1e5, coulomb_force=1.0)
    elif model_type == "pol-ind":
        from polind.models.pol_ind import default_table
        table = default_table()
        table["discretisation"]["elements"] = n
    else:
        raise ValueError(f"no benchmark model for {model_type!r}")
    return model_from_dict({"model": table})


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
    """Backward Euler on MODELS.md 6, the increment solved by brentq per step."""
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


def _numpy_reference(model, path):
    p = model.params
    curve = [p.get(key) for key in ("coulomb_force", "static_force", "stribeck_velocity",
                                    "stribeck_exponent")]
    if model.type == "maxwell-slip":
        return numpy_maxwell_slip(path, np.array(p["stiffness"]), np.array(p["breakaway_force"]))
    if model.type in ("gms", "pol-ind"):
        gms = p if model.type == "gms" else model.gms_parameters()
        return numpy_gms(path, np.array(gms["stiffness"]), np.array(gms["weight"]),
                         gms["attraction"], *[gms[key] for key in (
                             "coulomb_force", "static_force", "stribeck_velocity",
                             "stribeck_exponent")])
    if model.type == "leuven":
        return numpy_leuven(path, np.array(p["stiffness"]), np.array(p["breakaway_force"]),
                            p["exponent"], p["bristle_damping"], *curve)
    if model.type == "stribeck":
        return numpy_stribeck(path, *curve, p["viscous_coefficient"])
    if model.type == "lugre":
        return numpy_lugre(path, p["bristle_stiffness"], p["bristle_damping"], *curve)
    if model.type == "dahl":
        return numpy_dahl(path, p["stiffness"], p["coulomb_force"])
    raise ValueError(f"no NumPy reference for {model.type!r}")


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
    elements = n if model_type in ("maxwell-slip", "gms", "leuven", "pol-ind") else 1
    probe = bench_path(20_000)
    model._advance(bench_path(64), model.initial_state(), None)     # compile / load cache
    probe_time, _ = _best_time(lambda: model._advance(probe, model.initial_state(), None), 1)
    steps = _steps_for(kernel_seconds, 20_000, probe_time, 2e4, 5e7)
    path = bench_path(steps)
    kernel_time, _ = _best_time(
        lambda: model._advance(path, model.initial_state(), None), repeats)
    probe_numpy = bench_path(100)
    numpy_probe_time, _ = _best_time(lambda: _numpy_reference(model, probe_numpy), 1)
    numpy_steps = _steps_for(numpy_seconds, 100, numpy_probe_time, 200, steps)
    short = bench_path(numpy_steps)
    numpy_time, numpy_force = _best_time(lambda: _numpy_reference(model, short), 1)
    reference = model._advance(short, model.initial_state(), None)
    scale = max(np.max(np.abs(numpy_force)), 1e-300)
    difference = float(np.max(np.abs(reference - numpy_force)) / scale)
    return BenchRow(model_type, elements, steps, steps * elements / kernel_time,
                    numpy_steps * elements / numpy_time, difference)


def cases(models=None):
    """The (model, element count) pairs the benchmark runs."""
    from polind.models import MODEL_TYPES

    element_models = [m for m in ("maxwell-slip", "gms", "pol-ind", "leuven")
                      if m in MODEL_TYPES]
    single = ["lugre", "dahl", "stribeck"]
    chosen = models or element_models + single
    out = []
    for model_type in chosen:
        counts = ELEMENT_COUNTS if model_type in element_models else (1,)
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
    """Time the iterative method (MODELS.md 7.4) on a directly summed surface.

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
