"""One-degree-of-freedom systems (MODELS.md 8): ``polind.dynamics.simulate_system``.

Every check is against a closed form, an independent reference (scipy's
Radau on the LuGre ODE, ``polind.simulate`` along the body's own path) or a
much finer run of the same scheme (the convergence order), never against
stored output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import polind
import polind.dynamics as dynamics
from conftest import LUGRE_1995, lib, representative
from test_io import SYSTEM_TOML
from polind.dynamics import System, SystemResult, load_system, simulate_system
from polind.errors import InputError
from polind.models.pol_ind import default_table

FC, FS, VS = 1.0, 1.5, 1e-3


def observed_orders(errors):
    errors = np.asarray(errors)
    return np.log2(errors[:-1] / errors[1:])


def advance_per_cycle(res, period=1.0):
    """Change of the cycle-mean position from one forcing cycle to the next [m]."""
    per_cycle = int(round(period / (res.t[1] - res.t[0])))
    cycles = (res.t.shape[0] - 1) // per_cycle
    means = res.x[:cycles * per_cycle].reshape(cycles, per_cycle).mean(axis=1)
    return np.diff(means)


def spring_peaks(res, stiffness, velocity, above):
    """Times and values of the local maxima of the drive spring's force above ``above``."""
    spring = stiffness * (velocity * res.t - res.x)
    inner = (spring[1:-1] > spring[:-2]) & (spring[1:-1] >= spring[2:]) & (spring[1:-1] > above)
    index = np.flatnonzero(inner) + 1
    return res.t[index], spring[index]


# --- the result and its contract ----------------------------------------------------

def test_result_samples_every_time_step_and_applied_force_is_the_drive():
    system = System(mass=2.0, duration=1.0, time_step=0.01, spring_stiffness=3.0,
                    drive_velocity=0.2, offset=0.1, rate=0.5, amplitude=0.3, frequency=2.0)
    res = simulate_system(lib(representative("gms")), system)
    assert isinstance(res, SystemResult)
    assert res.t.shape == (101,)
    np.testing.assert_allclose(res.t, 0.01 * np.arange(101), rtol=0, atol=1e-15)
    for array in (res.x, res.v, res.force, res.applied):
        assert array.dtype == np.float64 and array.shape == res.t.shape
    expected = (3.0 * (0.2 * res.t - res.x) + 0.1 + 0.5 * res.t
                + 0.3 * np.sin(2 * np.pi * 2.0 * res.t))
    np.testing.assert_allclose(res.applied, expected, rtol=1e-13, atol=1e-15)
    assert res.final_state.model_type == "gms"
    assert res.final_state.time == res.t[-1] and res.final_state.position == res.x[-1]


def test_initial_conditions_and_initial_force():
    model = lib(representative("maxwell-slip"))   # sigma2 = 0.4, virgin elements
    res = simulate_system(model, System(mass=1.0, duration=0.1, time_step=1e-3, offset=0.2),
                          initial_position=0.3, initial_velocity=-0.01)
    assert res.x[0] == 0.3 and res.v[0] == -0.01
    assert res.force[0] == pytest.approx(0.4 * -0.01, rel=1e-15)
    assert res.applied[0] == 0.2


# --- (1) Coulomb block pulled by a spring ---------------------------------------------

@pytest.mark.parametrize("method, order", [("bdf2", 2.0), ("euler", 1.0)])
def test_coulomb_block_sticks_exactly_then_slips_harmonically(method, order):
    """Stuck (x exactly 0) while k_d v_d t <= Fc; then harmonic motion about the
    moving equilibrium: x = v_d tau - (v_d / w) sin(w tau), tau = t - Fc / (k_d v_d)."""
    mass, kd, vd = 1.0, 2.0, 0.1
    omega = math.sqrt(kd / mass)
    t_slip = FC / (kd * vd)
    model = lib({"type": "coulomb", "coulomb_force": FC})
    errors = []
    for h in (0.01, 0.005, 0.0025):
        system = System(mass=mass, duration=t_slip + 0.9 * 2 * math.pi / omega, time_step=h,
                        spring_stiffness=kd, drive_velocity=vd)
        res = simulate_system(model, system, method=method)
        stick = res.t < t_slip
        assert np.all(res.x[stick] == 0.0) and np.all(res.v[stick] == 0.0)
        # The static friction is the force that holds the block: the spring's.
        np.testing.assert_array_equal(res.force[stick], res.applied[stick])
        tau = res.t[~stick] - t_slip
        exact = vd * tau - vd / omega * np.sin(omega * tau)
        errors.append(np.max(np.abs(res.x[~stick] - exact)))
        assert np.all(res.force[~stick][1:] == FC)       # sliding forwards throughout
    np.testing.assert_allclose(observed_orders(errors), order, atol=0.15)
    assert errors[-1] < (2e-6 if method == "bdf2" else 1e-3)


def test_stribeck_body_is_held_exactly_below_the_static_force():
    model = lib(representative("stribeck"))
    held = simulate_system(model, System(mass=1.0, duration=2.0, time_step=1e-3,
                                         offset=1.2, amplitude=0.29, frequency=3.0))
    assert np.all(held.x == 0.0) and np.all(held.v == 0.0)
    np.testing.assert_allclose(held.force, held.applied, rtol=1e-15)   # one rounding apart
    moved = simulate_system(model, System(mass=1.0, duration=0.1, time_step=1e-3, offset=1.51))
    assert np.all(np.diff(moved.x) > 0.0)


# --- (2) stiff elements: stable, settles, no creep -------------------------------------

@pytest.mark.parametrize("method", ["bdf2", "euler"])
def test_stiff_maxwell_slip_body_settles_and_never_creeps(method):
    """k h^2 / m from 1e6 to 1e7 for every element, a constant force below break-away."""
    mass, h = 1.0, 0.1
    stiffness = np.geomspace(1e8, 1e9, 8)
    breakaway = np.full(8, 1.5 / 8)
    assert stiffness.min() * h ** 2 / mass == pytest.approx(1e6)
    model = lib({"type": "maxwell-slip", "stiffness": stiffness.tolist(),
                 "breakaway_force": breakaway.tolist()})
    res = simulate_system(model, System(mass=mass, duration=2e4, time_step=h, offset=1.0),
                          method=method)                                    # 2e5 steps
    assert np.all(np.isfinite(res.x)) and np.all(np.isfinite(res.force))
    # No blow-up: it stays within the slip distance of the softest element (no break-away).
    assert np.max(np.abs(res.x)) < np.max(breakaway / stiffness)
    settled = res.x[50]
    assert settled > 0.0
    assert np.max(np.abs(res.x[50:] - settled)) <= 1e-12 * settled
    np.testing.assert_allclose(res.force[50:], 1.0, rtol=1e-9)


def test_lugre_body_under_a_constant_force_comes_to_rest_and_stays():
    """LuGre drifts only under a varying force: under a constant one it rests."""
    res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=20.0, time_step=1e-3,
                                                  offset=0.8))
    settled = res.x[5000]
    assert np.max(np.abs(res.x[5000:] - settled)) <= 1e-12 * abs(settled)
    np.testing.assert_allclose(res.force[5000:], 0.8, rtol=1e-9)


@pytest.mark.parametrize("method", ["bdf2", "euler"])
def test_gms_body_stopping_from_slip_is_held(method):
    """A sliding GMS body stops against a force below Fc: its slipping elements
    (whose relaxation rate does not vanish as v -> 0+) settle and it stays put.
    The viscous term damps the presliding oscillation (sqrt(sum k / m) = 424
    rad/s) within a few hundredths of a second."""
    model = lib(representative("gms", viscous_coefficient=50.0))
    res = simulate_system(model, System(mass=1.0, duration=4.0, time_step=1e-3, offset=0.5),
                          initial_velocity=0.05, method=method)
    assert res.v[:10].min() > 0.0
    rest = res.t >= 2.0
    settled = res.x[rest][0]
    assert np.max(np.abs(res.x[rest] - settled)) <= 1e-12 * settled
    np.testing.assert_allclose(res.force[rest], 0.5, rtol=1e-9)


# --- (3) convergence order -------------------------------------------------------------

@pytest.fixture(scope="module")
def lugre_stick_slip_reference():
    """The LuGre stick-slip case (MODELS.md 8) by scipy's Radau on (x, v, z)."""
    s0, s1, s2 = (LUGRE_1995[key] for key in ("bristle_stiffness", "bristle_damping",
                                             "viscous_coefficient"))
    kd, vd = 2.0, 0.1

    def rhs(t, y):
        x, v, z = y
        g = FC + (FS - FC) * math.exp(-(v / VS) ** 2)
        rate = v - s0 * abs(v) * z / g
        return [v, kd * (vd * t - x) - (s0 * z + s1 * rate + s2 * v), rate]

    return solve_ivp(rhs, (0.0, 7.0), [0.0, 0.0, 0.0], method="Radau", rtol=1e-11,
                     atol=1e-14, max_step=1e-2, dense_output=True).sol


@pytest.mark.parametrize("method, order", [("bdf2", 2.0), ("euler", 1.0)])
def test_order_against_an_independent_reference(lugre_stick_slip_reference, method, order):
    """Stick, break-away and slip of the LuGre reference case: the error against
    Radau falls as h^2 (BDF2) or h (backward Euler)."""
    errors = []
    for h in (5e-4, 2.5e-4, 1.25e-4):
        res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=7.0, time_step=h,
                                                      spring_stiffness=2.0, drive_velocity=0.1),
                              method=method)
        errors.append(np.max(np.abs(res.x - lugre_stick_slip_reference(res.t)[0])))
    np.testing.assert_allclose(observed_orders(errors), order, atol=0.1)
    assert errors[-1] < (2e-6 if method == "bdf2" else 2e-4)


@pytest.mark.parametrize("method, order", [("bdf2", 2.0), ("euler", 1.0)])
def test_order_of_a_gms_body_against_a_fine_run(method, order):
    """Spring-driven GMS (attraction resolved by the step), sliding without
    stopping after break-away; error against the BDF2 run at h / 32."""
    rng = np.random.default_rng(1)
    weight = rng.uniform(0.5, 1.5, 16)
    model = lib(representative("gms", stiffness=np.geomspace(1e3, 1e5, 16).tolist(),
                               weight=(weight / weight.sum()).tolist(), attraction=20.0,
                               stribeck_velocity=1e-2))

    def system(h):
        return System(mass=1.0, duration=2.0, time_step=h, spring_stiffness=50.0,
                      drive_velocity=1.0)

    steps = (2e-3, 1e-3, 5e-4)
    fine = simulate_system(model, system(steps[0] / 32))
    assert np.all(fine.v[1:] > 0.0)
    errors = [np.max(np.abs(simulate_system(model, system(h), method=method).x
                            - fine.x[::int(round(h / fine.t[1]))])) for h in steps]
    np.testing.assert_allclose(observed_orders(errors), order, atol=0.2)


# --- (4) consistency with the prescribed-motion simulation -------------------------------

STATEFUL = {
    "dahl": representative("dahl"),
    "lugre": LUGRE_1995,
    "maxwell-slip": representative("maxwell-slip"),
    "gms": representative("gms"),
    "leuven": representative("leuven"),
    "pol-ind": default_table(),
}


def _shaking_system(model_type, h=1e-3):
    """Spring drive plus an oscillating force: presliding, stick, slip and reversals."""
    scale = 15.0 if model_type == "pol-ind" else 1.0
    return System(mass=1.0, duration=3.0, time_step=h, spring_stiffness=2.0 * scale,
                  drive_velocity=0.05, amplitude=0.9 * scale, frequency=2.0)


@pytest.mark.parametrize("model_type", list(STATEFUL))
def test_force_is_the_models_own_along_the_bodys_path(model_type):
    """Backward Euler: v is the step velocity, so the whole result equals
    ``simulate(model, t, x=x)`` (force and velocity)."""
    model = lib(STATEFUL[model_type])
    res = simulate_system(model, _shaking_system(model_type), method="euler")
    assert np.ptp(res.v) > 0.0 and res.v.min() < 0.0 < res.v.max()      # reversals happen
    prescribed = polind.simulate(model, res.t, x=res.x)
    np.testing.assert_array_equal(res.v[1:], prescribed.v[1:])
    scale = max(np.max(np.abs(prescribed.force)), 1.0)
    np.testing.assert_allclose(res.force[1:], prescribed.force[1:], rtol=0, atol=1e-9 * scale)
    for key, value in prescribed.final_state.variables.items():
        np.testing.assert_allclose(res.final_state.variables[key], value, rtol=1e-9,
                                   atol=1e-15, err_msg=key)


@pytest.mark.parametrize("model_type", list(STATEFUL))
def test_bdf2_state_follows_the_path_and_rate_terms_use_the_body_velocity(model_type):
    """BDF2: the model state is advanced along the body's own piecewise-linear
    path exactly as ``simulate`` does; the rate term sigma2 v is taken at the
    body's velocity instead of the step's."""
    model = lib(STATEFUL[model_type])
    res = simulate_system(model, _shaking_system(model_type))
    prescribed = polind.simulate(model, res.t, x=res.x)
    for key, value in prescribed.final_state.variables.items():
        np.testing.assert_allclose(res.final_state.variables[key], value, rtol=1e-9,
                                   atol=1e-15, err_msg=key)
    if model_type == "lugre":
        return   # its sigma1 dz/dt is nonlinear in v; covered by the Radau comparison
    sigma2 = model.params.get("viscous_coefficient", 0.0)
    expected = prescribed.force + sigma2 * (res.v - prescribed.v)
    scale = max(np.max(np.abs(prescribed.force)), 1.0)
    np.testing.assert_allclose(res.force[1:], expected[1:], rtol=0, atol=1e-9 * scale)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2 ** 32 - 1), elements=st.integers(1, 12),
       model_type=st.sampled_from(["maxwell-slip", "gms"]),
       stiffness_decades=st.floats(2.0, 9.0), mass=st.floats(1e-3, 10.0),
       drive=st.sampled_from(["spring", "force"]))
def test_random_bodies_are_consistent_and_balanced(seed, elements, model_type,
                                                   stiffness_decades, mass, drive):
    """Random element sets (k h^2 / m up to 1e9) and drives: the body's force is the
    model's along its path, and a body found at rest is in force balance."""
    rng = np.random.default_rng(seed)
    stiffness = 10.0 ** rng.uniform(stiffness_decades - 2.0, stiffness_decades, elements)
    share = rng.uniform(0.2, 1.0, elements)
    share /= share.sum()
    if model_type == "maxwell-slip":
        params = {"type": model_type, "stiffness": stiffness.tolist(),
                  "breakaway_force": (FS * share).tolist()}
    else:
        params = representative("gms", stiffness=stiffness.tolist(), weight=share.tolist(),
                                attraction=float(10.0 ** rng.uniform(0.0, 4.0)),
                                viscous_coefficient=0.0)
    model = lib(params)
    if drive == "spring":
        system = System(mass=mass, duration=0.5, time_step=5e-4,
                        spring_stiffness=float(10.0 ** rng.uniform(0.0, 3.0)),
                        drive_velocity=float(rng.uniform(-0.1, 0.1)))
    else:
        system = System(mass=mass, duration=0.5, time_step=5e-4,
                        offset=float(rng.uniform(-2.0, 2.0)),
                        amplitude=float(rng.uniform(0.0, 2.0)),
                        frequency=float(rng.uniform(0.0, 20.0)))
    method = "euler" if seed % 2 else "bdf2"
    res = simulate_system(model, system, method=method,
                          initial_velocity=float(rng.uniform(-0.01, 0.01)))
    assert np.all(np.isfinite(res.x)) and np.all(np.isfinite(res.v))
    prescribed = polind.simulate(model, res.t, x=res.x)
    np.testing.assert_allclose(res.force[1:], prescribed.force[1:], rtol=0, atol=1e-9 * FS)
    # Momentum balance of the scheme, step by step, except where the root lay in
    # the jump of a GMS force at w = 0 and the body moved by one ulp of x.
    step = np.abs(np.diff(res.x))
    jump = (step > 0.0) & (step <= np.spacing(np.maximum(np.abs(res.x[1:]), np.abs(res.x[:-1]))))
    assert model_type == "gms" or not np.any(jump)
    h = system.time_step
    dv = np.diff(res.v)
    if method == "euler":
        inertia = mass * dv / h
    else:
        inertia = np.empty_like(dv)
        inertia[0] = mass * dv[0] / h
        inertia[1:] = mass * (1.5 * dv[1:] - 0.5 * dv[:-1]) / h
    np.testing.assert_allclose(inertia[~jump], (res.applied[1:] - res.force[1:])[~jump], rtol=0,
                               atol=1e-6 * (FS + np.max(np.abs(res.applied))))


# --- (5) the LuGre stick-slip reference case ---------------------------------------------

def test_lugre_stick_slip_period_and_peak_do_not_depend_on_the_step():
    periods, peaks = [], []
    for h in (1e-3, 5e-4, 2.5e-4):
        res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=30.0, time_step=h,
                                                      spring_stiffness=2.0, drive_velocity=0.1))
        times, values = spring_peaks(res, 2.0, 0.1, above=1.2)
        assert len(times) >= 4                                  # it sticks and slips, again
        cycle = np.diff(times)
        np.testing.assert_allclose(cycle[1:], cycle[-1], rtol=2e-3)   # periodic
        np.testing.assert_allclose(values[1:], values[-1], rtol=1e-4)
        periods.append(cycle[-1])
        peaks.append(values[-1])
        # Sticking means the drive spring is loaded while the body barely moves.
        assert np.min(res.v) > -1e-3 and np.mean(np.abs(res.v) < 1e-3) > 0.5
    np.testing.assert_allclose(periods, periods[-1], rtol=2e-3)
    np.testing.assert_allclose(peaks, peaks[-1], rtol=1e-3)
    assert FS < peaks[-1] < 1.05 * FS                           # break-away near Fs


# --- (6) drift under an oscillating force below break-away -------------------------------

@pytest.mark.parametrize("h", [1e-3, 5e-4])
def test_lugre_drifts_steadily_by_its_own_amount(h):
    """F_a = 0.5 + 0.4 sin(2 pi t) N, 1995 parameters, m = 1 kg: about 6.6 um per cycle."""
    res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=8.0, time_step=h,
                                                  offset=0.5, amplitude=0.4, frequency=1.0))
    advance = advance_per_cycle(res)
    np.testing.assert_allclose(advance[1:], 6.6e-6, rtol=0.03)
    np.testing.assert_allclose(advance[1:], advance[-1], rtol=1e-3)     # steady, forever


@pytest.mark.parametrize("model_type", ["maxwell-slip", "gms"])
def test_maxwell_slip_family_shakes_down(model_type):
    res = simulate_system(lib(representative(model_type)),
                          System(mass=1.0, duration=8.0, time_step=1e-3, offset=0.5,
                                 amplitude=0.4, frequency=1.0))
    advance = advance_per_cycle(res)
    assert advance[0] > 0.0
    assert np.max(np.abs(advance[3:])) < 1e-6 * advance[0]


# --- pol-ind -------------------------------------------------------------------------

def test_pol_ind_body_breaks_away_at_the_static_coefficient_times_the_load():
    """A slow force ramp on the default Pol-Ind contact (100 N, mu_s = 0.15): the
    friction never exceeds mu_s N and the body breaks away as the force passes it."""
    model = lib(default_table())
    res = simulate_system(model, System(mass=1.0, duration=2.0, time_step=1e-4, rate=10.0))
    assert np.max(res.force) <= 15.0 * (1 + 1e-12)
    assert np.max(res.force) > 14.99
    breakaway = res.applied[np.argmax(res.v > VS)]
    assert 15.0 < breakaway < 15.2


# --- chunks, progress, inputs --------------------------------------------------------

def test_chunked_run_equals_one_run(monkeypatch):
    model = lib(representative("gms"))
    system = _shaking_system("gms")
    whole = simulate_system(model, system)
    monkeypatch.setattr(dynamics, "_CHUNK", 7)
    calls = []
    chunked = simulate_system(model, system, progress=lambda done, total: calls.append(done))
    for key in ("x", "v", "force", "applied"):
        np.testing.assert_array_equal(getattr(chunked, key), getattr(whole, key), err_msg=key)
    assert calls[-1] == whole.t.shape[0] - 1 and calls == sorted(calls) and len(calls) > 100


@pytest.mark.parametrize("changes, key", [
    ({"mass": 0.0}, "mass"), ({"mass": -1.0}, "mass"), ({"duration": float("nan")}, "duration"),
    ({"time_step": 0.0}, "time_step"), ({"time_step": 2.0}, "time_step"),
    ({"spring_stiffness": -1.0}, "spring_stiffness"), ({"frequency": -1.0}, "frequency"),
    ({"offset": float("inf")}, "offset"), ({"rate": "1"}, "rate"),
    ({"amplitude": True}, "amplitude"),
])
def test_system_validation_names_the_key(changes, key):
    with pytest.raises(InputError, match=f"'{key}'"):
        System(**{"mass": 1.0, "duration": 1.0, "time_step": 0.1, **changes})


def test_simulate_system_rejects_bad_arguments():
    model = lib(representative("gms"))
    system = System(mass=1.0, duration=1.0, time_step=0.1)
    with pytest.raises(InputError, match="'system'"):
        simulate_system(model, {"mass": 1.0})
    with pytest.raises(InputError, match="'model'"):
        simulate_system("gms", system)
    with pytest.raises(InputError, match="'method'"):
        simulate_system(model, system, method="rk4")
    with pytest.raises(InputError, match="'initial_velocity'"):
        simulate_system(model, system, initial_velocity=float("nan"))


def test_load_system_reads_the_system_file(tmp_path):
    path = tmp_path / "system.toml"
    path.write_text("[system]\nmass = 2.0\nduration = 3.0\ntime_step = 0.001\n"
                    "[system.spring_drive]\nstiffness = 4.0\nvelocity = 0.5\n"
                    "[system.force]\noffset = 0.25\namplitude = 0.1\nfrequency = 5.0\n")
    assert load_system(path) == System(mass=2.0, duration=3.0, time_step=0.001,
                                       spring_stiffness=4.0, drive_velocity=0.5, offset=0.25,
                                       amplitude=0.1, frequency=5.0)
    force_only = tmp_path / "force.toml"
    force_only.write_text("[system]\nmass = 1.0\nduration = 1.0\ntime_step = 0.01\n"
                          "[system.force]\nrate = 2.0\n")
    assert load_system(force_only) == System(mass=1.0, duration=1.0, time_step=0.01, rate=2.0)
    bad = tmp_path / "bad.toml"
    bad.write_text("[system]\nmass = -1.0\nduration = 1.0\ntime_step = 0.01\n"
                   "[system.force]\nrate = 2.0\n")
    with pytest.raises(InputError, match="mass"):
        load_system(bad)


# --- one validator for a [system] file and a System built in Python ---------------------

#: SYSTEM_TOML as System keywords.
SYSTEM_ARGUMENTS = {"mass": 1.0, "duration": 10.0, "time_step": 1e-4, "spring_stiffness": 2.0,
                    "drive_velocity": 0.1, "offset": 0.5, "rate": 0.0, "amplitude": 0.4,
                    "frequency": 1.0}


def _system_file(tmp_path, replacements):
    text = SYSTEM_TOML
    for old, new in replacements:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "system.toml"
    path.write_text(text)
    return path


# (id, the change to SYSTEM_TOML, the same mistake as System keywords, the file key named)
BAD_SYSTEM_VALUES = [
    ("zero-mass", ("mass = 1.0", "mass = 0.0"), {"mass": 0.0}, "'mass'"),
    ("negative-duration", ("duration = 10.0", "duration = -1"), {"duration": -1}, "'duration'"),
    ("zero-time-step", ("time_step = 1e-4", "time_step = 0"), {"time_step": 0}, "'time_step'"),
    ("time-step-beyond-duration", ("time_step = 1e-4", "time_step = 20.0"),
     {"time_step": 20.0}, "'time_step'"),
    ("negative-stiffness", ("stiffness = 2.0", "stiffness = -2.0"),
     {"spring_stiffness": -2.0}, "'spring_drive.stiffness'"),
    ("negative-frequency", ("frequency = 1.0", "frequency = -1.0"), {"frequency": -1.0},
     "'force.frequency'"),
    ("nan", ("amplitude = 0.4", "amplitude = nan"), {"amplitude": math.nan},
     "'force.amplitude'"),
    ("inf", ("mass = 1.0", "mass = inf"), {"mass": math.inf}, "'mass'"),
    ("text", ("offset = 0.5", 'offset = "half"'), {"offset": "half"}, "'force.offset'"),
    ("boolean", ("rate = 0.0", "rate = true"), {"rate": True}, "'force.rate'"),
    ("400-digit-integer", ("mass = 1.0", "mass = " + "9" * 400), {"mass": int("9" * 400)},
     "'mass'"),
    ("beyond-memory", ("time_step = 1e-4", "time_step = 1e-13"), {"time_step": 1e-13},
     "time_step"),
]


@pytest.mark.parametrize("change, arguments, key", [case[1:] for case in BAD_SYSTEM_VALUES],
                         ids=[case[0] for case in BAD_SYSTEM_VALUES])
def test_a_bad_system_value_has_one_message_from_a_file_and_from_python(tmp_path, change,
                                                                        arguments, key):
    with pytest.raises(InputError) as in_python:
        System(**{**SYSTEM_ARGUMENTS, **arguments})
    path = _system_file(tmp_path, [change])
    with pytest.raises(InputError) as from_file:
        load_system(path)
    assert str(from_file.value) == f"{path}: {in_python.value}"
    assert key in str(from_file.value)


# (id, changes to SYSTEM_TOML, fragments of the message after the file's name)
BAD_SYSTEM_KEYS = [
    ("unknown-key", [("mass = 1.0", "mass = 1.0\nmas = 2")], ["Unknown key 'mas'", "mass"]),
    ("unknown-subtable-key", [("velocity = 0.1", "velocity = 0.1\nspeed = 1")],
     ["Unknown key 'spring_drive.speed'"]),
    ("unknown-subtable", [("[system.force]", "[system.brake]\nx = 1\n[system.force]")],
     ["Unknown key 'brake'"]),
    ("missing-mass", [("mass = 1.0\n", "")], ["Missing key 'mass'"]),
    ("missing-drive-velocity", [("velocity = 0.1\n", "")],
     ["Missing key 'spring_drive.velocity'"]),
    ("empty-spring-drive", [("stiffness = 2.0\nvelocity = 0.1\n", "")],
     ["Missing key 'spring_drive.stiffness'"]),
    ("drive-not-table", [("[system.spring_drive]\nstiffness = 2.0\nvelocity = 0.1\n", ""),
                         ("time_step = 1e-4\n", "time_step = 1e-4\nspring_drive = 3\n")],
     ["'spring_drive' table", "Got 3"]),
    ("no-drive", [("[system.spring_drive]\nstiffness = 2.0\nvelocity = 0.1\n", ""),
                  ("[system.force]\noffset = 0.5\nrate = 0.0\namplitude = 0.4\n"
                   "frequency = 1.0\n", "")],
     ["no drive", "[system.spring_drive]", "[system.force]"]),
]


@pytest.mark.parametrize("changes, fragments", [case[1:] for case in BAD_SYSTEM_KEYS],
                         ids=[case[0] for case in BAD_SYSTEM_KEYS])
def test_a_bad_system_file_key_is_named_after_the_file(tmp_path, changes, fragments):
    path = _system_file(tmp_path, changes)
    with pytest.raises(InputError) as error:
        load_system(path)
    message = str(error.value)
    assert message.startswith(f"{path}: ") and message.count(f"{path}") == 1, message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_system_file_reads_as_its_python_system(tmp_path):
    assert load_system(_system_file(tmp_path, [])) == System(**SYSTEM_ARGUMENTS)
    integers = _system_file(tmp_path, [("mass = 1.0", "mass = 2"), ("duration = 10.0",
                                                                    "duration = 10")])
    loaded = load_system(integers)
    assert loaded == System(**{**SYSTEM_ARGUMENTS, "mass": 2.0})
    assert isinstance(loaded.mass, float) and isinstance(loaded.duration, float)


def test_polind_dynamics_and_polind_sweep_give_the_message_of_load_system(tmp_path, capsys):
    from polind.cli import _run
    from polind.sweeps import load_sweep

    path = _system_file(tmp_path, [("stiffness = 2.0", "stiffness = -2.0")])
    with pytest.raises(InputError) as error:
        load_system(path)
    model = tmp_path / "model.toml"
    model.write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    status = _run(["dynamics", str(model), "--system", str(path), "-o",
                   str(tmp_path / "out.csv")])
    assert status == 2
    assert capsys.readouterr().err == f"polind: error: {error.value}\n"
    sweep_file = tmp_path / "sweep.toml"
    sweep_file.write_text('[sweep]\nmodel = "model.toml"\nsystem = "system.toml"\n'
                          'metrics = ["mean_force"]\n'
                          '[sweep.parameters]\n"model.coulomb_force" = { values = [1.0] }\n')
    with pytest.raises(InputError) as from_sweep:
        load_sweep(sweep_file)
    assert str(from_sweep.value) == str(error.value)


# --- (3b) a convergence study from h = 1e-3 to 1e-5 s -------------------------------------

def _lugre_body_rhs(drive_stiffness, drive_velocity, offset):
    s0, s1, s2 = (LUGRE_1995[key] for key in ("bristle_stiffness", "bristle_damping",
                                             "viscous_coefficient"))

    def rhs(t, y):
        x, v, z = y
        g = FC + (FS - FC) * math.exp(-(v / VS) ** 2)
        rate = v - s0 * abs(v) * z / g
        return [v, drive_stiffness * (drive_velocity * t - x) + offset
                - (s0 * z + s1 * rate + s2 * v), rate]
    return rhs


def test_bdf2_is_second_order_on_smooth_sliding_down_to_1e_5():
    """LuGre sliding without stopping (v > 0.04 m/s throughout), against Radau at rtol 1e-12.

    Measured (max |x - x_ref|): h = 1e-3: 5.9e-4, 5e-4: 4.1e-4, 2e-4: 1.4e-4,
    1e-4: 4.6e-5, 5e-5: 1.3e-5, 2e-5: 2.4e-6, 1e-5: 6.1e-7.  Above 1e-4 the
    bristle relaxation (time constant g / (sigma0 |v|) = 2e-4 s) is not
    resolved and the scheme is first order there, as the integrator's notes say.
    """
    rhs = _lugre_body_rhs(20.0, 0.05, 1.0)
    reference = solve_ivp(rhs, (0.0, 2.0), [0.0, 0.05, 0.0], method="Radau", rtol=1e-12,
                          atol=1e-15, max_step=1e-3, dense_output=True).sol
    errors = []
    for h in (1e-4, 5e-5, 2.5e-5, 1.25e-5):
        res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=2.0, time_step=h,
                                                      spring_stiffness=20.0,
                                                      drive_velocity=0.05, offset=1.0),
                              initial_velocity=0.05)
        assert res.v.min() > 0.04
        errors.append(np.max(np.abs(res.x - reference(res.t)[0])))
    np.testing.assert_allclose(observed_orders(errors), 2.0, atol=0.25)


def test_stick_slip_converges_until_the_position_quantum():
    """The 1995 LuGre stick-slip case over two cycles (20 s), against Radau at rtol 1e-12.

    Measured (max |x - x_ref|): h = 1e-4: 1.6e-6, 5e-5: 4.4e-7, 2e-5: 1.4e-7,
    1e-5: 1.4e-6.  The error falls at second order until h = 2e-5 and rises at
    1e-5: positions are floats, so a step velocity matters only to within
    ulp(x) / h, a quantum that grows as h shrinks (and with |x|: started at
    x = 1e3 m the error at h = 1e-4 is 8e-5).  While LuGre creeps in stick its
    velocity is of the order of that quantum, and the stick phase is resolved
    no better.  The integrator's notes say so; take h >= 2e-5 s for x of order
    1 m, or measure x from a nearby origin.
    """
    rhs = _lugre_body_rhs(2.0, 0.1, 0.0)
    reference = solve_ivp(rhs, (0.0, 20.0), [0.0, 0.0, 0.0], method="Radau", rtol=1e-12,
                          atol=1e-14, max_step=1e-2, dense_output=True).sol
    errors = []
    for h in (1e-4, 5e-5, 2.5e-5):
        res = simulate_system(lib(LUGRE_1995), System(mass=1.0, duration=20.0, time_step=h,
                                                      spring_stiffness=2.0,
                                                      drive_velocity=0.1))
        errors.append(np.max(np.abs(res.x - reference(res.t)[0])))
    orders = observed_orders(errors)
    assert np.all(orders > 1.5), orders
    assert errors[-1] < 3e-7


def test_a_system_beyond_the_memory_limit_is_refused_before_allocating():
    from polind import resources

    with pytest.raises(InputError, match=r"1e\+12 samples\) needs about 40 TB"):
        System(mass=1.0, duration=1e6, time_step=1e-6)
    resources.set_memory_limit(1e6)
    try:
        with pytest.raises(InputError, match=r"needs about 4 MB of memory; the limit is 1 MB "
                                             r"\(set by --max-memory\)"):
            System(mass=1.0, duration=1.0, time_step=1e-5)
        System(mass=1.0, duration=1.0, time_step=1e-3)       # 40 kB: fine
    finally:
        resources.set_memory_limit(None)
