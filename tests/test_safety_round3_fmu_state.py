"""Nothing lost, round three (issue 44): FMU errors, hand-edited states, NumPy scalars in messages.

* An error inside an FMU (a non-finite input, a communication step that is
  not a whole multiple of ``time_step``) used to return ``fmi2Discard`` with
  ``fmi2Terminated`` set, and FMPy's ``simulate_fmu`` stopped early without a
  word.  It now reaches the master as a failed call (at least ``fmi2Error``;
  PythonFMU 0.7.0's binary makes a raising call ``fmi2Fatal``) after a log
  message with status ``fmi2Error`` that names the input, its value and the
  step.
* A hand-edited state (a Body's ``"body"`` history with a step velocity of
  1e308) gave ``-inf`` without an error, and an unknown key was accepted:
  every model's state given to a model now passes one check
  (``State.check_entries``) that names the key.
* The lost-step message printed ``np.float64(...)``: messages format the
  numbers, not the NumPy scalars' repr.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import polind
from polind.errors import describe
from polind.models import MODEL_TYPES, LuGre, State

FMI_ERROR = 3        # fmi2Error (fmi2Fatal is 4)

#: The master, in its own Python (as tests/test_fmu.py's DRIVER, and for the same
#: reason: numba's libraries are loaded before the FMU's first call): FMPy's
#: simulate_fmu on a case, its outcome and the FMU's log messages.  One case per
#: process: PythonFMU 0.7.0 cannot instantiate a second FMU in a process that ran one.
MASTER = r'''
import json, sys
import numpy as np
import polind
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

spec = json.load(open(sys.argv[1]))
model = polind.model_from_dict(json.load(open(spec["model"])))
polind.Body(model).step(0.0)
polind.Stepper(model).advance(1e-3, x=1e-9)
out = {}
for name, case in spec["cases"].items():
    log = []
    def logger(environment, instance, status, category, message):
        log.append([int(status), message.decode()])
    options = dict(stop_time=0.01, output_interval=case["step"], step_size=case["step"],
                   logger=logger, debug_logging=True)
    if "input" in case:
        column, value = case["input"]
        options["input"] = np.array([(0.0, 0.0), (0.002, value), (0.01, value)],
                                    dtype=[("time", float), (column, float)])
    result = {"status": None, "rows": None}
    try:
        result["rows"] = len(simulate_fmu(case["fmu"], **options))
    except FMICallException as error:
        result["status"], result["error"] = int(error.status), str(error)
    result["log"] = log
    out[name] = result
json.dump(out, open(sys.argv[2], "w"))
'''


@pytest.fixture(scope="module")
def fmu_runs(tmp_path_factory):
    """The three failing runs, one master process each (the FMUs built once)."""
    pytest.importorskip("pythonfmu")
    pytest.importorskip("fmpy")
    from polind.fmu import build_fmu

    folder = tmp_path_factory.mktemp("fmu")
    model = LuGre.example()
    model_path = folder / "lugre.json"
    model_path.write_text(model.to_json())
    body = str(build_fmu(model, folder / "body.fmu", input="force", time_step=1e-3))
    position = str(build_fmu(model, folder / "position.fmu", input="x"))
    (folder / "master.py").write_text(MASTER)
    cases = {"step": {"fmu": body, "step": 1.5e-3},
             "force": {"fmu": body, "step": 1e-3, "input": ["force", math.nan]},
             "x": {"fmu": position, "step": 1e-3, "input": ["x", math.nan]}}
    runs = {}
    for name, case in cases.items():
        spec, out = folder / f"{name}.json", folder / f"{name}-out.json"
        spec.write_text(json.dumps({"model": str(model_path), "cases": {name: case}}))
        done = subprocess.run([sys.executable, str(folder / "master.py"), str(spec), str(out)],
                              capture_output=True, text=True, timeout=600,
                              env=os.environ.copy())
        assert done.returncode == 0, done.stderr[-3000:]
        runs.update(json.loads(out.read_text()))
    return runs


def _error_message(run):
    """The run failed (no silent early end) after one fmi2Error message from polind: its text."""
    assert run["status"] is not None and run["status"] >= FMI_ERROR, run
    messages = [text for status, text in run["log"] if status == FMI_ERROR
                and text.startswith("polind: ")]
    assert len(messages) == 1, run["log"]
    return messages[0]


def test_a_step_not_a_multiple_of_time_step_fails_naming_the_step(fmu_runs):
    run = fmu_runs["step"]
    assert "fmi2DoStep failed" in run["error"]
    message = _error_message(run)
    assert "whole multiple of its time_step 0.001 s" in message
    assert "Got 0.0015 s" in message and "from t = 0.0 s of 0.0015 s" in message


def test_a_nan_force_fails_naming_the_input_its_value_and_the_step(fmu_runs):
    run = fmu_runs["force"]
    assert "fmi2DoStep failed" in run["error"]
    message = _error_message(run)
    assert "input 'force'" in message and "Got nan" in message
    assert "in the communication step from t = 0.001 s of 0.001 s" in message


def test_a_nan_position_fails_naming_the_input_its_value_and_the_point(fmu_runs):
    run = fmu_runs["x"]
    assert "fmi2SetReal failed" in run["error"]       # refused where it is set
    message = _error_message(run)
    assert "input 'x'" in message and "Got nan" in message and "t = 0.001 s" in message


# --- states: one check for every model's state --------------------------------------------

@pytest.fixture(scope="module")
def body_states():
    """A Body's state after a few steps, as its JSON dict, for every registered model."""
    states = {}
    for name, cls in MODEL_TYPES.items():
        model = cls.example()
        body = polind.Body(model)
        for force in (0.3, -0.2, 0.1):
            body.step(force)
        states[name] = (model, body.state.to_dict())
    return states


@pytest.mark.parametrize("name", list(MODEL_TYPES))
def test_an_unknown_key_is_refused_naming_it_and_the_keys_expected(body_states, name):
    model, saved = body_states[name]
    edited = dict(saved, frcition=[0.0])          # a misspelt key of an edited state file
    state = State.from_dict(edited)
    for build in (lambda: polind.Body(model, state=state),
                  lambda: polind.Stepper(model, state=state)):
        with pytest.raises(polind.InputError, match="entry 'frcition'") as error:
            build()
        expected = str(error.value).split("expected its keys: ")[1]
        assert set(expected.rstrip(".").split(", ")) == set(saved)
    polind.Body(model, state=State.from_dict(saved))       # the unedited state continues


def test_simulate_refuses_an_unknown_key_too(body_states):
    model, saved = body_states["dahl"]
    state = State.from_dict(dict(saved, extra=[1.0]))
    t = state.time + np.array([0.0, 1e-3])
    with pytest.raises(polind.InputError, match="entry 'extra'"):
        polind.simulate(model, t, x=np.array([state.position, state.position]), state=state)


@settings(max_examples=12, deadline=None)
@given(index=st.integers(0, 10), size=st.floats(1.0001e100, 1.7e308),
       sign=st.sampled_from([1.0, -1.0]))
def test_an_overflowing_body_history_is_refused_naming_the_key(body_states, index, size, sign):
    # The issue's case: the step velocity (index 5) at 1e308 gave a friction of -inf.
    model, saved = body_states["lugre"]
    edited = json.loads(json.dumps(saved))
    edited["body"][index] = sign * size
    with pytest.raises(polind.InputError, match=rf"'body' entry .* Got .* at index {index} "):
        State.from_json(json.dumps(edited))
    # the same number written into a State in Python is refused when a Body is given it
    state = State.from_dict(saved)
    state.variables["body"][index] = sign * size
    with pytest.raises(polind.InputError, match=rf"'body' entry .* at index {index} "):
        polind.Body(model, state=state)


@pytest.mark.parametrize("key", ["time", "position", "velocity", "force", "deflection"])
def test_an_overflowing_entry_is_refused_naming_it(body_states, key):
    model, saved = body_states["lugre"]
    edited = dict(saved)
    edited[key] = [1e308] if isinstance(saved[key], list) else 1e308
    with pytest.raises(polind.InputError, match=f"The '{key}' entry of a state"):
        State.from_dict(edited)
    state = State.from_dict(saved)
    if key in state.variables:
        state.variables[key] = np.array([-1e200])
    else:
        setattr(state, key, np.float64(-1e200))
    with pytest.raises(polind.InputError, match=f"The '{key}' entry .* Got -1e\\+200 instead"):
        polind.Stepper(model, state=state)


def test_the_issue_state_no_longer_steps_to_minus_infinity(body_states):
    model, saved = body_states["lugre"]
    edited = json.loads(json.dumps(saved))
    edited["body"][5] = 1e308                 # polind.stepper.HISTORY: the step velocity
    with pytest.raises(polind.InputError, match="at most 1e\\+100"):
        polind.Body(model, state=State.from_dict(edited))
    # a large but physical number still continues
    edited["body"][5] = 1e3
    body = polind.Body(model, state=State.from_dict(edited))
    assert all(math.isfinite(value) for value in body.step(0.1))


# --- NumPy scalars in messages ------------------------------------------------------------

def test_the_lost_step_messages_print_numbers():
    model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    state = model.initial_state()
    state.time = 1e12
    with pytest.raises(polind.InputError) as error:
        polind.Body(model, time_step=1e-9, state=state)
    text = str(error.value)
    assert "np." not in text
    assert "lost in its time 1000000000000.0 s: a step there is 0.0 s" in text
    # a step lost on the way (the time grows past 2**20 s, where 0.1 ms is lost)
    state.time = 2.0 ** 20 - 1e-3
    body = polind.Body(model, time_step=1e-4, state=state)
    with pytest.raises(polind.InputError, match="is lost in its time") as error:
        for _ in range(30):
            body.step(0.5)
    text = str(error.value)
    assert "np." not in text and "(0.0001 s) is lost in its time 1048576.0001 s" in text


@pytest.mark.parametrize("value", [np.float64(math.nan), np.float32(math.inf)])
def test_a_numpy_force_is_named_as_a_number(value):
    body = polind.Body(polind.model_from_dict({"model": {"type": "coulomb",
                                                         "coulomb_force": 1.0}}))
    with pytest.raises(polind.InputError) as error:
        body.step(value)
    assert "np." not in str(error.value)
    assert f"Got {float(value)!r} instead" in str(error.value)


@settings(max_examples=30, deadline=None)
@given(st.floats(allow_nan=True, allow_infinity=True))
def test_describe_gives_a_numpy_scalar_as_its_number(number):
    assert describe(np.float64(number)) == repr(number)
    assert describe(np.array(number)) == repr(number)
