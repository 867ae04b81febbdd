"""Maxwell-slip (MODELS.md 4): every exact property, against closed forms and
the reference stepper in ``oracles``."""

import numpy as np
import pytest

import oracles
from conftest import (
    BREAKAWAY,
    STIFFNESS,
    assert_close,
    element_forces,
    polyline,
    random_walk,
    representative,
    run,
    spoil_sample,
)

K = np.array(STIFFNESS)
W = np.array(BREAKAWAY)
D = W / K                       # 2e-6, 6e-6, 1.25e-5, 2.5e-5 m
SUM_W = float(W.sum())
EXACT = 1e-12                   # exact identities (rounding only)
REL = 1e-9                      # tolerance-scaled comparisons


def ms(sigma2=0.0):
    return representative("maxwell-slip", viscous_coefficient=sigma2)


# --- the oracle against the closed forms ---------------------------------

def test_oracle_virgin_and_masing():
    x_r = 1.5e-5
    t, x = polyline([0.0, x_r, -4e-5], samples_per_leg=[150, 550])
    ref = oracles.simulate(ms(), t, x=x)
    assert_close(ref.force[:151], oracles.virgin_curve(x[:151], K, W), EXACT, SUM_W, "virgin")
    check_masing_from_virgin_reversal(ref.force[150:], x[150:], x_r, EXACT)


def check_masing_from_virgin_reversal(force, x, x_r, rel):
    """From a reversal at ``x_r`` on the virgin curve the branch is Masing's
    ``F_r - 2 phi((x_r - x)/2)`` until it meets the virgin curve at ``-x_r``;
    beyond that point it is the virgin curve (the loop is wiped out). When
    every element had slipped at ``x_r`` (``|x_r| >= max D``) both coincide."""
    f_r = oracles.virgin_curve(x_r, K, W)
    assert force[0] == pytest.approx(f_r, rel=rel, abs=rel * SUM_W)
    within = np.abs(x) <= abs(x_r) * (1 + 1e-12)
    assert np.count_nonzero(within) > 10
    assert_close(force[within], oracles.masing_branch(x[within], x_r, f_r, K, W),
                 rel, SUM_W, "Masing branch")
    assert_close(force[~within], oracles.virgin_curve(x[~within], K, W),
                 rel, SUM_W, "virgin curve beyond -x_r")
    if abs(x_r) >= D.max():
        assert_close(force, oracles.masing_branch(x, x_r, f_r, K, W), rel, SUM_W,
                     "Masing branch after every element slipped")


# --- the library --------------------------------------------------------

@pytest.mark.parametrize("direction", [1.0, -1.0])
@pytest.mark.parametrize("sigma2", [0.0, 0.4])
def test_virgin_curve(direction, sigma2):
    speed = 2e-4
    t, x = polyline([0.0, direction * 4e-5], samples_per_leg=400, speed=speed)
    res = run(ms(sigma2), t, x=x)
    expected = oracles.virgin_curve(x, K, W) + sigma2 * direction * speed
    assert_close(res.force, expected, REL, SUM_W, "virgin curve")


@pytest.mark.parametrize("x_r", [1.0e-6, 1.5e-5, 4e-5, -9e-6, -3e-5])
def test_masing_rule_after_reversal_on_virgin_curve(x_r):
    x_end = -x_r - np.sign(x_r) * 3e-5
    t, x = polyline([0.0, x_r, x_end], samples_per_leg=[100, 700])
    res = run(ms(), t, x=x)
    check_masing_from_virgin_reversal(res.force[100:], x[100:], x_r, REL)


def test_masing_rule_on_nested_reversals():
    """Every branch from a reversal follows ``F_r - 2 phi((x_r - x)/2)`` until
    the path passes the previous reversal point (Masing's extended rules hold
    exactly for the Maxwell-slip structure)."""
    vertices = [0.0, 3e-5, -2e-5, 1.5e-5, -5e-6, 8e-6]   # shrinking nested legs
    t, x = polyline(vertices, samples_per_leg=200)
    res = run(ms(), t, x=x)
    ref = oracles.simulate(ms(), t, x=x)
    assert_close(res.force, ref.force, REL, SUM_W, "nested reversals vs oracle")
    for leg in range(1, len(vertices) - 1):
        i0, i1 = 200 * leg, 200 * (leg + 1)
        x_r, f_r = vertices[leg], res.force[i0]
        assert_close(res.force[i0:i1 + 1],
                     oracles.masing_branch(x[i0:i1 + 1], x_r, f_r, K, W),
                     REL, SUM_W, f"Masing branch of leg {leg}")


def test_masing_rule_from_symmetric_state():
    """After a full reversal (every element slipped the other way) the state is
    symmetric and the next branch is again a Masing branch."""
    vertices = [0.0, 1e-5, -6e-5, -2e-5, -5.5e-5]   # last leg stays above -6e-5
    t, x = polyline(vertices, samples_per_leg=300)
    res = run(ms(), t, x=x)
    for leg in (2, 3):
        i0, i1 = 300 * leg, 300 * (leg + 1)
        assert_close(res.force[i0:i1 + 1],
                     oracles.masing_branch(x[i0:i1 + 1], vertices[leg], res.force[i0], K, W),
                     REL, SUM_W, f"leg {leg}")
    # the full reversal reaches -sum W
    assert res.force[600] == pytest.approx(-SUM_W, rel=EXACT)


def test_wipe_out_non_local_memory():
    """Returning to an earlier reversal point gives the force there, and beyond
    it the force follows the branch it would have followed without the inner
    loop; beyond the outer reversal it rejoins the virgin curve."""
    a, b, c1, c2, e = 2e-5, -2e-5, 0.5e-5, -1e-5, 4e-5
    n = 60                     # samples per 1e-5 m, so shared samples coincide
    def legs(vs):
        return [int(round(abs(q - p) / 1e-5 * n)) for p, q in zip(vs[:-1], vs[1:])]

    outer = [0.0, a, b, c1, e]                 # b -> e passes c1 on the way
    inner = [0.0, a, b, c1, c2, c1, e]         # inner loop c1 -> c2 -> c1
    t1, x1 = polyline(outer, legs(outer))
    t2, x2 = polyline(inner, legs(inner))
    f1 = run(ms(), t1, x=x1).force
    f2 = run(ms(), t2, x=x2).force

    i_c1_outer = sum(legs(outer)[:3])
    i_c1_first = sum(legs(inner)[:3])
    i_c1_back = sum(legs(inner)[:5])
    # the force at the return to c1 equals the force at the first visit
    assert f2[i_c1_back] == pytest.approx(f2[i_c1_first], rel=EXACT, abs=EXACT * SUM_W)
    # the inner loop was a real loop (the force moved well away on it)
    assert np.max(np.abs(f2[i_c1_first:i_c1_back] - f2[i_c1_first])) > 0.1
    # beyond c1 both runs coincide sample by sample (same x)
    np.testing.assert_array_equal(x2[i_c1_back:], x1[i_c1_outer:])
    assert_close(f2[i_c1_back:], f1[i_c1_outer:], EXACT, SUM_W, "after the inner loop")
    # beyond the outer reversal point a the virgin curve continues
    past_a = x2[i_c1_back:] >= a
    assert np.count_nonzero(past_a) > 10
    assert_close(f2[i_c1_back:][past_a], oracles.virgin_curve(x2[i_c1_back:][past_a], K, W),
                 REL, SUM_W, "virgin curve beyond the outer reversal")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sampling_independence(seed):
    """The same piecewise-linear path sampled coarsely and finely (every
    reversal a sample) gives identical forces at the shared samples."""
    rng = np.random.default_rng(seed)
    vertices = np.concatenate([[0.0], np.cumsum(rng.uniform(-6e-5, 6e-5, size=12))])
    t_c, x_c = polyline(vertices, samples_per_leg=1, speed=3e-4)
    t_f, x_f = polyline(vertices, samples_per_leg=40, speed=3e-4)
    model = ms(sigma2=0.4)
    f_c = run(model, t_c, x=x_c).force
    f_f = run(model, t_f, x=x_f).force
    np.testing.assert_array_equal(x_f[::40], x_c)
    assert_close(f_f[::40], f_c, EXACT * 100, SUM_W, "coarse vs fine sampling")


@pytest.mark.parametrize("seed", [3, 4])
def test_bounded_and_matches_oracle(seed):
    t, x = random_walk(3000, 4e-6, seed, dwell=0.1)
    model = ms(sigma2=0.4)
    res = run(model, t, x=x)
    ref = oracles.simulate(model, t, x=x)
    assert_close(res.force, ref.force, REL, SUM_W, "random walk vs oracle")
    np.testing.assert_allclose(res.v, ref.v, rtol=1e-12)
    assert np.all(np.abs(res.force - 0.4 * res.v) <= SUM_W * (1 + 1e-12))
    assert_close(element_forces(res.final_state), ref.states["element_force"][-1],
                 REL, float(W.max()), "final element forces")
    assert np.all(np.abs(element_forces(res.final_state)) <= W * (1 + 1e-12))


def test_velocity_driven_matches_oracle():
    t = np.linspace(0.0, 1.0, 2001)
    v = 2e-4 * np.cos(2 * np.pi * 3 * t) + 5e-5 * np.sin(2 * np.pi * 7 * t)
    model = ms(sigma2=0.4)
    res = run(model, t, v=v)
    ref = oracles.simulate(model, t, v=v)
    np.testing.assert_allclose(res.x, ref.x, rtol=1e-12, atol=1e-18)
    assert_close(res.force, ref.force, REL, SUM_W, "v-driven vs oracle")


def test_masing_formula_of_models_md_4_holds_only_down_to_minus_x_r():
    """MODELS.md 4 states ``F = F_r - 2 phi((x_r - x)/2)`` "until the next
    reversal".  Taken literally after a reversal at ``x_r < max D`` it fails
    beyond ``-x_r``: it falls below ``-sum W``, which no Maxwell-slip model
    can reach.  The model (and the tests above) follow Masing's second rule:
    the branch joins the virgin curve at ``-x_r``.  This test records the
    disagreement with the spec's wording."""
    x_r = 1.0e-6                          # below every slip distance
    t, x = polyline([0.0, x_r, -6e-5], samples_per_leg=[100, 700])
    res = run(ms(), t, x=x)
    f_r = oracles.virgin_curve(x_r, K, W)
    literal = oracles.masing_branch(x[100:], x_r, f_r, K, W)
    assert literal.min() < -SUM_W * 1.1            # the literal formula breaks the bound
    assert res.force.min() >= -SUM_W * (1 + 1e-12)  # the model does not
    beyond = x[100:] < -x_r
    np.testing.assert_allclose(res.force[100:][beyond],
                               oracles.virgin_curve(x[100:][beyond], K, W), rtol=1e-9)


# --- simulate's two-samples-a-pass loop (kernels.elements.maxwell_slip_motion) --------------

@pytest.mark.parametrize("samples", [3, 4, 258, 259, 2601, 2602])
def test_any_sample_count_matches_the_oracle(samples):
    # Blocks of 256, pairs of samples, and an odd sample left at the end of a block.
    t, x = random_walk(samples, 4e-6, seed=samples, dwell=0.1)
    model = ms(sigma2=0.3)
    res = run(model, t, x=x)
    ref = oracles.simulate(model, t, x=x)
    assert_close(res.force, ref.force, REL, SUM_W, f"{samples} samples")
    assert_close(element_forces(res.final_state), ref.states["element_force"][-1],
                 REL, float(W.max()), "final element forces")


@pytest.mark.parametrize("where", [1, 2, 3, 300, 2600])
@pytest.mark.parametrize("what", ["x nan", "t inf", "t repeated"])
def test_a_bad_sample_in_any_block_is_named(where, what):
    import polind

    t, x = random_walk(2601, 4e-6, seed=1)
    t, x, message = spoil_sample(t, x, where, what)
    with pytest.raises(polind.InputError, match=message):
        polind.simulate(polind.model_from_dict({"model": ms()}), t, x=x)
