"""polind.save_model (polind.io): a model file that polind.load_model reads back to an equal
model, for every model type, written as every polind output is."""

from __future__ import annotations

import os
import tomllib

import numpy as np
import pytest

import polind
from polind import io
from polind.io import output
from polind.models.pol_ind import default_table
from conftest import REPRESENTATIVE, lib


def pol_ind_with(**changes):
    table = default_table()
    for key, value in changes.items():
        if isinstance(value, dict):
            table[key] = {**table.get(key, {}), **value}
        else:
            table[key] = value
    return table


CASES = {**{name: table for name, table in REPRESENTATIVE.items()},
         "pol-ind": default_table(),
         "pol-ind, direct, seeded": pol_ind_with(
             discretisation={"summation": "direct", "seed": 3},
             surface={"nominal_area": 2e-6}),
         "pol-ind, rational, compliance": pol_ind_with(stribeck_shape="rational",
                                                       compliance={"stiffness": 2.5e7}),
         "lugre, reference load and compliance": {**REPRESENTATIVE["lugre"],
                                                  "reference_load": 50.0,
                                                  "compliance": {"stiffness": 1e6}},
         "maxwell-slip, reference load": {**REPRESENTATIVE["maxwell-slip"],
                                          "reference_load": 1.0},
         "gms, 1/3 weights": {**REPRESENTATIVE["gms"], "stiffness": [1e5, 3e4, 1e4],
                              "weight": [1.0 / 3.0] * 3},
         }


def test_every_built_in_model_type_is_a_case():
    built_in = {name for name, cls in polind.MODEL_TYPES.items()
                if cls.__module__.startswith("polind.")}
    assert built_in <= {table["type"] for table in CASES.values()}


@pytest.mark.parametrize("suffix", [".toml", ".json"])
@pytest.mark.parametrize("case", list(CASES))
def test_round_trip_gives_an_equal_model(tmp_path, case, suffix):
    model = lib(CASES[case])
    path = tmp_path / f"model{suffix}"
    polind.save_model(model, path)
    again = polind.load_model(path)
    assert again == model
    assert type(again) is type(model)
    assert again.to_dict() == model.to_dict()
    if suffix == ".toml":
        document = tomllib.loads(path.read_text(encoding="utf-8"))
        assert list(document) == ["model"] and document["model"]["type"] == model.type


def test_nested_tables_and_mounts_are_tables_of_the_file(tmp_path):
    model = lib(CASES["pol-ind, rational, compliance"])
    path = tmp_path / "pol-ind.toml"
    polind.save_model(model, path)
    text = path.read_text(encoding="utf-8")
    for table in ("[model]", "[model.surface]", "[model.materials]", "[model.discretisation]",
                  "[model.compliance]"):
        assert table in text.splitlines(), table
    # a float reads back bit for bit
    awkward = lib({**REPRESENTATIVE["lugre"], "bristle_damping": 0.1 + 0.2,
                   "coulomb_force": np.float64(1.0) / 3.0})
    polind.save_model(awkward, path)
    assert polind.load_model(path).params["bristle_damping"] == 0.1 + 0.2


def test_a_relative_heights_file_is_saved_as_the_file_the_model_reads(tmp_path, monkeypatch):
    (tmp_path / "data").mkdir()
    (tmp_path / "out").mkdir()
    heights = np.random.default_rng(0).normal(0.0, 5e-7, 400)
    (tmp_path / "data" / "summits.csv").write_text(
        "h\n" + "\n".join(repr(float(h)) for h in heights) + "\n")
    table = default_table()
    table["surface"] = {"asperity_radius": table["surface"]["asperity_radius"]}
    table["discretisation"] = {"summation": "direct", "heights_file": "data/summits.csv"}
    monkeypatch.chdir(tmp_path)
    model = lib(table)
    polind.save_model(model, tmp_path / "out" / "model.toml")
    again = polind.load_model(tmp_path / "out" / "model.toml")
    saved = again.params["discretisation"]["heights_file"]
    assert saved == str(tmp_path / "data" / "summits.csv")
    assert again.with_params(discretisation={**again.params["discretisation"],
                                             "heights_file": "data/summits.csv"}) == model
    # the heights file is the model's input: never its output
    with pytest.raises(polind.InputError, match="input"):
        polind.save_model(model, tmp_path / "data" / "summits.csv")
    assert (tmp_path / "data" / "summits.csv").read_text().startswith("h\n")


def test_written_as_every_output_is(tmp_path, monkeypatch, capsys):
    model = lib(REPRESENTATIVE["dahl"])
    with pytest.raises(polind.InputError, match="directory"):
        polind.save_model(model, tmp_path)
    with pytest.raises(polind.InputError, match="FrictionModel"):
        polind.save_model(model.to_dict(), tmp_path / "model.toml")
    # an existing file is replaced whole, or left as it was
    path = tmp_path / "model.toml"
    path.write_text("old\n")
    real_replace = os.replace

    def full_disk(source, target):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(output.os, "replace", full_disk)
    with pytest.raises(polind.InputError, match="No space left"):
        polind.save_model(model, path)
    assert path.read_text() == "old\n"
    assert os.listdir(tmp_path) == ["model.toml"]              # no temporary file left
    monkeypatch.setattr(output.os, "replace", real_replace)
    polind.save_model(model, path)
    assert polind.load_model(path) == model
    # "-" is standard output
    capsys.readouterr()
    polind.save_model(model, "-")
    assert tomllib.loads(capsys.readouterr().out) == model.to_dict()


def test_save_model_is_public():
    assert "save_model" in polind.__all__
    assert polind.save_model is io.save_model
