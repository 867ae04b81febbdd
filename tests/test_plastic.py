"""Elastic-plastic asperities and the validity figures (MODELS.md 7.9; INTERFACE.md ``hardness``).

References, each independent of the code under test:
- the Kogut–Etsion table and the Chang–Etsion–Bogy yield inception written
  out here from the formulas (:func:`ke`);
- ``scipy.integrate.quad`` of that law times the Gaussian for the
  statistical surface (split at the kinks);
- plain Python sums over summits, each with its own radius, and
  ``scipy.optimize.brentq`` for the separation;
- the plain stepper of ``tests/oracles.py`` with the law above for a
  time-varying normal load;
- the Hertzian model itself, which a hardness of 1e30 must reproduce to
  the bit.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate, optimize

import oracles
import polind
from polind.contact import Plasticity, build_contact, elastic_plastic_area, elastic_plastic_load
from polind.contact.elements import element_table
from polind.contact.materials import effective_moduli
from polind.contact.separation import solve_separation, solve_separation_series
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.identification.parameters import fittable_keys
from polind.models.pol_ind import default_table

ETA, A0, R, SIGMA = 1e10, 1e-4, 50e-6, 0.5e-6
NU = 0.3
E_STAR, G_STAR = effective_moduli(210e9, NU, 210e9, NU)
MU = 0.15


def ke(delta, radius, hardness, nu=NU, e_star=E_STAR):
    """Load [N] and area [m^2] of one asperity: Hertz to w_c, then Kogut–Etsion (MODELS.md 7.9)."""
    K = 0.454 + 0.41 * nu
    w_c = (math.pi * K * hardness / (2 * e_star)) ** 2 * radius
    P_c = 2 / 3 * math.pi * K * hardness * radius * w_c
    A_c = math.pi * radius * w_c
    if delta <= 0:
        return 0.0, 0.0
    w = delta / w_c
    if w <= 1:
        return P_c * w ** 1.5, A_c * w
    if w <= 6:
        return P_c * 1.03 * w ** 1.425, A_c * 0.93 * w ** 1.136
    if w <= 110:
        return P_c * 1.40 * w ** 1.263, A_c * 0.94 * w ** 1.146
    return P_c * 3 / K * w, A_c * 2 * w


def critical(radius, hardness, nu=NU):
    K = 0.454 + 0.41 * nu
    return (math.pi * K * hardness / (2 * E_STAR)) ** 2 * radius


def statistical_reference(d, hardness, quantity):
    """eta A0 ∫_d^∞ f(h - d) Phi(h) dh by quad in sigma units, split at the kinks."""
    s = d / SIGMA
    w_c = critical(R, hardness)

    def per_asperity(delta):
        load, area = ke(delta, R, hardness)
        return {"load": load, "area": area, "count": 1.0,
                "stiffness": 8 * G_STAR * math.sqrt(area / math.pi),
                "plastic_load": load if delta > w_c else 0.0,
                "plastic_count": 1.0 if delta > w_c else 0.0}[quantity]

    phi = lambda t: math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi)  # noqa: E731
    end = math.sqrt(max(s, 0.0) ** 2 + 200.0) - s
    edges = sorted({0.0, end, *(k * w_c / SIGMA for k in (1, 6, 110) if k * w_c / SIGMA < end)})
    return ETA * A0 * sum(
        integrate.quad(lambda x: per_asperity(SIGMA * x) * phi(s + x), a, b, epsabs=0.0,
                       epsrel=1e-13, limit=400)[0]
        for a, b in zip(edges[:-1], edges[1:]))


@pytest.fixture(scope="module", params=[2e9, 8e9])
def plastic_surface(request):
    hardness = request.param
    surface = StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR).with_plasticity(
        Plasticity(hardness, NU))
    return hardness, surface


# --- one asperity -----------------------------------------------------------------------------

def test_yield_inception_is_chang_etsion_bogy_and_continuous_with_hertz():
    plasticity = Plasticity(3e9, NU)
    assert plasticity.yield_coefficient == pytest.approx(0.454 + 0.41 * NU)
    w_c = float(plasticity.critical_interference(R, E_STAR))
    assert w_c == pytest.approx((math.pi * 0.577 * 3e9 / (2 * E_STAR)) ** 2 * R, rel=1e-12)
    # At w_c the yield load is Hertz's load and A_c is Hertz's area.
    hertz = 4 / 3 * E_STAR * math.sqrt(R) * w_c ** 1.5
    assert 2 / 3 * math.pi * 0.577 * 3e9 * R * w_c == pytest.approx(hertz, rel=1e-12)
    assert float(elastic_plastic_load(w_c, R, E_STAR, plasticity)) == pytest.approx(hertz, rel=1e-12)
    assert float(elastic_plastic_area(w_c, R, E_STAR, plasticity)) == pytest.approx(
        math.pi * R * w_c, rel=1e-12)


@pytest.mark.parametrize("w", [0.25, 1.0, 1.0 + 1e-9, 3.0, 6.0, 6.5, 40.0, 110.0, 111.0, 2500.0])
@pytest.mark.parametrize("radius", [2e-6, 50e-6])
def test_each_of_the_four_ranges_is_its_formula(w, radius):
    hardness = 2e9
    plasticity = Plasticity(hardness, NU)
    delta = w * critical(radius, hardness)
    load, area = ke(delta, radius, hardness)
    assert float(elastic_plastic_load(delta, radius, E_STAR, plasticity)) == pytest.approx(load, rel=1e-12)
    assert float(elastic_plastic_area(delta, radius, E_STAR, plasticity)) == pytest.approx(area, rel=1e-12)


def test_the_published_fits_jump_at_the_range_boundaries():
    # Used as published: P jumps up by 3 %, 1.6 % and 8.5 % (nu = 0.3) at w = 1, 6, 110.
    plasticity = Plasticity(2e9, NU)
    w_c = critical(R, 2e9)
    for end, jump in ((1.0, 1.03), (6.0, 1.40 * 6 ** 1.263 / (1.03 * 6 ** 1.425)),
                      (110.0, 3 / 0.577 * 110 / (1.40 * 110 ** 1.263))):
        below, above = elastic_plastic_load(end * w_c * np.array([1.0, 1.0 + 1e-12]), R, E_STAR,
                                            plasticity)
        assert above / below == pytest.approx(jump, rel=1e-9)


# --- statistical summation --------------------------------------------------------------------

@pytest.mark.parametrize("s", [-3.0, 0.0, 1.5, 3.0, 5.0])
def test_statistical_totals_agree_with_an_independent_quadrature(plastic_surface, s):
    hardness, surface = plastic_surface
    d = s * SIGMA
    assert float(surface.normal_load(d)) == pytest.approx(statistical_reference(d, hardness, "load"),
                                                          rel=1e-10)
    assert float(surface.real_area(d)) == pytest.approx(statistical_reference(d, hardness, "area"),
                                                        rel=1e-10)
    assert float(surface.plastic_load(d)) == pytest.approx(
        statistical_reference(d, hardness, "plastic_load"), rel=1e-10)
    assert float(surface.plastic_contacts(d)) == pytest.approx(
        statistical_reference(d, hardness, "plastic_count"), rel=1e-10)
    assert float(surface.contacts(d)) == pytest.approx(statistical_reference(d, hardness, "count"),
                                                       rel=1e-10)


def test_the_statistical_slope_is_the_derivative(plastic_surface):
    _, surface = plastic_surface
    d = SIGMA * np.linspace(-4.0, 8.0, 13)
    h = 1e-5 * SIGMA
    numeric = (surface.normal_load(d + h) - surface.normal_load(d - h)) / (2 * h)
    np.testing.assert_allclose(surface.normal_load_slope(d), numeric, rtol=1e-7)
    for x in d[::4]:
        value, slope = surface.load_and_slope(float(x))
        assert value == float(surface.normal_load(x)) and slope == float(surface.normal_load_slope(x))


@pytest.mark.parametrize("load", [1e-3, 1.0, 100.0, 1e4])
def test_the_statistical_separation_carries_the_load(plastic_surface, load):
    _, surface = plastic_surface
    d = solve_separation(surface, load)
    assert float(surface.normal_load(d)) == pytest.approx(load, rel=1e-10)
    hertzian = solve_separation(StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR), load)
    assert d < hertzian                      # yielded summits carry less: the flat comes closer
    loads = load * (1.0 + 0.3 * np.sin(np.linspace(0.0, 6.0, 40)))
    separations = solve_separation_series(surface, loads)
    np.testing.assert_allclose(surface.normal_load(separations), loads, rtol=1e-10)


@pytest.mark.parametrize("n_elements", [64, 128])
@pytest.mark.parametrize("load", [1e-2, 100.0, 1e4])
def test_the_statistical_element_table_agrees_with_an_independent_quadrature(plastic_surface,
                                                                            n_elements, load):
    hardness, surface = plastic_surface
    d = solve_separation(surface, load)
    table = element_table(surface, d, MU, n_elements)              # no rescaling
    assert len(table) == n_elements
    loads, areas = zip(*(ke(delta, R, hardness) for delta in table.interference))
    carried = float(np.sum(table.asperities * np.array(loads)))
    assert carried == pytest.approx(statistical_reference(d, hardness, "load"), rel=1e-9)
    assert float(np.sum(table.asperities * np.array(areas))) == pytest.approx(
        statistical_reference(d, hardness, "area"), rel=1e-9)
    assert float(table.stiffness.sum()) == pytest.approx(
        statistical_reference(d, hardness, "stiffness"), rel=1e-9)
    assert float(table.asperities.sum()) == pytest.approx(
        statistical_reference(d, hardness, "count"), rel=1e-9)
    # Each element: k_j = n_j 8 G* sqrt(A / pi), W_j = n_j mu_s P.
    np.testing.assert_allclose(table.stiffness, table.asperities * 8 * G_STAR
                               * np.sqrt(np.array(areas) / math.pi), rtol=1e-12)
    np.testing.assert_allclose(table.breakaway_force, MU * table.asperities * np.array(loads),
                               rtol=1e-12)
    scaled = element_table(surface, d, MU, n_elements, normal_load=load)
    assert scaled.breakaway_force.sum() == pytest.approx(MU * load, rel=1e-12)    # Amontons


# --- direct summation: per-summit radii and the jumps -----------------------------------------

def plain_totals(d, heights, radii, counts, hardness):
    """N, A, n, plastic N and plastic n by a plain per-summit loop."""
    load = area = number = plastic_load = plastic_number = 0.0
    for h, radius, count in zip(heights, radii, counts):
        delta = h - d
        if delta <= 0:
            continue
        p, a = ke(delta, radius, hardness)
        load += count * p
        area += count * a
        number += count
        if delta > critical(radius, hardness):
            plastic_load += count * p
            plastic_number += count
    return load, area, number, plastic_load, plastic_number


def test_a_direct_surface_sums_the_law_per_summit_with_its_own_radius():
    rng = np.random.default_rng(7)
    heights = rng.normal(0.0, 2e-7, 400)
    radii = rng.uniform(2e-6, 4e-5, 400)
    counts = rng.uniform(0.5, 3.0, 400)
    heights[10] = heights[20] = heights[30]          # equal heights, three different radii
    hardness = 2e9
    surface = DirectSurface(heights, 1e-5, E_STAR, G_STAR, counts=counts, radii=radii,
                            plasticity=Plasticity(hardness, NU))
    assert surface.heights.size == 398 and surface.plastic_summits[0].size == 400
    for d in (-2e-7, 0.0, 2e-7, 4e-7):
        load, area, number, plastic_load, plastic_number = plain_totals(d, heights, radii, counts,
                                                                        hardness)
        assert plastic_number > 0
        assert float(surface.normal_load(d)) == pytest.approx(load, rel=1e-12)
        assert float(surface.real_area(d)) == pytest.approx(area, rel=1e-12)
        assert float(surface.contacts(d)) == pytest.approx(number, rel=1e-12)
        assert float(surface.plastic_load(d)) == pytest.approx(plastic_load, rel=1e-12)
        assert float(surface.plastic_contacts(d)) == pytest.approx(plastic_number, rel=1e-12)
        # Hertz's weight trick (c_i sqrt(R_i / R) summits of the reference radius) no
        # longer holds beyond yield: w_c grows with R.
        trick = plain_totals(d, heights, np.full(400, 1e-5), counts * np.sqrt(radii / 1e-5),
                             hardness)[0]
        assert abs(trick - load) > 1e-3 * load
    # The slope, between jumps.
    h = 1e-15
    numeric = (surface.normal_load(1e-7 + h) - surface.normal_load(1e-7 - h)) / (2 * h)
    assert float(surface.normal_load_slope(1e-7)) == pytest.approx(float(numeric), rel=1e-5)


def test_the_direct_element_table_has_each_summits_own_law():
    rng = np.random.default_rng(8)
    heights = rng.normal(0.0, 2e-7, 200)
    radii = rng.uniform(2e-6, 4e-5, 200)
    hardness = 3e9
    surface = DirectSurface(heights, 1e-5, E_STAR, G_STAR, radii=radii,
                            plasticity=Plasticity(hardness, NU))
    d = solve_separation(surface, 0.5)
    load = plain_totals(d, heights, radii, np.ones(200), hardness)[0]
    assert load == pytest.approx(0.5, rel=1e-10)
    table = element_table(surface, d, MU)
    order = np.argsort(heights)
    touching = order[heights[order] > d]
    np.testing.assert_array_equal(table.heights, heights[touching])
    np.testing.assert_array_equal(table.radii, radii[touching])
    laws = [ke(heights[i] - d, radii[i], hardness) for i in touching]
    np.testing.assert_allclose(table.breakaway_force, [MU * p for p, _ in laws], rtol=1e-12)
    np.testing.assert_allclose(table.stiffness, [8 * G_STAR * math.sqrt(a / math.pi) for _, a in laws],
                               rtol=1e-12)
    assert table.breakaway_force.sum() == pytest.approx(MU * 0.5, rel=1e-10)
    # The table as a surface carries the same load at the same separation.
    assert float(table.as_surface().normal_load(d)) == pytest.approx(0.5, rel=1e-12)


def test_a_load_inside_a_jump_of_a_direct_sum_stops_at_the_jump_and_is_reported(tmp_path):
    hardness = 2e9
    heights = np.array([-0.4e-6, 0.0, 0.3e-6, 2.0e-6])
    path = tmp_path / "summits.csv"
    path.write_text("h\n" + "\n".join(repr(float(h)) for h in heights) + "\n")
    table = default_table()
    table["materials"]["hardness"] = hardness
    table["surface"] = {"asperity_radius": R}
    table["discretisation"] = {"summation": "direct", "heights_file": str(path)}
    surface = polind.model_from_dict({"model": {**table, "normal_load": 1.0}}).contact().surface
    # The top summit reaches w = 110, where its load jumps up by 8.5 %.
    jump = heights[-1] - 110 * critical(R, hardness)
    step = 1e-3 * critical(R, hardness)
    above, below = (plain_totals(jump + side, heights, np.full(4, R), np.ones(4), hardness)[0]
                    for side in (-step, step))
    assert above > 1.05 * below
    load = 0.5 * (above + below)
    contact = polind.model_from_dict({"model": {**table, "normal_load": load}}).contact()
    sigma = float(np.std(heights))
    assert abs(contact.separation - jump) <= 1e-12 * sigma
    carried = float(surface.normal_load(contact.separation))
    assert contact.unmatched_load == load - carried
    assert 0.01 * load < abs(contact.unmatched_load) < 0.05 * load
    assert contact.validity()["unmatched_load"] == contact.unmatched_load
    # The elements carry N(d) (W = mu_s P of each summit): the unmatched load is not hidden.
    assert contact.elements.breakaway_force.sum() == pytest.approx(MU * carried, rel=1e-12)
    # Away from a jump the load is matched.
    matched = polind.model_from_dict({"model": {**table, "normal_load": 0.8 * load}}).contact()
    assert matched.unmatched_load == 0.0
    assert float(surface.normal_load(matched.separation)) == pytest.approx(0.8 * load, rel=1e-10)


# --- an infinite hardness is the elastic model -------------------------------------------------

def _variants(base):
    for hardness in (None, 1e30):
        table = {**base, "materials": dict(base["materials"])}
        if hardness is not None:
            table["materials"]["hardness"] = hardness
        yield polind.model_from_dict({"model": table})


@pytest.mark.filterwarnings("ignore:The pol-ind contact at")    # the direct sample's 11 GPa
@pytest.mark.parametrize("summation", ["statistical", "direct"])
def test_an_infinite_hardness_is_the_elastic_model_to_the_bit(summation):
    base = default_table()
    if summation == "direct":
        base["surface"]["nominal_area"] = 1e-6
        base["discretisation"] = {"summation": "direct", "seed": 2}
    elastic, hard = _variants(base)
    assert hard.contact().surface.plasticity is not None
    # A statistical surface on which no summit can yield runs the Hertzian step; a direct
    # one runs the elastic-plastic step, which within yield computes what it computes.
    assert hard.plastic == (summation == "direct")
    for name in ("separation", "contacts", "real_area"):
        assert getattr(hard.contact(), name) == getattr(elastic.contact(), name)
    for name in ("stiffness", "breakaway_force", "heights", "asperities"):
        np.testing.assert_array_equal(getattr(hard.element_table(), name),
                                      getattr(elastic.element_table(), name))
    t = np.linspace(0.0, 0.5, 1501)
    x = 2e-6 * np.sin(2 * np.pi * 4 * t) + 1e-3 * t
    load = 100.0 * (0.55 + 0.45 * np.cos(2 * np.pi * 3 * t) ** 2)
    for kwargs in ({}, {"normal_load": load}):
        np.testing.assert_array_equal(polind.simulate(hard, t, x=x, **kwargs).force,
                                      polind.simulate(elastic, t, x=x, **kwargs).force)
    hard_validity, elastic_validity = hard.contact().validity(), elastic.contact().validity()
    assert elastic_validity["plasticity_index"] is None and hard_validity["plasticity_index"] < 1e-19
    for key in ("plastic_contact_share", "plastic_load_share", "mean_real_pressure",
                "peak_asperity_pressure", "unmatched_load"):
        assert hard_validity[key] == elastic_validity[key]


# --- the model: keys, fitting, a varying load --------------------------------------------------

def test_hardness_or_yield_strength_but_not_both():
    table = default_table()
    table["materials"]["yield_strength"] = 1e9
    by_strength = polind.model_from_dict({"model": table})
    table["materials"] = {**default_table()["materials"], "hardness": 2.8e9}
    by_hardness = polind.model_from_dict({"model": table})
    assert by_strength.contact().separation == by_hardness.contact().separation
    table["materials"]["yield_strength"] = 1e9
    with pytest.raises(polind.InputError, match="'materials.hardness' and 'materials.yield_strength'"):
        polind.model_from_dict({"model": table})
    table["materials"] = {**default_table()["materials"], "hardness": -1.0}
    with pytest.raises(polind.InputError, match="'materials.hardness'"):
        polind.model_from_dict({"model": table})
    with pytest.raises(polind.InputError, match="'materials.hardness' and 'materials.yield_strength'"):
        build_contact({**default_table(), "materials": {**default_table()["materials"],
                                                        "hardness": 1e9, "yield_strength": 1e9}})


def test_the_hardness_is_fittable():
    table = default_table()
    table["materials"]["hardness"] = 4e9
    table["attraction"] = 1e9
    model = polind.model_from_dict({"model": table})
    assert {"materials.hardness", "materials.yield_strength"} <= set(fittable_keys(model))
    # Presliding data of H = 4 GPa, fitted from H = 8 GPa.
    t = np.linspace(0.0, 1.0, 401)
    x = 3e-7 * np.sin(2 * np.pi * t)
    force = polind.simulate(model, t, x=x).force
    table["materials"]["hardness"] = 8e9
    start = polind.model_from_dict({"model": table})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = polind.identify(start, {"t": t, "x": x, "F": force}, free=["materials.hardness"])
    assert result.model.params["materials"]["hardness"] == pytest.approx(4e9, rel=1e-6)


@pytest.mark.parametrize("summation", ["statistical", "direct"])
def test_a_time_varying_load_follows_the_rules_with_elastic_plastic_asperities(summation):
    hardness = 3e9
    table = default_table()
    table["materials"]["hardness"] = hardness
    if summation == "direct":
        table["surface"]["nominal_area"] = 4e-8              # 400 summits
        table["normal_load"] = 0.05
        table["discretisation"] = {"summation": "direct", "seed": 4}
    else:
        table["discretisation"]["elements"] = 16
    model = polind.model_from_dict({"model": table})
    assert model.plastic
    peak = table["normal_load"]
    t = np.linspace(0.0, 0.2, 161)
    x = 2e-7 * np.sin(2 * np.pi * 10 * t) + 2e-3 * t
    load = peak * (0.6 + 0.4 * np.sin(2 * np.pi * 7 * t) ** 2 - 0.3 * (t > 0.1))
    got = polind.simulate(model, t, x=x, normal_load=load).force
    elements = model.element_table(float(load.max()))
    surface = model.contact().surface
    if summation == "direct":
        heights, radii = surface.plastic_summits[0], surface.plastic_summits[2]
        ones = np.ones(heights.size)

        def separation_at(n):
            return optimize.brentq(
                lambda d: plain_totals(d, heights, radii, ones, hardness)[0] - n,
                heights[0] - 1e-5, heights[-1], xtol=1e-24, rtol=4 * np.finfo(float).eps)
    else:
        def separation_at(n):
            return optimize.brentq(lambda d: float(surface.normal_load(d)) - n, -5 * SIGMA,
                                   10 * SIGMA, xtol=1e-24, rtol=4 * np.finfo(float).eps)

    def law(delta):
        laws = [ke(value, radius, hardness) for value, radius in zip(delta, elements.radii)]
        stiffness = elements.asperities * 8 * G_STAR * np.sqrt([a / math.pi for _, a in laws])
        return stiffness, elements.asperities * np.array([p for p, _ in laws])

    want = oracles.pol_ind_varying_load(t, x, load, elements.heights, None, separation_at, G_STAR,
                                        mu_s=0.15, mu_k=0.10, element_law=law)
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-8 * 0.15 * peak)


# --- the validity figures ----------------------------------------------------------------------

def test_the_validity_figures_equal_their_formulas():
    for hardness in (None, 6e9):
        table = default_table()
        if hardness is not None:
            table["materials"]["hardness"] = hardness
        contact = polind.model_from_dict({"model": table}).contact()
        figures = contact.validity()
        top = int(np.argmax(contact.elements.heights))
        delta = float(contact.elements.interference[top])
        assert figures["mean_real_pressure"] == pytest.approx(100.0 / contact.real_area, rel=1e-12)
        assert figures["unmatched_load"] == 0.0
        if hardness is None:
            assert figures["plasticity_index"] is None
            assert figures["plastic_contact_share"] == figures["plastic_load_share"] == 0.0
            assert figures["peak_asperity_pressure"] == pytest.approx(
                2 * E_STAR / math.pi * math.sqrt(delta / R), rel=1e-12)
            continue
        assert figures["plasticity_index"] == pytest.approx(E_STAR / hardness * math.sqrt(SIGMA / R),
                                                            rel=1e-12)
        d = contact.separation
        assert figures["plastic_contact_share"] == pytest.approx(
            statistical_reference(d, hardness, "plastic_count")
            / statistical_reference(d, hardness, "count"), rel=1e-9)
        assert figures["plastic_load_share"] == pytest.approx(
            statistical_reference(d, hardness, "plastic_load") / 100.0, rel=1e-9)
        assert delta > critical(R, hardness)
        load, area = ke(delta, R, hardness)
        assert figures["peak_asperity_pressure"] == pytest.approx(load / area, rel=1e-12)


def test_a_hertzian_contact_beyond_10_gpa_warns_and_one_with_a_hardness_does_not():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        polind.models.PolInd.example().contact()                 # the default does not warn
    table = default_table()
    table["surface"]["height_std"] = 5e-6
    with pytest.warns(UserWarning, match="peak_asperity_pressure .* GPa .*'materials.hardness'") as record:
        contact = polind.model_from_dict({"model": table}).contact()
    assert contact.validity()["peak_asperity_pressure"] > 10e9
    assert "mean_real_pressure" in str(record[0].message)
    table["materials"]["hardness"] = 2e9
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        contact = polind.model_from_dict({"model": table}).contact()
    assert contact.validity_warning() is None


def test_a_measured_map_reports_the_plasticity_index_of_its_greenwood_williamson_equivalent(tmp_path):
    from test_topography import gaussian_field

    pixel = (0.5e-6, 0.5e-6)
    heights, _, _ = gaussian_field(128, pixel, 2.5e-6, 50e-9, seed=11)
    np.save(tmp_path / "rough.npy", heights)
    table = default_table()
    table["normal_load"] = 0.05
    table["surface"] = {"topography": str(tmp_path / "rough.npy"), "pixel_size": list(pixel)}
    table["discretisation"] = {}
    table["materials"]["hardness"] = 2e9
    model = polind.model_from_dict({"model": table})
    contact = model.contact()
    gw = contact.surface.greenwood_williamson
    figures = contact.validity()
    assert figures["plasticity_index"] == pytest.approx(
        E_STAR / 2e9 * math.sqrt(gw["height_std"] / gw["asperity_radius"]), rel=1e-9)
    # Peak: the highest summit with its own radius.
    top = int(np.argmax(contact.elements.heights))
    delta, radius = contact.elements.interference[top], contact.elements.radii[top]
    load, area = ke(delta, radius, 2e9)
    expected = load / area if delta > critical(radius, 2e9) else 2 * E_STAR / math.pi * math.sqrt(
        delta / radius)
    assert figures["peak_asperity_pressure"] == pytest.approx(expected, rel=1e-12)
    assert 0.0 < figures["plastic_contact_share"] <= 1.0


def test_a_fit_warns_about_validity_once_for_its_result_not_for_every_trial():
    """A fit tries many models; only the fitted one's validity is reported (once)."""
    import warnings

    import numpy as np

    import polind
    from polind.models import PolInd

    params = PolInd.example_parameters(elements=8)
    params["surface"]["asperity_radius"] = 1e-6        # sharp summits: tens of GPa in Hertz
    truth = PolInd(**params)
    t = np.linspace(0.0, 0.02, 201)
    x = 2e-6 * np.sin(2 * np.pi * 50 * t)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        force = polind.simulate(truth, t, x=x).force
        start = truth.with_params(kinetic_coefficient=0.12)
        fit = polind.identify(start, {"t": t, "x": x, "F": force},
                              free=["kinetic_coefficient"], starts=1)
    validity = [w for w in caught if issubclass(w.category, polind.ValidityWarning)]
    # the truth's run, the start's check and the fitted model: not one per trial
    assert fit.evaluations > 3 and 1 <= len(validity) <= 3
