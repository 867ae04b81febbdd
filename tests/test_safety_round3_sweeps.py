"""Nothing lost, round three: the sweeps (issue 44).

* An input file replaced mid-sweep (``cp new h.tmp && mv h.tmp h.csv``) stops
  the sweep naming the file; the rows kept are those of the file the sweep
  started with, and a resume refuses the new file and finishes with the old.
* A SIGKILLed Parquet sweep loses at most the runs of its last 2 seconds,
  killed at 5 random moments.
* SIGTERM and SIGHUP end a sweep as SIGINT does: the finished rows kept, the
  lock removed, exit 130.
* A run whose output is NaN or inf (a plugin model) is a failed row naming it.

The signals go to processes forked from one helper process, which loads the
kernel once: one process start for the 5 kills and the 4 signalled commands.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numba import njit

import polind
from polind import io
from polind.errors import InputError
from polind.sweeps import Sweep, read_results

from model_files import direct_pol_ind

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SAFETY = settings(max_examples=4, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture,
                                         HealthCheck.too_slow])

DIRECT = direct_pol_ind()


def heights_text(seed, count, std):
    values = np.random.default_rng(seed).normal(0.0, std, count)
    return "h\n" + "".join(f"{float(value)!r}\n" for value in values)


# --- an input file replaced mid-sweep ----------------------------------------------------------

@pytest.fixture(scope="module")
def replaced(tmp_path_factory):
    """A sweep over a heights file, its rows untouched, and the surface that replaces it."""
    folder = tmp_path_factory.mktemp("replaced")
    (folder / "heights.csv").write_text(heights_text(0, 50, 0.5e-6))
    (folder / "other.csv").write_text(heights_text(1, 10, 5e-6))
    (folder / "direct.toml").write_text(DIRECT)
    # Presliding (a nanometre a step): the force depends on every summit's height.
    io.write_csv_atomic(folder / "motion.csv", {"t": np.arange(11) * 1e-3,
                                                "x": 1e-10 * np.arange(11)})
    (folder / "sweep.toml").write_text(
        '[sweep]\nmodel = "direct.toml"\nmotion = "motion.csv"\nmetrics = ["mean_force"]\n'
        '[sweep.parameters]\n"model.normal_load" = { range = [0.2, 1.0], count = 12 }\n')
    untouched = polind.sweep(folder / "sweep.toml", folder / "untouched.csv", workers=1).table
    return folder, untouched


@SAFETY
@given(after=st.integers(0, 10), suffix=st.sampled_from([".csv", ".parquet"]))
def test_an_input_replaced_mid_sweep_stops_it_and_no_row_mixes_the_two(replaced, after,
                                                                        suffix):
    folder, untouched = replaced
    heights = folder / "heights.csv"
    original = heights.read_bytes()
    out = folder / f"r{after}{suffix}"
    for leftover in (out, io.lock_path(out), polind.sweeps.results.record_path(out)):
        if os.path.exists(leftover):
            os.unlink(leftover)

    def replace(done, total, failed):
        if done == after:
            shutil.copy(folder / "other.csv", folder / "h.tmp")
            os.replace(folder / "h.tmp", heights)

    try:
        try:
            polind.sweep(folder / "sweep.toml", out, workers=2, progress=replace)
            stopped = False     # every run had finished reading before the file was replaced
        except InputError as error:
            assert "heights.csv: changed while the sweep ran" in str(error)
            stopped = True
        assert not os.path.exists(io.lock_path(out))
        kept = read_results(out) if out.exists() else {"run": [], "mean_force": []}
        # Only rows of the first file (the runs that finished before it was replaced).
        for run, force in zip(kept["run"], kept["mean_force"]):
            assert force == untouched["mean_force"][run]
        assert stopped or len(kept["run"]) == 12
        # A resume with the new file is refused, naming it; with the old one it finishes.
        if kept["run"]:
            with pytest.raises(InputError, match="heights.csv changed since its rows"):
                polind.sweep(folder / "sweep.toml", out, workers=1)
        heights.write_bytes(original)
        done = polind.sweep(folder / "sweep.toml", out, workers=2)
        assert done.computed == 12 - len(kept["run"])
        assert done.table["mean_force"] == untouched["mean_force"]
    finally:
        heights.write_bytes(original)


def test_a_swept_file_replaced_mid_sweep_stops_it_naming_the_file(replaced, tmp_path):
    folder, _ = replaced
    for name in ("a.csv", "b.csv", "heights.csv"):
        shutil.copy(folder / "heights.csv", tmp_path / name)
    shutil.copy(folder / "direct.toml", tmp_path)
    shutil.copy(folder / "motion.csv", tmp_path)
    (tmp_path / "sweep.toml").write_text(
        '[sweep]\nmodel = "direct.toml"\nmotion = "motion.csv"\nmetrics = ["mean_force"]\n'
        '[sweep.parameters]\n"model.discretisation.heights_file" = { values = ["a.csv", '
        '"b.csv"] }\n"model.attraction" = { values = [1e3, 1e4, 1e5] }\n')

    def replace(done, total, failed):
        if done == 1:
            shutil.copy(folder / "other.csv", tmp_path / "b.csv")

    with pytest.raises(InputError, match="b.csv: changed while the sweep ran"):
        polind.sweep(tmp_path / "sweep.toml", tmp_path / "out.csv", workers=1,
                     progress=replace)
    assert read_results(tmp_path / "out.csv")["run"] == [0, 1, 2]     # those of a.csv


# --- a plugin model that gives NaN or inf ------------------------------------------------------

@njit(error_model="numpy")
def _poor_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
               normal_load):
    # A sign function written as v / |v|: 0 / 0 at rest, x / 0 when the scale is 0.
    return scalars[0] * step_velocity / (scalars[1] * abs(step_velocity))


@njit(error_model="numpy")
def _poor_force(scalars, table, state, sample_velocity, normal_load):
    return scalars[0] * sample_velocity / (scalars[1] * abs(sample_velocity))


@njit(error_model="numpy")
def _poor_tangent(scalars, table, state, step):
    return 0.0


class PoorCoulomb(polind.FrictionModel):
    """Coulomb friction as ``Fc v / (s |v|)``: NaN at rest, inf for s = 0."""

    type = "poor-coulomb"
    parameters = (polind.Param("coulomb_force", unit="N"), polind.Param("scale", unit="1", bound="nonnegative"))

    def step_functions(self):
        return polind.StepFunctions(_poor_step, _poor_force, _poor_tangent)

    def kernel_arrays(self, state):
        p = self.params
        return np.array([p["coulomb_force"], p["scale"]]), np.zeros((1, 0))

    def force_scale(self):
        return self.params["coulomb_force"]


def test_a_plugin_run_that_gives_nan_or_inf_is_a_failed_row_naming_it(tmp_path):
    polind.register_model(PoorCoulomb)
    try:
        t = np.arange(11) * 1e-3
        moving = 1e-6 * np.arange(11)
        resting = 1e-6 * np.minimum(np.arange(11), 5)         # at rest from the 7th sample
        model = {"model": {"type": "poor-coulomb", "coulomb_force": 1.0, "scale": 1.0}}
        rows = {}
        for name, x in (("moving", moving), ("resting", resting)):
            plan = Sweep(model, motion={"t": t, "x": x}, metrics=["max_force"],
                         parameters={"model.scale": {"values": [1.0, 0.0]}})
            rows[name] = polind.sweep(plan, tmp_path / f"{name}.csv", workers=1).table
        assert rows["moving"]["status"][0] == "ok"
        assert rows["moving"]["max_force"][0] == 1.0
        nan = rows["resting"]["status"][0]
        inf = rows["moving"]["status"][1]
        assert nan.startswith("the run's friction force is nan at t = 0.006 s (sample 7 of "
                              "11): the poor-coulomb model"), nan
        assert inf.startswith("the run's friction force is inf at t = 0 s (sample 1 of 11): "
                              "the poor-coulomb model"), inf
        assert np.isnan(rows["resting"]["max_force"][0])
        # The table says so too, read back.
        statuses = read_results(tmp_path / "resting.csv")["status"]
        assert all(status != "ok" for status in statuses)
    finally:
        polind.unregister_model(PoorCoulomb.type)


def test_a_non_finite_output_is_a_failed_row_even_where_simulate_lets_it_through(
        monkeypatch, tmp_path):
    """The sweep's own check, for a simulate without one (or a quantity it does not check)."""
    from types import SimpleNamespace

    import polind.sweeps.runs as runs

    def leaky(model, t, x=None, **options):
        velocity = np.gradient(x, t)
        velocity[3] = np.inf if model.params["coulomb_force"] > 1.5 else velocity[3]
        force = np.full(len(t), model.params["coulomb_force"])
        force[5] = np.nan if model.params["coulomb_force"] < 1.5 else force[5]
        return SimpleNamespace(t=t, x=x, v=velocity, force=force)

    monkeypatch.setattr(runs, "simulate", leaky)
    t = np.arange(11) * 1e-3
    plan = Sweep({"model": {"type": "coulomb", "coulomb_force": 1.0}},
                 motion={"t": t, "x": 1e-6 * np.arange(11)}, metrics=["max_force"],
                 parameters={"model.coulomb_force": {"values": [1.0, 2.0]}})
    table = polind.sweep(plan, tmp_path / "leaky.csv", workers=1).table
    assert table["status"][0].startswith("the run's friction force is nan at t = 0.005 s "
                                         "(sample 6 of 11): the coulomb model")
    assert table["status"][1].startswith("the run's velocity is inf at t = 0.003 s (sample 4 "
                                          "of 11): the coulomb model")
    assert all(np.isnan(value) for value in table["max_force"])


def test_the_sweep_leaves_an_ignored_signal_ignored_and_puts_handlers_back():
    import signal

    from polind.sweeps.engine import _signals_interrupt

    before = {number: signal.getsignal(number) for number in (signal.SIGTERM, signal.SIGHUP)}
    signal.signal(signal.SIGHUP, signal.SIG_IGN)            # nohup
    try:
        with _signals_interrupt():
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            with pytest.raises(KeyboardInterrupt):
                signal.raise_signal(signal.SIGTERM)
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
        assert signal.getsignal(signal.SIGTERM) == before[signal.SIGTERM]
    finally:
        for number, handler in before.items():
            signal.signal(number, handler)


# --- killed and signalled sweeps ---------------------------------------------------------------

_HELPER = textwrap.dedent(r'''
    import json, os, random, signal, sys, time

    import numpy as np

    import polind
    from polind.cli import _run
    from polind.sweeps import Sweep, read_results, register_metric

    # What the tests send must reach the sweeps, whatever the shell that started them.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    for name in ("SIGTERM", "SIGHUP"):
        signal.signal(getattr(signal, name), signal.SIG_DFL)
    folder = sys.argv[1]
    chance = random.Random()

    @register_metric("paced", unit="", definition="1, after a pause (long every 10th run)")
    def paced(run):
        # Bursts of rows and pauses between them, as the runs of a sweep come.
        index = round(run.model.params["coulomb_force"])
        time.sleep(2.6 if index % 10 == 9 else 0.02)
        return 1.0

    import pyarrow
    pyarrow.array([0.0])            # pandas, which pyarrow imports at its first array: once

    t = np.arange(11) * 1e-3
    motion = {"t": t, "x": 1e-6 * np.arange(11)}
    model = {"model": {"type": "coulomb", "coulomb_force": 1.0}}
    polind.simulate(polind.model_from_dict(model), t, x=motion["x"])      # the kernel, once
    plan = Sweep(model, motion=motion, metrics=["paced"],
                 parameters={"model.coulomb_force": {"range": [0.0, 999.0], "count": 1000}})
    with open(os.path.join(folder, "sweep.toml"), "w") as stream:
        stream.write('[sweep]\nmodel = "coulomb.toml"\nmotion = "motion.csv"\n'
                     'metrics = ["paced"]\n[sweep.parameters]\n'
                     '"model.coulomb_force" = { range = [0.0, 999.0], count = 1000 }\n')
    with open(os.path.join(folder, "coulomb.toml"), "w") as stream:
        stream.write('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    polind.io.write_csv_atomic(os.path.join(folder, "motion.csv"), motion)

    def child(job):
        """In a forked process: the job's sweep; never returns."""
        status = 1
        try:
            if job["kind"] == "kill":
                log = open(job["log"], "w", buffering=1)
                polind.sweep(plan, job["out"], workers=1, progress=lambda done, total,
                             failed: log.write(f"{done} {time.time()!r}\n"))
            else:
                err = os.open(job["err"], os.O_WRONLY | os.O_CREAT, 0o644)
                os.dup2(err, 2)
                status = _run(["sweep", os.path.join(folder, "sweep.toml"), "-o", job["out"],
                               "--workers", "1"])
        finally:
            os._exit(status)

    # Each kill at a random moment of the first pause, 2.1 to 2.5 s after the last row
    # before it: where a kill -9 may lose most (the rows of the burst are all more than
    # 2 s old, and no row came since).
    jobs = [{"kind": "kill", "signal": "SIGKILL", "out": os.path.join(folder, f"k{k}.parquet"),
             "log": os.path.join(folder, f"k{k}.log"), "row": 9,
             "after": chance.uniform(2.1, 2.5)} for k in range(5)]
    jobs += [{"kind": "command", "signal": name, "out": os.path.join(folder, f"s{k}{suffix}"),
              "err": os.path.join(folder, f"s{k}.err"), "after": chance.uniform(0.0, 0.15)}
             for k, (name, suffix) in enumerate([("SIGINT", ".csv"), ("SIGTERM", ".csv"),
                                                  ("SIGHUP", ".csv"), ("SIGTERM", ".parquet")])]
    try:
        for job in jobs:
            job["pid"] = os.fork()
            if job["pid"] == 0:
                child(job)
        deadline = time.time() + 30.0
        while any("status" not in job for job in jobs) and time.time() < deadline:
            for job in jobs:
                if "status" in job:
                    continue
                if "sent" not in job:
                    if "start" not in job and job["kind"] == "command":
                        if os.path.exists(job["out"]):
                            job["start"] = time.time()
                    elif "start" not in job and os.path.exists(job["log"]):
                        for line in open(job["log"]).read().split("\n")[:-1]:
                            done, moment = line.split()         # the complete lines
                            if int(done) == job["row"]:
                                job["start"] = float(moment)
                    elif time.time() >= job["start"] + job["after"]:
                        job["sent"] = time.time()
                        os.kill(job["pid"], getattr(signal, job["signal"]))
                pid, status = os.waitpid(job["pid"], os.WNOHANG)
                if pid:
                    job["status"] = os.waitstatus_to_exitcode(status)
            time.sleep(0.005)
    finally:
        for job in jobs:
            if "status" not in job:
                os.kill(job["pid"], signal.SIGKILL)
                job["status"] = os.waitstatus_to_exitcode(os.waitpid(job["pid"], 0)[1])
    for job in jobs:
        job["rows"] = len(read_results(job["out"])["run"]) if os.path.exists(job["out"]) else 0
        if job["kind"] == "kill":
            times = [line.split() for line in open(job["log"]).read().splitlines()]
            job["finished"] = [[int(done), float(moment)] for done, moment in times]
        else:
            job["err"] = open(job["err"]).read()
    json.dump({"jobs": jobs, "files": sorted(os.listdir(folder))}, sys.stdout)
''')


@pytest.fixture(scope="module")
def signalled(tmp_path_factory):
    folder = tmp_path_factory.mktemp("signalled")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [os.path.join(ROOT, "src")] + ([env["PYTHONPATH"]] if env.get("PYTHONPATH") else []))
    done = subprocess.run([sys.executable, "-c", _HELPER, os.fspath(folder)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    return report["jobs"], report["files"]


def test_a_sigkilled_parquet_sweep_loses_at_most_its_last_two_seconds(signalled):
    jobs, _ = signalled
    kills = [job for job in jobs if job["kind"] == "kill"]
    assert len(kills) == 5
    for job in kills:
        assert "sent" in job and job["status"] == -9, job["status"]
        # The runs finished more than 2 s before the kill are all in the table.
        due = max([done for done, moment in job["finished"] if moment <= job["sent"] - 2.0]
                  or [0])
        finished = job["finished"][-1][0]
        assert due <= job["rows"] <= finished, (job["after"], due, job["rows"], finished)


@pytest.mark.parametrize("number", range(4))
def test_sigterm_and_sighup_end_a_sweep_as_sigint_does(signalled, number):
    jobs, files = signalled
    job = [job for job in jobs if job["kind"] == "command"][number]
    name = os.path.basename(job["out"])
    assert job["status"] == 130, (job["signal"], job["status"], job["err"])
    assert f"stopped with {job['rows']} of 1000 runs written" in job["err"], job["err"]
    assert job["rows"] >= 1
    assert job["err"].endswith("polind: error: interrupted\n"), job["err"]
    # No lock, no temporary file left beside the table.
    assert [file for file in files if file.startswith(f".{name}")
            and not file.endswith(".sweep.json")] == []
