"""The frequency-domain rows of ``polind bench``: harmonic balance against time integration.

The two-mass example of the guide (:ref:`guide-frequency-domain`): a 1 kg
mass on a 10 kN/m spring to the ground, a 0.5 kg mass joined to it by a
64-element joint (Segalman's ``iwan4``: 10 kN/m, 1 N), 2 % damping on the
first mass, pushed by ``F cos(omega t)`` on the first mass over 50–250
rad/s, around both modes.

- *Harmonic balance*: :func:`polind.frequency_response` at 7 harmonics and
  the default 128 samples per period, asked for 200 points along the curve
  (its step length set so the curve takes about 200).
- *Time integration*: :func:`polind.simulate_structure` at the accuracy the
  curve has (about 0.1 % on the first harmonic): 1000 BDF2 steps per period,
  for as many periods as the slowest mode's transient needs to decay to
  0.1 % of the response, at each frequency.  Timing all 200 frequencies would
  take minutes, so ``probes`` of them (spread over the range) are timed and
  the total is their mean times the curve's point count; the detail says so.

Row 1 is the ratio (time integration over harmonic balance, at least 10);
row 2 the seconds of the harmonic-balance curve (at most 30 on the
2-core machine: an absolute time, which varies between runs, reported because
the issue asks for it).
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["two_mass_structure", "frequency_response_timing", "FORCE", "OMEGA_RANGE"]

#: The force amplitude [N] on the first mass: the joint slips over most of the range.
FORCE = 2.0
#: The frequency range [rad/s].
OMEGA_RANGE = (50.0, 250.0)
#: The time integration's steps per period and the decay its transient is run to.
STEPS_PER_PERIOD = 1000
DECAY = 1e-3


def two_mass_structure(joint=None):
    """The two-mass example: ``Structure`` with ``joint`` (default a 64-element ``iwan4``) between the masses."""
    import polind

    if joint is None:
        joint = polind.model_from_dict({"model": {
            "type": "iwan4", "slip_force": 1.0, "stiffness": 1e4, "chi": -0.5, "beta": 0.1,
            "elements": 64}})
    structure = polind.Structure(mass=[[1.0, 0.0], [0.0, 0.5]],
                                 stiffness=[[1e4, 0.0], [0.0, 0.0]],
                                 damping=[[4.0, 0.0], [0.0, 0.0]])
    structure.add_contact(joint, dofs=(0, 1))
    return structure


def _periods(structure):
    """Periods for the slowest-decaying mode (its linear damping ratio, joint stuck) to fall to DECAY."""
    import scipy.linalg

    from polind.structures.harmonic import PeriodicProblem

    # The joint's stiffness while it sticks: its tangent at rest, as the balance takes it.
    joint = PeriodicProblem(structure, 1, 8, "polind bench", 0.1)
    K = structure.stiffness + joint.B.T @ (joint.k_c[:, None] * joint.B)
    values, vectors = scipy.linalg.eigh(K, structure.mass)
    zeta = [float(v @ structure.damping @ v) / (2 * np.sqrt(w)) for w, v in
            zip(values, vectors.T)]
    return int(np.ceil(np.log(1 / DECAY) / (2 * np.pi * min(zeta))))


def frequency_response_timing(points=200, probes=4):
    """``(harmonic-balance seconds, time-integration seconds, point count, detail)``."""
    import polind

    structure = two_mass_structure()
    force = [FORCE, 0.0]
    # Warm-up, and the step length that gives about ``points`` points (the count is
    # roughly inversely proportional to it).
    step = 0.02
    for _ in range(4):
        start = time.perf_counter()
        curve = polind.frequency_response(structure, OMEGA_RANGE, force=force, harmonics=7,
                                          step=step, max_points=4 * points)
        hb_seconds = time.perf_counter() - start
        if abs(len(curve) - points) <= 0.1 * points:
            break
        step *= len(curve) / points
    periods = _periods(structure)
    td = []
    errors = []
    for omega in np.linspace(*OMEGA_RANGE, probes + 2)[1:-1]:
        period = 2 * np.pi / omega
        t = np.arange(periods * STEPS_PER_PERIOD + 1) * (period / STEPS_PER_PERIOD)
        applied = np.zeros((t.shape[0], 2))
        applied[:, 0] = FORCE * np.minimum(t / (0.25 * periods * period), 1.0) * np.cos(omega * t)
        begin = time.perf_counter()
        res = polind.simulate_structure(structure, t, force=applied)
        td.append(time.perf_counter() - begin)
        q, tt = res.q[-STEPS_PER_PERIOD - 1:-1, 0], t[-STEPS_PER_PERIOD - 1:-1]
        amplitude = np.hypot(2 * np.mean(q * np.cos(omega * tt)), 2 * np.mean(q * np.sin(omega * tt)))
        hb = polind.harmonic_balance(structure, omega, force=force, harmonics=7)
        errors.append(abs(hb.amplitude(0, harmonic=1) / amplitude - 1))
    td_seconds = float(np.mean(td)) * len(curve)
    detail = (f"{len(curve)} points in {hb_seconds:.2f} s; time integration "
              f"{np.mean(td):.2f} s per frequency ({periods} periods x {STEPS_PER_PERIOD} "
              f"steps, mean of {probes}) x {len(curve)}; first harmonics agree to "
              f"{max(errors):.1e}")
    return hb_seconds, td_seconds, len(curve), detail
