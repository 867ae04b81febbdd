"""SimulationResult's conveniences (polind.simulation): a short repr, to_frame (pandas) and
to_csv with the columns of ``polind simulate``."""

from __future__ import annotations

import numpy as np
import pytest

import polind
from polind import cli
from polind import io as polind_io
from polind.models.pol_ind import default_table
from conftest import lib, representative


@pytest.fixture(scope="module")
def result():
    model = lib(representative("maxwell-slip"))
    t = np.linspace(0.0, 1.0, 1001)
    return polind.simulate(model, t, x=3e-6 * np.sin(2.0 * np.pi * 3.0 * t))


def test_repr_is_one_short_line_whatever_the_run():
    model = lib(default_table())
    t = np.linspace(0.0, 1.0, 1_000_001)
    res = polind.simulate(model, t, x=1e-7 * np.sin(2.0 * np.pi * t), normal_load=100.0 + t)
    text = repr(res)
    assert "\n" not in text and len(text) < 300, text
    assert text.startswith("SimulationResult(1000001 samples, t 0 .. 1 s")
    assert "force " in text and " N" in text and "normal_load 100 .. 101 N" in text
    assert "final_state pol-ind at t = 1 s" in text
    assert "array" not in text and "..." not in text


def test_repr_of_a_result_without_normal_load(result):
    text = repr(result)
    assert "normal_load" not in text and "1001 samples" in text
    assert f"x {result.x.min():.4g} .. {result.x.max():.4g} m" in text


def test_to_frame_has_the_columns_of_polind_simulate(result):
    pandas = pytest.importorskip("pandas")
    frame = result.to_frame()
    assert isinstance(frame, pandas.DataFrame)
    assert frame.columns.tolist() == ["t", "x", "v", "F"]
    assert len(frame) == result.t.shape[0]
    for column, array in zip("txvF", (result.t, result.x, result.v, result.force)):
        np.testing.assert_array_equal(frame[column].to_numpy(), array)
    frame.loc[0, "F"] = 123.0                               # a copy: the result is untouched
    assert result.force[0] != 123.0


@pytest.mark.parametrize("name", ["out.csv", "out.parquet"])
def test_to_csv_writes_what_polind_simulate_writes(result, tmp_path, capsys, name):
    """The same header and the same numbers as ``polind simulate`` on the same motion."""
    model_path = tmp_path / "model.toml"
    polind.save_model(lib(representative("maxwell-slip")), model_path)
    motion = tmp_path / "motion.csv"
    polind_io.write_csv_atomic(motion, {"t": result.t, "x": result.x})
    by_cli = tmp_path / f"cli-{name}"
    with pytest.raises(SystemExit) as status:
        cli.main(["simulate", str(model_path), "--input", str(motion), "--output", str(by_cli)])
    assert status.value.code == 0
    capsys.readouterr()
    mine = tmp_path / name
    result.to_csv(mine)
    if name.endswith(".csv"):
        assert mine.read_text() == by_cli.read_text()
        assert mine.read_text().splitlines()[0] == "t,x,v,F"
    back = polind_io.read_csv_columns(mine, require=("t", "x", "v", "F"))
    for column, array in zip("txvF", (result.t, result.x, result.v, result.force)):
        np.testing.assert_array_equal(back[column], array)          # bit for bit


def test_to_csv_is_an_atomic_output(result, tmp_path):
    with pytest.raises(polind.InputError, match="directory"):
        result.to_csv(tmp_path)
    path = tmp_path / "out.csv"
    path.write_text("old\n")
    calls = []
    result.to_csv(path, progress=lambda done, total: calls.append((done, total)))
    assert path.read_text().startswith("t,x,v,F\n")
    assert calls[-1] == (1001, 1001)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]
