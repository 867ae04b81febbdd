"""Tests of the polind command line: exit statuses, one-line errors, atomic output."""

from __future__ import annotations

import io as text_io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import polind
from polind import cli
from polind import io as polind_io
from polind.io import table_output

try:
    from test_io import BAD_MOTIONS, write_file
except ImportError:  # tests/ run as a package
    from tests.test_io import BAD_MOTIONS, write_file

COULOMB = '[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n'
GOOD_MOTION = "t,x\n0,0\n0.5,1e-6\n1,-2e-6\n"


@pytest.fixture(autouse=True)
def no_debug(monkeypatch):
    monkeypatch.delenv("POLIND_DEBUG", raising=False)


def run(capsys, *args):
    """Run ``polind args``; return (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        cli.main([os.fspath(arg) for arg in args])
    captured = capsys.readouterr()
    return exit_info.value.code, captured.out, captured.err


def the_one_error_line(err: str) -> str:
    """Standard error must hold exactly one line, an error naming polind."""
    assert err.endswith("\n") and err.count("\n") == 1, repr(err)
    assert err.startswith("polind: error: "), err
    return err


@pytest.fixture
def files(tmp_path):
    """A coulomb model, a good motion and the (not yet existing) output path."""
    model = write_file(tmp_path / "model.toml", COULOMB)
    motion = write_file(tmp_path / "motion.csv", GOOD_MOTION)
    return model, motion, tmp_path / "out.csv"


def read_back(path):
    lines = Path(path).read_text().splitlines()
    table = np.array([[float(field) for field in line.split(",")] for line in lines[1:]])
    return lines[0], table


# --- the group ---------------------------------------------------------------------------------

def test_version_and_help(capsys):
    status, out, err = run(capsys, "--version")
    assert (status, out, err) == (0, f"polind {polind.__version__}\n", "")
    status, out, err = run(capsys, "--help")
    assert status == 0 and "simulate" in out and err == ""
    status, out, err = run(capsys)
    assert status == 0 and "simulate" in out and err == ""


@pytest.mark.parametrize("args, fragment", [
    (["simulat"], "No such command 'simulat'"),
    (["simulate"], "Missing argument 'MODEL'"),
    (["simulate", "m.toml", "--output", "o.csv"], "Missing option '--input'"),
    (["simulate", "m.toml", "--input", "i.csv"], "Missing option '--output'"),
    (["simulate", "m.toml", "-i", "i.csv", "-o", "o.csv", "--bogus"], "--bogus"),
])
def test_usage_errors_exit_2_with_one_line(capsys, args, fragment):
    status, out, err = run(capsys, *args)
    assert status == 2
    assert fragment in the_one_error_line(err)


# --- polind simulate: success -------------------------------------------------------------------

@pytest.mark.parametrize("column", ["x", "v"])
def test_simulate_writes_the_library_result_to_the_bit(capsys, files, column):
    model_path, motion_path, output = files
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.random(30) + 0.01) / 7.0
    motion = rng.normal(size=30) * 1e-5
    text = f"t,{column}\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(),
                                                                    motion.tolist()))
    write_file(motion_path, text)

    status, out, err = run(capsys, "simulate", model_path, "--input", motion_path,
                           "--output", output)
    assert (status, err) == (0, "")
    assert str(output) in out

    expected = polind.simulate(polind.load_model(model_path), t, **{column: motion})
    header, table = read_back(output)
    assert header == "t,x,v,F"
    for index, values in enumerate([expected.t, expected.x, expected.v, expected.force]):
        assert table[:, index].tobytes() == values.tobytes()
    assert sorted(os.listdir(output.parent)) == ["model.toml", "motion.csv", "out.csv"]


def test_simulate_json_model_and_replaced_output(capsys, files):
    _, motion_path, output = files
    model_path = write_file(output.parent / "model.json",
                            '{"model": {"type": "coulomb", "coulomb_force": 2.0}}')
    output.write_text("old\n")
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    assert (status, err) == (0, "")
    header, table = read_back(output)
    assert header == "t,x,v,F"
    np.testing.assert_array_equal(table[:, 3], [2.0, 2.0, -2.0])


# --- polind simulate: bad input --------------------------------------------------------------

@pytest.mark.parametrize("existing", [None, "previous run\n"], ids=["no-output", "old-output"])
@pytest.mark.parametrize("content, fragments", [case[1:] for case in BAD_MOTIONS],
                         ids=[case[0] for case in BAD_MOTIONS])
def test_simulate_bad_motion_exits_2_and_writes_nothing(capsys, files, content, fragments,
                                                         existing):
    model_path, motion_path, output = files
    write_file(motion_path, content)
    if existing is not None:
        output.write_text(existing)
    status, out, err = run(capsys, "simulate", model_path, "--input", motion_path,
                           "--output", output)
    assert status == 2
    line = the_one_error_line(err)
    assert f"{motion_path}: " in line
    for fragment in fragments:
        assert fragment in line
    if existing is None:
        assert not output.exists()
    else:
        assert output.read_text() == existing
    assert sorted(os.listdir(output.parent)) == sorted(
        ["model.toml", "motion.csv"] + ([] if existing is None else ["out.csv"]))


# Each case: which of (MODEL, --input, --output) is replaced, by which path under the
# test folder, and optionally the model file's content.  The message must name that path.
BAD_PATHS = [
    ("missing-model", "model", "absent.toml", None, []),
    ("model-is-directory", "model", ".", None, []),
    ("missing-motion", "motion", "absent.csv", None, []),
    ("motion-is-directory", "motion", ".", None, []),
    ("no-output-directory", "output", "nowhere/out.csv", None, []),
    ("output-is-directory", "output", ".", None, []),
    ("model-syntax", "model", "model.toml", '[model]\ncoulomb_force = = 1\n', ["line 2"]),
    ("model-without-model-table", "model", "model.toml", 'type = "coulomb"\n', ["[model]"]),
]


@pytest.mark.parametrize("which, name, content, fragments", [case[1:] for case in BAD_PATHS],
                         ids=[case[0] for case in BAD_PATHS])
def test_simulate_bad_paths_exit_2_naming_the_file(capsys, files, which, name, content,
                                                   fragments):
    model_path, motion_path, output = files
    paths = {"model": model_path, "motion": motion_path, "output": output}
    paths[which] = output.parent / name
    if content is not None:
        write_file(paths[which], content)
    status, _, err = run(capsys, "simulate", paths["model"], "--input", paths["motion"],
                         "--output", paths["output"])
    assert status == 2
    line = the_one_error_line(err)
    assert os.fspath(paths[which]) in line
    for fragment in fragments:
        assert fragment in line
    assert not output.exists()


@pytest.mark.parametrize("which", ["output", "motion"])
def test_a_path_ending_in_a_separator_names_a_directory_and_exits_2(capsys, files, which):
    """``new/`` is refused as a directory, not written as a file ``new`` (pathlib drops the /)."""
    model_path, motion_path, output = files
    paths = {"motion": os.fspath(motion_path), "output": os.fspath(output)}
    paths[which] = os.fspath(output.parent / "new") + "/"
    status, _, err = run(capsys, "simulate", model_path, "--input", paths["motion"],
                         "--output", paths["output"])
    assert status == 2
    line = the_one_error_line(err)
    assert paths[which] in line and "directory" in line
    assert sorted(os.listdir(output.parent)) == ["model.toml", "motion.csv"]


MODEL_ERRORS = [
    ("unknown-key", '[model]\ntype = "coulomb"\ncoulomb_forse = 1.0\n', "coulomb_forse"),
    ("missing-key", '[model]\ntype = "coulomb"\n', "coulomb_force"),
    ("missing-type", "[model]\ncoulomb_force = 1.0\n", "type"),
    ("unknown-type", '[model]\ntype = "friction9000"\ncoulomb_force = 1.0\n', "type"),
    ("wrong-type", '[model]\ntype = "coulomb"\ncoulomb_force = "one"\n', "coulomb_force"),
    ("non-finite", '[model]\ntype = "coulomb"\ncoulomb_force = inf\n', "coulomb_force"),
    ("negative-stiffness", '[model]\ntype = "dahl"\nstiffness = -1e5\ncoulomb_force = 1.0\n',
     "stiffness"),
    ("empty-element-list",
     '[model]\ntype = "maxwell-slip"\nstiffness = []\nbreakaway_force = []\n', "stiffness"),
    ("unequal-list-lengths",
     '[model]\ntype = "maxwell-slip"\nstiffness = [1e4, 2e4]\nbreakaway_force = [0.5]\n',
     "breakaway_force"),
    ("weights-not-summing-to-1",
     '[model]\ntype = "gms"\nstiffness = [1e4, 2e4]\nweight = [0.5, 0.4]\nattraction = 1e3\n'
     'coulomb_force = 1.0\nstatic_force = 1.5\nstribeck_velocity = 1e-3\n', "weight"),
]


@pytest.mark.parametrize("content, key", [case[1:] for case in MODEL_ERRORS],
                         ids=[case[0] for case in MODEL_ERRORS])
def test_simulate_bad_model_exits_2_naming_file_and_key(capsys, files, content, key):
    model_path, motion_path, output = files
    write_file(model_path, content)
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    assert status == 2
    line = the_one_error_line(err)
    assert f"{model_path}: " in line and f"'{key}'" in line
    assert not output.exists()


def test_simulate_normal_load_for_a_model_without_one(capsys, files):
    model_path, motion_path, output = files
    write_file(motion_path, "t,x,normal_load\n0,0,10\n1,1e-6,10\n")
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    # Ignored, and said once on stderr (the user guide: normal load for every model).
    assert status == 0
    warnings = [line for line in err.splitlines() if line.startswith("polind: warning:")]
    assert len(warnings) == 1 and "reference_load" in warnings[0]
    assert output.exists()


# --- internal errors and the atomic output ----------------------------------------------------

def test_internal_error_exits_1_with_one_line(capsys, files, monkeypatch):
    model_path, motion_path, output = files

    def broken_simulate(*args, **kwargs):
        raise RuntimeError("kernel exploded\nsecond line")

    monkeypatch.setattr(polind, "simulate", broken_simulate)
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    assert status == 1
    assert err == "polind: internal error: RuntimeError: kernel exploded second line\n"
    assert not output.exists()

    monkeypatch.setenv("POLIND_DEBUG", "1")
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    assert status == 1
    assert err.startswith("Traceback (most recent call last):")
    assert "broken_simulate" in err
    assert err.endswith("polind: internal error: RuntimeError: kernel exploded second line\n")


@pytest.mark.parametrize("existing", [None, "previous run\n"], ids=["no-output", "old-output"])
def test_writer_dying_midway_leaves_no_output(capsys, files, monkeypatch, existing):
    model_path, motion_path, output = files
    if existing is not None:
        output.write_text(existing)

    def rows_then_failure(table):
        yield "0,0,0,1\n0.5,"
        raise MemoryError("out of memory halfway")

    monkeypatch.setattr(table_output, "_format_rows", rows_then_failure)
    status, _, err = run(capsys, "simulate", model_path, "-i", motion_path, "-o", output)
    assert status == 1
    assert err == "polind: internal error: MemoryError: out of memory halfway\n"
    assert sorted(os.listdir(output.parent)) == sorted(
        ["model.toml", "motion.csv"] + ([] if existing is None else ["out.csv"]))
    if existing is not None:
        assert output.read_text() == existing


# --- progress --------------------------------------------------------------------------------

class Terminal(text_io.StringIO):
    def isatty(self):
        return True


def test_progress_bar_only_on_a_terminal(monkeypatch):
    piped = text_io.StringIO()
    monkeypatch.setattr(sys, "stderr", piped)
    with cli.progress(total=5, description="work") as bar:
        for _ in range(5):
            bar.update()
    assert piped.getvalue() == ""

    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    with cli.progress(total=5, description="work") as bar:
        for _ in range(5):
            bar.update()
    assert "work" in terminal.getvalue()


# --- the installed console script ----------------------------------------------------------

def test_console_script_bad_input(tmp_path):
    script = Path(sys.executable).with_name("polind")
    if not script.exists():
        pytest.skip("the polind console script is not installed beside this python")
    model = write_file(tmp_path / "model.toml", COULOMB)
    motion = write_file(tmp_path / "motion.csv", "t,x\n0,0\n1,abc\n")
    output = tmp_path / "out.csv"
    environment = {key: value for key, value in os.environ.items() if key != "POLIND_DEBUG"}
    done = subprocess.run([script, "simulate", model, "--input", motion, "--output", output],
                          capture_output=True, text=True, env=environment, timeout=120)
    assert done.returncode == 2
    assert done.stderr == f"polind: error: {motion}: row 3, column 'x': expected a number, " \
                          f"got 'abc'\n"
    assert not output.exists()


def test_cli_import_adds_no_heavy_module_to_polind():
    code = ("import sys, polind; before = set(sys.modules); import polind.cli; "
            "print(sorted(m for m in set(sys.modules) - before if m.split('.')[0] in "
            "('tqdm', 'matplotlib', 'scipy', 'numpy', 'numba', 'tomli_w')))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)
    assert done.stdout.strip() == "[]"
