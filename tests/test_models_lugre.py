"""LuGre (MODELS.md 3): steady state, the exact per-step update (via the
oracle) and its drift under a force cycle below break-away."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import oracles
from conftest import (LUGRE_1995, assert_close, polyline, random_walk, representative, run,
                      spoil_sample)

REL = 1e-9
S0 = LUGRE_1995["bristle_stiffness"]
S1 = LUGRE_1995["bristle_damping"]
S2 = LUGRE_1995["viscous_coefficient"]
FC, FS, VS = 1.0, 1.5, 1e-3


def lugre(shape="exponential", **changes):
    return representative("lugre", stribeck_shape=shape, **changes)


def g(v, shape="exponential"):
    return oracles.stribeck_curve(v, FC, FS, VS, 2.0, shape)


# --- the oracle --------------------------------------------------------------

def test_oracle_exponential_update_matches_integration():
    """The oracle's exact step against ``solve_ivp`` of the state equation on
    the same piecewise-constant velocity."""
    t, x = random_walk(60, 5e-6, seed=5)
    ref = oracles.simulate(lugre(), t, x=x)
    m = oracles.motion(t, x=x)
    z = 0.0
    for k in range(len(t) - 1):
        v = m.step_v[k]
        sol = solve_ivp(lambda _, y: [v - S0 * abs(v) * y[0] / g(v)], (0.0, m.step_h[k]),
                        [z], method="Radau", rtol=1e-12, atol=1e-18)
        z = sol.y[0, -1]
        assert ref.states["z"][k + 1] == pytest.approx(z, rel=1e-8, abs=1e-16)


# --- the library --------------------------------------------------------------

@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("v", [1e-4, 7e-4, 1e-3, 3e-3, 2e-2, -1e-4, -1e-3, -5e-3])
def test_steady_state(shape, v):
    """Constant ``v``: ``F -> g(v) sgn(v) + sigma2 v``."""
    duration = 60.0 * g(v, shape) / (S0 * abs(v))       # exp(-60): converged
    t = np.linspace(0.0, duration, 301)
    res = run(lugre(shape), t, x=v * t)
    expected = g(v, shape) * np.sign(v) + S2 * v
    assert res.force[-1] == pytest.approx(expected, rel=REL)
    ref = oracles.simulate(lugre(shape), t, x=v * t)
    assert_close(res.force, ref.force, REL, FS, "transient")


@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("seed", [0, 1])
def test_random_motion_against_oracle(shape, seed):
    t, x = random_walk(3000, 5e-6, seed)
    res = run(lugre(shape), t, x=x)
    ref = oracles.simulate(lugre(shape), t, x=x)
    assert_close(res.force, ref.force, REL, FS, "x-driven")


def test_standstill_steps_against_oracle():
    t, x = random_walk(3000, 5e-6, seed=9, dwell=0.2)
    res = run(lugre(), t, x=x)
    ref = oracles.simulate(lugre(), t, x=x)
    still = res.v == 0.0
    assert np.count_nonzero(still) > 300
    assert_close(res.force, ref.force, REL, FS, "with standstill steps")
    # at rest: F = sigma0 z, and z did not move over the standstill step
    i = np.flatnonzero(still[1:])[0] + 1
    assert res.force[i] == pytest.approx(S0 * ref.states["z"][i - 1], rel=1e-12)


@pytest.mark.parametrize("shape", ["exponential", "rational"])
def test_velocity_driven_against_oracle(shape):
    t = np.linspace(0.0, 2.0, 4001)
    v = 3e-3 * np.sin(2 * np.pi * t) + 1e-3 * np.sin(2 * np.pi * 5.3 * t)
    res = run(lugre(shape), t, v=v)
    ref = oracles.simulate(lugre(shape), t, v=v)
    np.testing.assert_array_equal(res.v, v)
    assert_close(res.force, ref.force, REL, FS, "v-driven")


def test_force_at_first_sample():
    """Zero state at sample 0: ``F = sigma1 v + sigma2 v`` with ``v = res.v[0]``."""
    t = np.array([0.0, 1e-3, 2e-3])
    res = run(lugre(), t, x=np.array([0.0, 1e-6, 3e-6]))
    assert res.force[0] == pytest.approx((S1 + S2) * 1e-3, rel=1e-12)


def test_drifts_under_a_force_cycle_below_breakaway():
    """Dupont et al. 2002: a force cycled between two levels below break-away
    makes LuGre creep by the same distance every cycle, forever.

    Quasi-static, with every leg at the speed ``u``: ``z`` follows the exact
    exponential in ``x``, so the bristle force ``sigma0 z`` cycles between
    ``F1`` and ``F2`` exactly when the legs have the lengths
    ``up = (g/sigma0) ln((g - F1)/(g - F2))`` and
    ``down = (g/sigma0) ln((g + F2)/(g + F1))``; the advance per cycle
    ``up - down`` is positive (the drift). The library must produce the
    periodic force on that creeping path."""
    u = 1e-7                                       # |v| << vs
    gu = g(u)
    f1, f2 = 0.1 * FC, 0.9 * FC
    first = (gu / S0) * math.log(gu / (gu - f2))    # from rest to F2
    up = (gu / S0) * math.log((gu - f1) / (gu - f2))
    down = (gu / S0) * math.log((gu + f2) / (gu + f1))
    advance = up - down
    assert advance > 0.0
    cycles = 8
    vertices = [0.0, first]
    for _ in range(cycles):
        vertices += [vertices[-1] - down, vertices[-1] - down + up]
    t, x = polyline(vertices, samples_per_leg=25, speed=u)
    res = run(lugre(), t, x=x)
    ref = oracles.simulate(lugre(), t, x=x)
    assert_close(res.force, ref.force, REL, FS, "force-cycle path vs oracle")

    def bristle(i):        # F - sigma1 dz/dt - sigma2 v at sample i
        v = res.v[i]
        z = (res.force[i] - S1 * v - S2 * v) / (S0 * (1.0 - S1 * abs(v) / g(v)))
        return S0 * z

    tops = [25 + 50 * c for c in range(cycles + 1)]         # ends of the up legs
    bottoms = [50 + 50 * c for c in range(cycles)]          # ends of the down legs
    for i in tops:
        assert bristle(i) == pytest.approx(f2, rel=1e-8)
    for i in bottoms:
        assert bristle(i) == pytest.approx(f1, rel=1e-7)
    # the same forces, ever further along: a constant advance per cycle
    np.testing.assert_allclose(np.diff(x[tops]), advance, rtol=1e-9)
    assert advance > 1e-3 * (f2 - f1) / S0


# --- simulate's blocked two-pass loop (kernels.single.lugre_motion) ---------------

@pytest.mark.parametrize("exponent", [1.0, 2.0, 2.5])
@pytest.mark.parametrize("shape", ["exponential", "rational"])
def test_long_random_motion_against_oracle_for_every_exponent(shape, exponent):
    # 2600 samples: several blocks of the vectorised loop, a partial last one.
    t, x = random_walk(2600, 5e-6, seed=3, dwell=0.1)
    model = lugre(shape, stribeck_exponent=exponent)
    res = run(model, t, x=x)
    ref = oracles.simulate(model, t, x=x)
    assert_close(res.force, ref.force, REL, FS, f"{shape}, exponent {exponent}")


@pytest.mark.parametrize("where", [1, 2, 700, 1500, 2599])
@pytest.mark.parametrize("what", ["x nan", "x inf", "t nan", "t repeated", "overflow"])
def test_a_bad_sample_in_any_block_is_named(where, what):
    import polind

    t, x = random_walk(2600, 5e-6, seed=4)
    t, x, message = spoil_sample(t, x, where, what)
    with pytest.raises(polind.InputError, match=message):
        polind.simulate(polind.model_from_dict({"model": lugre()}), t, x=x)
