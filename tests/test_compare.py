"""``polind.compare`` and ``polind compare`` (INTERFACE.md), and ``polind fit --holdout``.

The table is checked against numbers recomputed here from each fitted model
(its simulated force on the fitted and the held-out samples, the AIC and
BIC formulas of the documentation); the command line against the library
on the same data, and against the rules for outputs: never over an input,
exit 2 with one line for a user's mistake.
"""

from __future__ import annotations

import csv
import math
import tomllib
import warnings

import numpy as np
import pytest
import tomli_w

import polind
from polind.identification import COLUMNS, compare

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401

DAHL = {"type": "dahl", "stiffness": 1e5, "coulomb_force": 1.0}


def model(table):
    return polind.model_from_dict({"model": dict(table)})


def dahl_data(n=1201, noise=0.01):
    truth = model(DAHL)
    t = np.linspace(0.0, 6.0, n)
    x = 1e-4 * np.sin(np.pi * t) + 3e-5 * np.sin(4.3 * t)
    force = polind.simulate(truth, t, x=x).force
    force = force + noise * np.random.default_rng(5).standard_normal(n)
    return {"t": t, "x": x, "F": force}


def starts():
    return {"dahl": model({**DAHL, "stiffness": 3e4, "coulomb_force": 2.0}),
            "coulomb": model({"type": "coulomb", "coulomb_force": 2.0})}


def quiet_compare(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return compare(*args, **kwargs)


def quiet_fit(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return polind.identify(*args, **kwargs)


# --- the library ------------------------------------------------------------------------------

def test_the_table_is_what_the_fitted_models_give_on_the_two_parts():
    data = dahl_data()
    table = quiet_compare(starts(), data, holdout=0.25)
    n = len(data["t"])
    split = round(0.75 * n)
    assert table.fitted_samples == split and table.holdout == 0.25
    assert [row["model"] for row in table.rows] == ["dahl", "coulomb"]
    for row, k in zip(table.rows, (2, 1)):
        fitted = table.results[row["model"]].model
        force = polind.simulate(fitted, data["t"], x=data["x"]).force
        residual = force - data["F"]
        rss = float(residual[:split] @ residual[:split])
        assert set(row) == set(COLUMNS)
        assert row["free_parameters"] == k
        assert row["rms_in_sample"] == pytest.approx(math.sqrt(rss / split), rel=1e-9)
        assert row["rms_held_out"] == pytest.approx(
            math.sqrt(np.mean(residual[split:] ** 2)), rel=1e-9)
        assert row["aic"] == pytest.approx(split * math.log(rss / split) + 2 * k, rel=1e-9)
        assert row["bic"] == pytest.approx(split * math.log(rss / split) + k * math.log(split),
                                           rel=1e-9)
    dahl, coulomb = table.rows
    # The model the data came from fits and predicts to the noise; Coulomb cannot.
    assert dahl["rms_held_out"] == pytest.approx(0.01, rel=0.15)
    assert coulomb["rms_held_out"] > 3.0 * dahl["rms_held_out"]
    assert dahl["aic"] < coulomb["aic"] and dahl["bic"] < coulomb["bic"]


def test_labels_documents_and_no_holdout():
    data = dahl_data(601)
    document = {"model": dict(DAHL, stiffness=5e4), "fit": {"free": ["stiffness"]}}
    table = quiet_compare([model(DAHL), document, starts()["coulomb"]], data)
    assert [row["model"] for row in table.rows] == ["dahl", "dahl 2", "coulomb"]
    assert [row["free_parameters"] for row in table.rows] == [2, 1, 1]
    assert all(row["rms_held_out"] is None for row in table.rows)
    assert table.fitted_samples == 601
    lines = table.to_csv().splitlines()
    assert lines[0] == ",".join(COLUMNS) and len(lines) == 4
    assert lines[1].split(",")[3] == ""                # no held-out RMS: an empty field
    assert "dahl 2" in table.table()
    assert polind.compare is compare


def test_each_fit_warns_under_its_label_and_bad_models_are_named():
    data = dahl_data(601)
    with pytest.warns(UserWarning, match=r"^flat: The 'normal_load' column is not used"):
        compare({"flat": starts()["coulomb"]},
                {**data, "normal_load": np.full(601, 5.0)})
    with pytest.raises(polind.InputError, match="model 'bad': .*'roughness'"):
        compare({"good": model(DAHL), "bad": {"model": DAHL, "fit": {"free": ["roughness"]}}},
                data)
    with pytest.raises(polind.InputError, match="'holdout'"):
        compare([model(DAHL)], data, holdout=1.0)


def test_the_figure_has_a_row_per_model_and_shades_the_held_out_part(tmp_path):
    table = quiet_compare(starts(), dahl_data(), holdout=0.3)
    figure = table.figure()
    axes = figure.get_axes()
    assert len(axes) == 3 * 2
    shaded = [patch for ax in axes for patch in ax.patches]
    assert len(shaded) == 2 * 2                           # both time panels of both rows
    start = table.t[table.fitted_samples]
    for patch in shaded:
        corners = patch.get_patch_transform().transform(patch.get_path().vertices)
        assert corners[:, 0].min() == pytest.approx(start)          # from the split
        assert corners[:, 0].max() == pytest.approx(table.t[-1])    # to the end
    path = tmp_path / "compare.png"
    table.plot(path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 50_000


def reciprocating_record(cycles=4, per_stroke=150, noise=0.02):
    """Strokes of 0.24 mm with a dwell at each end, as a reciprocating tribometer's, of a
    three-element GMS whose slowest element never slips (t [s], x [m], F [N])."""
    t = np.linspace(0.0, 4.0 * cycles, 2 * per_stroke * cycles)
    phase = (t % 4.0) / 4.0
    stroke = np.clip(4.0 * np.abs((phase + 0.25) % 1.0 - 0.5) - 1.0, -0.8, 0.8) / 0.8
    x = 0.12e-3 * stroke
    truth = model({"type": "gms", "stiffness": [3e4, 1e4, 1e3], "weight": [0.6, 0.3, 0.1],
                   "attraction": 5.0, "coulomb_force": 2.4, "static_force": 2.6,
                   "stribeck_velocity": 3e-5})
    force = polind.simulate(truth, t, x=x).force
    return {"t": t, "x": x, "F": force + noise * np.random.default_rng(1).standard_normal(t.size)}


TEXTBOOK_GMS = {"type": "gms", "stiffness": [1e5, 1e4, 1e3], "weight": [0.4, 0.3, 0.3],
                "attraction": 1e4, "coulomb_force": 1.0, "static_force": 1.5,
                "stribeck_velocity": 1e-3}
TEXTBOOK_MAXWELL_SLIP = {"type": "maxwell-slip", "stiffness": [1e5, 1e4, 1e3],
                         "breakaway_force": [0.4, 0.3, 0.3]}


def test_gms_is_never_worse_in_sample_than_the_maxwell_slip_row_it_contains():
    data = reciprocating_record()
    gms, slip = model(TEXTBOOK_GMS), model(TEXTBOOK_MAXWELL_SLIP)
    # From its textbook values alone GMS ends worse than Maxwell-slip from its NNLS set
    # (so the check below can fail) ...
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        alone = polind.identify(gms, data, holdout=0.5, starts=1)
    # ... listed first, it is fitted after the Maxwell-slip row and starts from its fit too:
    # with Fs = Fc its force is that fit's, and the solver never climbs from a start.
    table = quiet_compare({"gms": gms, "maxwell-slip": slip}, data, holdout=0.5, starts=2)
    assert [row["model"] for row in table.rows] == ["gms", "maxwell-slip"]
    by_label = {row["model"]: row for row in table.rows}
    assert alone.rms_error > 1.2 * by_label["maxwell-slip"]["rms_in_sample"]
    assert by_label["gms"]["rms_in_sample"] <= by_label["maxwell-slip"]["rms_in_sample"] * (
        1.0 + 1e-12)
    labels = [label for label, _ in table.results["gms"].starts]
    assert labels == ["the model's values", "the fitted 'maxwell-slip' row"]


def test_every_fit_of_a_comparison_predicts_within_10_percent_of_the_best_or_warns():
    data = reciprocating_record()
    models = {"coulomb": model({"type": "coulomb", "coulomb_force": 1.0}),
              "dahl": model(DAHL),
              "lugre": model({"type": "lugre", "bristle_stiffness": 1e5,
                              "bristle_damping": 316.2, "coulomb_force": 1.0,
                              "static_force": 1.5, "stribeck_velocity": 1e-3}),
              "maxwell-slip": model(TEXTBOOK_MAXWELL_SLIP), "gms": model(TEXTBOOK_GMS)}
    table = quiet_compare(models, data, holdout=0.5)
    best = min(row["rms_held_out"] for row in table.rows)
    for row in table.rows:
        result = table.results[row["model"]]
        credible = row["rms_held_out"] <= 1.1 * best
        warned = any("force level" in note or "residuals" in note or "held-out" in note
                     or "not identifiable" in note or "bound" in note
                     for note in result.warnings)
        assert credible or warned, (row, result.warnings)
    # The models that cannot follow a presliding rise say so through their residuals.
    for name in ("coulomb", "dahl"):
        assert any("residuals of the fitted" in note
                   for note in table.results[name].warnings), name
    assert not any("residuals" in note for note in table.results["gms"].warnings)


def test_a_mapping_with_a_row_labelled_model_is_a_mapping_of_rows():
    data = dahl_data(601)
    document = {"model": dict(DAHL, stiffness=5e4), "fit": {"free": ["stiffness"]}}
    table = quiet_compare({"model": document}, data)
    assert [row["model"] for row in table.rows] == ["model"]
    table = quiet_compare({"model": model(DAHL), "coulomb": starts()["coulomb"]}, data)
    assert [row["model"] for row in table.rows] == ["model", "coulomb"]
    # One document is still one model.
    assert [row["model"] for row in quiet_compare(document, data).rows] == ["dahl"]


def test_the_figure_colours_each_part_the_same_in_every_row():
    from polind.identification import COLOURS
    from matplotlib.colors import to_rgba

    table = quiet_compare(starts(), dahl_data(), holdout=0.3, starts=1)
    figure = table.figure()
    axes = figure.get_axes()
    for panel in axes:
        for line in panel.get_lines():
            label = line.get_label()
            part = ("held out" if "held out" in label else "fitted" if "predicted" in label
                    else "measured")
            if panel in axes[2::3] and part == "measured":
                continue                                 # the grey cloud behind the position plot
            assert to_rgba(line.get_color()) == to_rgba(COLOURS[part]), (label, line.get_color())
    held_out = [line for panel in axes for line in panel.get_lines()
                if line.get_label() == "predicted, held out"]
    assert len(held_out) == 2 * 3                        # every panel of both rows


# --- the command line -----------------------------------------------------------------------------

@pytest.fixture
def files(tmp_path):
    data = dahl_data()
    data_path = tmp_path / "data.csv"
    np.savetxt(data_path, np.c_[data["t"], data["x"], data["F"]], delimiter=",",
               header="t,x,F", comments="", fmt="%.17g")
    dahl = tmp_path / "dahl.toml"
    dahl.write_text(tomli_w.dumps({"model": dict(DAHL, stiffness=3e4, coulomb_force=2.0)}))
    coulomb = tmp_path / "coulomb.toml"
    coulomb.write_text(tomli_w.dumps({"model": {"type": "coulomb", "coulomb_force": 2.0}}))
    return data, data_path, dahl, coulomb


def one_error_line(err, *fragments):
    assert err.count("\n") == 1 and err.startswith("polind: error: "), repr(err)
    for fragment in fragments:
        assert fragment in err, (fragment, err)


def test_compare_command_writes_the_library_table_and_the_figure(tmp_path, capsys, files):
    data, data_path, dahl, coulomb = files
    out, png = tmp_path / "table.csv", tmp_path / "compare.png"
    status, stdout, err = run(capsys, "compare", dahl, coulomb, "--data", data_path,
                              "--holdout", "0.25", "--output", out, "--plot", png)
    assert status == 0, err
    with open(out, newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert list(rows[0]) == list(COLUMNS)
    library = quiet_compare({"dahl": {"model": tomllib.loads(dahl.read_text())["model"]},
                             "coulomb": {"model": tomllib.loads(coulomb.read_text())["model"]}},
                            data, holdout=0.25)
    for written, row in zip(rows, library.rows):
        assert written["model"] == row["model"]
        assert int(written["free_parameters"]) == row["free_parameters"]
        for key in COLUMNS[2:]:
            assert float(written[key]) == row[key], key
    assert "dahl" in stdout and "coulomb" in stdout and "RMS held out" in stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compare_takes_a_file_named_model_toml(tmp_path, capsys, files):
    # It was taken for a single model document ({"model": <its document>}): "Missing key
    # 'type'".  The rows are labelled by file name; a file holding [model] is a row.
    data, data_path, dahl, coulomb = files
    named = tmp_path / "model.toml"
    named.write_bytes(dahl.read_bytes())
    status, stdout, err = run(capsys, "compare", named, "--data", data_path, "--starts", "1")
    assert status == 0, err
    assert stdout.splitlines()[1].startswith("model ")
    status, stdout, err = run(capsys, "compare", named, coulomb, "--data", data_path,
                              "--starts", "1")
    assert status == 0, err
    assert [line.split()[0] for line in stdout.splitlines()[1:3]] == ["model", "coulomb"]


def test_fit_starts_option_and_the_start_in_the_result(tmp_path, capsys, files):
    _, data_path, dahl, _ = files
    out = tmp_path / "fitted.toml"
    status, stdout, err = run(capsys, "fit", dahl, "--data", data_path, "--output", out,
                              "--starts", "1")
    assert status == 0, err
    result = tomllib.loads(out.read_text())["fit"]["result"]
    assert result["start"] == "the model's values"
    assert [row["start"] for row in result["starts"]] == ["the model's values"]
    assert "start: the model's values" in stdout
    status, _, _ = run(capsys, "fit", dahl, "--data", data_path, "--output", out)
    assert status == 0
    result = tomllib.loads(out.read_text())["fit"]["result"]
    assert [row["start"] for row in result["starts"]] == [
        "the model's values", "Latin hypercube point 1 of 2", "Latin hypercube point 2 of 2"]
    assert result["rms_error"] == pytest.approx(min(row["rms_error"]
                                                    for row in result["starts"]), rel=1e-9)
    status, _, err = run(capsys, "fit", dahl, "--data", data_path, "--output", out,
                         "--starts", "0")
    assert status == 2
    one_error_line(err, "--starts")


def test_fit_plot_labels_the_printed_errors_and_shades_the_held_out_part(tmp_path, files):
    from matplotlib.figure import Figure

    data, _, dahl, _ = files
    fit = quiet_fit(model(DAHL).with_params(stiffness=3e4), data, holdout=0.25)
    captured = {}
    original = Figure.savefig

    def keep(self, *args, **kwargs):
        captured["figure"] = self
        return original(self, *args, **kwargs)

    Figure.savefig = keep
    try:
        from polind.identification import plot_fit
        plot_fit(data, {"dahl": fit}, tmp_path / "fit.png")
    finally:
        Figure.savefig = original
    over_time, zoomed, against_x = captured["figure"].get_axes()
    label = f"dahl (RMS {fit.rms_error:.3g} N in sample, {fit.holdout_rms_error:.3g} N held out)"
    for panel in (over_time, zoomed, against_x):
        assert label in [line.get_label() for line in panel.get_lines()]
    split = data["t"][fit.fitted_samples]
    for panel in (over_time, zoomed):
        (patch,) = panel.patches
        corners = patch.get_patch_transform().transform(patch.get_path().vertices)
        assert corners[:, 0].min() == pytest.approx(split)
    assert not against_x.patches


def test_compare_to_standard_output(capsys, files):
    _, data_path, dahl, _ = files
    status, stdout, _ = run(capsys, "compare", dahl, "--data", data_path, "-o", "-")
    assert status == 0
    assert stdout.splitlines()[0] == ",".join(COLUMNS) and len(stdout.splitlines()) == 2


@pytest.mark.parametrize("which", ["output on a model", "output on the data",
                                   "plot on the data", "output on the plot"])
def test_compare_never_writes_over_an_input(tmp_path, capsys, files, which):
    _, data_path, dahl, coulomb = files
    before = {path: path.read_bytes() for path in (data_path, dahl, coulomb)}
    png = tmp_path / "same.png"
    options = {"output on a model": ["--output", coulomb],
               "output on the data": ["--output", data_path],
               "plot on the data": ["--plot", data_path],
               "output on the plot": ["--output", png, "--plot", png]}[which]
    status, stdout, err = run(capsys, "compare", dahl, coulomb, "--data", data_path, *options)
    assert status == 2 and stdout == ""
    one_error_line(err)
    assert {path: path.read_bytes() for path in before} == before
    assert not png.exists()


@pytest.mark.parametrize("args, fragment", [
    (["--holdout", "1.5"], "--holdout"),
    (["--holdout", "0"], "--holdout"),
    (["--holdout", "half"], "--holdout"),
])
def test_compare_bad_holdout_exits_2_with_one_line(capsys, files, args, fragment):
    _, data_path, dahl, _ = files
    status, _, err = run(capsys, "compare", dahl, "--data", data_path, *args)
    assert status == 2
    one_error_line(err, fragment)


def test_compare_bad_model_file_exits_2_naming_it(tmp_path, capsys, files):
    _, data_path, dahl, _ = files
    bad = tmp_path / "bad.toml"
    bad.write_text(tomli_w.dumps({"model": DAHL, "fit": {"free": ["roughness"]}}))
    status, _, err = run(capsys, "compare", dahl, bad, "--data", data_path)
    assert status == 2
    one_error_line(err, "bad.toml", "roughness")
    status, _, err = run(capsys, "compare", dahl, tmp_path / "missing.toml", "--data", data_path)
    assert status == 2
    one_error_line(err, "missing.toml")


def test_fit_with_holdout_writes_the_held_out_error_and_the_warnings(tmp_path, capsys, files):
    data, data_path, dahl, _ = files
    out = tmp_path / "fitted.toml"
    status, stdout, err = run(capsys, "fit", dahl, "--data", data_path, "--output", out,
                              "--holdout", "0.25")
    assert status == 0, err
    result = tomllib.loads(out.read_text())["fit"]["result"]
    fitted = polind.load_model(out)
    force = polind.simulate(fitted, data["t"], x=data["x"]).force
    split = round(0.75 * len(data["t"]))
    expected = math.sqrt(np.mean((force[split:] - data["F"][split:]) ** 2))
    assert result["holdout_rms_error"] == pytest.approx(expected, rel=1e-9)
    assert result["warnings"] == [] and err == ""
    assert "holdout_rms_error" in stdout


def test_fit_prints_each_warning_on_standard_error(tmp_path, capsys, files):
    _, data_path, _, _ = files
    start = tmp_path / "bounded.toml"
    start.write_text(tomli_w.dumps({"model": dict(DAHL, coulomb_force=0.6),
                                    "fit": {"free": ["coulomb_force"],
                                            "bounds": {"coulomb_force": [0.5, 0.7]}}}))
    out = tmp_path / "fitted.toml"
    status, _, err = run(capsys, "fit", start, "--data", data_path, "--output", out)
    assert status == 0
    lines = err.splitlines()
    assert any(line.startswith("polind: warning: ") and "'coulomb_force'" in line
               and "upper bound 0.7" in line for line in lines), err
    written = tomllib.loads(out.read_text())["fit"]["result"]["warnings"]
    assert len(written) == len(lines) and "upper bound 0.7" in written[0]


@pytest.mark.parametrize("target", ["model", "data"])
def test_fit_never_writes_over_its_inputs(tmp_path, capsys, files, target):
    _, data_path, dahl, _ = files
    before = dahl.read_bytes(), data_path.read_bytes()
    output = dahl if target == "model" else data_path
    status, stdout, err = run(capsys, "fit", dahl, "--data", data_path, "--output", output)
    assert status == 2 and stdout == ""
    one_error_line(err, str(output))
    assert (dahl.read_bytes(), data_path.read_bytes()) == before
    status, _, err = run(capsys, "fit", dahl, "--data", data_path, "--output",
                         tmp_path / "fitted.toml", "--plot", dahl)
    assert status == 2 and dahl.read_bytes() == before[0]
