"""Round three of "nothing lost" (issue 44): tables of any row length and padding, wide
instrument files at pyarrow's speed, unit conversions that overflow, a data description's
missing file, a velocity record without displacement.

References, each independent of the code under test:
- the numbers written here (``repr`` of each float, read back bit for bit), the rows and
  columns counted here;
- ``pyarrow.csv.read_csv`` on the same file, in the same process (the speed of a wide file
  is a ratio to it, not a time);
- overflow decided by plain float arithmetic on unit factors written out here
  (1 YN = 1e24 N, 1 EN = 1e18 N);
- the trapezoidal integral of ``v = +a, -a, +a...`` on a uniform grid, which is 0 at every
  sample.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import polind
from polind import io
from polind.errors import InputError
from polind.identification import default_bounds
from polind.io import sizing, tables

try:
    from test_cli import no_debug, run, the_one_error_line  # noqa: F401 - autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run, the_one_error_line  # noqa: F401

CHEAP = settings(max_examples=12, deadline=None, database=None,
                 suppress_health_check=[HealthCheck.function_scoped_fixture,
                                        HealthCheck.too_slow])


def write_rows(path, header, rows, newline="\n", padding=0, delimiter=","):
    """A table as a logger writes it: a header, rows of fields, then ``padding`` NULs."""
    text = newline.join([delimiter.join(header), *(delimiter.join(row) for row in rows)])
    path.write_bytes((text + newline).encode() + b"\0" * padding)
    return path


def write_description(path, file, columns, **keys):
    lines = ["[data]", f'file = "{file}"',
             "columns = { " + ", ".join(f'{key} = "{name}"' for key, name in columns.items())
             + " }"]
    for key, table in keys.items():
        lines.append(f"{key} = {{ " + ", ".join(f'{k} = {v!r}' for k, v in table.items())
                     + " }")
    path.write_text("\n".join(lines) + "\n")
    return path


def check_size(path, rows, columns):
    """table_size of a file: its columns, and its rows exactly or to within the estimate."""
    estimate, counted, exact = sizing.table_size(path)
    assert counted == columns
    if exact:
        assert estimate == rows
    else:
        assert 0.8 * rows <= estimate <= 1.25 * rows + 1, (estimate, rows)


# --- 1. any row length, any padding ------------------------------------------------------------

@CHEAP
@given(rows=st.integers(2, 60), zeros=st.integers(0, 9000), padding=st.integers(0, 100_000),
       newline=st.sampled_from(["\n", "\r\n"]))
@example(rows=40, zeros=5000, padding=0, newline="\n")           # rows of 5 KB
@example(rows=3, zeros=0, padding=100_000, newline="\r\n")       # a preallocated file
def test_a_motion_file_of_any_row_length_and_padding_reads(tmp_path_factory, rows, zeros,
                                                           padding, newline):
    """Rows made long by leading zeros (``000…1.5`` is 1.5), then NUL padding."""
    t = np.arange(rows) * 0.25
    x = np.arange(rows) * 1e-6 + 0.5
    fields = [("0" * zeros + repr(float(a)), repr(float(b))) for a, b in zip(t, x)]
    path = write_rows(tmp_path_factory.mktemp("m") / "motion.csv", ("t", "x"), fields,
                      newline, padding)
    check_size(path, rows, 2)
    motion = io.read_motion_csv(path)
    np.testing.assert_array_equal(motion["t"], t)
    np.testing.assert_array_equal(motion["x"], x)
    np.testing.assert_array_equal(io.read_record(path)["x"], x)


@CHEAP
@given(columns=st.integers(3, 700), rows=st.integers(2, 30), padding=st.integers(0, 100_000),
       delimiter=st.sampled_from([",", "\t", ";"]), seed=st.integers(0, 2 ** 32 - 1))
@example(columns=602, rows=30, padding=0, delimiter="\t", seed=0)
@example(columns=602, rows=20, padding=70_000, delimiter=";", seed=1)
def test_a_wide_instrument_file_reads_through_a_description(tmp_path_factory, columns, rows,
                                                            padding, delimiter, seed):
    """602 channels (rows over 4 KiB, files over 64 KiB) and a preallocated file's padding."""
    folder = tmp_path_factory.mktemp("wide")
    values = np.random.default_rng(seed).normal(size=(rows, columns))
    values[:, 0] = np.arange(rows) * 1e-3
    header = ["Time [s]", "Position [mm]", *(f"Channel {k} [V]" for k in range(columns - 2))]
    write_rows(folder / "run.tsv", header, [[repr(float(v)) for v in row] for row in values],
               padding=padding, delimiter=delimiter)
    check_size(folder / "run.tsv", rows, columns)
    description = write_description(
        folder / "run.toml", "run.tsv",
        {"t": "Time [s]", "x": "Position [mm]", "F": header[-1]}, units={"x": "mm"})
    record = io.read_record(description, **io.MEASUREMENT_COLUMNS)
    np.testing.assert_array_equal(record["t"], values[:, 0])
    np.testing.assert_array_equal(record["x"], values[:, 1] * 1e-3)
    np.testing.assert_array_equal(record["F"], values[:, -1])


def test_a_big_padded_wide_file_goes_through_the_fast_reader(tmp_path, monkeypatch):
    """Over 1 MiB: pyarrow reads the rows before the padding; Python's reader is not used."""
    values = np.random.default_rng(1).normal(size=(300, 602))
    values[:, 0] = np.arange(300) * 1e-3
    header = ["t", "x", *(f"c{k}" for k in range(600))]
    write_rows(tmp_path / "run.tsv", header, [[repr(float(v)) for v in row] for row in values],
               padding=3 << 20, delimiter="\t")

    def refuse(*args, **kwargs):
        raise AssertionError("read row by row")

    monkeypatch.setattr(tables, "_read_csv_carefully", refuse)
    description = write_description(tmp_path / "run.toml", "run.tsv",
                                    {"t": "t", "x": "x", "F": "c599"})
    record = io.read_record(description, **io.MEASUREMENT_COLUMNS)
    np.testing.assert_array_equal(record["F"], values[:, -1])
    check_size(tmp_path / "run.tsv", 300, 602)


@pytest.mark.parametrize("rows", [3, 90_000])         # Python's reader, then pyarrow's
def test_a_row_the_padding_cuts_short_is_named(tmp_path, rows):
    """A logger stopped mid-row: '…\\n5,3.' then NULs; 3. is not the number it was writing."""
    path = tmp_path / "motion.csv"
    body = "t,x\n" + "".join(f"{k},{k}e-6\n" for k in range(rows))
    path.write_bytes(body.encode() + b"5e9,3." + b"\0" * 5000)
    with pytest.raises(InputError, match=rf"^{path}: row {rows + 2}: cut short by the NUL "
                                         rf"padding after it .*delete row {rows + 2}$"):
        io.read_motion_csv(path)
    check_size(path, rows + 1, 2)


@CHEAP
@given(where=st.floats(0.0, 1.0), count=st.integers(1, 100_000), rows=st.integers(2, 400))
@example(where=1.0, count=70_000, rows=3)                  # trailing padding past 64 KiB
def test_nul_bytes_anywhere_give_a_table_or_an_input_error(tmp_path_factory, where, count,
                                                           rows):
    """A NUL that is not trailing padding is text where a number was expected."""
    path = tmp_path_factory.mktemp("nul") / "motion.csv"
    data = ("t,x\n" + "".join(f"{k},{k}e-6\n" for k in range(rows))).encode()
    at = int(where * len(data))
    path.write_bytes(data[:at] + b"\0" * count + data[at:])
    sizing.table_size(path)
    try:
        motion = io.read_motion_csv(path)
    except InputError as error:
        assert str(error).startswith(f"{path}: ") and "\n" not in str(error)
    else:
        assert motion["t"].size >= 2 and np.all(np.isfinite(motion["x"]))


# --- 2. a wide file at pyarrow's speed ----------------------------------------------------------

def test_a_wide_tsv_reads_through_a_description_within_twice_pyarrow(tmp_path):
    """600 columns: the description's read against pyarrow.csv.read_csv of the same file."""
    import pyarrow.csv as pacsv

    rng = np.random.default_rng(2)
    header = ["Time [s]", "Position [mm]", "Friction [uN]", "Normal [uN]",
              *(f"Channel {k} [V]" for k in range(596))]
    rows = 1500
    values = np.round(rng.normal(size=(rows, 600)), 4)
    values[:, 0] = np.arange(rows) * 1e-3
    values[:, 3] = 5e6
    write_rows(tmp_path / "run.tsv", header, [[repr(float(v)) for v in row] for row in values],
               delimiter="\t")
    description = write_description(
        tmp_path / "run.toml", "run.tsv",
        {"t": "Time [s]", "x": "Position [mm]", "F": "Friction [uN]",
         "normal_load": "Normal [uN]"}, units={"x": "mm", "F": "uN", "normal_load": "uN"})
    options = pacsv.ParseOptions(delimiter="\t")
    record = io.read_record(description, **io.MEASUREMENT_COLUMNS)   # pint imported
    np.testing.assert_array_equal(record["normal_load"], np.full(rows, 5.0))
    ours, theirs = [], []
    for _ in range(3):
        start = time.perf_counter()
        pacsv.read_csv(tmp_path / "run.tsv", parse_options=options)
        theirs.append(time.perf_counter() - start)
        start = time.perf_counter()
        io.read_record(description, **io.MEASUREMENT_COLUMNS)
        ours.append(time.perf_counter() - start)
    assert min(ours) <= 2.0 * min(theirs), (ours, theirs)


# --- 3. a unit conversion that overflows ------------------------------------------------------

FACTORS = {"N": 1.0, "kN": 1e3, "EN": 1e18, "YN": 1e24}


@CHEAP
@given(exponent=st.integers(250, 307), unit=st.sampled_from(sorted(FACTORS)),
       sign=st.sampled_from([1, -1]), bad_row=st.integers(0, 4))
def test_a_conversion_to_infinity_is_an_input_error(tmp_path_factory, exponent, unit, sign,
                                                    bad_row):
    folder = tmp_path_factory.mktemp("units")
    force = [1.0, -2.0, 1.5, -1.0, 2.0]
    force[bad_row] = float(f"1e{exponent}")
    rows = [(repr(k * 0.5), repr(k * 1e-6), repr(f)) for k, f in enumerate(force)]
    write_rows(folder / "run.csv", ("Time", "Position", "Friction"), rows)
    description = write_description(
        folder / "run.toml", "run.csv", {"t": "Time", "x": "Position", "F": "Friction"},
        units={"F": unit}, sign={"F": sign})
    finite = math.isfinite(float(f"1e{exponent}") * FACTORS[unit])
    if finite:
        record = io.read_record(description, **io.MEASUREMENT_COLUMNS)
        assert np.all(np.isfinite(record["F"]))
        return
    with pytest.raises(InputError) as caught:
        io.read_record(description, **io.MEASUREMENT_COLUMNS)
    message = str(caught.value)
    assert message.startswith(f"{folder / 'run.csv'}: row {bad_row + 2}, column 'Friction': "
                              f"1e+{exponent} is {'-' if sign < 0 else ''}inf N in SI units "
                              f"(data.units.F = '{unit}'"), message
    assert "\n" not in message and str(description) in message


def test_times_a_conversion_makes_equal_are_an_input_error(tmp_path):
    """1e-320 ns and 2e-320 ns are both 0 s: the record's time would not increase."""
    write_rows(tmp_path / "run.csv", ("t", "x"), [("0", "0"), ("1e-320", "1"), ("2e-320", "0")])
    description = write_description(tmp_path / "run.toml", "run.csv", {"t": "t", "x": "x"},
                                    units={"t": "ns"})
    with pytest.raises(InputError, match=r"run\.csv: row 3, column 't': 1e-320 after 0\.0 on "
                                         r"row 2 is 0\.0 s after 0\.0 s in SI units"):
        io.read_record(description)


# --- 4. a missing data.file names the description's key ---------------------------------------

@pytest.mark.parametrize("name, problem", [("absent.tsv", "no such file"),
                                           (".", "is a directory")])
def test_a_missing_data_file_names_the_key_and_the_description(tmp_path, name, problem):
    description = write_description(tmp_path / "run.toml", name, {"t": "t", "x": "x"})
    with pytest.raises(InputError) as caught:
        io.read_record(description)
    assert str(caught.value).startswith(
        f"{description}: key 'data.file': {tmp_path / name}: {problem}; expected the "
        f"instrument's file"), caught.value


def test_the_command_line_names_the_key_of_a_missing_data_file(tmp_path, capsys):
    model = tmp_path / "coulomb.toml"
    model.write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    description = write_description(tmp_path / "run.toml", "absent.tsv", {"t": "t", "x": "x"})
    status, _, err = run(capsys, "simulate", model, "-i", description, "-o", tmp_path / "o.csv")
    assert status == 2
    assert the_one_error_line(err).startswith(f"polind: error: {description}: key 'data.file': ")
    assert not (tmp_path / "o.csv").exists()


# --- 5. a velocity record without displacement ------------------------------------------------

DAHL = {"model": {"type": "dahl", "coulomb_force": 1.0, "stiffness": 1e4}}


@CHEAP
@given(amplitude=st.floats(1e-12, 1e3), samples=st.integers(3, 40))
def test_a_velocity_that_integrates_to_no_displacement_is_refused(amplitude, samples):
    """v = +a, -a, +a...: the trapezoidal position is 0 at every sample."""
    t = np.arange(samples) * 0.01
    v = amplitude * (-1.0) ** np.arange(samples)
    data = {"t": t, "v": v, "F": 0.5 * np.sign(v)}
    with pytest.raises(InputError, match=r"^The 'v' samples integrate to a position that never "
                                         r"changes .*no displacement"):
        default_bounds(polind.model_from_dict(DAHL), data)


def test_a_scale_the_data_make_infinite_names_the_key():
    """Displacements too small for a float's speed: A / V is infinite, no range of it."""
    model = polind.model_from_dict({"model": {
        "type": "lugre", "bristle_stiffness": 1e5, "bristle_damping": 316.2,
        "viscous_coefficient": 0.4, "coulomb_force": 1.0, "static_force": 1.5,
        "stribeck_velocity": 1e-3}})
    data = {"t": np.arange(5) * 10.0, "x": np.array([0.0, 5e-324, 0.0, 5e-324, 0.0]),
            "F": np.array([1.0, -1.0, 1.0, -1.0, 1.0])}
    with pytest.raises(InputError, match=r"^The default bounds of 'viscous_coefficient' are "
                                         r"\[0\.001, 10\] x A / V .* which is inf N s/m in "
                                         r"these data: .*\[fit\.bounds\]"):
        default_bounds(model, data, free=["viscous_coefficient"])
    bounds = default_bounds(model, data, free=["coulomb_force"])      # A alone is a scale
    assert bounds == {"coulomb_force": (1e-3, 10.0)}
