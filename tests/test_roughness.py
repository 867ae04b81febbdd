"""Measured maps conditioned and described as a metrologist would (issue 22, items 3 and 4).

Outliers, line-by-line levelling, the height channel, the cut-off limits, the
white-noise warning, the standard roughness figures, the power spectral
density, the cut-off study and the plasticity index.

References, each independent of the code under test:
- analytic sums for a sampled sine ``A sin(2 pi x / lambda)`` with whole
  periods on the grid: ``Sq``, ``Sa`` (``sum |sin| = 2 cot(pi / N)`` per period
  of ``N`` points), ``Ssk = 0``, ``Sku`` (``mean sin^4 = 3/8``), the two-point
  slope ``(2 A / dx) sin(pi dx / lambda)`` and the three-point curvature
  ``A (2 sin(pi dx / lambda) / dx)^2``, their rms over the points each stencil
  reaches;
- SurfaceTopography's own reading and analysis of the shipped maps
  (``open_topography(...).topography().detrend("height")`` and its ``Sq``,
  ``rms_gradient``, ``rms_curvature_from_area``), and ``scipy.stats`` for the
  skewness and kurtosis;
- a plain outlier rule written here (``numpy.linalg.lstsq`` plane, median and
  median absolute deviation, repeated) and spikes injected at known points;
- the 8-neighbour summit rule: removing points can only remove the summits
  whose 3 x 3 block holds one of them;
- independent runs of :func:`polind.topography.analyse` per cut-off.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from scipy import ndimage, stats

from polind import datasets
from polind.errors import InputError
from polind.topography import (HeightMap, analyse, cutoff_study, find_outliers, level_lines,
                               load_measured_surface, power_spectrum, read_height_map,
                               standard_roughness)
from polind.topography.analysis import NEAR_WHITE_NOISE, default_cutoffs
from polind.topography.outliers import MAD_TO_STD, OUTLIER_THRESHOLD
from polind.topography_figure import figure_png
from test_topography import gaussian_field, one_error_line, run

#: The keys INTERFACE.md lists for ``polind topography --json``.
INTERFACE_KEYS = {"grid", "pixel_size", "valid_points", "rms_height", "summits",
                  "summit_density", "summit_radius_mean", "summit_radius_median",
                  "summit_height_std", "greenwood_williamson", "roughness", "channel",
                  "outliers", "cutoff_study"}
ROUGHNESS = {"Sa", "Sq", "Ssk", "Sku", "Sdq", "rms_curvature"}


@pytest.fixture(scope="module")
def shipped():
    """The two shipped maps as read (no analysis)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return {name: datasets.height_map(name) for name in datasets.HEIGHT_MAPS}


def with_spikes(height_map, share, low, high, seed):
    """The map with ``share`` of its valid points raised or lowered by ``low..high`` times its rms."""
    rng = np.random.default_rng(seed)
    heights = height_map.heights.copy()
    valid = np.flatnonzero(~np.isnan(heights))
    chosen = rng.choice(valid, int(round(share * valid.size)), replace=False)
    rms = np.nanstd(heights)
    heights.ravel()[chosen] += rng.choice([-1.0, 1.0], chosen.size) * rng.uniform(
        low, high, chosen.size) * rms
    mask = np.zeros(heights.shape, dtype=bool)
    mask.ravel()[chosen] = True
    return HeightMap(heights, height_map.pixel_size, "spiky"), mask


# --- standard roughness: analytic cases --------------------------------------------------------

def test_roughness_of_a_sampled_sine_is_the_analytic_sums():
    A, wavelength, dx, N = 2e-8, 4e-6, 1e-7, 40      # 40 points per period
    n = 10 * N + 1                                   # 10 periods: 400 differences
    k = 2 * math.pi / wavelength
    heights = A * np.sin(k * np.arange(n) * dx)[:, None] * np.ones(30)
    r = standard_roughness(HeightMap.from_array(heights, (dx, 2e-7)))
    assert set(r) == ROUGHNESS
    # Over the 401 points: 10 whole periods and one more zero.
    assert r["Sq"] == pytest.approx(A * math.sqrt(200 / 401), rel=1e-12)
    assert r["Sa"] == pytest.approx(A * 10 * 2 / math.tan(math.pi / N) / 401, rel=1e-12)
    assert abs(r["Ssk"]) < 1e-12
    assert r["Sku"] == pytest.approx((3 / 8 * 400 / 401) / (200 / 401) ** 2, rel=1e-12)
    # Two-point slope over the 400 differences (whole periods): rms = amplitude / sqrt 2.
    slope = (2 * A / dx) * math.sin(k * dx / 2)
    assert r["Sdq"] == pytest.approx(slope / math.sqrt(2), rel=1e-12)
    # Three-point curvature at the 399 interior points: sum of sin^2 is 200.
    curvature = A * (2 * math.sin(k * dx / 2) / dx) ** 2
    assert r["rms_curvature"] == pytest.approx(0.5 * curvature * math.sqrt(200 / 399), rel=1e-12)


def test_roughness_of_an_egg_box_has_both_slopes():
    A, N, d = 1e-8, 16, 0.5e-6
    n = 8 * N + 1
    phase = 2 * math.pi * np.arange(n) / N
    heights = A * np.sin(phase)[:, None] * np.sin(phase)[None, :]
    r = standard_roughness(HeightMap.from_array(heights, (d, d)))
    assert r["Sq"] == pytest.approx(A * (64 / n), rel=1e-12)     # mean sin^2 sin^2 over n^2
    assert abs(r["Ssk"]) < 1e-12
    # The continuous rms slope sqrt(<h_x^2 + h_y^2>) = A k / sqrt 2, to the stencil's order.
    assert r["Sdq"] == pytest.approx(A * 2 * math.pi / (N * d) / math.sqrt(2), rel=0.02)


# --- standard roughness: SurfaceTopography's own numbers ----------------------------------------

@pytest.mark.parametrize("name", datasets.HEIGHT_MAPS)
def test_roughness_of_the_shipped_maps_is_surface_topographys(name):
    import SurfaceTopography

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        own = SurfaceTopography.open_topography(
            str(datasets.height_map_path(name))).topography().to_unit("m").detrend("height")
        surface = load_measured_surface(datasets.height_map_path(name))
    r = surface.roughness
    assert r["Sq"] == pytest.approx(own.Sq(), rel=1e-9)
    assert r["Sq"] == pytest.approx(surface.rms_height, rel=1e-9)
    if own.has_undefined_data:
        # Next to a missing point SurfaceTopography's linear interpolation drops differences
        # depending on how the positions round (its pipeline object and a plain Topography of
        # the same heights differ by 2 % on sur-2.sur): compare on a plain one.
        own = SurfaceTopography.Topography(own.heights(), own.physical_sizes, unit="m",
                                           periodic=False)
    assert r["Sdq"] == pytest.approx(own.rms_gradient(), rel=1e-9)
    assert r["rms_curvature"] == pytest.approx(own.rms_curvature_from_area(), rel=1e-9)
    valid = surface.heights[~np.isnan(surface.heights)]
    assert r["Sa"] == pytest.approx(np.mean(np.abs(valid - valid.mean())), rel=1e-9)
    assert r["Ssk"] == pytest.approx(stats.skew(valid), rel=1e-9)
    assert r["Sku"] == pytest.approx(stats.kurtosis(valid, fisher=False), rel=1e-9)


def test_power_spectrum_of_a_sine_peaks_at_its_wavevector():
    d, N = 0.25e-6, 32
    phase = 2 * math.pi * np.arange(512) / N
    heights = 1e-8 * np.sin(phase)[:, None] * np.ones(512)
    heights += 1e-11 * np.random.default_rng(0).standard_normal(heights.shape)
    q, C, filled = power_spectrum(HeightMap.from_array(heights, (d, d)))
    assert not filled and np.all(q > 0) and np.all(C > 0)
    assert q[np.argmax(C)] == pytest.approx(2 * math.pi / (N * d), rel=0.15)


def test_power_spectrum_fills_missing_points_first(shipped):
    q, C, filled = power_spectrum(shipped["sur-2.sur"])
    assert filled and q.size > 10 and np.all(np.isfinite(C))


# --- outliers ----------------------------------------------------------------------------------

def plain_outliers(heights, pixel_size, k=OUTLIER_THRESHOLD):
    """The rule of polind.topography.outliers, written plainly: lstsq plane, median, MAD."""
    nx, ny = heights.shape
    X, Y = np.meshgrid(np.arange(nx) * pixel_size[0], np.arange(ny) * pixel_size[1],
                       indexing="ij")
    outliers = np.zeros(heights.shape, dtype=bool)
    while True:
        fit = ~np.isnan(heights) & ~outliers
        design = np.column_stack([np.ones(fit.sum()), X[fit], Y[fit]])
        (a, b, c), *_ = np.linalg.lstsq(design, heights[fit], rcond=None)
        residual = heights - (a + b * X + c * Y)
        centre = np.median(residual[fit])
        scale = 1.4826 * np.median(np.abs(residual[fit] - centre))
        new = fit & (np.abs(residual - centre) > k * scale)
        if not new.any():
            return outliers
        outliers |= new


def test_outliers_follow_the_plain_rule_on_a_tilted_map_with_spikes():
    rng = np.random.default_rng(3)
    nx, ny, d = 120, 90, 1e-6
    heights = 5e-8 * rng.standard_normal((nx, ny))
    heights += 2e-3 * np.arange(nx)[:, None] * d - 1e-3 * np.arange(ny)[None, :] * d
    heights[rng.integers(0, nx, 40), rng.integers(0, ny, 40)] -= 6e-6   # deep spikes tilt the plane
    heights[5, 7] += 3e-7                                               # a 6-sigma point: kept
    heights[rng.integers(0, nx, 30), rng.integers(0, ny, 30)] = np.nan
    found = find_outliers(heights, (d, d))
    assert np.array_equal(found, plain_outliers(heights, (d, d)))
    assert found.sum() >= 35 and not found[5, 7] and not found[np.isnan(heights)].any()
    assert MAD_TO_STD == pytest.approx(1 / stats.norm.ppf(0.75), rel=1e-12)


def test_a_gaussian_surface_has_no_outlier():
    heights, _, _ = gaussian_field(256, (1e-6, 1e-6), 3e-6, 1e-7, seed=5)
    assert not find_outliers(heights, (1e-6, 1e-6)).any()


@pytest.mark.parametrize("amplitude", [(20, 200), (10, 30)])
def test_injected_spikes_are_found_warned_about_and_removed(shipped, amplitude):
    clean_map = shipped["x3p-2.x3p"]
    clean = analyse(clean_map, warn=False)
    spiky, injected = with_spikes(clean_map, 0.005, *amplitude, seed=7)
    with pytest.warns(UserWarning, match=r"left in.*--remove-outliers"):
        kept = analyse(spiky)
    found = np.zeros(injected.shape, dtype=bool)
    found[kept.outlier_index] = True
    assert clean.outliers == 0
    assert (found & ~injected).sum() == 0                        # nothing of the clean map
    assert kept.rms_height > 1.7 * clean.rms_height and kept.summits > 1.3 * clean.summits
    with warnings.catch_warnings():
        warnings.simplefilter("error")                          # removed: no warning
        removed = analyse(spiky, remove_outliers=True)
    assert removed.outliers == kept.outliers and removed.outliers_removed
    assert removed.valid_points == clean.valid_points - removed.outliers
    # A spike that lands in a valley can stay within 8 s of the median (2 of 2112 at 10-30
    # times the rms): it stays, and its slopes are in Sdq (+3 %); heights are not affected.
    missed = int((injected & ~found).sum())
    assert missed == 0 if amplitude[0] >= 20 else missed <= 0.002 * injected.sum()
    for key in ("Sq", "Sa", "Sdq") if not missed else ("Sq", "Sa"):
        assert removed.roughness[key] == pytest.approx(clean.roughness[key], rel=0.02), key
    assert removed.rms_height == pytest.approx(clean.rms_height, rel=0.02)
    # Summits: exactly the clean ones whose 3 x 3 block keeps all its points (the 8-neighbour
    # rule cannot make a summit next to a missing point), so per point that can be a summit
    # the density is the clean map's.
    near = ndimage.binary_dilation(found, np.ones((3, 3), dtype=bool))
    i, j = clean.summit_index
    expected = set(zip(i[~near[i, j]].tolist(), j[~near[i, j]].tolist()))
    got = set(zip(*(index.tolist() for index in removed.summit_index)))
    assert len(got ^ expected) <= missed                        # each can make or hide one
    per_candidate = removed.summits / removed.summit_candidates
    assert per_candidate == pytest.approx(clean.summits / clean.summit_candidates, rel=0.02)
    if not missed:        # one spike left on a summit can change 1 / mean(kappa) by 8 %
        assert removed.summit_radius_mean == pytest.approx(clean.summit_radius_mean, rel=0.02)


def test_the_sur_map_has_its_own_outliers_and_removing_them_restores_its_statistics(shipped):
    kept = analyse(shipped["sur-2.sur"], warn=False)
    removed = analyse(shipped["sur-2.sur"], remove_outliers=True, warn=False)
    assert kept.outliers == removed.outliers == 100
    assert kept.roughness["Sku"] > 100 and removed.roughness["Sku"] < 4
    assert removed.roughness["Sq"] < 0.85 * kept.roughness["Sq"]
    assert kept.summits - removed.summits < 0.01 * kept.summits


# --- line-by-line levelling ------------------------------------------------------------------

def test_line_levelling_removes_scan_line_offsets_and_tilts_that_a_plane_leaves():
    rng = np.random.default_rng(11)
    heights, _, _ = gaussian_field(128, (1e-8, 1e-8), 8e-8, 1e-9, seed=2)
    x = np.arange(128)[:, None] / 128
    lines = 5e-9 * rng.standard_normal(128)[None, :] + 3e-9 * rng.standard_normal(128)[None, :] * x
    scanned = heights + lines
    scanned[40:44, 60] = np.nan
    scanned[:, 90] = np.nan                                   # a lost scan line
    by_lines = level_lines(scanned, (1e-8, 1e-8))
    assert np.array_equal(np.isnan(by_lines), np.isnan(scanned))
    true_rms = np.std(heights)
    assert np.sqrt(np.nanmean(by_lines**2)) == pytest.approx(true_rms, rel=0.15)
    by_plane = analyse(HeightMap(scanned, (1e-8, 1e-8), "afm"), warn=False)
    assert by_plane.rms_height > 2 * true_rms
    by_line = analyse(HeightMap(scanned, (1e-8, 1e-8), "afm"), levelling="lines", warn=False)
    assert by_line.levelling == "lines"
    assert by_line.rms_height == pytest.approx(np.sqrt(np.nanmean(by_lines**2)), rel=1e-12)
    with pytest.raises(InputError, match="'levelling'.*'plane', 'lines'"):
        analyse(HeightMap(scanned, (1e-8, 1e-8), "afm"), levelling="rows")


# --- the channel -------------------------------------------------------------------------------

def write_two_channel_gwy(path, first, second):
    """A Gwyddion file with channels 'Height' and 'ZSensor' (m), through SurfaceTopography's writer."""
    from SurfaceTopography.IO.GWY import _gwy_write_object   # its GWY writer's object encoder

    def field(heights):
        nx, ny = heights.shape
        unit = ("o", ("GwySIUnit", {"unitstr": ("s", "m")}))
        return ("o", ("GwyDataField", {
            "xres": ("i", nx), "yres": ("i", ny), "xreal": ("d", nx * 1e-6),
            "yreal": ("d", ny * 1e-6), "xoff": ("d", 0.0), "yoff": ("d", 0.0),
            "si_unit_xy": unit, "si_unit_z": unit,
            "data": ("D", heights.T.astype("<f8").ravel())}))

    container = {"/0/data/title": ("s", "Height"), "/0/data": field(first),
                 "/1/data/title": ("s", "ZSensor"), "/1/data": field(second)}
    with open(path, "wb") as handle:
        handle.write(b"GWYP")
        _gwy_write_object(handle, "GwyContainer", container)


@pytest.fixture
def two_channels(tmp_path):
    heights, _, _ = gaussian_field(48, (1e-6, 1e-6), 3e-6, 1e-8, seed=1)
    path = tmp_path / "afm.gwy"
    write_two_channel_gwy(path, heights, 3.0 * heights)
    return path, heights


def test_the_channel_is_named_and_can_be_chosen(two_channels):
    path, heights = two_channels
    default = read_height_map(path)
    assert default.channel == "Height"
    np.testing.assert_allclose(default.heights, heights, rtol=1e-12)
    other = read_height_map(path, channel="ZSensor")
    assert other.channel == "ZSensor"
    np.testing.assert_allclose(other.heights, 3.0 * heights, rtol=1e-12)
    with pytest.raises(InputError, match=r"no channel 'Phase'.*'Height' \(height, m\), "
                                         r"'ZSensor' \(height, m\)"):
        read_height_map(path, channel="Phase")


def test_cli_names_the_channel_and_refuses_an_unknown_one(capsys, two_channels, tmp_path):
    path, _ = two_channels
    status, out, err = run(capsys, "topography", path, "--json", "--channel", "ZSensor")
    assert status == 0, err
    assert json.loads(out)["channel"] == "ZSensor"
    status, out, err = run(capsys, "topography", path)
    assert status == 0 and "channel            Height" in out
    status, out, err = run(capsys, "topography", path, "--channel", "Phase")
    assert status == 2 and out == ""
    one_error_line(err, str(path), "no channel 'Phase'", "'Height'", "'ZSensor'")
    grid = tmp_path / "grid.npy"
    np.save(grid, np.random.default_rng(0).normal(size=(8, 8)) * 1e-9)
    status, out, err = run(capsys, "topography", grid, "--pixel-size", "1e-6", "1e-6",
                           "--channel", "Height")
    assert status == 2
    one_error_line(err, str(grid), "one channel")


# --- the cut-off -------------------------------------------------------------------------------

def test_a_cutoff_under_two_pixels_is_refused_and_two_pixels_accepted(shipped):
    x3p = shipped["x3p-2.x3p"]
    shortest = 2 * min(x3p.pixel_size)
    with pytest.raises(InputError, match=r"'short_cutoff'.*at least twice the smaller pixel"):
        analyse(x3p, short_cutoff=0.99 * shortest)
    assert analyse(x3p, short_cutoff=shortest, warn=False).short_cutoff == shortest


def test_cli_refuses_an_over_fine_cutoff(capsys):
    path = datasets.height_map_path("sur-2.sur")
    status, out, err = run(capsys, "topography", path, "--short-cutoff", "5e-6")
    assert status == 2 and out == ""
    one_error_line(err, str(path), "short_cutoff", "6.968e-06 m")


def test_the_cutoff_study_is_analyse_at_each_cutoff(shipped):
    x3p = shipped["x3p-2.x3p"]
    surface = analyse(x3p, short_cutoff=1e-6, warn=False)
    rows = surface.cutoff_study
    assert rows[0]["short_cutoff"] is None
    assert rows[0]["summits"] == analyse(x3p, warn=False).summits        # before the low-pass
    cutoffs = [row["short_cutoff"] for row in rows[1:]]
    assert cutoffs == default_cutoffs(x3p.pixel_size, x3p.grid)
    assert cutoffs[0] == 2 * min(x3p.pixel_size) and len(cutoffs) == 6
    for row in rows[1:]:
        each = analyse(x3p, short_cutoff=row["short_cutoff"], warn=False)
        assert row["summits"] == each.summits
        assert row["summit_radius_mean"] == pytest.approx(each.summit_radius_mean, rel=1e-12)
    counts = [row["summits"] for row in rows]
    assert counts == sorted(counts, reverse=True)              # fewer summits, longer cut-off
    assert cutoff_study(surface, [4e-6])[1]["summits"] == analyse(x3p, 4e-6, warn=False).summits


# --- the white-noise warning ---------------------------------------------------------------------

def test_summits_near_the_white_noise_rate_warn():
    noise = np.random.default_rng(2).standard_normal((200, 200)) * 1e-9
    with pytest.warns(UserWarning, match=r"white-noise rate"):
        surface = analyse(HeightMap(noise, (1e-6, 1e-6), "noise"))
    assert surface.white_noise_share == pytest.approx(1.0, abs=0.05)
    smooth, _, _ = gaussian_field(200, (1e-6, 1e-6), 5e-6, 1e-9, seed=3)
    quiet = analyse(HeightMap(smooth, (1e-6, 1e-6), "smooth"), warn=False)
    assert quiet.white_noise_share < NEAR_WHITE_NOISE and not quiet.warnings
    # A low-pass of a few pixels takes the noise map away from the white-noise rate.
    filtered = analyse(HeightMap(noise, (1e-6, 1e-6), "noise"), short_cutoff=6e-6, warn=False)
    assert filtered.white_noise_share < NEAR_WHITE_NOISE


# --- the command line: keys, plasticity index, figure --------------------------------------------

def test_cli_json_has_every_interface_key_on_both_shipped_maps(capsys):
    for name in datasets.HEIGHT_MAPS:
        path = datasets.height_map_path(name)
        status, out, err = run(capsys, "topography", path, "--json", "--hardness", "2e9",
                               "--effective-modulus", "1.154e11")
        assert status == 0, err
        summary = json.loads(out, parse_constant=lambda c: pytest.fail(f"non-strict JSON {c}"))
        assert INTERFACE_KEYS <= set(summary)
        assert set(summary["roughness"]) == ROUGHNESS
        assert summary["channel"] == "Default"
        assert all(set(row) == {"short_cutoff", "summits", "summit_radius_mean"}
                   for row in summary["cutoff_study"])
        gw = summary["greenwood_williamson"]
        assert summary["plasticity_index"] == pytest.approx(
            1.154e11 / 2e9 * math.sqrt(gw["height_std"] / gw["asperity_radius"]), rel=1e-12)
    assert summary["outliers"] == 100 and len(summary["warnings"]) == 2   # sur-2.sur
    status, out, err = run(capsys, "topography", path, "--json", "--remove-outliers")
    assert json.loads(out)["outliers"] == 100 and json.loads(out)["outliers_removed"]


def test_cli_hardness_needs_the_modulus(capsys):
    path = datasets.height_map_path("x3p-2.x3p")
    status, out, err = run(capsys, "topography", path, "--hardness", "2e9")
    assert status == 2 and out == ""
    one_error_line(err, "--hardness", "--effective-modulus")


def test_the_figure_draws_outliers_left_in_and_the_new_panels(shipped):
    spiky, _ = with_spikes(shipped["x3p-2.x3p"], 0.005, 20, 200, seed=1)
    png = figure_png(analyse(spiky, short_cutoff=1e-6, warn=False), dpi=40)
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
