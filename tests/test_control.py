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
