"""`polind bench --processes`: whole `polind` processes cold and warm (issue 25, item 4).

Structure only, never timings: one small case really runs (Coulomb, whose
kernels compile in a second or two), the rest is checked on made-up rows.
"""

from __future__ import annotations

import pytest

from polind.bench import processes
from polind.cli import _run

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


#: What the suite's other worker may write into the clone while a test here runs: numba's
#: cache beside the sources, Hypothesis's database, pytest's cache.
OTHERS = {".git", "__pycache__", ".hypothesis", ".pytest_cache"}


def repository_files():
    return {path for path in ROOT.rglob("*") if not OTHERS.intersection(path.parts)}


def test_a_case_runs_cold_in_an_empty_cache_then_warm_in_the_same(tmp_path):
    before = repository_files()
    seen = []
    rows = processes.run_processes(["simulate coulomb"], warm_runs=1, cold_runs=2,
                                   folder=tmp_path, progress=seen.append)
    assert seen == rows and len(rows) == 1
    row = rows[0]
    assert row.case == "simulate coulomb"
    assert row.cold_seconds > 0 and row.warm_seconds > 0
    assert row.cache_files > 0          # numba compiled into the empty directory (cold) ...
    assert row.warm_changes == 0        # ... and the warm run loaded it, compiling nothing
    assert row.cold_over_warm == row.cold_seconds / row.warm_seconds
    assert list(tmp_path.iterdir()) == []                # the temporary files are gone
    assert repository_files() == before                  # nothing written into the repo
    table = processes.format_processes(rows).splitlines()
    assert table[0].startswith("whole process") and table[1].startswith("simulate coulomb")


def test_a_cold_run_refuses_a_cache_directory_that_is_not_empty(tmp_path):
    (tmp_path / "left-over.nbi").write_text("")
    with pytest.raises(ValueError, match="empty cache directory"):
        processes.run_case("simulate lugre", ["--help"], tmp_path)


def test_the_case_sets():
    every = processes.case_names()
    assert processes.case_names(quick=True) == list(processes.QUICK_CASES)
    assert set(processes.QUICK_CASES) <= set(every)
    for name in ("simulate lugre", "simulate pol-ind", "simulate pol-ind + compliance",
                 "simulate pol-ind map + compliance", "fit lugre",
                 "fit pol-ind map + compliance", "demo"):
        assert name in every
    with pytest.raises(processes.InputError, match="unknown whole-process case"):
        processes.run_processes(["simulate nothing"])


def made_up_rows():
    row = processes.ProcessRow
    return [row("simulate lugre", 6.0, 1.5, 9, 0, 300.0),
            row("simulate lugre + compliance", 9.0, 2.0, 12, 0, 300.0),
            row("simulate pol-ind", 20.0, 2.0, 30, 0, 300.0),
            row("simulate pol-ind + compliance", 30.0, 3.5, 40, 0, 300.0),
            row("fit pol-ind map + compliance", None, None, 50, 0, 300.0),
            row("demo", 80.0, 25.0, 90, 0, 300.0)]


def test_the_target_rows_are_ratios_of_the_same_runs():
    targets = {r.name: r for r in processes.target_rows(made_up_rows())}
    cold_warm = targets["cold / warm: simulate lugre"]
    assert cold_warm.value == 6.0 / 1.5 and cold_warm.target == 3.0 and not cold_warm.met
    assert targets["cold / warm: demo"].value == 80.0 / 25.0
    assert targets["cold / warm: demo"].met
    assert targets["warm: simulate lugre + compliance / without"].value == 2.0 / 1.5
    assert targets["warm: simulate pol-ind + compliance / without"].value == 3.5 / 2.0
    assert targets["warm: simulate pol-ind + compliance / lugre"].value == 3.5 / 1.5
    fit = targets["warm: fit pol-ind map + compliance"]
    assert fit.value is None and not fit.met and "> 300 s" in fit.detail
    text = processes.format_targets(list(targets.values()))
    assert "<= 30 s" in text and "NOT" in text and " met " in text
    assert "> 300" in processes.format_processes(made_up_rows())


def test_bench_runs_the_processes_only_when_asked(monkeypatch, capsys):
    from polind.bench import harness

    monkeypatch.setattr(harness, "run_case",
                        lambda model_type, n: harness.BenchRow("lugre", 1, 100, 1e8, 1e6, 0.0))
    calls = []

    def fake(progress=None, **options):
        rows = made_up_rows()
        calls.append(options)
        for row in rows:
            progress(row)
        return rows

    monkeypatch.setattr(processes, "run_processes", fake)
    assert _run(["bench", "--model", "lugre"]) == 0
    assert calls == [] and "whole process" not in capsys.readouterr().out
    assert _run(["bench", "--model", "lugre", "--processes"]) == 0
    out = capsys.readouterr().out
    assert len(calls) == 1 and "whole process" in out and "target (same run)" in out
    assert "warm: fit pol-ind map + compliance" in out


def test_the_note_on_bytecode_appears_only_where_processes_compile_their_libraries(
        monkeypatch, tmp_path):
    import importlib.util

    import numba

    compiled = tmp_path / "numba.pyc"
    monkeypatch.setattr(importlib.util, "cache_from_source", lambda path: str(compiled))
    assert processes.bytecode_note({}) == ""                  # the first process writes it
    note = processes.bytecode_note({"PYTHONDONTWRITEBYTECODE": "1"})
    assert "--compile-bytecode" in note and "\n" not in note  # missing and never written
    compiled.write_bytes(b"")
    assert processes.bytecode_note({"PYTHONDONTWRITEBYTECODE": "1"}) == ""   # installed
    assert numba.__file__.endswith("__init__.py")
