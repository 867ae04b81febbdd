"""A Body continued from its state, copied, stepped from numba, and many bodies at once.

Issue 23: ``Body.state`` carries the integrator's history, so a Body built
from it continues bit for bit; ``Body.copy`` for rollouts; ``Body.compiled``
for a user's ``@njit`` loop; :class:`polind.BodyBatch` for n bodies in one
call.  Every comparison below is exact (``assert_array_equal``): the same
compiled step runs on both sides.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from numba import njit

import polind
from polind.models import LuGre, PolInd

from conftest import REPRESENTATIVE, lib


def _models():
    return {
        "pol-ind": PolInd.example(),
        "lugre": LuGre.example(),
        "maxwell-slip": lib(REPRESENTATIVE["maxwell-slip"]),
        "compliance": lib({**REPRESENTATIVE["lugre"], "compliance": {"stiffness": 2e5}}),
    }


MODELS = _models()


def _pushes(n, amplitude=20.0):
    """Stick and slip: a slow sine of ``amplitude`` N at 1 kHz."""
    return (amplitude * np.sin(2.0 * np.pi * 2.0 * np.arange(1, n + 1) * 1e-3)).tolist()


def _run(body, forces):
    return np.array([body.step(force) for force in forces])


@pytest.mark.parametrize("method", ["bdf2", "euler"])
@pytest.mark.parametrize("name", list(MODELS))
def test_a_body_built_from_its_state_continues_bit_for_bit(name, method):
    model = MODELS[name]
    forces = _pushes(900)
    whole = polind.Body(model, mass=0.5, time_step=1e-3, method=method)
    expected = _run(whole, forces)
    first = polind.Body(model, mass=0.5, time_step=1e-3, method=method)
    head = _run(first, forces[:450])
    state = first.state
    # Through JSON too: the history is a variable of the state like the model's own.
    state = polind.State.from_json(state.to_json())
    restarted = polind.Body(model, mass=0.5, time_step=1e-3, method=method, state=state)
    assert restarted.time == first.time and restarted.position == first.position
    tail = _run(restarted, forces[450:])
    assert np.ptp(expected[:, 0]) > 0.0
    np.testing.assert_array_equal(np.vstack([head, tail]), expected)
    assert restarted.time == whole.time
    for key, value in whole.state.variables.items():
        np.testing.assert_array_equal(restarted.state.variables[key], value)


@pytest.mark.parametrize("name", ["pol-ind", "compliance"])
def test_a_copy_is_an_independent_body(name):
    model = MODELS[name]
    forces = _pushes(600)
    whole = polind.Body(model, time_step=1e-3)
    expected = _run(whole, forces)
    body = polind.Body(model, time_step=1e-3)
    head = _run(body, forces[:300])
    twin = body.copy()
    _run(body, [-7.0] * 50)                  # the original moves on: the copy does not follow
    tail = _run(twin, forces[300:])
    np.testing.assert_array_equal(np.vstack([head, tail]), expected)


def test_a_stale_history_is_ignored_and_a_disagreeing_position_refused():
    model = MODELS["lugre"]
    body = polind.Body(model, time_step=1e-3)
    _run(body, _pushes(100))
    state = body.state
    # simulate from it moves the sample on: the Body history it still holds is not its own.
    moved = polind.simulate(model, [body.time, body.time + 1e-3],
                            x=[body.position, body.position + 1e-6], state=state).final_state
    fresh = polind.Body(model, state=moved)
    assert fresh.position == 0.0 and fresh.time == moved.time
    with pytest.raises(polind.InputError, match="'position' of Body is the state's"):
        polind.Body(model, state=state, position=body.position + 1.0)
    assert polind.Body(model, state=state, position=body.position).position == body.position
    state.variables["body"] = np.zeros(3)
    with pytest.raises(polind.InputError, match="'body' entry"):
        polind.Body(model, state=state)
    assert json.loads(body.state.to_json())["body"][1] == body.position


@njit
def _users_loop(step, arguments, forces, out):
    for k in range(forces.shape[0]):
        x, v, friction = step(*arguments, forces[k])
        out[k, 0] = x
        out[k, 1] = v
        out[k, 2] = friction


@pytest.mark.parametrize("name", ["pol-ind", "lugre", "compliance"])
def test_a_users_njit_loop_around_compiled_equals_body_step(name):
    model = MODELS[name]
    forces = _pushes(500)
    body = polind.Body(model, time_step=1e-3)
    expected = _run(body, forces)
    other = polind.Body(model, time_step=1e-3)
    step, arguments = other.compiled()
    out = np.empty((500, 3))
    _users_loop(step, arguments, np.array(forces), out)
    np.testing.assert_array_equal(out, expected)
    # The body itself advanced: its properties and state follow, and Body.step goes on.
    assert other.time == body.time and other.friction == body.friction
    np.testing.assert_array_equal(other.state.variables["body"], body.state.variables["body"])
    assert other.step(1.0) == body.step(1.0)


@pytest.mark.parametrize("name", ["pol-ind", "lugre", "compliance"])
def test_a_body_batch_equals_independent_bodies(name):
    model = MODELS[name]
    n, steps = 5, 400
    masses = np.array([0.5, 1.0, 2.0, 1.0, 0.25])
    positions = np.array([0.0, 1e-3, -2e-3, 0.0, 5.0])
    rng = np.random.default_rng(3)
    forces = rng.normal(0.0, 15.0, (steps, n)) + np.array(_pushes(steps))[:, None]
    batch = polind.BodyBatch(model, n, mass=masses, time_step=1e-3, position=positions)
    bodies = [polind.Body(model, mass=masses[i], time_step=1e-3, position=positions[i])
              for i in range(n)]
    for k in range(steps):
        x, v, friction = batch.step(forces[k])
        expected = np.array([body.step(float(forces[k, i])) for i, body in enumerate(bodies)])
        np.testing.assert_array_equal(np.array([x, v, friction]).T, expected)
    assert batch.time == bodies[0].time
    np.testing.assert_array_equal(batch.position, [body.position for body in bodies])
    one = batch.body(2)
    assert one.step(3.0) == bodies[2].step(3.0)


def test_a_body_batch_refuses_bad_input():
    model = MODELS["lugre"]
    with pytest.raises(polind.InputError, match="'count'"):
        polind.BodyBatch(model, 0)
    with pytest.raises(polind.InputError, match="'mass' of BodyBatch must be positive"):
        polind.BodyBatch(model, 2, mass=[1.0, -1.0])
    with pytest.raises(polind.InputError, match=r"shape \(3,\)"):
        polind.BodyBatch(model, 2, position=[0.0, 1.0, 2.0])
    with pytest.raises(polind.InputError, match="'method'"):
        polind.BodyBatch(model, 2, method="rk4")
    batch = polind.BodyBatch(model, 3)
    with pytest.raises(polind.InputError, match=r"shape \(3,\)"):
        batch.step(np.zeros(2))
    with pytest.raises(polind.InputError, match=r"shape \(3,\)"):
        batch.step(np.zeros((3, 1)))
    with pytest.raises(polind.InputError, match="must be finite. Got nan for body 1"):
        batch.step([0.0, float("nan"), 0.0])
    with pytest.raises(polind.InputError, match="applied_forces"):
        batch.step("abc")
    assert batch.time == 0.0                     # nothing was stepped
    assert batch.step([1.0, 2.0, 3.0])[2].shape == (3,)


@pytest.mark.parametrize("name", ["pol-ind", "compliance"])
def test_a_refused_step_changes_nothing(name):
    """A non-finite force, or a bad load beside it, is named and leaves the body as it was."""
    model = MODELS[name]
    forces = _pushes(200)
    expected = _run(polind.Body(model, time_step=1e-3), forces)
    body = polind.Body(model, time_step=1e-3)
    head = _run(body, forces[:100])
    for bad, load in [(float("inf"), None), (float("nan"), None), (float("-inf"), -1.0)]:
        with pytest.raises(polind.InputError, match="'applied_force' of Body.step must be "
                                                    "finite"):
            body.step(bad, normal_load=load)
    with pytest.raises(polind.InputError, match="'normal_load'"):
        body.step(1.0, normal_load=-1.0)
    np.testing.assert_array_equal(np.vstack([head, _run(body, forces[100:])]), expected)


def test_a_step_lost_later_in_the_time_is_refused_there_and_changes_nothing():
    """The first steps from t = 1024 - 1e-7 s are 1e-7 s long; once past 1024 s they are not."""
    model = MODELS["lugre"]
    state = model.initial_state()
    state.time = 1024.0 - 1e-7
    body = polind.Body(model, time_step=1e-7, state=state)
    body.step(2.0)
    body.step(2.0)
    before = (body.time, body.position, body.velocity, body.friction)
    with pytest.raises(polind.InputError, match="'time_step' of Body .* is lost in its time"):
        body.step(2.0)
    assert (body.time, body.position, body.velocity, body.friction) == before
    step, arguments = body.compiled()        # from numba the lost step is NaNs, nothing changed
    out = np.empty((1, 3))
    _users_loop(step, arguments, np.array([2.0]), out)
    assert np.isnan(out).all() and body.position == before[1]
