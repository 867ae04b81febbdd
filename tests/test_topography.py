"""Measured surfaces (MODELS.md 7.8): reading, levelling, low-pass, summits, radii, the CLI.

References, each independent of the code under test:
- planted paraboloid caps: central differences are exact on a quadratic, so
  every cap's radius comes back to 1e-9 relative and the count is exact;
- a plain-Python loop over the 8 neighbours on random small grids full of
  ties and missing points (the summit definition, read literally);
- least squares by ``numpy.linalg.lstsq`` for the mean plane;
- the ISO 16610-61 transfer function ``exp(-pi (alpha lc / lambda)^2)``;
- Nayak (1971) for an isotropic Gaussian random surface: summit density
  ``m4 / (6 pi sqrt(3) m2)`` and mean summit curvature ``(8/3) sqrt(m4/pi)``
  (both over summits of all heights, so independent of the bandwidth);
- the two measured maps of :mod:`polind.datasets` and their README.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from scipy import integrate

from polind import cli, datasets
from polind.errors import InputError
from polind.topography import (HeightMap, analyse, find_summits, level,
                               load_measured_surface, low_pass, mean_plane, read_height_map,
                               summit_curvatures)
from polind.topography_figure import direct_normal_load, figure_png, statistical_normal_load


#: The keys INTERFACE.md lists for ``polind topography --json``.
JSON_KEYS = {"grid", "pixel_size", "valid_points", "rms_height", "summits", "summit_density",
             "summit_radius_mean", "summit_radius_median", "summit_height_std",
             "greenwood_williamson", "roughness", "channel", "outliers", "cutoff_study"}


# --- helpers -------------------------------------------------------------------------------

def reference_summits(h):
    """The definition read literally: interior, 8 valid neighbours, strictly higher than each."""
    found = []
    nx, ny = h.shape
    for i in range(1, nx - 1):
        for j in range(1, ny - 1):
            if math.isnan(h[i, j]):
                continue
            neighbours = [h[i + di, j + dj] for di in (-1, 0, 1) for dj in (-1, 0, 1)
                          if (di, dj) != (0, 0)]
            if all(not math.isnan(value) and h[i, j] > value for value in neighbours):
                found.append((i, j))
    return found


def gaussian_field(n, pixel_size, correlation_length, rms, seed):
    """An isotropic Gaussian random surface, periodic on the grid, ACF exp(-r^2/l^2).

    Returns the heights and the ensemble spectral moments ``m2 = <h_x^2>`` and
    ``m4 = <h_xx^2>`` of the surface (sums over the discrete spectrum used).
    """
    rng = np.random.default_rng(seed)
    dx, dy = pixel_size
    qx = 2 * np.pi * np.fft.fftfreq(n, dx)
    qy = 2 * np.pi * np.fft.fftfreq(n, dy)
    spectrum = np.exp(-(qx[:, None] ** 2 + qy[None, :] ** 2) * correlation_length**2 / 4)
    spectrum *= rms**2 / spectrum.sum()
    noise = np.fft.fft2(rng.standard_normal((n, n)))
    heights = np.fft.ifft2(noise * np.sqrt(spectrum)).real * n
    m2 = float((spectrum * qx[:, None] ** 2).sum())
    m4 = float((spectrum * qx[:, None] ** 4).sum())
    return heights, m2, m4


def run(capsys, *args):
    """``polind args`` in this process: (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        cli.main([os.fspath(arg) for arg in args])
    captured = capsys.readouterr()
    return exit_info.value.code, captured.out, captured.err


def one_error_line(err, *parts):
    assert err.endswith("\n") and err.count("\n") == 1, repr(err)
    assert err.startswith("polind: error: "), err
    for part in parts:
        assert part in err, (part, err)


# --- planted paraboloid caps ---------------------------------------------------------------

CAPS = [  # apex (x0, y0) [m], radii (Rx, Ry) [m], height H [m]
    ((10.3e-6, 12.2e-6), (20e-6, 20e-6), 80e-9),
    ((30.2e-6, 9.9e-6), (15e-6, 40e-6), 60e-9),
    ((21.1e-6, 30.05e-6), (50e-6, 25e-6), 100e-9),
    ((40.4e-6, 37.1e-6), (30e-6, 30e-6), 70e-9),
    ((8.05e-6, 36.9e-6), (12e-6, 18e-6), 50e-9),
]
PIXEL = (0.5e-6, 0.4e-6)
BOWL_RADIUS = 2.0          # m: a convex background (no summit of its own)


def planted_map():
    """Caps on a tilted convex bowl, ``h = plane + bowl + caps``, and what they should give."""
    dx, dy = PIXEL
    x = np.arange(100) * dx
    y = np.arange(120) * dy
    X, Y = np.meshgrid(x, y, indexing="ij")
    heights = 3e-7 + 2e-3 * X - 1e-3 * Y + ((X - 25e-6) ** 2 + (Y - 24e-6) ** 2) / (2 * BOWL_RADIUS)
    expected = []
    for (x0, y0), (rx, ry), top in CAPS:
        cap = top - (X - x0) ** 2 / (2 * rx) - (Y - y0) ** 2 / (2 * ry)
        heights += np.maximum(cap, 0.0)
        kappa = 0.5 * (1 / rx + 1 / ry) - 1 / BOWL_RADIUS
        expected.append(((round(x0 / dx), round(y0 / dy)), 1.0 / kappa))
    return heights, expected


def test_planted_caps_give_one_summit_each_and_their_exact_radius():
    heights, expected = planted_map()
    surface = analyse(HeightMap.from_array(heights, PIXEL, "caps"))
    found = dict(zip(zip(*(index.tolist() for index in surface.summit_index)),
                     surface.summit_radii.tolist()))
    assert surface.summits == len(CAPS)
    for position, radius in expected:
        assert position in found, (position, sorted(found))
        assert found[position] == pytest.approx(radius, rel=1e-9, abs=0)
    kappas = [1 / radius for _, radius in expected]
    assert surface.summit_radius_mean == pytest.approx(1 / np.mean(kappas), rel=1e-9)
    assert surface.summit_radius_median == pytest.approx(np.median([r for _, r in expected]),
                                                         rel=1e-9)
    assert surface.summit_density == surface.summits / (heights.size * PIXEL[0] * PIXEL[1])


def test_a_missing_neighbour_removes_a_summit_and_nothing_else():
    heights, expected = planted_map()
    (i, j), _ = expected[2]
    heights[i + 1, j - 1] = np.nan              # a diagonal neighbour of one apex
    heights[70, 5] = np.nan                     # and one point far from every cap
    surface = analyse(HeightMap.from_array(heights, PIXEL, "caps"))
    positions = set(zip(*(index.tolist() for index in surface.summit_index)))
    assert positions == {position for position, _ in expected} - {(i, j)}
    assert np.isnan(surface.heights[i + 1, j - 1]) and np.isnan(surface.heights[70, 5])
    assert surface.valid_points == heights.size - 2


# --- the summit definition, by hand and against a literal loop ------------------------------

def test_hand_checked_summits():
    nan = np.nan
    h = np.array([
        [9, 9, 9, 9, 9, 9, 9],      # border row: a 9 there is never a summit
        [0, 5, 0, 0, 0, 0, 0],      # (1,1) = 5: strictly above its 8 neighbours -> summit
        [0, 0, 0, 0, 4, 4, 0],      # (2,4) and (2,5): a tie -> neither
        [0, 0, 3, 0, 0, 0, 0],      # (3,2) = 3 -> summit
        [0, 0, 0, 0, 0, 2, 0],      # (4,5) = 2 but its neighbour (5,6) is missing -> not
        [0, 0, 0, 0, 0, 0, nan],
        [0, 6, 0, 0, 0, 0, 0],      # border row
    ], dtype=float)
    i, j = find_summits(h)
    assert list(zip(i.tolist(), j.tolist())) == [(3, 2)]  # (1,1) has the border 9s above it
    h[0, :] = 0.0
    i, j = find_summits(h)
    assert list(zip(i.tolist(), j.tolist())) == [(1, 1), (3, 2)]
    h[2, 1] = 3.0                   # a diagonal neighbour of (3,2) as high as it: no longer
    i, j = find_summits(h)
    assert list(zip(i.tolist(), j.tolist())) == [(1, 1)]


@pytest.mark.parametrize("seed", range(4))
def test_summits_match_the_literal_definition_on_grids_full_of_ties(seed):
    rng = np.random.default_rng(seed)
    h = rng.integers(0, 4, size=(23, 17)).astype(float)   # many equal neighbours
    h[rng.random(h.shape) < 0.08] = np.nan
    i, j = find_summits(h)
    assert list(zip(i.tolist(), j.tolist())) == reference_summits(h)


def test_curvature_is_the_central_difference_formula():
    rng = np.random.default_rng(5)
    h = rng.normal(size=(6, 5))
    dx, dy = 0.3e-6, 0.7e-6
    kappa = summit_curvatures(h, (dx, dy), np.array([2, 3]), np.array([1, 3]))
    for value, (i, j) in zip(kappa, [(2, 1), (3, 3)]):
        h_xx = (h[i + 1, j] - 2 * h[i, j] + h[i - 1, j]) / dx**2
        h_yy = (h[i, j + 1] - 2 * h[i, j] + h[i, j - 1]) / dy**2
        assert value == pytest.approx(-(h_xx + h_yy) / 2, rel=1e-13)


# --- levelling ------------------------------------------------------------------------------

def test_levelling_removes_a_plane_exactly_and_keeps_missing_points():
    dx, dy = 0.2e-6, 0.35e-6
    x = np.arange(64)[:, None] * dx
    y = np.arange(48)[None, :] * dy
    plane = 4e-6 + 3e-2 * x - 7e-3 * y
    rng = np.random.default_rng(1)
    missing = rng.random(plane.shape) < 0.1
    plane[missing] = np.nan
    a, b, c = mean_plane(plane, (dx, dy))
    assert (a, b, c) == pytest.approx((4e-6, 3e-2, -7e-3), rel=1e-12)
    levelled = level(plane, (dx, dy))
    assert np.array_equal(np.isnan(levelled), missing)
    assert np.nanmax(np.abs(levelled)) < 1e-12 * 4e-6


def test_levelling_is_the_least_squares_plane():
    rng = np.random.default_rng(2)
    dx, dy = 1e-6, 2e-6
    h = rng.normal(scale=1e-7, size=(30, 20)) + 1e-3 * np.arange(30)[:, None] * dx
    h[rng.random(h.shape) < 0.2] = np.nan
    i, j = np.nonzero(~np.isnan(h))
    design = np.column_stack([np.ones(i.size), i * dx, j * dy])
    reference = np.linalg.lstsq(design, h[i, j], rcond=None)[0]
    assert mean_plane(h, (dx, dy)) == pytest.approx(reference, rel=1e-10)
    residual = level(h, (dx, dy))[i, j]
    assert np.abs(design.T @ residual).max() < 1e-12 * np.abs(design.T @ np.abs(h[i, j])).max()


def test_levelling_refuses_points_on_one_line():
    h = np.full((5, 5), np.nan)
    h[2, :] = np.arange(5.0)
    with pytest.raises(InputError, match="line.*mean plane is not determined"):
        level(h, (1e-6, 1e-6), "row.npy")


# --- the ISO 16610-61 low-pass ----------------------------------------------------------------

@pytest.mark.parametrize("wavelength_over_cutoff", [1.0, 2.0, 0.75])
def test_low_pass_transmission_is_the_iso_gaussian(wavelength_over_cutoff):
    dx = 0.1e-6
    cutoff = 2e-6
    wavelength = wavelength_over_cutoff * cutoff
    x = np.arange(600) * dx
    h = np.cos(2 * np.pi * x / wavelength)[:, None] * np.ones((1, 7))
    out = low_pass(h, (dx, dx), cutoff)
    alpha = math.sqrt(math.log(2) / math.pi)
    expected = math.exp(-math.pi * (alpha * cutoff / wavelength) ** 2)
    middle = slice(150, 450)   # away from the ends of the map
    gain = np.abs(out[middle, 3]).max()
    assert gain == pytest.approx(expected, rel=2e-3)
    if wavelength_over_cutoff == 1.0:
        assert gain == pytest.approx(0.5, rel=2e-3)


def test_low_pass_keeps_missing_points_missing_and_a_constant_constant():
    h = np.full((40, 30), 2e-7)
    h[10, 10] = h[0, 0] = h[39, 5] = np.nan
    out = low_pass(h, (1e-6, 1e-6), 5e-6)
    assert np.array_equal(np.isnan(out), np.isnan(h))
    assert np.nanmax(np.abs(out - 2e-7)) < 1e-15 * 2e-7 * 100


# --- a Gaussian random surface: Nayak's summit statistics -------------------------------------

def test_gaussian_surface_summits_follow_nayak():
    # Well resolved (correlation length 8 pixels along x, 10 along y): the grid
    # summits converge to the continuous ones.  Sampling: ~2400 summits, a
    # relative spread of 1.2 % (density) and 0.6 % (mean curvature) between
    # seeds; central differences lower the curvature by about 1.5 %.
    pixel = (1e-6, 0.8e-6)
    heights, m2, m4 = gaussian_field(1024, pixel, 8e-6, 1e-6, seed=3)
    surface = analyse(HeightMap.from_array(heights, pixel, "gaussian"))
    density = m4 / (6 * math.pi * math.sqrt(3) * m2)
    mean_curvature = 8 / 3 * math.sqrt(m4 / math.pi)
    # Summits can only be interior points: count per interior area.
    interior = (1024 - 2) ** 2 * pixel[0] * pixel[1]
    assert surface.summits / interior == pytest.approx(density, rel=0.05)
    assert 1 / surface.summit_radius_mean == pytest.approx(mean_curvature, rel=0.05)
    assert np.all(surface.summit_curvatures > 0)
    # Summits are the high points: their mean height is above the mean plane.
    assert surface.summit_height_mean > 0.5e-6
    assert surface.rms_height == pytest.approx(1e-6, rel=0.05)


# --- the figure's two N(d) and the GW integral ------------------------------------------------

def test_direct_normal_load_is_the_plain_sum():
    rng = np.random.default_rng(7)
    heights = rng.normal(scale=1e-7, size=50)
    radii = rng.uniform(1e-6, 1e-5, size=50)
    separations = np.array([-1e-7, 0.0, 5e-8, 3e-7])
    expected = [(4 / 3) * 2e11 * sum(math.sqrt(r) * (h - d) ** 1.5
                                     for h, r in zip(heights, radii) if h > d)
                for d in separations]
    assert direct_normal_load(heights, radii, separations, 2e11) == pytest.approx(expected,
                                                                                  rel=1e-12)


def test_statistical_normal_load_against_quadrature_and_a_large_sample():
    sigma, radius, modulus, n = 5e-8, 2e-6, 1e11, 200_000
    separations = np.array([-0.5, 0.0, 1.0]) * sigma

    def three_halves(s):
        return integrate.quad(lambda t: t**1.5 * math.exp(-0.5 * (t + s) ** 2)
                              / math.sqrt(2 * math.pi), 0, np.inf)[0]

    statistical = statistical_normal_load(n, radius, sigma, separations, modulus)
    quadrature = [(4 / 3) * n * modulus * math.sqrt(radius) * sigma**1.5 * three_halves(d / sigma)
                  for d in separations]
    assert statistical == pytest.approx(quadrature, rel=1e-8)
    heights = np.random.default_rng(0).normal(scale=sigma, size=n)
    direct = direct_normal_load(heights, np.full(n, radius), separations, modulus)
    assert direct == pytest.approx(statistical, rel=0.02)


# --- reading ------------------------------------------------------------------------------

def test_npy_and_csv_grids_read_with_missing_points_kept(tmp_path):
    heights = np.arange(20.0).reshape(5, 4) * 1e-9
    heights[1, 2] = np.nan
    np.save(tmp_path / "map.npy", heights)
    (tmp_path / "map.csv").write_text(
        "# heights in metres\n" + "\n".join(
            ",".join("" if np.isnan(v) else repr(float(v)) for v in row) for row in heights) + "\n")
    (tmp_path / "nan.csv").write_text(
        "\n".join(",".join(repr(float(v)) for v in row) for row in heights) + "\n")
    for name in ("map.npy", "map.csv", "nan.csv"):
        height_map = read_height_map(tmp_path / name, pixel_size=(1e-6, 2e-6))
        assert height_map.pixel_size == (1e-6, 2e-6)
        assert np.array_equal(height_map.heights, heights, equal_nan=True), name
        assert height_map.valid_points == 19


def test_a_masked_array_becomes_missing_points():
    data = np.ma.masked_array(np.ones((4, 4)), mask=np.eye(4, dtype=bool))
    height_map = HeightMap.from_array(data, (1e-6, 1e-6))
    assert np.array_equal(np.isnan(height_map.heights), np.eye(4, dtype=bool))


@pytest.mark.parametrize("content, pixel, message", [
    ("1,2,3\n4,5\n7,8,9\n", (1e-6, 1e-6), "line 2 has 2 values; expected 3"),
    ("1,2,3\n4,x,6\n7,8,9\n", (1e-6, 1e-6), "line 2, column 2: 'x' is not a number"),
    ("1,2,3\n4,inf,6\n7,8,9\n", (1e-6, 1e-6), "infinite"),
    ("nan,nan,nan\nnan,nan,nan\n,,\n", (1e-6, 1e-6), "every one of the 9 points is missing"),
    ("1,2,3\n4,5,6\n", (1e-6, 1e-6), "at least 3 x 3"),
    ("1,2,3\n4,5,6\n7,8,9\n", None, "holds no pixel size"),
    ("1,2,3\n4,5,6\n7,8,9\n", (1e-6, -1.0), "'pixel_size' parameter of topography must be "
                                            "positive"),
])
def test_bad_grids_are_refused_naming_the_file(tmp_path, content, pixel, message):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(InputError) as error:
        read_height_map(path, pixel_size=pixel)
    assert message in str(error.value)
    assert "bad.csv" in str(error.value) or "pixel_size" in str(error.value)


def test_bad_npy_files_are_refused(tmp_path):
    np.save(tmp_path / "cube.npy", np.zeros((3, 3, 3)))
    (tmp_path / "junk.npy").write_bytes(b"not an array")
    for name, message in (("cube.npy", "3 dimension"), ("junk.npy", "NumPy .npy")):
        with pytest.raises(InputError, match=message):
            read_height_map(tmp_path / name, pixel_size=(1e-6, 1e-6))


def test_a_file_surface_topography_cannot_read_is_refused(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("these are not heights\n")
    with pytest.raises(InputError, match="notes.txt: SurfaceTopography recognises no"):
        read_height_map(path)
    with pytest.raises(InputError, match="no such file"):
        read_height_map(tmp_path / "absent.x3p")


@pytest.fixture(scope="module")
def measured():
    """Both maps of polind.datasets, read and analysed once."""
    return {name: load_measured_surface(datasets.height_map_path(name))
            for name in ("x3p-2.x3p", "sur-2.sur")}


def test_the_x3p_map_reads_in_metres(measured):
    surface = measured["x3p-2.x3p"]
    assert surface.grid == (650, 650)
    assert surface.pixel_size == pytest.approx((0.128e-6, 0.315e-6), rel=5e-3)
    assert surface.valid_points == 650 * 650
    assert surface.rms_height == pytest.approx(77e-9, rel=0.02)
    assert surface.nominal_area == pytest.approx(650 * 650 * surface.pixel_size[0]
                                                 * surface.pixel_size[1], rel=1e-12)
    assert 1000 < surface.summits < 10000


def test_the_sur_map_reads_in_metres_with_its_missing_points(measured):
    import SurfaceTopography

    surface = measured["sur-2.sur"]
    assert surface.grid == (563, 484)
    assert surface.pixel_size == pytest.approx((3.48e-6, 3.48e-6), rel=2e-3)
    assert surface.rms_height == pytest.approx(17e-9, rel=0.03)
    mask = np.ma.getmaskarray(SurfaceTopography.open_topography(
        str(datasets.height_map_path("sur-2.sur"))).topography().heights())
    assert mask.sum() > 0
    assert np.array_equal(np.isnan(surface.heights), mask)
    assert surface.valid_points == 563 * 484 - mask.sum()
    # No summit touches a missing point.
    i, j = surface.summit_index
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            assert not np.isnan(surface.heights[i + di, j + dj]).any()


def test_a_pixel_size_is_refused_for_a_file_that_has_its_own():
    with pytest.raises(InputError, match="gives its own physical size"):
        read_height_map(datasets.height_map_path("sur-2.sur"), pixel_size=(1e-6, 1e-6))


# --- the package stays light ------------------------------------------------------------------

def test_import_polind_imports_neither_surface_topography_nor_matplotlib():
    code = ("import sys, polind, polind.topography; "
            "print(sorted(m for m in ('SurfaceTopography', 'matplotlib') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


# --- the command line -------------------------------------------------------------------------

@pytest.fixture
def caps_npy(tmp_path):
    heights, _ = planted_map()
    path = tmp_path / "caps.npy"
    np.save(path, heights)
    return path


def test_cli_json_has_the_interface_keys(capsys, caps_npy):
    status, out, err = run(capsys, "topography", caps_npy, "--json", "--pixel-size",
                           str(PIXEL[0]), str(PIXEL[1]))
    assert status == 0, err
    summary = json.loads(out, parse_constant=lambda name: pytest.fail(f"non-strict JSON {name}"))
    assert JSON_KEYS <= set(summary)
    assert summary["grid"] == [100, 120] and summary["summits"] == len(CAPS)
    assert set(summary["greenwood_williamson"]) == {"asperity_density", "asperity_radius",
                                                    "height_std"}
    assert summary["greenwood_williamson"]["asperity_radius"] == summary["summit_radius_mean"]
    assert summary["channel"] is None                  # a .npy grid has no channels
    assert set(summary["roughness"]) == {"Sa", "Sq", "Ssk", "Sku", "Sdq", "rms_curvature"}


def test_cli_plot_writes_a_png_and_the_text_summary(capsys, caps_npy, tmp_path):
    png = tmp_path / "caps.png"
    status, out, err = run(capsys, "topography", caps_npy, "--plot", png, "--pixel-size",
                           str(PIXEL[0]), str(PIXEL[1]))
    assert status == 0, err
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "summits            5" in out and "asperity_radius = " in out


@pytest.mark.parametrize("case", ["unreadable", "no pixel size", "all missing", "no summit",
                                  "plot is the input", "absent", "bad cut-off",
                                  "png and json both on stdout"])
def test_cli_bad_input_is_one_line_and_exit_2(capsys, tmp_path, case):
    grid = tmp_path / "grid.npy"
    np.save(grid, np.random.default_rng(0).normal(size=(8, 8)) * 1e-9)
    arguments = {
        "unreadable": [tmp_path / "notes.dat"],
        "no pixel size": [grid],
        "all missing": [tmp_path / "empty.npy", "--pixel-size", "1e-6", "1e-6"],
        "no summit": [tmp_path / "flat.npy", "--pixel-size", "1e-6", "1e-6"],
        "plot is the input": [grid, "--pixel-size", "1e-6", "1e-6", "--plot", grid],
        "absent": [tmp_path / "absent.x3p"],
        "bad cut-off": [grid, "--pixel-size", "1e-6", "1e-6", "--short-cutoff", "0"],
        "png and json both on stdout": [grid, "--pixel-size", "1e-6", "1e-6", "--plot", "-",
                                        "--json"],
    }[case]
    (tmp_path / "notes.dat").write_text("no heights here\n")
    np.save(tmp_path / "empty.npy", np.full((5, 5), np.nan))
    np.save(tmp_path / "flat.npy", np.zeros((5, 5)))
    status, out, err = run(capsys, "topography", *arguments)
    assert status == 2 and out == ""
    one_error_line(err, "--plot -" if "--json" in arguments else os.fspath(arguments[0]))


def test_cli_a_truncated_measurement_is_one_line_and_exit_2(capsys, tmp_path):
    truncated = tmp_path / "cut.sur"
    truncated.write_bytes(datasets.height_map_path("sur-2.sur").read_bytes()[:500_000])
    status, out, err = run(capsys, "topography", truncated)
    assert status == 2 and out == ""
    one_error_line(err, os.fspath(truncated), "SurfaceTopography cannot read", "truncated")
