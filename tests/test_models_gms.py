"""Generalized Maxwell-slip (MODELS.md 5): steady sliding, the exact per-step
update (via the oracle), the Maxwell-slip limit and frictional lag."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import oracles
from conftest import (
    STIFFNESS,
    WEIGHT,
    assert_close,
    element_forces,
    polyline,
    random_walk,
    representative,
    run,
)

REL = 1e-9
FC, FS, VS = 1.0, 1.5, 1e-3
K = np.array(STIFFNESS)
ALPHA = np.array(WEIGHT)


def gms(shape="exponential", **changes):
    return representative("gms", stribeck_shape=shape, **changes)


def g(v, shape="exponential", fc=FC, fs=FS):
    return oracles.stribeck_curve(v, fc, fs, VS, 2.0, shape)


# --- the oracle --------------------------------------------------------------

def test_oracle_slip_update_matches_integration():
    """An element in slip: the oracle's exponential against ``solve_ivp``."""
    model = gms(attraction=30.0, viscous_coefficient=0.0)
    t = np.linspace(0.0, 0.5, 101)
    v = 2e-3 + 1.5e-3 * np.sin(2 * np.pi * 3 * t)         # > 0 throughout
    ref = oracles.simulate(model, t, v=v)
    m = oracles.motion(t, v=v)
    slipping = ref.states["slipping"]
    checked = 0
    for k in range(len(t) - 1):
        vk = m.step_v[k]
        for i in range(len(K)):
            if slipping[k, i] and slipping[k + 1, i]:
                f0 = ref.states["element_force"][k, i]
                target = ALPHA[i] * g(vk)
                sol = solve_ivp(lambda _, f: [30.0 * (1 - f[0] / target)], (0, m.step_h[k]),
                                [f0], method="DOP853", rtol=1e-12, atol=1e-15)
                assert ref.states["element_force"][k + 1, i] == pytest.approx(
                    sol.y[0, -1], rel=1e-9)
                checked += 1
    assert checked > 100


def test_oracle_stick_then_crossing():
    """One element from rest at constant ``v``: stick ``F = k x`` up to
    ``alpha g(v)``, then exactly ``alpha g(v)`` (the step splits there)."""
    model = gms(stiffness=[1e4], weight=[1.0], viscous_coefficient=0.0)
    v = 1e-3
    t, x = polyline([0.0, 3e-4], samples_per_leg=30, speed=v)
    ref = oracles.simulate(model, t, x=x)
    expected = np.minimum(1e4 * x, g(v))
    np.testing.assert_allclose(ref.force, expected, rtol=1e-14)


def test_oracle_gms_is_maxwell_slip_when_fs_equals_fc():
    t, x = random_walk(800, 4e-6, seed=2)
    a = oracles.simulate(gms(static_force=FC, viscous_coefficient=0.0, attraction=3.0), t, x=x)
    b = oracles.simulate({"type": "maxwell-slip", "stiffness": STIFFNESS,
                          "breakaway_force": list(ALPHA * FC)}, t, x=x)
    assert_close(a.force, b.force, 1e-12, FC, "oracle GMS vs oracle MS")


# --- the library --------------------------------------------------------------

@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("v", [3e-4, 1e-3, 3e-3, 1e-2, -3e-4, -1e-3, -1e-2])
@pytest.mark.parametrize("fs", [1.5, 0.8])
def test_steady_sliding(shape, v, fs):
    model = gms(shape, static_force=fs)
    gv = g(v, shape, fs=fs)
    slip_distance = float(np.max(ALPHA * max(fs, FC) / K))
    # long enough for every element to slip and relax (exp(-C h/(alpha g)) ~ 0)
    duration = max(3 * slip_distance / abs(v), 0.0) + 2.0
    t = np.linspace(0.0, duration, 2001)
    res = run(model, t, x=v * t)
    expected = gv * np.sign(v) + 0.4 * v
    assert res.force[-1] == pytest.approx(expected, rel=REL)
    ref = oracles.simulate(model, t, x=v * t)
    assert_close(res.force, ref.force, REL, FS, "constant velocity vs oracle")


@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("fs", [1.5, 0.8])
@pytest.mark.parametrize("seed", [0, 1])
def test_random_motion_against_oracle(shape, fs, seed):
    model = gms(shape, static_force=fs)
    t, x = random_walk(3000, 5e-6, seed)
    res = run(model, t, x=x)
    ref = oracles.simulate(model, t, x=x)
    assert_close(res.force, ref.force, REL, FS, "x-driven")
    assert_close(element_forces(res.final_state), ref.states["element_force"][-1],
                 REL, FS, "final element forces")


@pytest.mark.parametrize("fs", [1.5, 0.8])
def test_standstill_steps_against_oracle(fs):
    """Steps with ``v = 0`` (dwell between slips, and reversals through a
    dwell): nothing moves during them, the mode question they raise does not
    change the force (an element left at ``alpha_i s(v)`` slips again at once)."""
    model = gms(static_force=fs)
    t, x = random_walk(3000, 5e-6, seed=8, dwell=0.2)
    res = run(model, t, x=x)
    ref = oracles.simulate(model, t, x=x)
    assert np.count_nonzero(res.v == 0.0) > 300
    assert_close(res.force, ref.force, REL, FS, "with standstill steps")


@pytest.mark.parametrize("shape", ["exponential", "rational"])
def test_velocity_driven_against_oracle(shape):
    t = np.linspace(0.0, 2.0, 4001)
    v = 3e-3 * np.sin(2 * np.pi * t) + 1e-3 * np.sin(2 * np.pi * 5.3 * t + 0.2)
    res = run(gms(shape), t, v=v)
    ref = oracles.simulate(gms(shape), t, v=v)
    assert_close(res.force, ref.force, REL, FS, "v-driven")


def test_maxwell_slip_limit_with_fs_equal_fc():
    """``Fs = Fc``, ``C -> inf``: GMS is Maxwell-slip with ``W_i = alpha_i Fc``.
    With the crossing splitting the step, an element that reaches
    ``alpha_i Fc`` stays there, so the identity holds at every ``C``: the
    error must not grow with ``C`` and is at rounding level at ``C = 1e12``."""
    vertices = [0.0, 3e-5, -2e-5, 1.5e-5, -5e-6, 8e-6, -6e-5, 1e-5]
    t, x = polyline(vertices, samples_per_leg=120, speed=2e-4)
    ms = {"type": "maxwell-slip", "stiffness": STIFFNESS,
          "breakaway_force": list(ALPHA * FC)}
    f_ms = run(ms, t, x=x).force
    errors = []
    for c in [1.0, 1e2, 1e4, 1e8, 1e12]:
        f = run(gms(static_force=FC, attraction=c, viscous_coefficient=0.0), t, x=x).force
        errors.append(np.max(np.abs(f - f_ms)))
    assert errors[-1] <= 1e-12 * FC, errors
    assert all(e2 <= e1 + 1e-12 for e1, e2 in zip(errors[:-1], errors[1:])), errors
    assert max(errors) <= REL * FC, errors


def limit_oracle(t, x, shape="exponential"):
    """GMS at ``C = inf`` (slipping elements sit on ``alpha_i s(v)``)."""
    return oracles.simulate(gms(shape, attraction=np.inf, viscous_coefficient=0.0), t, x=x)


def test_error_shrinks_with_attraction():
    """``Fs != Fc`` and slow motion ``|v| << vs`` at varying speed: GMS(C)
    approaches its ``C -> inf`` limit; the error shrinks with ``C``."""
    rng = np.random.default_rng(7)
    vertices = np.concatenate([[0.0], np.cumsum(rng.uniform(-8e-5, 8e-5, 10))])
    t = [0.0]
    x = [0.0]
    for a, b in zip(vertices[:-1], vertices[1:]):
        speed = rng.uniform(0.02, 0.5) * VS                  # g varies leg to leg
        seg_t, seg_x = polyline([a, b], samples_per_leg=80, speed=speed, t0=t[-1])
        t.extend(seg_t[1:])
        x.extend(seg_x[1:])
    t, x = np.array(t), np.array(x)
    f_inf = limit_oracle(t, x).force
    errors = []
    for c in [1e1, 1e3, 1e5, 1e12]:
        f = run(gms(attraction=c, viscous_coefficient=0.0), t, x=x).force
        errors.append(np.max(np.abs(f - f_inf)))
    assert errors[0] > 1e-3, errors                 # the limit is not trivial
    assert errors[1] < errors[0] and errors[2] < errors[1], errors
    assert errors[-1] <= 1e-12 * FS, errors


def lag_loop(frequency, cycles=4, samples=2000, attraction=50.0):
    v0, va = 1e-3, 0.8e-3
    model = gms(attraction=attraction, viscous_coefficient=0.0)
    t = np.linspace(0.0, cycles / frequency, cycles * samples + 1)
    v = v0 + va * np.sin(2 * np.pi * frequency * t)
    f = run(model, t, v=v).force
    last = slice((cycles - 1) * samples, cycles * samples + 1)
    return t[last], v[last], f[last]


def test_frictional_lag():
    """``v = v0 + va sin(2 pi f t) > 0``: the force is higher while ``v``
    rises than while it falls at the same ``v``; the loop area grows with
    ``f`` and shrinks onto the Stribeck curve as ``f -> 0``."""
    areas, deviations = [], []
    for f in [0.01, 0.2, 1.0, 5.0]:
        t, v, force = lag_loop(f)
        phase = (2 * np.pi * f * t) % (2 * np.pi)
        rising = (phase < np.pi / 2) | (phase > 3 * np.pi / 2)
        vr, fr = v[rising], force[rising]
        vf, ff = v[~rising], force[~rising]
        order_r, order_f = np.argsort(vr), np.argsort(vf)
        grid = np.linspace(v.min(), v.max(), 50)[5:-5]     # interior speeds
        f_rise = np.interp(grid, vr[order_r], fr[order_r])
        f_fall = np.interp(grid, vf[order_f], ff[order_f])
        assert np.all(f_rise > f_fall), f"f = {f}: rising branch not above falling"
        # loop area in the (v, F) plane, positive for rising-above-falling
        areas.append(np.trapezoid(force, v))
        deviations.append(np.max(np.abs(force - g(v))))
    assert all(a > 0 for a in areas), areas
    assert areas[0] < areas[1] < areas[2] < areas[3], areas
    assert deviations[0] < deviations[1] < deviations[2] < deviations[3], deviations
    assert deviations[0] < 2e-3 * FS, deviations            # near the Stribeck curve
    assert areas[0] < 0.02 * areas[-1], areas
