"""polind.hysteresis_loop (MODELS.md 16): the last closed loop of a record and its figures,
against the exact energy of Maxwell-slip loops and the closed forms of a spring and a
viscous damper."""

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import polind
from polind.models.maxwell_slip import example_elements


def sine(amplitude, periods=3, per_period=400, phase=0.0):
    """``(t, u)``: ``periods`` periods of 1 s sampled ``per_period`` times each."""
    t = np.arange(periods * per_period + 1) / per_period
    return t, amplitude * np.sin(2 * np.pi * t + phase)


def element_energy(k, w, amplitude):
    """The exact energy per cycle of Maxwell-slip elements: sum 4 W (u0 - W/k) over the
    elements that slip (u0 > W/k)."""
    k, w = np.asarray(k), np.asarray(w)
    slipping = w / k < amplitude
    return float(np.sum(4 * w[slipping] * (amplitude - w[slipping] / k[slipping])))


@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 2 ** 16), fraction=st.floats(0.05, 2.0))
def test_the_energy_of_maxwell_slip_loops_is_the_element_sum(seed, fraction):
    """The force is exact at the samples and linear in u between them but in the steps
    where an element starts to slip; there the trapezoid cuts the corner by at most
    k du^2 / 8, twice per cycle: |D - exact| <= sum k du^2 / 4 over the slipping
    elements.  Measured over 100 element sets and amplitudes: at most 6e-5 of D (median
    4e-5) at 400 samples per period."""
    k, w = example_elements(16, seed=seed)
    model = polind.model_from_dict({"model": {"type": "maxwell-slip", "stiffness": k,
                                              "breakaway_force": w}})
    amplitude = fraction * float(np.max(np.asarray(w) / np.asarray(k)))
    t, u = sine(amplitude)            # 400 samples a period: the peaks are samples, +-u0
    force = polind.simulate(model, t, x=u).force
    loop = polind.hysteresis_loop(u, force)
    exact = element_energy(k, w, amplitude)
    slipping = np.asarray(w) / np.asarray(k) < amplitude
    bound = float(np.sum(np.asarray(k)[slipping])) * float(np.max(np.abs(np.diff(u)))) ** 2 / 4
    assert abs(loop.energy - exact) <= bound + 1e-12 * exact
    assert loop.energy == pytest.approx(exact, rel=1e-4)
    assert loop.stop - loop.start == 400
    np.testing.assert_array_equal(loop.u, u[loop.start:loop.stop + 1])
    np.testing.assert_array_equal(loop.F, force[loop.start:loop.stop + 1])


def test_the_loop_is_the_last_one():
    """Two cycles at 5 um then two at 20 um: the loop is the last 20 um cycle."""
    k, w = example_elements()
    model = polind.model_from_dict({"model": {"type": "maxwell-slip", "stiffness": k,
                                              "breakaway_force": w}})
    t, small = sine(5e-6, periods=2)
    _, large = sine(20e-6, periods=2)
    u = np.concatenate([small, large[1:]])
    force = polind.simulate(model, np.arange(u.size) / 400.0, x=u).force
    loop = polind.hysteresis_loop(u, force)
    assert (loop.start, loop.stop) == (1100, 1500)      # trough to trough, ending later
    assert loop.energy == pytest.approx(element_energy(k, w, 20e-6), rel=1e-4)
    assert loop.energy > 2 * element_energy(k, w, 5e-6)


def test_a_linear_spring_dissipates_nothing():
    t, u = sine(1e-3, phase=0.3)
    loop = polind.hysteresis_loop(u, 2e5 * u)
    assert abs(loop.energy) < 1e-12 * 2e5 * 1e-6
    assert loop.secant_stiffness == pytest.approx(2e5, rel=1e-12)
    assert abs(loop.damping_ratio) < 1e-12


@pytest.mark.parametrize("stiffness", [0.0, 1e5])
def test_a_viscous_damper_gives_its_damping_ratio(stiffness):
    """F = k u + c du/dt on u = a sin(omega t): an ellipse of area pi c omega a^2, whose
    trapezoid on N samples is exactly that times sin(h)/h (h = 2 pi / N); the secant
    stiffness is sqrt(k^2 + (c omega)^2) and the damping ratio
    c omega / (2 sqrt(k^2 + (c omega)^2)) (1/2 for a damper alone), both up to the
    sampled peaks (h^2 / 8)."""
    a, c, omega, n = 1e-3, 50.0, 2 * np.pi, 400
    t, u = sine(a, per_period=n, phase=0.1)
    force = stiffness * u + c * a * omega * np.cos(omega * t + 0.1)
    loop = polind.hysteresis_loop(u, force)
    h = 2 * np.pi / n
    assert loop.energy == pytest.approx(np.pi * c * omega * a ** 2 * math.sin(h) / h, rel=1e-10)
    modulus = math.hypot(stiffness, c * omega)
    assert loop.secant_stiffness == pytest.approx(modulus, rel=h ** 2 / 8)
    assert loop.damping_ratio == pytest.approx(c * omega / (2 * modulus), rel=h ** 2 / 3)
    assert loop.strain_energy == pytest.approx(modulus * a ** 2 / 2, rel=h ** 2 / 4)


@pytest.mark.parametrize("phase, cycle", [(0.0, (50, 150)), (0.3, (45, 145)),
                                          (np.pi / 2, (75, 175)), (4.0, (36, 136))])
def test_the_cycle_runs_between_the_last_two_maxima_or_minima(phase, cycle):
    """Two periods of 100 samples: the pair of extrema inside the record that ends later
    (a record that starts and ends at maxima has its two minima inside)."""
    t = np.arange(201) / 100
    u = np.cos(2 * np.pi * t + phase)
    loop = polind.hysteresis_loop(u, u)
    assert (loop.start, loop.stop) == cycle
    extremum = u[loop.start]
    assert abs(extremum) == pytest.approx(np.max(np.abs(u[1:-1])), rel=1e-3)


def test_noise_at_the_middle_starts_no_false_cycle():
    t, u = sine(1e-3, periods=4)
    u = u + 1e-5 * np.random.default_rng(1).standard_normal(u.size)
    loop = polind.hysteresis_loop(u, 1e5 * u)
    assert abs(loop.stop - loop.start - 400) <= 2


def test_the_repr_is_one_short_line():
    t, u = sine(1e-3)
    text = repr(polind.hysteresis_loop(u, 1e5 * u))
    assert text.startswith("HysteresisLoop(samples 700..1100, energy ") and "\n" not in text
    assert "array(" not in text and len(text) < 200


@pytest.mark.parametrize("u, F, words", [
    (np.linspace(0.0, 1.0, 50), np.zeros(50), "no closed loop"),                 # a ramp
    (np.sin(np.linspace(0.0, 1.8 * np.pi, 80)), np.zeros(80), "no closed loop"),  # one peak
    (np.zeros(10), np.zeros(10), "never changes"),
    (np.sin(np.linspace(0, 6 * np.pi, 90)), np.zeros(89), "'F'"),
    (np.append(np.sin(np.linspace(0, 6 * np.pi, 90)), np.nan), np.zeros(91), "'u'"),
    (np.zeros((10, 2)), np.zeros((10, 2)), "'u'"),
    ("abc", np.zeros(3), "'u'"),
    (np.sin(np.linspace(0, 6 * np.pi, 90)), [math.inf] * 90, "'F'"),
])
def test_a_bad_record_is_an_input_error(u, F, words):
    with pytest.raises(polind.InputError, match=words):
        polind.hysteresis_loop(u, F)
