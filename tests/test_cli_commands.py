"""The commands wired onto the library: surface, dynamics, fit, demo, bench (INTERFACE.md)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomli_w

import polind
from conftest import LUGRE_1995
from polind import cli
from polind.bench import harness, surfaces
from polind.models.pol_ind import default_table

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

def one_error_line(err, *fragments):
    assert err.count("\n") == 1 and err.startswith("polind: error: "), repr(err)
    for fragment in fragments:
        assert fragment in err, (fragment, err)


def write_toml(path, document):
    path.write_text(tomli_w.dumps(document))
    return path


# --- surface ------------------------------------------------------------------------------

def test_surface_json_is_the_contact_of_the_model(tmp_path, capsys):
    model_path = write_toml(tmp_path / "pol.toml", {"model": default_table()})
    status, out, err = run(capsys, "surface", model_path, "--json")
    assert status == 0 and err == ""
    summary = json.loads(out)
    assert set(summary) == {"separation", "contacts", "real_area", "normal_load", "elements",
                            "validity"}
    assert set(summary["elements"][0]) == {"stiffness", "breakaway_force", "asperities",
                                           "interference"}
    assert len(summary["elements"]) == 64
    total = sum(e["breakaway_force"] for e in summary["elements"])
    assert total == pytest.approx(0.15 * 100.0, rel=1e-9)          # Amontons
    model = polind.load_model(model_path)
    assert summary["separation"] == model.contact().separation


def test_surface_table_on_a_terminal_and_error_for_other_models(tmp_path, capsys):
    model_path = write_toml(tmp_path / "pol.toml", {"model": default_table()})
    status, out, _ = run(capsys, "surface", model_path)
    assert status == 0 and "separation" in out and "interference [m]" in out
    other = write_toml(tmp_path / "lugre.toml", {"model": LUGRE_1995})
    status, out, err = run(capsys, "surface", other)
    assert status == 2 and out == ""
    one_error_line(err, "lugre.toml", "pol-ind")


def test_surface_reports_the_validity_figures_with_and_without_a_hardness(tmp_path, capsys):
    keys = {"plasticity_index", "plastic_load_share", "plastic_contact_share",
            "mean_real_pressure", "peak_asperity_pressure", "unmatched_load"}
    elastic = write_toml(tmp_path / "elastic.toml", {"model": default_table()})
    status, out, err = run(capsys, "surface", elastic, "--json")
    assert status == 0 and err == ""                       # the default model does not warn
    validity = json.loads(out)["validity"]
    assert set(validity) == keys
    assert validity["plasticity_index"] is None
    assert validity["plastic_load_share"] == validity["plastic_contact_share"] == 0.0
    assert validity["mean_real_pressure"] == pytest.approx(100.0 / json.loads(out)["real_area"])
    table = default_table()
    table["materials"]["hardness"] = 4e9
    plastic = write_toml(tmp_path / "plastic.toml", {"model": table})
    status, out, err = run(capsys, "surface", plastic, "--json")
    assert status == 0 and err == ""
    validity = json.loads(out)["validity"]
    assert validity == polind.load_model(plastic).contact().validity()
    assert validity["plasticity_index"] == pytest.approx(115.38461538461539e9 / 4e9 * 0.1)
    assert 0.0 < validity["plastic_contact_share"] < validity["plastic_load_share"] < 1.0
    status, out, err = run(capsys, "surface", plastic)
    assert status == 0 and err == ""
    assert "plasticity index        2.885 (H = 4e+09 Pa" in out
    assert "peak asperity pressure" in out and "unmatched load          0 N" in out


def test_surface_warns_about_an_elastic_contact_beyond_its_validity(tmp_path, capsys):
    table = default_table()
    table["surface"]["height_std"] = 5e-6            # ten times rougher: a few GPa-loaded summits
    model_path = write_toml(tmp_path / "rough.toml", {"model": table})
    status, out, err = run(capsys, "surface", model_path, "--json")
    assert status == 0
    peak = json.loads(out)["validity"]["peak_asperity_pressure"]
    assert peak > 10e9
    assert err.count("\n") == 1 and err.startswith("polind: warning: ")
    for fragment in ("peak_asperity_pressure", "mean_real_pressure", f"{peak / 1e9:.3g} GPa",
                     "'materials.hardness'"):
        assert fragment in err, (fragment, err)


# --- dynamics -----------------------------------------------------------------------------

def test_dynamics_writes_the_library_result(tmp_path, capsys):
    model_path = write_toml(tmp_path / "lugre.toml", {"model": LUGRE_1995})
    system_path = write_toml(tmp_path / "system.toml", {"system": {
        "mass": 1.0, "duration": 2.0, "time_step": 1e-3,
        "spring_drive": {"stiffness": 2.0, "velocity": 0.1}}})
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "dynamics", model_path, "--system", system_path,
                         "--output", out)
    assert status == 0, err
    lines = out.read_text().splitlines()
    assert lines[0] == "t,x,v,F,F_applied"
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    want = polind.simulate_system(polind.load_model(model_path),
                                  polind.load_system(system_path))
    for column, values in zip(table.T, (want.t, want.x, want.v, want.force, want.applied)):
        np.testing.assert_array_equal(column, values)


@pytest.mark.parametrize("system, fragment", [
    ({"system": {"mass": -1.0, "duration": 1.0, "time_step": 1e-3,
                 "force": {"offset": 1.0}}}, "mass"),
    ({"system": {"mass": 1.0, "duration": 1.0, "time_step": 1e-3, "colour": 1,
                 "force": {"offset": 1.0}}}, "colour"),
])
def test_dynamics_bad_system_exits_2_and_writes_nothing(tmp_path, capsys, system, fragment):
    model_path = write_toml(tmp_path / "lugre.toml", {"model": LUGRE_1995})
    system_path = write_toml(tmp_path / "system.toml", system)
    out = tmp_path / "out.csv"
    status, _, err = run(capsys, "dynamics", model_path, "--system", system_path,
                         "--output", out)
    assert status == 2
    one_error_line(err, "system.toml", fragment)
    assert not out.exists()


# --- fit ----------------------------------------------------------------------------------

def stribeck_data(tmp_path):
    truth = polind.model_from_dict({"model": {"type": "stribeck", "coulomb_force": 1.0,
                                              "static_force": 1.5,
                                              "stribeck_velocity": 1e-3}})
    t = np.linspace(0.0, 2.0, 801)
    v = 0.01 * np.sin(2 * np.pi * t)
    force = polind.simulate(truth, t, v=v).force
    force += 0.005 * np.random.default_rng(3).standard_normal(t.size)
    data = tmp_path / "data.csv"
    np.savetxt(data, np.c_[t, v, force], delimiter=",", header="t,v,F", comments="",
               fmt="%.17g")
    return data


def test_fit_recovers_parameters_and_writes_fit_result(tmp_path, capsys):
    data = stribeck_data(tmp_path)
    model_path = write_toml(tmp_path / "start.toml", {
        "model": {"type": "stribeck", "coulomb_force": 2.0, "static_force": 3.0,
                  "stribeck_velocity": 3e-3},
        "fit": {"free": ["coulomb_force", "static_force", "stribeck_velocity"],
                "bounds": {"stribeck_velocity": [1e-5, 1e-1]}}})
    out, plot = tmp_path / "fitted.toml", tmp_path / "fit.png"
    status, stdout, err = run(capsys, "fit", model_path, "--data", data, "--output", out,
                              "--plot", plot)
    assert status == 0, err
    document = tomllib.loads(out.read_text())
    assert document["model"]["coulomb_force"] == pytest.approx(1.0, rel=0.02)
    assert document["model"]["static_force"] == pytest.approx(1.5, rel=0.02)
    assert document["model"]["stribeck_velocity"] == pytest.approx(1e-3, rel=0.05)
    result = document["fit"]["result"]
    assert result["rms_error"] == pytest.approx(0.005, rel=0.2)
    assert result["iterations"] >= 1
    for key in ("coulomb_force", "static_force", "stribeck_velocity"):
        assert set(result[key]) == {"value", "standard_error"}
        assert 0.0 < result[key]["standard_error"] < 0.1 * result[key]["value"]
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert polind.load_model(out).type == "stribeck"


@pytest.mark.parametrize("fit_table, fragment", [
    ({"free": ["roughness"]}, "roughness"),
    ({"free": ["coulomb_force"], "bounds": {"coulomb_force": [5.0, 6.0]}}, "coulomb_force"),
])
def test_fit_bad_fit_table_exits_2_naming_the_key(tmp_path, capsys, fit_table, fragment):
    data = stribeck_data(tmp_path)
    model_path = write_toml(tmp_path / "start.toml", {
        "model": {"type": "stribeck", "coulomb_force": 2.0, "static_force": 3.0,
                  "stribeck_velocity": 3e-3}, "fit": fit_table})
    out = tmp_path / "fitted.toml"
    status, _, err = run(capsys, "fit", model_path, "--data", data, "--output", out)
    assert status == 2
    one_error_line(err, "start.toml", fragment)
    assert not out.exists()


def test_fit_bad_data_exits_2_naming_the_file(tmp_path, capsys):
    data = tmp_path / "data.csv"
    data.write_text("t,v,F\n0,0.1,1\n1,0.1,nan\n2,0.1,1\n")
    model_path = write_toml(tmp_path / "start.toml", {
        "model": {"type": "coulomb", "coulomb_force": 2.0},
        "fit": {"free": ["coulomb_force"]}})
    status, _, err = run(capsys, "fit", model_path, "--data", data, "--output",
                         tmp_path / "fitted.toml")
    assert status == 2
    one_error_line(err, "data.csv", "row 3", "'F'")
    assert not (tmp_path / "fitted.toml").exists()


# --- demo and bench -----------------------------------------------------------------------

def test_demo_runs_any_model_alone_beside_its_peers(tmp_path, capsys):
    """A model without peers (LuGre) is the report's one model: every phenomenon is run and
    judged on it, and the report names it, not Pol-Ind."""
    other = write_toml(tmp_path / "lugre.toml", {"model": LUGRE_1995})
    status, out, err = run(capsys, "demo", "--out", tmp_path / "report", "--model", other)
    assert status == 0, err
    metrics = json.loads((tmp_path / "report" / "metrics.json").read_text())
    assert set(metrics) == {"stribeck", "presliding_memory", "frictional_lag", "non_drifting",
                            "stick_slip", "breakaway"}
    # LuGre shows the Stribeck effect, lag, stick-slip and break-away, and drifts
    # (the user guide's phenomenon table): the checks are the model's, not Pol-Ind's.
    assert metrics["stribeck"]["passed"] is True and metrics["non_drifting"]["passed"] is False
    page = (tmp_path / "report" / "report.html").read_text()
    assert "LuGre" in page


def test_bench_rejects_an_unknown_model(capsys):
    status, _, err = run(capsys, "bench", "--model", "friction-9000")
    assert status == 2
    one_error_line(err, "friction-9000", "--model")


def test_bench_cases_cover_the_element_counts_and_do_the_same_work():
    cases = harness.cases()
    assert ("maxwell-slip", 1024) in cases and ("gms", 64) in cases and ("pol-ind", 1024) in cases
    row = harness.run_case("pol-ind", 64, kernel_seconds=0.01, numpy_seconds=0.02, repeats=1)
    assert row.elements == 64 and row.kernel_rate > 0 and row.numpy_rate > 0
    assert row.max_difference < 1e-12          # the NumPy loop computes the same forces
    separation = surfaces.run_separation(asperities=20_000)
    assert separation.relative_residual <= 1e-10


def test_demo_into_an_uncreatable_directory_exits_2_before_running(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    status, out, err = run(capsys, "demo", "--out", blocker / "report")
    assert status == 2 and out == ""
    one_error_line(err, "report", "directory")


def test_dynamics_with_an_absurd_sample_count_exits_2(tmp_path, capsys):
    model_path = write_toml(tmp_path / "lugre.toml", {"model": LUGRE_1995})
    system_path = write_toml(tmp_path / "system.toml", {"system": {
        "mass": 1.0, "duration": 1e12, "time_step": 1e-6, "force": {"offset": 0.5}}})
    status, _, err = run(capsys, "dynamics", model_path, "--system", system_path,
                         "--output", tmp_path / "out.csv")
    assert status == 2
    one_error_line(err, "system.toml", "samples")
    assert not (tmp_path / "out.csv").exists()
