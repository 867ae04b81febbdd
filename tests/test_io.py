"""Tests of polind.io: model, system and motion files, and the atomic writers."""

from __future__ import annotations

import json
import os
import stat

import numpy as np
import pytest

from polind import io
from polind.errors import InputError
from polind.io import output, table_output

# One bad motion file per rule of INTERFACE.md / io.read_motion_csv: (id, content,
# fragments the one-line message must contain besides the file's path).  test_cli.py
# runs the same table through `polind simulate`.
BAD_MOTIONS = [
    ("empty", "", ["empty"]),
    ("blank-lines-only", "\n   \n\n", ["empty"]),
    ("header-only", "t,x\n", ["no data rows", "row 1"]),
    ("missing-t", "x,v\n0,0\n1,1\n", ["missing column 't'"]),
    ("neither-x-nor-v", "t,normal_load\n0,1\n1,1\n", ["'x'", "'v'", "exactly one"]),
    ("both-x-and-v", "t,x,v\n0,0,0\n1,1,1\n", ["doubled motion column", "'x'", "'v'"]),
    ("duplicated-column", "t,x,x\n0,0,0\n1,1,1\n", ["duplicated column 'x'"]),
    ("unknown-column", "t,x,F\n0,0,0\n1,1,1\n",
     ["unknown column 'F'", "t, x, v, normal_load"]),
    ("unnamed-column", "t,,x\n0,0,0\n1,1,1\n", ["row 1", "column 2", "no name"]),
    ("too-many-fields", "t,x\n0,0\n1,2,3\n", ["row 3", "expected 2", "got 3"]),
    ("too-few-fields", "t,x\n0,0\n1\n", ["row 3", "expected 2", "got 1"]),
    ("text-in-number", "t,x\n0,0\n0.5,1\n1,abc\n",
     ["row 4, column 'x'", "expected a number", "'abc'"]),
    ("empty-field", "t,x\n0,0\n1,\n", ["row 3, column 'x'", "expected a number"]),
    ("nan", "t,x\n0,0\n1,nan\n", ["row 3, column 'x'", "finite", "nan"]),
    ("inf-time", "t,x\n0,0\ninf,1\n", ["row 3, column 't'", "finite", "inf"]),
    ("negative-inf-load", "t,x,normal_load\n0,0,1\n1,1,-inf\n",
     ["row 3, column 'normal_load'", "finite"]),
    ("non-positive-load", "t,x,normal_load\n0,0,1\n1,1,0\n",
     ["row 3, column 'normal_load'", "positive"]),
    ("repeated-time", "t,x\n0,0\n1,1\n1,2\n", ["row 4, column 't'", "increase", "row 3"]),
    ("decreasing-time", "t,v\n0,0\n2,1\n1,2\n", ["row 4, column 't'", "increase"]),
    ("rows-counted-as-lines", "t,x\n\n0,0\n\n1,zz\n", ["row 5, column 'x'", "'zz'"]),
    ("one-row", "t,x\n0,0\n", ["at least 2", "got 1"]),
    ("not-utf8", b"t,x\n0,0\n\xff,1\n", ["row 3", "UTF-8"]),
]


def write_file(path, content):
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    return path


def assert_names(message, path, fragments):
    assert "\n" not in message
    assert message.startswith(f"{path}: "), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


# --- motion and data CSV -------------------------------------------------------------------

@pytest.mark.parametrize("content, fragments", [case[1:] for case in BAD_MOTIONS],
                         ids=[case[0] for case in BAD_MOTIONS])
def test_bad_motion_names_file_and_row_or_column(tmp_path, content, fragments):
    path = write_file(tmp_path / "motion.csv", content)
    with pytest.raises(InputError) as error:
        io.read_motion_csv(path)
    assert_names(str(error.value), path, fragments)


def test_missing_and_directory_motion_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        io.read_motion_csv(tmp_path / "absent.csv")
    with pytest.raises(InputError, match="is a directory"):
        io.read_motion_csv(tmp_path)


def test_motion_columns_whitespace_blank_lines_crlf_and_bom(tmp_path):
    path = write_file(tmp_path / "m.csv",
                      b"\xef\xbb\xbf t , v ,normal_load\r\n0, 1e-3 ,10\r\n\r\n 0.5,-2.5e-3, 12\r\n")
    motion = io.read_motion_csv(path)
    assert list(motion) == ["t", "v", "normal_load"]
    np.testing.assert_array_equal(motion["t"], [0.0, 0.5])
    np.testing.assert_array_equal(motion["v"], [1e-3, -2.5e-3])
    np.testing.assert_array_equal(motion["normal_load"], [10.0, 12.0])
    assert all(column.dtype == np.float64 and column.flags.c_contiguous
               for column in motion.values())


# A spreadsheet's ways of writing a table: each must read as the plain file does.
SPREADSHEET_FORMS = {
    "quoted-numbers": b'"t","x","F"\n"0","1.5","-2e-3"\n"0.5", "2.5" ,"1e-3"\n',
    "quoted-numbers-unquoted-header": b't,x,F\n"0","1.5","-2e-3"\n0.5,"2.5",1e-3\n',
    "byte-order-mark": b"\xef\xbb\xbft,x,F\n0,1.5,-2e-3\n0.5,2.5,1e-3\n",
    "crlf": b"t,x,F\r\n0,1.5,-2e-3\r\n0.5,2.5,1e-3\r\n",
    "blank-trailing-lines": b"t,x,F\n0,1.5,-2e-3\n0.5,2.5,1e-3\n\n\n\n",
    "blank-trailing-crlf-lines": b"t,x,F\r\n0,1.5,-2e-3\r\n0.5,2.5,1e-3\r\n\r\n\r\n",
    "all-at-once": b'\xef\xbb\xbf"t","x","F"\r\n"0","1.5","-2e-3"\r\n"0.5","2.5","1e-3"\r\n\r\n',
}


@pytest.mark.parametrize("reader", ["careful", "fast"])
@pytest.mark.parametrize("form", sorted(SPREADSHEET_FORMS))
def test_tables_as_spreadsheets_write_them(tmp_path, monkeypatch, form, reader):
    if reader == "fast":           # every file, however small, to pyarrow's reader first
        monkeypatch.setattr(io.tables, "_FAST_READ_BYTES", 0)
    path = write_file(tmp_path / "data.csv", SPREADSHEET_FORMS[form])
    data = io.read_motion_csv(path, **io.MEASUREMENT_COLUMNS)
    assert list(data) == ["t", "x", "F"]
    np.testing.assert_array_equal(data["t"], [0.0, 0.5])
    np.testing.assert_array_equal(data["x"], [1.5, 2.5])
    np.testing.assert_array_equal(data["F"], [-2e-3, 1e-3])


def test_a_quoted_field_that_is_not_a_number_names_its_row(tmp_path):
    path = write_file(tmp_path / "data.csv", 't,x\n"0","1"\n"1","1,5"\n')
    with pytest.raises(InputError) as error:
        io.read_motion_csv(path)
    assert_names(str(error.value), path, ["row 3, column 'x'", "expected a number", "'1,5'"])


def test_motion_values_read_to_the_bit(tmp_path):
    values = np.random.default_rng(1).normal(size=50) * 10.0 ** np.arange(-25, 25)
    text = "t,x\n" + "".join(f"{k},{float(value)!r}\n" for k, value in enumerate(values))
    motion = io.read_motion_csv(write_file(tmp_path / "m.csv", text))
    assert motion["x"].tobytes() == values.tobytes()


def test_measured_data_columns_for_fit(tmp_path):
    good = write_file(tmp_path / "data.csv", "t,x,F\n0,0,0.1\n1,1e-6,0.2\n")
    data = io.read_motion_csv(good, **io.MEASUREMENT_COLUMNS)
    np.testing.assert_array_equal(data["F"], [0.1, 0.2])
    missing = write_file(tmp_path / "nof.csv", "t,x\n0,0\n1,1\n")
    with pytest.raises(InputError) as error:
        io.read_motion_csv(missing, **io.MEASUREMENT_COLUMNS)
    assert_names(str(error.value), missing, ["missing column 'F'"])


def test_heights_file(tmp_path):
    path = write_file(tmp_path / "summits.csv", "h\n1e-6\n-2e-7\n")
    np.testing.assert_array_equal(io.read_heights_csv(path), [1e-6, -2e-7])
    bad = write_file(tmp_path / "bad.csv", "h\n1e-6\nx\n")
    with pytest.raises(InputError, match=r"row 3, column 'h'"):
        io.read_heights_csv(bad)


# --- CSV writing and atomic writes ---------------------------------------------------------

def test_write_csv_full_precision_round_trip(tmp_path):
    rng = np.random.default_rng(0)
    columns = {"t": np.cumsum(rng.random(40)),
               "x": rng.normal(size=40) * 10.0 ** rng.integers(-300, 300, 40),
               "F": np.array([0.1, -0.0, 5e-324, 1.7976931348623157e308] * 10)}
    path = tmp_path / "out.csv"
    io.write_csv_atomic(path, columns)
    lines = path.read_text().splitlines()
    assert lines[0] == "t,x,F"
    table = np.array([[float(field) for field in line.split(",")] for line in lines[1:]])
    for index, values in enumerate(columns.values()):
        assert table[:, index].tobytes() == values.tobytes()


def test_rows_formatted_in_chunks_join_seamlessly():
    table = np.random.default_rng(2).normal(size=(20, 3))
    chunked = "".join(table_output._format_rows(table, rows_per_chunk=7))
    assert chunked == "".join(table_output._format_rows(table))
    assert list(table_output._format_rows(np.empty((0, 3)))) == []


def test_write_csv_rejects_ragged_columns(tmp_path):
    with pytest.raises(ValueError, match="one length"):
        io.write_csv_atomic(tmp_path / "out.csv", {"t": [0.0, 1.0], "F": [1.0]})
    assert not (tmp_path / "out.csv").exists()


@pytest.mark.parametrize("existing", [None, "old content\n"])
def test_failed_write_leaves_nothing_and_keeps_old_file(tmp_path, monkeypatch, existing):
    path = tmp_path / "out.csv"
    if existing is not None:
        path.write_text(existing)

    def rows_then_failure(table):
        yield "0,1\n0.5,"  # half a table, then the failure
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(table_output, "_format_rows", rows_then_failure)
    with pytest.raises(RuntimeError, match="disk on fire"):
        io.write_csv_atomic(path, {"t": [0.0, 0.5], "F": [1.0, 2.0]})
    assert sorted(os.listdir(tmp_path)) == ([] if existing is None else ["out.csv"])
    if existing is not None:
        assert path.read_text() == existing


def test_os_error_while_writing_is_input_error_and_leaves_nothing(tmp_path, monkeypatch):
    path = tmp_path / "out.txt"

    def fsync_fails(descriptor):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(output.os, "fsync", fsync_fails)
    with pytest.raises(InputError, match=r"out.txt: cannot write: No space left"):
        io.atomic_write_text(path, "hello\n")
    assert os.listdir(tmp_path) == []


def test_atomic_writers(tmp_path):
    io.atomic_write_text(tmp_path / "a.txt", "héllo\nworld\n")
    assert (tmp_path / "a.txt").read_bytes() == "héllo\nworld\n".encode()
    io.atomic_write_bytes(tmp_path / "b.bin", b"\x00\x01")
    assert (tmp_path / "b.bin").read_bytes() == b"\x00\x01"
    io.atomic_write_bytes(tmp_path / "b.bin", b"new")  # replaces
    assert (tmp_path / "b.bin").read_bytes() == b"new"
    assert sorted(os.listdir(tmp_path)) == ["a.txt", "b.bin"]


def test_new_file_gets_umask_permissions_and_old_file_keeps_its_own(tmp_path):
    umask = os.umask(0o022)
    try:
        io.atomic_write_text(tmp_path / "new.txt", "x")
        assert stat.S_IMODE(os.stat(tmp_path / "new.txt").st_mode) == 0o644
        os.chmod(tmp_path / "new.txt", 0o600)
        io.atomic_write_text(tmp_path / "new.txt", "y")
        assert stat.S_IMODE(os.stat(tmp_path / "new.txt").st_mode) == 0o600
    finally:
        os.umask(umask)


def test_output_path_checks(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        io.write_csv_atomic(tmp_path / "no" / "out.csv", {"t": [0.0]})
    with pytest.raises(InputError, match="is a directory"):
        io.atomic_write_text(tmp_path, "x")
    io.check_output_path(tmp_path / "fine.csv")
    assert os.listdir(tmp_path) == []


# --- model files ----------------------------------------------------------------------------

COULOMB_TOML = '[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n'


def test_read_model_file_toml_json_and_other_extension(tmp_path):
    expected = {"model": {"type": "coulomb", "coulomb_force": 1.0}}
    assert io.read_model_file(write_file(tmp_path / "m.toml", COULOMB_TOML)) == expected
    assert io.read_model_file(write_file(tmp_path / "m.json", json.dumps(expected))) == expected
    assert io.read_model_file(write_file(tmp_path / "m.model", COULOMB_TOML)) == expected
    with_fit = COULOMB_TOML + '[fit]\nfree = ["coulomb_force"]\n'
    assert io.read_model_file(write_file(tmp_path / "f.toml", with_fit))["fit"] == {
        "free": ["coulomb_force"]}


BAD_MODEL_FILES = [
    ("toml-syntax", "m.toml", '[model]\ntype = "coulomb"\ncoulomb_force = \n',
     ["not valid TOML", "line 3"]),
    ("json-syntax", "m.json", '{"model": {"type": "coulomb",\n "coulomb_force": }}',
     ["not valid JSON", "line 2"]),
    ("json-duplicate-key", "m.json", '{"model": {"type": "coulomb", "type": "dahl"}}',
     ["duplicated key 'type'"]),
    ("json-not-object", "m.json", "[1, 2]", ["JSON object"]),
    ("no-model-table", "m.toml", "[modle]\ntype = 'coulomb'\n", ["'modle'"]),
    ("empty-file", "m.toml", "", ["no [model] table"]),
    ("model-not-table", "m.toml", "model = 3\n", ["'model' must be a table", "3"]),
    ("fit-not-table", "m.toml", COULOMB_TOML.replace("[model]", "fit = 1\n[model]"),
     ["'fit' must be a table"]),
    ("unknown-top-level", "m.toml", "extra = 1\n" + COULOMB_TOML, ["'extra'"]),
    ("not-utf8", "m.toml", b"[model]\ntype = '\xff'\n", ["row 2", "UTF-8"]),
]


@pytest.mark.parametrize("filename, content, fragments", [case[1:] for case in BAD_MODEL_FILES],
                         ids=[case[0] for case in BAD_MODEL_FILES])
def test_bad_model_file_names_file(tmp_path, filename, content, fragments):
    path = write_file(tmp_path / filename, content)
    with pytest.raises(InputError) as error:
        io.read_model_file(path)
    assert_names(str(error.value), path, fragments)


def test_missing_model_file(tmp_path):
    with pytest.raises(InputError) as error:
        io.read_model_file(tmp_path / "absent.toml")
    assert_names(str(error.value), tmp_path / "absent.toml", ["no such file"])


def test_relative_heights_file_is_resolved_against_the_model_file(tmp_path, monkeypatch):
    (tmp_path / "models").mkdir()
    text = '[model]\ntype = "pol-ind"\n[model.discretisation]\nheights_file = "../summits.csv"\n'
    write_file(tmp_path / "models" / "m.toml", text)
    monkeypatch.chdir(tmp_path / "models")
    from polind.models import read_model_document

    assert io.read_model_file("m.toml")["model"]["discretisation"]["heights_file"] == \
        "../summits.csv"                                   # io reads the file as written
    document = read_model_document("m.toml")               # the model says which keys are files
    assert document["model"]["discretisation"]["heights_file"] == str(tmp_path / "summits.csv")
    absolute = text.replace("../summits.csv", "/data/s.csv")
    document = read_model_document(write_file(tmp_path / "a.toml", absolute))
    assert document["model"]["discretisation"]["heights_file"] == "/data/s.csv"


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_write_model_file_round_trip(tmp_path, suffix):
    document = {"model": {"type": "maxwell-slip", "stiffness": np.array([1.0, 2.5]),
                          "breakaway_force": (0.5, np.float64(0.25)), "unset": None,
                          "surface": {"height_std": np.float64(5e-7)}},
                "fit": {"free": ["stiffness"], "result": {"iterations": np.int64(7)}}}
    path = tmp_path / f"fitted{suffix}"
    io.write_model_file(path, document)
    assert io.read_model_file(path) == {
        "model": {"type": "maxwell-slip", "stiffness": [1.0, 2.5],
                  "breakaway_force": [0.5, 0.25], "surface": {"height_std": 5e-7}},
        "fit": {"free": ["stiffness"], "result": {"iterations": 7}}}


# --- system files ---------------------------------------------------------------------------

SYSTEM_TOML = """\
[system]
mass = 1.0
duration = 10.0
time_step = 1e-4

[system.spring_drive]
stiffness = 2.0
velocity = 0.1

[system.force]
offset = 0.5
rate = 0.0
amplitude = 0.4
frequency = 1.0
"""


def test_read_system_file_gives_the_table_as_written(tmp_path):
    # Keys and values are checked by polind.load_system (test_dynamics.py), once.
    system = io.read_system_file(write_file(tmp_path / "s.toml", SYSTEM_TOML))
    assert system == {"mass": 1.0, "duration": 10.0, "time_step": 1e-4,
                      "spring_drive": {"stiffness": 2.0, "velocity": 0.1},
                      "force": {"offset": 0.5, "rate": 0.0, "amplitude": 0.4,
                                "frequency": 1.0}}


# (id, replacements (old, new) applied to SYSTEM_TOML, fragments of the message)
BAD_SYSTEM_FILES = [
    ("unknown-top-level", [("[system]\n", "[model]\n[system]\n")], ["'model'"]),
    ("no-system", [("[system]\n", "[sistem]\n")], ["'sistem'"]),
    ("not-toml", [("mass = 1.0", "mass = = 1.0")], ["not valid TOML"]),
]


@pytest.mark.parametrize("replacements, fragments", [case[1:] for case in BAD_SYSTEM_FILES],
                         ids=[case[0] for case in BAD_SYSTEM_FILES])
def test_bad_system_file_names_the_file(tmp_path, replacements, fragments):
    text = SYSTEM_TOML
    for old, new in replacements:
        assert old in text
        text = text.replace(old, new, 1)
    path = write_file(tmp_path / "system.toml", text)
    with pytest.raises(InputError) as error:
        io.read_system_file(path)
    assert_names(str(error.value), path, fragments)


