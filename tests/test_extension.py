"""A model of one's own, defined outside polind, through every entry point.

The model here lives only in this test module (a user's module): a Dahl
variant whose force relaxes exponentially in the travelled distance towards
``Fc tanh(v / v0)`` (a smoothed Coulomb level).  It is registered with
``polind.register_model`` and then used through model files, ``simulate``,
``Stepper``, ``Body``, ``simulate_system`` and ``identify`` without touching
polind's own files.  Its exact solution at constant velocity is checked
against a plain-Python reference, so the test can fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import polind
from polind.dynamics import System, simulate_system

# --- the user's module ---------------------------------------------------------------------


@njit
def _level(scalars, velocity):
    return scalars[1] * math.tanh(velocity / scalars[2])


@njit
def smooth_dahl_step(scalars, table, state, step, displacement, step_velocity,
                     sample_velocity, normal_load):
    # dF/ds = (sigma0 / Fc) (L(v) - F) along the travelled distance s: exact at constant v.
    target = _level(scalars, step_velocity)
    decay = math.exp(-scalars[0] / scalars[1] * abs(displacement))
    state[0] = target + (state[0] - target) * decay
    return state[0]


@njit
def smooth_dahl_force(scalars, table, state, sample_velocity, normal_load):
    return state[0]


@njit
def smooth_dahl_tangent(scalars, table, state, step):
    return scalars[0] * step


class SmoothDahl(polind.FrictionModel):
    """Dahl-like relaxation towards a smoothed Coulomb level ``Fc tanh(v / v0)``."""

    type = "smooth-dahl"
    parameters = (polind.Param("stiffness", unit="N/m"),
                  polind.Param("coulomb_force", unit="N"),
                  polind.Param("smoothing_velocity", unit="m/s"))

    def initial_variables(self, normal_load=None):
        return {"friction": np.zeros(1)}

    def step_functions(self):
        return polind.StepFunctions(smooth_dahl_step, smooth_dahl_force, smooth_dahl_tangent)

    def kernel_arrays(self, state):
        p = self.params
        scalars = np.array([p["stiffness"], p["coulomb_force"], p["smoothing_velocity"]])
        return scalars, np.zeros((1, 0))

    def force_scale(self):
        return self.params["coulomb_force"]


def reference(params, t, x):
    """Plain Python: the exact relaxation step by step."""
    force = [0.0]
    for k in range(1, len(t)):
        dx = x[k] - x[k - 1]
        level = params["coulomb_force"] * math.tanh(dx / (t[k] - t[k - 1])
                                                    / params["smoothing_velocity"])
        decay = math.exp(-params["stiffness"] / params["coulomb_force"] * abs(dx))
        force.append(level + (force[-1] - level) * decay)
    return np.array(force)


PARAMS = {"stiffness": 2e4, "coulomb_force": 1.5, "smoothing_velocity": 2e-3}

# --- the tests -----------------------------------------------------------------------------


@pytest.fixture
def registered():
    polind.register_model(SmoothDahl)
    yield SmoothDahl
    polind.unregister_model(SmoothDahl.type)


def _motion(n=800):
    t = np.linspace(0.0, 2.0, n)
    return t, 1e-3 * np.sin(2 * np.pi * t) + 2e-4 * np.sin(2 * np.pi * 3.7 * t)


def test_model_file_simulate_and_stepper(registered, tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[model]\ntype = "smooth-dahl"\nstiffness = 2e4\ncoulomb_force = 1.5\n'
                    'smoothing_velocity = 2e-3\n')
    model = polind.load_model(path)
    assert isinstance(model, SmoothDahl)
    t, x = _motion()
    res = polind.simulate(model, t, x=x)
    np.testing.assert_allclose(res.force, reference(PARAMS, t, x), rtol=1e-12, atol=1e-14)
    stepper = polind.Stepper(model)
    forces = [stepper.force] + [stepper.advance(float(t[k]), x=float(x[k]))
                                for k in range(1, len(t))]
    np.testing.assert_allclose(forces, res.force, rtol=1e-12, atol=1e-15)
    # a continuation from the saved state equals the whole run
    half = polind.simulate(model, t[:400], x=x[:400])
    rest = polind.simulate(model, t[399:], x=x[399:], state=half.final_state)
    np.testing.assert_allclose(rest.force, res.force[399:], rtol=1e-12, atol=1e-15)


def test_body_and_simulate_system(registered):
    model = polind.model_from_dict({"model": {"type": "smooth-dahl", **PARAMS}})
    n = 1000
    forces = 2.0 * np.sin(2 * np.pi * 2.0 * np.arange(n - 1) * 1e-3)
    res = simulate_system(model, System(mass=0.5, duration=(n - 1) * 1e-3, time_step=1e-3),
                          applied=forces)
    body = polind.Body(model, mass=0.5, time_step=1e-3)
    steps = np.array([body.step(float(f)) for f in forces])
    np.testing.assert_allclose(steps[:, 0], res.x[1:], rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(steps[:, 2], res.force[1:], rtol=1e-12, atol=1e-15)
    assert np.ptp(res.x) > 1e-4                       # it slides: above its level
    # the friction is the model's own along the body's path
    along = polind.simulate(model, res.t, x=res.x)
    np.testing.assert_allclose(res.force[1:], along.force[1:], rtol=1e-9, atol=1e-12)


def test_identify_recovers_its_parameters(registered):
    truth = polind.model_from_dict({"model": {"type": "smooth-dahl", **PARAMS}})
    t, x = _motion(1500)
    measured = polind.simulate(truth, t, x=x).force
    start = truth.with_params(stiffness=5e3, coulomb_force=1.0)
    fit = polind.identify(start, {"t": t, "x": x, "F": measured},
                          free=["stiffness", "coulomb_force"],
                          bounds={"stiffness": [1e2, 1e6], "coulomb_force": [0.1, 10.0]})
    assert fit.model.params["stiffness"] == pytest.approx(2e4, rel=1e-6)
    assert fit.model.params["coulomb_force"] == pytest.approx(1.5, rel=1e-6)


def test_register_model_refuses_what_is_not_a_model():
    with pytest.raises(polind.InputError, match="subclass of polind.FrictionModel"):
        polind.register_model(dict)

    class Nameless(SmoothDahl):
        type = ""

    with pytest.raises(polind.InputError, match="non-empty"):
        polind.register_model(Nameless)

    class Clash(SmoothDahl):
        type = "lugre"

    with pytest.raises(polind.InputError, match="already registered"):
        polind.register_model(Clash)

    class NoStep(polind.FrictionModel):
        type = "no-step"

    with pytest.raises(polind.InputError, match="step_functions"):
        polind.register_model(NoStep)


def test_an_unknown_type_is_an_error_not_a_fall_through():
    with pytest.raises(polind.InputError, match="Unknown model type 'smooth-dahl'"):
        polind.model_from_dict({"model": {"type": "smooth-dahl", **PARAMS}})
