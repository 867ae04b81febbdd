"""Height maps and contacts (issue 44: four causes of the surfaces).

* Random bytes under any extension a height map may have are "not a height
  map", never read as another format (a NASA SRTM tile is any file of
  ``2 n^2`` bytes).
* A map scaled by 1e-300 is refused with the range analysed, not reported
  with an rms height of 0 beside its summits.
* Every option of ``polind topography`` is checked before the map is read.
* A direct-summation Pol-Ind contact whose load no summit can carry in
  double precision is refused naming the load, constant or varying.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import polind
from polind.cli import _run
from polind.contact import solve_separation
from polind.contact.surface import DirectSurface
from polind.errors import InputError
from polind.topography import analyse
from polind.topography.heightmap import SMALLEST_HEIGHT, HeightMap, read_height_map

from model_files import direct_pol_ind

SAFETY = settings(max_examples=25, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture,
                                         HealthCheck.too_slow])


def _extensions():
    """Every file extension polind reads a height map from: SurfaceTopography's and its own."""
    from SurfaceTopography.IO import readers

    found = {"npy", "csv"}
    for reader in readers:
        found.update(extension.lower() for extension in reader.file_extensions() or ())
    return sorted(found)


EXTENSIONS = _extensions()


def _formats_of(extension):
    """The names SurfaceTopography's formats of that extension go by in a message."""
    from SurfaceTopography.IO import readers

    return [f"{reader.name()} ({reader.format()})" for reader in readers
            if extension in [e.lower() for e in reader.file_extensions() or ()]]


# --- cause 1: random bytes are not a height map ----------------------------------------------

def test_5000_random_bytes_named_x3p_are_not_a_height_map(tmp_path):
    path = tmp_path / "x.x3p"
    path.write_bytes(np.random.default_rng(44).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    with pytest.raises(InputError) as error:
        read_height_map(path)
    message = str(error.value)
    assert message.startswith(f"{path}: ") and "not a height map" in message, message
    assert "SRTM" not in message and "no length unit" not in message, message
    assert "expected a height map" in message and "\n" not in message


@SAFETY
@given(extension=st.sampled_from(EXTENSIONS),
       content=st.one_of(st.binary(min_size=1, max_size=6000),
                         st.sampled_from([50, 60, 100]).map(
                             lambda n: np.random.default_rng(n).integers(
                                 0, 256, 2 * n * n, dtype=np.uint8).tobytes())))
def test_random_bytes_under_every_extension_are_refused_for_what_they_are(
        tmp_path_factory, extension, content):
    """One line naming the file; never a format other than one its name gives."""
    path = tmp_path_factory.mktemp("garbage") / f"g.{extension}"
    path.write_bytes(content)
    grid = extension in ("npy", "csv")
    try:
        read_height_map(path, pixel_size=(1e-6, 1e-6) if grid else None)
    except InputError as error:
        message = str(error)
    else:  # random bytes are never a height map polind can use
        pytest.fail(f"{path} ({len(content)} random bytes) was read as a height map")
    assert message.startswith(f"{path}: ") and "\n" not in message and "expected" in message
    claims = [f"{path}: read as ", "not a height map: read as "]   # the format it was taken for
    for claim in claims:
        if claim not in message:
            continue
        taken = message.split(claim, 1)[1]
        assert any(taken.startswith(name) for name in _formats_of(extension)), message
    if extension == "hgt" and "no length unit" in message:
        return                # any 2 n^2 bytes are an SRTM tile, which gives no unit
    if extension == "csv" and ("not a number" in message or "values; expected" in message
                               or "holds no heights" in message):
        return                # text that decodes: the cell or row that is wrong is named,
                              # or whitespace alone: a grid without heights
    assert "not a height map" in message, message


def test_a_real_map_misnamed_is_still_read_by_its_signature(tmp_path):
    """A Digital Surf file named .x3p or with no extension: its content's signature decides."""
    source = polind.datasets.height_map_path("sur-2.sur").read_bytes()
    for name in ("misnamed.x3p", "no_extension"):
        (tmp_path / name).write_bytes(source)
        assert read_height_map(tmp_path / name).grid == (563, 484)


# --- cause 2: heights beyond double precision's squares ----------------------------------------

@given(st.floats(min_value=1e-320, max_value=1e-101))
@settings(max_examples=15, deadline=None, database=None)
def test_a_map_scaled_below_1e_100_is_refused_with_the_range(scale):
    heights = np.random.default_rng(3).normal(size=(20, 20))
    heights /= np.max(np.abs(heights))
    surface_map = HeightMap.from_array(heights * scale, (1e-6, 1e-6), "tiny.npy")
    with pytest.raises(InputError, match=r"^tiny\.npy: the largest height .* from 1e-100 to "
                                         r"1e\+100 m"):
        analyse(surface_map, warn=False)


def test_a_map_at_the_smallest_height_is_analysed_as_in_metres():
    """Scale invariance: the map at 1e-100 m gives the statistics of the map at 1e-6 m, scaled."""
    heights = np.random.default_rng(3).normal(size=(20, 20))
    heights /= np.max(np.abs(heights))
    small = analyse(HeightMap.from_array(heights * SMALLEST_HEIGHT, (1e-6, 1e-6)), warn=False)
    usual = analyse(HeightMap.from_array(heights * 1e-6, (1e-6, 1e-6)), warn=False)
    assert small.summits == usual.summits > 0
    assert small.rms_height / SMALLEST_HEIGHT == pytest.approx(usual.rms_height / 1e-6, rel=1e-12)
    got, want = small.summary(), usual.summary()
    for key in ("Sq", "Sdq", "rms_curvature"):
        assert got["roughness"][key] / SMALLEST_HEIGHT == pytest.approx(
            want["roughness"][key] / 1e-6, rel=1e-9), key


def test_a_statistic_that_underflows_through_the_pixel_size_is_refused_by_name():
    heights = np.random.default_rng(3).normal(size=(20, 20)) * 1e-90
    surface = analyse(HeightMap.from_array(heights, (1e100, 1e100), "wide.npy"), warn=False)
    with pytest.raises(InputError, match=r"^wide\.npy: its roughness\.Sdq is 0\.0 \(below double"):
        surface.summary()


# --- cause 3: options before analysis --------------------------------------------------------

@pytest.mark.parametrize("options, words", [
    (["--hardness", "-2e9", "--effective-modulus", "1e11"], "'hardness' parameter"),
    (["--hardness", "2e9", "--effective-modulus", "-1e11"], "'effective_modulus' parameter"),
    (["--effective-modulus", "0", "--plot", "{png}"], "'effective_modulus' parameter"),
    (["--short-cutoff", "1e-7"], "twice the smaller pixel spacing"),
    (["--hardness", "nan", "--effective-modulus", "1e11"], "'hardness' parameter"),
])
def test_every_option_is_refused_before_the_map_is_read(tmp_path, capsys, monkeypatch, options,
                                                        words):
    import polind.topography as measured

    def no_analysis(*args, **kwargs):
        raise AssertionError("the map was read and analysed before the options were checked")

    monkeypatch.setattr(measured, "load_measured_surface", no_analysis)
    monkeypatch.setattr(measured, "read_height_map", no_analysis)
    path = tmp_path / "map.npy"
    np.save(path, np.random.default_rng(0).normal(0.0, 1e-6, (16, 16)))
    arguments = [option.format(png=tmp_path / "p.png") for option in options]
    status = _run(["topography", str(path), "--pixel-size", "1e-6", "1e-6", *arguments])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and words in err, err
    assert sorted(os.listdir(tmp_path)) == ["map.npy"]


def test_the_library_checks_the_hardness_before_the_statistics(monkeypatch):
    heights = np.random.default_rng(3).normal(size=(20, 20)) * 1e-6
    surface = analyse(HeightMap.from_array(heights, (1e-6, 1e-6)), warn=False)
    monkeypatch.setattr(type(surface), "cutoff_study", property(lambda self: 1 / 0))
    with pytest.raises(InputError, match="'hardness' parameter of topography must be positive"):
        surface.summary(effective_modulus=1e11, hardness=-2e9)


# --- cause 4: a direct contact that no summit carries ----------------------------------------

def _direct_model(tmp_path, normal_load):
    heights = np.random.default_rng(0).normal(scale=0.5e-6, size=200)
    (tmp_path / "summits.csv").write_text("h\n" + "".join(f"{float(h)!r}\n" for h in heights))
    model = tmp_path / "direct.toml"
    model.write_text(direct_pol_ind(
        heights_file="summits.csv", normal_load=normal_load,
        model_lines="stribeck_exponent = 2.0\nviscous_coefficient = 0.0\n"))
    return model


def test_a_load_no_summit_carries_is_refused_naming_it(tmp_path, capsys):
    model = _direct_model(tmp_path, 1e-30)
    status = _run(["surface", str(model), "--json"])
    out, err = capsys.readouterr()
    assert status == 2 and out == "" and err.count("\n") == 1, err
    assert "'normal_load'" in err and "1e-30 N" in err and "no summit would be in contact" in err
    with pytest.raises(InputError, match=r"too small for its summits.*expected at least"):
        polind.load_model(model).step_kernel()


def test_a_varying_load_through_no_contact_is_refused_at_its_sample(tmp_path):
    model = polind.load_model(_direct_model(tmp_path, 1.0))
    t = np.linspace(0.0, 0.01, 5)
    with pytest.raises(InputError, match=r"no asperity would be in contact.*index 2"):
        polind.simulate(model, t, x=1e-9 * t, normal_load=[1.0, 0.5, 1e-30, 1e-30, 1.0])


@settings(max_examples=40, deadline=None, database=None)
@given(heights=st.lists(st.floats(-1e-5, 1e-5), min_size=1, max_size=20),
       exponent=st.floats(-40.0, 2.0))
def test_every_load_accepted_puts_a_summit_in_contact(heights, exponent):
    """Below the smallest load the solve refuses; from it on, the highest summit touches."""
    surface = DirectSurface(heights, 50e-6, 1.15e11, 2.4e10)
    load = 10.0 ** exponent
    smallest = surface.smallest_load
    assert surface.load_range[0] == smallest and math.isfinite(smallest)
    if load < smallest:
        with pytest.raises(InputError, match="too small for its summits"):
            solve_separation(surface, load)
        return
    d = solve_separation(surface, load)
    assert d < surface.heights[-1] and surface.contacts(d) >= 1.0
