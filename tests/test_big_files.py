"""Big files at disk speed (issue 14, item 5): pyarrow's C reader and writer, Parquet, and
the memory `simulate` holds.

The fast CSV reader must agree with the careful Python reader on every value and every
message; the fast writer must write the text of the Python formatter; Parquet files
follow the rules of CSV ones.  benchmarks/big_files.py measures the 1e7-sample case.
"""

from __future__ import annotations

import importlib
import os
import sys
import threading
import tracemalloc

import numpy as np
import pytest

import polind
from polind import io
from polind.cli import _run
from polind.errors import InputError
from polind.io import table_output, tables

from conftest import lib, representative
from test_io import BAD_MOTIONS

simulate_module = importlib.import_module("polind.simulation")

MAXWELL_SLIP = ('[model]\ntype = "maxwell-slip"\nstiffness = [1e5, 5e4, 2e4, 1e4]\n'
                'breakaway_force = [0.2, 0.3, 0.25, 0.25]\n')


def write_file(path, content):
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, newline="")
    return path


def outcome(read, path):
    """What a reader makes of a file: its columns (as bytes, to compare bit for bit) or
    its message."""
    try:
        table = read(path)
    except InputError as error:
        return "error", str(error)
    return "table", {column: values.tobytes() for column, values in table.items()}


def careful(path, **kwargs):
    """read_motion_csv by Python's reader alone."""
    original = tables._read_csv_fast
    tables._read_csv_fast = lambda *args, **kw: None
    try:
        return io.read_motion_csv(path, **kwargs)
    finally:
        tables._read_csv_fast = original


@pytest.fixture
def fast_reader(monkeypatch):
    """Every file, however small, goes to pyarrow's reader first."""
    monkeypatch.setattr(tables, "_FAST_READ_BYTES", 0)


# --- the fast CSV reader agrees with the careful one --------------------------------------

TRICKY_MOTIONS = [
    ("crlf-bom-whitespace", b"\xef\xbb\xbf t , x \r\n0, 1e-3 \r\n\r\n 0.5,\t-2.5e-3\r\n"),
    ("lone-cr", b"t,x\r0,0\r1,1\r"),
    ("blank-lines-then-repeated-time", "t,x\n\n0,0\n\n\n1,1\n\n1,2\n"),
    ("blank-lines-then-decreasing-time", "\n\nt,v\n\n0,0\n2,1\n\n1,2\n"),
    ("blank-lines-then-zero-load", "t,x,normal_load\n\n0,0,1\n\n1,1,0\n"),
    ("whitespace-only-line", "t,x\n0,0\n   \n1,1\n"),
    ("tab-only-line", "t,x\n0,0\n\t\n1,2\n"),
    ("quoted-number", 't,x\n0,0\n"1",1\n'),
    ("quoted-header-and-numbers", '"t","x"\r\n"0","0"\r\n"1","1"\r\n\r\n'),
    ("quoted-with-spaces", 't,x\n0,0\n "1" , "2" \n'),
    ("quoted-decimal-comma", 't,x\n0,0\n1,"1,5"\n'),
    ("quoted-empty", 't,x\n0,0\n1,""\n'),
    ("unterminated-quote", 't,x\n0,0\n1,"1\n2,2\n'),
    ("doubled-quotes", 't,x\n0,0\n1,""1""\n'),
    ("underscore", "t,x\n0,0\n1_000,1\n"),
    ("nan-with-payload", "t,x\n0,0\n1,nan(1)\n"),
    ("nan-before-bad-text", "t,x\n0,nan\n1,1\n2,abc\n"),
    ("infinity-spelled", "t,x\n0,0\n1,-Infinity\n"),
    ("overflowing-literal", "t,x\n0,0\n1,1e400\n"),
    ("underflowing-literal", "t,x\n0,0\n1,1e-400\n"),
    ("plus-signs-and-points", "t,x\n+0,.5\n1.,+2e+0\n"),
    ("arabic-indic-digit", "t,x\n0,0\n1,\u0663\n"),
    ("vertical-tab-around", "t,x\n0,0\n1,\x0b2\n"),
    ("no-final-newline", "t,x\n0,0\n1,1"),
    ("trailing-comma", "t,x\n0,0\n1,1,\n"),
    ("semicolons", "t;x\n0;0\n1;1\n"),
    ("nul-byte", b"t,x\n0,0\n1,\x001\n"),
    ("latin-1", b"t,x\n0,0\n1,\xe91\n"),
    ("long-digits", "t,x\n0,0\n1," + "1" * 400 + "\n"),
    ("header-after-many-blank-lines", "\n" * 70_000 + "t,x\n0,0\n1,1\n"),
    ("header-with-bom-and-space-names", b"\xef\xbb\xbf\r\n  t  ,  normal_load , v\r\n0,1,0\r\n1,2,1\r\n"),
]


@pytest.mark.parametrize("content", [case[1] for case in BAD_MOTIONS + TRICKY_MOTIONS],
                         ids=[case[0] for case in BAD_MOTIONS + TRICKY_MOTIONS])
def test_fast_reader_gives_the_careful_readers_values_and_messages(tmp_path, fast_reader,
                                                                    content):
    path = write_file(tmp_path / "motion.csv", content)
    assert outcome(io.read_motion_csv, path) == outcome(careful, path)


def test_tricky_cases_are_what_they_claim(tmp_path):
    # The cases above test something: the row numbers count blank lines, and some files
    # pass pyarrow and some do not.
    path = write_file(tmp_path / "m.csv", dict(TRICKY_MOTIONS)["blank-lines-then-repeated-time"])
    with pytest.raises(InputError, match=r"row 8, column 't'.* on row 6$"):
        careful(path)
    with pytest.raises(InputError, match=r"row 5, column 'normal_load'"):
        careful(write_file(tmp_path / "l.csv",
                           dict(TRICKY_MOTIONS)["blank-lines-then-zero-load"]))
    np.testing.assert_array_equal(
        careful(write_file(tmp_path / "a.csv", dict(TRICKY_MOTIONS)["arabic-indic-digit"]))["x"],
        [0.0, 3.0])


def test_fast_reader_is_used_for_well_formed_files(tmp_path, fast_reader, monkeypatch):
    path = write_file(tmp_path / "m.csv", "t,x,normal_load\n\n0,0,1\n0.5,1e-6,2\n\n1,2e-6,3\n")
    monkeypatch.setattr(tables, "_read_csv_carefully", None)        # would fail if called
    motion = io.read_motion_csv(path)
    np.testing.assert_array_equal(motion["x"], [0.0, 1e-6, 2e-6])
    assert all(values.flags.writeable and values.flags.c_contiguous and
               values.dtype == np.float64 for values in motion.values())


def big_motion(rows, seed=0):
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(1e-6, 1e-3, rows))
    x = rng.normal(size=rows) * 10.0 ** rng.integers(-300, 300, rows)
    return t, x


def motion_text(t, x):
    return "t,x\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist()))


def test_a_big_file_reads_to_the_bit_and_names_rows_past_blank_lines(tmp_path):
    t, x = big_motion(60_000)
    text = motion_text(t, x)
    path = write_file(tmp_path / "big.csv", text)
    assert path.stat().st_size >= tables._FAST_READ_BYTES
    motion = io.read_motion_csv(path)
    assert motion["t"].tobytes() == t.tobytes() and motion["x"].tobytes() == x.tobytes()

    lines = text.splitlines(keepends=True)
    # three blank lines early on, then sample 50,000 repeats the time of sample 49,999
    repeated = float(t[49_999])
    lines[50_001] = f"{repeated!r},0\n"
    lines[10:10] = ["\n", "\n", "\r\n"]
    bad = write_file(tmp_path / "bad.csv", "".join(lines))
    with pytest.raises(InputError) as error:
        io.read_motion_csv(bad)
    assert str(error.value) == (f"{bad}: row 50005, column 't': expected values that increase "
                                f"strictly, got {repeated!r} after {repeated!r} on row 50004")
    assert outcome(io.read_motion_csv, bad) == outcome(careful, bad)


def test_a_big_file_with_a_nan_is_named_as_written(tmp_path):
    t, x = big_motion(60_000)
    lines = motion_text(t, x).splitlines(keepends=True)
    lines[40_000] = f"{float(t[39_998])!r},NaN\n"
    path = write_file(tmp_path / "nan.csv", "".join(lines))
    with pytest.raises(InputError, match=r"row 40001, column 'x': expected a finite number"):
        io.read_motion_csv(path)


def test_read_progress_counts_bytes(tmp_path):
    t, x = big_motion(60_000)
    path = write_file(tmp_path / "big.csv", motion_text(t, x))
    calls = []
    io.read_motion_csv(path, progress=lambda done, total: calls.append((done, total)))
    size = path.stat().st_size
    assert calls[-1] == (size, size) and len(calls) >= 2
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)


# --- the writer ---------------------------------------------------------------------------

SPECIAL = [0.0, -0.0, 0.1, 1.0, -1.0, 1e-7, 1e-6, 9.999999999999999e-07, 3e9, 1e10,
           9999999999.999998, 1e21, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
           -2.5e-3, 1 / 3, 2.0 ** 53, float("nan"), float("inf"), float("-inf")]


def test_python_and_pyarrow_formatters_write_the_same_text(monkeypatch):
    rng = np.random.default_rng(3)
    bits = rng.integers(0, 2 ** 64, size=60_000, dtype=np.uint64).view(np.float64)
    decimals = rng.normal(size=20_000) * 10.0 ** rng.integers(-12, 13, 20_000)
    column = np.concatenate([np.array(SPECIAL), bits, decimals, -decimals])
    columns = [column, column[::-1].copy()]
    monkeypatch.setattr(table_output, "_FAST_WRITE_NUMBERS", 1 << 62)
    by_python = "".join(table_output._format_rows(columns, rows_per_chunk=10_000))
    monkeypatch.setattr(table_output, "_FAST_WRITE_NUMBERS", 0)
    by_pyarrow = "".join(table_output._format_rows(columns, rows_per_chunk=7_001))
    assert by_python == by_pyarrow
    back = np.array([[float(field) for field in line.split(",")]
                     for line in by_pyarrow.splitlines()])
    for index, values in enumerate(columns):
        same = (back[:, index].view(np.uint64) == values.view(np.uint64))
        assert (same | (np.isnan(back[:, index]) & np.isnan(values))).all()


def test_a_big_table_round_trips_to_the_bit(tmp_path):
    t, x = big_motion(50_000, seed=5)
    force = np.random.default_rng(6).integers(0, 2 ** 64, size=t.size, dtype=np.uint64) \
        .view(np.float64)
    force[~np.isfinite(force)] = -0.0
    path = tmp_path / "out.csv"
    calls = []
    io.write_csv_atomic(path, {"t": t, "x": x, "F": force},
                        progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (t.size, t.size)
    back = io.read_csv_columns(path, require=("t", "x", "F"))
    assert back["t"].tobytes() == t.tobytes()
    assert back["x"].tobytes() == x.tobytes()
    assert back["F"].tobytes() == force.tobytes()
    assert sorted(os.listdir(tmp_path)) == ["out.csv"]


def test_a_failing_big_write_leaves_nothing(tmp_path, monkeypatch):
    existing = tmp_path / "out.csv"
    existing.write_text("old\n")
    monkeypatch.setattr(table_output, "_ROWS_PER_CHUNK", 1000)
    calls = []

    def fail_midway(done, total):
        calls.append(done)
        if done >= 5000:
            raise RuntimeError("disk on fire")

    t, x = big_motion(20_000)
    with pytest.raises(RuntimeError, match="disk on fire"):
        io.write_csv_atomic(existing, {"t": t, "x": x}, progress=fail_midway)
    assert sorted(os.listdir(tmp_path)) == ["out.csv"] and existing.read_text() == "old\n"


# --- Parquet --------------------------------------------------------------------------------

def test_parquet_round_trip_to_the_bit(tmp_path):
    t, x = big_motion(3_000)
    path = tmp_path / "motion.parquet"
    io.write_csv_atomic(path, {"t": t, "x": x})
    motion = io.read_motion_csv(path)
    assert list(motion) == ["t", "x"]
    assert motion["t"].tobytes() == t.tobytes() and motion["x"].tobytes() == x.tobytes()
    assert all(values.flags.writeable for values in motion.values())
    io.write_parquet_atomic(tmp_path / "again.PARQUET", motion)
    again = io.read_parquet_columns(tmp_path / "again.PARQUET", ["t", "x"])
    assert again["x"].tobytes() == x.tobytes()


def parquet_file(path, **columns):
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table(columns), path)
    return path


BAD_PARQUET = [
    ("unknown-column", {"t": [0.0, 1.0], "x": [0.0, 1.0], "F": [0.0, 1.0]},
     ["unknown column 'F'"]),
    ("missing-t", {"x": [0.0, 1.0]}, ["missing column 't'"]),
    ("both-x-and-v", {"t": [0.0, 1.0], "x": [0.0, 1.0], "v": [0.0, 1.0]},
     ["doubled motion column"]),
    ("text-column", {"t": [0.0, 1.0], "x": ["a", "b"]}, ["column 'x'", "expected numbers",
                                                          "string"]),
    ("null", {"t": [0.0, 1.0, 2.0], "x": [0.0, None, 1.0]},
     ["row 2, column 'x'", "missing value"]),
    ("nan", {"t": [0.0, 1.0], "x": [0.0, float("nan")]}, ["row 2, column 'x'", "finite"]),
    ("repeated-time", {"t": [0.0, 1.0, 1.0], "x": [0.0, 1.0, 2.0]},
     ["row 3, column 't'", "increase", "row 2"]),
    ("zero-load", {"t": [0.0, 1.0], "x": [0.0, 1.0], "normal_load": [1.0, 0.0]},
     ["row 2, column 'normal_load'", "positive"]),
    ("one-row", {"t": [0.0], "x": [0.0]}, ["at least 2", "got 1"]),
    ("no-rows", {"t": np.empty(0), "x": np.empty(0)}, ["no data rows"]),
]


@pytest.mark.parametrize("columns, fragments", [case[1:] for case in BAD_PARQUET],
                         ids=[case[0] for case in BAD_PARQUET])
def test_bad_parquet_motion_names_file_row_and_column(tmp_path, columns, fragments):
    path = parquet_file(tmp_path / "motion.parquet", **columns)
    with pytest.raises(InputError) as error:
        io.read_motion_csv(path)
    message = str(error.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_parquet_integers_not_parquet_missing_and_directory(tmp_path):
    path = parquet_file(tmp_path / "ints.parquet", t=np.arange(3), v=np.array([0, 1, 2],
                                                                               np.int32))
    np.testing.assert_array_equal(io.read_motion_csv(path)["v"], [0.0, 1.0, 2.0])
    fake = write_file(tmp_path / "fake.parquet", "t,x\n0,0\n1,1\n")
    with pytest.raises(InputError, match=r"fake.parquet: not a Parquet file"):
        io.read_motion_csv(fake)
    with pytest.raises(InputError, match=r"absent.parquet: no such file"):
        io.read_motion_csv(tmp_path / "absent.parquet")
    (tmp_path / "dir.parquet").mkdir()
    with pytest.raises(InputError, match=r"dir.parquet: is a directory"):
        io.read_motion_csv(tmp_path / "dir.parquet")


def test_parquet_to_a_fifo_and_standard_output(tmp_path, capsysbinary):
    import pyarrow as pa
    import pyarrow.parquet as pq

    fifo = tmp_path / "pipe.parquet"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
    reader.start()
    io.write_csv_atomic(fifo, {"t": [0.0, 1.0]})
    reader.join(timeout=10)
    assert pq.read_table(pa.BufferReader(received[0])).column("t").to_pylist() == [0.0, 1.0]
    assert not fifo.is_file() and fifo.exists()


def test_simulate_command_with_parquet_in_and_out(tmp_path):
    model = write_file(tmp_path / "model.toml", MAXWELL_SLIP)
    t = np.linspace(0.0, 1.0, 20_001)
    x = 1e-5 * np.sin(2 * np.pi * 5 * t)
    io.write_csv_atomic(tmp_path / "motion.parquet", {"t": t, "x": x})
    io.write_csv_atomic(tmp_path / "motion.csv", {"t": t, "x": x})
    for suffix in ("parquet", "csv"):
        assert _run(["simulate", str(model), "-i", str(tmp_path / f"motion.{suffix}"),
                     "-o", str(tmp_path / f"out.{suffix}")]) == 0
    columns = ("t", "x", "v", "F")
    from_parquet = io.read_csv_columns(tmp_path / "out.parquet", require=columns)
    from_csv = io.read_csv_columns(tmp_path / "out.csv", require=columns)
    expected = polind.simulate(polind.load_model(model), t, x=x)
    for column, values in zip(columns, (expected.t, expected.x, expected.v, expected.force)):
        assert from_parquet[column].tobytes() == values.tobytes()
        assert from_csv[column].tobytes() == values.tobytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "model.toml", "motion.csv", "motion.parquet", "out.csv", "out.parquet"]


# --- the memory simulate holds --------------------------------------------------------------

@pytest.mark.parametrize("case", ["x", "v", "x+normal_load"])
def test_simulate_holds_at_most_40_bytes_a_sample(case):
    # issue 14: "simulate itself at most 40 bytes per sample beyond its inputs (today 57 to 65)"
    from polind.models.pol_ind import default_table

    model = lib(default_table() if case == "x+normal_load" else representative("maxwell-slip"))
    n = 1_000_000
    t = np.arange(n) * 1e-5
    motion = 1e-5 * np.sin(2 * np.pi * 5 * t)
    load = 100.0 + 10.0 * np.cos(t) if case == "x+normal_load" else None
    keyword = "v" if case == "v" else "x"
    polind.simulate(model, t[:10], normal_load=None if load is None else load[:10],
                    **{keyword: motion[:10]})
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        result = polind.simulate(model, t, normal_load=load, **{keyword: motion})
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert (peak - before) / n <= 40.0
    assert result.force.shape == (n,)


@pytest.mark.parametrize("model_type", ["maxwell-slip", "lugre", "leuven", "dahl",
                                        "maxwell-slip behind a spring"])
def test_the_blocks_of_a_run_never_change_a_result(monkeypatch, model_type):
    # Unmounted models run the fused loop (chunks only); a mounted one runs from
    # step arrays cut a block at a time.
    spring = model_type.endswith("behind a spring")
    table = representative(model_type.split(" ")[0])
    model = lib({**table, "compliance": {"stiffness": 3e4}} if spring else table)
    t = np.cumsum(np.random.default_rng(7).uniform(1e-4, 2e-4, 3001))
    x = 3e-5 * np.sin(2 * np.pi * 30 * t)
    v = np.gradient(x, t)
    whole = [polind.simulate(model, t, x=x), polind.simulate(model, t, v=v)]
    monkeypatch.setattr(simulate_module, "_BLOCK", 7)
    monkeypatch.setattr(simulate_module, "CHUNK", 500)
    blocks = [polind.simulate(model, t, x=x), polind.simulate(model, t, v=v)]
    for one, other in zip(whole, blocks):
        for field in ("t", "x", "v", "force"):
            assert getattr(one, field).tobytes() == getattr(other, field).tobytes()
        assert one.final_state.to_dict() == other.final_state.to_dict()


def test_the_normal_load_given_is_kept_without_a_copy():
    model = lib({**representative("maxwell-slip"), "reference_load": 10.0})
    t = np.linspace(0.0, 1.0, 11)
    load = np.full(11, 5.0)
    assert polind.simulate(model, t, x=1e-6 * t, normal_load=load).normal_load is load
    frozen = load.copy()
    frozen.flags.writeable = False
    kept = polind.simulate(model, t, x=1e-6 * t, normal_load=frozen).normal_load
    assert kept is not frozen and kept.flags.writeable
    listed = polind.simulate(model, t, x=1e-6 * t, normal_load=[5.0] * 11).normal_load
    np.testing.assert_array_equal(listed, load)
