"""Nothing lost (issue 24): what a command reads, owns and writes.

* Every file a command reads, directly or through a model (its heights file,
  its height map), a system or a sweep, is an input no output may replace
  (cause 1).
* A sweep checks that an existing CSV is its own results table before it
  touches it (cause 2).
* A write that fails on a device or a full standard output is exit 2 with one
  line (cause 6).
* The outputs of one command are written all or none (cause 14).

Each refusal: exit 2, one line on standard error, every input byte-identical,
no temporary file left.
"""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import polind
from polind import io
from polind.cli import _run
from polind.errors import InputError

from model_files import direct_pol_ind

SAFETY = settings(max_examples=25, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture,
                                         HealthCheck.too_slow])



def write_files(folder):
    """The files of the commands below: a Pol-Ind model reading a heights file, one reading
    a height map, a Coulomb model, a motion, measured data, a system and sweeps."""
    rng = np.random.default_rng(0)
    (folder / "heights.csv").write_text(
        "h\n" + "".join(f"{value!r}\n" for value in rng.normal(0.0, 0.5e-6, 50)))
    np.savetxt(folder / "map.csv", rng.normal(0.0, 1e-6, (12, 12)), delimiter=",")
    fit = '[fit]\nfree = ["attraction"]\n'
    (folder / "direct.toml").write_text(direct_pol_ind(fit=fit))
    (folder / "mapped.toml").write_text(direct_pol_ind(
        heights_file=None, surface='topography = "map.csv"\npixel_size = [1e-6, 1e-6]\n',
        fit=fit))
    (folder / "coulomb.toml").write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    t = np.arange(21) * 1e-3
    io.write_csv_atomic(folder / "motion.csv", {"t": t, "x": 1e-6 * np.arange(21)})
    t = np.arange(201) * 1e-3
    io.write_csv_atomic(folder / "data.csv", {"t": t, "x": 1e-4 * np.sin(50 * t),
                                              "F": np.tanh(np.cos(50 * t) * 10)})
    (folder / "system.toml").write_text("[system]\nmass = 1.0\nduration = 0.05\n"
                                        "time_step = 0.01\n[system.spring_drive]\n"
                                        "stiffness = 10.0\nvelocity = 0.1\n")
    for name, model in (("sweep.toml", "coulomb.toml"), ("direct_sweep.toml", "direct.toml")):
        (folder / name).write_text(f'[sweep]\nmodel = "{model}"\nmotion = "motion.csv"\n'
                                   f'metrics = ["mean_force"]\n[sweep.parameters]\n'
                                   f'"model.coulomb_force" = {{ values = [0.5, 1.0] }}\n'
                                   .replace("coulomb_force", "attraction" if "direct" in name
                                            else "coulomb_force"))
    return folder


def snapshot(folder):
    return {path.name: path.read_bytes() for path in folder.iterdir() if path.is_file()}


def one_error_line(err):
    """One error line, last; any line before it is a warning the run gave (each one line)."""
    lines = err.splitlines()
    assert err.endswith("\n") and lines and lines[-1].startswith("polind: error: "), err
    assert all(line.startswith("polind: warning: ") for line in lines[:-1]), err
    return lines[-1]


def leftovers(folder, before):
    """Files that appeared: temporary files, locks, records (none after a refusal)."""
    return sorted(set(path.name for path in folder.iterdir()) - set(before))


# Every command, with the files it reads through a model (the inputs its outputs may not be).
COMMANDS = {
    "simulate": (["simulate", "direct.toml", "-i", "motion.csv", "-o", "{out}"],
                 ["direct.toml", "heights.csv", "motion.csv"]),
    "simulate a map": (["simulate", "mapped.toml", "-i", "motion.csv", "-o", "{out}"],
                       ["mapped.toml", "map.csv", "motion.csv"]),
    "dynamics": (["dynamics", "direct.toml", "-s", "system.toml", "-o", "{out}"],
                 ["direct.toml", "heights.csv", "system.toml"]),
    "fit --plot": (["fit", "direct.toml", "--data", "data.csv", "-o", "fitted.toml",
                    "--plot", "{out}"], ["direct.toml", "heights.csv", "data.csv"]),
    "compare --output": (["compare", "coulomb.toml", "direct.toml", "--data", "data.csv",
                          "-o", "{out}"], ["coulomb.toml", "direct.toml", "heights.csv",
                                           "data.csv"]),
    "compare --plot": (["compare", "direct.toml", "--data", "data.csv", "--plot", "{out}"],
                       ["direct.toml", "heights.csv", "data.csv"]),
    "sweep --plot": (["sweep", "direct_sweep.toml", "-o", "r.csv", "--plot", "{out}"],
                     ["direct_sweep.toml", "direct.toml", "heights.csv", "motion.csv"]),
    "sweep --output": (["sweep", "direct_sweep.toml", "-o", "{out}"],
                       ["heights.csv", "motion.csv"]),
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return write_files(tmp_path_factory.mktemp("safety"))


@SAFETY
@given(st.sampled_from(sorted(COMMANDS)), st.data())
def test_no_output_replaces_a_file_the_command_reads(folder, capsys, command, data):
    """Cause 1: an output naming any file the command reads, through its model too."""
    argv, inputs = COMMANDS[command]
    target = data.draw(st.sampled_from(inputs))
    before = snapshot(folder)
    status = _run([os.fspath(folder / target) if part == "{out}" else
                   os.fspath(folder / part) if "." in part and not part.startswith("-")
                   else part for part in argv])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "is also an input" in one_error_line(err)
    assert snapshot(folder) == before and leftovers(folder, before) == []


NOT_RESULTS = st.one_of(
    st.binary(min_size=1, max_size=200),
    st.lists(st.text(alphabet="abc,0123456789.\"' ", max_size=20), min_size=1, max_size=5)
    .map(lambda lines: "\n".join(lines).encode()),
    st.sampled_from([b"id,value\n1,10\n2,20", b"my lab notes", b"run,status\n0,ok\n1,o",
                     b"\xef\xbb\xbfrun\n", b"\n\n"]),
).filter(bool)          # an empty file holds nothing to lose: a sweep may start there


@SAFETY
@given(NOT_RESULTS, st.sampled_from(["notes.csv", "notes.parquet"]))
def test_a_sweep_never_touches_a_table_it_does_not_own(folder, content, name):
    """Cause 2: a file that is not this sweep's results is refused and left as it was."""
    out = folder / name
    out.write_bytes(content)
    before = snapshot(folder)
    with pytest.raises(InputError, match=name):
        polind.sweep(folder / "sweep.toml", out, workers=1)
    assert snapshot(folder) == before and leftovers(folder, before) == []
    out.unlink()


def test_writes_to_a_full_device_are_exit_2(folder, capsys):
    """Cause 6: -o /dev/full (--plot /dev/full: the compare test below)."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    before = snapshot(folder)
    status = _run(["simulate", os.fspath(folder / "coulomb.toml"), "-i",
                   os.fspath(folder / "motion.csv"), "-o", "/dev/full"])
    err = capsys.readouterr().err
    assert status == 2 and "/dev/full: cannot write: No space left" in one_error_line(err), err
    assert snapshot(folder) == before and leftovers(folder, before) == []


class FullStream:
    """A standard output on a full disk: every write fails with ENOSPC."""

    encoding = "utf-8"

    def __init__(self):
        self.buffer = self

    def write(self, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def flush(self):
        pass

    def isatty(self):
        return False


def test_a_full_standard_output_is_exit_2(folder, capsys, monkeypatch):
    """Cause 6: -o - on a full standard output; and a summary printed there."""
    monkeypatch.setattr("sys.stdout", FullStream())
    for argv in (["simulate", os.fspath(folder / "coulomb.toml"), "-i",
                  os.fspath(folder / "motion.csv"), "-o", "-"],
                 ["topography", os.fspath(folder / "map.csv"), "--pixel-size", "1e-6", "1e-6",
                  "--json"]):
        status = _run(argv)
        err = capsys.readouterr().err
        assert status == 2 and "standard output: cannot write" in one_error_line(err), err


def test_compare_writes_its_table_and_figure_together_or_neither(folder, capsys):
    """Cause 14: a figure that fails leaves no table (and an old table as it was)."""
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full here")
    table = folder / "c.csv"
    for existing in (None, b"an old table\n"):
        if existing is not None:
            table.write_bytes(existing)
        before = snapshot(folder)
        status = _run(["compare", os.fspath(folder / "coulomb.toml"), "--data",
                       os.fspath(folder / "data.csv"), "-o", os.fspath(table), "--plot",
                       "/dev/full"])
        one_error_line(capsys.readouterr().err)
        assert status == 2
        assert snapshot(folder) == before and leftovers(folder, before) == []
    table.unlink()


@SAFETY
@given(st.lists(st.binary(max_size=50), min_size=1, max_size=4), st.data())
def test_write_together_writes_all_or_leaves_every_file_as_it_was(tmp_path_factory, contents,
                                                                  data):
    """Cause 14: an output that fails as it replaces its file, and no output of the group
    changes (those replaced before it are put back)."""
    from unittest import mock

    folder = tmp_path_factory.mktemp("together")
    paths = [folder / f"out{index}.bin" for index in range(len(contents))]
    for path in paths:
        if data.draw(st.booleans()):
            path.write_bytes(b"old " + path.name.encode())
    before = snapshot(folder)
    failing = data.draw(st.integers(0, len(paths)))
    outputs = dict(zip(paths, contents))
    if failing < len(paths):
        replace = os.replace
        doomed = os.path.realpath(paths[failing])

        def full_disk(source, target):
            if os.fspath(target) == doomed and not os.fspath(source).endswith(".kept.tmp"):
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return replace(source, target)

        with mock.patch.object(os, "replace", full_disk), pytest.raises(InputError):
            io.write_together(outputs)
        assert snapshot(folder) == before
        assert [name for name in os.listdir(folder) if name.endswith(".tmp")] == []
        return
    io.write_together(outputs)
    assert {path.name: path.read_bytes() for path in paths} == \
        {path.name: content for path, content in zip(paths, contents)}
    assert [name for name in os.listdir(folder) if name.endswith(".tmp")] == []
