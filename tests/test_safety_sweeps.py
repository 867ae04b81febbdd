"""Sweeps own their results (issue 24, causes 3, 5, 7, 9 and 11).

* One writer at a time: a second sweep on the same output is refused; a lock
  left by a killed writer does not stick (cause 3).
* The record of what was run covers the contents of every file the runs read:
  a resume after the heights changed is refused naming them (cause 3).
* A corrupt or foreign results file is refused naming what is wrong, and left
  as it was (cause 5).
* 400-digit integers in a sweep file are exit 2 (cause 7).
* A Dask address where no scheduler answers is refused in bounded time;
  ``ucx://`` and ``tls://`` are refused (cause 9).
* The Python API refuses wrong arguments with ``InputError`` (cause 11).
"""

from __future__ import annotations

import http.server
import json
import os
import signal
import socket
import stat
import subprocess
import sys
import threading
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import polind
from polind import io
from polind.cli import _run
from polind.errors import InputError
from polind.sweeps import read_results, register_metric
from polind.sweeps.results import record_path

from test_safety_outputs import leftovers, one_error_line, snapshot, write_files

SAFETY = settings(max_examples=20, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture,
                                         HealthCheck.too_slow])


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return write_files(tmp_path_factory.mktemp("sweeps"))


@pytest.fixture(scope="module")
def results(folder):
    """A finished results table of sweep.toml, as CSV and as Parquet (its bytes)."""
    made = {}
    for suffix in (".csv", ".parquet"):
        out = folder / f"made{suffix}"
        polind.sweep(folder / "sweep.toml", out, workers=1)
        made[suffix] = out.read_bytes()
        if suffix == ".csv":
            made["record"] = open(record_path(out), "rb").read()
    return made


def fresh(folder, results, suffix, name="r"):
    """A copy of a finished results table (with its record) to damage."""
    out = folder / f"{name}{suffix}"
    out.write_bytes(results[suffix])
    if suffix == ".csv":
        with open(record_path(out), "wb") as stream:
            stream.write(results["record"])
    return out


# --- one writer at a time -------------------------------------------------------------------

def test_a_second_writer_is_refused_and_the_lock_is_gone_after(folder, capsys):
    out = folder / "locked.parquet"
    with io.writer_lock(out):
        before = snapshot(folder)
        status = _run(["sweep", os.fspath(folder / "sweep.toml"), "-o", os.fspath(out)])
        assert status == 2 and "another sweep is writing" in one_error_line(
            capsys.readouterr().err)
        assert snapshot(folder) == before
    assert not os.path.exists(io.lock_path(out))
    assert polind.sweep(folder / "sweep.toml", out, workers=1).computed == 2
    assert not os.path.exists(io.lock_path(out))


def test_two_sweeps_at_once_lose_no_row(folder):
    out = folder / "twice.parquet"
    outcomes = []

    def sweep():
        try:
            outcomes.append(polind.sweep(folder / "sweep.toml", out, workers=1).computed)
        except InputError as error:
            outcomes.append(str(error))

    threads = [threading.Thread(target=sweep) for _ in range(3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    # Each either computed what was missing or was refused: every run is in the file once.
    assert all(isinstance(outcome, int) or "another sweep is writing" in outcome
               for outcome in outcomes), outcomes
    assert read_results(out)["run"] == [0, 1]
    assert sum(outcome for outcome in outcomes if isinstance(outcome, int)) == 2


def test_a_lock_held_by_a_killed_writer_does_not_stick(folder):
    out = folder / "killed.csv"
    script = ("import sys, time; from polind import io\n"
              "with io.writer_lock(sys.argv[1]):\n"
              "    print('held', flush=True); time.sleep(60)\n")
    holder = subprocess.Popen([sys.executable, "-c", script, os.fspath(out)],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        with pytest.raises(InputError, match="another sweep is writing"):
            polind.sweep(folder / "sweep.toml", out, workers=1)
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    assert os.path.exists(io.lock_path(out))          # left behind, but not held
    assert polind.sweep(folder / "sweep.toml", out, workers=1).computed == 2
    assert not os.path.exists(io.lock_path(out))


# --- the record covers the contents of the files the runs read ------------------------------

@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_resume_after_the_heights_changed_is_refused_naming_them(tmp_path, capsys, suffix):
    folder = write_files(tmp_path)
    # Runs that fail at once (a negative load): the record is written all the same,
    # without a contact to compute.
    (folder / "direct_sweep.toml").write_text(
        (folder / "direct_sweep.toml").read_text().replace(
            '"model.attraction" = { values = [0.5, 1.0] }',
            '"model.normal_load" = { values = [-1.0, -2.0] }'))
    out = folder / f"r{suffix}"
    assert polind.sweep(folder / "direct_sweep.toml", out, workers=1).failed == 2
    with open(folder / "heights.csv", "a") as stream:
        stream.write("1e-6\n")
    before = snapshot(folder)
    status = _run(["sweep", os.fspath(folder / "direct_sweep.toml"), "-o", os.fspath(out)])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and "heights.csv changed" in err, err
    assert snapshot(folder) == before and leftovers(folder, before) == []


# --- corrupt or foreign results --------------------------------------------------------------

def _parquet_with(path, replace):
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    pq.write_table(replace(table), path)


DAMAGES = {
    "a byte that is not UTF-8": (".csv", lambda path: path.write_bytes(
        path.read_bytes().replace(b",ok,", b",o\xffk,", 1)), "UTF-8"),
    "no record beside the CSV": (".csv", lambda path: os.unlink(record_path(path)),
                                 "no record"),
    "a record that is not JSON": (".csv", lambda path: open(record_path(path), "w").write(
        "{not json"), "not JSON"),
    "Parquet metadata that is not JSON": (".parquet", lambda path: _parquet_with(
        path, lambda table: table.replace_schema_metadata({b"polind.sweep": b"{"})),
        "not JSON"),
    "Parquet metadata that is JSON but no record": (".parquet", lambda path: _parquet_with(
        path, lambda table: table.replace_schema_metadata({b"polind.sweep": b"[1, 2]"})),
        "record"),
    "a column of the wrong type": (".parquet", lambda path: _parquet_with(
        path, lambda table: table.set_column(0, "run", table.column("run").cast("string"))),
        "'run' holds values of type string"),
    "not Parquet at all": (".parquet", lambda path: path.write_bytes(b"PAR1 not really"),
                           "cannot read"),
}


@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_corrupt_results_file_is_refused_and_left_as_it_was(folder, results, capsys,
                                                                damage):
    suffix, spoil, words = DAMAGES[damage]
    out = fresh(folder, results, suffix)
    spoil(out)
    before = snapshot(folder)
    status = _run(["sweep", os.fspath(folder / "sweep.toml"), "-o", os.fspath(out)])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and words in err and out.name in err, err
    assert snapshot(folder) == before and leftovers(folder, before) == []
    out.unlink()


def test_a_read_only_table_with_a_cut_row_is_refused(folder, results, capsys):
    out = fresh(folder, results, ".csv")
    lines = out.read_bytes().split(b"\n")
    out.write_bytes(b"\n".join(lines[:2]) + b"\n" + lines[2][:5])        # run 1 cut short
    out.chmod(stat.S_IRUSR | stat.S_IRGRP)
    try:
        before = snapshot(folder)
        status = _run(["sweep", os.fspath(folder / "sweep.toml"), "-o", os.fspath(out)])
        assert status == 2 and "read-only" in one_error_line(capsys.readouterr().err)
        assert snapshot(folder) == before
    finally:
        out.chmod(stat.S_IRUSR | stat.S_IWUSR)
        out.unlink()


@SAFETY
@given(st.data())
def test_a_byte_that_is_not_utf8_anywhere_is_refused(folder, results, data):
    out = fresh(folder, results, ".csv", "bytes")
    content = results[".csv"]
    position = data.draw(st.integers(0, content.rfind(b"\n")))
    byte = data.draw(st.sampled_from([b"\x80", b"\xbf", b"\xc0", b"\xff", b"\xfe"]))
    out.write_bytes(content[:position] + byte + content[position:])
    before = snapshot(folder)
    with pytest.raises(InputError, match="UTF-8"):
        polind.sweep(folder / "sweep.toml", out, workers=1)
    assert snapshot(folder) == before


@SAFETY
@given(st.binary(max_size=300), st.sampled_from([".csv", ".parquet"]))
def test_read_results_of_any_bytes_is_a_table_or_an_input_error(tmp_path_factory, content,
                                                                suffix):
    path = tmp_path_factory.mktemp("read") / f"any{suffix}"
    path.write_bytes(content)
    try:
        table = read_results(path)
    except InputError:
        return
    assert all(isinstance(index, int) for index in table["run"])


# --- huge integers ----------------------------------------------------------------------------

HUGE = "9" * 400
BIG_SWEEPS = {
    "samples": ('metrics = ', f'method = "random"\nsamples = {HUGE}\nmetrics = '),
    "seed": ('metrics = ', f'method = "random"\nsamples = 2\nseed = {HUGE}\nmetrics = '),
    "count": ("{ values = [0.5, 1.0] }", f"{{ range = [0.5, 1.5], count = {HUGE} }}"),
    "values": ("{ values = [0.5, 1.0] }", f"{{ values = [{HUGE}] }}"),
    "range": ("{ values = [0.5, 1.0] }", f"{{ range = [1, {HUGE}], count = 2 }}"),
    "5000 digits": ("{ values = [0.5, 1.0] }", f"{{ values = [{'9' * 5000}] }}"),
}


@pytest.mark.parametrize("key", sorted(BIG_SWEEPS))
def test_huge_integers_in_a_sweep_file_are_exit_2(folder, capsys, key):
    old, new = BIG_SWEEPS[key]
    path = folder / f"big_{key.replace(' ', '_')}.toml"
    path.write_text((folder / "sweep.toml").read_text().replace(old, new))
    before = snapshot(folder)
    status = _run(["--max-memory", "100M", "sweep", os.fspath(path), "-o",
                   os.fspath(folder / "big.csv"), "--yes"])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and len(err) < 400, err
    assert snapshot(folder) == before and leftovers(folder, before) == []


def test_a_range_to_the_largest_doubles_has_finite_points():
    from polind.sweeps.design import Axis

    for scale, low, high in (("linear", -1.7e308, 1.7e308), ("log", 1e-300, 1e300),
                             ("log", -1e300, -1e-300)):
        axis = Axis("model.x", "float", low=low, high=high, scale=scale, count=5)
        points = axis.grid()
        assert all(abs(point) < float("inf") for point in points), points
        assert points == sorted(points) and points[0] == low and points[-1] == high


# --- Dask -------------------------------------------------------------------------------------

@pytest.fixture
def quick_timeout(monkeypatch):
    monkeypatch.setattr(sys.modules["polind.sweeps.cluster"], "CONNECT_TIMEOUT", 1.0)


def _listening(serve):
    """A local address where ``serve`` listens (an HTTP server, or a socket that never answers)."""
    if serve == "http":
        server = http.server.HTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        return f"tcp://127.0.0.1:{server.server_port}", server.shutdown
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(5)
    return f"tcp://127.0.0.1:{listener.getsockname()[1]}", listener.close


@pytest.mark.parametrize("serve", ["http", "silent"])
def test_an_address_without_a_scheduler_is_refused_in_bounded_time(folder, capsys,
                                                                  quick_timeout, serve):
    address, stop = _listening(serve)
    try:
        started = time.monotonic()
        status = _run(["sweep", os.fspath(folder / "sweep.toml"), "-o",
                       os.fspath(folder / "dask.csv"), "--scheduler", address])
        err = one_error_line(capsys.readouterr().err)
        assert status == 2 and address in err, err
        assert time.monotonic() - started < 15.0
        assert not (folder / "dask.csv").exists()
    finally:
        stop()


def test_a_scheduler_killed_mid_sweep_is_exit_2_with_the_finished_rows_kept(tmp_path):
    pytest.importorskip("distributed")
    folder = write_files(tmp_path)
    (folder / "slow.toml").write_text((folder / "system.toml").read_text().replace(
        "duration = 0.05", "duration = 1.0").replace("time_step = 0.01", "time_step = 2e-5"))
    (folder / "killed.toml").write_text(
        '[sweep]\nmodel = "coulomb.toml"\nsystem = "slow.toml"\nmetrics = ["mean_force"]\n'
        '[sweep.parameters]\n"model.coulomb_force" = { range = [0.5, 1.5], count = 40 }\n')
    probe = socket.socket()
    probe.bind(("127.0.0.1", 0))
    port = probe.getsockname()[1]
    probe.close()
    address = f"tcp://127.0.0.1:{port}"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler",
                                  "--host", "127.0.0.1", "--port", str(port),
                                  "--no-dashboard"], **quiet)
    worker = None
    try:
        deadline = time.monotonic() + 60.0
        while time.monotonic() < deadline:
            try:
                polind.sweeps.cluster.check_scheduler(address, timeout=1.0)
                break
            except InputError:
                time.sleep(0.2)
        worker = subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker", address,
                                   "--nworkers", "1", "--nthreads", "1", "--no-dashboard"],
                                  **quiet)
        out = folder / "r.csv"
        sweep = subprocess.Popen([sys.executable, "-m", "polind", "sweep",
                                  os.fspath(folder / "killed.toml"), "-o", os.fspath(out),
                                  "--scheduler", address], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 120.0
        while time.monotonic() < deadline and not (
                out.exists() and out.read_text().count("\n") >= 3):
            time.sleep(0.05)
        scheduler.kill()
        _, err = sweep.communicate(timeout=120)
    finally:
        for process in (scheduler, worker):
            if process is not None:
                process.kill()
                process.wait()
    assert sweep.returncode == 2, err
    assert err.count("\n") == 1 and "went away" in err, err
    kept = read_results(out)["run"]
    assert 2 <= len(kept) < 40


@pytest.mark.parametrize("address", ["ucx://127.0.0.1:8786", "tls://127.0.0.1:8786",
                                     "tcp://127.0.0.1:99999", "tcp://:8786"])
def test_an_address_polind_cannot_use_is_refused(folder, capsys, address):
    status = _run(["sweep", os.fspath(folder / "sweep.toml"), "-o",
                   os.fspath(folder / "dask.csv"), "--scheduler", address])
    assert status == 2 and address in one_error_line(capsys.readouterr().err)


# --- the Python API ---------------------------------------------------------------------------

API_MISTAKES = {
    "output None": lambda folder: polind.sweep(folder / "sweep.toml", None),
    "spec None": lambda folder: polind.sweep(None, folder / "api.csv"),
    "scheduler 123": lambda folder: polind.sweep(folder / "sweep.toml", folder / "api.csv",
                                                 scheduler=123),
    "max_runs 'x'": lambda folder: polind.sweep(folder / "sweep.toml", folder / "api.csv",
                                                max_runs="x"),
    "max_runs nan": lambda folder: polind.sweep(folder / "sweep.toml", folder / "api.csv",
                                                max_runs=float("nan")),
    "register_metric(3)": lambda folder: register_metric(3),
    "register_metric without unit": lambda folder: register_metric("m", definition="x"),
    "a metric that is not callable": lambda folder: register_metric(
        "m", unit="N", definition="x")(3),
    "read_results of a missing file": lambda folder: read_results(folder / "missing.csv"),
    "read_results of a binary file": lambda folder: read_results(_binary(folder)),
    "read_results of a foreign file": lambda folder: read_results(folder / "data.csv"),
    "read_results of a directory": lambda folder: read_results(folder),
    "samples = -5 on a grid": lambda folder: polind.sweeps.Sweep(
        folder / "coulomb.toml", motion=folder / "motion.csv", metrics=["mean_force"],
        samples=-5, parameters={"model.coulomb_force": {"values": [1.0]}}),
}


def _binary(folder):
    path = folder / "binary.csv"
    path.write_bytes(bytes(range(256)) * 4)
    return path


@pytest.mark.parametrize("mistake", sorted(API_MISTAKES))
def test_the_python_api_refuses_mistakes_with_input_error(folder, mistake):
    with pytest.raises(InputError):
        API_MISTAKES[mistake](folder)
    assert not (folder / "api.csv").exists()


def test_the_record_holds_the_digest_of_each_file_the_runs_read(folder, results):
    record = json.loads(results["record"])
    assert set(record) >= {"fingerprint", "files", "sweep", "runs"}
    assert any(name.endswith("motion.csv") for name in record["files"])
