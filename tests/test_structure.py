"""polind.Structure and simulate_structure (the user guide, "Structures").

The structure driver is checked against what it must equal or approach, never
against its own earlier output:

* one coordinate with one contact to the ground is a :class:`polind.Body`
  driven by the same forces (1e-12);
* two masses with a Maxwell-slip joint match a plain explicit integration
  (written here, at a step 1e4 times smaller) to 1e-4 of the response
  amplitude, and converge at second order in the step;
* a stuck joint 100 times past the explicit stability limit is the linear
  structure with the joint's stiffness, integrated by BDF2 written here.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

import polind
from polind import InputError
from polind.models import PolInd

MODELS = {
    "coulomb": {"model": {"type": "coulomb", "coulomb_force": 1.0}},
    "maxwell-slip": {"model": {"type": "maxwell-slip", "stiffness": [1e5, 5e4],
                               "breakaway_force": [0.5, 0.5]}},
    "lugre+compliance": {"model": {
        "type": "lugre", "bristle_stiffness": 1e5, "bristle_damping": 316.0,
        "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
        "viscous_coefficient": 0.4, "compliance": {"stiffness": 2e4}}},
}


def _model(name):
    if name == "pol-ind":
        return PolInd.example()
    return polind.model_from_dict(MODELS[name])


@pytest.mark.parametrize("name", [*MODELS, "pol-ind"])
def test_one_ground_contact_is_a_body(name):
    model = _model(name)
    h = 1e-3
    samples = 801
    t = np.arange(samples) * h
    amplitude = 60.0 if name == "pol-ind" else 1.5      # beyond break-away: stick and slip
    applied = amplitude * np.sin(2 * np.pi * 3 * t)
    structure = polind.Structure(mass=1.0)
    structure.add_contact(model, dofs=(0,))
    res = polind.simulate_structure(structure, t, force=applied.reshape(-1, 1))
    body = polind.Body(model, mass=1.0, time_step=h)
    steps = np.array([body.step(float(applied[k])) for k in range(1, samples)])
    assert np.ptp(steps[:, 0]) > 0.0        # it moved
    for column, values in ((0, res.q[1:, 0]), (1, res.dq[1:, 0]), (2, res.contact_forces[1:, 0])):
        scale = max(np.ptp(steps[:, column]), 1e-300)
        assert np.abs(values - steps[:, column]).max() <= 1e-12 * scale, column
    assert res.t[-1] == pytest.approx(body.time, rel=1e-12)


@njit(cache=False)
def _explicit_two_masses(stiffness, capacity, masses, ground_stiffness, ground_damping,
                         amplitude, frequency, duration, dt):
    """A plain symplectic-Euler reference: two masses, a Maxwell-slip joint between them."""
    steps = int(round(duration / dt))
    q0 = q1 = v0 = v1 = 0.0
    slip = np.zeros(stiffness.size)
    out = np.empty((steps + 1, 3))
    out[0] = 0.0
    for i in range(steps):
        u = q0 - q1
        joint = 0.0
        for e in range(stiffness.size):
            f = stiffness[e] * (u - slip[e])
            if f > capacity[e]:
                slip[e] = u - capacity[e] / stiffness[e]
                f = capacity[e]
            elif f < -capacity[e]:
                slip[e] = u + capacity[e] / stiffness[e]
                f = -capacity[e]
            joint += f
        push = amplitude * np.sin(2 * np.pi * frequency * i * dt)
        v0 += dt * (push - ground_stiffness * q0 - ground_damping * v0 - joint) / masses[0]
        v1 += dt * joint / masses[1]
        q0 += dt * v0
        q1 += dt * v1
        out[i + 1] = q0, q1, joint
    return out


def _two_masses():
    stiffness, capacity = np.array([1e4, 5e3]), np.array([0.4, 0.6])
    joint = polind.model_from_dict({"model": {"type": "maxwell-slip",
                                              "stiffness": stiffness.tolist(),
                                              "breakaway_force": capacity.tolist()}})
    structure = polind.Structure(mass=np.diag([1.0, 0.5]),
                                 stiffness=[[200.0, 0.0], [0.0, 0.0]],
                                 damping=[[0.5, 0.0], [0.0, 0.0]])
    structure.add_contact(joint, dofs=(0, 1))
    return structure, stiffness, capacity


DURATION, REFERENCE_DT = 0.5, 1e-7


@pytest.fixture(scope="module")
def two_masses():
    structure, stiffness, capacity = _two_masses()
    reference = _explicit_two_masses(stiffness, capacity, np.array([1.0, 0.5]), 200.0, 0.5,
                                     2.0, 4.0, DURATION, REFERENCE_DT)
    return structure, reference


def _run(structure, h):
    samples = int(round(DURATION / h)) + 1
    t = np.arange(samples) * h
    force = np.zeros((samples, 2))
    force[:, 0] = 2.0 * np.sin(2 * np.pi * 4.0 * t)
    return polind.simulate_structure(structure, t, force=force)


def _error(res, reference):
    index = np.round(res.t / REFERENCE_DT).astype(int)
    amplitude = np.abs(reference[:, 0]).max()
    return np.abs(res.q[:, 0] - reference[index, 0]).max() / amplitude


def test_two_masses_with_a_joint_match_an_explicit_reference(two_masses):
    structure, reference = two_masses
    res = _run(structure, 6.25e-5)
    # the joint both sticks and slips in this run
    assert np.abs(reference[:, 2]).max() == pytest.approx(1.0, rel=1e-9)
    assert np.abs(res.contact_forces).max() == pytest.approx(1.0, rel=1e-9)
    assert _error(res, reference) <= 1e-4
    assert res.unconverged_steps == 0


def test_two_masses_converge_at_second_order(two_masses):
    structure, reference = two_masses
    errors = [_error(_run(structure, h), reference) for h in (5e-4, 2.5e-4, 1.25e-4)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert (orders > 1.8).all(), (errors, orders)


def test_a_stuck_joint_holds_far_past_the_explicit_limit():
    stiffness = np.array([6e8, 3e8])      # a Pol-Ind-like joint, N/m
    joint = polind.model_from_dict({"model": {"type": "maxwell-slip",
                                              "stiffness": stiffness.tolist(),
                                              "breakaway_force": [40.0, 60.0]}})
    mass = np.eye(2)
    ground = np.array([[1e4, 0.0], [0.0, 0.0]])
    structure = polind.Structure(mass=mass, stiffness=ground)
    structure.add_contact(joint, dofs=(0, 1))
    explicit_limit = 2.0 / np.sqrt(stiffness.sum() / 0.5)
    h = 100 * explicit_limit
    samples = 400
    t = np.arange(samples) * h
    force = np.zeros((samples, 2))
    force[:, 1] = 30.0 * np.sin(2 * np.pi * t / (50 * h))     # below the joint's 100 N
    res = polind.simulate_structure(structure, t, force=force)
    # The linear structure with the stuck joint's stiffness, BDF2 after one Euler step.
    linear = ground + stiffness.sum() * np.array([[1.0, -1.0], [-1.0, 1.0]])
    q = np.zeros((samples, 2))
    v = np.zeros((samples, 2))
    last_step = np.zeros(2)
    for k in range(1, samples):
        if k == 1:
            w = np.linalg.solve(mass / h + h * linear, force[k] + mass @ v[0] / h - linear @ q[0])
            v[k] = w
        else:
            w = np.linalg.solve(2.25 * mass / h + h * linear,
                                force[k] + mass @ (0.75 * last_step + 2 * v[k - 1]
                                                   - 0.5 * v[k - 2]) / h - linear @ q[k - 1])
            v[k] = 1.5 * w - 0.5 * last_step
        q[k] = q[k - 1] + h * w
        last_step = (q[k] - q[k - 1]) / h
    assert np.abs(res.q - q).max() <= 1e-9 * np.abs(q).max()
    slip = res.q[:, 0] - res.q[:, 1]
    # the joint force is its elements' springs, exactly: nothing slipped
    assert np.abs(res.contact_forces[:, 0] - stiffness.sum() * slip).max() \
        <= 1e-9 * np.abs(res.contact_forces).max()


def test_several_contacts_converge_and_match_the_reference():
    """Two ground contacts and a joint: the sweeps over three contacts converge."""
    stiffness, capacity = np.array([1e4, 5e3]), np.array([0.4, 0.6])
    joint = polind.model_from_dict({"model": {"type": "maxwell-slip",
                                              "stiffness": stiffness.tolist(),
                                              "breakaway_force": capacity.tolist()}})
    soft = polind.model_from_dict({"model": {"type": "maxwell-slip", "stiffness": [50.0],
                                             "breakaway_force": [1e6]}})
    structure = polind.Structure(mass=np.diag([1.0, 0.5]), damping=[[0.5, 0.0], [0.0, 0.0]])
    structure.add_contact(soft, dofs=(0,))        # a linear spring of 50 N/m, never slips
    structure.add_contact(soft, dofs=(0,))        # and another: 100 N/m to the ground
    structure.add_contact(joint, dofs=(0, 1))
    reference = _explicit_two_masses(stiffness, capacity, np.array([1.0, 0.5]), 100.0, 0.5,
                                     2.0, 4.0, DURATION, REFERENCE_DT)
    res = _run(structure, 6.25e-5)
    assert res.unconverged_steps == 0
    assert _error(res, reference) <= 1e-4
    assert res.contact_forces.shape == (res.t.shape[0], 3)
    np.testing.assert_allclose(res.contact_forces[:, 0], 50.0 * res.q[:, 0], rtol=1e-9,
                               atol=1e-12)


def test_a_contact_to_the_ground_on_the_second_slot_acts_on_minus_q():
    model = _model("maxwell-slip")
    t = np.arange(101) * 1e-3
    force = np.zeros((101, 2))
    force[:, 1] = 0.3
    s = polind.Structure(mass=np.eye(2))
    s.add_contact(model, dofs=(1, None))
    s.add_contact(model, dofs=(0,))
    res = polind.simulate_structure(s, t, force=force)
    # coordinate 1 pushed, held by its contact; coordinate 0 untouched
    assert np.abs(res.q[:, 0]).max() == 0.0
    assert res.q[-1, 1] > 0.0


def _structure():
    s = polind.Structure(mass=np.eye(2))
    s.add_contact(_model("maxwell-slip"), dofs=(0, 1))
    return s


@pytest.mark.parametrize("kwargs, words", [
    ({"mass": [[1.0, 0.5], [0.0, 1.0]]}, ["'mass'", "symmetric", "[0, 1]"]),
    ({"mass": [[1.0, 2.0], [2.0, 1.0]]}, ["'mass'", "positive definite"]),
    ({"mass": [[1.0, 0.0, 0.0]]}, ["'mass'", "square"]),
    ({"mass": np.eye(2), "stiffness": np.eye(3)}, ["'stiffness'", "2 x 2"]),
    ({"mass": np.eye(2), "damping": [1.0, 2.0]}, ["'damping'", "square"]),
    ({"mass": [[1.0, np.nan], [np.nan, 1.0]]}, ["'mass'", "finite"]),
    ({"mass": "heavy"}, ["'mass'", "numbers"]),
])
def test_bad_matrices_name_themselves(kwargs, words):
    with pytest.raises(InputError) as error:
        polind.Structure(**kwargs)
    for word in words:
        assert word in str(error.value)


@pytest.mark.parametrize("dofs, words", [
    ((2,), ["'dofs'", "0 to 1", "Got 2"]),
    ((0, 5), ["'dofs'", "Got 5 at index 1"]),
    ((0, 0), ["'dofs'", "different"]),
    ((0, 1, 1), ["'dofs'"]),
    (("a",), ["'dofs'", "indices"]),
])
def test_bad_dofs_name_themselves(dofs, words):
    s = polind.Structure(mass=np.eye(2))
    with pytest.raises(InputError) as error:
        s.add_contact(_model("maxwell-slip"), dofs=dofs)
    for word in words:
        assert word in str(error.value)


def test_a_contact_must_be_a_valid_model():
    s = polind.Structure(mass=np.eye(2))
    with pytest.raises(InputError, match="'model' of a Structure contact"):
        s.add_contact({"model": {"type": "coulomb"}}, dofs=(0,))
    with pytest.raises(InputError, match="stiffness"):
        s.add_contact(polind.model_from_dict({"model": {
            "type": "maxwell-slip", "stiffness": [-1.0], "breakaway_force": [1.0]}}), dofs=(0,))


def test_contacts_of_different_families_are_refused_by_name():
    s = polind.Structure(mass=np.eye(2))
    s.add_contact(_model("maxwell-slip"), dofs=(0, 1))
    s.add_contact(_model("coulomb"), dofs=(0,))
    with pytest.raises(InputError, match="'maxwell-slip' and 'coulomb'"):
        polind.simulate_structure(s, np.linspace(0.0, 1.0, 11))


@pytest.mark.parametrize("force, words", [
    (np.zeros((11, 3)), ["'force'", "(11, 2)", "(11, 3)"]),
    (np.zeros(11), ["'force'", "(11, 2)"]),
    (np.full((11, 2), np.inf), ["'force'", "finite", "sample 0"]),
    (lambda t: [0.0, 1.0, 2.0], ["'force' callable", "2 numbers"]),
])
def test_bad_forces_name_themselves(force, words):
    with pytest.raises(InputError) as error:
        polind.simulate_structure(_structure(), np.linspace(0.0, 1.0, 11), force=force)
    for word in words:
        assert word in str(error.value)


def test_bad_times_and_starts_are_input_errors():
    s = _structure()
    with pytest.raises(InputError, match="'t'"):
        polind.simulate_structure(s, [0.0, 1.0, 0.5])
    with pytest.raises(InputError, match="'initial_position'"):
        polind.simulate_structure(s, [0.0, 1.0], initial_position=[0.0])
    with pytest.raises(InputError, match="no contacts"):
        polind.simulate_structure(polind.Structure(mass=1.0), [0.0, 1.0])
    with pytest.raises(InputError, match="'method'"):
        polind.simulate_structure(s, [0.0, 1.0], method="rk4")


def test_a_callable_force_equals_its_samples():
    s = _structure()
    t = np.linspace(0.0, 0.2, 201)
    by_array = polind.simulate_structure(
        s, t, force=np.column_stack([np.sin(40 * t), np.zeros_like(t)]))
    by_call = polind.simulate_structure(s, t, force=lambda time: [np.sin(40 * time), 0.0])
    np.testing.assert_array_equal(by_array.q, by_call.q)
    assert by_call.final_states[0].model_type == "maxwell-slip"
