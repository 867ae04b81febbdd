"""A bolted lap joint: two masses, a Maxwell-slip joint between them
==================================================================

Two clamped plates, each a mass on its own spring to the ground, overlap
and are bolted together.  The bolted interface is a Maxwell-slip joint
(an Iwan model: 20 elements of one stiffness whose slip displacements are
spread evenly up to 40 µm), between the two coordinates, ``u = q_0 - q_1``.
The first plate is shaken near the structure's first mode at three force
levels, with :class:`polind.Structure` and :func:`polind.simulate_structure`:

* small: the joint stays stuck and the structure is linear (the joint's
  loop is a line, it dissipates nothing);
* medium: microslip, the outer elements slip and the inner ones hold, and
  the loop opens (the joint damps the structure and softens it);
* large: macroslip, every element slips, the joint's force is capped at the
  sum of its break-away forces and the plates slide past each other.

Each step is implicit in the joint (the structure driver,
:ref:`guide-structures`): the elements' stiffness never limits the step,
and a stuck element holds exactly.  The second plate's spring is softer
than the first's, so that the plates pull on the joint as they vibrate.

Run: ``python examples/bolted_lap_joint.py [OUT_DIR]``; writes
``bolted_lap_joint.png`` (the first plate's response against time at each
level, and the joint's force against its relative displacement over the
last period: its hysteresis loops) and prints the energy each loop
dissipates per cycle.  About 3 s once numba has compiled the structure
driver (a first run compiles it, about 15 s).

The same structure as a file, for ``polind structure FILE --output
OUT.csv --plot PNG`` (:ref:`formats-structure`)::

    [structure]
    mass = [[1.0, 0.0], [0.0, 0.5]]
    stiffness = [[1e5, 0.0], [0.0, 1e4]]
    damping = [[20.0, 0.0], [0.0, 10.0]]

    [[structure.contacts]]
    model = "joint.toml"          # the Maxwell-slip joint below, saved with polind.save_model
    dofs = [0, 1]

    [structure.run]
    duration = 1.0
    time_step = 2e-5
    [structure.run.force]
    amplitude = [20.0, 0.0]
    frequency = 40.0
"""

import sys
from pathlib import Path

import numpy as np

import polind

ELEMENTS = 20
JOINT_STIFFNESS = 2e6            # N/m: the stuck joint, all elements together
LAST_SLIP = 40e-6                # m: the displacement at which the last element slips
FREQUENCY = 40.0                 # Hz: below the first mode with the joint stuck (43 Hz)
DURATION, STEP = 1.0, 2e-5       # s: the transient has died out by the last period
LEVELS = {"stuck": 2.0, "microslip": 20.0, "macroslip": 80.0}     # N, on the first plate


# The bolted interface: an Iwan distribution of Maxwell-slip elements, one stiffness,
# slip displacements spread evenly up to LAST_SLIP.
STIFFNESS = np.full(ELEMENTS, JOINT_STIFFNESS / ELEMENTS)
BREAKAWAY = STIFFNESS * LAST_SLIP * np.arange(1, ELEMENTS + 1) / ELEMENTS


def joint():
    return polind.model_from_dict({"model": {"type": "maxwell-slip",
                                             "stiffness": STIFFNESS.tolist(),
                                             "breakaway_force": BREAKAWAY.tolist()}})


def lap_joint():
    structure = polind.Structure(mass=[[1.0, 0.0], [0.0, 0.5]],
                                 stiffness=[[1e5, 0.0], [0.0, 1e4]],
                                 damping=[[20.0, 0.0], [0.0, 10.0]])
    structure.add_contact(joint(), dofs=(0, 1))
    return structure


def loop_energy(u, force):
    """The energy the joint dissipates over a closed loop: the loop's area [J]."""
    return float(np.abs(np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(u))))


def main(out_dir="."):
    structure = lap_joint()
    capacity = BREAKAWAY.sum()
    print(f"joint: {ELEMENTS} elements, {JOINT_STIFFNESS:.3g} N/m stuck, slides at "
          f"{capacity:.4g} N")
    t = np.arange(int(round(DURATION / STEP)) + 1) * STEP
    last = t >= t[-1] - 1.0 / FREQUENCY - 0.5 * STEP        # one whole period: a closed loop
    runs = {}
    for label, amplitude in LEVELS.items():
        force = np.zeros((t.size, 2))
        force[:, 0] = amplitude * np.sin(2 * np.pi * FREQUENCY * t)
        res = polind.simulate_structure(structure, t, force=force)
        u = res.q[:, 0] - res.q[:, 1]
        runs[label] = res
        energy = loop_energy(u[last], res.contact_forces[last, 0])
        print(f"{label:10s} {amplitude:6.1f} N: |q_0| up to "
              f"{np.abs(res.q[last, 0]).max() * 1e3:7.4f} mm, |u| up to {np.abs(u[last]).max() * 1e6:8.2f} µm, joint force up to "
              f"{np.abs(res.contact_forces[last, 0]).max():6.2f} N, {energy * 1e3:8.4f} mJ "
              f"dissipated per cycle")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.5), layout="constrained")
    for column, (label, res) in enumerate(runs.items()):
        top, bottom = axes[0, column], axes[1, column]
        top.plot(res.t, res.q[:, 0] * 1e3, lw=0.9, label="plate 1, q_0")
        top.plot(res.t, res.q[:, 1] * 1e3, lw=0.9, label="plate 2, q_1")
        top.set(xlabel="time [s]", ylabel="displacement [mm]",
                title=f"{label}: {LEVELS[label]:g} N at {FREQUENCY:g} Hz")
        top.legend(loc="upper left", fontsize=8)
        u = res.q[:, 0] - res.q[:, 1]
        bottom.plot(u[last] * 1e6, res.contact_forces[last, 0], color="C3", lw=1.4)
        bottom.set(xlabel="u = q_0 − q_1 [µm]", ylabel="joint force [N]",
                   title="the joint's loop, last period")
        for panel in (top, bottom):
            panel.grid(alpha=0.3)
    path = Path(out_dir) / "bolted_lap_joint.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}")


if __name__ == "__main__":
    main(*sys.argv[1:])
