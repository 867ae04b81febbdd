"""Harmonic balance, frequency response curves and backbones (polind.structures.harmonic, continuation, modes).

Each check is against an analytic result (a linear structure's exact
frequency response, a Maxwell-slip joint's exact loop energy) or against the
time integration's steady state (polind.simulate_structure), never against
the solver's own earlier output.
"""

import numpy as np
import pytest

import polind
from polind.errors import InputError


def model(**table):
    return polind.model_from_dict({"model": table})


def jenkins(k=1e4, w=1.0):
    return model(type="maxwell-slip", stiffness=[k], breakaway_force=[w])


def iwan_table(count=64, total=1e4, largest=2e-4):
    """A Maxwell-slip joint of ``count`` equal springs, slip distances spread to ``largest``."""
    slip = (np.arange(count) + 1) / count * largest
    k = np.full(count, total / count)
    return k, k * slip, slip


def one_mass(joint, damping=4.0):
    s = polind.Structure(mass=1.0, stiffness=1e4, damping=damping)
    s.add_contact(joint, dofs=(0,))
    return s


def steady_first_harmonic(structure, omega, amplitude, steps=1000, periods=90, ramp=20,
                          initial_velocity=None):
    """The first harmonic amplitude of coordinate 0 in the time integration's last period.

    The force's amplitude rises over ``ramp`` periods, so that the response
    grows from rest without overshoot (an element a transient slipped would
    keep an offset that the symmetric periodic state does not have).
    """
    period = 2 * np.pi / omega
    t = np.arange(periods * steps + 1) * (period / steps)
    envelope = np.minimum(t / (ramp * period), 1.0) if ramp else np.ones_like(t)
    res = polind.simulate_structure(structure, t, force=(amplitude * envelope
                                                         * np.cos(omega * t))[:, None],
                                    initial_velocity=initial_velocity)
    q, tt = res.q[-steps - 1:-1, 0], t[-steps - 1:-1]
    return np.hypot(2 * np.mean(q * np.cos(omega * tt)), 2 * np.mean(q * np.sin(omega * tt)))


def test_a_linear_structure_is_its_exact_frequency_response():
    spring = model(type="maxwell-slip", stiffness=[1e4], breakaway_force=[1e12])
    M = np.array([[1.0, 0.0], [0.0, 0.5]])
    K = np.array([[200.0, -50.0], [-50.0, 50.0]])
    C = np.array([[0.3, 0.0], [0.0, 0.1]])
    s = polind.Structure(mass=M, stiffness=K, damping=C)
    s.add_contact(spring, dofs=(0, 1))
    f = np.array([1.0, 0.0])
    B = np.array([[1.0, -1.0]])

    def exact(omega):
        return np.linalg.solve(K + 1e4 * B.T @ B - omega ** 2 * M + 1j * omega * C, f)

    for omega in (10.0, 50.0, 143.0, 300.0):
        res = polind.harmonic_balance(s, omega, force=f, harmonics=3)
        Q = exact(omega)
        scale = np.abs(Q).max()
        assert np.abs(res.harmonics[:, 1] - Q.real).max() <= 1e-10 * scale
        assert np.abs(res.harmonics[:, 2] + Q.imag).max() <= 1e-10 * scale   # q = Re(Q e^{iwt})
        assert np.abs(res.harmonics[:, 3:]).max() <= 1e-10 * scale
    curve = polind.frequency_response(s, (20.0, 200.0), force=f, harmonics=3)
    assert curve.omega[0] == 20.0 and curve.omega[-1] == 200.0
    assert np.all(np.diff(curve.omega) > 0)
    for point in range(len(curve)):
        Q = exact(curve.omega[point])
        error = np.abs(curve.harmonics[point, :, 1] - 1j * curve.harmonics[point, :, 2] - Q)
        assert error.max() <= 1e-10 * np.abs(Q).max()


@pytest.mark.parametrize("joint", ["jenkins", "iwan4"])
def test_the_first_harmonic_is_the_time_integrations_steady_state(joint):
    if joint == "jenkins":
        contact, levels = jenkins(), np.geomspace(0.2, 6.0, 10)
    else:
        contact = model(type="iwan4", slip_force=1.0, stiffness=1e4, chi=-0.5, beta=0.1)
        levels = np.geomspace(0.1, 6.0, 10)
    s = one_mass(contact, damping=20.0)
    omega = 120.0
    errors = []
    for level in levels:
        hb = polind.harmonic_balance(s, omega, force=[level], harmonics=7)
        errors.append(hb.amplitude(0, harmonic=1) / steady_first_harmonic(s, omega, level) - 1)
    # From microslip (the joint stuck at the smallest level) to gross slip.
    assert np.abs(errors).max() <= 1e-3, errors


def test_4h_plus_1_samples_err_by_tenths_of_a_per_cent_and_the_default_does_not():
    s = one_mass(jenkins(), damping=20.0)
    reference = polind.harmonic_balance(s, 120.0, force=[2.0], harmonics=7, samples=2048)
    few = polind.harmonic_balance(s, 120.0, force=[2.0], harmonics=7, samples=29)
    default = polind.harmonic_balance(s, 120.0, force=[2.0], harmonics=7)
    truth = reference.amplitude(0, harmonic=1)
    assert 1e-3 < abs(few.amplitude(0, harmonic=1) / truth - 1) < 1e-2
    assert abs(default.amplitude(0, harmonic=1) / truth - 1) < 3e-4


def test_a_masing_joint_gives_a_curve_without_turning_points():
    curve = polind.frequency_response(one_mass(jenkins()), (60.0, 200.0), force=[1.0])
    assert len(curve.turning_points) == 0
    assert np.all(np.diff(curve.omega) > 0)
    # The peak softens from the stuck resonance sqrt(2e4) towards the slipping one, 100.
    peak = curve.omega[np.argmax(curve.amplitude(0))]
    assert 100.0 < peak < 141.0


def test_continuation_passes_the_turning_points_of_a_joint_with_stiction():
    """A one-element LuGre joint with Fs > Fc: an overhanging curve, each stable branch a sweep's.

    (A one-element GMS joint with stiction makes a curve too, but its
    force over a period has kinks where its element switches between stick
    and slip, and the corrector stalls at 1e-5 past the first fold.)
    """
    joint = model(type="lugre", bristle_stiffness=1e4, bristle_damping=10.0, coulomb_force=1.0,
                  static_force=2.0, stribeck_velocity=0.05, stribeck_exponent=2.0,
                  viscous_coefficient=0.0)
    s = one_mass(joint, damping=2.0)
    curve = polind.frequency_response(s, (80.0, 200.0), force=[1.5], harmonics=7)
    folds = curve.turning_points
    assert len(folds) == 2
    low, high = sorted(curve.omega[folds])
    assert 100.0 < low < high < 141.0
    omega = 0.5 * (low + high)
    # The curve crosses omega three times: lower, middle (unstable) and upper branch.
    crossings = [i for i in range(len(curve) - 1)
                 if (curve.omega[i] - omega) * (curve.omega[i + 1] - omega) <= 0]
    assert len(crossings) == 3
    # Each branch solved at omega itself from the curve's point, with the samples a
    # rate model's path needs (its force follows the velocity between the samples).
    branches = sorted(polind.harmonic_balance(s, omega, force=[1.5], harmonics=7, samples=1024,
                                              initial=curve.points[i]).amplitude(0, harmonic=1)
                      for i in crossings)
    # An up sweep arrives on the lower branch (from rest); a down sweep on the upper one
    # (from a large motion).
    lower = steady_first_harmonic(s, omega, 1.5, steps=500, periods=100)
    upper = steady_first_harmonic(s, omega, 1.5, steps=500, periods=100, ramp=0,
                                  initial_velocity=[omega * 1.2 * branches[2]])
    assert lower == pytest.approx(branches[0], rel=3e-3)
    assert upper == pytest.approx(branches[2], rel=3e-3)
    assert branches[0] < branches[1] < branches[2]


def test_the_backbone_damping_is_the_energy_definition():
    k, w, slip = iwan_table()
    joint = model(type="maxwell-slip", stiffness=k.tolist(), breakaway_force=w.tolist())
    s = polind.Structure(mass=2.0, stiffness=2e4)
    s.add_contact(joint, dofs=(0,))
    amplitudes = np.sqrt(2.0) * np.geomspace(8e-6, 1.5e-4, 6)
    bb = polind.backbone(s, amplitudes, harmonics=7)
    assert bb.linear_frequency == pytest.approx(np.sqrt(3e4 / 2.0))
    X = bb.displacement_amplitude(0)
    energy = np.array([np.sum(4 * w * np.clip(x - slip, 0, None)) for x in X])
    zeta = energy / (2 * np.pi * bb.frequency ** 2 * bb.amplitude ** 2)
    assert np.all(zeta > 0)
    np.testing.assert_allclose(bb.damping_ratio, zeta, rtol=1e-2)
    assert np.all(np.diff(bb.frequency) < 0)          # the joint softens the mode


def test_iwan4_damping_follows_a_to_the_1_plus_chi():
    chi = -0.4
    joint = model(type="iwan4", slip_force=1.0, stiffness=1e4, chi=chi, beta=0.2)
    s = polind.Structure(mass=1.0, stiffness=1e4)
    s.add_contact(joint, dofs=(0,))
    phi_max = joint.density()[0]
    bb = polind.backbone(s, [0.05 * phi_max, 0.1 * phi_max], harmonics=5)
    slope = np.diff(np.log(bb.damping_ratio)) / np.diff(np.log(bb.amplitude))
    # (The loop energy's slope is within a few per cent of 3 + chi at these amplitudes.)
    assert slope[0] == pytest.approx(1 + chi, abs=0.1)


@pytest.mark.parametrize("call, key", [
    (lambda s: polind.harmonic_balance(s, 0.0, force=[1.0]), "omega"),
    (lambda s: polind.harmonic_balance(s, -3.0, force=[1.0]), "omega"),
    (lambda s: polind.harmonic_balance(s, 100.0, force=[1.0], harmonics=7, samples=28),
     "samples"),
    (lambda s: polind.harmonic_balance(s, 100.0, force=[1.0, 2.0]), "force"),
    (lambda s: polind.frequency_response(s, (0.0, 100.0), force=[1.0]), "omega_range"),
    (lambda s: polind.frequency_response(s, (50.0, 50.0), force=[1.0]), "omega_range"),
    (lambda s: polind.backbone(s, [0.0, 1e-5]), "amplitudes"),
    (lambda s: polind.backbone(s, [1e-5], mode=1), "mode"),
])
def test_bad_input_names_its_key(call, key):
    with pytest.raises(InputError, match=f"'{key}'"):
        call(one_mass(jenkins()))


def test_a_continuation_that_stops_keeps_its_points_and_says_where():
    with pytest.raises(polind.ContinuationError, match=r"omega = [0-9.]+ rad/s") as caught:
        polind.frequency_response(one_mass(jenkins()), (60.0, 200.0), force=[1.0],
                                  max_points=5)
    curve = caught.value.curve
    assert len(curve) == 5 and curve.omega[0] == 60.0 and curve.omega[-1] < 200.0
    assert isinstance(caught.value, InputError)


def test_two_contacts_on_two_masses_are_the_time_integrations_steady_state():
    """The condensation onto several contacts: a joint between the masses and one to the ground."""
    s = polind.Structure(mass=[[1.0, 0.0], [0.0, 0.5]], stiffness=[[1e4, 0.0], [0.0, 2e3]],
                         damping=[[20.0, 0.0], [0.0, 10.0]])
    s.add_contact(jenkins(1e4, 1.0), dofs=(0, 1))
    s.add_contact(jenkins(5e3, 0.5), dofs=(1,))
    omega = 90.0
    hb = polind.harmonic_balance(s, omega, force=[3.0, 0.0], harmonics=7)
    period = 2 * np.pi / omega
    steps = 1000
    t = np.arange(80 * steps + 1) * (period / steps)
    applied = np.zeros((t.size, 2))
    applied[:, 0] = 3.0 * np.minimum(t / (20 * period), 1.0) * np.cos(omega * t)
    res = polind.simulate_structure(s, t, force=applied)
    tt = t[-steps - 1:-1]
    for dof in (0, 1):
        q = res.q[-steps - 1:-1, dof]
        first = np.hypot(2 * np.mean(q * np.cos(omega * tt)), 2 * np.mean(q * np.sin(omega * tt)))
        assert hb.amplitude(dof, harmonic=1) == pytest.approx(first, rel=1e-3)
    # Both contacts slip (the loops are open), and the joint's mean force is zero.
    assert np.abs(hb.contact_force[:, 2]).min() > 0.05
    assert abs(hb.contact_force[0, 0]) < 1e-9


def test_contacts_of_different_families_are_balanced_together():
    """Harmonic balance steps each contact with its own kernel: an iwan4 joint and a LuGre
    contact to the ground in one structure (which the time driver does not take yet)."""
    s = polind.Structure(mass=[[1.0, 0.0], [0.0, 0.5]], stiffness=[[1e4, 0.0], [0.0, 0.0]],
                         damping=[[10.0, 0.0], [0.0, 5.0]])
    s.add_contact(model(type="iwan4", slip_force=1.0, stiffness=1e4, chi=-0.5, beta=0.1),
                  dofs=(0, 1))
    s.add_contact(model(type="lugre", bristle_stiffness=1e4, bristle_damping=10.0,
                        coulomb_force=0.3, static_force=0.3, stribeck_velocity=0.1,
                        stribeck_exponent=2.0, viscous_coefficient=0.0), dofs=(1,))
    hb = polind.harmonic_balance(s, 80.0, force=[2.0, 0.0], harmonics=5)
    assert hb.residual < 1e-6
    # The balance holds for every coordinate's first harmonic (exact linear algebra).
    M, K, C = s.mass, s.stiffness, s.damping
    B = np.array([[1.0, -1.0], [0.0, 1.0]])
    Q = hb.harmonics[:, 1] - 1j * hb.harmonics[:, 2]
    F = hb.contact_force[:, 1] - 1j * hb.contact_force[:, 2]
    balance = (K - 80.0 ** 2 * M + 80.0j * C) @ Q + B.T @ F - np.array([2.0, 0.0])
    assert np.abs(balance).max() < 1e-6 * 2.0


def test_a_one_element_jenkins_backbone_needs_the_loops_own_amplitude():
    """With one element the mode's higher harmonics matter: the energy definition holds at the
    motion's peak displacement (the loop's amplitude), not at its first harmonic's."""
    s = one_mass(jenkins(), damping=0.0)
    bb = polind.backbone(s, np.geomspace(1.2e-4, 2e-3, 6), harmonics=7)

    def energy_ratio(X):
        D = 4 * 1.0 * np.clip(X - 1e-4, 0, None)            # one element: 4 W (X - W/k)
        return bb.damping_ratio / (D / (2 * np.pi * bb.frequency ** 2 * bb.amplitude ** 2)) - 1

    at_peak = energy_ratio(bb.displacement_amplitude(0))
    at_first = energy_ratio(bb.displacement_amplitude(0, harmonic=1))
    assert np.abs(at_peak).max() < 3e-3
    assert np.abs(at_first).max() > 1e-2
