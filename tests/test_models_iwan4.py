"""Segalman's four-parameter Iwan model (MODELS.md 12): its density, its element table and
its runs, against the closed forms of the density.

The closed forms used here, written out from the density ``rho = R phi^chi`` on
``(0, phi_max)`` plus ``S`` at ``phi_max`` (``c = chi + 1``):

* virgin curve ``F(u) = R (u phi_max^c / c - u^(c+1) / (c (c+1))) + S u`` for ``u <= phi_max``,
  ``F_S`` beyond;
* energy per cycle ``D(u0) = 4 R u0^(chi+3) / ((chi+2)(chi+3))`` for ``u0 < phi_max``.
"""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import polind
from conftest import polyline
from polind.models.iwan4 import element_table

FS, KT = 1000.0, 1e8              # the example joint: phi_max = 22.5 um at chi = -0.5, beta = 0.2


def iwan(**changes):
    table = {"type": "iwan4", "slip_force": FS, "stiffness": KT, "chi": -0.5, "beta": 0.2}
    table.update(changes)
    return polind.model_from_dict({"model": table})


def closed_density(chi, beta):
    """``(phi_max, R, S)`` from MODELS.md 12, written out again."""
    r = (chi + 1) / (chi + 2)
    phi_max = FS * (1 + beta) / (KT * (beta + r))
    return phi_max, FS * (chi + 1) / (phi_max ** (chi + 2) * (beta + r)), \
        FS / phi_max * beta / (beta + r)


def virgin_closed(u, chi, beta):
    phi_max, big_r, point = closed_density(chi, beta)
    c = chi + 1
    u = np.minimum(u, phi_max)
    return big_r * (u * phi_max ** c / c - u ** (c + 1) / (c * (c + 1))) + point * u


def energy_closed(u0, chi, beta):
    _, big_r, _ = closed_density(chi, beta)
    return 4 * big_r * u0 ** (chi + 3) / ((chi + 2) * (chi + 3))


def cycle_energy(model, u0, samples=1000):
    """``(D, F_max)`` of the closed loop ``u0 -> -u0 -> u0`` after the virgin load to ``u0``.

    The force is exact at the samples and piecewise linear in ``x`` between an
    element's slip events, so the trapezoid errs only in the steps where an
    element starts to slip: about ``sum k h^2`` with ``h = 2 u0 / samples``,
    below 1e-5 of D here.
    """
    t, x = polyline([0.0, u0, -u0, u0], samples_per_leg=[samples // 2, samples, samples],
                    speed=1.0)
    force = polind.simulate(model, t, x=x).force
    start = samples // 2
    return float(np.trapezoid(force[start:], x[start:])), float(force[start])


# --- the density and its table -------------------------------------------------------------

@settings(max_examples=25, deadline=None)
@given(chi=st.floats(-0.999, 0.0), beta=st.sampled_from([0.0, 1e-3, 0.2, 5.0]),
       elements=st.integers(2, 200))
def test_the_table_holds_the_density_s_stiffness_and_slip_force_exactly(chi, beta, elements):
    phi_max, big_r, point = closed_density(chi, beta)
    # the density's identities (the closed forms of MODELS.md 12)
    assert big_r * phi_max ** (chi + 1) / (chi + 1) + point == pytest.approx(KT, rel=1e-13)
    assert big_r * phi_max ** (chi + 2) / (chi + 2) + point * phi_max == pytest.approx(FS,
                                                                                      rel=1e-13)
    # ... held by the table as sums: exact but for rounding
    k, w = element_table(FS, KT, chi, beta, elements)
    assert len(k) == len(w) == elements
    assert math.fsum(k) == pytest.approx(KT, rel=4e-16 * elements)
    assert math.fsum(w) == pytest.approx(FS, rel=4e-16 * elements)
    slip = w / k
    assert np.all(k > 0) and np.all(np.diff(slip) > 0) and slip[-1] <= phi_max * (1 + 1e-12)
    if beta > 0:          # the point mass is the last element: k = S, slipping at phi_max
        assert k[-1] == pytest.approx(point, rel=1e-12)
        assert slip[-1] == pytest.approx(phi_max, rel=1e-12)


@pytest.mark.parametrize("chi, beta", [(0.0, 0.0), (-0.5, 0.2), (-0.9, 2.0), (-0.9, 0.0)])
def test_the_virgin_curve_is_the_density_s_within_its_quadrature(chi, beta):
    """Every element of a cell wholly below ``u`` carries its cell's ``integral rho phi`` and
    every one above its ``u integral rho``, exactly; only the cell holding ``u`` errs, by
    less than its stiffness times a fraction of its width.  Measured for u in
    [0.05, 1] phi_max: at most 0.16 % of F(u) (chi = 0, beta = 0); 0.2 % asserted."""
    model = iwan(chi=chi, beta=beta)
    phi_max = model.density()[0]
    t, x = polyline([0.0, 1.2 * phi_max], samples_per_leg=1200, speed=1.0)
    force = polind.simulate(model, t, x=x).force
    inside = (x >= 0.05 * phi_max) & (x <= phi_max)
    error = np.abs(force[inside] / virgin_closed(x[inside], chi, beta) - 1.0)
    assert error.max() < 2e-3
    beyond = x > phi_max * (1 + 1e-9)
    np.testing.assert_allclose(force[beyond], FS, rtol=1e-12)      # macroslip: F_S exactly


@pytest.mark.parametrize("chi", [0.0, -0.5, -0.95])
def test_the_energy_per_cycle_is_the_density_s_within_one_percent(chi):
    """D(u0) of a simulated cycle against ``4 R u0^(chi+3)/((chi+2)(chi+3))`` for u0 in
    [0.05, 0.9] phi_max with the default 64 elements.  Measured: at most 0.41 % (chi = 0),
    0.29 % (chi = -0.5), 0.19 % (chi = -0.95)."""
    model = iwan(chi=chi)
    phi_max = model.density()[0]
    errors = []
    for u0 in np.geomspace(0.05, 0.9, 9) * phi_max:
        energy, _ = cycle_energy(model, u0)
        errors.append(energy / energy_closed(u0, chi, 0.2) - 1.0)
    assert max(map(abs, errors)) < 0.01, errors


def test_unloading_follows_masing():
    """After the virgin load to u0, the branch down is ``F(u0) - 2 F_virgin((u0 - u)/2)``:
    the virgin leg is sampled at half the unloading step so that (u0 - u)/2 is a sample."""
    model = iwan()
    u0 = 0.6 * model.density()[0]
    n = 300
    t, x = polyline([0.0, u0, -u0], samples_per_leg=[n, n], speed=1.0)
    force = polind.simulate(model, t, x=x).force
    virgin, down = force[:n + 1], force[n:]
    np.testing.assert_allclose(down, force[n] - 2.0 * virgin, rtol=0, atol=1e-11 * FS)
    # and the same branch of the density's closed form, within its quadrature (0.2 %)
    want = virgin_closed(u0, -0.5, 0.2) - 2 * virgin_closed((u0 - x[n:]) / 2, -0.5, 0.2)
    assert np.max(np.abs(down - want)) < 2e-3 * virgin_closed(u0, -0.5, 0.2)


def test_the_energy_grows_as_the_force_to_the_power_three_plus_chi():
    """``D ∝ F^(3+chi)`` at small force: the log-log slope of the simulated D against the
    loop's force amplitude equals the density's, which tends to 3 + chi as u0 -> 0."""
    chi, beta = -0.3, 1.0
    model = iwan(chi=chi, beta=beta)
    phi_max = model.density()[0]
    low, high = 0.05 * phi_max, 0.07 * phi_max
    (d1, f1), (d2, f2) = cycle_energy(model, low), cycle_energy(model, high)
    slope = math.log(d2 / d1) / math.log(f2 / f1)

    def closed_slope(a, b):
        return math.log(energy_closed(b, chi, beta) / energy_closed(a, chi, beta)) \
            / math.log(virgin_closed(b, chi, beta) / virgin_closed(a, chi, beta))

    assert slope == pytest.approx(closed_slope(low, high), rel=0.01)
    assert closed_slope(low, high) == pytest.approx(3 + chi, rel=0.04)     # 2.7 -> 2.79 here
    assert closed_slope(1e-7 * phi_max, 1.4e-7 * phi_max) == pytest.approx(3 + chi, rel=1e-3)


# --- bad input -----------------------------------------------------------------------------

@pytest.mark.parametrize("key, value", [
    ("chi", 0.1), ("chi", -1.0), ("chi", -1.5), ("chi", "x"),
    ("beta", -0.1), ("slip_force", 0.0), ("slip_force", -1.0), ("stiffness", 0.0),
    ("stiffness", -1e8), ("elements", 1), ("elements", 0), ("elements", 2.5),
    ("elements", "64"),
])
def test_a_bad_parameter_is_an_input_error_naming_it(key, value):
    with pytest.raises(polind.InputError, match=f"'{key}'"):
        iwan(**{key: value})


# --- everywhere a model works --------------------------------------------------------------

def test_it_runs_as_its_maxwell_slip_table_under_a_load_and_behind_a_spring():
    """Normal load (reference_load) and series compliance are those of Maxwell-slip."""
    model = iwan(elements=16, reference_load=500.0, compliance={"stiffness": 3e8})
    table = model.to_maxwell_slip()
    assert len(table.params["stiffness"]) == 16
    t = np.linspace(0.0, 1.0, 801)
    x = 3e-5 * np.sin(2 * np.pi * 2 * t) * t
    load = 500.0 * (1.0 + 0.5 * np.sin(2 * np.pi * 3 * t))
    np.testing.assert_array_equal(polind.simulate(model, t, x=x, normal_load=load).force,
                                  polind.simulate(table, t, x=x, normal_load=load).force)
    stepper = polind.Stepper(model)
    stepped = [stepper.advance(t_k, x=x_k) for t_k, x_k in zip(t[1:], x[1:])]
    np.testing.assert_allclose(stepped, polind.simulate(model, t, x=x).force[1:], rtol=1e-12,
                               atol=1e-12 * FS)
    body, twin = polind.Body(model, mass=2.0, time_step=1e-4), \
        polind.Body(table, mass=2.0, time_step=1e-4)
    for k in range(200):
        push = 1500.0 * math.sin(2 * math.pi * 50 * k * 1e-4)
        assert body.step(push) == twin.step(push)


def test_a_model_file_reads_and_saves_back(tmp_path):
    path = tmp_path / "joint.toml"
    path.write_text('[model]\ntype = "iwan4"\nslip_force = 1000.0\nstiffness = 1e8\n'
                    'chi = -0.5\nbeta = 0.2\n')
    model = polind.load_model(path)
    assert model == iwan() and model.params["elements"] == 64
    polind.save_model(model, tmp_path / "copy.toml")
    assert polind.load_model(tmp_path / "copy.toml") == model
    path.write_text('[model]\ntype = "iwan4"\nslip_force = 1000.0\nstiffness = 1e8\n'
                    'chi = 0.5\nbeta = 0.2\n')
    with pytest.raises(polind.InputError, match="joint.toml.*'chi'.*\\(-1, 0\\]"):
        polind.load_model(path)


def test_identify_recovers_the_four_parameters():
    true = iwan(elements=16)
    phi_max = true.density()[0]
    t = np.linspace(0.0, 1.0, 401)
    x = 1.5 * phi_max * np.sin(2 * np.pi * 2 * t) * np.linspace(0.1, 1.0, t.size)
    data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    start = true.with_params(slip_force=700.0, stiffness=5e7, chi=-0.2, beta=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = polind.identify(start, data, starts=1)
    assert sorted(fit.free) == ["beta", "chi", "slip_force", "stiffness"]
    for key in ("slip_force", "stiffness", "chi", "beta"):
        assert fit.model.params[key] == pytest.approx(true.params[key], rel=1e-6, abs=1e-9)
