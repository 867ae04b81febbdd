"""``polind demo``'s report (polind.report, polind.demo): the files of INTERFACE.md, a
self-contained page, metrics.json with the six phenomena, the summary table, progress."""

import base64
import json
import os
import re
import subprocess
import sys

import pytest

from polind.phenomena import PHENOMENA

FIGURES = ("stribeck.png", "presliding_memory.png", "frictional_lag.png", "non_drifting.png",
           "stick_slip.png", "stick_slip_reference.png", "breakaway.png")
LABELS = ("Pol-Ind", "LuGre", "GMS", "Maxwell-slip")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    from polind.demo import run_demo

    out = tmp_path_factory.mktemp("report")
    calls = []
    summary = run_demo(out, progress=lambda done, total, what: calls.append((done, total, what)))
    return out, summary, calls


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
    assert "6.6 um/cyc" in rows["non_drifting"]               # LuGre's drift


def test_progress_callback(demo_run):
    _, _, calls = demo_run
    total = len(LABELS) * len(PHENOMENA) + 1
    assert [done for done, _, _ in calls] == list(range(1, total + 1))
    assert {count for _, count, _ in calls} == {total}
    assert calls[-1][2] == "report"


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
    from polind import io, report

    _, summary, _ = demo_run
    fake = {name: PNG_MAGIC + name.encode() for name in FIGURES}
    monkeypatch.setattr(report, "render_figures", lambda results, subject: fake)
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

    monkeypatch.setattr(io.os, "replace", refuse_the_page)
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
