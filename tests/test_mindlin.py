"""Microslip asperities and the ball's bulk compliance (issue 41; the guide's "Microslip asperities").

References, each from the contact mechanics and not from the table under test:

- Mindlin–Deresiewicz's loop energy of one sphere at the tangential amplitude
  ``Q = q mu P``:
  ``D(q) = (9 mu^2 P^2 / (10 a G*)) [1 - (1 - q)^(5/3) - (5 q / 6)(1 + (1 - q)^(2/3))]``;
- Cattaneo's virgin curve, derived here from the Iwan density
  ``k(phi) = (3 mu P / (4 u*^2)) (1 - phi / u*)^(-1/2)`` on ``(0, u*)``,
  ``u* = 3 mu P / (16 G* a)``: at the displacement ``u <= u*`` the elements
  with ``phi < u`` carry ``k phi``, the others ``k u``, so
  ``Q(u) = int_0^u k phi dphi + u int_u^u* k dphi``; with ``s = phi / u*`` and
  ``k = 4 G* a (1 - s)^(-1/2) / u*``, ``int s (1 - s)^(-1/2) ds = -(2/3)
  sqrt(1 - s) (2 + s)`` gives ``Q = (16/3) G* a u* [1 - (1 - u/u*)^(3/2)]
  = mu P [1 - (1 - u/u*)^(3/2)]``, and ``mu P`` beyond ``u*``;
- Hertz for the summit (``P = (4/3) E* sqrt(R) delta^(3/2)``, ``a = sqrt(R delta)``)
  and for the ball (``a_H = (3 N R_b / (4 E*))^(1/3)``);
- the elastic-slip table of the same model (``tangential`` left out) for the
  element sums.

The loops are simulated (:func:`polind.simulate`) with ``mu_k = mu_s`` and a
large attraction, where Pol-Ind is the Maxwell-slip model of its elements.
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest
import tomli_w
from hypothesis import given, settings, strategies as st

import polind
from polind.models.pol_ind import default_table

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
    from test_topography import gaussian_field
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401
    from tests.test_topography import gaussian_field

E, NU = 210e9, 0.3
E_STAR = 1.0 / (2.0 * (1.0 - NU ** 2) / E)
G_STAR = 1.0 / (2.0 * (2.0 - NU) / (E / (2.0 * (1.0 + NU))))
MU, RADIUS, LOAD = 0.15, 50e-6, 0.1
# One Hertzian summit under LOAD: its interference, contact radius and slip displacement.
DELTA = (3.0 * LOAD / (4.0 * E_STAR * math.sqrt(RADIUS))) ** (2.0 / 3.0)
A = math.sqrt(RADIUS * DELTA)
U_STAR = 3.0 * MU * LOAD / (16.0 * G_STAR * A)

pytestmark = pytest.mark.filterwarnings("ignore::polind.ValidityWarning")


def mindlin_deresiewicz(q):
    """D(q) [J], the formula as published."""
    return 9 * MU ** 2 * LOAD ** 2 / (10 * A * G_STAR) * (
        1 - (1 - q) ** (5 / 3) - (5 * q / 6) * (1 + (1 - q) ** (2 / 3)))


def cattaneo(u):
    """Q(u) [N] of the virgin curve (derived in the module notes)."""
    s = np.minimum(np.abs(u) / U_STAR, 1.0)
    return MU * LOAD * (1.0 - (1.0 - s) ** 1.5)


@pytest.fixture(scope="module")
def one_summit(tmp_path_factory):
    path = tmp_path_factory.mktemp("mindlin") / "one.csv"
    path.write_text("h\n1e-6\n")
    return path


def rate_free(table):
    """Pol-Ind with mu_k = mu_s and C large: the Maxwell-slip model of its elements."""
    table.update(static_coefficient=MU, kinetic_coefficient=MU, attraction=1e8)
    table["materials"] = {"youngs_modulus": [E, E], "poisson_ratio": [NU, NU]}
    return table


def summit_model(path, m=None, tangential="mindlin", **extra):
    table = rate_free(default_table())
    table["normal_load"] = LOAD
    table["surface"] = {"asperity_radius": RADIUS}
    table["discretisation"] = {"summation": "direct", "heights_file": str(path),
                               "tangential": tangential}
    if m is not None:
        table["discretisation"]["microslip_elements"] = m
    table.update(extra)
    return polind.model_from_dict({"model": table})


def loops(model, amplitudes, legs=200):
    """``(Q, D)`` of a symmetric cycle at each displacement amplitude, largest last.

    One record: from rest to the first amplitude, then for each amplitude
    ``+A -> -A -> +A`` (the loop, whose ``Q`` is the force at ``+A``), then on
    to the next (a larger amplitude wipes the smaller loops' memory).
    """
    pieces, cycles, last = [np.zeros(1)], [], 0.0
    for amplitude in amplitudes:
        pieces.append(np.linspace(last, amplitude, legs)[1:])
        start = sum(piece.size for piece in pieces) - 1
        pieces.append(np.linspace(amplitude, -amplitude, 2 * legs)[1:])
        pieces.append(np.linspace(-amplitude, amplitude, 2 * legs)[1:])
        cycles.append((start, sum(piece.size for piece in pieces) - 1))
        last = amplitude
    x = np.concatenate(pieces)
    force = polind.simulate(model, np.arange(x.size) * 1e-3, x=x).force
    out = []
    for start, stop in cycles:
        u, f = x[start:stop + 1], force[start:stop + 1]
        out.append((force[start], float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(u)))))
    return np.array(out)


def amplitudes_for(q):
    """The displacement amplitudes at which Cattaneo's curve reaches ``q mu P``."""
    return U_STAR * (1.0 - (1.0 - np.asarray(q)) ** (2.0 / 3.0))


# --- one summit --------------------------------------------------------------------------------

@pytest.mark.parametrize("m, tolerance", [(None, 0.01), (128, 0.001)])
def test_one_summits_loop_energy_is_mindlin_deresiewicz(one_summit, m, tolerance):
    q = np.geomspace(0.05, 0.95, 15)
    measured = loops(summit_model(one_summit, m), amplitudes_for(q))
    error = measured[:, 1] / mindlin_deresiewicz(measured[:, 0] / (MU * LOAD)) - 1.0
    assert np.all(np.abs(measured[:, 0] / (MU * LOAD) / q - 1.0) < 0.01)   # on the range
    assert np.max(np.abs(error)) <= tolerance, error
    if m is None:
        # Behind a series spring the loop against the force amplitude is the same.
        spring = 8 * G_STAR * A
        sprung = loops(summit_model(one_summit, compliance={"stiffness": spring}),
                       amplitudes_for(q) + q * MU * LOAD / spring)
        np.testing.assert_allclose(sprung[:, 1], mindlin_deresiewicz(sprung[:, 0] / (MU * LOAD)),
                                   rtol=tolerance)


def test_elastic_slip_summit_has_no_loop_below_its_slip_force(one_summit):
    measured = loops(summit_model(one_summit, tangential="elastic-slip"),
                     [0.5 * MU * LOAD / (8 * G_STAR * A)])
    assert abs(measured[0, 1]) <= 1e-12 * MU * LOAD * U_STAR


def test_small_amplitude_slope_is_the_laws_own(one_summit):
    exact = math.log(mindlin_deresiewicz(0.1) / mindlin_deresiewicz(0.05)) / math.log(2.0)
    assert exact == pytest.approx(3.05, abs=0.005)
    measured = loops(summit_model(one_summit), amplitudes_for([0.05, 0.1]))
    slope = math.log(measured[1, 1] / measured[0, 1]) / math.log(measured[1, 0] / measured[0, 0])
    assert slope == pytest.approx(exact, abs=0.05)


@pytest.mark.parametrize("m, tolerance", [(None, 0.0015), (128, 0.0003)])
def test_virgin_curve_is_cattaneos(one_summit, m, tolerance):
    x = np.linspace(0.0, 1.2 * U_STAR, 1201)
    force = polind.simulate(summit_model(one_summit, m), np.arange(x.size) * 1e-3, x=x).force
    assert np.max(np.abs(force - cattaneo(x))) <= tolerance * MU * LOAD
    # Mindlin's initial stiffness 8 G* a, and the slip force mu P beyond u*.
    assert force[1] / x[1] == pytest.approx(8 * G_STAR * A, rel=1e-12)
    assert force[-1] == pytest.approx(MU * LOAD, rel=1e-12)


def test_surface_prints_the_sub_elements_and_u_star(one_summit, tmp_path, capsys):
    path = tmp_path / "one.toml"
    polind.save_model(summit_model(one_summit, 16), path)
    status, out, err = run(capsys, "surface", path)
    assert status == 0 and err == "" and "16 microslip sub-elements per element" in out
    status, out, _ = run(capsys, "surface", path, "--json")
    summary = json.loads(out)
    assert status == 0 and summary["tangential"] == "mindlin"
    assert summary["microslip_elements"] == 16 and len(summary["elements"]) == 1
    assert summary["elements"][0]["slip_displacement"] == pytest.approx(U_STAR, rel=1e-9)
    # The text lists u* of each element.
    assert f"{U_STAR:.6g}" in run(capsys, "surface", path)[1]


# --- every kind of table -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    heights, _, _ = gaussian_field(64, (0.5e-6, 0.5e-6), 2.5e-6, 50e-9, seed=3)
    path = tmp_path_factory.mktemp("mindlin_map") / "rough.npy"
    np.save(path, heights)
    return path


def tables(small_map):
    """Model tables of every kind of element: bins, sampled and measured summits, plastic ones."""
    statistical = rate_free(default_table())
    statistical["discretisation"] = {"summation": "statistical", "elements": 16}
    sampled = rate_free(default_table())
    sampled["surface"]["nominal_area"] = 1e-8
    sampled["discretisation"] = {"summation": "direct", "seed": 4}
    measured = rate_free(default_table())
    measured["normal_load"] = 0.05
    measured["surface"] = {"topography": str(small_map), "pixel_size": [0.5e-6, 0.5e-6]}
    measured["discretisation"] = {}
    plastic = rate_free(default_table())
    plastic["discretisation"] = {"summation": "statistical", "elements": 16}
    plastic["materials"]["hardness"] = 2e9
    plastic_map = {**measured, "materials": {**measured["materials"], "hardness": 2e9}}
    return [statistical, sampled, measured, plastic, plastic_map]


@settings(max_examples=6, deadline=None)
@given(m=st.integers(2, 1024), kind=st.integers(0, 4))
def test_each_element_keeps_its_stiffness_and_capacity(small_map, m, kind):
    table = tables(small_map)[kind]
    elements = polind.model_from_dict({"model": table}).element_table()
    table["discretisation"] = {**table["discretisation"], "tangential": "mindlin",
                               "microslip_elements": m}
    model = polind.model_from_dict({"model": table})
    sub = model.element_table()
    assert len(sub) == m * len(elements)
    k = sub.stiffness.reshape(len(elements), m)
    W = sub.breakaway_force.reshape(len(elements), m)
    np.testing.assert_allclose(k.sum(axis=1), elements.stiffness, rtol=1e-13)
    np.testing.assert_allclose(W.sum(axis=1), elements.breakaway_force, rtol=1e-13)
    assert W.sum() == pytest.approx(elements.breakaway_force.sum(), rel=1e-13)
    assert W.sum() == pytest.approx(MU * table["normal_load"], rel=1e-9)    # Amontons
    # Each sub-element's slip displacement lies on its element's (0, u*].
    u_star = 3 * elements.breakaway_force / (2 * elements.stiffness)
    slip = W / k
    assert np.all(slip > 0) and np.all(slip <= u_star[:, None] * (1 + 1e-12))
    assert np.all(np.diff(slip, axis=1) > 0)


@pytest.mark.parametrize("kind", [1, 4])
def test_sliding_and_break_away_are_unchanged(small_map, kind):
    table = tables(small_map)[kind]
    table.update(kinetic_coefficient=0.10, attraction=1e4)
    table["discretisation"] = {**table["discretisation"], "tangential": "mindlin"}
    model = polind.model_from_dict({"model": table})
    t = np.linspace(0.0, 1.0, 401)
    steady = polind.simulate(model, t, v=np.full_like(t, 1e-2)).force[-1]
    assert steady == pytest.approx(0.10 * table["normal_load"], rel=1e-9)   # mu_k N at 10 vs


def surface_slope(tangential):
    """Log-log slope of a Gaussian surface's loop energy between q = 0.01 and 0.05."""
    table = rate_free(default_table())
    table["discretisation"] = {"summation": "statistical", "elements": 256,
                               "tangential": tangential}
    model = polind.model_from_dict({"model": table})
    slip_force = MU * table["normal_load"]
    x = np.linspace(0.0, 2e-6, 2001)
    virgin = polind.simulate(model, np.arange(x.size) * 1e-3, x=x).force
    measured = loops(model, np.interp([0.01 * slip_force, 0.05 * slip_force], virgin, x))
    q = measured[:, 0] / slip_force
    assert np.all(np.abs(q / [0.01, 0.05] - 1) < 0.05)
    return math.log(measured[1, 1] / measured[0, 1]) / math.log(q[1] / q[0])


def test_a_gaussian_surfaces_small_amplitude_slope():
    assert surface_slope("mindlin") == pytest.approx(3.0, abs=0.1)
    assert surface_slope("elastic-slip") == pytest.approx(3.5, abs=0.1)


# --- the ball's bulk ---------------------------------------------------------------------------

def ball_model(eta=1e11, sigma=0.1e-6, **surface):
    table = rate_free(default_table())
    table["normal_load"] = 5.0
    table["surface"] = {"asperity_density": eta, "asperity_radius": 20e-6, "height_std": sigma,
                        "ball_radius": 3e-3, **surface}
    table["discretisation"] = {"summation": "statistical", "elements": 16}
    return table


def initial_stiffness(table):
    """F / x of a displacement step a thousandth of the shortest slip distance of its elements."""
    model = polind.model_from_dict({"model": table})
    elements = model.element_table()
    displacement = 1e-3 * float(np.min(elements.breakaway_force / elements.stiffness))
    return polind.simulate(model, np.array([0.0, 1e-3]),
                           x=np.array([0.0, displacement])).force[1] / displacement


def mindlin_ball_stiffness():
    """8 G* a_H of the smooth ball at 5 N."""
    return 8 * G_STAR * (3 * 5.0 * 3e-3 / (4 * E_STAR)) ** (1 / 3)


@pytest.mark.parametrize("tangential", ["elastic-slip", "mindlin"])
def test_a_ball_carries_its_bulk_compliance_in_series(tangential):
    table = ball_model()
    table["discretisation"]["tangential"] = tangential
    asperities = polind.model_from_dict({"model": table}).element_table().stiffness.sum()
    bulk = mindlin_ball_stiffness()
    assert initial_stiffness(table) == pytest.approx(1 / (1 / asperities + 1 / bulk), rel=1e-12)
    table["compliance"] = {"stiffness": 1e7}
    assert initial_stiffness(table) == pytest.approx(1 / (1 / asperities + 1 / bulk + 1e-7),
                                                     rel=1e-12)
    del table["compliance"]
    table["surface"]["bulk_compliance"] = False
    assert initial_stiffness(table) == pytest.approx(asperities, rel=1e-12)


def test_a_stiff_asperity_layer_leaves_mindlins_ball():
    table = ball_model(eta=1e13, sigma=0.01e-6)
    layer = polind.model_from_dict({"model": table}).element_table().stiffness.sum()
    assert layer >= 50 * mindlin_ball_stiffness()
    assert initial_stiffness(table) == pytest.approx(mindlin_ball_stiffness(), rel=0.02)


# --- bad input ---------------------------------------------------------------------------------

@pytest.mark.parametrize("count", [1, 0, -3, 1025, 2.5, True, "32"])
def test_microslip_elements_out_of_range_is_refused(count):
    table = default_table()
    table["discretisation"].update(tangential="mindlin", microslip_elements=count)
    with pytest.raises(polind.InputError, match="discretisation.microslip_elements"):
        polind.model_from_dict({"model": table})


def test_a_microslip_key_without_mindlin_and_an_unknown_law_are_refused():
    table = default_table()
    table["discretisation"]["microslip_elements"] = 16
    with pytest.raises(polind.InputError, match="discretisation.microslip_elements"):
        polind.model_from_dict({"model": table})
    table["discretisation"] = {"tangential": "coulomb"}
    with pytest.raises(polind.InputError, match="tangential"):
        polind.model_from_dict({"model": table})


@pytest.mark.parametrize("value", [True, False])
def test_bulk_compliance_on_a_flat_is_refused(value, tmp_path, capsys):
    table = default_table()
    table["surface"]["bulk_compliance"] = value
    with pytest.raises(polind.InputError, match="surface.bulk_compliance"):
        polind.model_from_dict({"model": table})
    path = tmp_path / "flat.toml"
    path.write_text(tomli_w.dumps({"model": table}))
    status, out, err = run(capsys, "surface", path)
    assert status == 2 and out == "" and "surface.bulk_compliance" in err


def test_a_varying_load_is_refused_with_mindlin(one_summit):
    model = summit_model(one_summit)
    t = np.linspace(0.0, 1.0, 11)
    with pytest.raises(polind.InputError, match="constant normal load"):
        polind.simulate(model, t, x=1e-9 * t, normal_load=LOAD * (1.0 - 0.1 * t))
    constant = polind.simulate(model, t, x=1e-9 * t, normal_load=np.full_like(t, LOAD))
    np.testing.assert_array_equal(constant.force, polind.simulate(model, t, x=1e-9 * t).force)
    stepper = polind.Stepper(model)
    stepper.advance(1e-3, x=1e-10, normal_load=LOAD)
    with pytest.raises(polind.InputError, match="constant normal load"):
        stepper.advance(2e-3, x=2e-10, normal_load=0.5 * LOAD)


@pytest.mark.parametrize("heights", ["h\n1e-6\n", "h\n1e-6\n1e-6\n1e-6\n"])
def test_summits_all_at_one_height_are_a_contact(heights, tmp_path, capsys):
    path = tmp_path / "same.csv"
    path.write_text(heights)
    table = rate_free(default_table())
    table["normal_load"] = LOAD
    table["surface"] = {"asperity_radius": RADIUS}
    table["discretisation"] = {"summation": "direct", "heights_file": str(path)}
    model_path = tmp_path / "same.toml"
    model_path.write_text(tomli_w.dumps({"model": table}))
    status, out, err = run(capsys, "surface", model_path)
    assert status == 0 and err == "" and "every summit at one height" in out
    count = heights.count("1e-6")
    contact = polind.load_model(model_path).contact()
    # Each summit carries LOAD / count by Hertz.
    delta = (3 * LOAD / count / (4 * E_STAR * math.sqrt(RADIUS))) ** (2 / 3)
    assert contact.elements.interference[0] == pytest.approx(delta, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        status, _, _ = run(capsys, "surface", model_path, "--json")
    assert status == 0
