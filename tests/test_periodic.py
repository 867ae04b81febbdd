"""polind.structures.contact_period: a contact's periodic steady state along one period.

Checked against polind.simulate along the same motion repeated (the forces of
the last period) and against finite differences of simulate's last force in the
last displacement (the tangent).
"""

from __future__ import annotations

import numpy as np
import pytest

import polind
from polind import InputError
from polind.structures import contact_period

LUGRE = {"type": "lugre", "bristle_stiffness": 1e5, "bristle_damping": 316.0,
         "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
         "viscous_coefficient": 0.4}
MAXWELL_SLIP = {"type": "maxwell-slip", "stiffness": [1e5, 4e4, 1e4],
                "breakaway_force": [0.3, 0.3, 0.4]}
CASES = {
    "maxwell-slip": (MAXWELL_SLIP, 4e-5),
    "lugre+compliance": ({**LUGRE, "compliance": {"stiffness": 2e4}}, 1e-4),
    "coulomb": ({"type": "coulomb", "coulomb_force": 1.0}, 1e-4),
    "maxwell-slip+compliance": ({**MAXWELL_SLIP, "compliance": {"stiffness": 3e4}}, 6e-5),
}
SAMPLES, PERIOD = 96, 0.05


def _motion(amplitude):
    phase = 2 * np.pi * np.arange(SAMPLES) / SAMPLES
    return amplitude * (np.sin(phase) + 0.3 * np.sin(3 * phase + 0.4))


def _repeated(u, cycles, extra=0):
    """The motion of ``cycles`` periods and ``extra`` samples, as simulate takes it."""
    total = cycles * SAMPLES + extra
    t = np.arange(total + 1) * (PERIOD / SAMPLES)
    x = np.append(np.tile(u, cycles + 1)[:total], u[extra % SAMPLES])
    return t, x


@pytest.mark.parametrize("name", CASES)
def test_the_period_is_simulate_along_the_repeated_motion(name):
    document, amplitude = CASES[name]
    model = polind.model_from_dict({"model": document})
    u = _motion(amplitude)
    res = contact_period(model, u, PERIOD)
    t, x = _repeated(u, res.cycles)
    force = polind.simulate(model, t, x=x).force
    last = force[-SAMPLES:]              # samples 1 .. N of the last period
    scale = np.ptp(last)
    assert scale > 0.0
    np.testing.assert_allclose(np.roll(res.force, -1), last, rtol=0, atol=1e-12 * scale)
    # and it is periodic: one more period changes nothing
    t, x = _repeated(u, res.cycles + 1)
    again = polind.simulate(model, t, x=x).force[-SAMPLES:]
    np.testing.assert_allclose(again, last, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("name", ["maxwell-slip", "maxwell-slip+compliance"])
@pytest.mark.parametrize("sample", [5, 30, 61])
def test_the_tangent_is_the_derivative_of_the_force_in_the_last_displacement(name, sample):
    """Exact for the Maxwell-slip family (piecewise linear in the step), spring or not."""
    document, amplitude = CASES[name]
    model = polind.model_from_dict({"model": document})
    u = _motion(amplitude)
    res = contact_period(model, u, PERIOD)
    t, x = _repeated(u, res.cycles, sample)
    delta = 1e-7 * amplitude
    ends = []
    for sign in (1.0, -1.0):
        moved = x.copy()
        moved[-1] += sign * delta
        ends.append(polind.simulate(model, t, x=moved).force[-1])
    derivative = (ends[0] - ends[1]) / (2 * delta)
    stiffness = abs(res.tangent).max()
    assert stiffness > 0.0
    assert abs(res.tangent[sample] - derivative) <= 1e-5 * stiffness


def test_a_rate_model_s_tangent_is_its_stuck_tangent():
    """LuGre's tangent is k h + c of the state (MODELS' stepping contract), an estimate while
    sliding: positive, and at most the series spring's stiffness behind one."""
    document, amplitude = CASES["lugre+compliance"]
    res = contact_period(polind.model_from_dict({"model": document}), _motion(amplitude), PERIOD)
    assert (res.tangent > 0.0).all() and (res.tangent <= 2e4).all()


def test_bad_input_names_itself():
    model = polind.model_from_dict({"model": MAXWELL_SLIP})
    with pytest.raises(InputError, match="'period'"):
        contact_period(model, [0.0, 1e-5], -1.0)
    with pytest.raises(InputError, match="at least 2"):
        contact_period(model, [0.0], 1.0)
    with pytest.raises(InputError, match="finite. Got nan at index 1"):
        contact_period(model, [0.0, np.nan], 1.0)
    with pytest.raises(InputError, match="'model'"):
        contact_period("lugre", [0.0, 1e-5], 1.0)
    with pytest.raises(InputError, match="'cycles'"):
        contact_period(model, [0.0, 1e-5], 1.0, cycles=0)
