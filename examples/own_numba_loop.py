"""A polind model inside your own compiled loop
==============================================

A spring-mass oscillator with LuGre friction, integrated by your own numba loop.

``model.step_kernel()`` hands out the model's numba step function and its
arrays; a loop compiled with numba calls it once per sample and never
returns to Python.  Here the user's loop is their own integrator (a
symplectic Euler step of ``m a = -k x - F``, explicit, so the time step must
resolve the LuGre bristle stiffness), and the friction force comes from the
model's exact per-step update at the step's velocity.

Run: ``python examples/own_numba_loop.py [OUT_DIR]``; writes
``own_numba_loop.png`` (position and friction force against time) and prints
the decay of the oscillation.
"""

import sys
from pathlib import Path

import numpy as np
from numba import njit

import polind


@njit(cache=True)
def free_oscillation(step, scalars, table, state, normal_load, mass, stiffness, x0, h, n,
                     out_x, out_force):
    """Your own integrator: symplectic Euler with the model's friction force."""
    x, v, friction = x0, 0.0, 0.0
    for k in range(n):
        v += h * (-stiffness * x - friction) / mass
        dx = h * v
        x += dx
        friction = step(scalars, table, state, h, dx, v, v, normal_load)
        out_x[k] = x
        out_force[k] = friction


def main(out_dir="."):
    model = polind.model_from_dict({"model": {
        "type": "lugre", "bristle_stiffness": 1e5, "bristle_damping": 316.2,
        "viscous_coefficient": 0.4, "coulomb_force": 1.0, "static_force": 1.5,
        "stribeck_velocity": 1e-3}})
    kernel = model.step_kernel()
    h, n = 1e-5, 300_000               # h resolves sigma0 / m = 1e5 s^-2 with margin
    x = np.empty(n)
    force = np.empty(n)
    free_oscillation(kernel.step, kernel.scalars, kernel.table, kernel.state,
                     kernel.normal_load, 1.0, 100.0, 0.05, h, n, x, force)
    t = h * np.arange(1, n + 1)
    print(f"x(0) = 0.05 m; |x| after 3 s = {abs(x[-1]):.4g} m (Coulomb decay stops it "
          f"once k |x| < Fs)")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
    top.plot(t, x * 1e3)
    top.set_ylabel("position [mm]")
    top.set_title("Spring-mass oscillator, LuGre friction, user's own numba loop")
    bottom.plot(t, force)
    bottom.set_ylabel("friction [N]")
    bottom.set_xlabel("time [s]")
    fig.tight_layout()
    path = Path(out_dir) / "own_numba_loop.png"
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main(*sys.argv[1:])
