"""Bounded memory (issue 14): every command estimates what it will allocate first.

``polind simulate``, ``fit`` and ``compare`` estimate a data file's rows
from its size (Parquet: its metadata) and refuse before reading it; the
readers, :func:`polind.simulate`, :func:`polind.identify` and the element fit
refuse before allocating; the demo's runs are refused naming their
experiment.  Each refusal is an ``InputError`` (exit 2 on the command line)
naming the setting and the estimate; ``--max-memory`` sets the limit.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import tomli_w

import polind
from polind import io, resources
from polind.cli import _run
from polind.errors import InputError
from polind.io import tables
from polind.models.pol_ind import default_table

MAXWELL_SLIP = {"model": {"type": "maxwell-slip", "stiffness": [1e5, 5e4, 2e4, 1e4],
                          "breakaway_force": [0.2, 0.3, 0.25, 0.25]}}


@pytest.fixture
def limit():
    """Set a memory limit [bytes] for the test; the default again afterwards."""
    yield resources.set_memory_limit
    resources.set_memory_limit(None)


def run(capsys, *args):
    status = _run([str(arg) for arg in args])
    out, err = capsys.readouterr()
    return status, out, err


def write_motion(path, samples, force=False):
    t = np.arange(samples) * 1e-4
    x = 1e-5 * np.sin(2 * np.pi * 5.0 * t)
    columns = {"t": t, "x": x}
    if force:
        columns["F"] = 0.5 * np.tanh(x / 1e-6)
    io.write_csv_atomic(path, columns)
    return path


def forbid_reading(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("the file was read before the memory check")
    monkeypatch.setattr(tables, "read_csv_columns", refuse)


def test_table_size_counts_a_small_file_and_estimates_a_big_one(tmp_path):
    small = tmp_path / "small.csv"
    small.write_text("t,x\n0,0\n\n0.5,1e-6\n1,2e-6")
    assert io.table_size(small) == (3, 2, True)
    big = write_motion(tmp_path / "big.csv", 100_000)
    rows, columns, exact = io.table_size(big)
    assert columns == 2 and not exact and 0.8e5 < rows < 1.25e5
    parquet = write_motion(tmp_path / "m.parquet", 1234)
    assert io.table_size(parquet) == (1234, 2, True)
    assert io.table_size(tmp_path / "missing.csv") == (0, 0, True)


def test_simulate_command_refuses_before_reading(tmp_path, capsys, monkeypatch):
    model = tmp_path / "model.toml"
    model.write_text(tomli_w.dumps(MAXWELL_SLIP))
    motion = write_motion(tmp_path / "motion.csv", 100_000)
    out = tmp_path / "out.csv"
    forbid_reading(monkeypatch)
    status, _, err = run(capsys, "--max-memory", "2M", "simulate", model, "-i", motion,
                         "-o", out)
    assert status == 2 and err.count("\n") == 1, err
    assert err.startswith(f"polind: error: {motion}: simulating its ")
    assert "rows of 2 columns (estimated from the size of the file) needs about" in err
    assert "MB of memory; the limit is 2 MB (set by --max-memory)." in err
    assert not out.exists()


def test_simulate_command_runs_within_a_limit_that_fits(tmp_path, capsys):
    model = tmp_path / "model.toml"
    model.write_text(tomli_w.dumps(MAXWELL_SLIP))
    motion = write_motion(tmp_path / "motion.parquet", 20_000)
    out = tmp_path / "out.parquet"
    status, _, err = run(capsys, "--max-memory", "20M", "simulate", model, "-i", motion,
                         "-o", out)
    assert status == 0, err
    status, _, err = run(capsys, "--max-memory", "1M", "simulate", model, "-i", motion,
                         "-o", tmp_path / "other.csv")
    assert status == 2 and f"{motion}: simulating its 2e+04 rows of 2 columns needs" in err


def test_simulate_in_python_refuses_before_allocating(limit):
    model = polind.model_from_dict(MAXWELL_SLIP)
    t = np.linspace(0.0, 1.0, 10_000)
    limit(1e5)
    with pytest.raises(InputError, match=r"^A motion of 1e\+04 samples needs about 320 kB of "
                                         r"memory; the limit is 100 kB \(set by --max-memory\)"):
        polind.simulate(model, t, x=1e-6 * t)
    limit(1e6)
    assert polind.simulate(model, t, x=1e-6 * t).force.shape == (10_000,)


def test_readers_refuse_a_table_beyond_the_limit(tmp_path, limit):
    motion = write_motion(tmp_path / "motion.csv", 50_000)
    parquet = write_motion(tmp_path / "motion.parquet", 50_000)
    limit(1e6)
    with pytest.raises(InputError, match=f"^{motion}: reading its .* rows of 2 columns"):
        io.read_motion_csv(motion)
    with pytest.raises(InputError, match=f"^{parquet}: reading its 5e\\+04 rows of 2 columns "
                                         f"needs about 2.4 MB"):
        io.read_motion_csv(parquet)


def test_reading_a_big_file_row_by_row_is_checked_too(tmp_path, limit, monkeypatch):
    motion = write_motion(tmp_path / "motion.csv", 100_000)
    # The fast reader refuses (as it refuses a quoted field); the careful reader would
    # hold about six times the file.
    monkeypatch.setattr(tables, "_read_csv_fast", lambda *args, **kwargs: None)
    limit(4 * motion.stat().st_size)
    with pytest.raises(InputError, match=f"^{motion}: reading its .* MB row by row"):
        io.read_motion_csv(motion)


def fit_files(tmp_path, samples):
    model = tmp_path / "model.toml"
    model.write_text(tomli_w.dumps({**MAXWELL_SLIP, "fit": {"free": ["breakaway_force"]}}))
    data = write_motion(tmp_path / "data.csv", samples, force=True)
    return model, data


def test_fit_and_compare_refuse_before_reading(tmp_path, capsys, monkeypatch):
    model, data = fit_files(tmp_path, 20_000)
    out = tmp_path / "fitted.toml"
    forbid_reading(monkeypatch)
    status, _, err = run(capsys, "--max-memory", "5M", "fit", model, "-d", data, "-o", out)
    assert status == 2 and err.count("\n") == 1, err
    assert err.startswith(f"polind: error: {data}: fitting 1 free key to its ")
    assert "the limit is 5 MB (set by --max-memory)" in err
    assert not out.exists()
    status, _, err = run(capsys, "--max-memory", "5M", "compare", model, "-d", data)
    assert status == 2 and err.startswith(f"polind: error: {data}: fitting the models to its ")


def test_the_fit_estimate_grows_with_the_free_values():
    model = polind.model_from_dict(MAXWELL_SLIP)
    from polind.identification import fit_bytes_per_sample

    one = fit_bytes_per_sample(model, ["viscous_coefficient"])
    eight = fit_bytes_per_sample(model, ["stiffness", "breakaway_force"])
    assert 100 < one < eight and eight >= 8 * 64


def test_identify_and_the_element_fit_refuse_in_python(limit):
    from polind.identification import identify, identify_maxwell_slip

    model = polind.model_from_dict(MAXWELL_SLIP)
    t = np.linspace(0.0, 1.0, 20_000)
    x = 2e-5 * np.sin(2 * np.pi * t)
    data = {"t": t, "x": x, "F": polind.simulate(model, t, x=x).force}
    limit(2e6)
    with pytest.raises(InputError, match=r"^Fitting 8 free values to 2e\+04 samples of data "
                                         r"needs about .* MB"):
        identify(model, data, free=["stiffness", "breakaway_force"])
    with pytest.raises(InputError, match=r"^The element fit of 24 slip distances to 2e\+04 "
                                         r"samples of data needs about .* MB"):
        identify_maxwell_slip(data)


def light_pol_ind(load=1e-6):
    table = copy.deepcopy(default_table())
    table["normal_load"] = load
    return polind.model_from_dict({"model": table})


def test_a_light_load_pol_ind_runs_its_scale_dependent_experiments_in_bounded_memory(limit):
    # Its frictional-lag grid once asked for 595 GiB.  Every run is estimated first, so
    # under a limit of 100 MB they either fit or are refused; they fit.
    from polind import phenomena

    limit(100e6)
    model = light_pol_ind()
    lag = phenomena.frictional_lag(model)
    assert all(math.isfinite(area) for area in lag.metrics["loop_area"])
    assert phenomena.non_drifting(model).metrics["last_advance"] is not None


def test_demo_refuses_a_run_beyond_the_limit_naming_its_experiment(tmp_path, capsys):
    model = tmp_path / "light.toml"
    model.write_text(tomli_w.dumps({"model": light_pol_ind().to_dict()["model"]}))
    out_dir = tmp_path / "report"
    status, _, err = run(capsys, "--max-memory", "5M", "demo", "--model", model,
                         "--out", out_dir)
    assert status == 2 and err.count("\n") == 1, err
    assert err.startswith("polind: error: The frictional_lag experiment on Pol-Ind: The "
                          "frictional-lag run at ")
    assert "the limit is 5 MB (set by --max-memory)" in err
    assert not (out_dir / "report.html").exists()


def test_sizing_a_pipe_does_not_consume_it(tmp_path, capsys):
    import os
    import threading

    model = tmp_path / "model.toml"
    model.write_text(tomli_w.dumps(MAXWELL_SLIP))
    pipe = tmp_path / "motion.csv"
    os.mkfifo(pipe)
    assert io.table_size(pipe) == (0, 0, True)        # without opening it
    writer = threading.Thread(target=pipe.write_text, args=("t,x\n0,0\n0.5,1e-6\n1,2e-6\n",))
    writer.start()
    status, _, err = run(capsys, "simulate", model, "-i", pipe, "-o", tmp_path / "out.csv")
    writer.join(timeout=60)
    assert status == 0, err
    assert len((tmp_path / "out.csv").read_text().splitlines()) == 4


def test_frictional_lag_checks_memory_before_making_its_samples():
    from polind import phenomena

    model = polind.model_from_dict({"model": {"type": "lugre", "bristle_stiffness": 1e5,
                                              "bristle_damping": 316.2,
                                              "viscous_coefficient": 0.4, "coulomb_force": 1.0,
                                              "static_force": 1.5, "stribeck_velocity": 1e-3}})
    previous = resources._LIMIT
    resources.set_memory_limit(1e6)
    try:
        with pytest.raises(polind.InputError, match=r"The frictional-lag run at 1 Hz "
                                                    r"\(.* samples\) needs about"):
            # 1e5 steps per lag time: far more samples than 1 MB holds.
            phenomena.frictional_lag(model, frequencies=[1.0], steps_per_lag=100_000)
    finally:
        resources.set_memory_limit(previous)
