"""A ball on a flat under a varying normal load: the nominal area follows the load.

``[model.surface] ball_radius = R_b`` makes the nominal area the ball's Hertz
contact, ``A0(N) = pi (3 N R_b / (4 E*))^(2/3)``, at every load of a run; the
summit counts scale with it.  References, each independent of the kernels
under test:

- the ball's area written out here (:func:`ball_area`);
- the Greenwood–Williamson load by ``scipy.integrate.quad`` over the area
  ``A0(N)`` and its separation by ``scipy.optimize.brentq``;
- plain sums of Hertz's law over a map's summits, each with its own radius and
  standing for ``A0(N) / A_map`` summits, and ``brentq``;
- the plain stepper of ``tests/oracles.py`` with the element counts times
  ``A0(N) / A0(N_max)``;
- the constant-load model with ``nominal_area = A0(N)``, which knows nothing
  of a ball.

Without a ball the kernels must compute what they computed before the area
could follow the load, to the bit: checked against the separation solvers and
element functions composed as they were.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
from scipy import integrate, optimize

import oracles
import polind
from polind.contact.materials import effective_moduli
from polind.kernels import plastic, pol_ind_plastic
from polind.kernels import pol_ind as slots
from polind.kernels.elements import ELEMENT_CAPACITY, ELEMENT_STIFFNESS, element_properties
from polind.kernels.plastic_separation import (CRITICAL_FACTOR, PLASTIC_SCALE, SIZE,
                                               YIELD_COEFFICIENT, plastic_lower, plastic_newton)
from polind.kernels.separation import (STATISTICAL, direct_lower_bound, newton_separation,
                                       predicted_start, statistical_separation_only)
from polind.kernels.special import IVE, KVE
from polind.models.pol_ind import default_table
from polind.topography import HeightMap, analyse
from test_topography import gaussian_field

E_STAR, G_STAR = effective_moduli(210e9, 0.3, 210e9, 0.3)
MU_S, MU_K = 0.15, 0.10
# A 6 mm ball on a surface of 1e11 summits/m^2 (R = 20 um, sigma = 0.1 um): at 5 N
# A0 = 6.7e-9 m^2, 666 summits, d = 0.15 sigma; at 0.25 N 90 summits, d = 0.74 sigma.
BALL, ETA, RADIUS, SIGMA, PEAK = 3e-3, 1e11, 20e-6, 0.1e-6, 5.0
PIXEL = (0.5e-6, 0.5e-6)


def ball_area(load, ball_radius=BALL):
    """pi a^2 with a = (3 N R_b / (4 E*))^(1/3)."""
    return math.pi * (3.0 * load * ball_radius / (4.0 * E_STAR)) ** (2.0 / 3.0)


def ball_model(load=PEAK, hardness=None, elements=16, surface=None, **discretisation):
    table = default_table()
    table["normal_load"] = load
    table["surface"] = surface or {"asperity_density": ETA, "asperity_radius": RADIUS,
                                   "height_std": SIGMA, "ball_radius": BALL}
    if "ball_radius" in table["surface"]:
        # These tests are about the nominal area; the bulk's series spring is test_mindlin's.
        table["surface"].setdefault("bulk_compliance", False)
    table["discretisation"] = {"summation": "statistical", "elements": elements, **discretisation}
    if hardness is not None:
        table["materials"]["hardness"] = hardness
    return polind.model_from_dict({"model": table})


def gw_load(d, area):
    """N(d) of the Gaussian surface of nominal area ``area``, by quadrature."""
    f32 = integrate.quad(lambda u: (u - d / SIGMA) ** 1.5 * math.exp(-u * u / 2)
                         / math.sqrt(2 * math.pi), d / SIGMA, np.inf, epsabs=0, epsrel=1e-13)[0]
    return 4 / 3 * ETA * area * E_STAR * math.sqrt(RADIUS) * SIGMA ** 1.5 * f32


def gw_separation(load):
    """d with N(d) = load on the ball's area at that load."""
    area = ball_area(load)
    return optimize.brentq(lambda d: gw_load(d, area) - load, -4 * SIGMA, 8 * SIGMA,
                           xtol=1e-24, rtol=1e-15)


def plain_map_load(d, heights, radii, weight):
    delta = heights - d
    touching = delta > 0
    return weight * 4 / 3 * E_STAR * float(np.sum(np.sqrt(radii[touching])
                                                   * delta[touching] ** 1.5))


def map_separation(load, heights, radii, weight):
    return optimize.brentq(lambda d: plain_map_load(d, heights, radii, weight) - load,
                           heights.min(), heights.max(), xtol=1e-24,
                           rtol=4 * np.finfo(float).eps)


@pytest.fixture(scope="module")
def rough_map(tmp_path_factory):
    """A 160 x 160 Gaussian random surface (rms 50 nm) as a .npy grid, and its analysis."""
    heights, _, _ = gaussian_field(160, PIXEL, 2.5e-6, 50e-9, seed=5)
    path = tmp_path_factory.mktemp("ball") / "rough.npy"
    np.save(path, heights)
    return path, analyse(HeightMap.from_array(heights, PIXEL, "rough.npy"))


def map_ball_model(path, load, hardness=None, nominal_area=None):
    surface = {"topography": str(path), "pixel_size": list(PIXEL)}
    if nominal_area is None:
        surface["ball_radius"] = BALL
        surface["bulk_compliance"] = False     # the nominal area only (as ball_model)
    else:
        surface["nominal_area"] = nominal_area
    table = default_table()
    table["normal_load"] = load
    table["surface"] = surface
    table["discretisation"] = {}
    if hardness is not None:
        table["materials"]["hardness"] = hardness
    return polind.model_from_dict({"model": table})


def kernel_at(model, loads):
    """The model's kernel arrays for a run over ``loads`` (its table at their largest)."""
    return model.step_kernel(normal_load=np.asarray(loads, dtype=float))


# --- the kernel at each load -------------------------------------------------------------------

def test_the_kernel_solves_each_load_on_the_balls_area():
    model = ball_model()
    loads = [PEAK, 3.0, 1.0, 0.25, 4.0]
    kernel = kernel_at(model, loads)
    assert kernel.scalars[slots.BALL_LOAD] == PEAK
    table = model.element_table(PEAK)
    n = len(table)
    for load in loads:
        slots.set_load_apart(kernel.scalars, kernel.table, kernel.state, load)
        d = kernel.scalars[slots.SEPARATION]
        want = gw_separation(load)
        assert d == pytest.approx(want, rel=1e-10, abs=1e-12 * SIGMA)
        # The counts follow the area: r = A0(N) / A0(N_max) times the table's.
        counts = table.asperities * ball_area(load) / ball_area(PEAK)
        delta = np.maximum(table.heights - want, 0.0)
        np.testing.assert_allclose(kernel.table[ELEMENT_STIFFNESS],
                                   counts * 8 * G_STAR * np.sqrt(RADIUS * delta),
                                   rtol=1e-9, atol=1e-9 * np.max(kernel.table[ELEMENT_STIFFNESS]))
        np.testing.assert_allclose(kernel.table[slots.ELEMENT_SCRATCH],
                                   counts * MU_S * 4 / 3 * E_STAR * np.sqrt(RADIUS) * delta ** 1.5,
                                   rtol=1e-9,
                                   atol=1e-9 * np.max(kernel.table[slots.ELEMENT_SCRATCH]))
        # The capacities sum to mu_s N (Amontons), whatever the area.
        assert np.sum(kernel.table[ELEMENT_CAPACITY] * MU_S * load) == pytest.approx(
            MU_S * load, rel=1e-14)
        # And the model at that constant load with nominal_area = A0(N) has that separation.
        plain = ball_model(load, surface={"asperity_density": ETA, "asperity_radius": RADIUS,
                                          "height_std": SIGMA, "nominal_area": ball_area(load)})
        assert plain.contact().separation == pytest.approx(d, rel=1e-10, abs=1e-12 * SIGMA)
        assert model.contact(load).separation == pytest.approx(d, rel=1e-10, abs=1e-12 * SIGMA)
        assert kernel.state[3 * n:4 * n].tolist() == table.contact_weights.tolist()


def test_a_sampled_ball_surface_scales_the_summits_drawn_at_the_table_load():
    """Direct summation from a seed: the summits are drawn at the table load's area."""
    model = ball_model(summation="direct", seed=3)
    kernel = kernel_at(model, [PEAK, 1.0])
    surface = model.contact(PEAK).surface
    assert surface.asperity_count == round(ETA * ball_area(PEAK))
    for load in (2.0, 0.5, PEAK):
        slots.set_load_apart(kernel.scalars, kernel.table, kernel.state, load)
        weight = ball_area(load) / ball_area(PEAK)
        want = map_separation(load, surface.heights, np.full(surface.heights.size, RADIUS),
                              weight)
        assert kernel.scalars[slots.SEPARATION] == pytest.approx(want, rel=1e-9,
                                                                  abs=1e-11 * SIGMA)


# --- runs under a varying load -------------------------------------------------------------

def test_a_varying_load_on_a_ball_follows_the_plain_stepper():
    model = ball_model()
    t = np.linspace(0.0, 0.3, 601)
    x = 3e-8 * np.sin(2 * np.pi * 8 * t) + 2e-8 * t      # presliding loops, v << vs
    x[150:200] = x[150]                          # standing while the load changes
    load = PEAK * (0.55 + 0.45 * np.sin(2 * np.pi * 6 * t))   # 0.5 N to 5 N
    load[250:330] = load[250]                    # moving at an unchanged load
    load[480:483] = 0.3
    load[483:490:2] = 4.5                        # alternating jumps
    got = polind.simulate(model, t, x=x, normal_load=load).force
    table = model.element_table(float(load.max()))
    want = oracles.pol_ind_varying_load(
        t, x, load, table.heights, table.asperities * math.sqrt(RADIUS), gw_separation, G_STAR,
        MU_S, MU_K, count_scale=lambda n: ball_area(n) / ball_area(float(load.max())))
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-8 * MU_S * PEAK)
    # Without the area following the load the stiffness would be another: the run did
    # presliding at loads far from the table's.
    fixed = oracles.pol_ind_varying_load(
        t, x, load, table.heights, table.asperities * math.sqrt(RADIUS), gw_separation, G_STAR,
        MU_S, MU_K)
    assert np.max(np.abs(fixed - want)) > 1e-3 * MU_S * PEAK
    # One sample at a time is the same run (its table built at the run's largest load).
    stepper = polind.Stepper(model.with_params(normal_load=float(load.max())), time=t[0],
                             position=x[0])
    stepped = [stepper.advance(tk, x=xk, normal_load=nk)
               for tk, xk, nk in zip(t[1:].tolist(), x[1:].tolist(), load[1:].tolist())]
    np.testing.assert_allclose(stepped, got[1:], rtol=1e-12, atol=1e-12 * PEAK)


def test_sliding_at_each_load_is_mu_k_n_and_a_chunked_run_equals_one_run():
    model = ball_model(elements=32)
    t = np.linspace(0.0, 0.4, 801)
    v = np.full_like(t, 1e-2)                     # ten Stribeck velocities
    load = np.where(t < 0.1, PEAK, np.where(t < 0.2, 1.0, np.where(t < 0.3, 0.3, 2.5)))
    res = polind.simulate(model, t, v=v, normal_load=load)
    for end in (199, 399, 599, 800):              # the last sample of each plateau
        assert res.force[end] == pytest.approx(
            load[end] * (MU_K + (MU_S - MU_K) * math.exp(-100.0)), rel=1e-9)
    x = 3e-8 * np.sin(2 * np.pi * 5 * t) + 1e-4 * t
    load = PEAK * (0.6 + 0.4 * np.cos(2 * np.pi * 3 * t))    # the peak in the first chunk
    whole = polind.simulate(model, t, x=x, normal_load=load)
    forces, state = [], None
    for lo, hi in [(0, 300), (299, 550), (549, 801)]:
        part = polind.simulate(model, t[lo:hi], x=x[lo:hi], state=state, normal_load=load[lo:hi])
        state = polind.State.from_dict(json.loads(json.dumps(part.final_state.to_dict())))
        forces.append(part.force if not forces else part.force[1:])
    np.testing.assert_allclose(np.concatenate(forces), whole.force, rtol=1e-10,
                               atol=1e-12 * PEAK)
    # The table-load rule stands: a later chunk may not pass the table's load.
    with pytest.raises(polind.InputError, match=r"built for at most 5\.0 N"):
        polind.simulate(model, t[-1] + np.array([0.0, 1e-3, 2e-3]), x=np.full(3, x[-1]),
                        state=state, normal_load=np.full(3, 1.01 * PEAK))


@pytest.mark.parametrize("hardness", [None, 2e9])
def test_a_map_under_a_ball_from_rest_at_each_load_is_the_model_of_that_area(rough_map, hardness):
    """Exact where it can be: every summit of a map is an element of its own.

    The run stands at the largest load for its first sample, then moves from
    rest at a lower load ``N``: the summits in contact are the elements of
    the model built at ``N`` with ``nominal_area = A0(N)``, with the same
    counts, so the forces agree to the separation's tolerance.
    """
    path, measured = rough_map
    peak = 0.05
    model = map_ball_model(path, peak, hardness)
    assert model.plastic == (hardness is not None)
    t = np.linspace(0.0, 0.05, 201)
    x = np.concatenate([[0.0], 2e-8 * np.sin(2 * np.pi * 40 * t[1:]) ** 2])
    x[1] = 0.0
    heights = measured.summit_heights - np.mean(measured.summit_heights)
    for load in (0.04, 0.01, 0.002):
        loads = np.full_like(t, load)
        loads[0] = peak
        got = polind.simulate(model, t, x=x, normal_load=loads).force
        plain = map_ball_model(path, load, hardness, nominal_area=ball_area(load))
        want = polind.simulate(plain, t, x=x).force
        np.testing.assert_allclose(got[1:], want[1:], rtol=1e-8, atol=1e-10 * MU_S * load)
        assert np.max(np.abs(want)) > 0.1 * MU_S * load       # it did slide
        if hardness is None:
            # The separation itself, against the plain sum over the summits.
            kernel = kernel_at(model, loads)
            slots.set_load_apart(kernel.scalars, kernel.table, kernel.state, load)
            weight = ball_area(load) / measured.nominal_area
            want_d = map_separation(load, heights, np.asarray(measured.summit_radii), weight)
            assert kernel.scalars[slots.SEPARATION] == pytest.approx(want_d, rel=1e-9,
                                                                      abs=1e-12)


def test_a_hardness_model_under_a_ball_solves_each_load_on_its_area():
    model = ball_model(hardness=3e9)
    assert model.plastic
    loads = [PEAK, 2.0, 0.4, 3.0]
    kernel = kernel_at(model, loads)
    n = kernel.table.shape[1]
    rows = (kernel.state[2 * n:3 * n], kernel.state[3 * n:4 * n],
            kernel.table[pol_ind_plastic.ELEMENT_ASPERITIES],
            kernel.table[pol_ind_plastic.ELEMENT_RADIUS])
    for load in loads:
        pol_ind_plastic.plastic_set_load(kernel.scalars, kernel.table, kernel.state, load)
        plain = ball_model(load, hardness=3e9,
                           surface={"asperity_density": ETA, "asperity_radius": RADIUS,
                                    "height_std": SIGMA, "nominal_area": ball_area(load)})
        d = plain.contact().separation
        assert kernel.scalars[slots.SEPARATION] == pytest.approx(d, rel=1e-9, abs=1e-12 * SIGMA)
        # The rows: r times those of the table's counts at d (the elastic-plastic law).
        ratio = ball_area(load) / ball_area(PEAK)
        stiffness, capacity = np.empty(n), np.empty(n)
        surface = kernel.scalars[pol_ind_plastic.PLASTIC_SURFACE:]
        plastic.plastic_element_properties(
            *rows, d, RADIUS, E_STAR, G_STAR, MU_S, surface[CRITICAL_FACTOR],
            surface[PLASTIC_SCALE], surface[YIELD_COEFFICIENT], stiffness, capacity)
        np.testing.assert_allclose(kernel.table[ELEMENT_STIFFNESS], ratio * stiffness,
                                   rtol=1e-8, atol=1e-9 * np.max(stiffness))
        np.testing.assert_allclose(kernel.table[slots.ELEMENT_SCRATCH], ratio * capacity,
                                   rtol=1e-8, atol=1e-9 * np.max(capacity))
    # Some elements passed yield at the table load: the law is not Hertz's there.
    assert model.contact(PEAK).validity()["plastic_contact_share"] > 0.0
    # And a run under a varying load goes through.
    t = np.linspace(0.0, 0.1, 201)
    res = polind.simulate(model, t, x=2e-8 * np.sin(2 * np.pi * 20 * t) + 1e-4 * t,
                          normal_load=PEAK * (0.5 + 0.5 * np.cos(2 * np.pi * 10 * t)) + 0.1)
    assert np.all(np.isfinite(res.force))
    assert np.all(np.abs(res.force) <= MU_S * res.normal_load * (1 + 1e-12))


# --- the loads a ball model accepts ------------------------------------------------------------

def test_the_smallest_load_follows_the_balls_area():
    model = ball_model()
    state = model.initial_state()
    low, high = model.load_bounds(state)
    # N / r(N) = N^(1/3) N_t^(2/3) must reach the smallest load of the table load's surface.
    smallest = model.contact(PEAK).surface.load_range[0]
    assert high == PEAK
    assert low == pytest.approx(smallest ** 3 / PEAK ** 2, rel=1e-12)
    assert low < smallest
    t = np.linspace(0.0, 0.01, 3)
    with pytest.raises(polind.InputError, match=r"too small for its surface.*index 2"):
        polind.simulate(model, t, x=1e-9 * t, normal_load=[PEAK, 1.0, 0.5 * low])
    stepper = polind.Stepper(model)
    with pytest.raises(polind.InputError, match="too small for its surface"):
        stepper.advance(0.01, x=0.0, normal_load=0.5 * low)
    # And a ball model no longer refuses a varying load.
    polind.simulate(model, t, x=1e-9 * t, normal_load=[PEAK, 1.0, 0.5])


# --- without a ball, the kernels are what they were --------------------------------------------

def no_ball_models(rough_map):
    path, _ = rough_map
    models = {}
    for hardness in (None, 3e9):
        table = default_table()
        table["discretisation"]["elements"] = 16
        if hardness:
            table["materials"]["hardness"] = hardness
        models[f"statistical-{hardness}"] = polind.model_from_dict({"model": table})
        table = default_table()
        table["surface"]["nominal_area"] = 4e-8
        table["normal_load"] = 0.05
        table["discretisation"] = {"summation": "direct", "seed": 4}
        if hardness:
            table["materials"]["hardness"] = hardness
        models[f"direct-{hardness}"] = polind.model_from_dict({"model": table})
        models[f"map-{hardness}"] = map_ball_model(path, 0.05, hardness, nominal_area=1e-8)
    return models


def test_without_a_ball_the_load_step_is_the_solver_and_element_law_as_they_were(rough_map):
    """Bit for bit: the separation and rows are the solvers' and element laws' own numbers.

    Composed here from the functions the load step called before a ball could
    scale it (the load itself solved, ``G*`` and ``mu_s`` as given).  A measured
    map's separation is the plain Newton solver's to 1e-10 (the load step sums
    the load from the element rows it fills), and its rows are the element
    law's at that separation, bit for bit.
    """
    for name, model in no_ball_models(rough_map).items():
        peak = model.params["normal_load"]
        loads = [peak, 0.7 * peak, 0.2 * peak, 0.9 * peak]
        kernel = kernel_at(model, loads)
        scalars, table, state = kernel.scalars, kernel.table, kernel.state
        assert scalars[slots.BALL_LOAD] == 0.0, name
        n = table.shape[1]
        heights, counts = state[2 * n:3 * n].copy(), state[3 * n:4 * n].copy()
        R, E, G, mu = (scalars[key] for key in (slots.RADIUS, slots.E_STAR, slots.G_STAR,
                                                slots.STATIC_COEFFICIENT))
        for load in loads[1:]:
            before = scalars.copy()
            if model.plastic:
                pol_ind_plastic.plastic_set_load(scalars, table, state, load)
                surface = before[pol_ind_plastic.PLASTIC_SURFACE:
                                 pol_ind_plastic.PLASTIC_SURFACE + SIZE]
                asperities = table[pol_ind_plastic.ELEMENT_ASPERITIES]
                radii = table[pol_ind_plastic.ELEMENT_RADIUS]
                start = predicted_start(before[slots.SEPARATION], before[slots.LOAD_VALUE],
                                        before[slots.LOAD_SLOPE], load)
                lower = plastic_lower(load, before[slots.LOWER], surface, heights, asperities,
                                      radii)
                d = plastic_newton(load, start, lower, before[slots.UPPER], surface, heights,
                                   counts, asperities, radii)[0]
                # As for a measured map below: the same root within the solver's tolerance, its rows bit for bit.
                assert scalars[slots.SEPARATION] == pytest.approx(d, rel=1e-10, abs=0.0), \
                    (name, load)
                d = scalars[slots.SEPARATION]
                stiffness, capacity = np.empty(n), np.empty(n)
                plastic.plastic_element_properties(
                    heights, counts, asperities, radii, d, R, E, G, mu, surface[CRITICAL_FACTOR],
                    surface[PLASTIC_SCALE], surface[YIELD_COEFFICIENT], stiffness, capacity)
            else:
                slots.set_load_apart(scalars, table, state, load)
                if before[slots.SURFACE_KIND] == STATISTICAL:
                    d = statistical_separation_only(
                        load, before[slots.LOWER], before[slots.UPPER], before[slots.LOAD_SCALE],
                        before[slots.HEIGHT_STD], before[slots.ADDRESSES + KVE],
                        before[slots.ADDRESSES + IVE])
                else:
                    start = predicted_start(before[slots.SEPARATION], before[slots.LOAD_VALUE],
                                            before[slots.LOAD_SLOPE], load)
                    d = newton_separation(
                        load, start, direct_lower_bound(load, heights, counts, before[slots.HERTZ]),
                        before[slots.UPPER], before[slots.SURFACE_KIND], before[slots.LOAD_SCALE],
                        before[slots.HEIGHT_STD], heights, counts, before[slots.HERTZ],
                        before[slots.ADDRESSES:slots.ADDRESSES + 2])[0]
                # The load step's Newton evaluates the load as the sum of the element
                # rows it fills (one pass): the same root within the solver's tolerance (1e-10), the
                # sum taken in another order; the rows are the element law's at its root.
                assert scalars[slots.SEPARATION] == pytest.approx(d, rel=1e-10, abs=0.0), \
                    (name, load)
                d = scalars[slots.SEPARATION]
                stiffness, capacity = np.empty(n), np.empty(n)
                element_properties(heights, counts, d, R, E, G, mu, stiffness, capacity)
            assert scalars[slots.SEPARATION] == d, (name, load)
            assert table[ELEMENT_STIFFNESS].tolist() == stiffness.tolist(), (name, load)
            assert table[slots.ELEMENT_SCRATCH].tolist() == capacity.tolist(), (name, load)
            total = math.fsum(capacity)
            assert table[ELEMENT_CAPACITY].tolist() == pytest.approx(
                (capacity / total).tolist(), rel=1e-14), (name, load)
