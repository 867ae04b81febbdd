"""Stick-slip maps
===============

Where a spring-driven body sticks and slips, over drive velocity and stiffness::

    python examples/stick_slip_map.py [OUT_DIR] [--count N] [--workers N | --scheduler ADDRESS]

Two sweeps of ``polind.sweep`` over the drive velocity v_d and the drive
spring's stiffness k_d of the spring-driven body (the user guide,
"One-degree-of-freedom systems": ``m a = k_d (v_d t - x) - F``, started from
rest), each an N x N logarithmic grid (default 15 x 15):

* the default Pol-Ind model (``polind.models.pol_ind.default_table()``: a
  steel pair under 100 N, mu_s = 0.15, mu_k = 0.10, vs = 1 mm/s, no viscous
  damping) with a 10 kg body (the mass whose weight is the 100 N load),
  v_d from 0.1 mm/s to 0.1 m/s, k_d from 1e3 to 1e6 N/m, 20 s at 0.1 ms;
* LuGre with the parameters of Canudas de Wit et al. (1995) and their 1 kg
  body, v_d from 3 mm/s to 1 m/s, k_d from 1 to 1000 N/m, 100 s at 2 ms.

Each run keeps ``stuck_fraction``, ``stick_slip_amplitude`` and
``stick_slip_period`` (the user guide, "Sweeps", defines them, over the
second half of the run).  The results go to ``OUT_DIR/stick_slip_pol_ind.parquet`` and
``OUT_DIR/stick_slip_lugre.parquet``; running the script again computes only
runs that are missing there.  The figure ``OUT_DIR/stick_slip_map.png`` has
one row per model and one map per metric; the white line is where the body
is stuck a fifth of the time (the threshold ``polind demo`` uses to call a
run stick-slip).  The script prints, per stiffness, the highest drive
velocity at which each model still sticks and slips.
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

import polind
from polind.dynamics import System
from polind.models import LuGre
from polind.models.pol_ind import default_table
from polind.sweeps import Sweep, read_results

METRICS = ["stuck_fraction", "stick_slip_amplitude", "stick_slip_period"]

#: Model, body and drive ranges of each map: (label, model table, mass, velocity range,
#: stiffness range, duration, time step).
MAPS = {
    "pol_ind": ("Pol-Ind (default, 10 kg)", default_table(), 10.0, (1e-4, 1e-1), (1e3, 1e6),
                20.0, 1e-4),
    # LuGre.example() is the parameter set of Canudas de Wit et al. (1995).
    "lugre": ("LuGre (1995, 1 kg)", LuGre.example().to_dict()["model"], 1.0, (3e-3, 1.0),
              (1.0, 1e3), 100.0, 2e-3),
}

#: A run sticks and slips when its body is stuck at least this fraction of the time.
STICKING = 0.2


def stick_slip_sweep(name, count) -> Sweep:
    """The sweep of one map: a count x count grid over v_d and k_d."""
    _, table, mass, velocities, stiffnesses, duration, time_step = MAPS[name]
    system = System(mass=mass, duration=duration, time_step=time_step,
                    spring_stiffness=stiffnesses[0], drive_velocity=velocities[0])
    return Sweep({"model": table}, system=system, metrics=METRICS, method="grid", name=name,
                 parameters={
                     "system.spring_drive.velocity": {"range": list(velocities), "scale": "log",
                                                      "count": count},
                     "system.spring_drive.stiffness": {"range": list(stiffnesses),
                                                       "scale": "log", "count": count}})


def grid_of(table, metric):
    """(velocities, stiffnesses, values[stiffness, velocity]) of a grid sweep's table."""
    velocity = np.asarray(table["system.spring_drive.velocity"])
    stiffness = np.asarray(table["system.spring_drive.stiffness"])
    v_axis, k_axis = np.unique(velocity), np.unique(stiffness)
    values = np.full((k_axis.size, v_axis.size), np.nan)
    values[np.searchsorted(k_axis, stiffness), np.searchsorted(v_axis, velocity)] = \
        np.asarray(table[metric], dtype=float)
    return v_axis, k_axis, values


def edges(centres):
    """Cell edges of log-spaced centres."""
    logs = np.log(centres)
    middle = 0.5 * (logs[1:] + logs[:-1])
    return np.exp(np.concatenate(([2 * logs[0] - middle[0]], middle,
                                  [2 * logs[-1] - middle[-1]])))


def critical_velocities(table):
    """Per stiffness, the highest drive velocity at which the body still sticks and slips."""
    v_axis, k_axis, stuck = grid_of(table, "stuck_fraction")
    rows = []
    for k, fractions in zip(k_axis, stuck):
        sticking = v_axis[fractions >= STICKING]
        rows.append((float(k), float(sticking.max()) if sticking.size else math.nan))
    return rows


def plot(tables, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, Normalize

    titles = {"stuck_fraction": "stuck fraction",
              "stick_slip_amplitude": "stick-slip amplitude [N]",
              "stick_slip_period": "stick-slip period [s]"}
    figure, panels = plt.subplots(len(tables), len(METRICS), figsize=(13.5, 4.0 * len(tables)),
                                  layout="constrained", squeeze=False)
    colours = plt.get_cmap("viridis").with_extremes(bad="0.85")
    for row, (name, table) in enumerate(tables.items()):
        v_axis, k_axis, stuck = grid_of(table, "stuck_fraction")
        for panel, metric in zip(panels[row], METRICS):
            _, _, values = grid_of(table, metric)
            norm = Normalize(0.0, 1.0) if metric == "stuck_fraction" else LogNorm()
            image = panel.pcolormesh(edges(v_axis), edges(k_axis), np.ma.masked_invalid(values),
                                     cmap=colours, norm=norm, shading="flat")
            panel.contour(v_axis, k_axis, stuck, levels=[STICKING], colors="white",
                          linewidths=1.5)
            panel.set_xscale("log")
            panel.set_yscale("log")
            panel.set_xlabel("drive velocity v_d [m/s]")
            panel.set_ylabel("drive stiffness k_d [N/m]")
            panel.set_title(f"{MAPS[name][0]}: {titles[metric]}", fontsize=10)
            figure.colorbar(image, ax=panel)
    figure.suptitle("Spring-driven body from rest: stick-slip left of the white line (stuck "
                    f"{STICKING:.0%} of the time or more); grey: fewer than two slips in the "
                    "second half, or never stuck", fontsize=11)
    figure.savefig(path, dpi=80)
    plt.close(figure)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out_dir", nargs="?", default=".", help="where the tables and the "
                                                                 "figure go (default: here)")
    parser.add_argument("--count", type=int, default=15, help="grid points per axis (15)")
    engine = parser.add_mutually_exclusive_group()
    engine.add_argument("--workers", type=int, default=None, help="local threads (all cores)")
    engine.add_argument("--scheduler", default=None, help="a Dask scheduler, tcp://HOST:PORT")
    args = parser.parse_args(argv)
    os.makedirs(args.out_dir, exist_ok=True)
    tables = {}
    for name in MAPS:
        plan = stick_slip_sweep(name, args.count)
        out = os.path.join(args.out_dir, f"stick_slip_{name}.parquet")
        started = time.perf_counter()
        summary = polind.sweep(plan, out, workers=args.workers, scheduler=args.scheduler)
        print(f"{MAPS[name][0]}: {summary.runs} runs, {summary.computed} computed in "
              f"{time.perf_counter() - started:.1f} s, {summary.failed} failed -> {out}")
        tables[name] = read_results(out)
    path = os.path.join(args.out_dir, "stick_slip_map.png")
    plot(tables, path)
    print(f"wrote {path}\n")
    print("highest drive velocity with stick-slip [m/s], per drive stiffness [N/m]:")
    for name, table in tables.items():
        cells = ", ".join(f"{k:.3g}: {v:.2g}" for k, v in critical_velocities(table))
        print(f"  {MAPS[name][0]}: {cells}")


if __name__ == "__main__":
    main()
