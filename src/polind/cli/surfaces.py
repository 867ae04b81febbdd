"""Contact surfaces: ``polind surface`` (a model's) and ``polind topography`` (a measured map)."""

from __future__ import annotations

import os

import click

from polind.cli.common import (blame, cli, file_path, load_model, model_argument,
                               refuse_overwriting_inputs)
from polind.errors import InputError


@cli.command()
@model_argument
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object instead of the readable table.")
def surface(model_path, as_json):
    """The contact mechanics of a Pol-Ind model: separation, contacts, real area, elements.

    With --json: an object with keys separation, contacts, real_area,
    normal_load and elements (a list of {stiffness, breakaway_force,
    asperities, interference}).
    """
    import json

    model = load_model(model_path)
    with blame(model_path):
        contact = model.contact()
        summary = contact.summary()
    if as_json:
        click.echo(json.dumps(summary, allow_nan=False))
        return
    params = model.params
    surface = contact.surface
    # Sampled or measured summits: the standard deviation of their heights.
    sigma = surface.height_std if surface.kind == "statistical" else surface.height_statistics[1]
    kind = params["discretisation"]["summation"]
    lines = [
        f"Pol-Ind contact of {model_path} ({kind} summation, {len(summary['elements'])} elements)",
        f"  normal load    {summary['normal_load']:.6g} N",
        f"  separation     {summary['separation']:.6g} m   (d / sigma_a = "
        f"{summary['separation'] / sigma:.4f})",
        f"  contacts       {summary['contacts']:.6g} asperities",
        f"  real area      {summary['real_area']:.6g} m^2",
        f"  break-away     {sum(e['breakaway_force'] for e in summary['elements']):.6g} N "
        f"(mu_s N = {params['static_coefficient'] * summary['normal_load']:.6g} N)",
        "",
        f"  {'element':>7}  {'stiffness [N/m]':>16}  {'breakaway [N]':>14}  "
        f"{'asperities':>11}  {'interference [m]':>17}",
    ]
    for j, element in enumerate(summary["elements"]):
        lines.append(f"  {j:>7}  {element['stiffness']:>16.6g}  {element['breakaway_force']:>14.6g}"
                     f"  {element['asperities']:>11.6g}  {element['interference']:>17.6g}")
    click.echo("\n".join(lines))


@cli.command()
@click.argument("map_path", metavar="FILE", type=file_path())
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object instead of the readable summary.")
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="PNG",
              help="Also write a PNG: the levelled map and its summits, summit heights and "
                   "radii, N(d) beside the Greenwood-Williamson equivalent.")
@click.option("--pixel-size", "pixel_size", nargs=2, type=float, default=None,
              metavar="DX DY", help="Pixel size [m] of a .npy/.csv grid (heights in metres).")
@click.option("--short-cutoff", "short_cutoff", type=float, default=None, metavar="L",
              help="Gaussian low-pass (ISO 16610-61) cut-off wavelength [m] applied before "
                   "summit finding.")
def topography(map_path, as_json, plot_path, pixel_size, short_cutoff):
    """A measured height map: levelling, summits and their radii, the GW equivalent.

    FILE is any height map SurfaceTopography reads (x3p, sur, plu, opd, datx,
    di, ...; units from the file), or a .npy / .csv grid h[i, j] (i along x)
    in metres with --pixel-size.  With --json: an object with keys grid,
    pixel_size, valid_points, rms_height, summits, summit_density,
    summit_radius_mean, summit_radius_median, summit_height_std and
    greenwood_williamson ({asperity_density, asperity_radius, height_std}).
    """
    import json

    from polind import io
    from polind import topography as measured

    refuse_overwriting_inputs([map_path], {"--plot": plot_path})
    to_stdout = plot_path is not None and os.fspath(plot_path) == io.STDOUT
    if to_stdout and as_json:
        raise InputError("--plot -: the PNG and --json would both go to standard output; "
                         "expected a file name for --plot.")
    with blame(map_path):
        surface = measured.load_measured_surface(map_path, pixel_size=pixel_size,
                                                 short_cutoff=short_cutoff)
        summary = surface.summary()         # every number checked finite
    figure = None
    if plot_path is not None:
        from polind.topography_figure import figure_png

        figure = figure_png(surface)
    # What is printed goes first: a figure file appears only once it has (a file can be
    # left unwritten, a stream cannot take back what it took).
    if as_json:
        click.echo(json.dumps(summary, allow_nan=False))
    else:
        click.echo(_summary_text(map_path, summary), err=to_stdout)
    if figure is not None:
        io.atomic_write_bytes(plot_path, figure)
        if not (to_stdout or as_json):
            click.echo(f"\nwrote {plot_path}")


def _summary_text(map_path, summary) -> str:
    """The readable summary of ``polind topography``."""
    (nx, ny), (dx, dy) = summary["grid"], summary["pixel_size"]
    gw = summary["greenwood_williamson"]
    cutoff = summary["short_cutoff"]
    lines = [
        f"Height map {map_path}: {nx} x {ny} points, pixel {dx:.6g} x {dy:.6g} m",
        f"  valid points       {summary['valid_points']} of {nx * ny} "
        f"(nominal area {summary['nominal_area']:.6g} m^2)",
        f"  low-pass cut-off   {'none' if cutoff is None else f'{cutoff:.6g} m'}",
        f"  rms height         {summary['rms_height']:.6g} m (after levelling)",
        f"  summits            {summary['summits']} "
        f"(density {summary['summit_density']:.6g} 1/m^2)",
        f"  summit radius      {summary['summit_radius_mean']:.6g} m (1 / mean curvature), "
        f"median {summary['summit_radius_median']:.6g} m",
        f"  summit heights     mean {summary['summit_height_mean']:.6g} m, "
        f"std {summary['summit_height_std']:.6g} m (above the mean plane)",
        "",
        "The Greenwood-Williamson equivalent, as keys of [model.surface]:",
        f"  asperity_density = {gw['asperity_density']:.6g}",
        f"  asperity_radius = {gw['asperity_radius']:.6g}",
        f"  height_std = {gw['height_std']:.6g}",
    ]
    return "\n".join(lines)
