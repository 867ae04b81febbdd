"""Structure files and ``polind structure`` (the user guide, "Structures"; formats.rst).

A structure file is checked against what it must equal: the structure built in
Python with the same matrices, contacts and forces (the same bits), and, for
one coordinate on one ground contact, :func:`polind.simulate_system` of the
``[system]`` file with the same force.  Every bad file is one error naming
the file and the key.  The contacts are Maxwell-slip joints: their structure
runner compiles once (about 15 s cold) and the numba cache is shared.
"""

from __future__ import annotations

import copy
import json
import os

import numpy as np
import pytest
import tomli_w

import polind
from polind import InputError
from polind.structures import StructureRun, load_structure, structure_from_dict

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

JOINT = {"type": "maxwell-slip", "stiffness": [1e4, 5e3], "breakaway_force": [0.4, 0.6]}
GROUND = {"type": "maxwell-slip", "stiffness": [2e3], "breakaway_force": [0.3]}
MASS = [[1.0, 0.0], [0.0, 0.5]]
STIFFNESS = [[200.0, 0.0], [0.0, 0.0]]
DAMPING = [[0.5, 0.0], [0.0, 0.0]]
DURATION, STEP = 0.05, 1e-4
AMPLITUDE, OFFSET, FREQUENCY = [2.0, 0.0], [0.0, 0.1], 40.0


def document():
    """Two masses: a joint in a model file between them, an inline contact to the ground."""
    return {"structure": {
        "mass": MASS, "stiffness": STIFFNESS, "damping": DAMPING,
        "contacts": [{"model": "joint.toml", "dofs": [0, 1]},
                     {"model": copy.deepcopy(GROUND), "dofs": [1]}],
        "run": {"duration": DURATION, "time_step": STEP, "initial_velocity": [0.01, 0.0],
                "force": {"amplitude": AMPLITUDE, "offset": OFFSET,
                          "frequency": FREQUENCY}}}}


def write(folder, doc, name="structure.toml"):
    (folder / "joint.toml").write_text(tomli_w.dumps({"model": JOINT}))
    path = folder / name
    if name.endswith(".json"):
        path.write_text(json.dumps(doc))
    else:
        path.write_text(tomli_w.dumps(doc))
    return path


def in_python():
    structure = polind.Structure(mass=MASS, stiffness=STIFFNESS, damping=DAMPING)
    structure.add_contact(polind.model_from_dict({"model": JOINT}), dofs=(0, 1))
    structure.add_contact(polind.model_from_dict({"model": GROUND}), dofs=(1,))
    t = np.arange(int(round(DURATION / STEP)) + 1) * STEP
    force = np.array(OFFSET) + np.array(AMPLITUDE) * np.sin(2 * np.pi * FREQUENCY * t)[:, None]
    return polind.simulate_structure(structure, t, force=force, initial_velocity=[0.01, 0.0])


@pytest.fixture(scope="module")
def expected():
    return in_python()


# --- loading ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["structure.toml", "structure.json"])
def test_a_file_is_the_structure_built_in_python(tmp_path, expected, name):
    structure, run_ = load_structure(write(tmp_path, document(), name))
    assert repr(structure) == "Structure(2 coordinates, 2 contacts: maxwell-slip on (0, 1), " \
                              "maxwell-slip on (1, None))"
    assert isinstance(run_, StructureRun) and run_.method == "bdf2"
    result = run_.simulate(structure)
    for key in ("t", "q", "dq", "contact_forces", "applied"):
        assert np.array_equal(getattr(result, key), getattr(expected, key)), key
    assert np.ptp(result.contact_forces[:, 0]) > 0.5          # the joint slips
    assert polind.load_structure is load_structure


def test_one_ground_contact_is_the_system_file(tmp_path):
    structure, run_ = structure_from_dict({"structure": {
        "mass": 2.0, "contacts": [{"model": JOINT, "dofs": [0]}],
        "run": {"duration": 0.2, "time_step": 1e-3,
                "force": {"amplitude": [1.5], "offset": [0.2], "frequency": 3.0}}}})
    result = run_.simulate(structure)
    system = tmp_path / "system.toml"
    system.write_text("[system]\nmass = 2.0\nduration = 0.2\ntime_step = 1e-3\n"
                      "[system.force]\namplitude = 1.5\noffset = 0.2\nfrequency = 3.0\n")
    body = polind.simulate_system(polind.model_from_dict({"model": JOINT}),
                                  polind.load_system(system))
    assert np.ptp(body.x) > 0.0
    for values, reference in ((result.q[:, 0], body.x), (result.dq[:, 0], body.v),
                              (result.contact_forces[:, 0], body.force),
                              (result.applied[:, 0], body.applied)):
        assert np.abs(values - reference).max() <= 1e-12 * np.ptp(reference)


def test_an_inline_model_and_numbers_for_one_coordinate():
    structure, run_ = structure_from_dict({"structure": {
        "mass": 1, "stiffness": 100, "contacts": [{"model": GROUND, "dofs": 0}]}})
    assert run_ is None and structure.size == 1
    assert structure.stiffness.tolist() == [[100.0]]
    assert structure.contacts[0].second is None


# --- errors ---------------------------------------------------------------------------------

def _set(path, value):
    def change(doc):
        table = doc
        *parents, key = path
        for part in parents:
            table = table[part]
        if value is _DELETE:
            del table[key]
        else:
            table[key] = value
    return change


_DELETE = object()

BAD = {
    "non-symmetric mass": (_set(("structure", "mass"), [[1.0, 0.2], [0.0, 0.5]]),
                           ["'structure.mass'", "symmetric"]),
    "mass not positive definite": (_set(("structure", "mass"), [[1.0, 0.0], [0.0, -0.5]]),
                                   ["'structure.mass'", "positive definite"]),
    "ragged mass": (_set(("structure", "mass"), [[1.0, 0.0], [0.5]]),
                    ["'structure.mass'", "row 1"]),
    "stiffness of the wrong shape": (_set(("structure", "stiffness"), [[1.0, 0.0, 0.0]] * 3),
                                     ["'structure.stiffness'", "2 x 2", "3 rows"]),
    "damping of the wrong shape": (_set(("structure", "damping"), [[1.0]]),
                                   ["'structure.damping'", "2 x 2"]),
    "a stiffness that is not numbers": (_set(("structure", "stiffness"), [[1.0, "a"], [0, 0]]),
                                        ["'structure.stiffness'", "a finite number", "[0, 1]"]),
    "dof out of range": (_set(("structure", "contacts", 0, "dofs"), [0, 2]),
                         ["'structure.contacts[0].dofs'", "0 to 1", "got 2"]),
    "the same dof twice": (_set(("structure", "contacts", 1, "dofs"), [1, 1]),
                           ["'structure.contacts[1].dofs'", "two different"]),
    "a contact model that fails validation": (
        _set(("structure", "contacts", 1, "model", "stiffness"), [-1.0]),
        ["'structure.contacts[1].model'", "'stiffness' parameter of maxwell-slip",
         "positive"]),
    "a contact model file that does not exist": (
        _set(("structure", "contacts", 0, "model"), "missing.toml"),
        ["'structure.contacts[0].model'", "missing.toml"]),
    "an unknown model key": (_set(("structure", "contacts", 1, "model", "stifness"), [1.0]),
                             ["'structure.contacts[1].model'", "stifness"]),
    "an unknown structure key": (_set(("structure", "masses"), 1.0),
                                 ["'structure.masses'", "[structure]", "mass, stiffness"]),
    "an unknown contact key": (_set(("structure", "contacts", 0, "dof"), [0]),
                               ["'structure.contacts[0].dof'", "model, dofs"]),
    "an unknown run key": (_set(("structure", "run", "durations"), 1.0),
                           ["'structure.run.durations'", "[structure.run]", "duration, "
                                                                            "time_step"]),
    "an unknown force key": (_set(("structure", "run", "force", "phase"), 1.0),
                             ["'structure.run.force.phase'", "[structure.run.force]",
                              "offset, amplitude, frequency"]),
    "frequency_response with a time run's keys": (
        _set(("structure", "run", "kind"), "frequency_response"),
        ["'structure.run.duration'", "[structure.run]", "kind = 'frequency_response'",
         "omega_range, force"]),
    "a backbone table": (_set(("structure", "run", "backbone"), {"amplitudes": [1.0]}),
                         ["'structure.run.backbone'", "kind = 'backbone'"]),
    "an unknown kind": (_set(("structure", "run", "kind"), "modal"),
                        ["'structure.run.kind'", "'time'", "'frequency_response'",
                         "'backbone'", "'modal'"]),
    "no duration": (_set(("structure", "run", "duration"), _DELETE),
                    ["'structure.run.duration'", "missing"]),
    "a negative time step": (_set(("structure", "run", "time_step"), -1e-4),
                             ["'structure.run.time_step'", "positive"]),
    "a bad method": (_set(("structure", "run", "method"), "rk4"),
                     ["'structure.run.method'", "'bdf2'", "'rk4'"]),
    "an amplitude per coordinate missing": (_set(("structure", "run", "force", "amplitude"),
                                                 [1.0]),
                                            ["'structure.run.force.amplitude'", "2 numbers"]),
    "an amplitude without frequency": (_set(("structure", "run", "force", "frequency"),
                                            _DELETE),
                                       ["'structure.run.force.frequency'", "amplitude"]),
    "no contacts": (_set(("structure", "contacts"), _DELETE), ["[[structure.contacts]]"]),
    "a contact without dofs": (_set(("structure", "contacts", 0, "dofs"), _DELETE),
                               ["'structure.contacts[0].dofs'", "missing"]),
    "contacts of two families": (_set(("structure", "contacts", 1, "model"),
                                      {"type": "coulomb", "coulomb_force": 1.0}),
                                 ["'structure.contacts[1].model'", "coulomb", "one model "
                                                                              "family"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_every_error_names_the_file_and_its_key(tmp_path, case):
    change, fragments = BAD[case]
    doc = document()
    change(doc)
    path = write(tmp_path, doc)
    with pytest.raises(InputError) as error:
        load_structure(path)
    message = str(error.value)
    assert message.startswith(f"{path}: "), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_file_without_structure_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("[system]\nmass = 1.0\n")
    with pytest.raises(InputError, match="unknown top-level key 'system'"):
        load_structure(path)


# --- the command ------------------------------------------------------------------------------

def test_the_command_writes_the_table(tmp_path, capsys, expected):
    path = write(tmp_path, document())
    out = tmp_path / "out.csv"
    status, stdout, err = run(capsys, "structure", path, "--output", out)
    assert status == 0 and err == "", err
    assert "wrote" in stdout and "501 samples" in stdout
    lines = out.read_text().splitlines()
    assert lines[0] == "t,q_0,q_1,dq_0,dq_1,F_0,F_1"
    table = np.array([[float(field) for field in line.split(",")] for line in lines[1:]])
    assert table.shape == (501, 7)
    columns = np.column_stack([expected.t, expected.q, expected.dq, expected.contact_forces])
    assert np.array_equal(table, columns)                  # full precision: the same bits


def test_the_command_writes_to_standard_output(tmp_path, capsys, expected):
    path = write(tmp_path, document())
    status, stdout, err = run(capsys, "structure", path, "-o", "-")
    assert status == 0 and "wrote" in err
    lines = stdout.splitlines()
    assert lines[0] == "t,q_0,q_1,dq_0,dq_1,F_0,F_1" and len(lines) == 502


def test_the_plot_is_written_with_the_table(tmp_path, capsys):
    path = write(tmp_path, document())
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    status, stdout, err = run(capsys, "structure", path, "-o", out, "--plot", png)
    assert status == 0 and err == "", err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert out.read_text().startswith("t,q_0,q_1,dq_0,dq_1,F_0,F_1\n")
    assert f"wrote {out} and {png}" in stdout


@pytest.mark.parametrize("case", ["non-symmetric mass", "a contact model that fails validation",
                                  "frequency_response with a time run's keys",
                                  "an unknown run key"])
def test_a_bad_file_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, case):
    change, fragments = BAD[case]
    doc = document()
    change(doc)
    path = write(tmp_path, doc)
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    status, stdout, err = run(capsys, "structure", path, "-o", out, "--plot", png)
    assert status == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith(f"polind: error: {path}: "), err
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    assert not out.exists() and not png.exists()
    assert sorted(os.listdir(tmp_path)) == ["joint.toml", "structure.toml"]


def test_a_file_without_a_run_exits_2(tmp_path, capsys):
    doc = document()
    del doc["structure"]["run"]
    path = write(tmp_path, doc)
    status, _, err = run(capsys, "structure", path, "-o", tmp_path / "out.csv")
    assert status == 2 and "[structure.run]" in err and err.count("\n") == 1
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("option", ["-o", "--plot"])
def test_an_output_that_is_an_input_is_refused(tmp_path, capsys, option):
    path = write(tmp_path, document())
    joint = tmp_path / "joint.toml"
    before = joint.read_bytes()
    args = ["-o", joint] if option == "-o" else ["-o", tmp_path / "out.csv", "--plot", joint]
    status, _, err = run(capsys, "structure", path, *args)
    assert status == 2 and err.count("\n") == 1 and "joint.toml" in err
    assert joint.read_bytes() == before and not (tmp_path / "out.csv").exists()
    status, _, err = run(capsys, "structure", path, "-o", path)
    assert status == 2 and err.count("\n") == 1
