"""Series compliance and normal load for every model (the user guide; MODELS.md 9 and 10).

References are independent of polind's solver: a series spring on
Maxwell-slip elements solved per sample by SciPy's ``brentq`` on the plain
element update, and the classical models' forces from the plain reference
implementations in ``oracles.py``.
"""

from __future__ import annotations

import copy
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

import polind
from polind.dynamics import System, simulate_system

from conftest import REPRESENTATIVE, lib, random_walk

CLASSICAL = list(REPRESENTATIVE)


def _with(inner, **changes):
    out = copy.deepcopy(inner)
    out.update(changes)
    return out


def _series_maxwell_slip(stiffness, capacity, spring, x):
    """Elements (k_i, W_i) behind a spring k_s, driven at the spring's far end: brentq per sample.

    At every sample ``k_s (x - u) = sum_i clip(f_i + k_i (u - u_prev), +-W_i)``:
    the left side falls and the right side rises with ``u``, so the root is
    unique and lies between ``u_prev`` and ``u_prev + (x - x_prev)``.
    """
    stiffness, capacity = np.asarray(stiffness), np.asarray(capacity)
    element = np.zeros_like(stiffness)
    u = x[0]
    forces = [0.0]
    for k in range(1, len(x)):
        def residual(trial, u_prev=u):
            trial_forces = np.clip(element + stiffness * (trial - u_prev), -capacity, capacity)
            return spring * (x[k] - trial) - trial_forces.sum()
        low, high = sorted((u, u + (x[k] - x[k - 1])))
        if low == high:
            new = u
        elif residual(low) * residual(high) > 0.0:   # a root at an end, within rounding
            new = min((low, high), key=lambda end: abs(residual(end)))
        else:
            new = brentq(residual, low, high, xtol=1e-18, rtol=1e-15, maxiter=500)
        element = np.clip(element + stiffness * (new - u), -capacity, capacity)
        u = new
        forces.append(spring * (x[k] - u))
    return np.array(forces)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_maxwell_slip_behind_a_spring_is_the_piecewise_linear_solution(seed):
    rng = np.random.default_rng(seed)
    n = 6
    stiffness = rng.uniform(1e4, 1e6, n)
    capacity = rng.uniform(0.1, 1.0, n)
    spring = rng.uniform(2e4, 2e5)
    t, x = random_walk(1500, 2e-6, seed=seed)
    model = lib({"type": "maxwell-slip", "stiffness": stiffness.tolist(),
                 "breakaway_force": capacity.tolist(), "compliance": {"stiffness": spring}})
    got = polind.simulate(model, t, x=x).force
    expected = _series_maxwell_slip(stiffness, capacity, spring, x)
    scale = capacity.sum()
    assert np.max(np.abs(got - expected)) <= 1e-9 * scale
    # The spring matters: the rigid model's force is not this one.
    rigid = polind.simulate(lib({"type": "maxwell-slip", "stiffness": stiffness.tolist(),
                                 "breakaway_force": capacity.tolist()}), t, x=x).force
    assert np.max(np.abs(rigid - expected)) > 1e-2 * scale


@pytest.mark.parametrize("model_type", CLASSICAL + ["pol-ind"])
def test_a_stiff_spring_recovers_every_model(model_type):
    t = np.linspace(0.0, 1.0, 2001)
    x = 2e-3 * np.sin(2 * np.pi * 1.5 * t) + 1e-3 * np.sin(2 * np.pi * 4.0 * t)
    inner = (copy.deepcopy(REPRESENTATIVE[model_type]) if model_type != "pol-ind"
             else {"type": "pol-ind", **_small_pol_ind()})
    rigid = polind.simulate(lib(inner), t, x=x)
    scale = np.max(np.abs(rigid.force))
    errors = []
    stiffness = lib(inner).characteristic_scales()["presliding_stiffness"] or 1e3
    for spring in (1e5 * stiffness, 1e7 * stiffness):
        mounted = polind.simulate(lib(_with(inner, compliance={"stiffness": spring})), t, x=x)
        # Sample 0 carries the spring's force at rest (0); the rigid model's first
        # force is taken at the first step's velocity.
        errors.append(np.max(np.abs(mounted.force[2:] - rigid.force[2:])) / scale)
    assert errors[1] < 1e-4
    assert errors[1] <= errors[0] or errors[1] < 1e-9      # converges as k_s grows


def _small_pol_ind():
    from polind.models.pol_ind import default_table

    table = default_table()
    table.pop("type", None)
    table["discretisation"] = dict(table["discretisation"], elements=16)
    return table


def test_a_memoryless_contact_behind_a_spring_holds_until_the_spring_carries_its_static_force():
    spring, static = 1e4, 1.5
    model = lib(_with(REPRESENTATIVE["stribeck"], viscous_coefficient=0.0,
                      compliance={"stiffness": spring}))
    t = np.linspace(0.0, 1.0, 1001)
    x = 1e-3 * t                                         # the far end moves 1 mm in 1 s
    force = polind.simulate(model, t, x=x).force
    holding = spring * x < static
    # While held, the contact stands still and the spring's force is k_s x exactly.
    np.testing.assert_allclose(force[holding], spring * x[holding], rtol=1e-12, atol=1e-15)
    assert np.all(force <= static * (1 + 1e-12))
    assert force[-1] < static                             # then it slips, on the Stribeck curve


def test_the_spring_force_is_carried_over_a_continued_run():
    model = lib(_with(REPRESENTATIVE["gms"], compliance={"stiffness": 3e4}))
    t, x = random_walk(3001, 3e-6, seed=5)
    whole = polind.simulate(model, t, x=x)
    first = polind.simulate(model, t[:1500], x=x[:1500])
    second = polind.simulate(model, t[1499:], x=x[1499:], state=first.final_state)
    joined = np.concatenate((first.force, second.force[1:]))
    assert np.max(np.abs(joined - whole.force)) <= 1e-9 * np.max(np.abs(whole.force))


# One model of each kind of step (memoryless, one state, elements, load-dependent
# elements): the mounted runners are the same code for all, compiled per model.
@pytest.mark.parametrize("model_type", ["stribeck", "lugre", "gms", "pol-ind"])
def test_stepper_and_body_equal_the_runs_with_a_spring(model_type):
    inner = (copy.deepcopy(REPRESENTATIVE[model_type]) if model_type != "pol-ind"
             else {"type": "pol-ind", **_small_pol_ind()})
    model = lib(_with(inner, compliance={"stiffness": 5e4}))
    t, x = random_walk(400, 3e-6, seed=3)
    res = polind.simulate(model, t, x=x)
    stepper = polind.Stepper(model, velocity=float(res.v[0]))
    forces = [stepper.force] + [stepper.advance(float(tk), x=float(xk))
                                for tk, xk in zip(t[1:], x[1:])]
    np.testing.assert_allclose(forces, res.force, rtol=0, atol=1e-12 * np.max(np.abs(res.force)))

    rng = np.random.default_rng(1)
    applied = rng.uniform(-3.0, 3.0, 300)
    system = System(mass=0.5, duration=0.3, time_step=1e-3)
    whole = simulate_system(model, system, applied=applied)
    body = polind.Body(model, mass=0.5, time_step=1e-3)
    steps = np.array([body.step(float(f)) for f in applied])
    np.testing.assert_allclose(steps[:, 0], whole.x[1:], rtol=0, atol=1e-15)
    np.testing.assert_allclose(steps[:, 2], whole.force[1:], rtol=0, atol=1e-12)


def test_a_body_behind_a_spring_rings_on_the_spring_while_the_contact_holds():
    spring, applied = 1e5, 0.3
    model = lib(_with(REPRESENTATIVE["coulomb"], compliance={"stiffness": spring}))
    body = polind.Body(model, mass=1.0, time_step=1e-4, method="euler")
    steps = np.array([body.step(applied) for _ in range(3000)])
    x, friction = steps[:, 0], steps[:, 2]
    # The contact never moves (the spring's force stays below Fc = 1 N): the
    # friction is the spring's force k_s x, and the body is a mass on a spring,
    # x = (F/k_s)(1 - cos w t), damped only by backward Euler.
    np.testing.assert_allclose(friction, spring * x, rtol=1e-9, atol=1e-12)
    assert np.max(x) <= 2 * applied / spring * (1 + 1e-9)
    assert np.min(x) >= -1e-15
    assert np.mean(x[-1000:]) == pytest.approx(applied / spring, rel=0.02)


@pytest.mark.parametrize("model_type", CLASSICAL)
def test_a_classical_model_scales_with_the_normal_load(model_type):
    inner = copy.deepcopy(REPRESENTATIVE[model_type])
    reference = 20.0
    t, x = random_walk(2000, 4e-6, seed=11)
    load = reference * (1.0 + 0.6 * np.sin(2 * np.pi * 3.0 * t))
    got = polind.simulate(lib(_with(inner, reference_load=reference)), t, x=x, normal_load=load)
    # The model as written, at N0: the property relates the two runs (each
    # model's own force is checked against oracles.py in its own tests).
    plain = polind.simulate(lib(inner), t, x=x)
    sigma2 = inner.get("viscous_coefficient", 0.0)
    viscous = sigma2 * got.v
    expected = load / reference * (plain.force - viscous)
    scale = np.max(np.abs(plain.force))
    # Sample 0 is the force at the state (before any step) in both.
    assert np.max(np.abs((got.force - viscous) - expected)[1:]) <= 1e-10 * scale


def test_the_reference_load_changes_nothing_at_the_reference_load():
    inner = _with(REPRESENTATIVE["lugre"], reference_load=7.0)
    t, x = random_walk(500, 4e-6, seed=2)
    loaded = polind.simulate(lib(inner), t, x=x, normal_load=np.full_like(t, 7.0))
    plain = polind.simulate(lib(REPRESENTATIVE["lugre"]), t, x=x)
    # The same arithmetic, compiled in another runner: equal to rounding.
    np.testing.assert_allclose(loaded.force, plain.force, rtol=1e-14, atol=0)


def test_a_model_without_reference_load_ignores_the_load_and_says_so():
    t, x = random_walk(200, 4e-6, seed=2)
    model = lib(REPRESENTATIVE["maxwell-slip"])
    with pytest.warns(UserWarning, match="reference_load"):
        loaded = polind.simulate(model, t, x=x, normal_load=np.full_like(t, 3.0))
    np.testing.assert_array_equal(loaded.force, polind.simulate(model, t, x=x).force)
    assert loaded.normal_load is None


def test_a_stepper_and_a_body_scale_with_the_load_as_simulate_does():
    model = lib(_with(REPRESENTATIVE["gms"], reference_load=10.0))
    t, x = random_walk(300, 4e-6, seed=8)
    load = 10.0 + 5.0 * np.cos(2 * np.pi * t)
    res = polind.simulate(model, t, x=x, normal_load=load)
    stepper = polind.Stepper(model, velocity=float(res.v[0]))
    forces = [stepper.advance(float(tk), x=float(xk), normal_load=float(nk))
              for tk, xk, nk in zip(t[1:], x[1:], load[1:])]
    np.testing.assert_allclose(forces, res.force[1:], rtol=0, atol=1e-12)


def test_mount_keys_are_checked_like_every_other_key():
    with pytest.raises(polind.InputError, match="compliance.stiffness"):
        lib(_with(REPRESENTATIVE["lugre"], compliance={"stiffness": -1.0}))
    with pytest.raises(polind.InputError, match="compliance.damping"):
        lib(_with(REPRESENTATIVE["lugre"], compliance={"stiffness": 1.0, "damping": 1.0}))
    with pytest.raises(polind.InputError, match="reference_load"):
        lib(_with(REPRESENTATIVE["lugre"], reference_load=0.0))
    with pytest.raises(polind.InputError, match="Unknown key 'reference_load'"):
        lib({"type": "pol-ind", **_small_pol_ind(), "reference_load": 1.0})


def test_the_rigid_mount_constant_matches_the_kernel_layout():
    from polind.kernels.mount import make_mount
    from polind.models.kernel import RIGID as _RIGID

    np.testing.assert_array_equal(_RIGID, make_mount(force_scale=0.0))


def test_a_fit_recovers_a_known_series_stiffness():
    inner = {"type": "maxwell-slip", "stiffness": [2e5, 8e4, 3e4],
             "breakaway_force": [0.4, 0.6, 0.5], "compliance": {"stiffness": 4e4}}
    t = np.linspace(0.0, 2.0, 4001)
    x = 3e-5 * np.sin(2 * np.pi * t) + 1e-5 * np.sin(2 * np.pi * 3.3 * t)
    truth = polind.simulate(lib(inner), t, x=x).force
    rng = np.random.default_rng(0)
    measured = truth + rng.normal(0.0, 0.01 * np.std(truth), truth.shape)
    start = lib(_with(inner, compliance={"stiffness": 1e4}))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = polind.identify(start, {"t": t, "x": x, "F": measured},
                              free=["compliance.stiffness"],
                              bounds={"compliance.stiffness": [1e3, 1e6]})
    assert fit.model.series_stiffness == pytest.approx(4e4, rel=0.01)


def test_pol_ind_behind_a_spring_under_a_varying_load():
    inner = {"type": "pol-ind", **_small_pol_ind()}
    t, x = random_walk(600, 2e-7, seed=4)
    load = inner["normal_load"] * (0.8 + 0.2 * np.sin(2 * np.pi * 2.0 * t))
    rigid = polind.simulate(lib(inner), t, x=x, normal_load=load)
    stiffness = lib(inner).characteristic_scales()["presliding_stiffness"]
    stiff = polind.simulate(lib(_with(inner, compliance={"stiffness": 1e7 * stiffness})), t,
                            x=x, normal_load=load)
    scale = np.max(np.abs(rigid.force))
    assert np.max(np.abs(stiff.force[2:] - rigid.force[2:])) <= 1e-5 * scale
    model = lib(_with(inner, compliance={"stiffness": 0.5 * stiffness}))
    res = polind.simulate(model, t, x=x, normal_load=load)
    # The element table is built for the largest load of the run, as simulate does.
    stepper = polind.Stepper(model, state=model.initial_state(load))
    forces = [stepper.advance(float(tk), x=float(xk), normal_load=float(nk))
              for tk, xk, nk in zip(t[1:], x[1:], load[1:])]
    np.testing.assert_allclose(forces, res.force[1:], rtol=0, atol=1e-12 * scale)
