"""Property-based fuzzing of polind's promises to a user who makes mistakes.

Random model tables (valid, and mutated into invalid ones), motions, states
and command lines.  The properties:

* Python: a bad argument raises ``InputError`` and nothing else; a good one
  gives finite forces.
* Command line: exit 0 or 2, never 1 or a traceback; an output file exists
  only after success; the input files are never changed.

The number of generated cases is set here (``FUZZ_EXAMPLES`` per test, with
hypothesis' database off so a run is reproducible from its seed).
"""

from __future__ import annotations

import copy
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import polind
from polind.cli import _run

from conftest import REPRESENTATIVE

FUZZ_EXAMPLES = 60
FUZZ = settings(max_examples=FUZZ_EXAMPLES, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow,
                                       HealthCheck.function_scoped_fixture])

# Values a user might type where a number belongs.
ODD_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**400, max_value=10**400),
    st.text(max_size=5), st.booleans(), st.none(),
    st.lists(st.floats(min_value=-10, max_value=10), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.sampled_from([0.0, -1.0, 1e300, 1e-300, 5e-324, 2**63, -2**63]),
)


@st.composite
def model_tables(draw):
    """A representative model table, maybe with one key changed, added or removed."""
    model_type = draw(st.sampled_from(sorted(REPRESENTATIVE)))
    table = copy.deepcopy(REPRESENTATIVE[model_type])
    action = draw(st.sampled_from(["keep", "change", "add", "remove", "mount"]))
    keys = [key for key in table if key != "type"]
    if action == "change":
        table[draw(st.sampled_from(keys + ["type"]))] = draw(ODD_VALUES)
    elif action == "add":
        table[draw(st.text(min_size=1, max_size=8))] = draw(ODD_VALUES)
    elif action == "remove":
        del table[draw(st.sampled_from(keys))]
    elif action == "mount":
        table["compliance"] = {"stiffness": draw(st.one_of(
            st.floats(min_value=1e2, max_value=1e8), ODD_VALUES))}
    return table


@st.composite
def motions(draw):
    n = draw(st.integers(min_value=0, max_value=40))
    dt = draw(st.floats(min_value=1e-6, max_value=1e-1))
    t = np.arange(n) * dt
    if n and draw(st.booleans()):
        t[draw(st.integers(0, n - 1))] = draw(st.floats(allow_nan=True, allow_infinity=True))
    amplitude = draw(st.floats(min_value=1e-9, max_value=1e-2))
    x = amplitude * np.sin(np.linspace(0.0, 6.0, n))
    if n and draw(st.booleans()):
        x[draw(st.integers(0, n - 1))] = draw(st.floats(allow_nan=True, allow_infinity=True))
    return t, x


@FUZZ
@given(model_tables(), motions())
def test_python_raises_input_error_or_gives_finite_forces(table, motion):
    t, x = motion
    try:
        model = polind.model_from_dict({"model": table})
    except polind.InputError:
        return
    try:
        result = polind.simulate(model, t, x=x)
    except polind.InputError:
        return
    assert np.all(np.isfinite(result.force))
    state = result.final_state
    assert polind.State.from_json(state.to_json()).to_dict() == state.to_dict()


@FUZZ
@given(st.dictionaries(st.sampled_from(["time", "position", "velocity", "force",
                                        "element_force", "deflection", "type"]),
                       ODD_VALUES, max_size=4))
def test_a_mangled_state_is_an_input_error(changes):
    model = polind.model_from_dict({"model": REPRESENTATIVE["maxwell-slip"]})
    t = np.linspace(0.0, 0.01, 11)
    base = polind.simulate(model, t, x=1e-5 * t).final_state.to_dict()
    base.update(changes)
    try:
        state = polind.State.from_dict(base)
        polind.Stepper(model, state=state).advance(state.time + 1e-3, x=state.position)
    except polind.InputError:
        pass


def _toml_value(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        return "[" + ", ".join(_toml_value(item) for item in value) + "]"
    return '"unrepresentable"'


def _write_model(path, table):
    lines = ["[model]"]
    nested = {}
    for key, value in table.items():
        if isinstance(value, dict):
            nested[key] = value
        elif value is not None:
            lines.append(f"{_toml_value(key)} = {_toml_value(value)}")
    for key, value in nested.items():
        lines.append(f"[model.{_toml_value(key)}]")
        lines.extend(f"{_toml_value(k)} = {_toml_value(v)}" for k, v in value.items()
                     if not isinstance(v, (dict, type(None))))
    path.write_text("\n".join(lines) + "\n")


CSV_LINES = st.lists(st.one_of(
    st.just("0,0"), st.just("0.001,1e-6"), st.just("0.002,2e-6"), st.just(""),
    st.just("nan,1"), st.just("0.001,abc"), st.just("1,2,3"), st.just("0.0005,1e-7"),
    st.text(alphabet="0123456789.,-e \t", max_size=12)), max_size=8)


@FUZZ
@given(model_tables(), st.sampled_from(["t,x", "t,v", "x,t", "t", "t,x,normal_load", "",
                                        "t,x,x"]), CSV_LINES,
       st.sampled_from(["out.csv", "motion.csv", "model.toml", "sub/", "missing/out.csv",
                        "-"]))
def test_the_command_line_exits_0_or_2_and_keeps_its_inputs(tmp_path_factory, table, header,
                                                             rows, output):
    folder = tmp_path_factory.mktemp("fuzz")
    model_path = folder / "model.toml"
    _write_model(model_path, table)
    motion_path = folder / "motion.csv"
    motion_path.write_text("\n".join([header] + rows) + "\n")
    (folder / "sub").mkdir()
    before = {path: path.read_bytes() for path in (model_path, motion_path)}
    target = "-" if output == "-" else os.path.join(os.fspath(folder), output)
    status = _run(["simulate", str(model_path), "--input", str(motion_path), "--output",
                   target])
    assert status in (0, 2)
    for path, content in before.items():
        assert path.read_bytes() == content
    if output == "out.csv":
        assert (folder / "out.csv").exists() == (status == 0)
    leftovers = [name for name in os.listdir(folder) if name.endswith(".tmp")]
    assert leftovers == []
