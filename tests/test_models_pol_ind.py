"""The Pol-Ind model (MODELS.md 7.5-7.6): every limit of 7.6 as a test.

References are closed forms, the plain GMS oracle of ``tests/oracles.py`` run
on the model's own element table, and (for a time-varying load) a plain
Python stepper written here from the rules of 7.5 with its own separation
solve (scipy ``brentq`` on the Greenwood-Williamson load written with
``quad``), so nothing is checked against polind's own earlier output.
"""

import copy
import json
import math

import numpy as np
import pytest
from scipy import integrate, optimize

import polind
import oracles
from polind.models.pol_ind import default_table


def pol_ind(**changes):
    table = default_table()
    for key, value in changes.items():
        if "." in key:
            outer, inner = key.split(".")
            table[outer][inner] = value
        else:
            table[key] = value
    return polind.model_from_dict({"model": table})


def stribeck(v, n=100.0, mu_s=0.15, mu_k=0.10, vs=1e-3, delta=2.0, shape="exponential"):
    ratio = abs(v / vs) ** delta
    decay = math.exp(-ratio) if shape == "exponential" else 1.0 / (1.0 + ratio)
    return n * (mu_k + (mu_s - mu_k) * decay)


def table_as_gms(model, **changes):
    p = model.params
    table = model.element_table()
    n = p["normal_load"]
    gms = {"type": "gms", "stiffness": table.stiffness.tolist(),
           "weight": table.weight.tolist(), "attraction": p["attraction"],
           "coulomb_force": p["kinetic_coefficient"] * n,
           "static_force": p["static_coefficient"] * n,
           "stribeck_velocity": p["stribeck_velocity"],
           "stribeck_exponent": p["stribeck_exponent"],
           "stribeck_shape": p["stribeck_shape"],
           "viscous_coefficient": p["viscous_coefficient"]}
    gms.update(changes)
    return gms


@pytest.mark.parametrize("shape", ["exponential", "rational"])
@pytest.mark.parametrize("velocity", [-3e-2, -1e-3, -2e-4, 5e-4, 1e-3, 4e-3, 1e-1])
def test_steady_sliding_follows_the_stribeck_curve(shape, velocity):
    model = pol_ind(stribeck_shape=shape, viscous_coefficient=2.0)
    t = np.linspace(0.0, 2.0, 4001)
    res = polind.simulate(model, t, v=np.full_like(t, velocity))
    want = stribeck(velocity, shape=shape) * np.sign(velocity) + 2.0 * velocity
    assert res.force[-1] == pytest.approx(want, rel=1e-9)


def test_amontons_law_sum_of_breakaway_forces_is_mu_s_n():
    for load in (0.5, 7.0, 100.0, 3.3e3):
        table = pol_ind(normal_load=load).element_table()
        assert table.breakaway_force.sum() == pytest.approx(0.15 * load, rel=1e-9)
        assert table.weight.sum() == pytest.approx(1.0, rel=1e-12)


def test_breakaway_force_at_vanishing_velocity_is_mu_s_n():
    # A slow ramp (v = 1e-3 vs): every element reaches alpha_j g(v) with
    # g(v) = N [mu_k + (mu_s - mu_k) exp(-1e-6)], i.e. mu_s N to 1e-7.
    model = pol_ind()
    velocity = 1e-6
    table = model.element_table()
    travel = 2.0 * np.max(table.breakaway_force / table.stiffness)
    t = np.linspace(0.0, travel / velocity, 2001)
    res = polind.simulate(model, t, x=velocity * t)
    assert res.force.max() == pytest.approx(stribeck(velocity), rel=1e-9)
    assert res.force.max() == pytest.approx(15.0, rel=1e-6)


def test_presliding_virgin_curve_is_the_direct_sum_of_elastic_slip_asperity_laws():
    # From rest, a monotone displacement at |v| << vs: stuck elements follow
    # k_j u, saturated ones sit at alpha_j g(v) = W_j (1 - 1e-12).
    model = pol_ind()
    table = model.element_table()
    slip = table.breakaway_force / table.stiffness
    u = np.linspace(0.0, 1.5 * slip.max(), 3001)
    t = u / 1e-9
    res = polind.simulate(model, t, x=u)
    direct_sum = np.array([np.sum(np.minimum(table.stiffness * ui, table.breakaway_force))
                           for ui in u])
    np.testing.assert_allclose(res.force, direct_sum, rtol=1e-9, atol=1e-12 * 15.0)
    # ... and the element law is the asperity law of 7.2 / 7.5 (not a refit).
    radius, e_star, g_star = table.asperity_radius, table.E_star, table.G_star
    delta = table.interference
    np.testing.assert_allclose(table.stiffness,
                               table.asperities * 8 * g_star * np.sqrt(radius * delta), rtol=1e-12)
    np.testing.assert_allclose(table.breakaway_force,
                               table.asperities * 0.15 * 4 / 3 * e_star * np.sqrt(radius)
                               * delta ** 1.5, rtol=1e-12)


def nested_reversals(scale, samples=400):
    """A presliding path with nested reversals; every reversal is a sample."""
    corners = scale * np.array([0.0, 1.0, -0.6, 0.5, -0.2, 0.3, -0.6, 0.8, -1.0, 1.0])
    x = np.concatenate([np.linspace(a, b, samples, endpoint=False)
                        for a, b in zip(corners[:-1], corners[1:])] + [corners[-1:]])
    return np.arange(x.size) * 1e-3, x


def test_with_large_attraction_and_slow_motion_presliding_is_its_maxwell_slip_model():
    model = pol_ind(attraction=1e14)
    table = model.element_table()
    t, x = nested_reversals(0.8 * np.max(table.breakaway_force / table.stiffness))
    t = t * 1e3   # |v| ~ 1e-10 m/s << vs
    ms = polind.model_from_dict({"model": {"type": "maxwell-slip",
                                           "stiffness": table.stiffness.tolist(),
                                           "breakaway_force": table.breakaway_force.tolist()}})
    got = polind.simulate(model, t, x=x).force
    want = oracles.simulate({"type": "maxwell-slip", "stiffness": table.stiffness.tolist(),
                             "breakaway_force": table.breakaway_force.tolist()}, t, x=x).force
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * 15.0)
    np.testing.assert_allclose(polind.simulate(ms, t, x=x).force, want, rtol=1e-9,
                               atol=1e-9 * 15.0)
    # Non-local memory: back at the outer reversal x = +0.8 D_max the force is the first peak.
    peaks = np.flatnonzero(x == x.max())
    assert got[peaks[-1]] == pytest.approx(got[peaks[0]], rel=1e-9)


@pytest.mark.parametrize("motion", ["x", "v"])
def test_matches_the_gms_oracle_on_its_own_element_table(motion):
    model = pol_ind()
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(1e-4, 2e-3, 1500))
    t -= t[0]
    if motion == "x":
        kwargs = {"x": 2e-7 * np.sin(2 * np.pi * 3 * t) + 5e-8 * rng.standard_normal(t.size)}
    else:
        kwargs = {"v": 3e-3 * np.sin(2 * np.pi * 2 * t) + 1e-3 * rng.standard_normal(t.size)}
    got = polind.simulate(model, t, **kwargs).force
    want = oracles.simulate(table_as_gms(model), t, **kwargs).force
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * 15.0)


@pytest.mark.parametrize("level", [0.6, 3.0], ids=["stick-slip", "sliding"])
def test_the_kept_decay_factors_change_no_bit(level):
    # A Pol-Ind step takes its elements' decay factors from rows it keeps between steps
    # (polind.kernels.pol_ind.decay_row: the body's trials and commit, and samples with
    # the same step length, share them); GMS on its element table computes every one.
    # Pushed at 1 kHz from t = 1 s on (the step length then takes two values), sliding
    # fast (g is mu_k N to the bit: the rows serve many steps) or sticking and slipping.
    model = pol_ind()
    gms = polind.model_from_dict({"model": table_as_gms(model)})
    k = np.arange(3000)
    pushes = (level * 10.0 * np.where((k // 250) % 2 == 0, 1.0, -1.0)
              + np.sin(2 * np.pi * k / 700.0)).tolist()
    bodies = []
    for each in (model, gms):
        start = each.initial_state()
        start.time = 1.0
        bodies.append(polind.Body(each, state=start))
    got, want = bodies
    assert [got.step(push) for push in pushes] == [want.step(push) for push in pushes]
    system = polind.System(mass=2.0, duration=2.0, time_step=1e-3)
    forces = np.array(pushes[:system.times.shape[0] - 1])
    for method in ("bdf2", "euler"):
        a = polind.simulate_system(model, system, applied=forces, method=method)
        b = polind.simulate_system(gms, system, applied=forces, method=method)
        np.testing.assert_array_equal(np.array([a.x, a.v, a.force]),
                                      np.array([b.x, b.v, b.force]))
    t = 1.0 + np.arange(4000) * 2e-4
    x = 3e-3 * np.sin(2 * np.pi * 3 * t)
    np.testing.assert_array_equal(polind.simulate(model, t, x=x).force,
                                  polind.simulate(gms, t, x=x).force)


@pytest.mark.parametrize("summation", ["statistical", "direct"])
def test_the_kept_decay_factors_follow_a_changing_load(summation):
    # A load that dips for one step and comes back changes the weights under the kept
    # factors (a direct surface's separation, warm-started, comes back to within a few
    # ulp): a body equals one whose kept factors are forgotten before every step.
    from polind.kernels import pol_ind as slots

    model = pol_ind(**{"discretisation.summation": summation, "discretisation.elements": 48})
    bodies = polind.Body(model), polind.Body(model)
    forgotten = bodies[1]._kernel.scalars
    for k in range(1500):
        load = 90.0 if k % 5 == 0 else (100.0 if (k // 100) % 2 == 0 else 95.0)
        push = 14.0 * (1.0 if (k // 300) % 2 == 0 else -1.0)
        forgotten[slots.DECAY_KEYS:slots.DECAY_KEYS + 4] = np.nan
        assert bodies[0].step(push, normal_load=load) == bodies[1].step(push, normal_load=load)


def test_the_kept_decay_factors_are_computed_again_for_new_weights():
    # Whatever writes the weights, a step after it uses factors of the weights it finds:
    # a step at the h and g of kept factors, on weights changed in place, equals the step
    # on a copy of the arrays that kept no factors.
    from polind.kernels import elements, pol_ind as slots

    model = pol_ind()
    kernel = model.step_kernel(model.initial_state())
    scalars, table, state = kernel.scalars, kernel.table, kernel.state
    # Sliding at two velocities below a few Stribeck velocities (vs = 1 mm/s): g differs
    # between them, so the slipping elements relax with their factors at each change
    # (with C h / g about 1e-2: factors of order one).
    step, load = 1e-5, kernel.normal_load
    for velocity in (2e-3, 1e-3, 2e-3, 1e-3):
        slots.settled_step(scalars, table, state, step, step * velocity, velocity, velocity, load)
    velocity = 2e-3
    table[elements.ELEMENT_INVERSE, ::3] *= 1.25
    fresh = scalars.copy(), table.copy(), state.copy()
    fresh[0][slots.DECAY_KEYS:slots.DECAY_KEYS + 4] = np.nan
    got = slots.settled_step(scalars, table, state, step, step * velocity, velocity, velocity,
                             load)
    want = slots.settled_step(*fresh, step, step * velocity, velocity, velocity, load)
    assert got == want
    np.testing.assert_array_equal(state, fresh[2])


# --- a time-varying normal load (MODELS.md 7.5 Choice) ------------------------------------

def gw_load(d, p):
    """N(d) of the statistical surface, by quadrature in the normalised height."""
    s = p["surface"]
    e1, e2 = p["materials"]["youngs_modulus"]
    n1, n2 = p["materials"]["poisson_ratio"]
    e_star = 1.0 / ((1 - n1 ** 2) / e1 + (1 - n2 ** 2) / e2)
    sigma = s["height_std"]
    f32 = integrate.quad(lambda u: (u - d / sigma) ** 1.5 * math.exp(-u * u / 2)
                         / math.sqrt(2 * math.pi), d / sigma, np.inf, epsabs=0, epsrel=1e-13)[0]
    return (4 / 3 * s["asperity_density"] * s["nominal_area"] * e_star
            * math.sqrt(s["asperity_radius"]) * sigma ** 1.5 * f32)


def reference_varying_load(model, t, x, load):
    """Plain stepper of 7.5-7.6 with elements fixed in h, d(t) by brentq on the GW load."""
    p = model.params
    table = model.element_table(float(load.max()))
    sigma = p["surface"]["height_std"]

    def separation_at(n):
        return optimize.brentq(lambda d: gw_load(d, p) - n, -4 * sigma, 8 * sigma,
                               xtol=1e-22, rtol=1e-15)

    return oracles.pol_ind_varying_load(
        t, x, load, table.heights, table.asperities * np.sqrt(table.asperity_radius),
        separation_at, table.G_star, p["static_coefficient"], p["kinetic_coefficient"],
        p["stribeck_velocity"], p["attraction"])


def test_time_varying_load_follows_the_rules_of_7_5():
    model = pol_ind(**{"discretisation.elements": 16})
    t = np.linspace(0.0, 0.2, 241)
    x = 3e-7 * np.sin(2 * np.pi * 10 * t) + 2e-3 * t
    load = 100.0 + 60.0 * np.sin(2 * np.pi * 7 * t) ** 2 - 30.0 * (t > 0.1)
    got = polind.simulate(model, t, x=x, normal_load=load).force
    want = reference_varying_load(model, t, x, load)
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-8 * 160.0)
    # Sliding friction scales with the load it has at each sample (Amontons).
    sliding = np.abs(np.gradient(x, t)) > 1e-3
    assert np.all(np.abs(got[sliding]) <= 0.15 * load[sliding] * (1 + 1e-12))


def test_varying_load_through_every_branch_of_the_step():
    """Moving and standing samples, changing and repeated loads, contact lost and regained.

    The kernel takes a different path for each: a moving sample at a new load
    (one fused pass), a standing one at a new load (the table first), a moving
    one at the previous load just after a new one (the weights brought up to
    date first) and one at an unchanged load.  All against the plain stepper.
    """
    model = pol_ind(**{"discretisation.elements": 16})
    t = np.linspace(0.0, 0.3, 601)
    x = 3e-7 * np.sin(2 * np.pi * 8 * t) + 1e-3 * t
    x[150:200] = x[150]                          # standing while the load changes
    x[400:420] = x[400]
    load = 90.0 + 70.0 * np.sin(2 * np.pi * 6 * t)   # 20 N to 160 N: elements leave and return
    load[250:330] = load[250]                    # then moving at an unchanged load
    load[480:483] = 35.0
    load[483:490:2] = 150.0                      # alternating jumps
    got = polind.simulate(model, t, x=x, normal_load=load).force
    want = reference_varying_load(model, t, x, load)
    np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-8 * 160.0)
    # And one sample at a time (Stepper) is the same run.
    # (its state's table is built at the model's load: the largest of the run)
    stepper = polind.Stepper(model.with_params(normal_load=float(load.max())), time=t[0],
                             position=x[0])
    stepped = [stepper.advance(tk, x=xk, normal_load=nk)
               for tk, xk, nk in zip(t[1:].tolist(), x[1:].tolist(), load[1:].tolist())]
    np.testing.assert_allclose(stepped, got[1:], rtol=1e-12, atol=1e-12 * 160.0)
    # The run did lose and regain contact: at 20 N 5 of the 16 elements carry load.
    p = model.params
    sigma = p["surface"]["height_std"]
    lowest = optimize.brentq(lambda d: gw_load(d, p) - load.min(), -4 * sigma, 8 * sigma,
                             xtol=1e-22, rtol=1e-15)
    heights = model.element_table(float(load.max())).heights
    assert 0 < np.sum(heights > lowest) < heights.size // 2


@pytest.mark.parametrize("changes", [{}, {"materials.hardness": 2e9},
                                     {"compliance": {"stiffness": 2e6}}],
                         ids=["hertz", "plastic", "compliance"])
def test_constant_load_array_equals_the_constant_load_model(changes):
    # Without a load the run takes the fixed-load step (no load path compiled); with a
    # constant load array the full step: bit for bit the same forces.
    table = default_table()
    for key, value in changes.items():
        if "." in key:
            outer, inner = key.split(".")
            table.setdefault(outer, {})[inner] = value
        else:
            table[key] = value
    model = polind.model_from_dict({"model": table})
    fixed = model.step_kernel(model.initial_state(), fixed_load=True)
    full = model.step_kernel(model.initial_state(), np.array([100.0]))
    assert fixed.runners is not full.runners and fixed.step is not full.step
    t = np.linspace(0.0, 0.5, 501)
    x = 4e-7 * np.sin(2 * np.pi * 4 * t) + 2e-4 * t
    a = polind.simulate(model, t, x=x).force
    b = polind.simulate(model, t, x=x, normal_load=np.full_like(t, 100.0)).force
    np.testing.assert_array_equal(a, b)
    assert np.ptp(a) > 1.0


def test_a_state_tabled_at_another_load_takes_the_full_step():
    model = pol_ind()
    state = polind.simulate(model, [0.0, 1e-3], x=[0.0, 1e-7],
                            normal_load=[120.0, 120.0]).final_state
    kernel = model.step_kernel(state, fixed_load=True)
    assert kernel.step is model.step_functions().step
    assert model.step_kernel(model.initial_state(), fixed_load=True).step \
        is not model.step_functions().step


def test_the_fixed_load_step_refuses_another_load():
    # A caller that broke the fixed-load promise gets a non-finite force, never a wrong one.
    from polind.kernels.pol_ind_fixed import fixed_load_step

    model = pol_ind()
    kernel = model.step_kernel(model.initial_state(), fixed_load=True)
    force = fixed_load_step(kernel.scalars, kernel.table, kernel.state, 1e-3, 1e-8, 1e-5,
                            1e-5, 90.0)
    assert not math.isfinite(force)
    kernel = model.step_kernel(model.initial_state(), fixed_load=True)
    assert math.isfinite(fixed_load_step(kernel.scalars, kernel.table, kernel.state, 1e-3,
                                         1e-8, 1e-5, 1e-5, 100.0))


@pytest.mark.parametrize("plastic", [False, True], ids=["hertz", "plastic"])
def test_the_fixed_load_functions_take_only_a_fresh_table_at_its_load(plastic):
    # A fixed-load kernel's arrays are fresh at the table's load: the one promise its
    # functions (no upkeep of the table) rely on. A table that is stale or at another load
    # gets NaN and no step; kept, the path step, the solvers' step and their trial agree
    # to the bit.
    from polind.kernels.pol_ind import CURRENT_LOAD, TABLE_STALE
    from polind.kernels.pol_ind_fixed import (fixed_load_force, fixed_load_path_step,
                                              fixed_load_step, fixed_load_trial_step)

    model = pol_ind(**({"materials.hardness": 2e9} if plastic else {}))
    kernel = model.step_kernel(model.initial_state(), fixed_load=True)
    assert kernel.scalars[CURRENT_LOAD] == kernel.normal_load == 100.0
    assert kernel.scalars[TABLE_STALE] == 0.0
    assert kernel.runners.model_trial is fixed_load_trial_step
    arguments = (1e-3, 1e-8, 1e-5, 1e-5)
    for load, stale in ((90.0, 0.0), (100.0, 1.0)):
        scalars, table, state = kernel.scalars.copy(), kernel.table.copy(), kernel.state.copy()
        scalars[TABLE_STALE] = stale
        for step in (fixed_load_path_step, fixed_load_step):
            assert math.isnan(step(scalars, table, state, *arguments, load))
        assert math.isnan(fixed_load_force(scalars, table, state, 1e-5, load))
        assert fixed_load_trial_step(scalars, table, state, np.empty(state.size), True,
                                     *arguments, load)[2] == -1
        np.testing.assert_array_equal(state, kernel.state)
        np.testing.assert_array_equal(table, kernel.table)
    a, b, c = (model.step_kernel(model.initial_state(), fixed_load=True) for _ in range(3))
    out = np.empty(c.state.size)
    slipped = False
    for k in range(1, 200):
        w = 2e-3 * math.cos(k / 15.0)
        step = (1e-3, 1e-3 * w, w, w, 100.0)
        force = fixed_load_step(b.scalars, b.table, b.state, *step)
        assert fixed_load_path_step(a.scalars, a.table, a.state, *step) == force
        trial, _, written = fixed_load_trial_step(c.scalars, c.table, c.state, out, True, *step)
        assert trial == pytest.approx(force, rel=1e-14)      # its own sum: to rounding
        c.state[:written] = out[:written]
        n = b.table.shape[1]
        slipped |= bool(np.any(b.state[n:2 * n] != 0.0))
    assert slipped                  # the decay factors were used
    np.testing.assert_array_equal(a.state, b.state)
    np.testing.assert_array_equal(c.state, b.state)


@pytest.mark.parametrize("varying", [False, True])
def test_chunked_run_equals_one_run(varying):
    model = pol_ind(**{"discretisation.elements": 32})
    t = np.linspace(0.0, 0.4, 801)
    x = 3e-7 * np.sin(2 * np.pi * 5 * t) + 1e-3 * t
    load = 100.0 + 20 * np.cos(2 * np.pi * 3 * t) if varying else None   # peak in chunk 1
    whole = polind.simulate(model, t, x=x, normal_load=load)
    forces = []
    state = None
    for lo, hi in [(0, 300), (299, 550), (549, 801)]:
        part = polind.simulate(model, t[lo:hi], x=x[lo:hi], state=state,
                               normal_load=None if load is None else load[lo:hi])
        state = polind.State.from_dict(json.loads(json.dumps(part.final_state.to_dict())))
        forces.append(part.force if not forces else part.force[1:])
        if len(forces) > 1:
            assert part.force[0] == previous_last
        previous_last = part.force[-1]
    np.testing.assert_allclose(np.concatenate(forces), whole.force, rtol=1e-10, atol=1e-12)


def test_continuation_above_the_tables_load_is_an_error():
    model = pol_ind()
    t = np.linspace(0.0, 0.1, 11)
    res = polind.simulate(model, t, x=1e-8 * t, normal_load=np.full(11, 50.0))
    with pytest.raises(polind.InputError, match="normal_load"):
        polind.simulate(model, t + 0.1, x=1e-8 * (t + 0.1), normal_load=np.full(11, 80.0),
                        state=res.final_state)


def test_direct_summation_runs_on_sampled_asperities():
    model = pol_ind(**{"discretisation.summation": "direct"})
    table = model.element_table()
    assert np.all(table.asperities == 1.0)
    assert table.breakaway_force.sum() == pytest.approx(15.0, rel=1e-9)
    t = np.linspace(0.0, 1.0, 2001)
    res = polind.simulate(model, t, v=np.full_like(t, 0.01))
    assert res.force[-1] == pytest.approx(stribeck(0.01), rel=1e-9)


@pytest.mark.parametrize("key, value, fragment", [
    ("normal_load", -1.0, "normal_load"),
    ("surface.height_std", 0.0, "surface.height_std"),
    ("materials.poisson_ratio", [0.3, 0.7], "materials.poisson_ratio"),
    ("materials.youngs_modulus", [210e9], "materials.youngs_modulus"),
    ("discretisation.summation", "fractal", "discretisation.summation"),
    ("discretisation.elements", 0, "discretisation.elements"),
    ("attraction", float("nan"), "attraction"),
])
def test_bad_parameters_name_the_key(key, value, fragment):
    with pytest.raises(polind.InputError, match=fragment.replace(".", r"\.")):
        pol_ind(**{key: value})


def test_unknown_nested_key_is_named():
    table = default_table()
    table["surface"]["roughness"] = 1.0
    with pytest.raises(polind.InputError, match=r"surface\.roughness"):
        polind.model_from_dict({"model": table})


def test_normal_load_array_must_be_positive_and_a_model_without_load_ignores_it():
    t = np.linspace(0.0, 1.0, 5)
    coulomb = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    with pytest.warns(UserWarning, match="ignores the normal-load signal"):
        polind.simulate(coulomb, t, x=t, normal_load=np.ones(5))
    with pytest.raises(polind.InputError, match="normal_load"):
        polind.simulate(coulomb, t, x=t, normal_load=-np.ones(5))
    with pytest.raises(polind.InputError, match="normal_load"):
        polind.simulate(pol_ind(), t, x=t, normal_load=np.array([1.0, 2.0, -1.0, 1.0, 1.0]))


def test_simulate_does_not_mutate_the_model():
    model = pol_ind()
    before = copy.deepcopy(model.to_dict())
    t = np.linspace(0.0, 0.1, 101)
    polind.simulate(model, t, x=1e-7 * np.sin(60 * t), normal_load=90 + 10 * t)
    assert model.to_dict() == before


def test_gms_parameters_are_the_gms_this_model_is_at_its_load():
    model = pol_ind(viscous_coefficient=0.7, stribeck_shape="rational")
    got = model.gms_parameters()
    want = table_as_gms(model)
    assert set(got) == set(want) - {"type"}
    for key in got:
        if isinstance(want[key], str):
            assert got[key] == want[key]
        else:
            np.testing.assert_allclose(got[key], want[key], rtol=1e-15)
    gms = polind.model_from_dict({"model": {"type": "gms", **{
        key: (value.tolist() if isinstance(value, np.ndarray) else value)
        for key, value in got.items()}}})
    t = np.linspace(0.0, 0.5, 1001)
    x = 4e-7 * np.sin(2 * np.pi * 6 * t) + 2e-3 * t
    np.testing.assert_array_equal(polind.simulate(gms, t, x=x).force,
                                  polind.simulate(model, t, x=x).force)


def test_models_with_the_same_surface_share_it_and_others_do_not():
    table = default_table()
    table["discretisation"] = {"summation": "direct", "seed": 3, "elements": 16}
    one = polind.model_from_dict({"model": table})
    other = one.with_params(static_coefficient=0.2, kinetic_coefficient=0.12)
    assert one.contact().surface is other.contact().surface
    np.testing.assert_allclose(one.element_table().weight, other.element_table().weight,
                               rtol=1e-14)
    # The break-away forces are the model's own (mu_s N times the weights).
    np.testing.assert_allclose(other.element_table().breakaway_force.sum(), 0.2 * 100.0)
    rougher = one.with_params(surface=dict(table["surface"], height_std=1e-6))
    assert rougher.contact().surface is not one.contact().surface


def test_a_heights_file_replaces_the_sampled_surface_keys(tmp_path):
    summits = tmp_path / "summits.csv"
    rng = np.random.default_rng(2)
    summits.write_text("h\n" + "\n".join(repr(float(h)) for h in rng.normal(0.0, 1e-6, 500)))
    table = default_table()
    table["discretisation"] = {"summation": "direct", "heights_file": str(summits),
                               "elements": 16}
    with pytest.raises(polind.InputError, match=r"'surface.asperity_density' .* not used with "
                                                r"a 'discretisation.heights_file'"):
        polind.model_from_dict({"model": table})
    table["surface"] = {"asperity_radius": table["surface"]["asperity_radius"]}
    model = polind.model_from_dict({"model": table})
    assert model.contact().surface.asperity_count == 500
    assert model.contact().elements.normal_load == pytest.approx(100.0, rel=1e-10)
    statistical = default_table()
    del statistical["surface"]["height_std"]
    with pytest.raises(polind.InputError, match="Missing key 'surface.height_std'"):
        polind.model_from_dict({"model": statistical})


def test_a_fit_of_a_model_on_measured_summits_frees_only_the_keys_it_has(tmp_path):
    summits = tmp_path / "summits.csv"
    rng = np.random.default_rng(3)
    summits.write_text("h\n" + "\n".join(repr(float(h)) for h in rng.normal(0.0, 1e-6, 300)))
    table = default_table()
    table["discretisation"] = {"summation": "direct", "heights_file": str(summits),
                               "elements": 8}
    table["surface"] = {"asperity_radius": table["surface"]["asperity_radius"]}
    truth = polind.model_from_dict({"model": table})
    t = np.linspace(0.0, 1.0, 201)
    x = 2e-7 * np.sin(6 * t)
    data = {"t": t, "x": x, "F": polind.simulate(truth, t, x=x).force}
    start = truth.with_params(static_coefficient=0.2)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = polind.identify(start, data)
    assert "static_coefficient" in fit.free and "surface.height_std" not in fit.free
    assert fit.model.params["static_coefficient"] == pytest.approx(0.15, rel=1e-3)
