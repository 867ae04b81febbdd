"""The modified Maxwell-slip element table and build_contact (MODELS.md 7.5; INTERFACE.md)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import integrate

from polind.contact.builder import build_contact
from polind.models import PolInd
from polind.contact.elements import element_properties, element_table
from polind.contact.materials import effective_moduli
from polind.contact.separation import solve_separation, solve_separation_series
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.errors import InputError

ETA, A0, R, SIGMA = 1e10, 1e-4, 50e-6, 0.5e-6
E_STAR, G_STAR = effective_moduli(210e9, 0.3, 210e9, 0.3)
MU = 0.15


@pytest.fixture(scope="module")
def statistical():
    return StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR)


@pytest.fixture(scope="module")
def direct():
    return DirectSurface.from_seed(ETA, 1e-5, SIGMA, R, E_STAR, G_STAR, seed=1)


def hertz(delta):
    return 4.0 / 3.0 * E_STAR * math.sqrt(R) * np.maximum(delta, 0.0) ** 1.5


def gaussian_tail_moment(d, power):
    """eta A0 ∫_d^∞ (h - d)^power Phi(h) dh by quadrature (metres, sigma units)."""
    s = d / SIGMA
    f = lambda t: (SIGMA * (t - s)) ** power * math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi)  # noqa: E731
    value = sum(
        integrate.quad(f, a, b, epsabs=0.0, epsrel=1e-12, limit=200)[0]
        for a, b in ((s, s + 1.0), (s + 1.0, max(s, 0.0) + 14.0))
    )
    return ETA * A0 * value


LOADS = [1e-4, 0.1, 10.0, 100.0, 1e4, 1e6]


@pytest.mark.parametrize("n_elements", [64, 128, 256])
@pytest.mark.parametrize("load", [1e-3, 1.0, 100.0, 1e5])
def test_binning_reproduces_the_load(statistical, n_elements, load):
    d = solve_separation(statistical, load)
    table = element_table(statistical, d, MU, n_elements)           # no rescaling
    assert len(table) == n_elements
    carried = float(np.sum(table.asperities * hertz(table.interference)))
    assert carried == pytest.approx(gaussian_tail_moment(d, 1.5) * 4 / 3 * E_STAR * math.sqrt(R), rel=1e-6)
    # The two-point rules make count, stiffness and area exact as well.
    assert table.asperities.sum() == pytest.approx(gaussian_tail_moment(d, 0.0), rel=1e-9)
    assert table.stiffness.sum() == pytest.approx(
        8 * G_STAR * math.sqrt(R) * gaussian_tail_moment(d, 0.5), rel=1e-9
    )
    assert np.sum(table.asperities * table.interference) == pytest.approx(
        gaussian_tail_moment(d, 1.0), rel=1e-9
    )
    assert np.all(np.diff(table.heights) > 0) and np.all(table.interference > 0)
    assert np.all(table.asperities > 0)


@pytest.mark.parametrize("n_elements", [1, 3, 7, 65])
def test_odd_element_counts_keep_the_load(statistical, n_elements):
    d = 1.3 * SIGMA
    table = element_table(statistical, d, MU, n_elements)
    assert len(table) == n_elements
    assert table.normal_load == pytest.approx(float(statistical.normal_load(d)), rel=1e-9)
    assert table.asperities.sum() == pytest.approx(float(statistical.contacts(d)), rel=1e-9)


@pytest.mark.parametrize("load", np.geomspace(1e-6, 3e6, 23))
def test_amontons_is_exact(statistical, direct, load):
    for surface in (statistical, direct):
        if load > surface.load_range[1]:
            continue
        d = solve_separation(surface, load)
        table = element_table(surface, d, MU, 64, normal_load=load)
        assert abs(table.breakaway_force.sum() - MU * load) <= 1e-9 * MU * load


def test_element_formulas_against_direct_evaluation(statistical, direct):
    for surface in (statistical, direct):
        d = solve_separation(surface, 25.0)
        table = element_table(surface, d, MU, 64, normal_load=25.0)
        delta = table.heights - d
        np.testing.assert_array_equal(table.interference, delta)
        np.testing.assert_allclose(table.stiffness, table.asperities * 8 * G_STAR * np.sqrt(R * delta), rtol=1e-14)
        np.testing.assert_allclose(table.breakaway_force, table.asperities * MU * hertz(delta), rtol=1e-14)
        # The presliding virgin curve is the direct sum of elastic-slip laws.
        u = np.array([-3e-7, -1e-9, 0.0, 2e-9, 5e-8, 1e-6])
        expected = [np.sign(x) * np.sum(np.minimum(table.stiffness * abs(x), table.breakaway_force)) for x in u]
        np.testing.assert_allclose(table.virgin_force(u), expected, rtol=1e-14)
        assert float(table.virgin_force(1.0)) == pytest.approx(MU * 25.0, rel=1e-9)


def test_direct_table_is_one_element_per_summit_in_contact(direct):
    d = solve_separation(direct, 10.0)
    table = element_table(direct, d, MU)
    above = np.sort(direct.heights[direct.heights > d])
    np.testing.assert_array_equal(table.heights, above)
    np.testing.assert_array_equal(table.asperities, np.ones(above.size))
    assert table.normal_load == pytest.approx(10.0, rel=1e-10)


def test_element_properties_follow_the_separation(statistical):
    d = solve_separation(statistical, 100.0)
    table = element_table(statistical, d, MU, 64, normal_load=100.0)
    k, W = table.properties_at(d)
    np.testing.assert_array_equal(k, table.stiffness)
    np.testing.assert_array_equal(W, table.breakaway_force)
    # Lift the flat: elements at or below it carry nothing, the rest follow P(h - d).
    lifted = float(table.heights[20])
    out_k, out_W = np.full(64, np.nan), np.full(64, np.nan)
    element_properties(table.heights, table.asperities, lifted, R, E_STAR, G_STAR, MU, out_k, out_W)
    assert np.all(out_k[:21] == 0.0) and np.all(out_W[:21] == 0.0)
    delta = table.heights[21:] - lifted
    np.testing.assert_allclose(out_k[21:], table.asperities[21:] * 8 * G_STAR * np.sqrt(R * delta), rtol=1e-14)
    np.testing.assert_allclose(out_W[21:], table.asperities[21:] * MU * hertz(delta), rtol=1e-14)


def test_table_as_surface_keeps_amontons_under_a_varying_load(statistical):
    peak = 150.0
    d = solve_separation(statistical, peak)
    table = element_table(statistical, d, MU, 64, normal_load=peak)
    loads = np.linspace(50.0, peak, 11)
    separations = solve_separation_series(table.as_surface(), loads)
    for load, x in zip(loads, separations):
        _, W = table.properties_at(x)
        assert W.sum() == pytest.approx(MU * load, rel=1e-9)


def _contact_parameters(change=None):
    """The default Pol-Ind table (its own example) with ``change`` merged into its tables."""
    params = PolInd.example_parameters()
    for key, value in (change or {}).items():
        if isinstance(value, dict) and isinstance(params.get(key), dict):
            params[key].update(value)
        else:
            params[key] = value
    return params


def test_default_contact_summary():
    contact = build_contact(_contact_parameters())
    summary = contact.summary()
    assert set(summary) == {"separation", "contacts", "real_area", "normal_load", "elements", "validity"}
    assert set(summary["validity"]) == {"plasticity_index", "plastic_contact_share", "plastic_load_share",
                                        "mean_real_pressure", "peak_asperity_pressure", "unmatched_load"}
    assert json.loads(json.dumps(summary)) == summary
    assert summary["normal_load"] == 100.0
    assert len(summary["elements"]) == 64
    assert set(summary["elements"][0]) == {"stiffness", "breakaway_force", "asperities", "interference"}
    surface = StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR)
    assert float(surface.normal_load(summary["separation"])) == pytest.approx(100.0, rel=1e-10)
    assert summary["contacts"] == pytest.approx(float(surface.contacts(summary["separation"])), rel=1e-12)
    assert summary["real_area"] == pytest.approx(float(surface.real_area(summary["separation"])), rel=1e-12)
    assert sum(e["breakaway_force"] for e in summary["elements"]) == pytest.approx(15.0, rel=1e-12)


def test_direct_contact_from_seed_and_from_file(tmp_path):
    params = _contact_parameters()
    params["nominal_area"] = 1.0            # not a contact key: ignored
    params["surface"]["nominal_area"] = 2e-6
    params["discretisation"]["summation"] = "direct"
    params["normal_load"] = 1.0
    seeded = build_contact(params)
    assert seeded.surface.asperity_count == 20000
    assert seeded.elements.normal_load == pytest.approx(1.0, rel=1e-10)
    heights = seeded.surface.heights[::-1]
    (tmp_path / "summits.csv").write_text("h\n" + "\n".join(repr(float(h)) for h in heights) + "\n")
    params["discretisation"]["heights_file"] = "summits.csv"
    measured = build_contact(params, base_dir=tmp_path)
    assert measured.separation == pytest.approx(seeded.separation, rel=1e-12, abs=1e-20)
    assert len(measured.elements) == len(seeded.elements)


@pytest.mark.parametrize(
    "change, match",
    [
        ({"normal_load": -1.0}, "'normal_load'"),
        ({"static_coefficient": 0.0}, "'static_coefficient'"),
        ({"surface": {"height_std": -1e-6}}, "'surface.height_std'"),
        ({"surface": 3}, "'surface' of pol-ind must be a table"),
        ({"materials": {"youngs_modulus": [210e9]}}, "'materials.youngs_modulus'"),
        ({"materials": {"poisson_ratio": [0.3, 0.7]}}, "'materials.poisson_ratio\\[1\\]'"),
        ({"discretisation": {"summation": "fractal"}}, "'discretisation.summation'"),
        ({"discretisation": {"elements": 0}}, "'discretisation.elements'"),
        ({"discretisation": {"elements": 64.5}}, "'discretisation.elements'"),
        ({"discretisation": {"heights_file": "x.csv"}}, "only read with"),
        ({"discretisation": {"summation": "direct", "seed": "zero"}, "surface": {"nominal_area": 1e-8}},
         "'discretisation.seed'"),
        ({"discretisation": {"summation": "direct", "heights_file": "missing.csv"}}, "missing.csv"),
        ({"normal_load": 1e9}, "too large"),
    ],
)
def test_bad_contact_parameters(change, match):
    with pytest.raises(InputError, match=match):
        build_contact(_contact_parameters(change))


@pytest.mark.parametrize("table, key", [(None, "normal_load"), ("surface", "height_std"),
                                        ("materials", "poisson_ratio")])
def test_a_missing_contact_key_is_named(table, key):
    params = _contact_parameters()
    del (params if table is None else params[table])[key]
    with pytest.raises(InputError, match=f"Missing key '{key if table is None else f'{table}.{key}'}'"):
        build_contact(params)


@pytest.mark.parametrize("seed", range(4))
def test_the_tables_numpy_properties_are_the_kernels_to_the_bit(seed):
    # The table is built with NumPy (no compilation); the kernels re-evaluate it at a new
    # load with element_properties: the same bits, or a run would jump at its first load.
    from polind.contact.elements import _hertz_properties

    rng = np.random.default_rng(seed)
    heights = rng.normal(0.0, 5e-7, 500)
    counts = rng.uniform(0.0, 1e6, 500)
    d = float(rng.normal(0.0, 5e-7))
    moduli = (float(rng.uniform(5e-5, 1e-4)), 1.15e11 * rng.uniform(0.5, 2.0),
              2.4e10 * rng.uniform(0.5, 2.0), float(rng.uniform(0.05, 0.5)))
    numpy_k, numpy_W, kernel_k, kernel_W = (np.full(500, np.nan) for _ in range(4))
    _hertz_properties(heights, counts, d, *moduli, numpy_k, numpy_W)
    element_properties(heights, counts, d, *moduli, kernel_k, kernel_W)
    assert 0 < np.count_nonzero(numpy_k) < 500
    assert numpy_k.tobytes() == kernel_k.tobytes()
    assert numpy_W.tobytes() == kernel_W.tobytes()
