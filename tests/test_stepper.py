"""Stepper and Body against simulate and simulate_system, for every model type.

The equalities of the stepping contract: a Stepper fed the samples of a
path one at a time gives ``simulate``'s forces, and a Body stepped with a
sequence of applied forces gives ``simulate_system(..., applied=...)``'s
positions, velocities and forces.  Random paths and random valid parameter
sets (seeded), so the equality is not a coincidence of one case.
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest

import polind
from polind.dynamics import System, simulate_system
from polind.models.pol_ind import default_table

from conftest import REPRESENTATIVE, assert_close, lib, random_walk


def _pol_ind_small():
    table = default_table()
    table["discretisation"]["elements"] = 8
    return table


ALL = {**copy.deepcopy(REPRESENTATIVE), "pol-ind": _pol_ind_small()}


def random_parameters(model_type, seed):
    """A valid parameter set near the representative one, every level scaled at random."""
    rng = np.random.default_rng(seed)
    table = copy.deepcopy(ALL[model_type])

    def scale(value, low=0.5, high=2.0):
        factor = rng.uniform(low, high, size=np.shape(value))
        return (np.asarray(value) * factor).tolist()

    for key in ("stiffness", "bristle_stiffness", "attraction", "stribeck_velocity",
                "viscous_coefficient", "bristle_damping"):
        if key in table:
            table[key] = scale(table[key])
    if "coulomb_force" in table:
        table["coulomb_force"] = scale(table["coulomb_force"])
        if "static_force" in table:
            table["static_force"] = table["coulomb_force"] * float(rng.uniform(1.0, 2.0))
    if model_type == "gms":
        weight = rng.uniform(0.2, 1.0, size=len(table["weight"]))
        table["weight"] = (weight / weight.sum()).tolist()
    if model_type == "maxwell-slip":
        table["breakaway_force"] = scale(table["breakaway_force"])
    if model_type == "leuven":
        share = rng.uniform(0.2, 1.0, size=len(table["breakaway_force"]))
        table["breakaway_force"] = (share / share.sum() * table["static_force"]).tolist()
    if model_type == "pol-ind":
        table["static_coefficient"] = float(rng.uniform(0.12, 0.2))
        table["kinetic_coefficient"] = float(rng.uniform(0.05, 0.11))
        table["attraction"] = float(rng.uniform(1e3, 1e5))
    return table


def _path(model_type, seed, n=600):
    scale = 2e-7 if model_type == "pol-ind" else 2e-6
    return random_walk(n, scale, seed, dwell=0.1)


def _stepper_forces(stepper, t, x=None, v=None, normal_load=None):
    forces = [stepper.force]
    for k in range(1, t.shape[0]):
        kwargs = {"x": float(x[k])} if x is not None else {"v": float(v[k])}
        if normal_load is not None:
            kwargs["normal_load"] = float(normal_load[k])
        forces.append(stepper.advance(float(t[k]), **kwargs))
    return np.array(forces)


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize("model_type", list(ALL))
def test_stepper_with_x_equals_simulate(model_type, seed):
    model = lib(random_parameters(model_type, seed))
    t, x = _path(model_type, seed)
    res = polind.simulate(model, t, x=x)
    # simulate reports the first step's velocity at sample 0; a stepper is told it.
    stepper = polind.Stepper(model, velocity=float(res.v[0]))
    forces = _stepper_forces(stepper, t, x=x)
    scale = max(float(np.max(np.abs(res.force))), 1e-300)
    assert_close(forces, res.force, 1e-12, scale, f"{model_type} Stepper(x)")
    assert stepper.position == res.x[-1] and stepper.time == res.t[-1]
    assert stepper.velocity == res.v[-1]
    final = stepper.state
    for key, value in res.final_state.variables.items():
        np.testing.assert_allclose(final.variables[key], value, rtol=1e-12,
                                   atol=1e-12 * scale)


@pytest.mark.parametrize("model_type", list(ALL))
def test_stepper_with_v_equals_simulate(model_type):
    model = lib(random_parameters(model_type, 7))
    t, x = _path(model_type, 7)
    v = np.gradient(x, t)
    res = polind.simulate(model, t, v=v)
    stepper = polind.Stepper(model, velocity=float(v[0]))
    forces = _stepper_forces(stepper, t, v=v)
    scale = max(float(np.max(np.abs(res.force))), 1e-300)
    assert_close(forces, res.force, 1e-12, scale, f"{model_type} Stepper(v)")
    assert abs(stepper.position - res.x[-1]) <= 1e-15 * max(abs(res.x[-1]), 1e-300) or \
        stepper.position == res.x[-1]


@pytest.mark.parametrize("model_type", list(ALL))
def test_stepper_continues_a_saved_state(model_type):
    model = lib(ALL[model_type])
    t, x = _path(model_type, 3)
    whole = polind.simulate(model, t, x=x)
    first = polind.simulate(model, t[:300], x=x[:300])
    state = polind.State.from_json(first.final_state.to_json())
    stepper = polind.Stepper(model, state=state)
    forces = _stepper_forces(stepper, t[299:], x=x[299:])
    scale = max(float(np.max(np.abs(whole.force))), 1e-300)
    assert_close(forces, whole.force[299:], 1e-10, scale, f"{model_type} continued")


def test_stepper_pol_ind_under_a_varying_load_equals_simulate():
    model = lib(ALL["pol-ind"])
    t, x = _path("pol-ind", 5)
    load = 100.0 * (0.75 + 0.25 * np.cos(2 * np.pi * t / t[-1] * 3))
    res = polind.simulate(model, t, x=x, normal_load=load)
    stepper = polind.Stepper(model, velocity=float(res.v[0]))
    # the stepper starts at the model's own load, simulate at load[0] = 100 N: the same.
    forces = _stepper_forces(stepper, t, x=x, normal_load=load)
    assert_close(forces, res.force, 1e-12, float(np.max(np.abs(res.force))), "pol-ind N(t)")


def _applied_forces(model_type, n, seed):
    rng = np.random.default_rng(seed)
    level = 15.0 if model_type == "pol-ind" else 1.0
    t = np.arange(n - 1) * 1e-3
    # below and above break-away, with reversals: stick, presliding and slip
    return level * (0.9 * np.sin(2 * np.pi * 3.0 * t) + 0.8 * np.sin(2 * np.pi * 0.7 * t)
                    + 0.05 * rng.normal(size=n - 1))


@pytest.mark.parametrize("method", ["bdf2", "euler"])
@pytest.mark.parametrize("model_type", ALL)
def test_body_equals_simulate_system_with_applied_forces(model_type, method):
    # Both run the model's one compiled body step (the runners' body_step).
    model = lib(random_parameters(model_type, 11))
    n = 1500
    system = System(mass=1.0, duration=(n - 1) * 1e-3, time_step=1e-3)
    forces = _applied_forces(model_type, n, 11)
    res = simulate_system(model, system, applied=forces, method=method)
    assert res.t.shape[0] == n
    body = polind.Body(model, mass=1.0, time_step=1e-3, method=method)
    steps = np.array([body.step(float(f)) for f in forces])
    assert np.ptp(res.x) > 0.0
    assert_close(steps[:, 0], res.x[1:], 1e-12, float(np.max(np.abs(res.x))), "x")
    assert_close(steps[:, 1], res.v[1:], 1e-12, float(np.max(np.abs(res.v))), "v")
    assert_close(steps[:, 2], res.force[1:], 1e-12, float(np.max(np.abs(res.force))), "F")
    np.testing.assert_array_equal(res.applied[:-1], forces)
    assert body.time == res.t[-1]
    for key, value in res.final_state.variables.items():
        np.testing.assert_allclose(body.state.variables[key], value, rtol=1e-12, atol=1e-300)


def test_a_stuck_body_holds_still_with_stiff_elements():
    model = lib(default_table())                     # k h^2 / m of the elements is ~1e4+
    body = polind.Body(model, mass=1.0, time_step=1e-3)
    for _ in range(200):
        x, v, friction = body.step(5.0)              # below mu_s N = 15 N
    assert v == 0.0 or abs(v) < 1e-12
    assert friction == pytest.approx(5.0, rel=1e-9)
    before = body.position
    for _ in range(100):
        body.step(5.0)
    assert body.position == before


@pytest.mark.parametrize("bad, message", [
    ({"t": float("nan"), "x": 0.0}, "'t'"),
    ({"t": 0.0, "x": 0.0}, "after the current time"),
    ({"t": -1.0, "x": 0.0}, "after the current time"),
    ({"t": 1.0, "x": float("inf")}, "'x'"),
    ({"t": 1.0, "v": float("nan")}, "'v'"),
    ({"t": 1.0}, "exactly one"),
    ({"t": 1.0, "x": 0.0, "v": 0.0}, "exactly one"),
    ({"t": 1.0, "x": "0.1"}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": 1j}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": 0.0, "normal_load": -10.0}, "'normal_load' parameter of Stepper must be positive"),
])
def test_stepper_refuses_bad_samples(bad, message):
    stepper = polind.Stepper(lib(ALL["lugre"]))
    with pytest.raises(polind.InputError, match=message):
        stepper.advance(**bad)
    assert stepper.time == 0.0                       # nothing advanced


def test_a_load_signal_a_model_ignores_is_said_once_and_changes_nothing():
    model = lib(ALL["lugre"])
    plain, loaded = polind.Stepper(model), polind.Stepper(model)
    with pytest.warns(UserWarning, match="ignores the normal-load signal") as record:
        forces = [loaded.advance(k * 1e-3, x=1e-6 * k, normal_load=5.0 + k) for k in (1, 2, 3)]
    assert len(record) == 1
    assert forces == [plain.advance(k * 1e-3, x=1e-6 * k) for k in (1, 2, 3)]


def test_stepper_refuses_a_load_the_pol_ind_table_cannot_take():
    stepper = polind.Stepper(lib(ALL["pol-ind"]))
    with pytest.raises(polind.InputError, match="table was built for at most"):
        stepper.advance(1e-3, x=0.0, normal_load=200.0)
    with pytest.raises(polind.InputError, match="positive"):
        stepper.advance(1e-3, x=0.0, normal_load=-1.0)


def test_stepper_and_body_refuse_bad_construction():
    model = lib(ALL["gms"])
    with pytest.raises(polind.InputError, match="friction model"):
        polind.Stepper({"type": "gms"})
    with pytest.raises(polind.InputError, match="the state's"):
        polind.Stepper(model, state=model.initial_state(), time=1.0)
    # the defaults of the signature, or the state's own values, are accepted beside a state
    state = model.initial_state()
    state.time, state.position = 2.0, 1e-6
    assert polind.Stepper(model, state=state, time=0.0, position=0.0).time == 2.0
    assert polind.Stepper(model, state=state, time=2.0, position=1e-6).position == 1e-6
    other = lib(ALL["maxwell-slip"]).initial_state()
    with pytest.raises(polind.InputError, match="maxwell-slip"):
        polind.Stepper(model, state=other)
    with pytest.raises(polind.InputError, match="'mass'"):
        polind.Body(model, mass=0.0)
    with pytest.raises(polind.InputError, match="'time_step'"):
        polind.Body(model, time_step=float("nan"))
    with pytest.raises(polind.InputError, match="'method'"):
        polind.Body(model, method="rk4")
    body = polind.Body(model)
    with pytest.raises(polind.InputError, match="applied_force"):
        body.step(float("inf"))
    with pytest.raises(polind.InputError, match="applied_force"):
        body.step("1")


def test_simulate_system_refuses_an_applied_array_of_the_wrong_length():
    model = lib(ALL["coulomb"])
    system = System(mass=1.0, duration=1.0, time_step=0.1)
    with pytest.raises(polind.InputError, match="'applied'"):
        simulate_system(model, system, applied=np.zeros(11))
    with pytest.raises(polind.InputError, match="'applied'"):
        simulate_system(model, system, applied=np.full(10, np.nan))


@pytest.mark.parametrize("model_type", list(ALL))
def test_a_users_own_njit_loop_advances_the_model(model_type):
    from numba import njit

    @njit
    def users_loop(step, scalars, table, state, t, x, normal_load, out):
        # The user's own compiled loop: no return to Python between samples.
        for k in range(1, t.shape[0]):
            h = t[k] - t[k - 1]
            dx = x[k] - x[k - 1]
            out[k] = step(scalars, table, state, h, dx, dx / h, dx / h, normal_load)

    model = lib(ALL[model_type])
    t, x = _path(model_type, 9)
    kernel = model.step_kernel()
    out = np.zeros(t.shape[0])
    users_loop(kernel.step, kernel.scalars, kernel.table, kernel.state, t, x,
               kernel.normal_load, out)
    res = polind.simulate(model, t, x=x)
    scale = max(float(np.max(np.abs(res.force))), 1e-300)
    assert_close(out[1:], res.force[1:], 1e-12, scale, f"{model_type} user loop")
    state = model.initial_state()
    model.unflatten_state(kernel.state, state)
    for key, value in res.final_state.variables.items():
        np.testing.assert_allclose(state.variables[key], value, rtol=1e-12, atol=1e-12 * scale)


@pytest.mark.parametrize("model_type", ["lugre", "pol-ind", "compliance"])
def test_a_refused_sample_changes_nothing(model_type):
    """Each bad sample is named; the stepper then goes on as if it had never been given."""
    inner = ALL["lugre"] if model_type == "compliance" else ALL[model_type]
    if model_type == "compliance":
        inner = {**inner, "compliance": {"stiffness": 2e5}}
    model = lib(inner)
    t = np.arange(0.0, 0.2, 1e-3)
    x = 2e-6 * np.sin(2.0 * np.pi * 5.0 * t)
    expected = _stepper_forces(polind.Stepper(model), t, x=x)
    stepper = polind.Stepper(model)
    forces = [stepper.force]
    for k in range(1, t.shape[0]):
        if k % 20 == 0:
            for bad in ({"t": float(t[k - 1]), "x": float(x[k])},
                        {"t": float(t[k]), "x": float("inf")},
                        {"t": float(t[k]), "v": float("nan")},
                        {"t": float(t[k]), "x": 1e308},
                        {"t": float(t[k]), "x": float(x[k]), "normal_load": -1.0}):
                with pytest.raises(polind.InputError):
                    stepper.advance(**bad)
        forces.append(stepper.advance(float(t[k]), x=float(x[k])))
    np.testing.assert_array_equal(forces, expected)


@pytest.mark.parametrize("bad, message", [
    ({"t": 0.0}, "after the current time"),                          # and no motion
    ({"t": 0.0, "x": "0.1"}, "after the current time"),              # and a motion not a number
    ({"t": 0.0, "x": 1.0, "normal_load": -1.0}, "after the current time"),
    ({"t": 1.0, "x": float("nan"), "normal_load": -1.0}, "'x'"),
])
def test_the_time_then_the_motion_then_the_load_is_named(bad, message):
    stepper = polind.Stepper(lib(ALL["pol-ind"]))
    with pytest.raises(polind.InputError, match=message):
        stepper.advance(**bad)


# --- NumPy scalars and ints: the forces of floats, and the same refusals (issue 38) --------

def _scalar_models():
    compliant = {**ALL["lugre"], "compliance": {"stiffness": 2e5}}     # a mounted contact
    return {"lugre": ALL["lugre"], "maxwell-slip": ALL["maxwell-slip"],
            "pol-ind": ALL["pol-ind"], "compliance": compliant}


# Each kind turns a float sample into an argument, and that argument into the float it means.
_KINDS = {
    "np.float64": (np.float64, float),
    "np.float32": (np.float32, lambda value: float(np.float32(value))),
    "np.longdouble": (np.longdouble, lambda value: float(np.longdouble(value))),
    "np.int64": (lambda value: np.int64(round(value)), lambda value: float(round(value))),
    "int": (lambda value: int(round(value)), lambda value: float(round(value))),
}


def _samples(kind, model_type, n=120):
    """``(t, x, v, load)`` of a path in units an integer kind can carry (ms, µm, N)."""
    integer = kind in ("np.int64", "int")
    k = np.arange(1, n)
    t = k * (1.0 if integer else 1e-3)               # s (an integer kind: 1 s steps)
    x = np.round(3.0 * np.sin(0.2 * k)) if integer else 2e-6 * np.sin(0.2 * k)
    v = np.round(2.0 * np.cos(0.3 * k)) if integer else 1e-3 * np.cos(0.3 * k)
    load = np.round(90.0 + 5.0 * np.sin(0.1 * k))   # N, within the Pol-Ind table
    if integer and model_type in ("pol-ind", "maxwell-slip"):
        x, v = x * 1e-6, v * 1e-6      # µm: an integer kind then gives the time and load only
    return t, x, v, load


@pytest.mark.parametrize("kind", list(_KINDS))
@pytest.mark.parametrize("model_type", list(_scalar_models()))
def test_numpy_scalars_and_ints_give_the_forces_of_floats(model_type, kind):
    """Stepper (by x, by v, with a load) and Body fed NumPy scalars or ints give, bit for bit,
    the forces of the same values as floats."""
    make, meaning = _KINDS[kind]
    model = lib(_scalar_models()[model_type])
    t, x, v, load = _samples(kind, model_type)
    integer_motion = kind in ("np.int64", "int") and model_type in ("pol-ind", "maxwell-slip")
    loaded = model_type == "pol-ind"

    def run(convert, motion_convert):
        by_x, by_v, body = polind.Stepper(model), polind.Stepper(model), polind.Body(model)
        out = []
        for k in range(t.shape[0]):
            extra = {"normal_load": convert(load[k])} if loaded else {}
            out.append(by_x.advance(convert(t[k]), x=motion_convert(x[k]), **extra))
            out.append(by_v.advance(convert(t[k]), v=motion_convert(v[k]), **extra))
            out.extend(body.step(convert(100.0 * x[k] / max(np.max(np.abs(x)), 1e-300)),
                                 **extra))
        return np.array(out), by_x.state.variables, body.state.variables

    motion = float if integer_motion else make
    motion_meaning = float if integer_motion else meaning
    got, got_state, got_body = run(make, motion)
    expected, state, body = run(meaning, motion_meaning)
    np.testing.assert_array_equal(got, expected)
    for key in state:
        np.testing.assert_array_equal(got_state[key], state[key])
    np.testing.assert_array_equal(got_body["body"], body["body"])


def test_the_elements_of_arrays_give_the_forces_of_floats_and_of_simulate():
    """What the shipped examples pass: ``advance(t[k], x=x[k])`` (np.float64), as they are."""
    model = lib(ALL["pol-ind"])
    t, x = _path("pol-ind", 4)
    res = polind.simulate(model, t, x=x)
    stepper = polind.Stepper(model, velocity=res.v[0])
    forces = [stepper.force] + [stepper.advance(t[k], x=x[k]) for k in range(1, t.shape[0])]
    np.testing.assert_array_equal(forces, _stepper_forces(
        polind.Stepper(model, velocity=float(res.v[0])), t, x=x))
    assert_close(forces, res.force, 1e-12, float(np.max(np.abs(res.force))), "np.float64")


_NAN64, _INF32 = np.float64("nan"), np.float32("inf")


@pytest.mark.parametrize("bad, message", [
    # what check_number names, whatever the type the fast path takes a number as
    ({"t": _NAN64, "x": 0.0}, r"'t' parameter of Stepper.advance must be finite\. Got "
                              r"nan instead"),            # the number, not np.float64(nan)
    ({"t": np.longdouble("1e400"), "x": 0.0}, "'t' parameter of Stepper.advance must be finite"),
    ({"t": 1.0, "x": _INF32}, r"'x' parameter of Stepper.advance must be finite\. Got "
                              r"inf instead"),
    ({"t": 1.0, "v": _NAN64}, "'v' parameter of Stepper.advance must be finite"),
    ({"t": 1.0, "x": 10 ** 400}, "'x' parameter of Stepper.advance must be a finite number of "
                                 "double precision"),
    ({"t": 10 ** 400, "x": 0.0}, "'t' parameter of Stepper.advance must be a finite number"),
    ({"t": np.float64(1.0), "x": True}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.bool_(True)}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": np.True_, "x": 0.0}, "'t' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.array(0.1)}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.array([0.1])}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": np.array(1.0), "x": 0.1}, "'t' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.zeros(3)}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.complex128(1.0)}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.str_("0.1")}, "'x' parameter of Stepper.advance must be a number"),
    ({"t": 1.0, "x": np.float64(1.0), "v": np.float64(0.0)}, "exactly one"),
    ({"t": np.float64(1.0)}, "exactly one"),
    ({"t": np.float64(1e-10), "x": np.float64(1e308)}, "finite step velocity"),
    # the time, then the motion, then the load, whatever the types
    ({"t": np.float64(0.0), "x": np.float64(1.0), "normal_load": -1.0}, "after the current"),
    ({"t": 0, "x": 0, "normal_load": np.float64(-1.0)}, "after the current time"),
    ({"t": np.int64(1), "x": np.float64("nan"), "normal_load": np.float32(-1.0)},
     r"'x' parameter of Stepper.advance must be finite\. Got nan instead"),
    ({"t": 1.0, "x": np.float64(0.0), "normal_load": np.float64(-10.0)},
     "'normal_load' parameter of Stepper must be positive"),
    ({"t": 1.0, "x": 0.0, "normal_load": np.float32("nan")},
     "'normal_load' parameter of Stepper must be finite"),
    ({"t": 1.0, "x": 0.0, "normal_load": np.array(90.0)},
     "'normal_load' parameter of Stepper must be a number"),
    ({"t": 1.0, "x": 0.0, "normal_load": np.float64(200.0)}, "table was built for at most"),
])
@pytest.mark.parametrize("model_type", ["pol-ind", "compliance"])
def test_numpy_scalars_are_refused_as_floats_are(model_type, bad, message):
    if model_type == "compliance" and "table was built" in message:
        pytest.skip("a load bound of the Pol-Ind table")
    stepper = polind.Stepper(lib(_scalar_models()[model_type]))
    with pytest.raises(polind.InputError, match=message):
        stepper.advance(**bad)
    assert (stepper.time, stepper.position, stepper.force) == (0.0, 0.0, 0.0)


def test_a_bad_numpy_sample_is_named_before_a_load_warning():
    """A model that ignores a load warns at its first load; a bad time or motion given as a
    NumPy scalar is named before, as a float's check did, and the warning then comes once."""
    stepper = polind.Stepper(lib(ALL["lugre"]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(polind.InputError, match="'x' parameter of Stepper.advance"):
            stepper.advance(np.float64(1.0), x=np.float64("nan"), normal_load=np.float64(5.0))
        with pytest.raises(polind.InputError, match="after the current time"):
            stepper.advance(np.float64(0.0), x=np.float64(0.0), normal_load=5.0)
    with pytest.warns(UserWarning, match="ignores the normal-load signal"):
        stepper.advance(np.float64(1.0), x=np.float64(1e-6), normal_load=np.float64(5.0))


@pytest.mark.parametrize("force, message", [
    (np.float64("nan"), r"'applied_force' parameter of Body.step must be finite\. Got "
                        r"nan instead"),
    (np.float32("-inf"), "'applied_force' parameter of Body.step must be finite"),
    (np.longdouble("1e400"), "'applied_force' parameter of Body.step must be finite"),
    (10 ** 400, "'applied_force' parameter of Body.step must be a finite number"),
    (np.bool_(True), "'applied_force' parameter of Body.step must be a number"),
    (np.array(1.0), "'applied_force' parameter of Body.step must be a number"),
    (np.array([1.0]), "'applied_force' parameter of Body.step must be a number"),
    (np.complex64(1.0), "'applied_force' parameter of Body.step must be a number"),
])
@pytest.mark.parametrize("load", [None, np.float64(90.0), np.float64(-1.0)])
@pytest.mark.parametrize("model_type", ["pol-ind", "compliance"])
def test_a_body_refuses_bad_numpy_forces_as_before(model_type, load, force, message):
    body = polind.Body(lib(_scalar_models()[model_type]))
    body.step(np.float64(1.0))
    before = (body.time, body.position, body.velocity, body.friction)
    extra = {} if load is None else {"normal_load": load}
    with pytest.raises(polind.InputError, match=message):
        body.step(force, **extra)               # the force is named first, beside a bad load
    assert (body.time, body.position, body.velocity, body.friction) == before
