"""Height maps and memory (issue 24, causes 4, 8, 10 and 13).

* Memory is estimated before it is allocated: a ``.npy`` header, a map under
  ``--max-memory``, direct summation over sampled summits, a CSV whose first
  rows are long (cause 8).
* ``polind topography`` never prints ``inf`` or ``nan`` where a number is
  promised: heights, pixel sizes and cut-offs beyond double precision are
  exit 2 (causes 4 and 10).
* An empty or damaged map is reported for what it is; a valid single-summit
  map is drawn; a flat tilted plane has no summit, as a constant map (cause 13).
"""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from polind.cli import _run
from polind.io import sizing
from polind.resources import set_memory_limit

SAFETY = settings(max_examples=30, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(autouse=True)
def default_limit():
    yield
    set_memory_limit(None)


def topography(capsys, *args):
    status = _run(["topography", *map(str, args)])
    out, err = capsys.readouterr()
    return status, out, err


def one_error_line(err):
    """One error line, last; any line before it is a warning the run gave (each one line)."""
    lines = err.splitlines()
    assert err.endswith("\n") and lines and lines[-1].startswith("polind: error: "), err
    assert all(line.startswith("polind: warning: ") for line in lines[:-1]), err
    return lines[-1]


def rough(shape=(16, 16), seed=0):
    return np.random.default_rng(seed).normal(0.0, 1e-6, shape)


# --- memory -------------------------------------------------------------------------------

def test_a_npy_header_declaring_a_huge_map_is_refused_before_reading(tmp_path, capsys):
    path = tmp_path / "huge.npy"
    with open(path, "wb") as stream:
        np.lib.format.write_array_header_1_0(stream, {"descr": "<f8", "fortran_order": False,
                                                      "shape": (1000000, 1000000)})
        stream.write(b"\0" * 64)
    status = _run(["--max-memory", "100M", "topography", str(path), "--pixel-size", "1e-6",
                   "1e-6"])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and "1000000 x 1000000" in err and "--max-memory" in err
    # Within the limit, the header still declares more than the file holds.
    with open(path, "wb") as stream:
        np.lib.format.write_array_header_1_0(stream, {"descr": "<f8", "fortran_order": False,
                                                      "shape": (100, 100)})
        stream.write(b"\0" * 64)
    status, _, err = topography(capsys, path, "--pixel-size", 1e-6, 1e-6)
    assert status == 2 and "declares" in one_error_line(err)


def test_topography_honours_max_memory(tmp_path, capsys):
    path = tmp_path / "map.npy"
    np.save(path, rough((400, 400)))
    status = _run(["--max-memory", "1M", "topography", str(path), "--pixel-size", "1e-6",
                   "1e-6"])
    assert status == 2 and "400 x 400" in one_error_line(capsys.readouterr().err)


def test_direct_summation_over_many_summits_is_refused_before_drawing_them(tmp_path, capsys):
    model = tmp_path / "direct.toml"
    model.write_text('[model]\ntype = "pol-ind"\nnormal_load = 1.0\nstatic_coefficient = 0.15\n'
                     'kinetic_coefficient = 0.1\nstribeck_velocity = 1e-3\nattraction = 1e4\n'
                     '[model.surface]\nasperity_density = 4.9e11\nnominal_area = 1e-4\n'
                     'asperity_radius = 50e-6\nheight_std = 0.5e-6\n[model.materials]\n'
                     'youngs_modulus = [210e9, 210e9]\npoisson_ratio = [0.3, 0.3]\n'
                     '[model.discretisation]\nsummation = "direct"\n')
    status = _run(["--max-memory", "200M", "surface", str(model)])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and "4.9e+07" in err and "--max-memory" in err


@settings(max_examples=10, deadline=None, database=None)
@given(st.integers(min_value=50, max_value=400), st.integers(min_value=1, max_value=3))
def test_long_first_rows_do_not_fool_the_row_estimate(tmp_path_factory, width, digits):
    """The rows of a CSV whose first 64 KiB are long rows and the rest short ones."""
    path = tmp_path_factory.mktemp("rows") / "motion.csv"
    long_rows = (sizing.HEADER_BYTES * 2) // width
    short = "".join(f"{k % 10 ** digits},0\n" for k in range(200_000))
    with open(path, "w") as stream:
        stream.write("t,x\n" + f"{'1' * (width - 3)},0\n" * long_rows + short)
    rows, columns, exact = sizing.table_size(path)
    assert columns == 2 and not exact
    assert rows >= 0.8 * (long_rows + 200_000), rows


def test_a_big_csv_is_refused_before_it_is_read(tmp_path, capsys):
    path = tmp_path / "motion.csv"
    with open(path, "w") as stream:
        stream.write("t,x\n" + f"{'1' * 160},0\n" * 800)
        stream.write("".join(f"{k},0\n" for k in range(1000, 600_000)))
    model = tmp_path / "coulomb.toml"
    model.write_text('[model]\ntype = "coulomb"\ncoulomb_force = 1.0\n')
    status = _run(["--max-memory", "10M", "simulate", str(model), "-i", str(path), "-o",
                   str(tmp_path / "out.csv")])
    err = one_error_line(capsys.readouterr().err)
    assert status == 2 and "estimated from the size of the file" in err, err
    assert not (tmp_path / "out.csv").exists()


# --- numbers beyond double precision ------------------------------------------------------

@SAFETY
@given(st.floats(min_value=1e-320, max_value=1e308), st.floats(min_value=1e-320,
                                                               max_value=1e308),
       st.booleans())
def test_topography_json_is_finite_or_exit_2(tmp_path_factory, capsys, height, pixel, cut):
    """Any scale of heights and pixels: finite numbers in the JSON, or one line and exit 2."""
    path = tmp_path_factory.mktemp("scale") / "map.npy"
    with np.errstate(over="ignore"):          # infinite heights are among the cases
        np.save(path, rough() / 1e-6 * height)
    options = ["--short-cutoff", 4 * pixel] if cut else []
    status, out, err = topography(capsys, path, "--pixel-size", pixel, pixel, "--json",
                                  *options)
    if status == 2:
        one_error_line(err)
        return
    assert status == 0, err
    summary = json.loads(out)              # strict: NaN and Infinity are not JSON

    def numbers(value):
        if isinstance(value, dict):
            return [n for item in value.values() for n in numbers(item)]
        if isinstance(value, list):
            return [n for item in value for n in numbers(item)]
        return [value] if isinstance(value, float) else []

    assert all(math.isfinite(number) for number in numbers(summary))


@pytest.mark.parametrize("args", [
    ["--pixel-size", "1e-6", "1e-6", "--json"],
    ["--pixel-size", "1e-6", "1e-6"],
    ["--pixel-size", "1e-6", "1e-6", "--plot", "{png}"],
])
def test_heights_near_1e300_are_exit_2(tmp_path, capsys, args):
    path = tmp_path / "huge.npy"
    np.save(path, rough() * 1e306)
    status, out, err = topography(capsys, path, *[arg.format(png=tmp_path / "p.png")
                                                  for arg in args])
    assert status == 2 and "a height is" in one_error_line(err) and "inf" not in out
    assert not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("args, words", [
    (["--pixel-size", "1e-300", "1e-300"], "pixel_size"),
    (["--pixel-size", "1e-6", "1e-6", "--short-cutoff", "1e300"], "short_cutoff"),
])
def test_pixel_sizes_and_cutoffs_beyond_reason_are_exit_2(tmp_path, capsys, args, words):
    path = tmp_path / "map.npy"
    np.save(path, rough())
    status, _, err = topography(capsys, path, *args)
    assert status == 2 and words in one_error_line(err)


# --- what a map is ----------------------------------------------------------------------------

@pytest.mark.parametrize("name, content", [
    ("empty.x3p", b""), ("empty.sur", b""), ("empty.txt", b""),
    ("random.sur", bytes(np.random.default_rng(1).integers(0, 256, 300, dtype=np.uint8))),
])
def test_an_empty_or_damaged_map_is_reported_for_what_it_is(tmp_path, capsys, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    status, _, err = topography(capsys, path)
    err = one_error_line(err)
    assert status == 2 and name in err and "no length unit" not in err, err
    assert path.read_bytes() == content


def test_a_single_summit_map_is_drawn(tmp_path, capsys):
    x = (np.arange(9) - 4) * 1e-6
    cap = np.maximum(0.0, 1e-7 - (x[:, None] ** 2 + x[None, :] ** 2) / (2 * 20e-6))
    path = tmp_path / "cap.npy"
    np.save(path, cap)
    status, out, err = topography(capsys, path, "--pixel-size", 1e-6, 1e-6, "--plot",
                                  tmp_path / "cap.png")
    assert status == 0 and err == "", err
    assert (tmp_path / "cap.png").read_bytes().startswith(b"\x89PNG")


@settings(max_examples=25, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.floats(min_value=-1e-3, max_value=1e-3), st.floats(min_value=-1.0, max_value=1.0),
       st.floats(min_value=-1.0, max_value=1.0), st.integers(min_value=3, max_value=40))
def test_a_flat_plane_has_no_summit_tilted_or_not(tmp_path_factory, capsys, offset, slope_x,
                                                  slope_y, size):
    i, j = np.meshgrid(np.arange(size), np.arange(size + 1), indexing="ij")
    path = tmp_path_factory.mktemp("plane") / "plane.npy"
    np.save(path, offset + slope_x * i * 1e-6 + slope_y * j * 1e-6)
    status, _, err = topography(capsys, path, "--pixel-size", 1e-6, 1e-6, "--json")
    assert status == 2 and "no summit" in one_error_line(err), err


def test_a_plot_appears_only_once_the_summary_is_printed(tmp_path, capsys, monkeypatch):
    """Cause 14 for topography: standard output full, and no figure file either."""
    from test_safety_outputs import FullStream

    path = tmp_path / "map.npy"
    np.save(path, rough())
    monkeypatch.setattr("sys.stdout", FullStream())
    status = _run(["topography", str(path), "--pixel-size", "1e-6", "1e-6", "--plot",
                   str(tmp_path / "p.png")])
    assert status == 2 and "standard output" in one_error_line(capsys.readouterr().err)
    assert sorted(os.listdir(tmp_path)) == ["map.npy"]


def test_the_fixtures_are_left_as_they_were(tmp_path, capsys):
    """Every refusal above leaves its map byte-identical (checked here once for a plot)."""
    path = tmp_path / "plane.npy"
    np.save(path, np.add.outer(np.arange(8.0), np.arange(8.0)) * 1e-7)
    before = path.read_bytes()
    status, _, _ = topography(capsys, path, "--pixel-size", 1e-6, 1e-6, "--plot",
                              tmp_path / "p.png")
    assert status == 2 and path.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["plane.npy"]
