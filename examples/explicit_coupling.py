"""A PD loop in python-control: the body as one system, or friction beside a mass
================================================================================

A PD position loop on a 1 kg body with the default Pol-Ind friction, closed
in python-control two ways.

* ``polind.control.body_system``: the mass and its contact as one system,
  stepped by ``polind.Body``'s implicit step. The loop sticks the body short
  of the set point, where the PD force falls below break-away, at any rate.
* ``polind.control.friction_system`` beside a separate mass: the friction of
  one sample acts on the mass over the next (explicit coupling). A stuck
  Pol-Ind contact is a spring of about 6e8 N/m, and that spring, integrated
  explicitly, is stable only for ``dt < 2 sqrt(m / k)``, 82 µs here. At
  1 kHz and at 10 kHz the loop chatters: the friction jumps between its
  levels every sample (±10 N at 1 kHz) and the body creeps to the set point
  (1 kHz) or towards it (10 kHz), which the real body never reaches. At
  20 kHz (50 µs) it sticks as the body does.

Run: ``python examples/explicit_coupling.py [OUT_DIR]``; writes
``explicit_coupling.png`` (position and friction force against time, the
last 5 ms enlarged) and prints where each loop ends. About 6 s once numba
has compiled the model (a first run compiles ``Body``'s step, a minute).
"""

import sys
from pathlib import Path

import numpy as np
import control

import polind
from polind.control import body_system, friction_system, initial_state

MASS = 1.0                            # kg
SETPOINT, KP, KD = 1e-3, 1e5, 6e2     # m, N/m, N s/m: poles of the bare mass near 50 Hz
DURATION = 0.3                        # s
ZOOM = 0.005                          # s: the enlarged end of the run


def controller(dt):
    """The PD controller as a static python-control system, inputs x and v, output u."""
    return control.nlsys(None, lambda t, x, u, params: [KP * (SETPOINT - u[0]) - KD * u[1]],
                         inputs=["x", "v"], outputs=["u"], dt=dt, name="pd")


def body_loop(model, dt):
    """The PD loop around ``body_system``: rows x, F."""
    plant = body_system(model, MASS, dt, name="body")
    loop = control.interconnect([plant, controller(dt)], inplist=[],
                                outlist=["body.x", "body.F"])
    t = dt * np.arange(round(DURATION / dt))
    return t, control.input_output_response(loop, t, 0.0, plant.initial_state).outputs


def explicit_loop(model, dt):
    """The PD loop around ``friction_system`` and a mass (semi-implicit Euler): rows x, F."""
    mass = control.ss([[1.0, dt], [0.0, 1.0]], [[dt * dt / MASS], [dt / MASS]], np.eye(2),
                      np.zeros((2, 1)), dt=dt, inputs=["f"], outputs=["x", "v"], name="mass")
    contact = friction_system(model, dt, name="contact")
    net = control.summing_junction(inputs=["u", "-F"], output="f", dt=dt, name="net")
    loop = control.interconnect([mass, contact, controller(dt), net], inplist=[],
                                outlist=["mass.x", "contact.F"])
    t = dt * np.arange(round(DURATION / dt))
    x0 = [np.zeros(2), initial_state(model)]
    return t, control.input_output_response(loop, t, 0.0, x0).outputs


def main(out_dir="."):
    model = polind.models.PolInd.example()
    stiffness = model.characteristic_scales()["presliding_stiffness"]
    limit = 2.0 * np.sqrt(MASS / stiffness)
    print(f"presliding stiffness {stiffness:.3g} N/m: explicit coupling is stable for "
          f"dt < 2 sqrt(m / k) = {limit * 1e6:.0f} us")
    runs = [("body_system, 1 kHz", body_loop(model, 1e-3)),
            ("friction_system + mass, 1 kHz", explicit_loop(model, 1e-3)),
            ("friction_system + mass, 10 kHz", explicit_loop(model, 1e-4)),
            ("friction_system + mass, 20 kHz", explicit_loop(model, 5e-5))]
    print(f"{'loop':32s} {'x at 0.3 s':>12s} {'x range, last 20 ms':>20s} "
          f"{'F range, last 20 ms':>20s}")
    for label, (t, (x, friction)) in runs:
        late = t > t[-1] - 0.02
        print(f"{label:32s} {x[-1] * 1e6:9.1f} um {np.ptp(x[late]) * 1e6:17.3f} um "
              f"{np.ptp(friction[late]):18.2f} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex="col",
                             gridspec_kw={"width_ratios": [3, 1]})
    styles = [dict(color="k", lw=2.0, zorder=4), dict(color="tab:red", lw=0.9, zorder=3,
                                                      marker="o", ms=3),
              dict(color="tab:orange", lw=0.6, zorder=1),
              dict(color="tab:blue", lw=1.2, ls="--", zorder=2)]
    for (label, (t, (x, friction))), style in zip(runs, styles):
        late = t > t[-1] - ZOOM
        whole = dict(style, marker=None)
        for column, part, look in ((0, slice(None), whole), (1, late, style)):
            axes[0, column].plot(t[part] * 1e3, x[part] * 1e6, label=label, **look)
            axes[1, column].plot(t[part] * 1e3, friction[part], **look)
    axes[0, 0].axhline(SETPOINT * 1e6, color="0.6", lw=0.8, ls=":")
    axes[0, 0].set_ylabel("position [µm]")
    axes[1, 0].set_ylabel("friction [N]")
    axes[1, 0].set_xlabel("time [ms]")
    axes[1, 1].set_xlabel(f"time [ms], last {ZOOM * 1e3:.0f} ms")
    axes[0, 0].legend(fontsize=8, loc="lower right")
    axes[0, 0].set_title(f"PD to 1 mm, 1 kg, default Pol-Ind (k = {stiffness:.2g} N/m): "
                         f"explicit coupling needs dt < {limit * 1e6:.0f} µs", fontsize=10)
    fig.tight_layout()
    path = Path(out_dir) / "explicit_coupling.png"
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


if __name__ == "__main__":
    main(*sys.argv[1:])
