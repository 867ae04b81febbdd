"""Single-asperity laws (MODELS.md 7.1, 7.2): moduli, Hertz, Mindlin, Masing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from polind.contact.asperity import (
    contact_radius,
    hertz_load,
    masing_force,
    mindlin_force,
    mindlin_slip_displacement,
    slip_capacity,
    tangential_stiffness,
)
from polind.contact.materials import effective_moduli
from polind.errors import InputError

# One steel asperity, 1 µm into the flat.
E_STAR, G_STAR = 115.38461538461539e9, 23.756e9
R = 50e-6
MU = 0.15
DELTA = 1e-6
P = 4.0 / 3.0 * E_STAR * math.sqrt(R) * DELTA**1.5
A = math.sqrt(R * DELTA)
U_STAR = 3.0 * MU * P / (16.0 * G_STAR * A)


def virgin(u):
    """Mindlin's virgin curve, written out from MODELS.md 7.2."""
    u = float(u)
    if abs(u) >= U_STAR:
        return math.copysign(MU * P, u)
    return math.copysign(MU * P * (1.0 - (1.0 - abs(u) / U_STAR) ** 1.5), u)


def test_effective_moduli_of_the_default_steel_pair():
    E_star, G_star = effective_moduli(210e9, 0.3, 210e9, 0.3)
    G = 210e9 / 2.6
    assert E_star == pytest.approx(210e9 / (2 * 0.91), rel=1e-15)
    assert G_star == pytest.approx(G / 3.4, rel=1e-15)


def test_effective_moduli_of_a_dissimilar_pair():
    E_star, G_star = effective_moduli(70e9, 0.33, 200e9, 0.25)
    assert 1.0 / E_star == pytest.approx((1 - 0.33**2) / 70e9 + (1 - 0.25**2) / 200e9, rel=1e-15)
    G1, G2 = 70e9 / (2 * 1.33), 200e9 / (2 * 1.25)
    assert 1.0 / G_star == pytest.approx((2 - 0.33) / G1 + (2 - 0.25) / G2, rel=1e-15)


@pytest.mark.parametrize(
    "args, name",
    [
        ((-1.0, 0.3, 1e9, 0.3), "youngs_modulus\\[0\\]"),
        ((1e9, 0.3, math.inf, 0.3), "youngs_modulus\\[1\\]"),
        ((1e9, 0.6, 1e9, 0.3), "poisson_ratio\\[0\\]"),
        ((1e9, 0.3, 1e9, -1.0), "poisson_ratio\\[1\\]"),
        ((1e9, "0.3", 1e9, 0.3), "poisson_ratio\\[0\\]"),
    ],
)
def test_bad_materials_are_input_errors(args, name):
    with pytest.raises(InputError, match=name):
        effective_moduli(*args)


def test_hertz_load_radius_stiffness_and_capacity():
    delta = np.array([-1e-7, 0.0, 2.5e-7, 1e-6])
    load = hertz_load(delta, E_STAR, R)
    np.testing.assert_allclose(load, [0, 0, 4 / 3 * E_STAR * math.sqrt(R) * 2.5e-7**1.5, P], rtol=1e-15)
    np.testing.assert_allclose(contact_radius(delta, R), [0, 0, math.sqrt(R * 2.5e-7), A], rtol=1e-15)
    np.testing.assert_allclose(tangential_stiffness(delta, R, G_STAR), 8 * G_STAR * contact_radius(delta, R))
    np.testing.assert_allclose(slip_capacity(delta, E_STAR, R, MU), MU * load)
    # The elastic-slip element's slip distance mu P / k_t = mu E* delta / (6 G*).
    assert slip_capacity(DELTA, E_STAR, R, MU) / tangential_stiffness(DELTA, R, G_STAR) == pytest.approx(
        MU * E_STAR * DELTA / (6 * G_STAR), rel=1e-14
    )


def test_mindlin_closed_form_saturation_and_oddness():
    assert float(mindlin_slip_displacement(P, A, MU, G_STAR)) == pytest.approx(U_STAR, rel=1e-15)
    u = U_STAR * np.array([0.0, 0.1, 0.5, 0.9, 1.0, 1.5, 20.0])
    expected = [virgin(x) for x in u]
    np.testing.assert_allclose(mindlin_force(u, P, A, MU, G_STAR), expected, rtol=1e-14, atol=0)
    assert float(mindlin_force(0.5 * U_STAR, P, A, MU, G_STAR)) == pytest.approx(MU * P * (1 - 0.5**1.5))
    np.testing.assert_array_equal(mindlin_force(-u, P, A, MU, G_STAR), -mindlin_force(u, P, A, MU, G_STAR))
    # An unloaded asperity carries nothing.
    assert float(mindlin_force(1e-6, 0.0, 0.0, MU, G_STAR)) == 0.0


def test_mindlin_initial_slope_is_8_G_star_a():
    h = 1e-7 * U_STAR
    slope = float(mindlin_force(h, P, A, MU, G_STAR) - mindlin_force(-h, P, A, MU, G_STAR)) / (2 * h)
    assert slope == pytest.approx(8 * G_STAR * A, rel=1e-6)


def test_masing_branch_formula():
    """Load to u_r on the virgin curve, then unload: Q = Q_r - 2 Q_v((u_r - u)/2)."""
    u_r = 0.6 * U_STAR
    down = np.linspace(u_r, -u_r, 41)
    path = np.concatenate([np.linspace(0, u_r, 21)[1:], down[1:]])
    Q = masing_force(path, P, A, MU, G_STAR)
    q_r = virgin(u_r)
    expected = [q_r - 2 * virgin((u_r - u) / 2) for u in down[1:]]
    np.testing.assert_allclose(Q[20:], expected, rtol=1e-13, atol=1e-15 * MU * P)
    np.testing.assert_allclose(Q[:20], [virgin(u) for u in path[:20]], rtol=1e-14)


def test_masing_loop_closes_and_rejoins_the_virgin_curve():
    u_r = 0.7 * U_STAR
    leg = 50
    path = np.concatenate(
        [
            np.linspace(0, u_r, leg + 1)[1:],
            np.linspace(u_r, -u_r, 2 * leg + 1)[1:],
            np.linspace(-u_r, u_r, 2 * leg + 1)[1:],
            np.linspace(u_r, 1.5 * U_STAR, leg + 1)[1:],
        ]
    )
    Q = masing_force(path, P, A, MU, G_STAR)
    q_r = virgin(u_r)
    # At -u_r the unloading branch meets the mirror of the virgin curve.
    assert Q[leg - 1 + 2 * leg] == pytest.approx(-q_r, rel=1e-13)
    # Reloading returns to (u_r, Q_r) and then continues on the virgin curve.
    assert Q[leg - 1 + 4 * leg] == pytest.approx(q_r, rel=1e-13)
    tail = path[5 * leg :]
    np.testing.assert_allclose(Q[5 * leg :], [virgin(u) for u in tail], rtol=1e-13)


def test_masing_nested_loops_are_wiped_out():
    """An inner loop closes on its starting reversal; the outer branch resumes."""
    a, b, c = 0.8 * U_STAR, -0.2 * U_STAR, 0.3 * U_STAR
    with_inner = np.concatenate(
        [
            np.linspace(0, a, 81)[1:],
            np.linspace(a, b, 101)[1:],
            np.linspace(b, c, 51)[1:],     # inner reload
            np.linspace(c, b, 51)[1:],     # back to b: the inner loop closes there
            np.linspace(b, -a, 61)[1:],
        ]
    )
    Q = masing_force(with_inner, P, A, MU, G_STAR)
    q_a = virgin(a)
    # Past b the force is the outer unloading branch, as if no inner loop.
    last = with_inner[-60:]
    np.testing.assert_allclose(Q[-60:], [q_a - 2 * virgin((a - u) / 2) for u in last], rtol=1e-12)
    # The inner reload branch from (b, Q_b).
    q_b = q_a - 2 * virgin((a - b) / 2)
    inner = with_inner[180:230]
    np.testing.assert_allclose(Q[180:230], [q_b - 2 * virgin((b - u) / 2) for u in inner], rtol=1e-12)


def _iwan_reference(path, elements):
    """Plain Maxwell-slip (Iwan) model whose virgin curve approximates Mindlin's.

    Mindlin's Q'' = -rho(x), rho(x) = (3/4) mu P / u*^2 (1 - x/u*)^(-1/2) on
    [0, u*]: elements with the stiffness of each slip-displacement bin
    (integrated exactly) and its mean slip displacement.
    """
    edges = np.linspace(0.0, U_STAR, elements + 1)
    # ∫ rho dx and ∫ x rho dx over each bin, with z = 1 - x/u*.
    z = 1.0 - edges / U_STAR
    scale = 0.75 * MU * P / U_STAR**2 * U_STAR
    stiffness = scale * 2.0 * (z[:-1] ** 0.5 - z[1:] ** 0.5)
    first = scale * U_STAR * (2.0 * (z[:-1] ** 0.5 - z[1:] ** 0.5) - (2.0 / 3.0) * (z[:-1] ** 1.5 - z[1:] ** 1.5))
    capacity = first  # k_i x_i with x_i the bin's mean slip displacement
    force = np.zeros(elements)
    previous = 0.0
    out = []
    for u in path:
        force = np.clip(force + stiffness * (u - previous), -capacity, capacity)
        previous = u
        out.append(force.sum())
    return np.array(out)


def test_masing_is_the_limit_of_a_fine_maxwell_slip_model():
    """The stack implementation vs. Iwan models of 50, 200 and 800 elements."""
    rng = np.random.default_rng(3)
    turning = U_STAR * np.array([0.0, 0.9, -0.5, 0.6, -0.2, 0.3, -1.4, 1.1, 0.2, 0.7])
    turning[1:] += 0.02 * U_STAR * rng.standard_normal(turning.size - 1)
    path = np.concatenate([np.linspace(a, b, 200)[1:] for a, b in zip(turning[:-1], turning[1:])])
    exact = masing_force(path, P, A, MU, G_STAR)
    errors = [np.abs(_iwan_reference(path, m) - exact).max() / (MU * P) for m in (50, 200, 800)]
    # Measured: 6.5e-4, 3.3e-5, 2.6e-6 of mu P.
    assert errors[-1] < 1e-5
    # Better than first order in 1/elements (4x finer, error below 1/4).
    assert errors[1] < 0.25 * errors[0] and errors[2] < 0.25 * errors[1]


def test_masing_path_shape_error():
    with pytest.raises(InputError, match="1-D"):
        masing_force(np.zeros((2, 2)), P, A, MU, G_STAR)
