"""States that cannot lie, and model parameters that cannot give NaN (issue: checked states)."""

from __future__ import annotations

import copy

import numpy as np
import pytest

import polind
from polind.models.pol_ind import default_table

from conftest import REPRESENTATIVE, lib


def _pol_ind(elements):
    table = default_table()
    table["discretisation"] = dict(table["discretisation"], elements=elements)
    return polind.model_from_dict({"model": table})


def _final_state(model, n=50):
    t = np.linspace(0.0, 0.05, n)
    return polind.simulate(model, t, x=1e-7 * np.sin(100 * t)).final_state


@pytest.mark.parametrize("other", [200, 32])
def test_a_pol_ind_state_of_another_element_count_is_refused_naming_both(other):
    model = _pol_ind(64)
    state = _final_state(_pol_ind(other))
    t = np.array([state.time, state.time + 1e-3])
    x = np.array([state.position, state.position])
    with pytest.raises(polind.InputError, match=rf"state has {other} elements but this pol-ind "
                                                 rf"model has 64"):
        polind.simulate(model, t, x=x, state=state)
    with pytest.raises(polind.InputError, match="64"):
        polind.Stepper(model, state=state)
    with pytest.raises(polind.InputError, match="64"):
        polind.Body(model, state=state)


@pytest.mark.parametrize("key, value, message", [
    ("element_count", lambda a: np.where(np.arange(a.size) == 3, -1.0, a), "non-negative"),
    ("table_load", lambda a: np.zeros(0), "table_load"),
    ("table_load", lambda a: -a, "table_load"),
    ("slip_direction", lambda a: a + 0.5, "-1, 0 or 1"),
])
def test_a_pol_ind_state_with_impossible_values_is_refused(key, value, message):
    model = _pol_ind(16)
    state = _final_state(model)
    data = state.to_dict()
    data[key] = value(np.asarray(data[key], dtype=float)).tolist()
    bad = polind.State.from_dict(data)
    with pytest.raises(polind.InputError, match=message):
        polind.Stepper(model, state=bad)


def test_a_classical_state_of_another_element_count_is_refused():
    model = lib(REPRESENTATIVE["maxwell-slip"])
    fewer = copy.deepcopy(REPRESENTATIVE["maxwell-slip"])
    fewer["stiffness"], fewer["breakaway_force"] = fewer["stiffness"][:2], \
        fewer["breakaway_force"][:2]
    state = _final_state(lib(fewer))
    with pytest.raises(polind.InputError, match="element_force"):
        polind.Stepper(model, state=state)


def test_complex_samples_are_refused_not_truncated():
    model = lib(REPRESENTATIVE["lugre"])
    t = np.linspace(0.0, 1.0, 5)
    with pytest.raises(polind.InputError, match="'x' samples must be numbers"):
        polind.simulate(model, t, x=np.ones(5) * (1 + 1j))
    with pytest.raises(polind.InputError, match="'t' samples must be numbers"):
        polind.simulate(model, t.astype(complex), x=t)


def test_state_from_json_refuses_what_is_not_a_state():
    with pytest.raises(polind.InputError, match="JSON"):
        polind.State.from_json("{not json")
    with pytest.raises(polind.InputError, match="JSON text"):
        polind.State.from_json(3.0)


def test_parameters_too_large_for_doubles_are_refused_before_they_give_nan():
    table = default_table()
    table["static_coefficient"] = 1e300
    model = polind.model_from_dict({"model": table})
    t = np.linspace(0.0, 0.01, 5)
    with pytest.raises(polind.InputError, match="static_coefficient"):
        polind.simulate(model, t, x=1e-7 * t)


def test_json_output_is_strict():
    model = lib(REPRESENTATIVE["lugre"])
    assert "Infinity" not in model.to_json()
    state = model.initial_state()
    state.force = float("nan")
    with pytest.raises(ValueError):
        state.to_json()


@pytest.mark.parametrize("table, message", [
    ({"type": "lugre", **{k: v for k, v in REPRESENTATIVE["lugre"].items() if k != "type"},
      "bristle_stiffness": 10 ** 400}, "bristle_stiffness"),
    ({"type": ["lugre"]}, "type"),
    ({"type": {"a": 1}}, "type"),
])
def test_values_python_cannot_convert_are_input_errors(table, message):
    with pytest.raises(polind.InputError, match=message):
        polind.model_from_dict({"model": table})


def test_a_400_digit_integer_in_a_model_file_exits_2(tmp_path):
    from polind.cli import _run

    path = tmp_path / "m.toml"
    path.write_text('[model]\ntype = "coulomb"\ncoulomb_force = ' + "9" * 400 + "\n")
    motion = tmp_path / "motion.csv"
    motion.write_text("t,x\n0,0\n1,1\n")
    assert _run(["simulate", str(path), "--input", str(motion), "--output",
                 str(tmp_path / "out.csv")]) == 2
    assert not (tmp_path / "out.csv").exists()


def test_a_model_error_found_late_is_blamed_on_the_model_file(tmp_path, capsys):
    from polind.cli import _run

    table = default_table()
    table["static_coefficient"] = 1e300
    import tomli_w
    model = tmp_path / "model.toml"
    model.write_text(tomli_w.dumps({"model": table}))
    motion = tmp_path / "motion.csv"
    motion.write_text("t,x\n0,0\n0.001,1e-7\n")
    assert _run(["simulate", str(model), "--input", str(motion), "--output",
                 str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert f"{model}: " in err and "static_coefficient" in err


@pytest.mark.parametrize("options, key", [
    ({"max_evaluations": 0}, "max_evaluations"), ({"max_evaluations": 2.5}, "max_evaluations"),
    ({"tolerance": -1.0}, "tolerance"), ({"tolerance": 1e-30}, "tolerance"),
    ({"diff_step": 0}, "diff_step"), ({"diff_step": 2.0}, "diff_step"),
])
def test_identify_refuses_bad_solver_options_with_input_errors(options, key):
    model = lib(REPRESENTATIVE["dahl"])
    t = np.linspace(0.0, 1.0, 101)
    x = 1e-4 * np.sin(6 * t)
    data = {"t": t, "x": x, "F": polind.simulate(model, t, x=x).force}
    with pytest.raises(polind.InputError, match=key):
        polind.identify(model, data, **options)


def test_max_memory_refuses_a_system_run_with_exit_2(tmp_path, capsys):
    from polind.cli import _run

    model = tmp_path / "model.toml"
    model.write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    system = tmp_path / "system.toml"
    system.write_text("[system]\nmass = 1.0\nduration = 10.0\ntime_step = 1e-5\n"
                      "[system.force]\namplitude = 0.5\nfrequency = 1.0\n")
    out = tmp_path / "out.csv"
    assert _run(["--max-memory", "1M", "dynamics", str(model), "--system", str(system),
                 "--output", str(out)]) == 2
    err = capsys.readouterr().err
    assert "needs about 40 MB" in err and "--max-memory" in err and not out.exists()
    assert _run(["--max-memory", "lots", "dynamics", str(model), "--system", str(system),
                 "--output", str(out)]) == 2
    assert _run(["--max-memory", "100M", "dynamics", str(model), "--system", str(system),
                 "--output", str(out)]) == 0
    from polind import resources
    assert resources._LIMIT is None                # the option ends with its command
