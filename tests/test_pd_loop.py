"""A PD position loop at 1 kHz on a 1 kg polind.Body with the default Pol-Ind friction.

The "done means" of the user-loop API: a controller written in Python steps
the body with the force it computes, and once the loop has settled the body
holds exactly still, the friction balances the applied force (it is the
reaction of a stuck contact, not a force the model makes up) and it never
changes sign.  And a Body stepped with a sequence of forces is the same run
as ``simulate_system`` given those forces.
"""

from __future__ import annotations

import numpy as np
import pytest

import polind
from polind.dynamics import System, simulate_system
from polind.models.pol_ind import default_table

MASS = 1.0          # kg
TIME_STEP = 1e-3    # s (1 kHz)
STEPS = 2000        # 2 s

# (setpoint [m], Kp [N/m], Kd [N s/m]).  The first stays in presliding: Kp * 1e-4 m = 2 N,
# below the 15 N break-away force (mu_s N), so the body settles after a few nanometres
# of elastic asperity deflection.  The second breaks away (Kp * 1e-3 m = 100 N), slides
# at up to 0.14 m/s against Fc = 10 N and sticks short of the setpoint, where the PD
# force (about 10.7 N) is below break-away.
LOOPS = {"presliding": (1e-4, 2e4, 2e2), "sliding": (1e-3, 1e5, 6e2)}


@pytest.fixture(scope="module")
def model():
    return polind.model_from_dict({"model": default_table()})


def run_pd(model, setpoint, kp, kd, steps=STEPS):
    """PD regulation on a Body; arrays of the applied force and of (x, v, F) after each step."""
    body = polind.Body(model, mass=MASS, time_step=TIME_STEP)
    applied = np.empty(steps)
    x = np.empty(steps)
    v = np.empty(steps)
    friction = np.empty(steps)
    for k in range(steps):
        applied[k] = kp * (setpoint - body.position) - kd * body.velocity
        x[k], v[k], friction[k] = body.step(applied[k])
    return applied, x, v, friction


@pytest.fixture(scope="module")
def loops(model):
    return {name: run_pd(model, *gains) for name, gains in LOOPS.items()}


@pytest.mark.parametrize("name", sorted(LOOPS))
def test_pd_loop_settles_and_holds_still(loops, name):
    applied, x, v, friction = loops[name]
    moving = np.flatnonzero(np.abs(v) > 1e-12)
    settled = moving[-1] + 1 if moving.size else 0
    # Settles (|v| below 1e-12 m/s for good) within the first tenth of the run:
    # after about 10 steps in presliding, 35 after sliding.
    assert settled < STEPS // 10, f"{name}: still moving at step {settled}"
    # From then on the friction never changes sign (nor vanishes): it resists the push.
    after = slice(settled, None)
    assert np.all(np.sign(friction[after]) == np.sign(applied[-1]))
    # Over the last half the body holds exactly still: no velocity, not an ulp of
    # position (the last sub-1e-12 m/s motion dies out a few steps after settling) ...
    tail = slice(STEPS // 2, None)
    assert np.all(v[tail] == 0.0)
    assert np.all(x[tail] == x[-1])
    # ... and the friction is the reaction that holds it: it equals the applied force.
    assert np.all(np.abs(friction[tail] - applied[tail]) <= 1e-9 * np.abs(applied[tail]))
    # A stuck contact holds less than the break-away force mu_s N = 15 N.
    assert np.all(np.abs(friction[tail]) < 15.0)


def test_pd_loop_presliding_stays_within_the_contact_compliance(loops):
    # 2 N on a contact of presliding stiffness ~6e8 N/m: nanometres, no gross slip.
    applied, x, v, friction = loops["presliding"]
    assert 0.0 < x[-1] < 1e-8
    assert friction[-1] == pytest.approx(applied[-1], rel=1e-9)


def test_pd_loop_sliding_sticks_short_of_the_setpoint(loops):
    # The body breaks away, slides, then sticks where the PD force is below break-away:
    # a PD loop with friction has a steady error of up to Fs / Kp.
    setpoint, kp, _ = LOOPS["sliding"]
    applied, x, v, friction = loops["sliding"]
    assert np.max(np.abs(v)) > 0.1                     # it did slide
    error = setpoint - x[-1]
    assert 0.0 < error < 15.0 / kp
    assert friction[-1] == pytest.approx(kp * error, rel=1e-9)


@pytest.mark.parametrize("name", sorted(LOOPS))
def test_body_steps_equal_simulate_system_with_the_same_forces(model, loops, name):
    applied, x, v, friction = loops[name]
    steps = 500                                        # the transient and the settled start
    system = System(mass=MASS, duration=steps * TIME_STEP, time_step=TIME_STEP)
    res = simulate_system(model, system, applied=applied[:steps])
    assert res.t.shape[0] == steps + 1
    assert res.x[0] == 0.0 and res.v[0] == 0.0
    for label, ours, theirs in (("x", x[:steps], res.x[1:]), ("v", v[:steps], res.v[1:]),
                                ("F", friction[:steps], res.force[1:])):
        scale = max(np.max(np.abs(theirs)), 1e-300)
        difference = np.max(np.abs(ours - theirs)) / scale
        assert difference <= 1e-12, f"{name}: Body {label} differs by {difference:.2e} (relative)"
    np.testing.assert_array_equal(res.applied[:steps], applied[:steps])
