"""Leuven (MODELS.md 6): the hysteresis force is a Maxwell-slip structure
driven by the state ``z``.

The library integrates ``dz/dt`` with an implicit step, so its forces are
compared with the accurate oracle at a tolerance that reflects the time
discretisation, and its convergence is checked as the step shrinks. The
steady state and the non-local memory of the hysteresis force are exact.
"""

import math

import numpy as np
import pytest

import oracles
from conftest import (
    REPRESENTATIVE,
    element_forces,
    polyline,
    representative,
    run,
    run_collecting_states,
)

P = REPRESENTATIVE["leuven"]
K = np.array(P["stiffness"])
W = np.array(P["breakaway_force"])
D = W / K
FC, FS, VS = P["coulomb_force"], P["static_force"], P["stribeck_velocity"]
S1, S2 = P["bristle_damping"], P["viscous_coefficient"]
REL = 1e-9


def leuven(shape="exponential", **changes):
    return representative("leuven", stribeck_shape=shape, **changes)


def s_of(v, shape="exponential"):
    return np.sign(v) * oracles.stribeck_curve(v, FC, FS, VS, 2.0, shape)


# --- the oracle --------------------------------------------------------------

def exact_step_exponent_one(deflections, v, h, s):
    """``n = 1``: on each linear piece of the branch ``Fh = Fh0 + b dz`` the
    state equation gives ``Fh(t) = s + (Fh0 - s) exp(-b v t / s)``; pieces
    end where an element saturates. Returns ``(dz, deflections)``."""
    fh = float(np.sum(K * deflections))
    direction = math.copysign(1.0, v) if fh / s < 1.0 else -math.copysign(1.0, v)
    if fh == s:
        return 0.0, deflections
    dz, remaining = 0.0, h
    while remaining > 0.0:
        current = np.clip(deflections + dz, -D, D)
        free = np.abs(direction * D - current) > 0.0       # not yet saturated this way
        b = float(np.sum(K[free]))
        fh = float(np.sum(K * current))
        if b == 0.0:
            dz += v * (1.0 - fh / s) * remaining
            break
        reach = np.min(np.abs(direction * D[free] - current[free]))   # to the next kink
        fh_kink = fh + b * direction * reach
        ratio = (fh_kink - s) / (fh - s)
        tau = -(s / (b * v)) * math.log(ratio) if 0.0 < ratio < 1.0 else math.inf
        if tau >= remaining:
            fh_end = s + (fh - s) * math.exp(-b * v * remaining / s)
            dz += (fh_end - fh) / b
            break
        dz += direction * reach
        remaining -= tau
    return dz, np.clip(deflections + dz, -D, D)


def test_oracle_matches_piecewise_exact_solution_for_exponent_one():
    model = leuven(exponent=1.0)
    t = np.linspace(0.0, 0.4, 81)
    x = 6e-5 * np.sin(2 * np.pi * 2.5 * t) + 1e-5 * np.sin(2 * np.pi * 9 * t)
    ref = oracles.simulate(model, t, x=x)
    m = oracles.motion(t, x=x)
    z, deflections = 0.0, np.zeros(len(K))
    for k in range(len(t) - 1):
        v = m.step_v[k]
        dz, deflections = exact_step_exponent_one(deflections, v, m.step_h[k], s_of(v))
        z += dz
        assert ref.states["z"][k + 1] == pytest.approx(z, rel=1e-8, abs=1e-8 * D.max())
        np.testing.assert_allclose(ref.states["element_force"][k + 1], K * deflections,
                                   rtol=1e-8, atol=1e-8 * W.max())


def virgin_consistent(forces, rel=1e-9):
    """Whether element forces lie on the virgin branch ``e_i = k_i clip(z*)``
    of one common ``z*`` (the state of a monotone path from rest)."""
    forces = np.asarray(forces, dtype=float)
    saturated = np.abs(forces) >= W * (1 - rel)
    free = ~saturated
    if np.any(free):
        z_star = forces[free] / K[free]
        if np.ptp(z_star) > rel * D.max():
            return False
        z_ref = float(np.mean(z_star))
    else:
        z_ref = float(np.sign(forces[0]) * D.max())
    signs_ok = np.all(np.sign(forces[saturated]) == np.sign(z_ref))
    reach_ok = np.all(D[saturated] <= abs(z_ref) * (1 + rel) + rel * D.max())
    return bool(signs_ok and reach_ok)


def memory_path():
    """Presliding (``|v| << vs``): rest -> A -> B -> back up beyond A."""
    return polyline([0.0, 1.6e-5, 0.4e-5, 3.0e-5], samples_per_leg=[80, 60, 130], speed=1e-6)


def test_oracle_hysteresis_memory_in_z():
    t, x = memory_path()
    ref = oracles.simulate(leuven(), t, x=x)
    z, e = ref.states["z"], ref.states["element_force"]
    z_a = z[80]
    back = np.arange(140, len(t))
    assert np.all(np.diff(z[back]) > 0)
    beyond = back[z[back] > z_a * (1 + 1e-9)]
    assert len(beyond) > 20
    for i in beyond:      # past A the state is the virgin-branch state at z
        np.testing.assert_allclose(e[i], K * np.clip(z[i], -D, D), rtol=1e-12,
                                   atol=1e-12 * W.max())
    assert not virgin_consistent(e[140])


# --- the library --------------------------------------------------------------

@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("v", [3e-4, 1e-3, 5e-3, -3e-4, -2e-3])
def test_steady_state(shape, v):
    """Steady sliding: ``dz/dt -> 0`` where ``Fh(z) = s(v)`` (``|s| < Fs`` is
    inside the range of ``Fh``), so ``F -> s(v) + sigma1 * 0 + sigma2 v``."""
    t = np.linspace(0.0, 30.0, 3001)
    res = run(leuven(shape), t, x=v * t)
    expected = s_of(v, shape) + S2 * v
    assert res.force[-1] == pytest.approx(expected, rel=REL)
    assert res.force[-2] == pytest.approx(expected, rel=REL)


def convergence_motion(n):
    t = np.linspace(0.0, 1.0, n + 1)
    x = 5e-5 * np.sin(2 * np.pi * 1.5 * t) + 1e-5 * np.sin(2 * np.pi * 7 * t + 0.4)
    return t, x


@pytest.mark.parametrize("shape, damping, drive", [("exponential", S1, "x"), ("rational", S1, "x"),
                                                  ("exponential", 0.0, "x"),
                                                  ("exponential", S1, "v")])
def test_against_oracle_converges_as_the_step_shrinks(shape, damping, drive):
    """Same sampled path for library and oracle: the difference is the
    library's time discretisation of ``z``. It must shrink at least at first
    order as the step halves, and be small at the finest step."""
    model = leuven(shape, bristle_damping=damping)
    errors = []
    for n in [150, 300, 600, 1200]:
        t, x = convergence_motion(n)
        kwargs = {"x": x} if drive == "x" else {"v": velocity_of(t)}
        res = run(model, t, **kwargs)
        ref = oracles.simulate(model, t, **kwargs)
        # sample 0 is left out: the mean dz/dt of "the step ending there" is open
        errors.append(float(np.max(np.abs(res.force[1:] - ref.force[1:]))))
    floor = 1e-9 * FS                       # an exact integrator would sit here
    for coarse, fine in zip(errors[:-1], errors[1:]):
        assert fine <= max(coarse / 1.5, floor), errors
    assert errors[-1] <= max(1e-2 * FS, floor), errors


def velocity_of(t):
    return (5e-5 * 2 * np.pi * 1.5 * np.cos(2 * np.pi * 1.5 * t)
            + 1e-5 * 2 * np.pi * 7 * np.cos(2 * np.pi * 7 * t + 0.4))


def test_standstill_keeps_the_hysteresis_force():
    """Steps with ``v = 0``: ``z`` and the elements stay, ``dz/dt = 0``, so the
    force is the hysteresis force ``sum F_i`` and does not change."""
    x = np.concatenate([np.linspace(0.0, 1e-5, 21), np.full(10, 1e-5),
                        np.linspace(1e-5, 0.2e-5, 21)[1:]])
    t = np.arange(len(x)) * 1e-2
    forces, states = run_collecting_states(leuven(), t, x, [20, 21, 25, 30])
    for i in (21, 25, 30):
        assert forces[i] == forces[21]
        np.testing.assert_array_equal(element_forces(states[i]), element_forces(states[20]))
    assert forces[25] == pytest.approx(float(np.sum(element_forces(states[25]))), rel=1e-12)


def test_hysteresis_non_local_memory():
    """Presliding loop rest -> A -> B -> beyond A: once the hysteresis force
    passes its value at A again, the element forces are exactly those of the
    virgin branch (the inner loop is wiped out), whatever the time step of
    ``z``. Element forces are read from ``state.to_dict()['element_force']``."""
    model = leuven(bristle_damping=0.0, viscous_coefficient=0.0)
    t, x = memory_path()
    check = list(range(85, 140, 6)) + list(range(141, len(t) - 1, 4))
    forces, states = run_collecting_states(model, t, x, check)
    e = {i: element_forces(st) for i, st in states.items()}
    fh = {i: float(np.sum(ei)) for i, ei in e.items()}
    for i in check:
        assert fh[i] == pytest.approx(forces[i], rel=1e-12, abs=1e-12)   # F = Fh here
    _, states_a = run_collecting_states(model, t[:81], x[:81], [])
    e_a = element_forces(states_a[80])
    assert virgin_consistent(e_a)
    fh_a = float(np.sum(e_a))
    assert fh_a < 0.9 * FS                    # presliding: A is below saturation
    inner = [i for i in check if 80 < i <= 140]
    assert not all(virgin_consistent(e[i]) for i in inner)   # the loop is real
    past = [i for i in check if i > 140 and fh[i] > fh_a + 1e-6 * FS]
    assert len(past) >= 5
    for i in past:
        assert virgin_consistent(e[i]), (i, e[i])
    assert np.all(np.abs(np.array(list(e.values()))) <= W * (1 + 1e-12))
