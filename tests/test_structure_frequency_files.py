"""Structure files of kind "frequency_response" and "backbone", and ``polind structure`` on them.

The command's table is checked against what it must equal: the Python API's
curve or backbone of the same structure and settings (the same bits: the CSV
is written at full precision and the solvers are deterministic), the
amplitude and force columns recomputed from the API's harmonics.  Every bad
key or value is one error naming its dotted key; a continuation that stops
early writes the points it found and exits 2, never 0.  The model is one
Jenkins joint (a one-element Maxwell-slip) on one mass: its curve over
[60, 200] rad/s takes about 0.2 s.
"""

from __future__ import annotations

import copy
import os

import numpy as np
import pytest
import tomli_w
from hypothesis import given, settings
from hypothesis import strategies as st

import polind
from polind import InputError
from polind.structures import (BackboneRun, FrequencyResponseRun, load_structure,
                               structure_from_dict)
from polind.structures.continuation import FrequencyResponse

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

JOINT = {"type": "maxwell-slip", "stiffness": [1e4], "breakaway_force": [1.0]}
OMEGA_RANGE, FORCE = [60.0, 200.0], [1.0]
AMPLITUDES = [2e-5, 1e-4, 2e-4]
HEADER = ("omega,amplitude_q_0," + ",".join(
    ["q_0_0"] + [f"q_0_{kind}{h}" for h in range(1, 8) for kind in "cs"]) + ",F_0_1")


def document(run_table):
    return {"structure": {"mass": 1.0, "stiffness": 1e4, "damping": 4.0,
                          "contacts": [{"model": copy.deepcopy(JOINT), "dofs": [0]}],
                          "run": run_table}}


def frequency_document(**changes):
    table = {"kind": "frequency_response", "omega_range": list(OMEGA_RANGE), "force": FORCE}
    table.update(changes)
    return document(table)


def backbone_document(**changes):
    table = {"kind": "backbone", "amplitudes": list(AMPLITUDES)}
    table.update(changes)
    return document(table)


def write(folder, doc, name="structure.toml"):
    path = folder / name
    path.write_text(tomli_w.dumps(doc))
    return path


def in_python():
    structure = polind.Structure(mass=1.0, stiffness=1e4, damping=4.0)
    structure.add_contact(polind.model_from_dict({"model": JOINT}), dofs=(0,))
    return structure


def read_table(path):
    lines = path.read_text().splitlines()
    return lines[0], np.array([[float(field) for field in line.split(",")]
                               for line in lines[1:]])


def check_png(path, width_over_height):
    """A PNG, not blank, of the figure's proportions."""
    import matplotlib.image

    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    pixels = matplotlib.image.imread(path)
    height, width = pixels.shape[:2]
    assert width / height == pytest.approx(width_over_height, rel=0.02)
    assert pixels[..., :3].std() > 0.05               # lines and text, not one colour


# --- the command ------------------------------------------------------------------------

def test_a_frequency_response_file_writes_the_api_curve(tmp_path, capsys):
    path = write(tmp_path, frequency_document())
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    status, stdout, err = run(capsys, "structure", path, "-o", out, "--plot", png)
    assert status == 0 and err == "", err
    curve = polind.frequency_response(in_python(), omega_range=OMEGA_RANGE, force=FORCE,
                                      harmonics=7)
    assert f"wrote {out} and {png}: {len(curve)} points, omega 60 to 200 rad/s" in stdout
    header, table = read_table(out)
    assert header == HEADER
    assert table.shape == (len(curve), 2 + 15 + 1)
    assert np.array_equal(table[:, 0], curve.omega)
    assert np.array_equal(table[:, 2:17], curve.harmonics[:, 0, :])
    # The amplitude is the largest |q - Q_0| over the period, from the coefficients.
    theta = np.linspace(0.0, 2.0 * np.pi, 4096, endpoint=False)
    q = sum(curve.harmonics[:, 0, 2 * h - 1, None] * np.cos(h * theta)
            + curve.harmonics[:, 0, 2 * h, None] * np.sin(h * theta) for h in range(1, 8))
    assert np.abs(table[:, 1] - np.abs(q).max(axis=1)).max() <= 1e-4 * table[:, 1].max()
    assert np.array_equal(table[:, 17], np.hypot(curve.contact_force[:, 0, 1],
                                                 curve.contact_force[:, 0, 2]))
    # Past the joint's slip the peak: amplitudes fall from 60 rad/s (below the stuck
    # resonance at 141 rad/s the joint slips).
    assert table[0, 1] > table[-1, 1] > 0
    check_png(png, 7.0 / 4.4)


def test_a_backbone_file_writes_the_api_backbone(tmp_path, capsys):
    path = write(tmp_path, backbone_document(harmonics=5, samples=64))
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    status, stdout, err = run(capsys, "structure", path, "-o", out, "--plot", png)
    assert status == 0 and err == "", err
    assert f"wrote {out} and {png}: 3 amplitudes of mode 0" in stdout
    expected = polind.backbone(in_python(), AMPLITUDES, mode=0, harmonics=5, samples=64)
    header, table = read_table(out)
    assert header == "amplitude,frequency,damping_ratio,amplitude_q_0"
    assert np.array_equal(table, np.column_stack([
        expected.amplitude, expected.frequency, expected.damping_ratio,
        expected.displacement_amplitude(0)]))
    # Stuck at the smallest amplitude: the linear mode, sqrt(2e4) rad/s, and C's damping.
    assert table[0, 1] == pytest.approx(np.sqrt(2e4), rel=1e-9)
    assert table[0, 2] == pytest.approx(4.0 / (2.0 * np.sqrt(2e4)), rel=1e-6)
    assert table[-1, 1] < table[0, 1] and table[-1, 2] > table[0, 2]   # softer, more damped
    check_png(png, 7.0 / 6.0)


def test_a_continuation_that_stops_writes_its_points_and_exits_2(tmp_path, capsys):
    path = write(tmp_path, frequency_document(max_points=3))
    out, png = tmp_path / "out.csv", tmp_path / "out.png"
    status, stdout, err = run(capsys, "structure", path, "-o", out, "--plot", png)
    with pytest.raises(polind.ContinuationError) as stopped:
        polind.frequency_response(in_python(), omega_range=OMEGA_RANGE, force=FORCE,
                                  max_points=3)
    curve = stopped.value.curve
    assert status == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith(f"polind: error: {path}: "), err
    assert "'max_points' (3)" in err and f"omega = {float(curve.omega[-1])!r} rad/s" in err
    assert f"Wrote {out} and {png}: 3 points" in err
    header, table = read_table(out)
    assert header == HEADER and table.shape[0] == 3
    assert np.array_equal(table[:, 0], curve.omega)
    check_png(png, 7.0 / 4.4)


def test_a_stopped_continuation_without_a_plot_writes_the_table(tmp_path, capsys):
    path = write(tmp_path, frequency_document(max_points=2))
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "structure", path, "-o", out)
    assert status == 2 and "'max_points' (2)" in err and f"Wrote {out}: 2 points" in err
    assert len(out.read_text().splitlines()) == 3


@pytest.mark.parametrize("make", [frequency_document, backbone_document])
def test_an_output_that_is_the_structure_file_is_refused(tmp_path, capsys, make):
    path = write(tmp_path, make())
    before = path.read_bytes()
    for args in (["-o", path], ["-o", tmp_path / "out.csv", "--plot", path]):
        status, _, err = run(capsys, "structure", path, *args)
        assert status == 2 and err.count("\n") == 1
    assert path.read_bytes() == before and sorted(os.listdir(tmp_path)) == ["structure.toml"]


# --- the keys ----------------------------------------------------------------------------

BAD = {
    "a time key": (frequency_document(duration=1.0),
                   ["unknown key 'structure.run.duration'", "[structure.run]",
                    "kind = 'frequency_response'", "omega_range, force, harmonics"]),
    "a frequency key in a backbone": (backbone_document(force=[1.0]),
                                      ["unknown key 'structure.run.force'", "amplitudes, mode"]),
    "no omega_range": (document({"kind": "frequency_response", "force": FORCE}),
                       ["missing key 'structure.run.omega_range'", "rad/s"]),
    "no force": (document({"kind": "frequency_response", "omega_range": OMEGA_RANGE}),
                 ["missing key 'structure.run.force'"]),
    "one frequency": (frequency_document(omega_range=[60.0]),
                      ["'structure.run.omega_range'", "two different positive"]),
    "a zero frequency": (frequency_document(omega_range=[0.0, 200.0]),
                         ["'structure.run.omega_range'", "positive", "index 0"]),
    "the same frequency twice": (frequency_document(omega_range=[90.0, 90.0]),
                                 ["'structure.run.omega_range'", "the same frequency twice"]),
    "a force per coordinate missing": (frequency_document(force=[1.0, 2.0]),
                                       ["'structure.run.force'", "1 numbers", "2 numbers"]),
    "a zero force": (frequency_document(force=[0.0]),
                     ["'structure.run.force'", "at least one coordinate"]),
    "a force table": (frequency_document(force={"amplitude": [1.0]}),
                      ["'structure.run.force'", "a list of 1 force amplitude", "a table"]),
    "zero harmonics": (frequency_document(harmonics=0),
                       ["'structure.run.harmonics'", "a positive integer", "got 0"]),
    "fractional harmonics": (frequency_document(harmonics=2.5),
                             ["'structure.run.harmonics'", "got 2.5"]),
    "too few samples": (frequency_document(harmonics=7, samples=28),
                        ["'structure.run.samples'", "4 harmonics + 1 = 29", "got 28"]),
    "zero max_points": (frequency_document(max_points=0),
                        ["'structure.run.max_points'", "positive integer"]),
    "no amplitudes": (document({"kind": "backbone"}),
                      ["missing key 'structure.run.amplitudes'"]),
    "empty amplitudes": (backbone_document(amplitudes=[]),
                         ["'structure.run.amplitudes'", "positive modal amplitudes"]),
    "a zero amplitude": (backbone_document(amplitudes=[1e-4, 0.0]),
                         ["'structure.run.amplitudes'", "positive", "index 1"]),
    "a mode out of range": (backbone_document(mode=1),
                            ["'structure.run.mode'", "a mode 0 to 0", "got 1"]),
    "a negative mode": (backbone_document(mode=-1), ["'structure.run.mode'", "got -1"]),
    "a kind that is not a word": (frequency_document(kind=3),
                                  ["'structure.run.kind'", "'backbone'", "got 3"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_every_bad_key_or_value_is_named(case):
    doc, fragments = BAD[case]
    with pytest.raises(InputError) as error:
        structure_from_dict(doc)
    message = str(error.value)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


@pytest.mark.parametrize("case", ["a time key", "too few samples", "a mode out of range"])
def test_a_bad_file_exits_2_naming_the_key_and_writes_nothing(tmp_path, capsys, case):
    doc, fragments = BAD[case]
    path = write(tmp_path, doc)
    status, stdout, err = run(capsys, "structure", path, "-o", tmp_path / "out.csv",
                              "--plot", tmp_path / "out.png")
    assert status == 2 and stdout == "" and err.count("\n") == 1
    assert err.startswith(f"polind: error: {path}: ") and fragments[0] in err, err
    assert sorted(os.listdir(tmp_path)) == ["structure.toml"]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.one_of(st.floats(allow_nan=True), st.integers(-5, 5)), min_size=2,
                max_size=2))
def test_an_omega_range_is_two_different_positive_frequencies(values):
    good = all(np.isfinite(v) and v > 0 for v in values) and values[0] != values[1]
    doc = frequency_document(omega_range=values)
    if good:
        _, run_ = structure_from_dict(doc)
        assert run_.omega_range == (float(values[0]), float(values[1]))
    else:
        with pytest.raises(InputError, match=r"key 'structure\.run\.omega_range'"):
            structure_from_dict(doc)


def test_the_runs_and_their_defaults(tmp_path):
    _, fr = load_structure(write(tmp_path, frequency_document(force=2.5)))
    assert isinstance(fr, FrequencyResponseRun)
    assert (fr.omega_range, fr.force.tolist(), fr.harmonics, fr.samples, fr.max_points) == \
        ((60.0, 200.0), [2.5], 7, None, 2000)
    _, bb = load_structure(write(tmp_path, backbone_document(mode=0, harmonics=3)))
    assert isinstance(bb, BackboneRun)
    assert (bb.amplitudes.tolist(), bb.mode, bb.harmonics, bb.samples) == \
        (AMPLITUDES, 0, 3, None)


def test_the_columns_of_two_coordinates_and_two_contacts():
    """Each coordinate's harmonics in order, then each contact's first-harmonic force."""
    harmonics = np.arange(2 * 5, dtype=float).reshape(1, 2, 5)       # H = 2
    force = np.zeros((1, 2, 5))
    force[0, 1, 1:3] = [3.0, 4.0]
    curve = FrequencyResponse(omega=np.array([10.0]), harmonics=harmonics,
                              contact_displacement=np.zeros((1, 2, 5)), contact_force=force,
                              residual=np.zeros(1))
    columns = FrequencyResponseRun(omega_range=(1.0, 2.0), force=np.ones(2),
                                   harmonics=2).columns(curve)
    assert list(columns) == ["omega", "amplitude_q_0", "amplitude_q_1",
                             "q_0_0", "q_0_c1", "q_0_s1", "q_0_c2", "q_0_s2",
                             "q_1_0", "q_1_c1", "q_1_s1", "q_1_c2", "q_1_s2", "F_0_1", "F_1_1"]
    assert columns["q_1_s2"].tolist() == [9.0] and columns["q_0_c1"].tolist() == [1.0]
    assert columns["F_0_1"].tolist() == [0.0] and columns["F_1_1"].tolist() == [5.0]


def test_a_run_beyond_the_memory_is_refused_naming_its_keys():
    with pytest.raises(InputError) as error:
        structure_from_dict(frequency_document(harmonics=10 ** 400))
    message = str(error.value)
    assert "[structure.run]" in message and "harmonics = an integer of 401 digits" in message
    assert "of memory" in message
