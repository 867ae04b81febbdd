"""The data polind ships (:mod:`polind.datasets`), and no path to data outside the project.

References, each independent of the code under test:
- the facts of the data's README (``src/polind/datasets/data/README.md``):
  friction about +-2.5 N, a normal load of 5.0 N, strokes of 0.24 mm, 5 ms samples;
- the raw file read again here by pyarrow's CSV reader and turned into SI units by
  the rules of its data description (``tribometer_reciprocating.toml``), parsed by
  :mod:`tomllib`;
- the physics of sliding: at the end of a stroke the contact slides, and friction
  resisting the motion has the sign of the velocity;
- the project's own files, read as text, for paths to a data folder outside it.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

import polind
from polind import datasets
from polind.errors import InputError
from polind.topography import HeightMap

ROOT = Path(__file__).resolve().parents[1]

#: The unit names a data description uses, in SI.
SI = {"s": 1.0, "mm": 1e-3, "m": 1.0, "uN": 1e-6, "N": 1.0}


# --- the tribometer record --------------------------------------------------------------------

@pytest.fixture(scope="module")
def record():
    return datasets.tribometer()


def test_the_record_is_four_float_arrays_of_one_length(record):
    assert set(record) == {"t", "x", "F", "normal_load"}
    for key, array in record.items():
        assert isinstance(array, np.ndarray) and array.dtype == np.float64, key
        assert array.shape == (40800,), key
        assert np.isfinite(array).all(), key


def test_time_increases_strictly_every_5_ms_over_the_loaded_part(record):
    t = record["t"]
    assert np.all(np.diff(t) > 0)
    assert np.diff(t) == pytest.approx(0.005, abs=1e-9)
    assert (t[0], t[-1]) == (6.789, 210.784)


def test_the_record_is_in_si_units(record):
    # Friction of about 2.5 N (a coefficient near 0.5), not 2.5e6 uN.
    assert 2.0 < np.max(np.abs(record["F"])) < 3.0
    # The normal load is held at 5.0 N (its median; the brief's "about 4.8 N" is its
    # mean over the whole raw record, the unloaded ends included); the window keeps
    # only samples loaded to at least half of it.
    load = record["normal_load"]
    assert np.median(load) == pytest.approx(5.0, rel=0.01)
    assert np.min(load) >= 0.5 * np.median(load)
    # Strokes of 0.24 mm, the position zeroed at the first sample.
    assert record["x"][0] == 0.0
    assert np.ptp(record["x"]) == pytest.approx(0.24e-3, rel=0.02)


def velocity(record, half_span=10):
    """Centred differences over ``2 half_span`` samples (0.1 s: the position is quantised
    to 0.1 µm), with the friction at the same samples."""
    x, t, k = record["x"], record["t"], half_span
    return ((x[2 * k:] - x[:-2 * k]) / (t[2 * k:] - t[:-2 * k]), record["F"][k:-k],
            x[k:-k])


def test_friction_resists_motion(record):
    v, force, x = velocity(record)
    moving = np.abs(v) > 0.5 * np.max(np.abs(v))
    assert moving.sum() > 10000
    # Over the moving samples friction goes with the sign of the velocity (the
    # instrument's own sign would give a negative correlation).
    assert np.corrcoef(force[moving], np.sign(v[moving]))[0, 1] > 0.3
    # In the last quarter of every stroke the contact slides: friction has the
    # velocity's sign on every sample, at about 2.3 N.
    low, span = x.min(), np.ptp(x)
    late = moving & (((v > 0) & (x > low + 0.75 * span)) | ((v < 0) & (x < low + 0.25 * span)))
    assert late.sum() > 1000
    sliding = force[late] * np.sign(v[late])
    assert np.all(sliding > 0)
    assert np.median(sliding) == pytest.approx(2.3, rel=0.05)


def test_each_call_returns_new_arrays(record):
    first = datasets.tribometer()
    first["F"][:] = 0.0
    first["t"] = None
    again = datasets.tribometer()
    assert again["F"] is not first["F"]
    assert np.array_equal(again["F"], record["F"]) and np.max(np.abs(again["F"])) > 2.0
    assert again["t"] is not None and again["t"].flags.writeable


# --- the raw file, its data description and its licence ----------------------------------------

@pytest.fixture(scope="module")
def description():
    path = datasets.tribometer_description_path()
    with open(path, "rb") as stream:
        return path, tomllib.load(stream)


def test_the_data_description_parses_with_its_keys(description):
    path, document = description
    assert path.parent == datasets.tribometer_path().parent
    data = document["data"]
    assert set(data) == {"file", "delimiter", "columns", "units", "sign", "zero", "window"}
    assert data["file"] == "tribometer_reciprocating.tsv"
    assert (path.parent / data["file"]).is_file()
    assert path.parent / data["file"] == datasets.tribometer_path()
    assert data["delimiter"] == "\t"
    assert data["columns"] == {"t": "Time [s]", "x": "Position [mm]", "F": "Friction [uN]",
                               "normal_load": "Normal [uN]"}
    assert data["units"] == {"x": "mm", "F": "uN", "normal_load": "uN"}
    assert data["sign"] == {"F": -1}
    assert data["zero"] == ["x"]
    low, high = data["window"]
    assert isinstance(low, float) and isinstance(high, float) and low < high


def test_the_data_description_read_by_hand_gives_the_record(description, record):
    import pyarrow.csv

    path, document = description
    data = document["data"]
    table = pyarrow.csv.read_csv(path.parent / data["file"],
                                 parse_options=pyarrow.csv.ParseOptions(
                                     delimiter=data["delimiter"]))
    assert table.num_rows == 42579
    assert table.column_names == ["Time [s]", "Normal [uN]", "Position [mm]", "Friction [uN]"]
    columns = {key: table[name].to_numpy().astype(np.float64)
               for key, name in data["columns"].items()}
    low, high = data["window"]
    keep = (columns["t"] >= low) & (columns["t"] <= high)
    for key, raw in columns.items():
        value = raw[keep] * SI[data["units"].get(key, "s")] * data["sign"].get(key, 1)
        if key in data["zero"]:
            value = value - value[0]
        assert np.allclose(value, record[key], rtol=1e-12, atol=1e-15), key
    # The window is the loaded contact: half the median load is crossed just outside it.
    load = columns["normal_load"]
    half = 0.5 * np.median(load)
    loaded = np.flatnonzero(load >= half)
    assert (columns["t"][loaded[0]], columns["t"][loaded[-1]]) == (low, high)


def test_the_record_is_the_arrays_the_hand_reader_gave_to_the_bit(record):
    # The reader polind.datasets had before the data description was read by
    # polind.io.read_record, kept here as the reference: numpy's parser, the columns by
    # name, mm and uN scaled by hand, the sign of the friction flipped, the window kept
    # and the position zeroed.
    path = datasets.tribometer_path()
    with open(path, encoding="utf-8") as stream:
        header = [name.strip() for name in stream.readline().rstrip("\n").split("\t")]
    table = np.loadtxt(path, delimiter="\t", skiprows=1, dtype=np.float64, ndmin=2)
    columns = {"t": "Time [s]", "x": "Position [mm]", "F": "Friction [uN]",
               "normal_load": "Normal [uN]"}
    scale = {"t": 1.0, "x": 1e-3, "F": -1e-6, "normal_load": 1e-6}
    t = table[:, header.index("Time [s]")]
    keep = (t >= 6.789) & (t <= 210.784)
    by_hand = {key: table[keep, header.index(column)] * scale[key]
               for key, column in columns.items()}
    by_hand["x"] = by_hand["x"] - by_hand["x"][0]
    assert list(record) == list(by_hand)
    for key, values in by_hand.items():
        assert record[key].tobytes() == values.tobytes(), key


def test_the_record_is_read_through_its_data_description(record):
    from polind import io

    described = io.read_record(datasets.tribometer_description_path())
    assert list(described) == ["t", "x", "F", "normal_load"]
    for key, values in described.items():
        assert record[key].tobytes() == values.tobytes(), key
    assert io.record_files(datasets.tribometer_description_path())[-1] == \
        datasets.tribometer_path()


def test_the_licences_and_the_notes_are_beside_the_data():
    folder = datasets.data_folder()
    assert datasets.tribometer_path().parent == folder
    licence = (folder / "tribometer_reciprocating.LICENSE").read_text(encoding="utf-8")
    assert "MIT License" in licence and "Christopherson" in licence
    assert "MIT license" in (folder / "topography" / "LICENSE").read_text(encoding="utf-8")
    notes = (folder / "README.md").read_text(encoding="utf-8")
    for fact in ("FrictionModels.jl", "examples/test_data_2.txt", "SurfaceTopography",
                 "test/file_format_examples/", "42,579 samples", "F = -Friction",
                 "6.789 s to 210.784 s"):
        assert fact in notes, fact


def test_every_data_file_is_package_data_of_the_wheel():
    with open(ROOT / "pyproject.toml", "rb") as stream:
        patterns = tomllib.load(stream)["tool"]["setuptools"]["package-data"]["polind.datasets"]
    package = Path(datasets.__file__).parent
    shipped = {path for pattern in patterns for path in package.glob(pattern) if path.is_file()}
    files = {path for path in (package / "data").rglob("*") if path.is_file()}
    assert files - shipped == set()
    assert {path.name for path in files} >= {
        "tribometer_reciprocating.tsv", "tribometer_reciprocating.LICENSE",
        "tribometer_reciprocating.toml", "README.md", "x3p-2.x3p", "sur-2.sur", "LICENSE"}


# --- the height maps ------------------------------------------------------------------------

@pytest.mark.parametrize("name, grid, pixel", [("x3p-2.x3p", (650, 650), (0.128e-6, 0.315e-6)),
                                               ("sur-2.sur", (563, 484), (3.48e-6, 3.48e-6))])
def test_each_height_map_reads_in_metres(name, grid, pixel):
    assert name in datasets.HEIGHT_MAPS
    assert datasets.height_map_path(name).is_file()
    surface = datasets.height_map(name)
    assert isinstance(surface, HeightMap)
    assert surface.grid == grid
    assert surface.pixel_size == pytest.approx(pixel, rel=5e-3)
    heights = surface.heights[np.isfinite(surface.heights)]
    assert 1e-9 < np.std(heights) < 1e-6                    # nanometres, in metres
    assert np.isnan(surface.heights).any() == (name == "sur-2.sur")


def test_an_unknown_height_map_is_refused_naming_the_maps():
    assert datasets.HEIGHT_MAPS == ("x3p-2.x3p", "sur-2.sur")
    for call in (datasets.height_map, datasets.height_map_path):
        with pytest.raises(InputError, match=r"'x3p-2\.x3p', 'sur-2\.sur'") as caught:
            call("x3p-1.x3p")
        assert "x3p-1.x3p" in str(caught.value)
        assert isinstance(caught.value, polind.InputError)


def test_datasets_is_imported_on_first_use_only():
    code = ("import sys\nimport polind\n"
            "before = 'polind.datasets' in sys.modules or 'numpy' in sys.modules\n"
            "print(before, polind.datasets.HEIGHT_MAPS[0], "
            "'polind.datasets' in sys.modules, 'SurfaceTopography' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=True)
    assert done.stdout.split() == ["False", "x3p-2.x3p", "True", "False"]


# --- no data from outside the project ----------------------------------------------------------

#: Paths that reach for data outside the project: the development machine's folder,
#: a sibling "shared" folder (relative, or joined onto a parent of the project).  Each
#: pattern is written so that it does not match its own text, so this file is searched
#: too.
OUTSIDE = (
    (re.compile(r"/wor[k]/"), "an absolute path of the development machine"),
    (re.compile(r"\.\./share[d]\b"), "a relative path to a sibling folder"),
    (re.compile(r"""parent[s]?(\[\d+\])?\s*/\s*["']share[d]["']"""),
     "a folder beside the project"),
    (re.compile(r"""/\s*["']share[d]["']\s*/"""), "a path through a folder named shared"),
    (re.compile(r"""["']share[d]["']\s*,\s*["']data["']"""), "a path through a shared data folder"),
    (re.compile(r"\bshare[d]/data\b"), "a shared data folder"),
)

#: Where the project's text lives: folders searched whole, and single files.
SEARCHED = ("src", "tests", "examples", "docs", "benchmarks", "README.md", "Makefile",
            "pyproject.toml")
#: Made by builds, not written by hand: a stale copy would not be a source.
GENERATED = ("docs/_build", "docs/auto_examples", "docs/api/generated")
TEXT = {".py", ".md", ".rst", ".toml", ".txt", ".cfg", ".ini", ".yml", ".yaml", ".json",
        ".html", ".css", ".js", ".sh", ".csv", ".LICENSE", ""}


def project_files():
    for name in SEARCHED:
        top = ROOT / name
        paths = [top] if top.is_file() else sorted(top.rglob("*"))
        for path in paths:
            relative = path.relative_to(ROOT).as_posix()
            if not path.is_file() or "__pycache__" in path.parts or any(
                    relative == folder or relative.startswith(folder + "/")
                    for folder in GENERATED):
                continue
            if path.suffix in TEXT or path.name == "Makefile":
                yield relative, path


def outside_paths(text: str, where: str) -> list[str]:
    """``where:line: what: the line`` for each line of ``text`` with a path outside."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        for pattern, what in OUTSIDE:
            if pattern.search(line):
                found.append(f"{where}:{number}: {what}: {line.strip()}")
                break
    return found


def test_nothing_reads_data_from_outside_the_project():
    found = []
    searched = set()
    for relative, path in project_files():
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        searched.add(relative)
        found += outside_paths(text, relative)
    # This file is searched too: its patterns do not match their own text.
    assert {"tests/test_datasets.py", "README.md", "Makefile", "pyproject.toml",
            "examples/tribometer_fit.py", "docs/conf.py"} <= searched
    assert not found, "paths outside the project:\n" + "\n".join(found)


@pytest.mark.parametrize("line", [
    # Each split inside a word, so that this file does not hold the path itself.
    'DATA = Path("/wo' + 'rk/data/tribometer_reciprocating.tsv")',
    'open("../sha' + 'red/topography/x3p-2.x3p")',
    'Path(__file__).resolve().parents[2] / "sha' + 'red" / "data"',
    '_DATA = [ROOT.parent / "sha' + 'red" / "data" / "topography"]',
    "here.parent / 'sha" + "red' / 'data'",
    'os.path.join(ROOT, "..", "sha' + 'red", "data")',
    "- the maps of sha" + "red/data/topography",
])
def test_the_search_finds_each_form_of_an_outside_path(line):
    assert outside_paths(f"x = 1\n{line}\n", "example.py") != []
    assert outside_paths(f"x = 1\n{line}\n", "example.py")[0].startswith("example.py:2: ")


@pytest.mark.parametrize("line", [
    "# The machine the figures are taken on is shared, and absolute rates vary",
    "shared = client.scatter(plan, broadcast=True, hash=False)",
    "n = 60                     # samples per 1e-5 m, so shared samples coincide",
    "path = datasets.height_map_path('x3p-2.x3p')",
])
def test_the_search_lets_other_uses_of_the_word_pass(line):
    assert outside_paths(line, "example.py") == []
