"""Property tests over random parameters and random motions (hypothesis).

* Bounded element forces: Maxwell-slip ``|F - sigma2 v| <= sum W_i`` and
  ``|F_i| <= W_i``; GMS ``|F - sigma2 v| <= max(Fs, Fc)`` and
  ``|F_i| <= alpha_i max(Fs, Fc)``; Leuven's hysteresis elements
  ``|F_i| <= W_i``. Element forces are read from
  ``state.to_dict()["element_force"]``.
* Energy: over a closed displacement cycle ``oint F dx >= 0`` for the
  rate-independent models: Maxwell-slip from any state (each element is
  elastic-perfectly-plastic), Dahl and GMS (large ``C``, slow constant-speed
  motion) from rest (their stored energy starts at 0 and is never negative).

The cycle integral is the trapezoid over a finely sampled piecewise-linear
path. Along a monotone leg these forces are concave in the direction of
motion with a slope that falls by at most ``K`` over the leg (``K = sum k_i``
for the Maxwell-slip family, ``sigma0 2^alpha`` for Dahl), so the trapezoid
errs by at most ``K h^2 / 8`` per leg (``h`` the sample spacing): that bound,
plus rounding, is the tolerance.
"""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from conftest import element_forces, polyline, run

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

log_uniform = lambda lo, hi: st.floats(lo, hi).map(lambda e: 10.0 ** e)   # noqa: E731
unit = st.floats(-1.0, 1.0, allow_nan=False)


def physical(low, high):
    """0 or a number in [low, high] of a physical size (a model refuses magnitudes below
    1e-100: its arithmetic multiplies and divides them)."""
    return st.one_of(st.just(0.0), st.floats(max(low, 1e-100), high))


@st.composite
def element_sets(draw, min_size=1, max_size=5):
    n = draw(st.integers(min_size, max_size))
    k = [draw(log_uniform(3, 7)) for _ in range(n)]
    w = [draw(log_uniform(-2, 1)) for _ in range(n)]
    return k, w


@st.composite
def weights(draw, n):
    raw = np.array([draw(st.floats(0.05, 1.0)) for _ in range(n)])
    alpha = raw / raw.sum()
    alpha[-1] = 1.0 - alpha[:-1].sum()
    return [float(a) for a in alpha]


@st.composite
def stribeck(draw):
    fc = draw(log_uniform(-1, 1))
    return {
        "coulomb_force": fc,
        "static_force": fc * draw(st.floats(0.3, 3.0)),
        "stribeck_velocity": draw(log_uniform(-4, -1)),
        "stribeck_exponent": draw(st.floats(0.5, 3.0)),
        "stribeck_shape": draw(st.sampled_from(["exponential", "rational"])),
    }


@st.composite
def motions(draw, length_scale, time_scale, max_steps=300):
    """Random increments (some zero) at random time steps."""
    n = draw(st.integers(2, max_steps))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    persistence = draw(st.floats(0.0, 1.0))
    steps = rng.uniform(-1.0, 1.0, n - 1) + persistence * draw(unit)
    steps[rng.uniform(size=n - 1) < 0.05] = 0.0
    dx = steps * length_scale * 10.0 ** rng.uniform(-2, 0.5, n - 1)
    dt = time_scale * 10.0 ** rng.uniform(-1, 1, n - 1)
    t = np.concatenate([[0.0], np.cumsum(dt)])
    x = np.concatenate([[0.0], np.cumsum(dx)])
    use_velocity = draw(st.booleans())
    return t, x, use_velocity


def drive(t, x, use_velocity):
    if use_velocity:     # a velocity history with the same scale
        v = np.concatenate([[0.0], np.diff(x) / np.diff(t)])
        return {"v": v}
    return {"x": x}


def run_with_mid_state(model, t, drive_kwargs):
    """One run plus the state at a middle sample (via a continued chunk)."""
    (name, values), = drive_kwargs.items()
    res = run(model, t, **drive_kwargs)
    mid = len(t) // 2
    states = [res.final_state]
    if 0 < mid < len(t) - 1:
        states.append(run(model, t[:mid + 1], **{name: values[:mid + 1]}).final_state)
    return res, states


# --- bounded forces ----------------------------------------------------------

@SETTINGS
@given(elements=element_sets(), sigma2=physical(0.0, 2.0), data=st.data())
def test_maxwell_slip_forces_bounded(elements, sigma2, data):
    k, w = elements
    d_max = max(wi / ki for ki, wi in zip(k, w))
    t, x, use_v = data.draw(motions(d_max, 1e-3))
    model = {"type": "maxwell-slip", "stiffness": k, "breakaway_force": w,
             "viscous_coefficient": sigma2}
    res, states = run_with_mid_state(model, t, drive(t, x, use_v))
    assert np.all(np.isfinite(res.force))
    assert np.all(np.abs(res.force - sigma2 * res.v) <= sum(w) * (1 + 1e-12) + 1e-300)
    for state in states:
        e = element_forces(state)
        assert e.shape == (len(k),)
        assert np.all(np.abs(e) <= np.asarray(w) * (1 + 1e-12))


@SETTINGS
@given(elements=element_sets(), curve=stribeck(), attraction=log_uniform(0, 8),
       sigma2=physical(0.0, 2.0), data=st.data())
def test_gms_forces_bounded(elements, curve, attraction, sigma2, data):
    k, _ = elements
    alpha = data.draw(weights(len(k)))
    cap = max(curve["static_force"], curve["coulomb_force"])
    d_max = max(a * cap / ki for ki, a in zip(k, alpha))
    t, x, use_v = data.draw(motions(d_max, d_max / curve["stribeck_velocity"]))
    model = {"type": "gms", "stiffness": k, "weight": alpha, "attraction": attraction,
             "viscous_coefficient": sigma2, **curve}
    res, states = run_with_mid_state(model, t, drive(t, x, use_v))
    assert np.all(np.isfinite(res.force))
    assert np.all(np.abs(res.force - sigma2 * res.v) <= cap * (1 + 1e-9))
    for state in states:
        e = element_forces(state)
        assert e.shape == (len(k),)
        assert np.all(np.abs(e) <= np.asarray(alpha) * cap * (1 + 1e-9))


@SETTINGS
@given(elements=element_sets(max_size=4), curve=stribeck(), exponent=st.floats(0.5, 3.0),
       data=st.data())
def test_leuven_hysteresis_elements_bounded(elements, curve, exponent, data):
    k, w = elements
    w = list(np.asarray(w) * curve["static_force"] / sum(w))     # sum W_i = Fs
    d_max = max(wi / ki for ki, wi in zip(k, w))
    t, x, use_v = data.draw(motions(d_max, d_max / curve["stribeck_velocity"], max_steps=150))
    model = {"type": "leuven", "stiffness": k, "breakaway_force": w, "exponent": exponent,
             "bristle_damping": data.draw(physical(0.0, 10.0)),
             "viscous_coefficient": 0.0, **curve}
    res, states = run_with_mid_state(model, t, drive(t, x, use_v))
    assert np.all(np.isfinite(res.force))
    for state in states:
        e = element_forces(state)
        assert e.shape == (len(k),)
        assert np.all(np.abs(e) <= np.asarray(w) * (1 + 1e-9))


# --- energy over closed cycles -------------------------------------------------

SAMPLES_PER_LEG = 64


@st.composite
def closed_cycles(draw, scale, with_prefix=True):
    """Vertices of a prefix path (possibly empty; always empty without
    ``with_prefix``: the cycle then starts from rest) and of a closed cycle."""
    def legs(count):
        out = []
        for _ in range(count):
            size = draw(st.floats(0.01, 3.0)) * scale
            out.append(size if draw(st.booleans()) else -size)
        return out

    prefix = legs(draw(st.integers(0, 3))) if with_prefix else []
    cycle = legs(draw(st.integers(1, 5)))
    start = float(np.sum(prefix))
    vertices = [0.0] + list(np.cumsum(prefix)) if prefix else [0.0]
    cycle_vertices = list(start + np.cumsum(cycle))
    if abs(cycle_vertices[-1] - start) < 1e-3 * scale:   # keep every leg non-empty
        cycle_vertices.append(start + 0.5 * scale)
    cycle_vertices.append(start)                          # close the cycle
    return vertices, cycle_vertices


def cycle_work(model, vertices, cycle_vertices, slope_drop, speed):
    """``oint F dx`` over the cycle and its tolerance (trapezoid bound)."""
    path = vertices + cycle_vertices
    t, x = polyline(path, samples_per_leg=SAMPLES_PER_LEG, speed=speed)
    f = run(model, t, x=x).force
    first = (len(vertices) - 1) * SAMPLES_PER_LEG
    xs, fs = x[first:], f[first:]
    assert xs[0] == xs[-1]
    dx = np.diff(xs)
    f_mid = 0.5 * (fs[1:] + fs[:-1])
    work = float(np.sum(f_mid * dx))
    legs = np.abs(np.diff([path[len(vertices) - 1]] + cycle_vertices))
    tolerance = float(np.sum(slope_drop * (legs / SAMPLES_PER_LEG) ** 2 / 8.0))
    tolerance += 1e-12 * float(np.sum(np.abs(f_mid * dx))) + 1e-300
    return work, tolerance


@SETTINGS
@given(elements=element_sets(), data=st.data())
def test_maxwell_slip_dissipates_over_any_closed_cycle(elements, data):
    k, w = elements
    d_max = max(wi / ki for ki, wi in zip(k, w))
    vertices, cycle = data.draw(closed_cycles(d_max))
    model = {"type": "maxwell-slip", "stiffness": k, "breakaway_force": w}
    work, tolerance = cycle_work(model, vertices, cycle, sum(k), speed=1e-4)
    assert work >= -tolerance, (work, tolerance)


@SETTINGS
@given(stiffness=log_uniform(3, 7), fc=log_uniform(-1, 1), alpha=st.floats(0.0, 3.0),
       data=st.data())
def test_dahl_dissipates_over_closed_cycles_from_rest(stiffness, fc, alpha, data):
    _, cycle = data.draw(closed_cycles(fc / stiffness, with_prefix=False))
    model = {"type": "dahl", "stiffness": stiffness, "coulomb_force": fc, "exponent": alpha}
    work, tolerance = cycle_work(model, [0.0], cycle, stiffness * 2.0 ** alpha, speed=1e-4)
    assert work >= -tolerance, (work, tolerance)


@SETTINGS
@given(elements=element_sets(), curve=stribeck(), data=st.data())
def test_gms_dissipates_over_slow_closed_cycles_from_rest(elements, curve, data):
    k, _ = elements
    alpha = data.draw(weights(len(k)))
    cap = max(curve["static_force"], curve["coulomb_force"])
    d_max = max(a * cap / ki for ki, a in zip(k, alpha))
    _, cycle = data.draw(closed_cycles(d_max, with_prefix=False))
    model = {"type": "gms", "stiffness": k, "weight": alpha, "attraction": 1e10, **curve}
    speed = 1e-3 * curve["stribeck_velocity"]
    work, tolerance = cycle_work(model, [0.0], cycle, sum(k), speed=speed)
    assert work >= -tolerance, (work, tolerance)
