"""Identify LuGre, GMS and Pol-Ind on a measured reciprocating-tribometer record.

Run::

    python examples/tribometer_fit.py [--out DIR] [--step N] [--data FILE]
                                      [--models lugre,gms,pol-ind]

The record (``/work/shared/data/tribometer_reciprocating.tsv``, see its
README) is a ball-on-flat reciprocating test: strokes of about 0.24 mm at
about 0.25 mm/s with a dwell of about 1 s at each end, under a normal load
of about 5 N.  What this script does with it:

1. **Units and sign.**  Normal load and friction are in µN, position in mm:
   converted to N and m.  The instrument's friction sign is flipped
   (``F = -Friction``) so that friction resists positive motion
   (MODELS.md 0), and the first position is subtracted.
2. **Unloaded samples dropped.**  The contact is loaded a few seconds after
   the record starts (the load ramps up from ~0 to 5 N between about 5.4 and
   7.7 s) and unloaded before it ends (after about 210.8 s).  Only the
   loaded part is kept: from the first to the last sample whose normal load
   is at least 90 % of the record's median load.  The load is positive
   there, as Pol-Ind's ``normal_load=`` array requires, and the contact is
   at rest at its start, as every model's initial state assumes.
3. **Decimated.**  Every ``N``-th sample is kept (default 4: 20 ms instead
   of 5 ms, about 10,000 samples).  The shortest feature, the presliding
   rise after a reversal, lasts about 0.4 s, so it keeps about 20 samples:
   the models fitted on the decimated record have RMS errors on the full
   record within 3 % of those on the decimated one.  (``--step 1`` fits the
   full record in about the same time on two cores; it may land in another
   of the nearby local minima, e.g. Pol-Ind at 0.21 N instead of 0.19 N.)
4. **Fits.**  A Maxwell-slip element set by NNLS (the structure fit,
   :func:`polind.identification.identify_maxwell_slip`) gives the starting
   stiffnesses of GMS and of LuGre's bristle; LuGre, GMS and Pol-Ind are
   then fitted by bounded nonlinear least squares
   (:func:`polind.identify`).  Pol-Ind is given the measured normal
   load sample by sample.  Bounds keep the Stribeck parameters physical: a
   record at one sliding speed says little about the Stribeck curve, and
   without bounds the fit trades ``static_force`` against
   ``stribeck_velocity`` towards absurd values.
5. **Output.**  Each model's RMS error and identified values on the
   terminal; ``DIR/tribometer_fit.png`` (measured against fitted force over
   time, in a window of a few strokes, and against position) and one fitted
   model file per model, ``DIR/<model>.toml``, in the format ``polind fit``
   writes.

It runs in under a minute on two cores: 14-18 s measured on an idle machine,
45 s while other jobs ran; most of it is Pol-Ind (the time is printed).

RMS errors found: Maxwell-slip by NNLS 0.106 N, LuGre 0.24 N, GMS 0.103 N,
Pol-Ind 0.19 N, against a force amplitude of about 2.4 N.  LuGre's single
exponential presliding curve and Pol-Ind's Greenwood-Williamson element
distribution cannot follow the nearly linear presliding rise of this rig as
closely as the free element set of GMS; the Pol-Ind fit puts the rig's
compliance into the surface (``height_std`` near 0.45 mm).  Without the
Stribeck bounds LuGre reaches 0.10 N, with ``static_force`` near 1e8 N and
``stribeck_velocity`` near 6e-5 m/s: a curve bent to the two speeds of a
stroke, meaningless anywhere else.
"""

from __future__ import annotations

import argparse
import importlib
import time
from pathlib import Path

import numpy as np

import polind
from polind import io
from polind.identification import identify, identify_gms, identify_maxwell_slip, plot_fit

DATA = Path("/work/shared/data/tribometer_reciprocating.tsv")
COLUMNS = ("Time [s]", "Normal [uN]", "Position [mm]", "Friction [uN]")
LOADED_FRACTION = 0.9       # keep samples loaded to at least this share of the median load


def read_record(path: Path, step: int) -> dict:
    """The loaded, decimated record in SI units: ``t``, ``x``, ``F``, ``normal_load``."""
    with open(path, encoding="utf-8") as stream:
        header = [name.strip() for name in stream.readline().split("\t")]
    if tuple(header) != COLUMNS:
        raise SystemExit(f"{path}: expected the columns {COLUMNS}, got {tuple(header)}")
    time_s, normal_un, position_mm, friction_un = np.loadtxt(path, delimiter="\t",
                                                             skiprows=1, unpack=True)
    normal = normal_un * 1e-6                       # uN -> N
    force = -friction_un * 1e-6                     # uN -> N, resisting positive motion
    position = (position_mm - position_mm[0]) * 1e-3   # mm -> m, from the first sample
    loaded = np.flatnonzero(normal >= LOADED_FRACTION * np.median(normal))
    first, last = loaded[0], loaded[-1]
    keep = slice(first, last + 1, step)
    print(f"record: {time_s.size} samples over {time_s[-1] - time_s[0]:.1f} s; loaded from "
          f"{time_s[first]:.3f} s to {time_s[last]:.3f} s (normal load >= "
          f"{LOADED_FRACTION:.0%} of the median {np.median(normal):.3f} N); keeping 1 sample "
          f"in {step}: {time_s[keep].size} samples")
    return {"t": time_s[keep], "x": position[keep], "F": force[keep],
            "normal_load": normal[keep]}


def pol_ind_start(data: dict, sliding_force: float):
    """A Pol-Ind starting point: the default surface, steel, the measured mean load."""
    module = importlib.import_module("polind.models.pol_ind")   # registers pol-ind if unwired
    table = module.default_table()
    load = float(np.mean(data["normal_load"]))
    mu = sliding_force / load
    table.update(normal_load=load, static_coefficient=1.05 * mu, kinetic_coefficient=mu,
                 stribeck_velocity=1e-4, attraction=10.0)
    table["discretisation"]["elements"] = 16
    return polind.model_from_dict({"model": table})


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("tribometer-fit"),
                        help="output directory (default: tribometer-fit)")
    parser.add_argument("--step", type=int, default=4, help="keep every N-th sample (default 4)")
    parser.add_argument("--data", type=Path, default=DATA, help="the tribometer TSV file")
    parser.add_argument("--models", default="lugre,gms,pol-ind",
                        help="comma-separated models to fit (default: lugre,gms,pol-ind)")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()

    record = read_record(args.data, args.step)
    motion = {key: record[key] for key in ("t", "x", "F")}      # the classical models
    speed = np.abs(np.diff(record["x"]) / np.diff(record["t"]))
    sliding = speed > 0.5 * speed.max()
    # The force level of sliding: the upper tail of |F| (the strokes' plateaus).
    sliding_force = float(np.percentile(np.abs(record["F"]), 90))
    typical_speed = float(np.median(speed[sliding]))
    stribeck_bounds = {"static_force": [0.5 * sliding_force, 2.0 * sliding_force],
                       "stribeck_velocity": [1e-2 * typical_speed, 10.0 * typical_speed]}

    chosen = set(args.models.split(","))
    results, timings = {}, {}

    clock = time.perf_counter()
    slip = identify_maxwell_slip(motion, n=24)
    timings["maxwell-slip (NNLS)"] = time.perf_counter() - clock
    results["maxwell-slip (NNLS)"] = slip
    initial_stiffness = float(np.sum(slip.params["stiffness"]))

    if "lugre" in chosen:
        clock = time.perf_counter()
        lugre = polind.model_from_dict({"model": {
            "type": "lugre", "bristle_stiffness": initial_stiffness, "bristle_damping": 0.0,
            "coulomb_force": sliding_force, "static_force": 1.2 * sliding_force,
            "stribeck_velocity": 0.5 * typical_speed}})
        results["lugre"] = identify(lugre, motion, bounds=stribeck_bounds,
                                    free=["bristle_stiffness", "coulomb_force", "static_force",
                                          "stribeck_velocity"])
        timings["lugre"] = time.perf_counter() - clock

    if "gms" in chosen:
        clock = time.perf_counter()
        gms = identify_gms(motion, n=24)
        results["gms"] = identify(gms, motion, bounds=stribeck_bounds,
                                  free=["stiffness", "attraction", "coulomb_force",
                                        "static_force", "stribeck_velocity"])
        timings["gms"] = time.perf_counter() - clock

    if "pol-ind" in chosen:
        start = pol_ind_start(record, sliding_force)
        clock = time.perf_counter()
        results["pol-ind"] = identify(
            start, record,
            free=["static_coefficient", "kinetic_coefficient", "stribeck_velocity",
                  "attraction", "surface.height_std"],
            bounds={"stribeck_velocity": stribeck_bounds["stribeck_velocity"],
                    "surface.height_std": [1e-8, 1e-3]})
        timings["pol-ind"] = time.perf_counter() - clock

    print(f"\n{'model':<22}{'RMS error [N]':>14}{'iterations':>12}{'time [s]':>10}")
    for name, result in results.items():
        if isinstance(result, polind.FrictionModel):
            force = polind.simulate(result, record["t"], x=record["x"]).force
            rms, iterations = float(np.sqrt(np.mean((force - record["F"]) ** 2))), 0
        else:
            rms, iterations = result.rms_error, result.iterations
            io.write_model_file(args.out / f"{name}.toml", result.to_document())
        print(f"{name:<22}{rms:>14.4f}{iterations:>12d}{timings[name]:>10.1f}")
    for name, result in results.items():
        if not isinstance(result, polind.FrictionModel):
            print("\n" + result.summary())

    figure = args.out / "tribometer_fit.png"
    shown = {name: result for name, result in results.items() if name != "maxwell-slip (NNLS)"}
    plot_fit(record, shown, figure, window=(60.0, 70.0),
             title="Reciprocating tribometer: measured and fitted friction force")
    print(f"\nwrote {figure} and the fitted model files in {args.out}/")
    print(f"total time {time.perf_counter() - started:.1f} s")


if __name__ == "__main__":
    main()
