"""Instrument records read through a data description (:mod:`polind.io.records`).

References, each independent of the code under test:
- a record made here in SI units (a Stribeck model's force along a sine motion), written
  in an instrument's layout by hand: its own column names, ms, mm, µN, friction's sign
  flipped, an offset position, extra samples at both ends and a column the
  description does not name; reading it back must give the SI record, to rounding;
- unit factors written out here (1 mm = 1e-3 m, 1 µN = 1e-6 N, 1 ms = 1e-3 s);
- the command line's contract (INTERFACE.md): exit 2, one line naming the file and the
  key, nothing written.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
import tomli_w

import polind
from polind import io
from polind.errors import InputError
from polind.io import records, tables

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

TRUTH = {"type": "stribeck", "coulomb_force": 1.0, "static_force": 1.5,
         "stribeck_velocity": 1e-3}
HEADER = ("Time [ms]", "Temperature", "Position [mm]", "Friction [uN]", "Normal [uN]")
DESCRIPTION = {"file": "run1.tsv", "delimiter": "\t",
               "columns": {"t": "Time [ms]", "x": "Position [mm]", "F": "Friction [uN]",
                           "normal_load": "Normal [uN]"},
               "units": {"t": "ms", "x": "mm", "F": "µN", "normal_load": "uN"},
               "sign": {"F": -1}, "zero": ["x"], "window": [0.2, 1.8]}


def si_record(samples=401):
    """The record in SI units over 2 s: t, x, F and normal_load."""
    t = np.linspace(0.0, 2.0, samples)
    x = 2e-4 * np.sin(2 * np.pi * t) + 3e-4            # an offset position [m]
    truth = polind.model_from_dict({"model": TRUTH})
    force = polind.simulate(truth, t, x=x).force
    load = 5.0 + 0.1 * np.cos(2 * np.pi * t)
    return {"t": t, "x": x, "F": force, "normal_load": load}


def write_instrument_file(path, record, delimiter="\t", newline="\n", quote=False,
                          bom=False, trailing_blank_lines=0):
    """The record as an instrument writes it: ms, mm, µN, friction's sign flipped."""
    columns = (record["t"] * 1e3, np.full(record["t"].size, 21.5), record["x"] * 1e3,
               -record["F"] * 1e6, record["normal_load"] * 1e6)
    wrap = (lambda text: f'"{text}"') if quote else (lambda text: text)
    lines = [delimiter.join(wrap(name) for name in HEADER)]
    lines += [delimiter.join(wrap(repr(float(value))) for value in row)
              for row in zip(*columns)]
    text = newline.join(lines) + newline + newline * trailing_blank_lines
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8"))
    return path


def write_description(path, **changes):
    data = {**DESCRIPTION, **changes}
    data = {key: value for key, value in data.items() if value is not None}
    path.write_text(tomli_w.dumps({"data": data}), encoding="utf-8")
    return path


def expected(record, window=(0.2, 1.8)):
    """What the description above must give: the window kept, the position zeroed."""
    keep = (record["t"] >= window[0] - 1e-12) & (record["t"] <= window[1] + 1e-12)
    out = {key: value[keep] for key, value in record.items()}
    out["x"] = out["x"] - out["x"][0]
    return out


def assert_record(got, want):
    assert list(got) == ["t", "x", "F", "normal_load"]
    for key, value in want.items():
        assert got[key].dtype == np.float64 and got[key].flags.c_contiguous, key
        np.testing.assert_allclose(got[key], value, rtol=1e-14, atol=1e-15 * np.ptp(value),
                                   err_msg=key)


@pytest.fixture
def instrument(tmp_path):
    record = si_record()
    write_instrument_file(tmp_path / "run1.tsv", record)
    return write_description(tmp_path / "run1.toml"), record


# --- reading a record ---------------------------------------------------------------------

def test_a_description_gives_the_record_in_si_units(instrument):
    path, record = instrument
    got = io.read_record(path)
    assert_record(got, expected(record))
    assert (got["t"][0], got["t"][-1]) == pytest.approx((0.2, 1.8), abs=1e-12)
    assert got["x"][0] == 0.0


def test_the_description_is_read_and_checked(instrument):
    path, _ = instrument
    description = io.read_description(path)
    assert description.file == path.parent / "run1.tsv"
    assert description.scale == pytest.approx({"t": 1e-3, "x": 1e-3, "F": -1e-6,
                                               "normal_load": 1e-6}, rel=1e-15)
    assert description.zero == ("x",) and description.window == (0.2, 1.8)
    assert io.record_files(path) == [path, path.parent / "run1.tsv"]
    assert io.record_files(path.parent / "run1.csv") == [path.parent / "run1.csv"]
    assert io.is_description(path) and not io.is_description("run1.parquet")


@pytest.mark.parametrize("unit, si, factor", [
    ("mm", "m", 1e-3), ("um", "m", 1e-6), ("µm", "m", 1e-6), ("in", "m", 0.0254),
    ("uN", "N", 1e-6), ("µN", "N", 1e-6), ("\u03bcN", "N", 1e-6), ("mN", "N", 1e-3),
    ("kN", "N", 1e3), ("ms", "s", 1e-3), ("min", "s", 60.0), ("mm/s", "m/s", 1e-3),
])
def test_units_are_converted_by_the_unit_library(unit, si, factor):
    assert records.si_factor(unit, si) == pytest.approx(factor, rel=1e-15)


def test_without_units_sign_zero_or_window_the_columns_are_read_as_they_are(tmp_path):
    record = si_record(101)
    write_instrument_file(tmp_path / "run1.tsv", record)
    path = write_description(tmp_path / "d.toml", units=None, sign=None, zero=None,
                             window=None, delimiter=None)
    got = io.read_record(path)
    np.testing.assert_allclose(got["t"], record["t"] * 1e3, rtol=1e-15)
    np.testing.assert_allclose(got["F"], -record["F"] * 1e6, rtol=1e-15)
    np.testing.assert_allclose(got["x"], record["x"] * 1e3, rtol=1e-15)


@pytest.mark.parametrize("delimiter", ["\t", ",", ";"])
def test_the_delimiter_is_guessed_from_the_header(tmp_path, delimiter):
    record = si_record(101)
    write_instrument_file(tmp_path / "run1.tsv", record, delimiter=delimiter)
    got = io.read_record(write_description(tmp_path / "d.toml", delimiter=None))
    assert_record(got, expected(record))


@pytest.mark.parametrize("form", ["quoted", "bom", "crlf", "blank-trailing-lines", "all"])
def test_spreadsheet_forms_are_read_as_numbers_and_lines(tmp_path, form):
    record = si_record(101)
    options = {"quoted": {"quote": True}, "bom": {"bom": True}, "crlf": {"newline": "\r\n"},
               "blank-trailing-lines": {"trailing_blank_lines": 3},
               "all": {"quote": True, "bom": True, "newline": "\r\n",
                       "trailing_blank_lines": 2, "delimiter": ","}}[form]
    write_instrument_file(tmp_path / "run1.tsv", record, **options)
    got = io.read_record(write_description(tmp_path / "d.toml", delimiter=None))
    assert_record(got, expected(record))


def test_a_big_file_goes_through_the_fast_reader_with_the_same_values(tmp_path, monkeypatch):
    record = si_record(101)
    write_instrument_file(tmp_path / "run1.tsv", record, quote=True, newline="\r\n")
    path = write_description(tmp_path / "d.toml")
    careful = io.read_record(path)
    monkeypatch.setattr(tables, "_FAST_READ_BYTES", 0)
    monkeypatch.setattr(tables, "_read_csv_carefully", None)       # would fail if called
    fast = io.read_record(path)
    for key in careful:
        assert fast[key].tobytes() == careful[key].tobytes(), key


def test_a_parquet_file_is_read_by_its_column_names(tmp_path):
    record = si_record(101)
    raw = {"Time [ms]": record["t"] * 1e3, "Position [mm]": record["x"] * 1e3,
           "Friction [uN]": -record["F"] * 1e6, "Normal [uN]": record["normal_load"] * 1e6,
           "Temperature": np.full(101, 21.5)}
    io.write_parquet_atomic(tmp_path / "run1.parquet", raw)
    got = io.read_record(write_description(tmp_path / "d.toml", file="run1.parquet",
                                           delimiter=None))
    assert_record(got, expected(record))


def test_the_caller_takes_only_its_columns(instrument):
    path, record = instrument
    motion = io.read_record(path, **io.MOTION_COLUMNS)
    assert list(motion) == ["t", "x", "normal_load"]
    data = io.read_record(path, **io.MEASUREMENT_COLUMNS)
    assert list(data) == ["t", "x", "F", "normal_load"]


def test_a_velocity_column_in_mm_per_s(tmp_path):
    t = np.linspace(0.0, 1.0, 51)
    v = 1e-3 * np.cos(t)
    (tmp_path / "v.csv").write_text("time,speed\n" + "".join(
        f"{a!r},{b * 1e3!r}\n" for a, b in zip(t.tolist(), v.tolist())))
    (tmp_path / "v.toml").write_text('[data]\nfile = "v.csv"\n'
                                     'columns = { t = "time", v = "speed" }\n'
                                     'units = { v = "mm/s" }\n')
    got = io.read_record(tmp_path / "v.toml")
    assert list(got) == ["t", "v"]
    np.testing.assert_allclose(got["v"], v, rtol=1e-15)


def test_identify_and_compare_take_the_record(instrument):
    path, _ = instrument
    data = io.read_record(path, require=("t", "F"), optional=())
    start = polind.model_from_dict({"model": {**TRUTH, "coulomb_force": 2.0}})
    # The force of a memoryless model at the first kept sample is that of the step
    # before the window: the one sample the record and the truth disagree on.
    result = polind.identify(start, data, free=["coulomb_force"])
    assert result.model.params["coulomb_force"] == pytest.approx(1.0, rel=1e-3)
    table = polind.compare({"stribeck": start}, data, holdout=0.25)
    assert table.rows[0]["rms_held_out"] < 1e-3


# --- every mistake names its key ----------------------------------------------------------

def description_text(**changes):
    data = {key: value for key, value in {**DESCRIPTION, **changes}.items() if value is not None}
    return tomli_w.dumps({"data": data})


MISTAKES = [
    ("unknown-key", description_text(delimeter=","), ["unknown key 'data.delimeter'",
                                                       "delimiter"]),
    ("unknown-table", description_text() + "[model]\ntype = 'coulomb'\n",
     ["unknown top-level key 'model'"]),
    ("no-data-table", "[record]\nfile = 'run1.tsv'\n", ["unknown top-level key 'record'"]),
    ("empty", "", ["no [data] table"]),
    ("no-file", tomli_w.dumps({"data": {k: v for k, v in DESCRIPTION.items() if k != "file"}}),
     ["'data.file'", "missing"]),
    ("file-not-text", description_text(file=3), ["'data.file'", "3"]),
    ("long-delimiter", description_text(delimiter="\\t"), ["'data.delimiter'", "one character"]),
    ("unknown-column-key", description_text(columns={**DESCRIPTION["columns"], "y": "Y"}),
     ["unknown key 'data.columns.y'"]),
    ("no-time", description_text(columns={"x": "Position [mm]", "F": "Friction [uN]"},
                                 units={}, zero=[], window=None),
     ["'data.columns'", "no 't'"]),
    ("both-x-and-v", description_text(columns={**DESCRIPTION["columns"], "v": "Speed"}),
     ["'data.columns.x'", "'data.columns.v'", "both"]),
    ("neither-x-nor-v", description_text(columns={"t": "Time [ms]", "F": "Friction [uN]"},
                                         units={"t": "ms"}, zero=[]),
     ["'data.columns'", "neither 'x' nor 'v'"]),
    ("column-twice", description_text(columns={**DESCRIPTION["columns"],
                                               "normal_load": "Friction [uN]"}),
     ["'data.columns.normal_load'", "'Friction [uN]'", "data.columns.F"]),
    ("column-not-text", description_text(columns={**DESCRIPTION["columns"], "F": 4}),
     ["'data.columns.F'", "4"]),
    ("unit-of-unknown-column", description_text(units={"Friction [uN]": "uN"}),
     ["'data.units.Friction [uN]'", "not a column of data.columns", "record's names"]),
    ("not-a-unit", description_text(units={**DESCRIPTION["units"], "x": "furlongz"}),
     ["'data.units.x'", "'furlongz' is not a unit", "length"]),
    ("force-in-mm", description_text(units={**DESCRIPTION["units"], "F": "mm"}),
     ["'data.units.F'", "'mm' is a length", "expected a force unit"]),
    ("time-in-newton", description_text(units={**DESCRIPTION["units"], "t": "N"}),
     ["'data.units.t'", "'N' is a force", "expected a time unit"]),
    ("load-in-kelvin", description_text(units={**DESCRIPTION["units"], "normal_load": "K"}),
     ["'data.units.normal_load'", "'K' is of dimension", "temperature", "force"]),
    ("unit-not-text", description_text(units={**DESCRIPTION["units"], "x": 1e-3}),
     ["'data.units.x'", "0.001"]),
    ("sign-two", description_text(sign={"F": 2}), ["'data.sign.F'", "expected 1 or -1", "2"]),
    ("sign-text", description_text(sign={"F": "-"}), ["'data.sign.F'", "expected 1 or -1"]),
    ("sign-of-unknown-column", description_text(sign={"Friction": -1}),
     ["'data.sign.Friction'", "not a column"]),
    ("time-backwards", description_text(sign={"t": -1}), ["'data.sign.t'", "forward"]),
    ("zero-unknown", description_text(zero=["Position [mm]"]),
     ["'data.zero'", "'Position [mm]' is not a column"]),
    ("zero-not-a-list", description_text(zero="x"), ["'data.zero'", "a list"]),
    ("window-reversed", description_text(window=[1.8, 0.2]), ["'data.window'", "t0 < t1"]),
    ("window-one-number", description_text(window=[0.2]), ["'data.window'", "[t0, t1]"]),
    ("window-in-ms", description_text(window=[200.0, 1800.0]),
     ["'data.window'", "outside the record", "2.0 s"]),
    ("window-before-the-record", description_text(window=[-1.0, 1.0]),
     ["'data.window'", "outside the record"]),
    ("window-between-two-samples", description_text(window=[0.201, 0.2049]),
     ["'data.window'", "keeps 0 samples", "at least 2"]),
    ("column-not-in-the-file", description_text(columns={**DESCRIPTION["columns"],
                                                         "F": "Friction [mN]"}),
     ["'data.columns.F'", "run1.tsv", "has no column 'Friction [mN]'", "'Friction [uN]'"]),
    ("wrong-delimiter", description_text(delimiter=";"),
     ["'data.columns.t'", "has no column 'Time [ms]'", "data.delimiter"]),
    ("delimiter-of-parquet", description_text(file="run1.parquet"),
     ["'data.delimiter'", "Parquet"]),
    ("not-toml", "[data\nfile = 1\n", ["not valid TOML"]),
]


@pytest.mark.parametrize("text, fragments", [case[1:] for case in MISTAKES],
                         ids=[case[0] for case in MISTAKES])
def test_every_mistake_in_a_description_names_its_key(instrument, text, fragments):
    path, _ = instrument
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError) as caught:
        io.read_record(path)
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"{path}: "), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_a_required_column_the_description_does_not_name(instrument):
    path, _ = instrument
    columns = {key: value for key, value in DESCRIPTION["columns"].items() if key != "F"}
    write_description(path, columns=columns, sign={},
                      units={key: unit for key, unit in DESCRIPTION["units"].items() if key != "F"})
    assert "F" not in io.read_record(path)
    with pytest.raises(InputError, match=r"^\S+run1\.toml: key 'data\.columns': no 'F'"):
        io.read_record(path, **io.MEASUREMENT_COLUMNS)


def test_the_data_file_is_named_for_its_own_mistakes(instrument):
    path, record = instrument
    data = path.parent / "run1.tsv"
    data.unlink()
    with pytest.raises(InputError, match=f"^{path}: key 'data.file': {data}: no such file; "):
        io.read_record(path)
    lines = write_instrument_file(data, record).read_text().splitlines()
    lines[5] = lines[5].replace(lines[5].split("\t")[3], "12,5")        # friction at row 6
    data.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=f"^{data}: row 6, column 'Friction \\[uN\\]': "
                                         f"expected a number, got '12,5'$"):
        io.read_record(path)
    lines = write_instrument_file(data, record).read_text().splitlines()
    lines[100] = lines[99]                                               # time repeated
    data.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=f"^{data}: row 101, column 'Time \\[ms\\]': "
                                         "expected values that increase strictly"):
        io.read_record(path)


def test_values_outside_the_window_are_not_judged(instrument):
    path, record = instrument
    data = path.parent / "run1.tsv"
    spoilt = {**record, "normal_load": record["normal_load"].copy(), "F": record["F"].copy()}
    spoilt["normal_load"][:5] = -1e-3           # the unloaded start, before 0.2 s
    spoilt["F"][-3:] = np.nan                   # after 1.8 s
    write_instrument_file(data, spoilt)
    assert_record(io.read_record(path), expected(record))
    spoilt["normal_load"][200] = 0.0            # at 1.0 s: kept
    write_instrument_file(data, spoilt)
    with pytest.raises(InputError, match=f"^{data}: row 202, column 'Normal \\[uN\\]': "
                                         "expected a positive normal load, got 0.0"):
        io.read_record(path)
    spoilt["normal_load"][200] = 5.0
    spoilt["x"][150] = np.inf
    write_instrument_file(data, spoilt)
    with pytest.raises(InputError, match=f"^{data}: row 152, column 'Position \\[mm\\]': "
                                         "expected a finite number"):
        io.read_record(path)


# --- the command line ---------------------------------------------------------------------

def model_file(tmp_path, **changes):
    path = tmp_path / "start.toml"
    path.write_text(tomli_w.dumps({"model": {**TRUTH, "coulomb_force": 2.0, **changes},
                                   "fit": {"free": ["coulomb_force"]}}))
    return path


def test_fit_compare_and_simulate_take_a_description(instrument, capsys):
    path, record = instrument
    folder = path.parent
    start = model_file(folder)
    status, _, err = run(capsys, "fit", start, "--data", path, "-o", folder / "fitted.toml",
                         "--holdout", "0.25")
    assert status == 0, err
    fitted = tomllib.loads((folder / "fitted.toml").read_text())
    assert fitted["model"]["coulomb_force"] == pytest.approx(1.0, rel=1e-3)
    assert fitted["fit"]["result"]["holdout_rms_error"] < 1e-3

    status, out, err = run(capsys, "compare", start, "--data", path, "--holdout", "0.25",
                           "-o", folder / "table.csv")
    assert status == 0, err
    assert (folder / "table.csv").read_text().startswith("model,free_parameters,")

    status, _, err = run(capsys, "simulate", folder / "fitted.toml", "--input", path,
                         "-o", folder / "out.csv")
    assert status == 0, err
    simulated = io.read_csv_columns(folder / "out.csv", require=("t", "x", "v", "F"))
    want = expected(record)
    np.testing.assert_allclose(simulated["t"], want["t"], rtol=1e-14)
    np.testing.assert_allclose(simulated["x"], want["x"], rtol=1e-14, atol=1e-18)
    again = polind.simulate(polind.load_model(folder / "fitted.toml"), want["t"], x=want["x"])
    np.testing.assert_allclose(simulated["F"], again.force, rtol=1e-12)
    np.testing.assert_allclose(simulated["F"][1:], want["F"][1:], rtol=1e-3)


@pytest.mark.parametrize("command", ["fit", "compare", "simulate"])
def test_a_bad_description_exits_2_naming_its_key_and_writes_nothing(instrument, capsys,
                                                                     command):
    path, _ = instrument
    write_description(path, units={**DESCRIPTION["units"], "F": "mm"})
    out = path.parent / ("out.csv" if command != "fit" else "fitted.toml")
    option = "--input" if command == "simulate" else "--data"
    status, stdout, err = run(capsys, command, model_file(path.parent), option, path,
                              "-o", out)
    assert status == 2 and stdout == ""
    assert err.count("\n") == 1 and err.startswith(f"polind: error: {path}: "), err
    assert "'data.units.F'" in err and "'mm' is a length" in err
    assert not out.exists()


def test_an_output_onto_the_described_file_is_refused(instrument, capsys):
    path, _ = instrument
    data = path.parent / "run1.tsv"
    before = data.read_bytes()
    status, _, err = run(capsys, "simulate", model_file(path.parent), "--input", path,
                         "-o", data)
    assert status == 2 and "run1.tsv" in err, err
    assert data.read_bytes() == before


# --- the documentation shows what polind reads ----------------------------------------------

def test_the_readme_and_the_guide_show_files_polind_reads():
    import re
    from pathlib import Path

    from polind import datasets

    root = Path(__file__).resolve().parents[1]
    shipped = tomllib.loads(datasets.tribometer_description_path().read_text(encoding="utf-8"))
    readme = (root / "README.md").read_text(encoding="utf-8")
    blocks = [tomllib.loads(block) for block in re.findall(r"```toml\n(.*?)```", readme, re.S)
              if block.startswith("[data]")]
    assert blocks == [shipped]
    guide = (root / "docs" / "guide" / "identification.rst").read_text(encoding="utf-8")
    models = {}
    for block in re.findall(r"\.\. code-block:: toml\n\n((?:   .*\n|\n)+)", guide):
        text = "\n".join(line[3:] for line in block.splitlines())
        name = re.match(r"\s*# (\S+)\.toml\n", text)
        if name:
            models[name.group(1)] = polind.model_from_dict(tomllib.loads(text))
    assert {label: model.type for label, model in models.items()} == {
        "lugre": "lugre", "gms": "gms", "maxwell-slip": "maxwell-slip", "pol-ind": "pol-ind"}
