"""polind.control.friction_system against simulate, for every model type (INTERFACE.md).

A friction model as a discrete-time python-control system, driven by
``control.input_output_response``, gives ``simulate``'s forces on the same
samples to 1e-12 relative: position and velocity inputs, random smooth
paths (seeded), Pol-Ind under its own load and under a varying one, a
response started from a saved state.  Then the state layout, the errors,
and the optional import.
"""

from __future__ import annotations

import copy
import importlib
import subprocess
import sys

import numpy as np
import pytest

control = pytest.importorskip("control")

import polind  # noqa: E402
from polind.control import (CARRIED_STATES, friction_system, initial_state,  # noqa: E402
                            state_names)
from polind.models.pol_ind import default_table  # noqa: E402

from conftest import REPRESENTATIVE, assert_close, lib  # noqa: E402

DT = 1e-3
N = 200


def _pol_ind_small():
    table = default_table()
    table["discretisation"]["elements"] = 8
    return table


ALL = {**copy.deepcopy(REPRESENTATIVE), "pol-ind": _pol_ind_small()}


def test_every_model_type_of_polind_is_covered():
    # (other test modules register models of their own: only polind's count here)
    own = {name for name, cls in polind.MODEL_TYPES.items()
           if cls.__module__.startswith("polind.")}
    assert own == set(ALL)


def _times(n=N):
    return DT * np.arange(n)


def _smooth(rng, t, amplitude):
    """A sum of a few sines of random frequency (2-25 Hz) and phase: reversals, sliding."""
    signal = np.zeros_like(t)
    for _ in range(4):
        frequency = rng.uniform(2.0, 25.0)
        signal += rng.uniform(0.2, 1.0) * np.sin(2 * np.pi * frequency * t
                                                 + rng.uniform(0, 2 * np.pi))
    return amplitude * signal


def _amplitude(model_type):
    # Pol-Ind's elements are stiffer: a smaller motion still slides.
    return 2e-6 if model_type == "pol-ind" else 5e-5


def _respond(system, t, motion, x0, load=None):
    """``input_output_response``; a model with a load input gets its own 100 N by default."""
    if system.ninputs == 2:
        load = np.full_like(motion, 100.0) if load is None else load
        return control.input_output_response(system, t, np.vstack([motion, load]), x0)
    return control.input_output_response(system, t, motion, x0)


def _force(resp):
    return np.asarray(resp.outputs, dtype=float).reshape(-1)


def _scale(force):
    return max(float(np.max(np.abs(force))), 1e-300)


@pytest.mark.parametrize("model_type", list(ALL))
def test_position_input_equals_simulate(model_type):
    model = lib(ALL[model_type])
    rng = np.random.default_rng(11)
    t = _times()
    x = _smooth(rng, t, _amplitude(model_type))
    res = polind.simulate(model, t, x=x)
    system = friction_system(model, DT)
    force = _force(_respond(system, t, x, initial_state(model)))
    scale = _scale(res.force)
    # sample 0: simulate reports the first step's velocity, unknown to a causal system
    assert_close(force[1:], res.force[1:], 1e-12, scale, f"{model_type} x")
    # ... and the force at rest at 0 velocity there
    kernel = model.step_kernel()
    assert force[0] == kernel.force(kernel.scalars, kernel.table, kernel.state, 0.0,
                                    kernel.normal_load)
    # told the first step's velocity, every sample is simulate's
    told = initial_state(model, velocity=(x[1] - x[0]) / DT)
    force = _force(_respond(system, t, x, told))
    assert_close(force, res.force, 1e-12, scale, f"{model_type} x, v0 given")


@pytest.mark.parametrize("model_type", list(ALL))
def test_velocity_input_equals_simulate_from_sample_0(model_type):
    model = lib(ALL[model_type])
    rng = np.random.default_rng(12)
    t = _times()
    v = _smooth(rng, t, 60 * _amplitude(model_type))
    res = polind.simulate(model, t, v=v)
    system = friction_system(model, DT, input="v")
    resp = _respond(system, t, v, initial_state(model))
    assert_close(_force(resp), res.force, 1e-12, _scale(res.force), f"{model_type} v")
    # the carried position is simulate's trapezoidal integral
    position = resp.states[state_names(model).index("position")]
    np.testing.assert_allclose(position[1:], res.x[:-1], rtol=0.0,
                               atol=1e-12 * float(np.max(np.abs(res.x))))


@pytest.mark.parametrize("input_name", ["x", "v"])
@pytest.mark.parametrize("model_type", list(ALL))
def test_final_state_is_simulates(model_type, input_name):
    model = lib(ALL[model_type])
    rng = np.random.default_rng(13)
    t = _times()
    motion = _smooth(rng, t, _amplitude(model_type) * (60 if input_name == "v" else 1))
    res = polind.simulate(model, t, **{input_name: motion})
    system = friction_system(model, DT, input=input_name)
    resp = _respond(system, t, motion, initial_state(model))
    load = [] if system.ninputs == 1 else [100.0]
    # states[:, k] is the state before sample k: one more update reaches the end
    final = system.dynamics(t[-1], resp.states[:, -1], [motion[-1], *load])
    size = model.flat_state(res.final_state).shape[0]
    expected = model.flat_state(res.final_state)
    np.testing.assert_allclose(final[:size], expected, rtol=1e-12,
                               atol=1e-12 * max(np.max(np.abs(expected), initial=0.0), 1.0))
    carried = [res.final_state.position, res.final_state.velocity, 1.0]
    np.testing.assert_allclose(final[size:], carried, rtol=1e-12,
                               atol=1e-12 * float(np.max(np.abs(res.x))))


@pytest.mark.parametrize("input_name", ["x", "v"])
def test_pol_ind_under_a_varying_load_equals_simulate(input_name):
    model = lib(ALL["pol-ind"])
    rng = np.random.default_rng(14)
    t = _times()
    motion = _smooth(rng, t, _amplitude("pol-ind") * (60 if input_name == "v" else 1))
    # 50-100 N, 100 N (the model's own load, which its table is built for) at sample 0
    load = 75.0 + 25.0 * np.cos(2 * np.pi * rng.uniform(5.0, 15.0) * t)
    assert load[0] == 100.0 and load.min() < 55.0
    res = polind.simulate(model, t, normal_load=load, **{input_name: motion})
    system = friction_system(model, DT, input=input_name, normal_load=True)
    x0 = initial_state(model) if input_name == "v" else \
        initial_state(model, velocity=(motion[1] - motion[0]) / DT)
    first = _force(_respond(system, t, motion, x0, load))
    assert_close(first, res.force, 1e-12, _scale(res.force), f"pol-ind N(t), {input_name}")
    # a second response from the same X0 is the same (the system is a pure function)
    again = _force(_respond(system, t, motion, x0, load))
    np.testing.assert_array_equal(again, first)
    # and the load matters
    constant = polind.simulate(model, t, **{input_name: motion}).force
    assert np.max(np.abs(constant - res.force)) > 1e-3 * _scale(res.force)


@pytest.mark.parametrize("model_type", list(ALL))
def test_a_response_continues_a_saved_state(model_type):
    model = lib(ALL[model_type])
    rng = np.random.default_rng(15)
    t = _times(2 * N)
    x = _smooth(rng, t, _amplitude(model_type))
    first = polind.simulate(model, t[:N], x=x[:N])
    state = polind.State.from_json(first.final_state.to_json())
    rest = polind.simulate(model, t[N - 1:], x=x[N - 1:], state=state)
    system = friction_system(model, DT)
    # the state's sample precedes the response's first one
    force = _force(_respond(system, t[N:], x[N:], initial_state(model, state)))
    assert_close(force, rest.force[1:], 1e-12, _scale(rest.force), f"{model_type} continued")


def test_names_and_layout():
    model = lib(ALL["pol-ind"])
    system = friction_system(model, DT, name="contact")
    assert system.name == "contact"
    assert system.isdtime(strict=True) and system.dt == DT
    assert system.input_labels == ["x"]       # the model's own load unless asked for
    assert friction_system(model, DT, normal_load=True).input_labels == ["x", "normal_load"]
    assert system.output_labels == ["F"]
    names = state_names(model)
    assert system.state_labels == names
    assert names[:2] == ["element_force[0]", "element_force[1]"]
    assert names[-4:] == ["table_load[0]", *CARRIED_STATES]
    x0 = initial_state(model)
    assert x0.shape == (len(names),) and x0.dtype == np.float64
    assert x0[-3:].tolist() == [0.0, 0.0, 0.0]

    dahl = lib(ALL["dahl"])
    system = friction_system(dahl, 0.5, input="v")
    assert system.input_labels == ["v"]
    assert system.state_labels == ["friction[0]", *CARRIED_STATES]
    assert initial_state(dahl, position=2.0, velocity=3.0)[-3:].tolist() == [2.0, 3.0, 0.0]
    saved = polind.simulate(dahl, [0.0, 1.0], x=[0.0, 1e-6]).final_state
    assert initial_state(dahl, saved)[-3:].tolist() == [1e-6, 1e-6, 1.0]


@pytest.mark.parametrize("dt", [0.0, -1e-3, float("nan"), float("inf"), "1e-3", True, None])
def test_friction_system_refuses_a_bad_dt(dt):
    with pytest.raises(polind.InputError, match="'dt'"):
        friction_system(lib(ALL["lugre"]), dt)


@pytest.mark.parametrize("bad", ["y", "X", "", None, 1])
def test_friction_system_refuses_a_bad_input(bad):
    with pytest.raises(polind.InputError, match="'input'"):
        friction_system(lib(ALL["lugre"]), DT, input=bad)


@pytest.mark.parametrize("model_type", ["lugre", "dahl", "coulomb"])
def test_a_load_input_for_a_model_that_uses_none_is_refused(model_type):
    model = lib(ALL[model_type])
    assert not model.uses_normal_load
    with pytest.raises(polind.InputError, match="'normal_load'.*does not use a normal load"):
        friction_system(model, DT, normal_load=True)
    # with a reference load it does use one
    loaded = lib({**ALL[model_type], "reference_load": 50.0})
    assert friction_system(loaded, DT, normal_load=True).input_labels == ["x", "normal_load"]


@pytest.mark.parametrize("flag", [1, "yes", None, 0.0])
def test_normal_load_must_be_true_or_false(flag):
    with pytest.raises(polind.InputError, match="'normal_load' of friction_system must be True"):
        friction_system(lib(ALL["pol-ind"]), DT, normal_load=flag)


def test_pol_ind_without_a_load_input_runs_at_its_own_load():
    # Issue 23: left unconnected, the load input failed deep inside python-control.
    model = lib(ALL["pol-ind"])
    t = _times(50)
    x = 1e-6 * np.sin(2 * np.pi * 10.0 * t)
    system = friction_system(model, DT)
    assert system.input_labels == ["x"]
    force = _force(control.input_output_response(
        system, t, x, initial_state(model, velocity=(x[1] - x[0]) / DT)))
    res = polind.simulate(model, t, x=x)
    assert_close(force, res.force, 1e-12, _scale(res.force), "pol-ind at its own load")


def test_friction_system_and_initial_state_refuse_a_non_model():
    with pytest.raises(polind.InputError, match="friction model"):
        friction_system({"type": "lugre"}, DT)
    with pytest.raises(polind.InputError, match="friction model"):
        initial_state("lugre")


def test_initial_state_refuses_bad_arguments():
    model = lib(ALL["gms"])
    with pytest.raises(polind.InputError, match="not both"):
        initial_state(model, model.initial_state(), position=1.0)
    with pytest.raises(polind.InputError, match="polind State"):
        initial_state(model, {"type": "gms"})
    with pytest.raises(polind.InputError, match="maxwell-slip"):
        initial_state(model, lib(ALL["maxwell-slip"]).initial_state())
    with pytest.raises(polind.InputError, match="'velocity'"):
        initial_state(model, velocity=float("nan"))


def test_a_response_refuses_bad_samples():
    model = lib(ALL["pol-ind"])
    system = friction_system(model, DT, normal_load=True)
    t = _times(5)
    x = np.zeros(5)
    x0 = initial_state(model)
    with pytest.raises(polind.InputError, match="table was built for at most"):
        _respond(system, t, x, x0, np.full(5, 200.0))
    with pytest.raises(polind.InputError, match="positive"):
        _respond(system, t, x, x0, np.full(5, -1.0))
    bad = x.copy()
    bad[3] = np.nan
    with pytest.raises(polind.InputError, match="'x' input"):
        _respond(system, t, bad, x0, np.full(5, 100.0))
    with pytest.raises(polind.InputError, match="'v' input"):
        _respond(friction_system(lib(ALL["dahl"]), DT, input="v"), t, bad,
                 initial_state(lib(ALL["dahl"])))


def test_without_python_control_the_import_says_how_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "control", None)    # `import control` fails
    monkeypatch.delitem(sys.modules, "polind.control")
    with pytest.raises(ImportError, match=r"pip install polind\[control\]"):
        importlib.import_module("polind.control")


def test_import_polind_does_not_import_python_control():
    code = ("import sys, polind; print(sorted(m for m in sys.modules "
            "if m.split('.')[0] == 'control' or m == 'polind.control'))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize("input_name", ["x", "v"])
@pytest.mark.parametrize("model_type, mount", [
    ("gms", {"compliance": {"stiffness": 3e4}}),
    ("lugre", {"reference_load": 80.0}),
    ("stribeck", {"reference_load": 80.0, "compliance": {"stiffness": 2e4}}),
])
def test_a_mounted_model_equals_simulate(model_type, mount, input_name):
    model = lib({**ALL[model_type], **mount})
    rng = np.random.default_rng(15)
    t = _times()
    motion = _smooth(rng, t, _amplitude(model_type) * (60 if input_name == "v" else 1))
    load = 100.0 + 25.0 * np.cos(2 * np.pi * 7.0 * t)
    uses_load = model.uses_normal_load
    res = polind.simulate(model, t, normal_load=load if uses_load else None,
                          **{input_name: motion})
    system = friction_system(model, DT, input=input_name, normal_load=uses_load)
    assert system.ninputs == (2 if uses_load else 1)
    names = state_names(model)
    assert names[-6:-3] == ["spring_force", "contact_position", "contact_velocity"]
    x0 = initial_state(model) if input_name == "v" else \
        initial_state(model, velocity=(motion[1] - motion[0]) / DT)
    force = _force(_respond(system, t, motion, x0, load))
    first = 1 if model.series_stiffness == np.inf else 0
    assert_close(force[first:], res.force[first:], 1e-12, _scale(res.force),
                 f"{model_type} mounted, {input_name}")


# ---------------------------------------------------------------------------
# body_system: the mass and its contact as one system (Body's implicit step)
# ---------------------------------------------------------------------------

from polind.control import (BODY_STATES, MOUNT_STATES, body_state_names,  # noqa: E402
                            body_system, contact_stiffness, linearize)
from polind.models import GMS, Dahl, Leuven, LuGre, MaxwellSlip, PolInd  # noqa: E402

MASS = 1.0
#: (set point [m], Kp [N/m], Kd [N s/m]) of a 1 kHz PD loop that breaks the body away,
#: slides it and sticks it short of the set point (the PD force falls below break-away).
PD_GAINS = {"pol-ind": (1e-3, 1e5, 6e2), "lugre": (1e-3, 1e4, 2e2)}
EXAMPLES = {"pol-ind": PolInd.example, "lugre": LuGre.example}


def _pd(setpoint, kp, kd):
    """The controller, one expression for both loops (so the forces are the same floats)."""
    return lambda x, v: kp * (setpoint - x) - kd * v


def _body_loop(model, controller, steps, dt=DT, **body_args):
    """``body.step(controller(body.position, body.velocity))``: rows x, v, F at each sample."""
    body = polind.Body(model, mass=MASS, time_step=dt, **body_args)
    out = np.empty((3, steps))
    for k in range(steps):
        out[:, k] = body.position, body.velocity, body.friction
        body.step(controller(body.position, body.velocity))
    return out


def _closed_loop(plant, controller, steps, dt=DT):
    """The same loop in python-control: ``interconnect`` of the plant and a static controller."""
    pd = control.nlsys(None, lambda t, x, u, params: [controller(u[0], u[1])],
                       inputs=["x", "v"], outputs=["u"], dt=dt, name="pd")
    loop = control.interconnect([plant, pd], inplist=[], outlist=["body.x", "body.v", "body.F"])
    resp = control.input_output_response(loop, dt * np.arange(steps), 0.0, plant.initial_state)
    return np.asarray(resp.outputs, dtype=float)


@pytest.mark.parametrize("model_type", list(EXAMPLES))
def test_a_pd_loop_around_body_system_equals_the_loop_around_body(model_type):
    model = EXAMPLES[model_type]()
    controller = _pd(*PD_GAINS[model_type])
    steps = 1500
    expected = _body_loop(model, controller, steps)
    got = _closed_loop(body_system(model, MASS, DT, name="body"), controller, steps)
    for row, label in enumerate("xvF"):
        assert_close(got[row], expected[row], 1e-12, _scale(expected[row]), f"{model_type} {label}")
    # the loop is worth comparing: the body broke away, slid and stuck short of the set point
    x, v = expected[0], expected[1]
    assert np.max(np.abs(v)) > 1e-2
    assert np.all(v[-200:] == 0.0) and np.all(x[-200:] == x[-1])
    assert 0.5e-3 < x[-1] < PD_GAINS[model_type][0]


@pytest.mark.parametrize("case", ["euler", "started", "gms behind a spring", "stribeck",
                                  "lugre under a load", "pol-ind under a load"])
def test_a_response_to_forces_equals_body_steps(case):
    rng = np.random.default_rng(21)
    steps = 300
    load = None
    start = {}
    method = "bdf2"
    if case == "euler":
        model, method = LuGre.example(), "euler"
    elif case == "started":
        model = GMS.example()
        saved = polind.simulate(model, [0.0, 0.5, 1.0], x=[0.0, 3e-5, 1e-5]).final_state
        start = {"position": 2e-3, "velocity": -1e-3, "state": saved}
    elif case == "gms behind a spring":
        model = lib({**ALL["gms"], "compliance": {"stiffness": 3e4}})
    elif case == "stribeck":
        model = lib(ALL["stribeck"])
    elif case == "lugre under a load":
        model = lib({**ALL["lugre"], "reference_load": 80.0})
        load = 80.0 + 30.0 * np.sin(2 * np.pi * 7.0 * DT * np.arange(steps))
    else:                     # its contact mechanics at 50-100 N (at most its own load)
        model = PolInd.example()
        load = 75.0 + 25.0 * np.cos(2 * np.pi * 6.0 * DT * np.arange(steps))
    scale = model.characteristic_scales()["static_force"]
    forces = scale * (1.5 * np.sin(2 * np.pi * 4.0 * DT * np.arange(steps))
                      + 0.3 * rng.standard_normal(steps))
    body = polind.Body(model, MASS, DT, method=method, **start)
    expected = np.empty((3, steps))
    for k in range(steps):
        expected[:, k] = body.position, body.velocity, body.friction
        body.step(float(forces[k]), None if load is None else float(load[k]))
    system = body_system(model, MASS, DT, method=method, normal_load=load is not None, **start)
    inputs = forces if load is None else np.vstack([forces, load])
    resp = control.input_output_response(system, DT * np.arange(steps), inputs,
                                         system.initial_state)
    got = np.asarray(resp.outputs, dtype=float)
    for row, label in enumerate("xvF"):
        assert_close(got[row], expected[row], 1e-12, _scale(expected[row]), f"{case} {label}")
    # the state carries the body's time: start_time + steps * dt
    names = system.state_labels
    final = system.dynamics(0.0, resp.states[:, -1], inputs[..., -1])
    assert final[names.index("steps")] == steps
    assert final[names.index("start_time")] + steps * DT == pytest.approx(body.time, abs=1e-15)
    np.testing.assert_array_equal(final[:model.flat_state(body.state).shape[0]],
                                  model.flat_state(body.state))


def test_body_system_layout_and_strictly_proper_outputs():
    model = lib(ALL["lugre"])
    system = body_system(model, 2.0, 0.01, position=1e-3, velocity=0.5, name="body")
    assert system.name == "body" and system.isdtime(strict=True) and system.dt == 0.01
    assert system.input_labels == ["u"] and system.output_labels == ["x", "v", "F"]
    assert system.state_labels == body_state_names(model)
    assert system.state_labels == ["deflection[0]", *BODY_STATES]
    x0 = system.initial_state
    body = polind.Body(model, 2.0, 0.01, position=1e-3, velocity=0.5)
    # sample 0 is the body before any step, whatever the input
    for u in (0.0, 5.0, -1e3):
        assert system.output(0.0, x0, [u]).tolist() == [body.position, body.velocity,
                                                        body.friction]
    # the update is a pure function of (state, input): two inputs from one state
    first = system.dynamics(0.0, x0, [3.0])
    second = system.dynamics(0.0, x0, [-3.0])
    np.testing.assert_array_equal(system.dynamics(0.0, x0, [3.0]), first)
    body.step(-3.0)
    assert system.output(0.01, second, [0.0]).tolist() == [body.position, body.velocity,
                                                           body.friction]
    assert not np.array_equal(first, second)
    # a mounted model carries the mount's states; a load input only when asked for
    mounted = lib({**ALL["gms"], "reference_load": 10.0})
    names = body_state_names(mounted)
    assert names[-len(BODY_STATES) - 3:-len(BODY_STATES)] == list(MOUNT_STATES)
    assert body_system(mounted, 1.0, DT).input_labels == ["u"]
    assert body_system(mounted, 1.0, DT, normal_load=True).input_labels == ["u", "normal_load"]


@pytest.mark.parametrize("model_type", ["pol-ind", "lugre", "gms"])
def test_the_state_vector_alone_continues_the_run(model_type):
    # A second system, which never saw the first one's states, continues from the state
    # vector of sample 200 (BDF2 history included; its kernel rebuilt from the state).
    model = lib(ALL[model_type])
    steps, middle = 400, 200
    forces = model.characteristic_scales()["static_force"] * 1.3 * np.sin(
        2 * np.pi * 3.0 * DT * np.arange(steps))
    first = body_system(model, MASS, DT)
    whole = control.input_output_response(first, DT * np.arange(steps), forces,
                                          first.initial_state)
    second = body_system(model, MASS, DT)
    rest = control.input_output_response(second, DT * np.arange(middle, steps),
                                         forces[middle:], whole.states[:, middle])
    np.testing.assert_array_equal(rest.outputs, whole.outputs[:, middle:])
    assert np.max(np.abs(whole.outputs[1])) > 0.0        # it moved


@pytest.mark.parametrize("argument, value, match", [
    ("mass", 0.0, "'mass'"), ("mass", "1", "'mass'"), ("dt", -1.0, "'dt'"),
    ("method", "rk4", "'method'"), ("position", float("nan"), "'position'"),
    ("normal_load", True, "'normal_load'.*does not use"), ("normal_load", "no", "'normal_load'"),
    ("state", {"z": 0.0}, "polind State"),
])
def test_body_system_refuses_bad_arguments(argument, value, match):
    arguments = {"mass": 1.0, "dt": DT, argument: value}
    with pytest.raises(polind.InputError, match=match):
        body_system(lib(ALL["lugre"]), **arguments)


@pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning")   # python-control's
def test_body_system_refuses_a_bad_input_sample():
    system = body_system(lib(ALL["lugre"]), 1.0, DT)
    with pytest.raises(polind.InputError, match="'u' input of body_system"):
        control.input_output_response(system, DT * np.arange(3), [0.0, np.inf, 0.0],
                                      system.initial_state)
    with pytest.raises(polind.InputError, match="friction model"):
        body_system("lugre", 1.0, DT)


def test_explicit_coupling_chatters_where_body_system_holds_still():
    # The guide's stability rule: friction_system fed a separate mass (semi-implicit Euler
    # of m a = u - F) is an explicit spring, unstable for dt > 2 sqrt(m / k).
    model = PolInd.example()
    stiffness = model.characteristic_scales()["presliding_stiffness"]
    limit = 2.0 * np.sqrt(MASS / stiffness)
    assert 5e-5 < limit < 1e-4                      # 80 us: any usual control rate is above
    controller = _pd(*PD_GAINS["pol-ind"])
    steps = 1500
    mass = control.ss([[1.0, DT], [0.0, 1.0]], [[DT * DT / MASS], [DT / MASS]],
                      np.eye(2), np.zeros((2, 1)), dt=DT, inputs=["f"], outputs=["x", "v"],
                      name="mass")
    contact = friction_system(model, DT, name="contact")
    pd = control.nlsys(None, lambda t, x, u, params: [controller(u[0], u[1])],
                       inputs=["x", "v"], outputs=["u"], dt=DT, name="pd")
    net = control.summing_junction(inputs=["u", "-F"], output="f", dt=DT, name="net")
    loop = control.interconnect([mass, contact, pd, net], inplist=[],
                                outlist=["mass.x", "contact.F"])
    x0 = [np.zeros(2), initial_state(model)]
    explicit = control.input_output_response(loop, DT * np.arange(steps), 0.0, x0).outputs
    implicit = _body_loop(model, controller, steps)
    late = slice(steps - 100, steps)
    assert np.all(implicit[1, late] == 0.0)                     # stuck, still
    friction = explicit[1, late]
    assert np.count_nonzero(np.diff(np.sign(friction))) > 20    # chatters
    assert np.ptp(explicit[0, late]) > 1e-7


# ---------------------------------------------------------------------------
# linearize: the stuck body's two-state model
# ---------------------------------------------------------------------------

def _measured_stiffness(model, start=None, t0=0.0, x0=0.0):
    """The slope of F against x over a tiny slow displacement (1e-4 of the presliding range)."""
    travel = 1e-4 * model.characteristic_scales()["presliding_range"]
    t = t0 + np.linspace(0.0, 1.0, 101)
    res = polind.simulate(model, t, x=x0 + travel * (t - t0), state=start)
    return float(np.polyfit(res.x[1:], res.force[1:], 1)[0])


@pytest.mark.parametrize("cls", [PolInd, LuGre, GMS, MaxwellSlip, Dahl, Leuven],
                         ids=lambda cls: cls.type)
def test_the_natural_frequency_is_that_of_the_measured_presliding_stiffness(cls):
    model = cls.example()
    mass = 2.5
    system = linearize(model, mass)
    assert system.nstates == 2 and system.isctime()
    assert system.state_labels == ["x", "v"] and system.input_labels == ["u"]
    assert system.output_labels == ["x", "v", "F"]
    natural, _, _ = system.damp()
    measured = np.sqrt(_measured_stiffness(model) / mass)
    assert natural[0] == pytest.approx(measured, rel=0.01)
    # Pol-Ind: the stiffness its characteristic scales give (the sum of its elements)
    stiffness, _ = contact_stiffness(model)
    assert stiffness == pytest.approx(model.characteristic_scales()["presliding_stiffness"],
                                      rel=1e-12)


def test_lugre_damping_is_its_bristle_damping_and_viscous_term():
    model = LuGre.example()
    params = model.params
    stiffness, damping = contact_stiffness(model)
    assert stiffness == pytest.approx(params["bristle_stiffness"], rel=1e-12)
    assert damping == pytest.approx(params["bristle_damping"] + params["viscous_coefficient"],
                                    rel=1e-12)
    # measured: the force at one tiny displacement reached at two velocities
    t = np.linspace(0.0, 1e-3, 101)
    slow = polind.simulate(model, t, x=1e-6 * t).force[-1]            # 1 um/s
    fast = polind.simulate(model, t / 2, x=1e-6 * t).force[-1]        # 2 um/s
    assert (fast - slow) / 1e-6 == pytest.approx(damping, rel=0.01)
    _, zeta, _ = linearize(model, 1.0).damp()
    assert zeta[0] == pytest.approx(damping / (2.0 * np.sqrt(stiffness)), rel=1e-9)


def test_at_a_state_only_the_elements_that_stick_count():
    # Maxwell-slip pushed through half its presliding range: the soft elements have
    # slipped, and a further push meets only the stiff ones that still stick.
    model = MaxwellSlip.example()
    travel = 0.5 * model.characteristic_scales()["presliding_range"]
    res = polind.simulate(model, np.linspace(0.0, 1.0, 101), x=travel * np.linspace(0, 1, 101))
    state = res.final_state
    at_rest, _ = contact_stiffness(model)
    there, _ = contact_stiffness(model, state)
    assert there < 0.5 * at_rest
    assert there == pytest.approx(_measured_stiffness(model, state, 1.0, res.x[-1]), rel=0.01)
    natural, _, _ = linearize(model, 1.0, state=state).damp()
    assert natural[0] == pytest.approx(np.sqrt(there), rel=1e-12)


def test_a_series_spring_is_in_series_with_the_contact():
    spring = 3e4
    model = lib({**REPRESENTATIVE["gms"], "compliance": {"stiffness": spring}})
    contact, damping = contact_stiffness(lib(REPRESENTATIVE["gms"]))
    stiffness, seen = contact_stiffness(model)
    assert stiffness == pytest.approx(contact * spring / (contact + spring), rel=1e-12)
    assert seen == pytest.approx(damping * (spring / (contact + spring)) ** 2, rel=1e-12)
    assert stiffness == pytest.approx(_measured_stiffness(model), rel=0.01)
    # a memoryless contact behind a spring: the spring alone
    stribeck = lib({**REPRESENTATIVE["stribeck"], "compliance": {"stiffness": spring}})
    assert contact_stiffness(stribeck) == (spring, 0.0)


@pytest.mark.parametrize("model_type", ["coulomb", "stribeck"])
def test_a_memoryless_model_has_no_small_signal_model(model_type):
    with pytest.raises(polind.InputError, match="rigidly"):
        linearize(lib(REPRESENTATIVE[model_type]), 1.0)


def test_linearize_refuses_bad_arguments():
    model = LuGre.example()
    with pytest.raises(polind.InputError, match="'mass'"):
        linearize(model, 0.0)
    with pytest.raises(polind.InputError, match="friction model"):
        linearize("lugre", 1.0)
    with pytest.raises(polind.InputError, match="polind State"):
        linearize(model, 1.0, state={"z": 0.0})
