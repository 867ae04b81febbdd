"""`polind bench --big-files`: the 1e7-sample `polind simulate` case as a bench row (issue 14)."""

from __future__ import annotations

import numpy as np

from polind import io
from polind.bench import big_files, harness
from polind.cli import _run


def test_the_big_file_row_measures_a_real_simulate_process(tmp_path):
    row = big_files.run_big_files(samples=3000, folder=tmp_path)
    assert row.samples == 3000 and row.seconds > 0 and row.cpu_seconds > 0
    assert 20e6 < row.peak_bytes < 2e9                  # a Python process with numba in it
    assert row.input_bytes > 3000 * 2 * 17 and row.output_bytes > row.input_bytes
    assert list(tmp_path.iterdir()) == []                # the temporary files are gone
    text = big_files.format_big_files(row)
    assert "3e+03-sample CSV" in text and "target 8 s and 1000 MB" in text


def test_the_big_motion_reads_back_to_the_bit(tmp_path):
    t, x = big_files.big_motion(1000)
    path = tmp_path / "motion.csv"
    big_files.write_big_motion_csv(path, t, x)
    motion = io.read_motion_csv(path)
    np.testing.assert_array_equal(motion["t"], t)
    np.testing.assert_array_equal(motion["x"], x)


def fake_bench(monkeypatch):
    row = harness.BenchRow("lugre", 1, 100, 1e8, 1e6, 0.0)
    monkeypatch.setattr(harness, "run_case", lambda model_type, n: row)
    calls = []

    def fake_big_files(samples=big_files.BIG_FILE_SAMPLES, folder=None, progress=None):
        calls.append(samples)
        return big_files.BigFileRow(samples, 423_000_000, 854_000_000, 7.5, 7.0, 900_000_000)

    monkeypatch.setattr(big_files, "run_big_files", fake_big_files)
    return calls


def test_bench_runs_the_big_files_only_when_asked(monkeypatch, capsys):
    calls = fake_bench(monkeypatch)
    assert _run(["bench", "--model", "lugre"]) == 0
    assert calls == [] and "Maxwell-slip" not in capsys.readouterr().out
    assert _run(["bench", "--model", "lugre", "--big-files"]) == 0
    out = capsys.readouterr().out
    assert calls == [big_files.BIG_FILE_SAMPLES]
    assert out.splitlines()[-1] == (
        "polind simulate, 4-element Maxwell-slip, 1e+07-sample CSV in and out (423 MB in, "
        "854 MB out): 7.50 s (7.00 s of CPU), peak 900 MB; target 8 s and 1000 MB: met")
