"""The Pol-Ind model on a measured height map (MODELS.md 7.8, direct summation with own radii).

References, each independent of the code under test:
- the summits and radii of :func:`polind.topography.analyse` (themselves
  tested against planted caps and hand-checked grids in test_topography.py);
- plain Python sums of Hertz's law over those summits, each with its own
  radius, and ``scipy.optimize.brentq`` for the separation;
- the plain Maxwell-slip oracle of ``tests/oracles.py``;
- a plain stepper of the time-varying-load rules written here (elements fixed
  in height, the separation re-solved by ``brentq`` on the plain sum).
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest
from scipy import optimize

import oracles
import polind
from polind import cli, datasets
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.models.pol_ind import default_table
from polind.topography import HeightMap, analyse, load_measured_surface
from polind.topography_figure import virgin_curves
from test_topography import gaussian_field


PIXEL = (0.5e-6, 0.5e-6)
E1, NU = 210e9, 0.3
E_STAR = 1.0 / (2 * (1 - NU**2) / E1)
G_STAR = 1.0 / (2 * (2 - NU) * 2 * (1 + NU) / E1)      # 1/G* = sum (2 - nu)/G, G = E/(2(1 + nu))


@pytest.fixture(scope="module")
def rough_map(tmp_path_factory):
    """A 192 x 160 Gaussian random surface (rms 50 nm), as a .npy grid and its analysis."""
    heights, _, _ = gaussian_field(192, PIXEL, 2.5e-6, 50e-9, seed=11)
    heights = heights[:, :160]
    folder = tmp_path_factory.mktemp("map")
    np.save(folder / "rough.npy", heights)
    return folder / "rough.npy", analyse(HeightMap.from_array(heights, PIXEL, "rough.npy"))


def map_model(path, load=0.05, nominal_area=None, **changes):
    table = default_table()
    table["normal_load"] = load
    table["surface"] = {"topography": str(path), "pixel_size": list(PIXEL)}
    if nominal_area is not None:
        table["surface"]["nominal_area"] = nominal_area
    table["discretisation"] = {}
    table.update(changes)
    return polind.model_from_dict({"model": table})


def plain_load(d, heights, radii, weight=1.0):
    """N(d) = sum over summits above d of weight (4/3) E* sqrt(R_i) (h_i - d)^(3/2)."""
    delta = heights - d
    touching = delta > 0
    return weight * 4 / 3 * E_STAR * float(np.sum(np.sqrt(radii[touching])
                                                   * delta[touching] ** 1.5))


def plain_separation(load, heights, radii, weight=1.0):
    top = heights.max()
    return optimize.brentq(lambda d: plain_load(d, heights, radii, weight) - load,
                           heights.min(), top, xtol=1e-24, rtol=4 * np.finfo(float).eps)


def plain_elements(measured, load, weight=1.0, mu_s=0.15):
    """Heights, k_i and W_i of the summits in contact at ``load``, from the summits themselves."""
    heights = measured.summit_heights - measured.summit_heights.mean()
    radii = measured.summit_radii
    d = plain_separation(load, heights, radii, weight)
    touching = heights > d
    delta = heights[touching] - d
    stiffness = weight * 8 * G_STAR * np.sqrt(radii[touching] * delta)
    breakaway = weight * mu_s * 4 / 3 * E_STAR * np.sqrt(radii[touching]) * delta ** 1.5
    order = np.argsort(heights[touching], kind="stable")
    return d, heights[touching][order], radii[touching][order], stiffness[order], breakaway[order]


# --- the surface: per-summit radii ----------------------------------------------------------

def test_a_direct_surface_with_own_radii_sums_hertz_per_summit():
    rng = np.random.default_rng(5)
    heights = rng.normal(0.0, 1e-7, 300)
    heights[10] = heights[20]                      # equal heights with different radii merge
    radii = rng.uniform(1e-6, 2e-5, 300)
    counts = rng.uniform(0.5, 3.0, 300)
    surface = DirectSurface(heights, 5e-6, E_STAR, G_STAR, counts=counts, radii=radii)
    assert surface.heights.size == 299
    for d in (-2e-7, 0.0, 1e-7):
        delta = heights - d
        on = delta > 0
        assert float(surface.normal_load(d)) == pytest.approx(
            4 / 3 * E_STAR * np.sum(counts[on] * np.sqrt(radii[on]) * delta[on] ** 1.5), rel=1e-12)
        assert float(surface.normal_load_slope(d)) == pytest.approx(
            -2 * E_STAR * np.sum(counts[on] * np.sqrt(radii[on] * delta[on])), rel=1e-12)
        assert float(surface.contacts(d)) == pytest.approx(np.sum(counts[on]), rel=1e-12)
        assert float(surface.real_area(d)) == pytest.approx(
            math.pi * np.sum(counts[on] * radii[on] * delta[on]), rel=1e-12)


def test_the_separation_of_a_map_carries_the_load_to_1e_10(rough_map):
    path, measured = rough_map
    heights = measured.summit_heights - measured.summit_heights.mean()
    for load in (1e-4, 3e-3, 0.05, 0.4):
        contact = map_model(path, load=load).contact()
        assert plain_load(contact.separation, heights, measured.summit_radii) \
            == pytest.approx(load, rel=1e-10)
        assert contact.separation == pytest.approx(
            plain_separation(load, heights, measured.summit_radii), rel=1e-9, abs=1e-18)


def test_nominal_area_makes_each_summit_stand_for_a0_over_a_map(rough_map):
    path, measured = rough_map
    scale = 40.0
    model = map_model(path, load=0.05 * scale, nominal_area=scale * measured.nominal_area)
    contact = model.contact()
    reference = map_model(path, load=0.05).contact()
    # Same pressure, same separation; every count and force scaled by A0 / A_map.
    assert contact.separation == pytest.approx(reference.separation, rel=1e-9, abs=1e-18)
    assert contact.contacts == pytest.approx(scale * reference.contacts, rel=1e-12)
    assert contact.real_area == pytest.approx(scale * reference.real_area, rel=1e-9)
    np.testing.assert_allclose(contact.elements.stiffness, scale * reference.elements.stiffness,
                               rtol=1e-8)


# --- the elements and the model's properties ------------------------------------------------

def test_elements_are_the_summits_in_contact_with_their_own_radii(rough_map):
    path, measured = rough_map
    table = map_model(path).element_table()
    d, heights, radii, stiffness, breakaway = plain_elements(measured, 0.05)
    assert len(table) == heights.size > 20
    np.testing.assert_allclose(table.heights, heights, rtol=0, atol=1e-20)
    np.testing.assert_allclose(table.stiffness, stiffness, rtol=1e-8)
    np.testing.assert_allclose(table.breakaway_force, breakaway, rtol=1e-8, atol=1e-14)
    np.testing.assert_array_equal(table.asperities, np.ones(heights.size))
    # Amontons' law: the elements' break-away forces sum to mu_s N.
    assert table.breakaway_force.sum() == pytest.approx(0.15 * 0.05, rel=1e-10)


def test_the_virgin_curve_of_a_map_model_is_the_sum_of_elastic_slip_summits(rough_map):
    path, measured = rough_map
    model = map_model(path, attraction=1e14)
    _, _, _, stiffness, breakaway = plain_elements(measured, 0.05)
    u = np.linspace(0.0, 1.3 * np.max(breakaway / stiffness), 801)
    want = np.array([np.sum(np.minimum(stiffness * ui, breakaway)) for ui in u])
    got = polind.simulate(model, u / 1e-9, x=u).force             # |v| = 1e-9 m/s << vs
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9 * 0.0075)
    curves = virgin_curves(measured, normal_load=0.05, moduli=(E_STAR, G_STAR), points=101)
    want = np.array([np.sum(np.minimum(stiffness * ui, breakaway))
                     for ui in curves["displacement"]])
    np.testing.assert_allclose(curves["direct"], want, rtol=1e-8, atol=1e-12)


def test_presliding_on_a_map_is_the_maxwell_slip_model_of_its_summits(rough_map):
    path, measured = rough_map
    model = map_model(path, attraction=1e14)
    _, _, _, stiffness, breakaway = plain_elements(measured, 0.05)
    scale = 0.8 * np.max(breakaway / stiffness)
    corners = scale * np.array([0.0, 1.0, -0.6, 0.5, -0.2, 0.3, -0.6, 0.8, -1.0, 1.0])
    x = np.concatenate([np.linspace(a, b, 200, endpoint=False)
                        for a, b in zip(corners[:-1], corners[1:])] + [corners[-1:]])
    t = np.arange(x.size) * 1.0                                   # |v| ~ 1e-10 m/s
    got = polind.simulate(model, t, x=x).force
    want = oracles.simulate({"type": "maxwell-slip", "stiffness": stiffness.tolist(),
                             "breakaway_force": breakaway.tolist()}, t, x=x).force
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9 * 0.0075)


@pytest.mark.parametrize("load", [2e-3, 0.05, 0.3])
def test_sliding_friction_on_a_map_follows_amontons(rough_map, load):
    path, _ = rough_map
    model = map_model(path, load=load, viscous_coefficient=0.0)
    t = np.linspace(0.0, 1.0, 1001)
    for velocity, mu in ((1e-1, 0.10), (-1e-1, 0.10)):
        force = polind.simulate(model, t, v=np.full_like(t, velocity)).force
        assert force[-1] == pytest.approx(math.copysign(mu * load, velocity), rel=1e-9)


def reference_varying_load(measured, t, x, load):
    """Plain stepper: elements of the summits touching at max load, d(t) by brentq."""
    heights = measured.summit_heights - measured.summit_heights.mean()
    radii = measured.summit_radii
    _, el_h, el_r, _, _ = plain_elements(measured, float(load.max()))
    return oracles.pol_ind_varying_load(
        t, x, load, el_h, np.sqrt(el_r), lambda n: plain_separation(n, heights, radii),
        G_STAR, mu_s=0.15, mu_k=0.10)


def test_a_time_varying_load_on_a_map_follows_the_rules(rough_map):
    path, measured = rough_map
    model = map_model(path, load=0.05)
    t = np.linspace(0.0, 0.2, 161)
    x = 2e-8 * np.sin(2 * np.pi * 10 * t) + 2e-3 * t
    load = 0.05 + 0.03 * np.sin(2 * np.pi * 7 * t) ** 2 - 0.02 * (t > 0.1)
    got = polind.simulate(model, t, x=x, normal_load=load).force
    want = reference_varying_load(measured, t, x, load)
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-8 * 0.012)


# --- the statistical equivalent -------------------------------------------------------------

def test_the_statistical_equivalent_has_the_maps_greenwood_williamson_keys(rough_map):
    path, measured = rough_map
    model = map_model(path)
    twin = model.statistical_equivalent()
    surface = twin.params["surface"]
    assert surface["asperity_density"] == pytest.approx(measured.summits / measured.nominal_area)
    assert surface["asperity_radius"] == pytest.approx(1 / np.mean(measured.summit_curvatures))
    assert surface["height_std"] == pytest.approx(np.std(measured.summit_heights))
    assert surface["nominal_area"] == pytest.approx(measured.nominal_area)
    assert twin.params["discretisation"]["summation"] == "statistical"
    assert twin.contact().surface.kind == "statistical"
    with pytest.raises(polind.InputError, match="needs a pol-ind model with a 'surface.topography'"):
        twin.statistical_equivalent()


def test_direct_and_statistical_loads_agree_within_sampling_error_on_a_gaussian_surface():
    # The direct sum over the summit heights of a Gaussian random surface with
    # one radius 1/mean(kappa) against its Greenwood-Williamson equivalent:
    # equal within the sampling error of a sum over ~2400 summits.  With each
    # summit's own radius the direct load is lower: on a Gaussian surface the
    # higher summits are the sharper ones (Nayak 1971), which GW's single
    # radius ignores.
    pixel = (1e-6, 0.8e-6)
    heights, _, _ = gaussian_field(1024, pixel, 8e-6, 1e-6, seed=3)
    measured = analyse(HeightMap.from_array(heights, pixel, "gaussian"))
    direct = DirectSurface.from_topography(measured, E_STAR, G_STAR)
    gw = direct.greenwood_williamson
    statistical = StatisticalSurface(gw["asperity_density"], gw["nominal_area"],
                                     gw["asperity_radius"], gw["height_std"], E_STAR, G_STAR)
    one_radius = DirectSurface(direct.heights, gw["asperity_radius"], E_STAR, G_STAR)
    sigma = gw["height_std"]
    for d in np.array([-1.0, 0.0, 1.0]) * sigma:
        delta = np.maximum(direct.heights - d, 0.0)
        per_summit = 4 / 3 * E_STAR * math.sqrt(gw["asperity_radius"]) * delta ** 1.5
        standard_error = math.sqrt(per_summit.size * per_summit.var())
        assert abs(float(one_radius.normal_load(d)) - float(statistical.normal_load(d))) \
            < 3 * standard_error
        assert float(direct.normal_load(d)) < float(one_radius.normal_load(d))


# --- model files: keys, paths, errors -------------------------------------------------------

def test_a_model_file_reads_its_map_relative_to_itself(tmp_path, rough_map):
    path, measured = rough_map
    folder = tmp_path / "models"
    folder.mkdir()
    (folder / "scan.npy").write_bytes(Path(path).read_bytes())
    (folder / "m.toml").write_text(
        '[model]\ntype = "pol-ind"\nnormal_load = 0.05\nstatic_coefficient = 0.15\n'
        'kinetic_coefficient = 0.1\nstribeck_velocity = 1e-3\nattraction = 1e4\n'
        '[model.surface]\ntopography = "scan.npy"\npixel_size = [5e-7, 5e-7]\n'
        '[model.materials]\nyoungs_modulus = [210e9, 210e9]\npoisson_ratio = [0.3, 0.3]\n')
    model = polind.load_model(folder / "m.toml")
    assert model.params["surface"]["topography"] == str(folder / "scan.npy")
    assert model.contact().surface.asperity_count == measured.summits


@pytest.mark.parametrize("surface, discretisation, message", [
    ({"asperity_radius": 1e-5}, {}, "'surface.asperity_radius' parameter of pol-ind is not used "
                                    "with a 'surface.topography'"),
    ({"height_std": 1e-7}, {}, "'surface.height_std' .* not used with a 'surface.topography'"),
    ({"asperity_density": 1e10}, {}, "'surface.asperity_density' .* not used"),
    ({}, {"summation": "statistical"}, "needs summation = \"direct\""),
    ({}, {"summation": "direct", "heights_file": "h.csv"}, "not both"),
])
def test_keys_a_map_replaces_are_refused_with_the_reason(rough_map, surface, discretisation,
                                                         message):
    path, _ = rough_map
    table = default_table()
    table["surface"] = {"topography": str(path), "pixel_size": list(PIXEL), **surface}
    table["discretisation"] = discretisation
    with pytest.raises(polind.InputError, match=message):
        polind.model_from_dict({"model": table})


def test_map_keys_without_a_map_are_refused():
    table = default_table()
    table["surface"]["pixel_size"] = [1e-6, 1e-6]
    with pytest.raises(polind.InputError, match="'surface.pixel_size' .* only goes with a "
                                                "'surface.topography'"):
        polind.model_from_dict({"model": table})
    table = default_table()
    del table["surface"]["asperity_radius"]
    with pytest.raises(polind.InputError, match="Missing key 'surface.asperity_radius'"):
        polind.model_from_dict({"model": table})


def test_a_load_the_maps_summits_cannot_carry_is_refused(rough_map):
    path, measured = rough_map
    heights = measured.summit_heights - measured.summit_heights.mean()
    most = plain_load(heights.min(), heights, measured.summit_radii)
    with pytest.raises(polind.InputError, match=r"more than the measured surface '.*rough.npy' "
                                                r"can carry: every one of its \d+ summits"):
        map_model(path, load=1.01 * most).contact()
    # Just below it the flat is just above the lowest summit: all the others touch.
    assert map_model(path, load=0.99 * most).contact().contacts == measured.summits - 1


def run(capsys, *args):
    """``polind args`` in this process: (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exit_info:
        cli.main([str(arg) for arg in args])
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def test_cli_surface_of_a_map_model_and_its_errors(capsys, tmp_path, rough_map):
    path, measured = rough_map
    (tmp_path / "m.toml").write_text(
        '[model]\ntype = "pol-ind"\nnormal_load = 0.05\nstatic_coefficient = 0.15\n'
        'kinetic_coefficient = 0.1\nstribeck_velocity = 1e-3\nattraction = 1e4\n'
        f'[model.surface]\ntopography = "{path}"\npixel_size = [5e-7, 5e-7]\n'
        '[model.materials]\nyoungs_modulus = [210e9, 210e9]\npoisson_ratio = [0.3, 0.3]\n')
    code, out, err = run(capsys, "surface", str(tmp_path / "m.toml"))
    assert code == 0, err
    assert "direct summation" in out
    (tmp_path / "bad.toml").write_text(
        (tmp_path / "m.toml").read_text().replace("normal_load = 0.05", "normal_load = 1e6"))
    code, out, err = run(capsys, "surface", str(tmp_path / "bad.toml"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "rough.npy" in err
    (tmp_path / "nopixel.toml").write_text(
        (tmp_path / "m.toml").read_text().replace("pixel_size = [5e-7, 5e-7]\n", ""))
    code, out, err = run(capsys, "surface", str(tmp_path / "nopixel.toml"))
    assert code == 2 and len(err.strip().splitlines()) == 1 and "rough.npy" in err


def test_the_x3p_map_of_the_datasets_gives_a_pol_ind_model():
    path = datasets.height_map_path("x3p-2.x3p")
    model = map_model(path, load=1.0)
    model = polind.model_from_dict({"model": {**model.params, "type": "pol-ind",
                                              "surface": {"topography": str(path)}}})
    measured = load_measured_surface(path)
    contact = model.contact()
    heights = measured.summit_heights - measured.summit_heights.mean()
    assert plain_load(contact.separation, heights, measured.summit_radii) \
        == pytest.approx(1.0, rel=1e-10)
    assert contact.elements.breakaway_force.sum() == pytest.approx(0.15, rel=1e-10)
    twin = model.statistical_equivalent().contact()
    assert twin.elements.breakaway_force.sum() == pytest.approx(0.15, rel=1e-10)


def test_short_cutoff_reaches_the_summits_and_a_changed_map_is_read_again(tmp_path, rough_map):
    path, _ = rough_map
    copy = tmp_path / "copy.npy"
    copy.write_bytes(Path(path).read_bytes())
    table = default_table()
    table.update(normal_load=0.05, discretisation={})
    table["surface"] = {"topography": str(copy), "pixel_size": list(PIXEL), "short_cutoff": 4e-6}
    model = polind.model_from_dict({"model": table})
    smooth = load_measured_surface(copy, PIXEL, short_cutoff=4e-6)
    assert model.contact().surface.asperity_count == smooth.summits
    assert smooth.summits < load_measured_surface(copy, PIXEL).summits
    # The same model keys on a rewritten file: the surface is built anew, not taken
    # from the cache of built surfaces.
    heights = np.load(copy)
    np.save(copy, heights[:, :100])
    os.utime(copy, ns=(1, 1))
    again = polind.model_from_dict({"model": table})
    assert again.contact().surface.asperity_count \
        == load_measured_surface(copy, PIXEL, short_cutoff=4e-6).summits


def test_a_fit_on_a_map_model_frees_only_friction_keys(rough_map):
    path, _ = rough_map
    truth = map_model(path)
    t = np.linspace(0.0, 1.0, 201)
    x = 1e-8 * np.sin(6 * t)
    data = {"t": t, "x": x, "F": polind.simulate(truth, t, x=x).force}
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = polind.identify(truth.with_params(static_coefficient=0.2), data)
    assert not any(key.startswith("surface.") for key in fit.free)
    assert fit.model.params["static_coefficient"] == pytest.approx(0.15, rel=1e-3)


# --- map conditioning keys and the ball on a flat (issue 22) ------------------------------------

def test_conditioning_keys_reach_the_summits(tmp_path, rough_map):
    path, measured = rough_map
    heights = np.load(path)
    rng = np.random.default_rng(4)
    spikes = rng.choice(heights.size, heights.size // 200, replace=False)
    heights.ravel()[spikes] += rng.choice([-1.0, 1.0], spikes.size) * 3e-6
    spiky = tmp_path / "spiky.npy"
    np.save(spiky, heights)
    with pytest.warns(UserWarning, match=r"\d+ point\(s\) lie more than 8 robust"):
        kept = map_model(spiky).contact().surface.asperity_count
    model = map_model(spiky, surface={"topography": str(spiky), "pixel_size": list(PIXEL),
                                      "remove_outliers": True, "levelling": "lines"})
    removed = load_measured_surface(spiky, PIXEL, remove_outliers=True, levelling="lines")
    assert removed.outliers == spikes.size and removed.levelling == "lines"
    assert model.contact().surface.asperity_count == removed.summits != kept
    with pytest.raises(polind.InputError, match="'surface.remove_outliers' parameter of pol-ind "
                                                "must be true or false"):
        map_model(spiky, surface={"topography": str(spiky), "pixel_size": list(PIXEL),
                                  "remove_outliers": "yes"})
    for key, value in (("remove_outliers", True), ("levelling", "lines"), ("channel", "Height")):
        table = default_table()
        table["surface"][key] = value
        with pytest.raises(polind.InputError, match=f"'surface.{key}' .* only goes with"):
            polind.model_from_dict({"model": table})


def test_a_cutoff_under_two_pixels_is_refused_in_a_model(rough_map):
    path, _ = rough_map
    model = map_model(path, surface={"topography": str(path), "pixel_size": list(PIXEL),
                                     "short_cutoff": 0.9e-6})
    with pytest.raises(polind.InputError, match=r"rough.npy: the 'short_cutoff' must be at least "
                                                r"twice the smaller pixel spacing, 1e-06 m"):
        model.contact()


def hertz_area(load, ball_radius):
    """pi a^2, a = (3 N R_b / (4 E*))^(1/3): the ball's macroscopic Hertz contact."""
    return math.pi * (3 * load * ball_radius / (4 * E_STAR)) ** (2 / 3)


def test_a_ball_radius_gives_the_nominal_area_of_the_balls_hertz_contact(rough_map):
    path, measured = rough_map
    ball = {"topography": str(path), "pixel_size": list(PIXEL), "ball_radius": 2e-3}
    model = map_model(path, load=0.05, surface=ball)
    for load in (0.05, 0.2):
        contact = model.contact(load)
        same = map_model(path, load=load, nominal_area=hertz_area(load, 2e-3)).contact()
        scale = hertz_area(load, 2e-3) / measured.nominal_area
        np.testing.assert_allclose(contact.surface.counts, scale, rtol=1e-12)
        assert contact.separation == pytest.approx(same.separation, rel=1e-12, abs=1e-20)
        assert contact.real_area == pytest.approx(same.real_area, rel=1e-12)
    # The statistical surfaces take it too, and the statistical equivalent keeps the ball.
    table = default_table()
    table["surface"] = {key: value for key, value in table["surface"].items()
                        if key != "nominal_area"}
    table["surface"]["ball_radius"] = 5e-3
    statistical = polind.model_from_dict({"model": table})
    assert statistical.contact().surface.nominal_area == pytest.approx(
        hertz_area(table["normal_load"], 5e-3), rel=1e-12)
    twin = model.statistical_equivalent()
    assert twin.params["surface"]["ball_radius"] == 2e-3
    assert twin.contact().surface.nominal_area == pytest.approx(hertz_area(0.05, 2e-3), rel=1e-12)


def test_a_ball_radius_takes_a_varying_load_and_refuses_a_second_area(rough_map):
    path, _ = rough_map
    ball = {"topography": str(path), "pixel_size": list(PIXEL), "ball_radius": 2e-3}
    model = map_model(path, load=0.05, surface=ball)
    t = np.linspace(0.0, 1.0, 51)
    x = 1e-8 * np.sin(2 * np.pi * t)
    constant = polind.simulate(model, t, x=x, normal_load=np.full_like(t, 0.05))
    np.testing.assert_array_equal(constant.force, polind.simulate(model, t, x=x).force)
    # A varying load runs, the area following it (tests/test_ball.py checks the numbers).
    varying = polind.simulate(model, t, x=x, normal_load=0.05 - 0.04 * t)
    assert np.all(np.abs(varying.force) <= 0.15 * varying.normal_load * (1 + 1e-12))
    with pytest.raises(polind.InputError, match="'surface.nominal_area' or 'surface.ball_radius'"):
        map_model(path, nominal_area=1e-8, surface={**ball, "nominal_area": 1e-8})
    table = default_table()
    table["surface"] = {"asperity_radius": 5e-5, "ball_radius": 1e-3}
    table["discretisation"] = {"summation": "direct", "heights_file": "h.csv"}
    with pytest.raises(polind.InputError, match="'surface.ball_radius' .* not used with a "
                                                "'discretisation.heights_file'"):
        polind.model_from_dict({"model": table})


def test_the_guides_path_from_the_shipped_map_to_a_presliding_loop(tmp_path):
    # The user guide's "From a measured map to a presliding loop", its numbers as printed.
    import shutil

    shutil.copy(datasets.height_map_path("sur-2.sur"), tmp_path / "sur-2.sur")
    (tmp_path / "model.toml").write_text(
        '[model]\ntype = "pol-ind"\nnormal_load = 0.5\nstatic_coefficient = 0.15\n'
        'kinetic_coefficient = 0.10\nstribeck_velocity = 1e-3\nattraction = 1e4\n'
        '[model.surface]\ntopography = "sur-2.sur"\nremove_outliers = true\n'
        'short_cutoff = 1.4e-5\n[model.materials]\nyoungs_modulus = [210e9, 210e9]\n'
        'poisson_ratio = [0.3, 0.3]\nhardness = 2e9\n')
    model = polind.load_model(tmp_path / "model.toml")
    assert model.plastic
    contact = model.contact()
    validity = contact.validity()
    assert round(validity["plasticity_index"], 2) == 0.06
    assert validity["plastic_contact_share"] == validity["plastic_load_share"] == 0.0
    assert round(validity["mean_real_pressure"] / 1e6) == 14
    assert round(validity["peak_asperity_pressure"] / 1e6) == 55
    table = model.element_table()
    assert table.stiffness.size == 269
    D = float(np.max(table.breakaway_force / table.stiffness))
    assert round(D * 1e9, 2) == 0.73
    path = [0.0, 1.5 * D, -1.5 * D, 0.3 * D, -0.3 * D, 1.5 * D]
    t = np.linspace(0.0, 1.0, 5001)
    x = np.interp(t, np.linspace(0.0, 1.0, len(path)), path)
    force = polind.simulate(model, t, x=x).force
    assert round(float(x[np.argmax(force >= 0.99 * 0.075)]) * 1e9, 2) == 0.62
    # The inner loop closes on its starting reversal (0.3 D, at t = 0.6): the outer
    # curve goes on from there, through the force it had when it left.
    inner_start = np.argmin(np.abs(t - 0.6))
    assert round(float(force[inner_start]), 4) == 0.0741
    after = np.flatnonzero((t > 0.8) & (x >= x[inner_start]))[0]
    np.testing.assert_allclose(force[after], force[inner_start], atol=2e-4 * 0.075)
