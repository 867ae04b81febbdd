"""Static models (MODELS.md 0-1): Coulomb and Stribeck, both curve shapes."""

import math

import numpy as np
import pytest

import oracles
from conftest import assert_close, representative, run

REL = 1e-12
VELOCITIES = np.array([-1e-1, -3e-3, -1e-3, -2e-4, -1e-7, 0.0, 1e-7, 2e-4, 1e-3,
                       3e-3, 1e-1])


def hand_g(v, fc, fs, vs, delta, shape):
    """MODELS.md 0 typed out once more, scalar by scalar."""
    a = abs(v / vs) ** delta
    if shape == "exponential":
        return fc + (fs - fc) * math.exp(-a)
    return fc + (fs - fc) / (1.0 + a)


@pytest.mark.parametrize("shape", ["exponential", "rational"])
def test_oracle_stribeck_curve(shape):
    for v in VELOCITIES:
        assert oracles.stribeck_curve(v, 1.0, 1.5, 1e-3, 2.0, shape) == pytest.approx(
            hand_g(v, 1.0, 1.5, 1e-3, 2.0, shape), rel=1e-15)
    # limits: g(0) = Fs, g(inf) = Fc, and at v = vs the two shapes differ as printed
    assert oracles.stribeck_curve(0.0, 1.0, 1.5, 1e-3, 2.0, shape) == 1.5
    assert oracles.stribeck_curve(1e3, 1.0, 1.5, 1e-3, 2.0, shape) == pytest.approx(1.0, abs=1e-6)
    at_vs = oracles.stribeck_curve(1e-3, 1.0, 1.5, 1e-3, 2.0, shape)
    assert at_vs == pytest.approx(1.0 + 0.5 * (math.exp(-1) if shape == "exponential" else 0.5))


def test_coulomb_sign_law():
    t = np.arange(len(VELOCITIES), dtype=float)
    res = run({"type": "coulomb", "coulomb_force": 2.5}, t, v=VELOCITIES)
    np.testing.assert_array_equal(res.force, 2.5 * np.sign(VELOCITIES))
    assert res.force[VELOCITIES == 0.0][0] == 0.0         # sgn(0) = 0


def test_coulomb_position_driven_uses_step_velocity():
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    x = np.array([0.0, 1.0, 1.0, 0.5, 0.7])           # steps +1, 0, -0.5, +0.2
    res = run({"type": "coulomb", "coulomb_force": 1.0}, t, x=x)
    np.testing.assert_allclose(res.v, [1.0, 1.0, 0.0, -0.5, 0.2], rtol=1e-14)
    np.testing.assert_array_equal(res.force, [1.0, 1.0, 0.0, -1.0, 1.0])


@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("fs, delta, sigma2", [(1.5, 2.0, 0.4), (0.7, 1.3, 0.0), (3.0, 0.5, 2.0)])
def test_stribeck_formula(shape, fs, delta, sigma2):
    model = representative("stribeck", static_force=fs, stribeck_exponent=delta,
                           viscous_coefficient=sigma2, stribeck_shape=shape)
    t = np.arange(len(VELOCITIES), dtype=float)
    res = run(model, t, v=VELOCITIES)
    expected = [hand_g(v, 1.0, fs, 1e-3, delta, shape) * np.sign(v) + sigma2 * v
                for v in VELOCITIES]
    assert_close(res.force, expected, REL, 1.0, "Stribeck F = g(v) sgn(v) + sigma2 v")
    assert res.force[VELOCITIES == 0.0][0] == 0.0
    assert_close(res.force, oracles.simulate(model, t, v=VELOCITIES).force, REL, 1.0, "oracle")


def test_stribeck_defaults():
    """``stribeck_exponent`` 2, ``viscous_coefficient`` 0 and the exponential
    shape are the defaults."""
    full = representative("stribeck", viscous_coefficient=0.0)
    bare = {k: v for k, v in full.items()
            if k not in ("stribeck_exponent", "viscous_coefficient", "stribeck_shape")}
    t = np.arange(len(VELOCITIES), dtype=float)
    np.testing.assert_array_equal(run(bare, t, v=VELOCITIES).force,
                                  run(full, t, v=VELOCITIES).force)


def test_stribeck_position_driven():
    t = np.linspace(0.0, 1.0, 501)
    x = 2e-3 * np.sin(2 * np.pi * t) ** 3
    for shape in ("exponential", "rational"):
        model = representative("stribeck", stribeck_shape=shape)
        res = run(model, t, x=x)
        step_v = np.diff(x) / np.diff(t)
        np.testing.assert_allclose(res.v, np.concatenate([step_v[:1], step_v]), rtol=1e-12)
        g = np.array([hand_g(v, 1.0, 1.5, 1e-3, 2.0, shape) for v in res.v])
        assert_close(res.force, g * np.sign(res.v) + 0.4 * res.v, REL, 1.0, shape)
