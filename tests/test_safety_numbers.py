"""Finite or refused (issue 24, causes 4, 7 and 12).

* A model's numbers that its arithmetic cannot take (too large, too small,
  force levels further apart than a double resolves) are refused when the
  model is first stepped, naming the key (cause 4).
* A ``Body`` whose time step is lost in its absolute time, a ``State`` whose
  numbers are not finite, are refused (cause 4).
* Huge integers and deep nesting in a model file, 400-digit ``[fit.bounds]``,
  are exit 2 (cause 7).
* A model of one's own whose declarations are wrong fails at
  ``register_model``, naming the method (cause 12).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import polind
from polind.cli import _run
from polind.errors import InputError
from polind.models import FrictionModel, StepFunctions, register_model, unregister_model
from polind.models.checks import LARGEST, SMALLEST
from polind.models.params import Param

from conftest import LUGRE_1995, REPRESENTATIVE

SAFETY = settings(max_examples=40, deadline=None, database=None)

# Magnitudes a model's arithmetic cannot take: beyond LARGEST, or below SMALLEST (subnormals
# included).
UNPHYSICAL = st.one_of(st.floats(min_value=LARGEST * 1.01, max_value=1.7e308),
                       st.floats(min_value=5e-324, max_value=SMALLEST * 0.99),
                       st.sampled_from([1e200, 1e-300, 5e-324, 1e101, 9e-101]))


def _float_keys(table):
    """``(key, index)`` of every positive float of a representative table (index: in a list)."""
    for key, value in table.items():
        if isinstance(value, float) and value > 0.0:
            yield key, None
        elif isinstance(value, list) and value and all(isinstance(v, float) for v in value):
            yield key, 0


@SAFETY
@given(st.sampled_from(sorted(REPRESENTATIVE)), st.data(), UNPHYSICAL)
def test_a_number_the_arithmetic_cannot_take_is_refused_naming_its_key(model_type, data, size):
    table = copy.deepcopy(REPRESENTATIVE[model_type])
    keys = list(_float_keys(table))
    key, index = data.draw(st.sampled_from(keys))
    if index is None:
        table[key] = size
    else:
        table[key][index] = size
    try:
        model = polind.model_from_dict({"model": table})
    except InputError:
        return                          # refused by a rule of its own (a sum, an order)
    with pytest.raises(InputError, match=f"'{key}'|{key}"):
        model.step_kernel()


@pytest.mark.parametrize("changes, names", [
    ({"coulomb_force": 1e200}, ["coulomb_force"]),
    ({"static_force": 1e-300}, ["static_force"]),
    ({"bristle_stiffness": 5e-324}, ["bristle_stiffness"]),
    ({"coulomb_force": 1e20}, ["static_force", "coulomb_force"]),
    ({"static_force": 1e-17}, ["static_force", "coulomb_force"]),
])
def test_lugre_of_the_issue_is_refused_at_build_naming_the_key(changes, names):
    model = polind.model_from_dict({"model": {**LUGRE_1995, **changes}})
    with pytest.raises(InputError) as refused:
        polind.Body(model, time_step=1e-3)
    assert all(name in str(refused.value) for name in names), refused.value


def test_the_commands_refuse_them_with_one_line(tmp_path, capsys):
    model = tmp_path / "big.toml"
    model.write_text("[model]\n" + "".join(
        f"{key} = {value!r}\n" if not isinstance(value, str) else f'{key} = "{value}"\n'
        for key, value in {**LUGRE_1995, "coulomb_force": 1e200}.items()))
    (tmp_path / "system.toml").write_text("[system]\nmass = 1.0\nduration = 0.1\n"
                                          "time_step = 0.01\n[system.force]\namplitude = 1.0\n"
                                          "frequency = 1.0\n")
    status = _run(["dynamics", str(model), "-s", str(tmp_path / "system.toml"), "-o",
                   str(tmp_path / "out.csv")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "coulomb_force" in err, err
    assert not (tmp_path / "out.csv").exists()


@settings(max_examples=30, deadline=None, database=None)
@given(st.floats(min_value=0.0, max_value=1e12), st.floats(min_value=1e-9, max_value=1.0))
def test_a_body_whose_step_is_lost_in_its_time_is_refused(start, time_step):
    model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    state = model.initial_state()
    state.time = start
    step = (start + time_step) - start
    lost = abs(step - time_step) > 1e-6 * time_step
    try:
        body = polind.Body(model, time_step=time_step, state=state)
    except InputError as error:
        assert lost and "time_step" in str(error)
        return
    assert not lost
    x, v, force = body.step(2.0)
    assert all(math.isfinite(value) for value in (x, v, force))


def test_the_body_of_the_issue_is_refused():
    model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    state = model.initial_state()
    state.time = 1.7e9
    with pytest.raises(InputError, match="time_step"):
        polind.Body(model, time_step=1e-7, state=state)


@SAFETY
@given(st.sampled_from(["variable", "time", "position", "velocity", "force"]),
       st.sampled_from([math.nan, math.inf, -math.inf]))
def test_a_state_that_is_not_finite_is_refused(where, value):
    model = polind.model_from_dict({"model": REPRESENTATIVE["maxwell-slip"]})
    state = model.initial_state()
    with pytest.raises(InputError):
        if where == "variable":
            polind.State(state.model_type, variables={"element_force": np.array([value])})
        else:
            polind.State(state.model_type, **{where: value})
    # Changed after it was built: refused when given to a model.
    if where == "variable":
        next(iter(state.variables.values()))[0] = value
    else:
        setattr(state, where, value)
    with pytest.raises(InputError):
        polind.Stepper(model, state=state)


# --- huge integers, deep nesting --------------------------------------------------------------

@settings(max_examples=15, deadline=None, database=None)
@given(st.integers(min_value=33, max_value=3000), st.sampled_from([".toml", ".json"]))
def test_deep_nesting_is_exit_2(tmp_path_factory, depth, suffix):
    folder = tmp_path_factory.mktemp("deep")
    path = folder / f"deep{suffix}"
    nested = "[" * depth + "]" * depth
    if suffix == ".json":
        path.write_text('{"model": {"type": "coulomb", "coulomb_force": ' + nested + "}}")
    else:
        path.write_text('[model]\ntype = "coulomb"\ncoulomb_force = ' + nested + "\n")
    with pytest.raises(InputError, match="nest"):
        polind.load_model(path)


@pytest.mark.parametrize("text, key", [
    ('[model]\ntype = "coulomb"\ncoulomb_force = ' + "9" * 400 + "\n", "coulomb_force"),
    ('[model]\ntype = "coulomb"\ncoulomb_force = ' + "9" * 5000 + "\n", "digits"),
    ("[model]\n" + "".join(f"{k} = {v!r}\n" if not isinstance(v, str) else f'{k} = "{v}"\n'
                           for k, v in LUGRE_1995.items())
     + '[fit]\nfree = ["coulomb_force"]\n[fit.bounds]\ncoulomb_force = [0.1, ' + "9" * 400
     + "]\n", "coulomb_force"),
])
def test_huge_integers_in_a_model_file_are_exit_2(tmp_path, capsys, text, key):
    model = tmp_path / "m.toml"
    model.write_text(text)
    data = tmp_path / "data.csv"
    data.write_text("t,x,F\n" + "".join(f"{k * 0.01},{k * 1e-5},{math.tanh(k)}\n"
                                        for k in range(20)))
    status = _run(["fit", str(model), "--data", str(data), "-o", str(tmp_path / "f.toml")])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and key in err, err
    assert len(err) < 600


# --- a model of one's own ---------------------------------------------------------------------

def _own_model(name, **methods):
    """A model class of one's own: a LuGre in disguise, with ``methods`` replaced."""
    from polind.models.lugre import LuGre

    class Own(FrictionModel):
        type = name
        parameters = LuGre.parameters

        @classmethod
        def example_parameters(cls, elements=None):
            return LuGre.example_parameters()

        def initial_variables(self, normal_load=None):
            return {"deflection": np.zeros(1)}

        def step_functions(self):
            return LuGre.step_functions(self)

        def kernel_arrays(self, state):
            return LuGre.kernel_arrays(self, state)

    for key, method in methods.items():
        setattr(Own, key, method)
    return Own


WRONG = {
    "step_functions": lambda self: (1, 2, 3),
    "kernel_arrays": lambda self, state: [np.zeros(8)],
    "initial_variables": lambda self, normal_load=None: {"deflection": "zero"},
    "characteristic_scales": lambda self: 1 / 0,
}


@pytest.mark.parametrize("method", sorted(WRONG))
def test_a_wrong_declaration_fails_at_register_naming_the_method(method):
    cls = _own_model(f"own-{method.replace('_', '-')}", **{method: WRONG[method]})
    with pytest.raises(InputError, match=f"{method}"):
        register_model(cls)
    assert cls.type not in polind.models.MODEL_TYPES


def test_without_example_parameters_it_fails_at_first_build_naming_the_method():
    cls = _own_model("own-no-example", step_functions=lambda self: (1, 2, 3))
    del cls.example_parameters
    register_model(cls)
    try:
        model = polind.model_from_dict({"model": {"type": "own-no-example",
                                                  **polind.models.LuGre.example_parameters()}})
        with pytest.raises(InputError, match="step_functions"):
            polind.simulate(model, np.linspace(0.0, 1.0, 5), x=np.zeros(5))
    finally:
        unregister_model("own-no-example")


def test_a_right_declaration_registers_and_runs():
    cls = _own_model("own-right")
    register_model(cls)
    try:
        model = polind.model_from_dict({"model": {"type": "own-right",
                                                  **polind.models.LuGre.example_parameters()}})
        t = np.linspace(0.0, 0.01, 11)
        assert np.isfinite(polind.simulate(model, t, x=1e-6 * t).force).all()
    finally:
        unregister_model("own-right")


def test_step_functions_must_be_numba_functions():
    cls = _own_model("own-python", step_functions=lambda self: StepFunctions(
        lambda *a: 0.0, lambda *a: 0.0, lambda *a: 1.0))
    with pytest.raises(InputError, match="step_functions.*numba"):
        register_model(cls)


def test_parameters_must_be_a_tuple():
    cls = _own_model("own-parameters")
    cls.parameters = [Param("coulomb_force")]
    with pytest.raises(InputError, match="parameters"):
        register_model(cls)
