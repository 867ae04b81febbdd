"""A Pol-Ind model from a measured surface
========================================

From an interferometer height map to a friction model, side by side with the
statistical model of the same surface::

    python examples/measured_surface.py [OUT_DIR] [--map FILE] [--load N]

1. ``polind.topography.load_measured_surface`` reads the map (by default
   ``x3p-2.x3p``, installed with polind: ``polind.datasets.height_map_path``;
   an ISO 25178-72 file that SurfaceTopography reads with its units), levels it and finds its summits
   and their radii (the user guide, "Measured surfaces").
2. A Pol-Ind model takes the map as its surface (``[model.surface]
   topography = "..."``): direct summation over the measured summits, each
   with its own height and radius, at ``N`` (default 1 N) with the default
   steel pair and friction parameters.  ``statistical_equivalent()`` gives
   the same model on the Greenwood–Williamson surface of the map (its
   summit density, ``R = 1 / mean(kappa)`` and summit-height standard
   deviation).
3. For both: the loaded contact (separation, summits in contact, real area),
   the steady Stribeck curve (``polind.phenomena.stribeck_effect``) and the
   presliding loops with nested reversals
   (``polind.phenomena.presliding_memory``, the same path for both).

Writes ``OUT_DIR/measured_surface.png`` (default the current directory), the
model file ``OUT_DIR/measured_pol_ind.toml`` (the map's path in it is
absolute, so the file can be moved) and prints the contact table.  The
steady sliding force is ``N s(v)`` for any surface (Amontons' law holds
element by element), so the two Stribeck curves coincide; the surfaces
differ in presliding, where the measured summits, whose higher members are
the sharper ones, reach gross sliding over a different displacement than
the one-radius Gaussian idealisation.
"""

from __future__ import annotations

import argparse
import os

import numpy as np

import polind
from polind import datasets, phenomena
from polind.models.pol_ind import default_table
from polind.topography import load_measured_surface

DEFAULT_MAP = datasets.height_map_path("x3p-2.x3p")


def map_model(path, normal_load) -> polind.FrictionModel:
    """The default Pol-Ind model with the map as its surface."""
    table = default_table()
    table["normal_load"] = float(normal_load)
    table["surface"] = {"topography": os.path.abspath(path)}
    table["discretisation"] = {}            # direct summation is implied by the map
    return polind.model_from_dict({"model": table})


def contact_row(label, model) -> dict:
    contact = model.contact()
    return {"model": label, "separation_nm": contact.separation * 1e9,
            "contacts": contact.contacts, "elements": len(contact.elements),
            "real_area_um2": contact.real_area * 1e12,
            "breakaway_N": float(contact.elements.breakaway_force.sum())}


def main(argv=None):
    paragraphs = (__doc__ or "").split("\n\n")      # sphinx-gallery empties __doc__
    parser = argparse.ArgumentParser(description=paragraphs[1] if len(paragraphs) > 1 else None)
    parser.add_argument("out", nargs="?", default=".", help="output directory")
    parser.add_argument("--map", default=str(DEFAULT_MAP), help="height map file")
    parser.add_argument("--load", type=float, default=1.0, help="normal load [N]")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)

    measured = load_measured_surface(args.map)
    summary = measured.summary()
    print(f"{os.path.basename(args.map)}: {summary['summits']} summits, density "
          f"{summary['summit_density']:.4g} 1/m^2, radius 1/mean(kappa) "
          f"{summary['summit_radius_mean'] * 1e6:.3g} µm (median "
          f"{summary['summit_radius_median'] * 1e6:.3g} µm), summit heights std "
          f"{summary['summit_height_std'] * 1e9:.3g} nm, nominal area "
          f"{summary['nominal_area'] * 1e6:.4g} mm^2")

    direct = map_model(args.map, args.load)
    statistical = direct.statistical_equivalent()
    rows = [contact_row("measured summits (direct)", direct),
            contact_row("Greenwood–Williamson equivalent", statistical)]
    print(f"\nat N = {args.load:g} N, steel on steel:")
    print(f"{'surface':<34}{'d [nm]':>9}{'contacts':>10}{'elements':>10}"
          f"{'real area [µm^2]':>18}{'sum W [N]':>11}")
    for row in rows:
        print(f"{row['model']:<34}{row['separation_nm']:>9.2f}{row['contacts']:>10.1f}"
              f"{row['elements']:>10}{row['real_area_um2']:>18.4g}{row['breakaway_N']:>11.4g}")

    stribeck = [phenomena.stribeck_effect(model, points=25) for model in (direct, statistical)]
    # One path for both: 0.8 of the larger of the two presliding ranges.
    ranges = [float(np.max(model.element_table().breakaway_force
                           / model.element_table().stiffness))
              for model in (direct, statistical)]
    amplitude = 0.8 * max(ranges)
    loops = [phenomena.presliding_memory(model, amplitude=amplitude)
             for model in (direct, statistical)]

    polind.save_model(direct, os.path.join(args.out, "measured_pol_ind.toml"))
    figure_path = os.path.join(args.out, "measured_surface.png")
    draw(figure_path, os.path.basename(args.map), args.load, stribeck, loops)
    print(f"\nwrote {figure_path} and {os.path.join(args.out, 'measured_pol_ind.toml')}")
    return rows


def draw(path, name, load, stribeck, loops):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(13, 5), layout="constrained")
    FigureCanvasAgg(figure)
    left, right = figure.subplots(1, 2)
    styles = [("#1f77b4", "-", 2.0, "measured summits, own radii (direct)"),
              ("#d62728", "--", 1.5, "Greenwood–Williamson equivalent")]
    for result, (color, dash, width, label) in zip(stribeck, styles):
        left.semilogx(result.data["velocity"], result.data["force"], color=color, ls=dash,
                      lw=width, marker="o" if dash == "-" else None, ms=3, label=label)
    left.set(xlabel="sliding velocity v [m/s]", ylabel="steady friction force F [N]",
             title=f"Stribeck curve at N = {load:g} N (identical: F = N s(v) for any surface)")
    left.legend(fontsize=8)
    left.grid(alpha=0.3, which="both")
    for result, (color, dash, width, label) in zip(loops, styles):
        right.plot(result.data["x"] * 1e9, result.data["force"], color=color, ls=dash, lw=width,
                   label=label)
    right.set(xlabel="displacement x [nm]", ylabel="friction force F [N]",
              title="Presliding hysteresis, nested reversals (same path)")
    right.legend(fontsize=8, loc="upper left")
    right.grid(alpha=0.3)
    figure.suptitle(f"Pol-Ind on {name} against its statistical equivalent")
    figure.savefig(path, dpi=110, metadata={"Software": None})


if __name__ == "__main__":
    main()
