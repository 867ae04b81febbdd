"""``polind demo``'s report (polind.report, polind.demo): the files of INTERFACE.md, a
self-contained page, metrics.json with the six phenomena, the summary table, progress."""

import base64
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from polind.phenomena import PHENOMENA

FIGURES = ("stribeck.png", "presliding_memory.png", "frictional_lag.png", "non_drifting.png",
           "stick_slip.png", "stick_slip_reference.png", "breakaway.png")
LABELS = ("Pol-Ind", "LuGre", "GMS", "Maxwell-slip")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


class RecordingBar:
    """The command's progress bar, recording what run_demo tells it."""

    def __init__(self, bar):
        self.bar, self.said = bar, []

    @property
    def total(self):
        return self.bar.total

    @total.setter
    def total(self, value):
        self.bar.total = value

    def refresh(self):
        self.bar.refresh()

    def set_description_str(self, text):
        self.said.append(("description", text))
        self.bar.set_description_str(text)

    def update(self, k=1):
        self.said.append(("update", k))
        self.bar.update(k)


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    """``polind demo --out DIR`` run once, in this process as the CLI tests run commands:
    ``(DIR, the summary its run_demo returned, the command's record)``, the record holding
    its exit status, standard output and error, and its progress bar's calls."""
    import contextlib
    import io

    from polind import cli, demo

    out = tmp_path_factory.mktemp("report")
    real_run_demo, seen = demo.run_demo, {}

    def recorded(out_dir, progress=None, **options):
        seen["bar"] = RecordingBar(progress)
        seen["summary"] = real_run_demo(out_dir, progress=seen["bar"], **options)
        return seen["summary"]

    stdout, stderr = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as patch, contextlib.redirect_stdout(stdout), \
            contextlib.redirect_stderr(stderr):
        patch.delenv("POLIND_DEBUG", raising=False)
        patch.setattr(demo, "run_demo", recorded)
        with pytest.raises(SystemExit) as exit_info:
            cli.main(["demo", "--out", str(out)])
    command = {"status": exit_info.value.code, "out": stdout.getvalue(),
               "err": stderr.getvalue(), "bar": seen.get("bar")}
    assert command["status"] == 0, command["err"]
    return out, seen["summary"], command


def test_the_command_exits_0_and_prints_the_table(demo_run):
    out, summary, command = demo_run
    assert command["status"] == 0, command["err"]
    metrics = json.loads((out / "metrics.json").read_text())
    assert set(metrics) == {"stribeck", "presliding_memory", "frictional_lag", "non_drifting",
                            "stick_slip", "breakaway"}
    assert all(entry["passed"] is True for entry in metrics.values())
    assert (out / "report.html").exists()
    assert len(list(out.glob("*.png"))) >= 6
    assert "stick_slip" in command["out"]
    assert summary["table"] in command["out"]


def test_every_file_is_written(demo_run):
    out, summary, _ = demo_run
    names = sorted(os.listdir(out))
    assert names == sorted(FIGURES + ("metrics.json", "report.html"))
    assert sorted(summary["files"]) == names
    for name in FIGURES:
        data = (out / name).read_bytes()
        assert data.startswith(PNG_MAGIC), name
        assert len(data) > 20_000, name                 # a real figure, not an empty canvas


def test_metrics_json_has_the_six_phenomena(demo_run):
    out, summary, _ = demo_run
    metrics = json.loads((out / "metrics.json").read_text())
    assert list(metrics) == list(PHENOMENA)
    for phenomenon, entry in metrics.items():
        assert isinstance(entry["passed"], bool), phenomenon
        assert entry["passed"], f"{phenomenon} does not appear in Pol-Ind"
        assert entry["as_expected"], phenomenon
        assert list(entry["models"]) == list(LABELS)
        for label, result in entry["models"].items():
            assert isinstance(result["passed"], bool) and isinstance(result["expected"], bool)
            assert result["passed"] == result["expected"], (phenomenon, label)
    assert summary["passed"] == {phenomenon: True for phenomenon in PHENOMENA}


def test_metrics_json_holds_the_numbers_the_figures_show(demo_run):
    out, _, _ = demo_run
    metrics = json.loads((out / "metrics.json").read_text())
    lugre = metrics["non_drifting"]["models"]["LuGre"]
    assert lugre["drifts"] is True and 6.3e-6 < lugre["steady_advance"] < 6.9e-6
    stribeck = metrics["stribeck"]["models"]["Pol-Ind"]
    assert len(stribeck["velocity"]) == len(stribeck["force"]) == 49
    assert stribeck["force_at_lowest_velocity"] == pytest.approx(15.0, rel=1e-5)
    lag = metrics["frictional_lag"]["models"]["Pol-Ind"]
    assert len(lag["frequency"]) == len(lag["loop_area"]) == 4
    reference = metrics["stick_slip"]["models"]["LuGre"]["reference"]
    assert (reference["mass"], reference["spring_stiffness"], reference["drive_velocity"]) \
        == (1.0, 2.0, 0.1)
    assert reference["sticks_and_slips"] is True
    breakaway = metrics["breakaway"]["models"]["Pol-Ind"]
    assert abs(breakaway["breakaway_ratio"][0] - 1.0) < 0.02


def test_report_html_is_self_contained(demo_run):
    out, _, _ = demo_run
    page = (out / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    # no network: no URL scheme anywhere, no external script, style sheet or image
    assert "http:" not in page and "https:" not in page
    assert not re.search(r"""(src|href)\s*=\s*["'](?!data:|#)""", page)
    assert "<script" not in page and "<link" not in page and "@import" not in page
    # every figure embedded, byte for byte
    embedded = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', page)
    assert len(embedded) == len(FIGURES)
    on_disk = {(out / name).read_bytes() for name in FIGURES}
    assert {base64.b64decode(data) for data in embedded} == on_disk


def test_report_html_explains_each_phenomenon(demo_run):
    from polind.report import DESCRIPTIONS, TITLES
    import html

    out, _, _ = demo_run
    page = (out / "report.html").read_text()
    for phenomenon in PHENOMENA:
        assert f'id="{phenomenon}"' in page
        assert TITLES[phenomenon] in page
        assert html.escape(DESCRIPTIONS[phenomenon]) in page
    for label in LABELS:
        assert f"<h3>{label}</h3>" in page
    assert "bristle_stiffness = 100000.0" in page        # the parameter values used
    assert "static_coefficient = 0.15" in page


def test_summary_table(demo_run):
    _, summary, _ = demo_run
    table = summary["table"]
    assert str(summary) == table
    lines = table.splitlines()
    assert all(label in lines[0] for label in LABELS)
    rows = {line.split()[0]: line for line in lines[2:2 + len(PHENOMENA)]}
    assert list(rows) == list(PHENOMENA)
    assert " !" not in table.replace("; ! where", "")        # nothing contradicts MODELS.md
    assert "6.6 µm/cyc" in rows["non_drifting"]               # LuGre's drift


def test_progress_callback(demo_run):
    """The command's bar is told every experiment and the report, one update each, with
    its total; :func:`test_experiments_in_processes_equal_those_in_this_process` checks
    the same hook given a function ``progress(done, total, what)``."""
    _, _, command = demo_run
    total = len(LABELS) * len(PHENOMENA) + 1
    said = command["bar"].said
    assert said[0::2] == [("description", text) for _, text in said[0::2]]
    assert said[1::2] == [("update", 1)] * total and len(said) == 2 * total
    assert command["bar"].total == total
    assert said[-2] == ("description", "report")


def test_progress_bar_object():
    from polind.demo import _progress_hooks

    class Bar:
        total = None

        def __init__(self):
            self.n = 0
            self.text = []

        def update(self, k):
            self.n += k

        def set_description_str(self, text):
            self.text.append(text)

    bar = Bar()
    advance = _progress_hooks(bar, 5)
    for k in range(5):
        advance(f"step {k}")
    assert bar.total == 5 and bar.n == 5 and bar.text[-1] == "step 4"


def test_files_are_replaced_atomically(demo_run, tmp_path, monkeypatch):
    """Writing again replaces every file and leaves no temporary file behind; a write
    that fails leaves the previous file as it was."""
    from polind import report
    from polind.io import output
    from polind.report import writer

    _, summary, _ = demo_run
    fake = {name: PNG_MAGIC + name.encode() for name in FIGURES}
    # write_report (polind.report.writer) renders through its module's render_figures
    monkeypatch.setattr(writer, "render_figures", lambda results, subject: fake)
    (tmp_path / "report.html").write_text("old page")
    report.write_report(summary["results"], tmp_path)
    assert sorted(os.listdir(tmp_path)) == sorted(FIGURES + ("metrics.json", "report.html"))
    assert (tmp_path / "stribeck.png").read_bytes() == fake["stribeck.png"]
    page = (tmp_path / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>")

    real_replace = os.replace

    def refuse_the_page(source, target):
        if str(target).endswith("report.html"):
            raise OSError(28, "No space left on device")
        real_replace(source, target)

    monkeypatch.setattr(output.os, "replace", refuse_the_page)
    (tmp_path / "report.html").write_text("old page")
    with pytest.raises(ValueError, match="report.html"):
        report.write_report(summary["results"], tmp_path)
    assert (tmp_path / "report.html").read_text() == "old page"
    assert not [name for name in os.listdir(tmp_path) if name.endswith(".tmp")]


def test_write_report_needs_every_phenomenon(tmp_path):
    from polind import report

    with pytest.raises(ValueError, match="stribeck"):
        report.write_report({}, tmp_path)
    assert os.listdir(tmp_path) == []


def test_importing_polind_does_not_import_matplotlib():
    code = ("import sys, polind, polind.phenomena, polind.report, polind.demo; "
            "print('matplotlib' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_a_report_is_written_whole_or_not_at_all(demo_run, tmp_path):
    from polind import InputError
    from polind.demo import run_demo
    from polind.report import write_report

    _, summary, _ = demo_run
    (tmp_path / "report.html").mkdir()
    with pytest.raises(InputError, match="report.html"):
        write_report(summary["results"], tmp_path)
    assert sorted(os.listdir(tmp_path)) == ["report.html"]       # no PNG left behind
    with pytest.raises(InputError, match="report.html"):
        run_demo(tmp_path)


# --- what the report says matches what was run (issue 13) -----------------------------------

def _figures(results, subject="Pol-Ind"):
    """Every figure of the report as a matplotlib Figure, by file name (closed by the caller)."""
    from polind.report import figures as plots

    figures = {
        "stribeck.png": plots._figure_stribeck(results["stribeck"]),
        "presliding_memory.png": plots._figure_presliding_memory(results["presliding_memory"]),
        "frictional_lag.png": plots._figure_frictional_lag(results["frictional_lag"]),
        "non_drifting.png": plots._figure_non_drifting(results["non_drifting"]),
        "stick_slip.png": plots._figure_stick_slip(results["stick_slip"]),
        "breakaway.png": plots._figure_breakaway(results["breakaway"], subject),
    }
    figures["stick_slip_reference.png"] = plots._figure_stick_slip_reference(
        results["stick_slip"]["LuGre"], "LuGre")
    assert sorted(figures) == sorted(FIGURES)
    return figures


@pytest.fixture(scope="module")
def figures(demo_run):
    import matplotlib.pyplot as plt

    _, summary, _ = demo_run
    made = _figures(summary["results"])
    yield made
    for figure in made.values():
        plt.close(figure)


def _curve_points(line, per_segment=8):
    """A drawn curve in display coordinates: its samples, and points along its segments."""
    xy = np.asarray(line.get_xydata(), dtype=float)
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if xy.shape[0] < 3:                 # markers of single points, reference lines
        return np.zeros((0, 2))
    display = line.get_transform().transform(xy)
    if line.get_linestyle() in ("None", "", " ", "none"):
        return display
    s = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    along = display[:-1, None, :] + s[None, :, None] * np.diff(display, axis=0)[:, None, :]
    return np.concatenate([along.reshape(-1, 2), display[-1:]])


def test_no_text_box_or_legend_covers_a_curve(figures):
    """Annotation boxes and legends sit where no curve is (they covered the curves of
    non_drifting.png and presliding_memory.png)."""
    covered = []
    for name, figure in figures.items():
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        for ax in figure.axes:
            boxes = [t.get_bbox_patch().get_window_extent(renderer) for t in ax.texts
                     if t.get_bbox_patch() is not None and t.get_visible()]
            if ax.get_legend() is not None:
                boxes.append(ax.get_legend().get_window_extent(renderer))
            curves = [_curve_points(line) for line in ax.lines if line.get_visible()]
            points = np.concatenate(curves) if curves else np.zeros((0, 2))
            for box in boxes:
                inside = ((points[:, 0] > box.x0) & (points[:, 0] < box.x1)
                          & (points[:, 1] > box.y0) & (points[:, 1] < box.y1))
                if inside.any():
                    covered.append((name, ax.get_title(), int(inside.sum())))
    assert not covered


def _figure_texts(figure):
    texts = [text.get_text() for text in figure.findobj(lambda a: hasattr(a, "get_text"))]
    return "\n".join(texts)


def test_micrometres_are_written_um_nowhere(demo_run, figures):
    out, summary, _ = demo_run
    page = (out / "report.html").read_text(encoding="utf-8")
    # the page's words, without its embedded figures: their base64 may hold "+um/"
    words = re.sub(r"base64,[A-Za-z0-9+/=]+", "base64,", page)
    assert len(words) < len(page) / 2                     # the figures were there to strip
    metrics = (out / "metrics.json").read_text(encoding="utf-8")
    for name, text in [("report.html", words), ("metrics.json", metrics),
                       ("summary table", summary["table"])] + [
            (name, _figure_texts(figure)) for name, figure in figures.items()]:
        assert not re.search(r"\bum\b", text), name
    assert "6.64 µm every cycle" in page                  # LuGre's drift, in its reading
    assert "[µm]" in _figure_texts(figures["non_drifting.png"])


def test_stick_slip_settings_are_those_of_the_runs(demo_run):
    """The settings printed under the stick-slip figure are each run's own (they showed the
    last run's duration and time step for every run)."""
    import html

    out, summary, _ = demo_run
    page = html.unescape((out / "report.html").read_text(encoding="utf-8"))
    section = page[page.index('id="stick_slip"'):page.index('id="breakaway"')]
    for label, result in summary["results"]["stick_slip"].items():
        settings = result.settings
        for run in ("reference", "low", "high"):
            measured = result.metrics[run]
            assert settings[f"{run}_duration"] == pytest.approx(measured["duration"], rel=1e-12)
            assert settings[f"{run}_time_step"] == pytest.approx(measured["time_step"],
                                                                 rel=1e-9)
            assert settings[f"{run}_stiffness"] == measured["spring_stiffness"]
            assert settings[f"{run}_drive_velocity"] == measured["drive_velocity"]
        assert (settings["reference_duration"], settings["reference_time_step"]) == (50.0, 1e-3)
        line = section[section.index(f"<b>{label}</b>"):]
        line = line[:line.index("</li>")]
        assert "reference_duration = 50;" in line and "reference_time_step = 0.001;" in line
        assert "low_duration = 10;" in line and "low_time_step = 0.0001;" in line


def test_only_the_1995_set_up_is_called_so(demo_run, figures):
    from polind.report import SET_UP_1995

    _, summary, _ = demo_run
    axes = figures["stick_slip.png"].axes
    runs = ("reference", "low", "high")
    called = []
    for row, (label, result) in enumerate(summary["results"]["stick_slip"].items()):
        for col, run in enumerate(runs):
            title = axes[row * len(runs) + col].get_title()
            m = result.metrics[run]
            assert title.startswith(label)
            assert f"m = {m['mass']:g} kg, k_d = {m['spring_stiffness']:g} N/m" in title
            is_1995 = (m["mass"], m["spring_stiffness"], m["drive_velocity"]) == SET_UP_1995
            assert ("1995" in title) == is_1995, title
            if is_1995:
                called.append((label, run))
    assert called == [("LuGre", "reference")]


def test_the_reference_figure_follows_the_1995_set_up_not_the_model_type(demo_run):
    """stick_slip_reference.png shows the run on the published 1995 set-up (LuGre's in the
    demo), chosen by the run's set-up: retagging the results' model types does not move
    the choice; without a run on that set-up it is the first model, whatever the types."""
    import dataclasses

    from polind.report import SET_UP_1995, is_1995_set_up, reference_label

    _, summary, _ = demo_run
    results = summary["results"]["stick_slip"]
    assert reference_label(results) == "LuGre"
    assert [label for label, result in results.items()
            if is_1995_set_up(result.metrics["reference"])] == ["LuGre"]
    # LuGre's result tagged as another model's type, every other one tagged "lugre"
    retagged = {label: dataclasses.replace(result,
                                           model_type="pol-ind" if label == "LuGre" else "lugre")
                for label, result in results.items()}
    assert reference_label(retagged) == "LuGre"
    # the same results in another order: still the run on the 1995 set-up
    reordered = dict(reversed(list(retagged.items())))
    assert reference_label(reordered) == "LuGre"
    # no run on the 1995 set-up (LuGre's drive velocity doubled): the first model
    moved = dict(retagged["LuGre"].metrics["reference"], drive_velocity=2.0 * SET_UP_1995[2])
    off = dict(retagged, LuGre=dataclasses.replace(
        retagged["LuGre"], metrics=dict(retagged["LuGre"].metrics, reference=moved)))
    assert reference_label(off) == "Pol-Ind"
    assert reference_label({label: off[label] for label in ("GMS", "LuGre")}) == "GMS"


def test_a_loop_is_marked_closed_only_when_it_closes(demo_run, figures):
    """The circles "a loop closes" appear exactly where the measured mismatch is below the
    tolerance; LuGre's loops, which do not close, get the open-loop mark instead."""
    from polind.phenomena import MEMORY_TOLERANCE

    _, summary, _ = demo_run
    results = summary["results"]["presliding_memory"]
    for ax, (label, result) in zip(figures["presliding_memory.png"].axes, results.items()):
        closes = result.metrics["loops_close"]
        assert closes == [gap < MEMORY_TOLERANCE
                          for gap in result.metrics["closure_mismatches"]]
        circles = [line for line in ax.lines if line.get_marker() == "o"]
        squares = [line for line in ax.lines if line.get_marker() == "s"]
        assert len(circles) == sum(closes), label
        assert len(squares) == len(closes) - sum(closes), label
        assert ax.get_title().splitlines()[1].startswith(f"{sum(closes)} of {len(closes)}")
    assert not any(results["LuGre"].metrics["loops_close"])
    assert all(results["Pol-Ind"].metrics["loops_close"])


def test_lag_loops_carry_arrows_the_way_they_are_travelled(demo_run, figures):
    """Two arrows per loop with an area, each from a sample of the loop to a later one, so
    that they point the way the loop circulates; none on a flat "loop"."""
    from matplotlib.text import Annotation

    _, summary, _ = demo_run
    results = summary["results"]["frictional_lag"]
    for ax, (label, result) in zip(figures["frictional_lag.png"].axes, results.items()):
        arrows = [child for child in ax.get_children() if isinstance(child, Annotation)]
        with_area = [loop for loop, area in zip(result.data["loops"],
                                                result.metrics["loop_area"]) if area != 0.0]
        assert len(arrows) == 2 * len(with_area), label
        for arrow in arrows:
            start, end = np.asarray(arrow.xyann), np.asarray(arrow.xy)
            found = False
            for v, force in with_area:
                points = np.column_stack((v * 1e3, force))
                first = np.flatnonzero(np.all(points == start, axis=1))
                last = np.flatnonzero(np.all(points == end, axis=1))
                found = found or (first.size and last.size and last.max() > first.min())
            assert found, (label, start, end)
    assert results["Maxwell-slip"].metrics["loop_area"] == [0.0] * 4


def test_loop_areas_are_not_rounding_noise(demo_run):
    """Maxwell-slip has no lag loop: its area is 0, not -2e-16, and so is what the report
    prints."""
    out, summary, _ = demo_run
    flat = summary["results"]["frictional_lag"]["Maxwell-slip"]
    assert flat.metrics["loop_area"] == [0.0] * 4
    assert flat.metrics["relative_area"] == [0.0] * 4
    row = next(line for line in summary["table"].splitlines()
               if line.startswith("frictional_lag"))
    assert "area 0" in row and "e-1" not in row.split("area 0")[-1]
    page = (out / "report.html").read_text(encoding="utf-8")
    assert not re.search(r"area -\d", page)
    for result in summary["results"]["frictional_lag"].values():
        assert min(result.metrics["loop_area"]) >= 0.0


def test_the_subjects_breakaway_markers_are_not_hidden(figures):
    """Pol-Ind and GMS break away at nearly the same forces: Pol-Ind's markers are drawn
    on top, large and open, with a marker of their own."""
    left = figures["breakaway.png"].axes[0]
    lines = {line.get_label().split(" (")[0]: line for line in left.lines
             if not line.get_label().startswith("_")}
    subject = lines.pop("Pol-Ind")
    assert subject.get_markerfacecolor() == "none"
    assert all(subject.get_zorder() > line.get_zorder() for line in lines.values())
    assert all(subject.get_markersize() > line.get_markersize() for line in lines.values())
    markers = [line.get_marker() for line in lines.values()]
    assert len(set(markers)) == len(markers) and subject.get_marker() not in markers


def test_parameter_blocks_are_model_files(demo_run, tmp_path):
    """Every parameter block of report.html is a model file: tomllib reads it and
    polind.load_model builds the very model the demo ran."""
    import html
    import tomllib

    import polind
    from polind.demo import demo_models

    out, _, _ = demo_run
    page = (out / "report.html").read_text(encoding="utf-8")
    blocks = [html.unescape(text) for text in
              re.findall(r'<pre class="model-file">(.*?)</pre>', page, flags=re.S)]
    models = {label: model for label, (model, _) in demo_models().items()}
    assert len(blocks) == len(models) == len(LABELS)
    for (label, model), block in zip(models.items(), blocks):
        document = tomllib.loads(block)
        assert list(document) == ["model"] and document["model"]["type"] == model.type
        path = tmp_path / f"{label}.toml"
        path.write_text(block, encoding="utf-8")
        assert polind.load_model(path) == model, label


# --- the models' experiments in processes of their own -----------------------------------------

def test_experiments_in_processes_equal_those_in_this_process():
    # A cheap model with every phenomenon: the pool's results are the in-process ones, bit
    # for bit.
    from polind.demo import _experiments, _experiments_in_processes, _progress_hooks
    from polind.models import MODEL_TYPES

    dahl = MODEL_TYPES["dahl"].example()
    said = []
    pooled = _experiments_in_processes({"a": dahl, "b": dahl}, 2, said.append)
    calls = []          # a progress function: progress(done, total, description)
    total = len(PHENOMENA) + 1
    here = _experiments("a", dahl, _progress_hooks(
        lambda done, count, what: calls.append((done, count, what)), total))
    assert calls == [(k + 1, total, f"{phenomenon}: a") for k, phenomenon in enumerate(PHENOMENA)]
    assert list(pooled) in (["a", "b"], ["b", "a"]) and len(said) == 2 * len(PHENOMENA)
    for phenomenon in PHENOMENA:
        assert _same(vars(pooled["a"][phenomenon]), vars(here[phenomenon])), phenomenon


def _same(a, b):
    """Equal to the bit: the same structure, arrays and numbers (NaN equal to NaN)."""
    if isinstance(a, dict):
        return isinstance(b, dict) and list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(map(_same, a, b))
    if isinstance(a, (np.ndarray, float, np.floating)):
        return np.array_equal(a, b, equal_nan=True) and np.shape(a) == np.shape(b)
    if hasattr(a, "__dict__") and not isinstance(a, type):
        return type(a) is type(b) and _same(vars(a), vars(b))
    return a == b


def _unscaled_coulomb():
    from polind.models.static import Coulomb

    class Unscaled(Coulomb):
        """A model that declares no scales: the phenomena refuse it."""

        def characteristic_scales(self):
            return None

    Unscaled.__module__, Unscaled.__qualname__ = __name__, "UNSCALED"
    return Unscaled


UNSCALED = _unscaled_coulomb()     # module level: a spawned process unpickles it by name


def _warning_dahl():
    import warnings

    from polind.models.dahl import Dahl

    class Warns(Dahl):
        """A Dahl model that warns whenever an experiment sizes itself."""

        def characteristic_scales(self):
            warnings.warn("sized in its own process", UserWarning)
            return super().characteristic_scales()

    Warns.__module__, Warns.__qualname__ = __name__, "WARNS"
    return Warns


WARNS = _warning_dahl()


def test_warnings_and_the_memory_limit_cross_to_the_processes():
    import warnings

    from polind import InputError
    from polind.demo import _experiments_in_processes
    from polind.resources import set_memory_limit

    model = WARNS(**WARNS.example().params)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _experiments_in_processes({"a": model}, 2, lambda what: None)
    said = [str(w.message) for w in caught if "own process" in str(w.message)]
    assert said == ["sized in its own process"]          # given here, once
    set_memory_limit(1e3)
    try:
        with pytest.raises(InputError, match=r"set by --max-memory"):
            _experiments_in_processes({"a": model}, 2, lambda what: None)
    finally:
        set_memory_limit(None)


def test_a_failed_experiment_in_a_process_is_the_input_error_it_raised():
    from polind import InputError
    from polind.demo import _experiments_in_processes

    model = UNSCALED(coulomb_force=1.0)
    with pytest.raises(InputError, match=r"^The stribeck experiment on lone: "):
        _experiments_in_processes({"lone": model, "other": model}, 2, lambda what: None)


@pytest.mark.parametrize("workers", [0, -1, 1.5, True, "2"])
def test_workers_must_be_a_whole_number_of_processes(workers, tmp_path):
    from polind import InputError
    from polind.demo import run_demo

    with pytest.raises(InputError, match="'workers' of run_demo"):
        run_demo(tmp_path / "out", workers=workers)
    assert not (tmp_path / "out").exists()
