"""The ratio rows of ``polind bench``: two timings taken in the same run, and their ratio.

The figures the user-loop API is held to: :class:`polind.Stepper` and a
moving :class:`polind.Body` against a bare Python-to-numba call, and each
given NumPy ``float64`` scalars (what indexing an array gives) against the
same call given floats, :class:`polind.BodyBatch` per body-step against
:func:`polind.simulate_system`, :func:`polind.simulate` end to end against the
bare numba loops of :mod:`polind.bench.references`, and the Pol-Ind model under
a varying against a constant normal load (:func:`run_ratios`; the rows are
listed, unmeasured, by :func:`ratio_specs`).

The machine the figures are taken on is shared, and absolute rates vary by 2x
between runs; a ratio of two timings taken in the same run, interleaved,
varies much less.  Each row times two things round-robin (one after the
other, ``rounds`` times, after a warm-up call of each that also compiles or
loads numba's cache) and keeps the best time of each.

The models are the representative ones (``example()``, at the element counts
the rows name); the bare Maxwell-slip and GMS loops are written without a
viscous term, so those rows run their example with ``viscous_coefficient = 0``.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from polind.bench.frequency import frequency_response_timing
from polind.bench.harness import bench_path
from polind.bench.references import bare_call, bare_lugre, bare_maxwell_slip, plain_gms
from polind.models import GMS, LuGre, MaxwellSlip, PolInd
from polind.models.base import STATE_OFFSET, TABLE_OFFSET, page_placed


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


def stepper_call_ratio(model, calls=5_000, rounds=28):
    """``Stepper.advance`` per call over a bare Python-to-numba call; ``(ratio, detail)``.

    Both loops run over the same Python lists with the same ``zip`` (the loop's
    own cost is on both sides): one calls ``advance(t, x=x)`` along the
    benchmark's sinusoid, the other ``bare_call(x)``.  Each pass advances a
    stepper of its own, built before the timing (building one is not a
    call).  Many short passes: on a shared machine the best of them is the
    one that no other job interrupted.
    """
    from polind.stepper import Stepper

    path = bench_path(calls + 1)
    times, positions = path.t[1:].tolist(), path.x[1:].tolist()
    steppers = [Stepper(model) for _ in range(rounds + 1)]     # the warm-up's and each pass's

    def bare():
        call = bare_call
        for _, x in zip(times, positions):
            call(x)

    def stepper():
        advance = steppers.pop().advance
        for t, x in zip(times, positions):
            advance(t, x=x)

    bare_time, stepper_time = _interleaved([bare, stepper], rounds)
    return stepper_time / bare_time, (f"{stepper_time / calls * 1e9:.0f} ns vs "
                                      f"{bare_time / calls * 1e9:.0f} ns per call")


def stepper_scalar_ratio(model, scalar=np.float64, calls=5_000, rounds=28):
    """``Stepper.advance`` with NumPy scalars over the same call with floats; ``(ratio, detail)``.

    The same samples as :func:`stepper_call_ratio`, once as Python floats
    and once as ``scalar`` (``np.float64``: what indexing an array gives),
    each pass a stepper of its own; the detail says whether the scalars give
    the forces of their values as floats, bit for bit (one untimed run of
    each).
    """
    from polind.stepper import Stepper

    path = bench_path(calls + 1)
    floats = (path.t[1:].tolist(), path.x[1:].tolist())
    scalars = tuple(list(np.asarray(values, dtype=scalar)) for values in (path.t[1:],
                                                                           path.x[1:]))
    steppers = [Stepper(model) for _ in range(2 * (rounds + 1))]

    def timed(times, positions):
        def run():
            advance = steppers.pop().advance
            for t, x in zip(times, positions):
                advance(t, x=x)
        return run

    def forces(times, positions):
        advance = Stepper(model).advance
        return np.array([advance(t, x=x) for t, x in zip(times, positions)])

    same = np.array_equal(forces(*([float(value) for value in values] for values in scalars)),
                          forces(*scalars))
    float_time, scalar_time = _interleaved([timed(*floats), timed(*scalars)], rounds)
    return scalar_time / float_time, (f"{scalar_time / calls * 1e9:.0f} ns vs "
                                      f"{float_time / calls * 1e9:.0f} ns per call; forces "
                                      f"{'the same' if same else 'DIFFERENT'}")


def _moving_pushes(model, steps):
    """Forces that keep a 1 kg body sliding at 1 kHz: 1.5 times its steady force at 1 cm/s, in
    a slow square wave (it reverses every 100 steps, so it sticks briefly and breaks away)."""
    from polind.simulation import simulate

    t = np.array([0.0, 0.1])
    level = 1.5 * abs(float(simulate(model, t, v=[1e-2, 1e-2]).force[-1]))
    signs = np.where((np.arange(steps) // 100) % 2 == 0, 1.0, -1.0)
    return level * signs


def body_call_ratio(model, steps=2_000, rounds=17):
    """A moving ``Body.step`` per call over a bare Python-to-numba call; ``(ratio, detail)``.

    The body (1 kg, 1 kHz) is pushed by :func:`_moving_pushes`; the detail
    also gives the compiled step alone (``Body.compiled`` in a numba loop),
    which is what the Python call adds to.  Each pass steps a body of its
    own, built before the timing, in many short passes
    (:func:`stepper_call_ratio`).
    """
    from polind.kernels import jit
    from polind.stepper import Body

    pushes = _moving_pushes(model, steps)
    forces = pushes.tolist()
    bodies = [Body(model, time_step=1e-3) for _ in range(2 * (rounds + 1))]

    @jit(cache=False)
    def compiled_loop(step, arguments, pushes):
        for k in range(pushes.shape[0]):
            step(*arguments, pushes[k])

    def bare():
        call = bare_call
        for force in forces:
            call(force)

    def body():
        step = bodies.pop().step
        for force in forces:
            step(force)

    def compiled():
        step, arguments = bodies.pop().compiled()
        compiled_loop(step, arguments, pushes)

    bare_time, body_time, compiled_time = _interleaved([bare, body, compiled], rounds)
    return body_time / bare_time, (f"{body_time / steps * 1e9:.0f} ns vs "
                                   f"{bare_time / steps * 1e9:.0f} ns per call; the compiled "
                                   f"step alone {compiled_time / steps * 1e9:.0f} ns")


def body_scalar_ratio(model, scalar=np.float64, steps=2_000, rounds=17):
    """A moving ``Body.step`` with a NumPy scalar force over a float one; ``(ratio, detail)``.

    The pushes of :func:`body_call_ratio`, once as Python floats and once as
    ``scalar``, each pass a body of its own; the detail says whether the
    scalars give the steps of their values as floats, bit for bit (one
    untimed run of each).
    """
    from polind.stepper import Body

    pushes = _moving_pushes(model, steps)
    floats, scalars = pushes.tolist(), list(np.asarray(pushes, dtype=scalar))
    bodies = [Body(model, time_step=1e-3) for _ in range(2 * (rounds + 1))]

    def timed(forces):
        def run():
            step = bodies.pop().step
            for force in forces:
                step(force)
        return run

    def steps_of(forces):
        step = Body(model, time_step=1e-3).step
        return np.array([step(force) for force in forces])

    same = np.array_equal(steps_of([float(force) for force in scalars]), steps_of(scalars))
    float_time, scalar_time = _interleaved([timed(floats), timed(scalars)], rounds)
    return scalar_time / float_time, (f"{scalar_time / steps * 1e9:.0f} ns vs "
                                      f"{float_time / steps * 1e9:.0f} ns per call; steps "
                                      f"{'the same' if same else 'DIFFERENT'}")


def batch_step_ratio(model, count=64, steps=2_000, rounds=5):
    """``BodyBatch`` per body-step over a ``simulate_system`` step of the same model.

    ``count`` bodies of 1 kg at 1 kHz, each pushed by :func:`_moving_pushes`
    (shifted by a few steps per body), against ``simulate_system`` of one such
    body over ``count * steps`` steps; ``(ratio, detail)``.
    """
    from polind.batch import BodyBatch
    from polind.dynamics import System, simulate_system

    pushes = _moving_pushes(model, steps + count)
    rows = np.array([pushes[k:k + count] for k in range(steps)])
    long_pushes = _moving_pushes(model, count * steps)
    system = System(mass=1.0, duration=count * steps * 1e-3, time_step=1e-3)

    def batch():
        step = BodyBatch(model, count, time_step=1e-3).step
        for row in rows:
            step(row)

    def system_run():
        simulate_system(model, system, applied=long_pushes[:system.times.shape[0]])

    batch_time, system_time = _interleaved([batch, system_run], rounds)
    per_batch = batch_time / (count * steps)
    per_system = system_time / (system.times.shape[0] - 1)
    return per_batch / per_system, (f"{per_batch * 1e9:.0f} ns vs {per_system * 1e9:.0f} ns "
                                    f"per body-step ({count} bodies)")


def structure_step_ratio(model, steps=100_000, rounds=5):
    """A structure step (two masses, ``model`` as the joint between them) over a ``simulate_system`` step.

    The first mass (1 kg, on a 1 kN/m spring) is pushed by a 5 Hz sine of
    twice the joint's sliding force, the second (0.5 kg) hangs on the joint;
    against ``simulate_system`` of one 1 kg body on the same model pushed by
    the same sine; both at 10 kHz; ``(ratio, detail)``.
    """
    from polind.dynamics import System, simulate_system
    from polind.structures import Structure, simulate_structure

    h = 1e-4
    t = np.arange(steps + 1) * h
    amplitude = 2.0 * float(model.force_scale())
    force = np.zeros((steps + 1, 2))
    force[:, 0] = amplitude * np.sin(2 * np.pi * 5.0 * t)
    structure = Structure(mass=np.diag([1.0, 0.5]), stiffness=[[1e3, 0.0], [0.0, 0.0]])
    structure.add_contact(model, dofs=(0, 1))
    system = System(mass=1.0, duration=steps * h, time_step=h, amplitude=amplitude,
                    frequency=5.0)

    def structure_run():
        simulate_structure(structure, t, force=force)

    def system_run():
        simulate_system(model, system)

    structure_time, system_time = _interleaved([structure_run, system_run], rounds)
    per_structure = structure_time / steps
    per_system = system_time / (system.times.shape[0] - 1)
    return per_structure / per_system, (f"{per_structure * 1e9:.0f} ns vs "
                                        f"{per_system * 1e9:.0f} ns per step")


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
    """A bare Maxwell-slip loop over ``simulate`` on ``n`` elements: ``(ratio, detail)``.

    The model is the example at ``n`` elements without its viscous term (the
    bare loop has none).
    """
    model = MaxwellSlip.example(elements=n).with_params(viscous_coefficient=0.0)
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
    model = LuGre.example()
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


def varying_load_ratios(samples=100_000, calls=10_000, body_steps=3_000, rounds=3,
                        user_rounds=15):
    """The default Pol-Ind model under ``100 N (0.75 + 0.25 sin)`` vs its constant 100 N.

    Per-sample cost ratio (varying / constant) in ``simulate`` (the benchmark
    sinusoid), :class:`polind.Stepper` (the same motion, sample by sample) and
    :class:`polind.Body` (pushed by ``20 N sin(2 pi 2 t)`` at 1 kHz: it sticks
    and slips).  The load changes at every sample, so every sample re-solves
    the separation and re-evaluates the element table
    (:ref:`guide-pol-ind-varying-load`).  ``simulate`` is timed ``rounds``
    times, the Stepper and the Body ``user_rounds`` times (they are short),
    each pass with a Stepper or Body of its own built before the timing.
    Returns ``{"simulate" | "Stepper" | "Body": (ratio, detail)}``.
    """
    from polind.simulation import simulate
    from polind.stepper import Body, Stepper

    model = PolInd.example()
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

    steppers = [Stepper(model) for _ in range(2 * (user_rounds + 1))]

    def stepper_constant():
        advance = steppers.pop().advance
        for t, x, _ in zip(times, positions, step_loads):
            advance(t, x=x)

    def stepper_varying():
        advance = steppers.pop().advance
        for t, x, load in zip(times, positions, step_loads):
            advance(t, x=x, normal_load=load)

    constant, varying = _interleaved([stepper_constant, stepper_varying], user_rounds)
    out["Stepper"] = (varying / constant, f"{varying / calls * 1e9:.0f} ns vs "
                                          f"{constant / calls * 1e9:.0f} ns per call")

    body_times = np.arange(1, body_steps + 1) * 1e-3
    pushes = (20.0 * np.sin(2.0 * np.pi * 2.0 * body_times)).tolist()
    body_loads = load_at(body_times).tolist()

    bodies = [Body(model, time_step=1e-3) for _ in range(2 * (user_rounds + 1))]

    def body_constant():
        step = bodies.pop().step
        for push, _ in zip(pushes, body_loads):
            step(push)

    def body_varying():
        step = bodies.pop().step
        for push, load in zip(pushes, body_loads):
            step(push, normal_load=load)

    constant, varying = _interleaved([body_constant, body_varying], user_rounds)
    out["Body"] = (varying / constant, f"{varying / body_steps * 1e6:.1f} µs vs "
                                       f"{constant / body_steps * 1e6:.1f} µs per step")
    return out


@dataclass(frozen=True)
class RatioSpec:
    """One ratio row before it is measured: its name, target, and how it is measured."""

    name: str
    target: float
    at_most: bool
    measure: Callable[[], tuple[float, str]]     # () -> (ratio, detail)


def ratio_specs():
    """Every ratio row of :func:`run_ratios`, in its order, without measuring any.

    The models are built when a row is measured; the three varying-load rows
    share one measurement (:func:`varying_load_ratios`, taken once per list).
    """
    specs = []

    def add(name, measure, target, at_most=True):
        specs.append(RatioSpec(name, target, at_most, measure))

    for label, model, target in (("LuGre", LuGre.example, 3.0),
                                 ("Pol-Ind (64)", PolInd.example, 3.0),
                                 ("GMS, 64 elements", lambda: GMS.example(elements=64), 8.0)):
        add(f"Stepper.advance / bare numba call: {label}",
            lambda model=model: stepper_call_ratio(model()), target)
    for label, model in (("LuGre", LuGre.example), ("Pol-Ind (64)", PolInd.example)):
        add(f"moving Body.step / bare numba call: {label}",
            lambda model=model: body_call_ratio(model()), 5.0)
    # NumPy scalars (what indexing an array gives) cost what floats do (issue 38).
    for label, model in (("LuGre", LuGre.example), ("Pol-Ind (64)", PolInd.example)):
        add(f"Stepper.advance np.float64 / float arguments: {label}",
            lambda model=model: stepper_scalar_ratio(model()), 1.2)
    for label, model in (("LuGre", LuGre.example), ("Pol-Ind (64)", PolInd.example)):
        add(f"Body.step np.float64 / float argument: {label}",
            lambda model=model: body_scalar_ratio(model()), 1.2)
    for label, model in (("LuGre", LuGre.example), ("Pol-Ind (64)", PolInd.example)):
        add(f"BodyBatch / simulate_system per body-step: {label}",
            lambda model=model: batch_step_ratio(model()), 2.0)
    # A structure (issue 38): a 64-element joint between two masses.
    add("structure / simulate_system step: 64-element MS joint",
        lambda: structure_step_ratio(MaxwellSlip.example(elements=64)), 3.0)
    # The frequency domain (issue 39): a 200-point curve of the two-mass example.
    timing = functools.cache(frequency_response_timing)
    add("time integration / harmonic balance: 200-point curve",
        lambda: (timing()[1] / timing()[0], timing()[3]), 10.0, False)
    add("harmonic balance, 200-point curve: seconds (absolute)",
        lambda: (timing()[0], "the same curve's wall-clock seconds"), 30.0)
    add("bare loop / simulate: Maxwell-slip, 64 elements",
        lambda: maxwell_slip_simulate_ratio(64, 1_000_000), 0.7, False)
    add("bare loop / simulate: Maxwell-slip, 1024 elements",
        lambda: maxwell_slip_simulate_ratio(1024, 200_000), 1.0, False)
    add("bare loop / simulate: LuGre", lugre_simulate_ratio, 1.0, False)

    def gms():
        model = GMS.example(elements=1024).with_params(viscous_coefficient=0.0)
        return gms_simulate_ratio(model, model.params)

    def pol_ind():
        model = PolInd.example(elements=1024)
        return gms_simulate_ratio(model, model.gms_parameters())

    add("plain math.exp loop / simulate: GMS, 1024 elements", gms, 5.0, False)
    add("plain math.exp loop / simulate: Pol-Ind, 1024 elements", pol_ind, 5.0, False)
    varying = functools.cache(varying_load_ratios)
    for where in ("simulate", "Stepper", "Body"):
        add(f"varying / constant load: Pol-Ind (64) in {where}",
            lambda where=where: varying()[where], 2.0)
    return specs


def run_ratios(progress=None, only=None):
    """Every ratio row (about half a minute); ``progress(row)`` is called after each.

    ``only``: the rows whose name contains one of these strings (default: all).
    """
    rows = []
    for spec in ratio_specs():
        if only is not None and not any(part in spec.name for part in only):
            continue
        value, detail = spec.measure()
        rows.append(RatioRow(spec.name, value, spec.target, spec.at_most, detail))
        if progress is not None:
            progress(rows[-1])
    return rows


def format_ratios(rows):
    lines = [f"{'ratio (same run)':<58}{'measured':>9}{'target':>10}{'':>6}  detail"]
    for r in rows:
        target = f"{'<=' if r.at_most else '>='} {r.target:g}"
        lines.append(f"{r.name:<58}{r.value:>9.3g}{target:>10}{'met' if r.met else 'NOT':>6}"
                     f"  {r.detail}")
    return "\n".join(lines)
