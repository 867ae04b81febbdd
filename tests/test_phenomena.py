"""The six phenomena of MODELS.md 7.7 (polind.phenomena): each check on the models that
show the phenomenon, on those that do not, and on negative controls where it must fail.

The demo's models (Pol-Ind default, LuGre 1995, GMS and Maxwell-slip built from the
Pol-Ind element table) are built once per session.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from conftest import LUGRE_1995, lib
from polind import phenomena
from polind.phenomena import PHENOMENA, friction_levels, stickslip_runs


@pytest.fixture(scope="session")
def demo():
    """The demo's models by label: Pol-Ind, LuGre, GMS, Maxwell-slip."""
    from polind.demo import demo_models

    return {label: model for label, (model, _) in demo_models().items()}


@pytest.fixture(scope="session")
def pol_ind(demo):
    return demo["Pol-Ind"]


@pytest.fixture(scope="session")
def lugre(demo):
    return demo["LuGre"]


def stribeck_static(**changes):
    return lib({"type": "stribeck", "coulomb_force": 1.0, "static_force": 1.5,
                "stribeck_velocity": 1e-3, "viscous_coefficient": 0.4, **changes})


# --- the model's scales ------------------------------------------------------------------

def test_levels_of_the_demo_models(demo):
    pol_ind, lugre, gms, maxwell_slip = demo.values()
    levels = friction_levels(pol_ind)
    assert levels.static_force == pytest.approx(15.0)
    assert levels.coulomb_force == pytest.approx(10.0)
    table = pol_ind.element_table()
    slip = np.asarray(table.breakaway_force) / np.asarray(table.stiffness)
    assert levels.presliding_range == pytest.approx(float(slip.max()), rel=1e-12)
    assert friction_levels(gms).presliding_range == pytest.approx(levels.presliding_range,
                                                                  rel=1e-12)
    lu = friction_levels(lugre)
    assert (lu.static_force, lu.coulomb_force, lu.presliding_range) == (1.5, 1.0, 1.5e-5)
    assert lu.lag_time(1e-3) == pytest.approx((1.0 + 0.5 * math.exp(-1.0)) / 100.0)
    ms = friction_levels(maxwell_slip)
    assert ms.static_force == ms.coulomb_force == pytest.approx(15.0)
    assert ms.stribeck_velocity is None and ms.lag_time(1e-3) is None


def test_result_is_json_ready(lugre):
    import json

    result = phenomena.presliding_memory(lugre)
    text = json.dumps(result.to_dict(), allow_nan=False)
    assert '"passed": false' in text and '"expected": false' in text
    assert result.phenomenon in PHENOMENA


# --- 1. Stribeck ----------------------------------------------------------------------------

@pytest.mark.parametrize("label", ["Pol-Ind", "GMS", "LuGre"])
def test_stribeck_dip_on_the_analytic_curve(label, demo):
    model = demo[label]
    result = phenomena.stribeck_effect(model)
    levels = friction_levels(model)
    assert result.passed and result.expected
    m = result.metrics
    assert m["max_relative_deviation"] < 1e-9
    assert m["force_at_lowest_velocity"] == pytest.approx(levels.static_force, rel=1e-5)
    assert m["minimum_force"] == pytest.approx(levels.coulomb_force, rel=5e-3)
    assert m["dip"] == pytest.approx(1.0 - levels.coulomb_force / levels.static_force, rel=0.01)
    assert result.data["velocity"][0] == pytest.approx(1e-3 * levels.stribeck_velocity)
    assert result.data["velocity"][-1] == pytest.approx(1e3 * levels.stribeck_velocity)


def test_stribeck_absent_where_friction_does_not_weaken(demo):
    maxwell_slip = demo["Maxwell-slip"]
    result = phenomena.stribeck_effect(maxwell_slip)
    assert not result.passed and not result.expected and result.as_expected
    assert result.metrics["dip"] == 0.0
    # Fs = Fc: a flat curve, and velocity strengthening (Fs < Fc): a rise, not a dip.
    for model in (stribeck_static(static_force=1.0), stribeck_static(static_force=0.5)):
        result = phenomena.stribeck_effect(model)
        assert not result.passed, result.metrics["dip"]
        assert result.metrics["max_relative_deviation"] < 1e-12


# --- 2. presliding memory -------------------------------------------------------------------

@pytest.mark.parametrize("label", ["Pol-Ind", "GMS", "Maxwell-slip"])
def test_inner_loops_close_and_are_wiped_out(label, demo):
    result = phenomena.presliding_memory(demo[label])
    assert result.passed and result.expected
    assert result.metrics["closure_mismatch"] < 1e-12
    assert result.metrics["branch_mismatch"] < 1e-12
    assert len(result.metrics["closure_mismatches"]) == 3
    # the path stays inside the presliding range, and the loops are real loops
    levels = friction_levels(demo[label])
    assert np.max(np.abs(result.data["x"])) <= levels.presliding_range
    assert result.metrics["major_loop_span"] > levels.static_force


@pytest.mark.parametrize("model_table", [LUGRE_1995, {"type": "dahl", "stiffness": 1e5,
                                                      "coulomb_force": 1.0}])
def test_single_state_models_have_no_nonlocal_memory(model_table):
    result = phenomena.presliding_memory(lib(model_table))
    assert not result.passed and not result.expected
    assert result.metrics["closure_mismatch"] > 1e-3
    assert result.metrics["branch_mismatch"] > 1e-3


def test_presliding_memory_needs_a_presliding_range():
    from polind import InputError

    with pytest.raises(InputError, match="presliding range"):
        phenomena.presliding_memory(stribeck_static())


# --- 3. frictional lag ----------------------------------------------------------------------

@pytest.mark.parametrize("label", ["Pol-Ind", "GMS", "LuGre"])
def test_lag_loops_grow_with_frequency(label, demo):
    result = phenomena.frictional_lag(demo[label])
    assert result.passed and result.expected
    area = np.asarray(result.metrics["loop_area"])
    assert np.all(area > 0.0)                      # clockwise: higher force while v rises
    assert np.all(np.diff(area) > 0.0)
    assert result.metrics["relative_area"][0] < 1e-2 * result.metrics["relative_area"][-1]
    # v > 0 throughout
    assert result.settings["mean_velocity"] > result.settings["velocity_amplitude"]


def test_lag_loop_shrinks_onto_steady_curve(demo):
    gms = demo["GMS"]
    """At the lowest frequency the loop's force differs from the steady curve by a
    small fraction of the Stribeck drop."""
    result = phenomena.frictional_lag(gms)
    v, force = result.data["loops"][0]
    steady = friction_levels(gms).steady_force(v)
    assert np.max(np.abs(force - steady)) < 0.02 * 5.0


def test_no_lag_loop_in_memoryless_or_rate_independent_models(demo):
    for model in (stribeck_static(), demo["Maxwell-slip"]):
        result = phenomena.frictional_lag(model)
        assert not result.passed and not result.expected
        assert np.max(np.abs(result.metrics["relative_area"])) < 1e-12


def test_loop_area_is_signed_and_free_of_rounding_noise():
    """The closed integral of F dv: positive for a loop travelled in the lag direction
    (higher force while v rises), negative the other way, and exactly 0 -- not a rounding
    residue of either sign -- for a force that does not change around the loop."""
    phase = np.linspace(0.0, 2.0 * np.pi, 4001)
    v = 1e-3 + 0.9e-3 * np.sin(phase)
    force = 12.0 + 0.5 * np.cos(phase)        # leads v by a quarter period: clockwise
    expected = np.pi * 0.9e-3 * 0.5
    assert phenomena.cycle_area(v, force) == pytest.approx(expected, rel=1e-5)
    assert phenomena.cycle_area(v, 24.0 - force) == pytest.approx(-expected, rel=1e-5)
    assert phenomena.cycle_area(v, np.full_like(v, 15.0)) == 0.0
    # a force that wobbles by a few ulps around 15 N: noise, not a loop
    wobble = 15.0 + 4.0 * np.spacing(15.0) * np.sign(np.sin(7.0 * phase))
    assert phenomena.cycle_area(v, wobble) == 0.0


def test_stick_slip_settings_are_the_runs_own(lugre):
    result = phenomena.stick_slip(lugre)
    for run in ("reference", "low", "high"):
        m = result.metrics[run]
        assert result.settings[f"{run}_duration"] == m["duration"]
        assert result.settings[f"{run}_time_step"] == pytest.approx(m["time_step"], rel=1e-9)
        assert result.settings[f"{run}_stiffness"] == m["spring_stiffness"]
        assert result.settings[f"{run}_drive_velocity"] == m["drive_velocity"]
    assert result.metrics["reference"]["duration"] == 50.0
    assert result.metrics["reference"]["time_step"] == pytest.approx(1e-3, rel=1e-9)
    assert result.metrics["low"]["duration"] == 10.0


def test_lag_check_fails_when_area_shrinks(pol_ind):
    """Far above the lag's corner frequency the loop closes again: the area falls with
    f and the check must say so."""
    tau = friction_levels(pol_ind).lag_time(1e-3)
    corner = 1.0 / (2.0 * math.pi * tau)
    result = phenomena.frictional_lag(pol_ind, frequencies=[300.0 * corner, 30.0 * corner],
                                      periods=2)
    area = result.metrics["loop_area"]
    assert area[1] < area[0]
    assert not result.passed


# --- 4. non-drifting ------------------------------------------------------------------------

@pytest.mark.parametrize("label", ["Pol-Ind", "GMS", "Maxwell-slip"])
def test_maxwell_slip_family_shakes_down(label, demo):
    result = phenomena.non_drifting(demo[label])
    assert result.passed and result.expected
    m = result.metrics
    assert m["first_advance"] > 0.0
    assert abs(m["last_advance"]) <= 1e-3 * m["first_advance"]
    assert not m["drifts"]
    # the applied force stays below break-away
    levels = friction_levels(demo[label])
    assert np.max(result.data["applied"]) < levels.static_force


def test_lugre_drifts_steadily(lugre):
    """Dupont et al. 2002: about 6.6 µm every cycle with the 1995 parameters and m = 1 kg."""
    result = phenomena.non_drifting(lugre)
    assert not result.passed and not result.expected and result.as_expected
    m = result.metrics
    assert m["drifts"]
    assert 6.55e-6 < m["steady_advance"] < 6.72e-6   # MODELS.md 7.7: about 6.6 µm
    assert "µm every cycle" in result.note
    advance = np.asarray(m["advance_per_cycle"])
    assert np.ptp(advance[1:]) < 0.01 * advance[-1]


def test_memoryless_static_friction_holds_the_body():
    result = phenomena.non_drifting(lib({"type": "coulomb", "coulomb_force": 1.0}), cycles=3)
    assert result.passed and result.expected
    assert result.metrics["first_advance"] == 0.0 == result.metrics["last_advance"]


def test_non_drifting_check_fails_for_a_body_pushed_past_breakaway(demo):
    gms = demo["GMS"]
    """A velocity-strengthening GMS (Fs = 5 N < Fc = 10 N) is pushed up to 0.9 Fc = 9 N,
    past its break-away level: it slides forward every cycle, and the check must fail."""
    result = phenomena.non_drifting(gms.with_params(static_force=5.0), cycles=4)
    assert not result.passed
    advance = result.metrics["advance_per_cycle"]
    assert min(advance) > 1e3 * friction_levels(gms).presliding_range


# --- 5. stick-slip --------------------------------------------------------------------------

def lugre_reference_oracle():
    """The LuGre reference case (MODELS.md 8) integrated independently: LSODA on
    (x, v, z) with tight tolerances."""
    s0, s1, s2, fc, fs, vs = 1e5, math.sqrt(1e5), 0.4, 1.0, 1.5, 1e-3
    m, k, vd = 1.0, 2.0, 0.1

    def rhs(t, y):
        x, v, z = y
        g = fc + (fs - fc) * math.exp(-(v / vs) ** 2)
        dz = v - s0 * abs(v) * z / g
        return [v, (k * (vd * t - x) - (s0 * z + s1 * dz + s2 * v)) / m, dz]

    t = np.arange(0.0, 50.0 + 1e-9, 1e-3)
    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, 0.0, 0.0], method="LSODA", rtol=1e-9,
                    atol=[1e-12, 1e-12, 1e-15], max_step=0.01, t_eval=t)
    assert sol.status == 0
    late = t >= 25.0
    spring = k * (vd * t - sol.y[0])
    starts = stickslip_runs._stick_episodes(t[late], sol.y[1][late], vd)
    return float(np.mean(np.diff(starts))), float(spring[late].min()), float(spring[late].max())


def test_lugre_reference_case_is_reproduced(lugre):
    result = phenomena.stick_slip(lugre)
    ref = result.metrics["reference"]
    assert ref["mass"] == 1.0 and ref["spring_stiffness"] == 2.0 and ref["drive_velocity"] == 0.1
    assert ref["from_rest"] and ref["sticks_and_slips"]
    period, low, high = lugre_reference_oracle()
    assert ref["period"] == pytest.approx(period, rel=2e-3)
    assert ref["spring_force_range"][0] == pytest.approx(low, rel=2e-3)
    assert ref["spring_force_range"][1] == pytest.approx(high, rel=2e-3)
    assert result.passed


@pytest.mark.parametrize("label", ["Pol-Ind", "LuGre"])
def test_stick_slip_at_low_steady_sliding_at_high_velocity(label, demo):
    result = phenomena.stick_slip(demo[label])
    assert result.passed and result.expected
    low, high = result.metrics["low"], result.metrics["high"]
    fc = friction_levels(demo[label]).coulomb_force
    assert low["sticks_and_slips"] and low["stick_episodes"] >= 3
    assert 0.3 < low["period"] < 3.0
    assert low["spring_force_amplitude"] > 0.2 * fc
    assert high["slides_steadily"] and high["stick_episodes"] == 0
    assert high["spring_force_amplitude"] < 0.05 * fc


def test_no_stick_slip_without_velocity_weakening(demo):
    for model in (demo["Maxwell-slip"], demo["GMS"].with_params(static_force=10.0)):
        result = phenomena.stick_slip(model)
        assert not result.passed and not result.expected
        assert not result.metrics["low"]["sticks_and_slips"]
        assert result.metrics["low"]["slides_steadily"]


def test_stick_slip_check_fails_when_high_run_keeps_sticking(pol_ind):
    """A 'high' velocity still on the falling branch of the Stribeck curve (2 vs), where
    steady sliding is unstable, must fail the steady-sliding check."""
    result = phenomena.stick_slip(pol_ind, high_velocity=2e-3)
    assert result.metrics["low"]["sticks_and_slips"]
    assert not result.metrics["high"]["slides_steadily"]
    assert not result.passed


# --- 6. break-away --------------------------------------------------------------------------

@pytest.mark.parametrize("label", ["Pol-Ind", "GMS", "LuGre", "Maxwell-slip"])
def test_breakaway_at_the_static_level_for_slow_ramps(label, demo):
    model = demo[label]
    result = phenomena.breakaway(model)
    assert result.passed and result.expected
    ratio = result.metrics["breakaway_ratio"]
    assert abs(ratio[0] - 1.0) < 0.02
    assert all(math.isfinite(r) for r in ratio)
    rates = result.metrics["rate"]
    assert rates == sorted(rates) and rates[-1] == pytest.approx(1e3 * rates[0])


def test_breakaway_rate_effects(pol_ind, lugre):
    """Inertia raises Pol-Ind's break-away force with the rate; LuGre's creep (its drift
    below Fs) lowers it."""
    pol = phenomena.breakaway(pol_ind).metrics["breakaway_ratio"]
    lu = phenomena.breakaway(lugre).metrics["breakaway_ratio"]
    assert all(b > a for a, b in zip(pol[:-1], pol[1:]))
    assert all(b < a for a, b in zip(lu[:-1], lu[1:]))


def test_breakaway_check_fails_with_a_threshold_inside_presliding(pol_ind):
    """A threshold below the presliding velocity fires at once: the check must fail."""
    result = phenomena.breakaway(pol_ind, threshold_velocity=1e-12)
    assert not result.passed
    assert result.metrics["breakaway_ratio"][0] < 0.5


def test_frictional_lag_of_a_lightly_loaded_pol_ind_contact_stays_small():
    # Its lag time is tiny against its presliding range: a uniform grid over the
    # warm-up slide would take 8e10 samples (595 GiB).
    import polind
    import polind.phenomena as phenomena
    from polind.models.pol_ind import default_table
    from polind.phenomena import lag

    table = default_table()
    table["normal_load"] = 1e-6
    model = polind.model_from_dict({"model": table})
    sizes = []
    original = lag.simulate       # the simulate that frictional_lag (polind.phenomena.lag) calls

    def counting(model, t, *args, **kwargs):
        sizes.append(len(t))
        return original(model, t, *args, **kwargs)

    lag.simulate = counting
    try:
        result = phenomena.frictional_lag(model)
    finally:
        lag.simulate = original
    assert max(sizes) < 2_000_000
    assert result.passed
