"""Outputs never destroy data: the writer of polind.io and the commands that use it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import polind
from polind import io
from polind.cli import _run


def _motion(tmp_path):
    path = tmp_path / "motion.csv"
    path.write_text("t,x\n0,0\n0.001,1e-6\n0.002,2e-6\n")
    return path


def _model(tmp_path):
    path = tmp_path / "model.toml"
    path.write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    return path


def test_a_symlinked_output_keeps_its_link_and_replaces_its_target(tmp_path):
    target = tmp_path / "real.csv"
    target.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    io.write_csv_atomic(link, {"t": [0.0, 1.0]})
    assert link.is_symlink()
    assert target.read_text() == "t\n0\n1\n"


def test_a_fifo_is_written_to_not_replaced(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(open(fifo).read()))
    reader.start()
    io.write_csv_atomic(fifo, {"t": [0.0, 1.0]})
    reader.join(timeout=10)
    assert received == ["t\n0\n1\n"]
    assert not fifo.is_file() and fifo.exists()          # still a FIFO


def test_dash_is_standard_output(capsys):
    io.atomic_write_text("-", "hello\n")
    assert capsys.readouterr().out == "hello\n"


@pytest.mark.parametrize("name", ["newdir/", "existing"])
def test_a_directory_is_refused(tmp_path, name):
    (tmp_path / "existing").mkdir()
    target = os.path.join(os.fspath(tmp_path), name)
    with pytest.raises(polind.InputError, match="directory"):
        io.write_csv_atomic(target, {"t": [0.0]})
    assert not (tmp_path / "newdir").exists()


def test_an_output_that_is_an_input_is_refused(tmp_path):
    motion = _motion(tmp_path)
    before = motion.read_bytes()
    with pytest.raises(polind.InputError, match="input"):
        io.check_output_path(motion, inputs=[motion])
    model = _model(tmp_path)
    for output in (motion, model):
        assert _run(["simulate", str(model), "--input", str(motion), "--output",
                     str(output)]) == 2
    assert motion.read_bytes() == before
    link = tmp_path / "alias.csv"
    link.symlink_to(motion)
    assert _run(["simulate", str(model), "--input", str(motion), "--output", str(link)]) == 2
    assert motion.read_bytes() == before


def test_simulate_to_standard_output(tmp_path, capsys):
    assert _run(["simulate", str(_model(tmp_path)), "--input", str(_motion(tmp_path)),
                 "--output", "-"]) == 0
    captured = capsys.readouterr()
    rows = captured.out.splitlines()
    assert rows[0] == "t,x,v,F" and len(rows) == 4          # the table and nothing else
    assert "wrote -" in captured.err


_SLOW_WRITER = """
import sys, time
from polind import io
def rows():
    yield "t\\n"
    print("started", flush=True)
    for k in range(10_000):
        time.sleep(0.01)
        yield f"{k}\\n"
with io.atomic_open(sys.argv[1]) as stream:
    for row in rows():
        stream.write(row)
"""


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_signal_during_a_write_leaves_no_temporary_file(tmp_path, signame):
    out = tmp_path / "out.csv"
    process = subprocess.Popen([sys.executable, "-c", _SLOW_WRITER, str(out)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "started"
    time.sleep(0.1)
    process.send_signal(getattr(signal, signame))
    process.wait(timeout=30)
    assert process.returncode != 0
    assert sorted(p.name for p in tmp_path.iterdir()) == []
