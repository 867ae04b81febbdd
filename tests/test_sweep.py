"""polind.sweep, the package polind.sweeps and `polind sweep` (INTERFACE.md "Sweeps").

The runs are small (LuGre of 1995, a few thousand steps each) so that the
tests time the bookkeeping, not the physics: rows equal direct runs, the
engines agree bit for bit, an interrupted sweep resumes with every run once,
a failing run is a row, bad sweep files are one line and exit 2.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import tomli_w

import polind
from conftest import LUGRE_1995
from polind.dynamics import System, simulate_system
from polind.errors import InputError
from polind.sweeps import (MAX_RUNS, METRICS, Sweep, SweepInterrupted, load_sweep, plot_results,
                           read_results, register_metric)

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

ROOT = Path(__file__).resolve().parents[1]

#: A spring-driven LuGre body pushed by a sinusoidal force too: every metric is defined.
SYSTEM = {"system": {"mass": 1.0, "duration": 4.0, "time_step": 2e-3,
                     "spring_drive": {"stiffness": 20.0, "velocity": 0.02},
                     "force": {"offset": 0.0, "amplitude": 0.2, "frequency": 2.0}}}
ALL_METRICS = ["mean_force", "max_force", "rms_force", "stick_slip_amplitude",
               "stick_slip_period", "stuck_fraction", "advance_per_cycle", "breakaway_force",
               "loop_area"]


def write_toml(path, document):
    path.write_text(tomli_w.dumps(document))
    return path


def sweep_files(folder):
    """A LuGre model file and a system file in ``folder``, and a writer of sweep files
    beside them."""
    write_toml(folder / "lugre.toml", {"model": LUGRE_1995})
    write_toml(folder / "system.toml", SYSTEM)

    def sweep_file(parameters=None, name="sweep.toml", **extra):
        table = {"model": "lugre.toml", "system": "system.toml", "metrics": ALL_METRICS,
                 "method": "grid", **extra}
        table["parameters"] = parameters if parameters is not None else {
            "system.spring_drive.velocity": {"values": [0.05, 0.2]},
            "system.spring_drive.stiffness": {"range": [10.0, 100.0], "scale": "log",
                                              "count": 3}}
        return write_toml(folder / name, {"sweep": table})

    return sweep_file


@pytest.fixture
def files(tmp_path):
    """:func:`sweep_files` in the test's own folder."""
    return sweep_files(tmp_path)


def rows(table):
    """The rows of a results table without the wall times (which differ from run to run)."""
    keys = [key for key in table if key != "seconds"]
    return [tuple(table[key][i] for key in keys) for i in range(len(table["run"]))]


def same_rows(one, other):
    """Bit for bit, NaN equal to NaN."""
    assert len(one) == len(other)
    for a, b in zip(one, other):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            if isinstance(x, float) and math.isnan(x):
                assert isinstance(y, float) and math.isnan(y), (a, b)
            else:
                assert x == y, (a, b)


# --- the metrics equal direct runs ------------------------------------------------------------

def independent_metrics(res, system, model_levels_vs):
    """Each metric of the README computed again, plainly, from a direct run."""
    t, x, v, force, applied = res.t, res.x, res.v, res.force, res.applied
    late = t >= 0.5 * t[-1]
    vd = system.drive_velocity
    stuck = v < 0.1 * vd
    # slips: the drive force falls into the lower quarter of its range from the upper quarter
    low, high = applied[late].min(), applied[late].max()
    slips, armed = [], False
    for k in np.flatnonzero(late):
        if applied[k] > high - 0.25 * (high - low):
            armed = True
        elif applied[k] < low + 0.25 * (high - low):
            if armed:
                slips.append(t[k])
            armed = False
    period = float(np.mean(np.diff(slips))) if len(slips) >= 2 and stuck[late].any() \
        else math.nan
    f = system.frequency
    cycles = int(math.floor(t[-1] * f * (1 + 1e-12)))
    means = [np.mean(x[(t * f * (1 + 1e-12) >= c) & (np.floor(t * f * (1 + 1e-12)) == c)])
             for c in range(cycles)]
    moving = np.flatnonzero(np.abs(v) > model_levels_vs)
    vl, fl = v[late], force[late]
    middle = 0.5 * (vl.min() + vl.max())
    up = [k for k in range(1, vl.size) if vl[k - 1] < middle <= vl[k]]
    area = math.nan
    if len(up) >= 2:
        a, b = up[-2], up[-1]
        area = sum(0.5 * (fl[k + 1] + fl[k]) * (vl[k + 1] - vl[k]) for k in range(a, b))
    return {
        "mean_force": float(np.mean(force)),
        "max_force": float(np.max(force)),
        "rms_force": math.sqrt(float(np.mean(force ** 2))),
        "stick_slip_amplitude": 0.5 * float(applied[late].max() - applied[late].min()),
        "stick_slip_period": period,
        "stuck_fraction": float(np.mean(stuck[late])),
        "advance_per_cycle": float(means[-1] - means[-2]),
        "breakaway_force": float(applied[moving[0]]) if moving.size else math.nan,
        "loop_area": area,
    }


def test_rows_equal_direct_simulate_system_runs(files, tmp_path):
    out = tmp_path / "results.csv"
    summary = polind.sweep(files(), out, workers=2)
    assert summary.runs == summary.computed == 6 and summary.failed == 0
    table = read_results(out)
    assert table["run"] == list(range(6))
    assert table["system.spring_drive.velocity"] == [0.05] * 3 + [0.2] * 3   # last key fastest
    assert table["system.spring_drive.stiffness"][:3] == pytest.approx([10.0, 31.6227766, 100.0])
    model = polind.model_from_dict({"model": LUGRE_1995})
    for index in (2, 4):
        vd, kd = table["system.spring_drive.velocity"][index], \
            table["system.spring_drive.stiffness"][index]
        system = System(mass=1.0, duration=4.0, time_step=2e-3, spring_stiffness=kd,
                        drive_velocity=vd, amplitude=0.2, frequency=2.0)
        res = simulate_system(model, system)
        want = independent_metrics(res, system, LUGRE_1995["stribeck_velocity"])
        for name, value in want.items():
            got = table[name][index]
            if math.isnan(value):
                assert math.isnan(got), name
            else:
                assert got == pytest.approx(value, rel=1e-12, abs=1e-15), name
        assert table["mean_force"][index] == float(np.mean(res.force))   # bit for bit
    # run 2 has every metric defined (it sticks and slips); run 4 has no stick-slip period
    assert not any(math.isnan(table[name][2]) for name in ALL_METRICS)
    assert math.isnan(table["stick_slip_period"][4])


def test_rows_equal_direct_simulate_runs_over_a_motion(tmp_path):
    t = np.linspace(0.0, 2.0, 2001)
    v = 1e-3 + 0.9e-3 * np.sin(2 * np.pi * 2.0 * t)
    plan = Sweep({"model": LUGRE_1995}, motion={"t": t, "v": v},
                 metrics=["mean_force", "max_force", "rms_force", "loop_area"],
                 parameters={"model.bristle_stiffness": {"range": [1e4, 1e6], "scale": "log"},
                             "model.stribeck_shape": {"values": ["exponential", "rational"]}},
                 method="latin-hypercube", samples=4, seed=3)
    summary = polind.sweep(plan, tmp_path / "motion.parquet", workers=1)
    table = summary.table
    assert set(table["model.stribeck_shape"]) == {"exponential", "rational"}
    for index in (1, 3):
        model = polind.model_from_dict({"model": {
            **LUGRE_1995, "bristle_stiffness": table["model.bristle_stiffness"][index],
            "stribeck_shape": table["model.stribeck_shape"][index]}})
        force = polind.simulate(model, t, v=v).force
        assert table["mean_force"][index] == float(np.mean(force))
        assert table["max_force"][index] == float(np.max(force))
        assert table["rms_force"][index] == pytest.approx(math.sqrt(np.mean(force ** 2)),
                                                           rel=1e-14)
        assert table["loop_area"][index] > 0.0          # frictional lag


# --- designs ---------------------------------------------------------------------------------

def test_latin_hypercube_strata_and_random_seed(tmp_path):
    system = System(mass=1.0, duration=0.1, time_step=1e-3, spring_stiffness=1.0,
                    drive_velocity=0.1)
    common = dict(system=system, metrics=["mean_force"],
                  parameters={"model.coulomb_force": {"range": [1.0, 2.0]},
                              "model.static_force": {"range": [1e-1, 1e3], "scale": "log"}})
    lhs = Sweep({"model": LUGRE_1995}, method="latin-hypercube", samples=10, seed=1, **common)
    design = np.array(lhs.design())
    assert sorted(np.floor((design[:, 0] - 1.0) * 10).astype(int)) == list(range(10))
    assert sorted(np.floor((np.log10(design[:, 1]) + 1) / 4 * 10).astype(int)) == list(range(10))
    assert lhs.design() == [tuple(row) for row in design.tolist()]    # same seed, same runs
    random = Sweep({"model": LUGRE_1995}, method="random", samples=8, seed=1, **common)
    longer = Sweep({"model": LUGRE_1995}, method="random", samples=12, seed=1, **common)
    assert longer.design()[:8] == random.design()          # a random sweep can grow
    other = Sweep({"model": LUGRE_1995}, method="random", samples=8, seed=2, **common)
    assert other.design() != random.design()


def test_a_random_sweep_grown_computes_only_the_new_runs(tmp_path):
    system = System(mass=1.0, duration=0.2, time_step=1e-3, spring_stiffness=1.0,
                    drive_velocity=0.1)
    common = dict(system=system, metrics=["mean_force"], method="random", seed=0,
                  parameters={"model.coulomb_force": {"range": [0.5, 1.0]}})
    out = tmp_path / "grow.parquet"
    first = polind.sweep(Sweep({"model": LUGRE_1995}, samples=5, **common), out, workers=2)
    second = polind.sweep(Sweep({"model": LUGRE_1995}, samples=9, **common), out, workers=2)
    assert (first.computed, second.computed, second.existing) == (5, 4, 5)
    assert second.table["run"] == list(range(9))


# --- engines -------------------------------------------------------------------------------

def engine_sweep(files):
    return files({"model.bristle_damping": {"values": [100.0, 316.0]},
                  "system.spring_drive.velocity": {"range": [0.005, 0.2], "scale": "log",
                                                   "count": 3}})


@pytest.fixture(scope="module")
def engine_runs(tmp_path_factory):
    """The engine sweep run once on one thread (one.csv) and once on two (two.parquet), and
    the map of the second drawn (two.png): ``(folder, one, two)``."""
    folder = tmp_path_factory.mktemp("engines")
    path = engine_sweep(sweep_files(folder))
    one = polind.sweep(path, folder / "one.csv", workers=1)
    two = polind.sweep(path, folder / "two.parquet", workers=2)
    plot_results(folder / "two.parquet", path, folder / "two.png")
    return folder, one, two


def test_one_and_two_threads_give_identical_rows(engine_runs):
    folder, one, two = engine_runs
    same_rows(rows(one.table), rows(two.table))
    same_rows(rows(read_results(folder / "one.csv")),
              rows(read_results(folder / "two.parquet")))


def test_a_dask_cluster_of_two_processes_gives_identical_rows(files, tmp_path):
    distributed = pytest.importorskip("distributed")
    path = engine_sweep(files)
    local = polind.sweep(path, tmp_path / "local.csv", workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40) as cluster:
        remote = polind.sweep(path, tmp_path / "dask.csv", scheduler=cluster.scheduler_address)
    assert remote.computed == 6 and remote.lost == 0
    same_rows(rows(local.table), rows(remote.table))
    same_rows(rows(read_results(tmp_path / "local.csv")), rows(read_results(tmp_path / "dask.csv")))


def test_an_unreachable_scheduler_is_one_line_and_exit_2(files, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(sys.modules["polind.sweeps.cluster"], "CONNECT_TIMEOUT", 1.0)
    status, _, err = run(capsys, "sweep", files(), "--output", tmp_path / "r.csv",
                         "--scheduler", "tcp://127.0.0.1:9")
    assert status == 2 and err.count("\n") == 1 and "127.0.0.1:9" in err, err
    assert not (tmp_path / "r.csv").exists()


# --- nothing lost ----------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_an_interrupted_sweep_run_again_has_every_run_exactly_once(files, tmp_path, suffix):
    path = engine_sweep(files)
    out = tmp_path / f"results{suffix}"

    def interrupt(done, total, failed):
        if done == 2:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted) as stopped:
        polind.sweep(path, out, workers=2, progress=interrupt)
    kept = read_results(out)["run"]
    assert stopped.value.done == len(kept) >= 2 and len(kept) < 6
    again = polind.sweep(path, out, workers=2)
    assert again.computed == 6 - len(kept) and again.existing == len(kept)
    table = read_results(out)
    assert sorted(table["run"]) == list(range(6))
    if suffix == ".csv":        # appended as they finished: each run on exactly one line
        lines = out.read_text().splitlines()[1:]
        assert sorted(int(line.split(",")[0]) for line in lines) == list(range(6))
    whole = polind.sweep(path, tmp_path / f"whole{suffix}", workers=1)
    same_rows(rows(table), rows(whole.table))
    assert polind.sweep(path, out, workers=2).computed == 0


def test_a_killed_sweep_keeps_its_finished_rows(files, tmp_path):
    """SIGKILL mid-way (no clean-up at all): a row cut short is dropped, the others kept."""
    # 16 runs of about 0.15 s each: killed after 3, with a dozen left to run again
    path = files({"system.spring_drive.velocity": {"range": [0.01, 0.1], "count": 16},
                  "system.time_step": {"values": [2e-5]}}, metrics=["mean_force"])
    out = tmp_path / "killed.csv"
    script = ("import polind, sys; polind.sweep(sys.argv[1], sys.argv[2], workers=1)")
    process = subprocess.Popen([sys.executable, "-c", script, str(path), str(out)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline:
        if out.exists() and out.read_text().count("\n") >= 4:
            break
        time.sleep(0.02)
    process.kill()
    process.wait()
    with out.open("a") as stream:             # as if it died in the middle of a row
        stream.write("17,0.0")
    kept = out.read_text().count("\n") - 1
    assert 3 <= kept < 16
    again = polind.sweep(path, out, workers=2)
    assert again.computed == 16 - kept
    lines = out.read_text().splitlines()[1:]
    assert sorted(int(line.split(",")[0]) for line in lines) == list(range(16))


def test_a_failing_run_is_recorded_and_the_rest_complete(files, tmp_path):
    path = files({"model.static_force": {"values": [1.5, -1.0, 2.0]},
                  "system.time_step": {"values": [2e-3, 10.0]}})
    summary = polind.sweep(path, tmp_path / "fail.parquet", workers=2)
    table = summary.table
    assert summary.computed == 6 and summary.failed == 4
    status = dict(zip(table["run"], table["status"]))
    assert status[0] == status[4] == "ok"
    assert "'static_force'" in status[2] and "-1.0" in status[2] and "\n" not in status[2]
    assert "'time_step'" in status[1]                        # longer than the duration
    assert all(math.isnan(table["mean_force"][i]) for i in (1, 2, 3, 5))
    assert not math.isnan(table["mean_force"][4])


# --- refusing another sweep's output -------------------------------------------------------------

def test_an_output_of_another_sweep_is_refused_not_mixed(files, tmp_path):
    out_csv, out_parquet = tmp_path / "r.csv", tmp_path / "r.parquet"
    polind.sweep(files(), out_csv, workers=2)
    polind.sweep(files(), out_parquet, workers=2)
    before = out_csv.read_bytes(), out_parquet.read_bytes()
    other_values = files({"system.spring_drive.velocity": {"values": [0.05, 0.3]},
                          "system.spring_drive.stiffness": {"range": [10.0, 100.0],
                                                            "scale": "log", "count": 3}},
                         name="other.toml")
    for out in (out_csv, out_parquet):
        with pytest.raises(InputError, match=r"run 3\) has system.spring_drive.velocity = 0.2 "
                                             r"where .*other.toml gives 0.3"):
            polind.sweep(other_values, out)
    other_metrics = files(name="metrics.toml", metrics=["mean_force"])
    for out in (out_csv, out_parquet):
        with pytest.raises(InputError, match="columns"):
            polind.sweep(other_metrics, out)
    # the same parameters but another model: the Parquet metadata tells
    write_toml(tmp_path / "lugre.toml", {"model": {**LUGRE_1995, "coulomb_force": 0.9}})
    with pytest.raises(InputError, match="another model"):
        polind.sweep(files(), out_parquet)
    assert (out_csv.read_bytes(), out_parquet.read_bytes()) == before


# --- bad sweep files ----------------------------------------------------------------------------

BAD = {
    "unknown key": ({"model.atraction": {"values": [1.0]}}, {},
                    ["model.atraction", "unknown key"]),
    "unknown system key": ({"system.spring_drive.speed": {"values": [1.0]}}, {},
                           ["system.spring_drive.speed", "unknown key"]),
    "empty range": ({"model.coulomb_force": {"range": [2.0, 2.0], "count": 3}}, {},
                    ["model.coulomb_force", "empty"]),
    "reversed range": ({"model.coulomb_force": {"range": [2.0, 1.0], "count": 3}}, {},
                       ["model.coulomb_force", "empty"]),
    "empty values": ({"model.coulomb_force": {"values": []}}, {},
                     ["model.coulomb_force", "empty"]),
    "log range through zero": ({"model.coulomb_force": {"range": [-1.0, 1.0], "scale": "log",
                                                        "count": 3}}, {},
                               ["model.coulomb_force", "log range", "zero"]),
    "log range from zero": ({"model.coulomb_force": {"range": [0.0, 1.0], "scale": "log",
                                                     "count": 3}}, {},
                            ["model.coulomb_force", "zero"]),
    "grid range without count": ({"model.coulomb_force": {"range": [1.0, 2.0]}}, {},
                                 ["model.coulomb_force", "count = N"]),
    "unknown metric": (None, {"metrics": ["mean_force", "stickslip"]},
                       ["sweep.metrics", "stickslip"]),
    "unknown sweep key": (None, {"sample": 3}, ["sweep.sample", "unknown key"]),
    "unknown method": (None, {"method": "sobol"}, ["sweep.method", "sobol"]),
    "samples missing": (None, {"method": "random"}, ["sweep.samples"]),
    "a word for a number": ({"model.bristle_stiffness": {"values": ["a"]}}, {},
                            ["model.bristle_stiffness", "finite numbers"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_sweep_file_is_one_line_naming_file_and_key(files, tmp_path, capsys, case):
    parameters, extra, fragments = BAD[case]
    path = files(parameters, **extra)
    with pytest.raises(InputError):
        load_sweep(path)
    status, out, err = run(capsys, "sweep", path, "--output", tmp_path / "r.csv")
    assert status == 2 and out == "", err
    assert err.startswith("polind: error: ") and err.count("\n") == 1, err
    for fragment in [str(path), *fragments]:
        assert fragment in err, (fragment, err)
    assert not (tmp_path / "r.csv").exists()


def test_too_many_runs_need_yes(files, tmp_path, capsys):
    path = files({"model.coulomb_force": {"range": [0.5, 1.0], "count": 200},
                  "model.static_force": {"range": [1.5, 2.0], "count": 60}})
    status, _, err = run(capsys, "sweep", path, "--output", tmp_path / "r.csv")
    assert status == 2 and err.count("\n") == 1
    for fragment in (str(path), "12,000 runs", f"{MAX_RUNS:,}", "--yes"):
        assert fragment in err, err
    huge = files({"model.coulomb_force": {"range": [0.5, 1.0], "count": 100000},
                  "model.static_force": {"range": [1.5, 2.0], "count": 100000}}, name="huge.toml")
    with pytest.raises(InputError, match="10,000,000,000 runs"):   # counted, never built
        polind.sweep(huge, tmp_path / "r.csv")
    assert str(MAX_RUNS) in " ".join(
        subprocess.run([sys.executable, "-m", "polind", "sweep", "--help"], capture_output=True,
                       text=True, check=True).stdout.replace(",", "").split())


def test_a_metric_that_needs_a_body_is_refused_over_a_motion(tmp_path):
    with pytest.raises(InputError, match="stick_slip_period.*needs a \\[system"):
        Sweep({"model": LUGRE_1995}, motion={"t": [0.0, 1.0], "x": [0.0, 1e-3]},
              metrics=["stick_slip_period"], parameters={"model.coulomb_force": {"values": [1.0]}})
    write_toml(tmp_path / "s.toml", {"system": {"mass": 1.0, "duration": 1.0, "time_step": 0.1,
                                               "spring_drive": {"stiffness": 1.0,
                                                                "velocity": 0.1}}})
    with pytest.raises(InputError, match="advance_per_cycle.*system.force"):
        Sweep({"model": LUGRE_1995}, system=tmp_path / "s.toml", metrics=["advance_per_cycle"],
              parameters={"model.coulomb_force": {"values": [1.0]}})


# --- the module, the registry, the figure -----------------------------------------------------

def test_polind_sweep_is_the_function_and_polind_sweeps_the_package_whichever_comes_first():
    import importlib.util
    import inspect
    import types

    for code in ("import polind; f = polind.sweep; import polind.sweeps as m; "
                 "assert m.sweep is f and polind.sweep is f and callable(f) "
                 "and 'loop_area' in m.METRICS",
                 "import polind.sweeps as m; import polind; "
                 "assert polind.sweeps is m and polind.sweep is m.sweep and callable(polind.sweep)",
                 "import polind; m = polind.sweeps; "
                 "assert polind.sweep is m.sweep and 'loop_area' in m.METRICS"):
        subprocess.run([sys.executable, "-c", code], check=True)
    assert inspect.isfunction(polind.sweep) and polind.sweep.__name__ == "sweep"
    assert isinstance(polind.sweeps, types.ModuleType) and not callable(polind.sweeps)
    assert polind.sweeps.sweep is polind.sweep and polind.sweeps.METRICS is METRICS
    assert importlib.util.find_spec("polind.sweep") is None      # no module of that name
    # The public surface: polind.sweeps exports what the tests, the docs and the CLI use.
    for name in ("Sweep", "SweepSummary", "SweepInterrupted", "load_sweep", "read_results",
                 "plot_results", "METRICS", "NEEDS", "register_metric", "MAX_RUNS", "SWEEP_KEYS",
                 "Metric", "RunOutput", "sweep"):
        assert name in polind.sweeps.__all__ and getattr(polind.sweeps, name) is not None, name
    assert polind.SweepSummary is polind.sweeps.SweepSummary and "SweepSummary" in polind.__all__


def test_every_metric_is_defined_in_the_readme():
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("## Sweeps"):]
    for name in METRICS:
        assert f"`{name}`" in section, name


def test_a_registered_metric_becomes_a_column(files, tmp_path):
    @register_metric("final_position", unit="m", needs="body", definition="x at the end")
    def final_position(run):
        return float(run.x[-1])

    try:
        path = files({"system.spring_drive.velocity": {"values": [0.05]}},
                     metrics=["final_position"])
        table = polind.sweep(path, tmp_path / "f.csv", workers=1).table
        assert table["final_position"][0] > 0.0
    finally:
        del METRICS["final_position"]


@pytest.mark.parametrize("method", ["grid", "random"])
def test_plot_draws_a_line_over_one_parameter_and_a_map_over_two(files, tmp_path, method,
                                                                  engine_runs):
    extra = {"method": method, "samples": 6} if method == "random" else {}
    one = files({"system.spring_drive.velocity": {"range": [0.005, 0.2], "scale": "log",
                                                  "count": 4}}, name="one.toml",
                metrics=["mean_force", "stuck_fraction"], **extra)
    polind.sweep(one, tmp_path / "one.csv", workers=2)
    plot_results(tmp_path / "one.csv", one, tmp_path / "one.png")
    # the map over two parameters: the engine sweep's, drawn once (engine_runs)
    for png in (tmp_path / "one.png", engine_runs[0] / "two.png"):
        data = png.read_bytes()
        assert data.startswith(b"\x89PNG") and 5_000 < len(data) < 400_000


# --- the command line -------------------------------------------------------------------------

def test_the_command_writes_the_table_and_the_plot(files, tmp_path, capsys):
    path = files()
    out, png = tmp_path / "r.parquet", tmp_path / "map.png"
    status, stdout, err = run(capsys, "sweep", path, "--output", out, "--workers", "2",
                              "--plot", png)
    assert status == 0, err
    assert "6 runs" in stdout and str(out) in stdout and str(png) in stdout
    assert read_results(out)["status"] == ["ok"] * 6 and png.read_bytes().startswith(b"\x89PNG")
    status, stdout, err = run(capsys, "sweep", path, "--output", out)
    assert status == 0 and "0 computed" in stdout and "6 already" in stdout, stdout


def test_the_command_refuses_an_output_that_is_an_input(files, tmp_path, capsys):
    status, _, err = run(capsys, "sweep", files(), "--output", tmp_path / "lugre.toml")
    assert status == 2 and err.count("\n") == 1
    status, _, err = run(capsys, "sweep", files(), "--output", tmp_path / "r.txt")
    assert status == 2 and ".parquet or .csv" in err


def test_ctrl_c_stops_the_command_with_its_finished_rows_kept(files, tmp_path):
    path = files({"system.spring_drive.velocity": {"range": [0.01, 0.1], "count": 60},
                  "system.time_step": {"values": [2e-5]}}, metrics=["mean_force"])
    out = tmp_path / "r.csv"
    process = subprocess.Popen([sys.executable, "-m", "polind", "sweep", str(path), "--output",
                                str(out), "--workers", "1"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 60.0
    while time.monotonic() < deadline and not (out.exists() and
                                               out.read_text().count("\n") >= 3):
        time.sleep(0.02)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert "run the same command again" in err
    kept = read_results(out)["run"]
    assert 2 <= len(kept) < 60
    assert not [name for name in os.listdir(tmp_path) if name.endswith(".tmp")]
