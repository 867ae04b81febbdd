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
    normal_load, elements (a list of {stiffness, breakaway_force,
    asperities, interference}) and validity ({plasticity_index,
    plastic_contact_share, plastic_load_share, mean_real_pressure,
    peak_asperity_pressure, unmatched_load}); with tangential = "mindlin"
    also tangential, microslip_elements and each element's
    slip_displacement u*.  An elastic (Hertzian) contact with a peak
    asperity pressure above 10 GPa warns.
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
    # Summits all at one height (one sphere, or a flat-topped sample) have no spread.
    spread = (f"(d / sigma_a = {summary['separation'] / sigma:.4f})" if sigma > 0.0
              else "(every summit at one height: sigma_a = 0)")
    microslip = summary.get("microslip_elements")
    lines = [
        f"Pol-Ind contact of {model_path} ({kind} summation, {len(summary['elements'])} elements)",
        f"  normal load    {summary['normal_load']:.6g} N",
        f"  separation     {summary['separation']:.6g} m   {spread}",
        f"  contacts       {summary['contacts']:.6g} asperities",
        f"  real area      {summary['real_area']:.6g} m^2",
        f"  break-away     {sum(e['breakaway_force'] for e in summary['elements']):.6g} N "
        f"(mu_s N = {params['static_coefficient'] * summary['normal_load']:.6g} N)",
        *([] if microslip is None else [
            f"  tangential     mindlin: {microslip} microslip sub-elements per element "
            f"({microslip * len(summary['elements'])} in all); u* = 3 mu_s P / (16 G* a) "
            f"per element below"]),
        "",
        *_validity_lines(summary["validity"], surface.plasticity),
        "",
        f"  {'element':>7}  {'stiffness [N/m]':>16}  {'breakaway [N]':>14}  "
        f"{'asperities':>11}  {'interference [m]':>17}" + ("" if microslip is None else
                                                           f"  {'u* [m]':>12}"),
    ]
    for j, element in enumerate(summary["elements"]):
        lines.append(f"  {j:>7}  {element['stiffness']:>16.6g}  {element['breakaway_force']:>14.6g}"
                     f"  {element['asperities']:>11.6g}  {element['interference']:>17.6g}"
                     + ("" if microslip is None else f"  {element['slip_displacement']:>12.6g}"))
    click.echo("\n".join(lines))


def _validity_lines(figures: dict, plasticity) -> list[str]:
    """The validity figures of ``polind surface`` as lines of its table."""
    if plasticity is None:
        index = "none (no hardness: Hertzian asperities)"
    else:
        index = (f"{figures['plasticity_index']:.4g} (H = {plasticity.hardness:.4g} Pa; "
                 f"below 0.6 mostly elastic, above 1 mostly plastic)")
    return [
        "Validity of the asperity law:",
        f"  plasticity index        {index}",
        f"  beyond yield            {100 * figures['plastic_contact_share']:.4g} % of the contacts, "
        f"{100 * figures['plastic_load_share']:.4g} % of the load",
        f"  mean real pressure      {figures['mean_real_pressure']:.6g} Pa",
        f"  peak asperity pressure  {figures['peak_asperity_pressure']:.6g} Pa",
        f"  unmatched load          {figures['unmatched_load']:.6g} N",
    ]


@cli.command()
@click.argument("map_path", metavar="FILE", type=file_path())
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object instead of the readable summary.")
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="PNG",
              help="Also write a PNG: the levelled map and its summits, summit heights and "
                   "radii, N(d) beside the Greenwood-Williamson equivalent, the presliding "
                   "virgin curve, the power spectral density and the cut-off study.")
@click.option("--pixel-size", "pixel_size", nargs=2, type=float, default=None,
              metavar="DX DY", help="Pixel size [m] of a .npy/.csv grid (heights in metres).")
@click.option("--short-cutoff", "short_cutoff", type=float, default=None, metavar="L",
              help="Gaussian low-pass (ISO 16610-61) cut-off wavelength [m] applied before "
                   "summit finding; at least twice the smaller pixel spacing.")
@click.option("--remove-outliers", "remove_outliers", is_flag=True,
              help="Mark the outliers (points more than 8 robust standard deviations from the "
                   "median height) missing; without it they are only counted.")
@click.option("--channel", "channel", default=None, metavar="NAME",
              help="The channel of a file with several (an AFM's Height, Amplitude, ...); "
                   "default: the file's default height channel.")
@click.option("--levelling", "levelling", type=click.Choice(["plane", "lines"]),
              default="plane", show_default=True,
              help="'lines': level each scan line (along x) on its own, for scanning-probe "
                   "(AFM, STM) maps; 'plane': the least-squares plane.")
@click.option("--hardness", "hardness", type=float, default=None, metavar="H",
              help="Hardness [Pa] of the softer body: with --effective-modulus, adds the "
                   "plasticity index of the map's Greenwood-Williamson equivalent.")
@click.option("--effective-modulus", "effective_modulus", type=float, default=None,
              metavar="E", help="Effective modulus E* [Pa] of the pair, for the plasticity "
                                "index and the figure (default there: steel on steel).")
def topography(map_path, as_json, plot_path, pixel_size, short_cutoff, remove_outliers, channel,
               levelling, hardness, effective_modulus):
    """A measured height map: conditioning, standard roughness, summits and their radii.

    FILE is any height map SurfaceTopography reads (x3p, sur, plu, opd, datx,
    di, ...; units from the file), or a .npy / .csv grid h[i, j] (i along x)
    in metres with --pixel-size.  Outliers (spikes) are counted, and marked
    missing with --remove-outliers.  With --json: an object with keys grid,
    pixel_size, valid_points, rms_height, summits, summit_density,
    summit_radius_mean, summit_radius_median, summit_height_std,
    greenwood_williamson ({asperity_density, asperity_radius, height_std}),
    roughness ({Sa, Sq, Ssk, Sku, Sdq, rms_curvature}), channel, outliers and
    cutoff_study (a list of {short_cutoff, summits, summit_radius_mean});
    with --hardness and --effective-modulus also plasticity_index.
    """
    import json
    import warnings

    from polind import io
    from polind import topography as measured

    refuse_overwriting_inputs([map_path], {"--plot": plot_path})
    to_stdout = plot_path is not None and os.fspath(plot_path) == io.STDOUT
    if to_stdout and as_json:
        raise InputError("--plot -: the PNG and --json would both go to standard output; "
                         "expected a file name for --plot.")
    with blame(map_path):
        _check_topography_options(hardness, effective_modulus, pixel_size, short_cutoff)
        surface = measured.load_measured_surface(
            map_path, pixel_size=pixel_size, short_cutoff=short_cutoff,
            remove_outliers=remove_outliers, levelling=levelling, channel=channel)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")        # the map's warnings were issued above
            summary = surface.summary(effective_modulus=effective_modulus if hardness else None,
                                      hardness=hardness)     # every number checked finite
    figure = None
    if plot_path is not None:
        from polind.topography_figure import figure_png

        figure = figure_png(surface, effective_modulus)
    # What is printed goes first: a figure file appears only once it has (a file can be
    # left unwritten, a stream cannot take back what it took).
    if as_json:
        click.echo(json.dumps(summary, allow_nan=False))
    else:
        click.echo("\n".join(_topography_text(map_path, summary, None, to_stdout)),
                   err=to_stdout)
    if figure is not None:
        io.atomic_write_bytes(plot_path, figure)
        if not (to_stdout or as_json):
            click.echo(f"\nwrote {plot_path}")


def _check_topography_options(hardness, effective_modulus, pixel_size, short_cutoff) -> None:
    """Every option of ``polind topography`` checked before the map is read or analysed.

    The map's own checks (its pixel size against ``--short-cutoff`` for a
    file that gives its own) need the file; everything the options alone
    decide is refused here, so that a mistyped number costs no analysis.
    """
    from polind.topography.analysis import check_cutoff
    from polind.topography.heightmap import check_pixel_size
    from polind.validation import check_number

    if hardness is not None and effective_modulus is None:
        raise InputError("--hardness: the plasticity index needs the pair's effective modulus "
                         "too; expected --effective-modulus E* [Pa] with it.")
    if hardness is not None:
        check_number("topography", "hardness", hardness, "positive")
    if effective_modulus is not None:
        check_number("topography", "effective_modulus", effective_modulus, "positive")
    if pixel_size is not None:
        pixel_size = check_pixel_size(pixel_size)
    if short_cutoff is not None:
        check_number("topography", "short_cutoff", short_cutoff, "positive")
        if pixel_size is not None:
            check_cutoff(short_cutoff, pixel_size, "--short-cutoff")


def _topography_text(map_path, summary, plot_path, to_stdout) -> list:
    """The readable summary of ``polind topography``, line by line."""
    (nx, ny), (dx, dy) = summary["grid"], summary["pixel_size"]
    gw = summary["greenwood_williamson"]
    cutoff = summary["short_cutoff"]
    rough = summary["roughness"]
    removed = ("" if not summary["outliers"] else
               " (marked missing)" if summary["outliers_removed"] else " (left in)")
    lines = [
        f"Height map {map_path}: {nx} x {ny} points, pixel {dx:.6g} x {dy:.6g} m",
        f"  channel            {summary['channel'] or '(a grid: the heights)'}",
        f"  valid points       {summary['valid_points']} of {nx * ny} "
        f"(nominal area {summary['nominal_area']:.6g} m^2)",
        f"  outliers           {summary['outliers']}{removed}",
        f"  levelling          {summary['levelling']}",
        f"  low-pass cut-off   {'none' if cutoff is None else f'{cutoff:.6g} m'}",
        f"  rms height         {summary['rms_height']:.6g} m (after levelling)",
        "",
        "Standard roughness (ISO 25178-2; Sq, Sdq and the curvature by SurfaceTopography):",
        f"  Sa {rough['Sa']:.6g} m   Sq {rough['Sq']:.6g} m   Ssk {rough['Ssk']:.4g}   "
        f"Sku {rough['Sku']:.4g}",
        f"  Sdq (rms slope) {rough['Sdq']:.6g}   rms curvature {rough['rms_curvature']:.6g} 1/m",
        "",
        f"  summits            {summary['summits']} "
        f"(density {summary['summit_density']:.6g} 1/m^2)",
        f"  summit radius      {summary['summit_radius_mean']:.6g} m (1 / mean curvature), "
        f"median {summary['summit_radius_median']:.6g} m",
        f"  summit heights     mean {summary['summit_height_mean']:.6g} m, "
        f"std {summary['summit_height_std']:.6g} m (above the mean plane)",
    ]
    if "plasticity_index" in summary:
        lines.append(f"  plasticity index   {summary['plasticity_index']:.4g} "
                     f"(below 0.6 mostly elastic, above 1 mostly plastic)")
    lines += ["", "Cut-off study (the low-pass cut-off against summits and 1 / mean curvature):",
              f"  {'short_cutoff [m]':>16}  {'summits':>8}  {'radius [m]':>12}"]
    for row in summary["cutoff_study"]:
        shown = "none" if row["short_cutoff"] is None else f"{row['short_cutoff']:.4g}"
        radius = "-" if row["summit_radius_mean"] is None else f"{row['summit_radius_mean']:.4g}"
        lines.append(f"  {shown:>16}  {row['summits']:>8}  {radius:>12}")
    lines += [
        "",
        "The Greenwood-Williamson equivalent, as keys of [model.surface]:",
        f"  asperity_density = {gw['asperity_density']:.6g}",
        f"  asperity_radius = {gw['asperity_radius']:.6g}",
        f"  height_std = {gw['height_std']:.6g}",
    ]
    if plot_path is not None and not to_stdout:
        lines += ["", f"wrote {plot_path}"]
    return lines
