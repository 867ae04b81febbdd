"""The ``polind`` command line (:ref:`cli`): parsing and printing only.

Each command is one small function registered on the :func:`cli` group; it
reads its files with :mod:`polind.io`, calls the library, and writes its
output with an atomic writer.  Commands never print errors or choose exit
statuses themselves: they raise, and :func:`main` turns what they raise into
the exit status of :ref:`cli-exit-status`:

- 0 success;
- 2 bad input (:class:`~polind.errors.InputError`, click usage errors), with
  exactly one line ``polind: error: <message>`` on standard error;
- 1 an internal error, one line ``polind: internal error: <type>: <message>``
  (and the traceback when the environment variable ``POLIND_DEBUG`` is set).

Adding a command (``demo``, ``dynamics``, ``fit``, ``surface``, ``bench``) is
one function: decorate it with ``@cli.command()``, take the model path with
``@model_argument`` and the output with ``@output_option``, load the model
with :func:`load_model`, call :func:`check_output_path` on the output before
any long computation, show progress with :func:`progress`, and import the
heavy modules (numpy, the models, matplotlib) inside the function so that
``polind --help`` stays fast.
"""

from __future__ import annotations

import contextlib
import os
import sys
import traceback
import warnings
from pathlib import Path

import click

from polind import __version__
from polind.errors import InputError

__all__ = ["cli", "main", "progress"]

_PROGRAM = "polind"


# --- pieces shared by the commands ---------------------------------------------------------

class _FilePath(click.Path):
    """``click.Path`` to a file that refuses a name ending in a separator.

    Such a name means a directory, but the ``pathlib.Path`` it becomes has
    lost the separator, so that the checks after it (existing directories,
    :func:`polind.io.check_output_path`) would take ``new/`` for a file ``new``.
    """

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value.endswith((os.sep, "/")):
            self.fail(f"{value}: names a directory; expected a file name", param, ctx)
        return super().convert(value, param, ctx)


def _file_path(**kwargs):
    """A path parameter; existence is checked by the reader, which names the file."""
    return _FilePath(dir_okay=False, path_type=Path, **kwargs)


def model_argument(command):
    """The ``MODEL`` argument: a model file (TOML, or JSON by extension)."""
    return click.argument("model_path", metavar="MODEL", type=_file_path())(command)


def output_option(command):
    """The required ``--output`` option: the file written on success only."""
    return click.option("--output", "-o", "output_path", required=True, type=_file_path(),
                        help="File to write; nothing is written unless the run succeeds.",
                        )(command)


@contextlib.contextmanager
def blame(path):
    """Prefix the file's path to an InputError raised inside, unless it already names it.

    The library's messages name a parameter or column; on the command line the
    user also needs to know which file it came from.
    """
    name = os.fspath(path)
    try:
        yield
    except InputError as exc:
        message = str(exc)
        if message.startswith(name):
            raise
        raise InputError(f"{name}: {message}") from exc


def load_model(path):
    """The model of a model file, errors prefixed with the file's path.

    What the model derives from its parameters (a Pol-Ind contact, kernel
    arrays) is built here too, so that a parameter that gives no valid model
    is blamed on the model file, not on a motion or data file read later.
    """
    import polind

    with blame(path):
        model = polind.load_model(path)
        model.step_kernel()
        return model


def check_output_path(path) -> None:
    """Fail before a long run if ``--output`` cannot be written."""
    from polind import io

    io.check_output_path(path)


def _stderr_is_terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # replaced or closed stream
        return False


def progress(total=None, description="", unit="step", unit_scale=False):
    """A progress bar on a terminal, nothing when standard error is piped.

    Returns a ``tqdm`` object (disabled when not on a terminal: its
    ``update`` and ``close`` then do nothing); use it as a context manager.

    Examples
    --------
    >>> with progress(total=3, description="phenomena") as bar:
    ...     for _ in range(3):
    ...         bar.update()
    """
    from tqdm import tqdm

    return tqdm(total=total, desc=description, unit=unit, unit_scale=unit_scale,
                file=sys.stderr, leave=False, dynamic_ncols=True,
                disable=not _stderr_is_terminal())


def advancing(bar):
    """A ``progress(done, total)`` callback that moves ``bar`` to ``done`` of ``total``."""
    def advance(done, total):
        bar.total = total
        bar.update(done - bar.n)
    return advance


def read_samples(path, **columns):
    """A motion or data file (CSV or Parquet), with a progress bar over its bytes."""
    from polind import io

    with progress(description="read", unit="B", unit_scale=True) as bar:
        return io.read_motion_csv(path, progress=advancing(bar), **columns)


def write_samples(path, columns):
    """A table of samples (CSV or Parquet by extension), with a progress bar over its rows."""
    from polind import io

    rows = len(next(iter(columns.values())))
    with progress(total=rows, description="write", unit=" rows") as bar:
        io.write_csv_atomic(path, columns, progress=advancing(bar))


# --- the commands ---------------------------------------------------------------------------

_SIZE_UNITS = {"": 1.0, "K": 1e3, "M": 1e6, "G": 1e9, "T": 1e12}


def _memory_size(text):
    """``--max-memory``: bytes, or a number with K, M, G or T (powers of 1000)."""
    value = str(text).strip().upper().removesuffix("B")
    unit = value[-1:] if value[-1:] in _SIZE_UNITS else ""
    try:
        number = float(value[:len(value) - len(unit)])
    except ValueError:
        number = float("nan")
    if not (number > 0.0 and number < float("inf")):
        raise InputError(f"The '--max-memory' option must be a positive size such as 4G or "
                         f"500M. Got {text!r} instead.")
    return number * _SIZE_UNITS[unit]


@click.group(name=_PROGRAM, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", prog_name=_PROGRAM,
                      message="%(prog)s %(version)s")
@click.option("--max-memory", metavar="SIZE", default=None,
              help="Refuse a run whose arrays would need more than SIZE (e.g. 4G, 500M); "
                   "default: half of the memory available.")
def cli(max_memory):
    """polind: dynamic friction modelling, the Pol-Ind model and its classical peers.

    Exit status: 0 success, 2 bad input (one line on standard error), 1 an
    internal error (set POLIND_DEBUG=1 for the traceback).
    """
    from polind.resources import set_memory_limit

    set_memory_limit(None if max_memory is None else _memory_size(max_memory))


@cli.command()
@model_argument
@click.option("--input", "-i", "motion_path", required=True, type=_file_path(),
              metavar="MOTION.csv",
              help="Prescribed motion: header with t and one of x [m], v [m/s]; "
                   "optionally normal_load [N] (pol-ind).")
@output_option
def simulate(model_path, motion_path, output_path):
    """Friction force along a prescribed motion.

    Writes OUT.csv with the header t,x,v,F (SI units, full float precision);
    MOTION and OUT may be Parquet files (.parquet), OUT may be - (stdout).
    """
    import polind
    from polind import io
    from polind.simulate import BYTES_PER_SAMPLE

    refuse_overwriting_inputs([model_path, motion_path], {"--output": output_path})
    check_output_path(output_path)
    model = load_model(model_path)
    io.check_table_memory(motion_path, BYTES_PER_SAMPLE, "simulating")
    motion = read_samples(motion_path)
    with blame(motion_path), progress(total=len(motion["t"]), description="simulate",
                                      unit=" samples") as bar:
        result = polind.simulate(model, motion["t"], x=motion.get("x"), v=motion.get("v"),
                                 normal_load=motion.get("normal_load"),
                                 progress=advancing(bar))
    del motion
    write_samples(output_path, {"t": result.t, "x": result.x, "v": result.v,
                                "F": result.force})
    click.echo(f"wrote {output_path}: {len(result.t)} samples", err=os.fspath(output_path) == "-")


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
@click.argument("map_path", metavar="FILE", type=_file_path())
@click.option("--json", "as_json", is_flag=True,
              help="Print one JSON object instead of the readable summary.")
@click.option("--plot", "plot_path", default=None, type=_file_path(), metavar="PNG",
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
    if plot_path is not None:
        from polind.topography_figure import figure_png

        io.atomic_write_bytes(plot_path, figure_png(surface))
    summary = surface.summary()
    if as_json:
        click.echo(json.dumps(summary, allow_nan=False))
        return
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
    if plot_path is not None and not to_stdout:
        lines += ["", f"wrote {plot_path}"]
    click.echo("\n".join(lines), err=to_stdout)


@cli.command()
@click.option("--model", "models", multiple=True, metavar="TYPE",
              help="Benchmark only this model type (repeatable). Default: every registered "
                   "model.")
@click.option("--big-files", "big_files", is_flag=True,
              help="Also time `polind simulate` along a 1e7-sample motion CSV (423 MB) end to "
                   "end: a minute or so, and 1.3 GB of temporary files.")
def bench(models, big_files):
    """The performance benchmark: element-steps per second, numba kernel vs plain NumPy.

    Each registered model runs at 1, 64 and 1024 elements (the single-state
    models at one); the same work done by a plain NumPy loop (step loop in
    Python, elements vectorised) is timed in the same run and the ratio
    printed ("—" for a model without one).  With a model of contact mechanics
    (Pol-Ind), its separation solve and a measured height map follow.
    Without --model, ratios taken in the same run follow: Stepper against a
    bare numba call, simulate against bare numba loops, Pol-Ind under a
    varying against a constant load.  With --big-files, last: the wall time
    and peak memory of a `polind simulate` process of a 4-element
    Maxwell-slip model along a 1e7-sample motion CSV (targets 8 s, 1 GB).
    """
    from polind.bench import big_files as big, harness, ratios, surfaces
    from polind.models.registry import model_class

    for model_type in models:       # any registered type (an installed plugin's too)
        model_class(model_type, "for option '--model'")
    chosen = harness.model_types(list(models) or None)
    cases = harness.cases(chosen)
    rows = []
    click.echo("polind bench: one thread, best of 3 timed runs after a warm-up")
    click.echo(harness.format_table([]))
    with progress(total=len(cases), description="bench", unit=" cases") as bar:
        for model_type, n in cases:
            rows.append(harness.run_case(model_type, n))
            bar.clear()
            click.echo(harness.format_table(rows[-1:]).splitlines()[-1])
            bar.update()
    if any(model_class(model_type).has_contact for model_type in chosen):
        separation = surfaces.run_separation()
        click.echo(f"\npol-ind separation solve, {separation.asperities:,} sampled asperities "
                   f"(direct summation): {separation.solve_seconds * 1e3:.2f} ms, "
                   f"{separation.evaluations} load evaluations, |N(d) - N|/N = "
                   f"{separation.relative_residual:.1e} (building the sorted surface: "
                   f"{separation.build_seconds * 1e3:.0f} ms, once per surface)")
        surface = surfaces.run_topography()
        click.echo(f"height map {surface.size} x {surface.size} (.npy) read, levelled and "
                   f"reduced to {surface.summits:,} summits: {surface.analyse_seconds:.2f} s "
                   f"(target 10 s); a pol-ind model on it at 1 N ({surface.elements} summits in "
                   f"contact): {surface.model_seconds:.2f} s")
    if not models:
        click.echo("\n" + ratios.format_ratios([]))
        ratios.run_ratios(progress=lambda row: click.echo(
            ratios.format_ratios([row]).splitlines()[-1]))
    if big_files:
        with progress(description="big files", unit="") as bar:
            row = big.run_big_files(progress=bar.set_description_str)
        click.echo("\n" + big.format_big_files(row))


@cli.command()
@model_argument
@click.option("--system", "-s", "system_path", required=True, type=_file_path(),
              metavar="SYSTEM.toml",
              help="The [system] file (the user guide, 'One-degree-of-freedom systems'): mass, "
                   "duration, time_step, spring_drive and/or force.")
@output_option
def dynamics(model_path, system_path, output_path):
    """A one-degree-of-freedom system: a mass driven by a spring and/or a force.

    Writes OUT.csv with the header t,x,v,F,F_applied (SI units); a .parquet
    OUT is written as Parquet, - to standard output.
    """
    import polind
    from polind import io

    refuse_overwriting_inputs([model_path, system_path], {"--output": output_path})
    check_output_path(output_path)
    model = load_model(model_path)
    with blame(system_path):
        system = polind.load_system(system_path)
    steps = len(system.times) - 1
    with progress(total=steps, description="dynamics", unit=" steps") as bar:
        def advance(done, total):
            bar.update(done - bar.n)

        result = polind.simulate_system(model, system, progress=advance)
    write_samples(output_path, {"t": result.t, "x": result.x, "v": result.v,
                                "F": result.force, "F_applied": result.applied})
    click.echo(f"wrote {output_path}: {len(result.t)} samples", err=os.fspath(output_path) == "-")


@cli.command()
@click.option("--out", "out_dir", default="polind-report", show_default=True,
              type=click.Path(file_okay=False, path_type=Path),
              help="Directory for report.html, metrics.json and the PNGs.")
@click.option("--model", "model_path", default=None, type=_file_path(), metavar="MODEL",
              help="A pol-ind model file to use instead of the default parameters.")
def demo(out_dir, model_path):
    """The friction phenomena on the default Pol-Ind model beside LuGre, GMS and Maxwell-slip.

    Runs the six experiments of the user guide's 'Friction phenomena'
    (Stribeck effect, presliding memory, frictional lag, non-drifting,
    stick-slip, break-away) and writes
    DIR/report.html (self-contained), one PNG per figure and DIR/metrics.json.
    """
    import time

    from polind.demo import run_demo

    model = None
    if model_path is not None:
        model = load_model(model_path)
    try:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(f"{out_dir}: cannot create the report directory "
                         f"({error.strerror or error}); expected a writable directory.") from None
    if not os.access(out_dir, os.W_OK):
        raise InputError(f"{out_dir}: the report directory is not writable; expected a "
                         f"writable directory.")
    started = time.perf_counter()
    with progress(description="demo", unit=" experiments") as bar:
        summary = run_demo(out_dir, progress=bar, model=model)
    click.echo(summary["table"])
    click.echo(f"\nwrote {Path(out_dir) / 'report.html'}, metrics.json and "
               f"{sum(1 for f in summary['files'] if str(f).endswith('.png'))} figures "
               f"in {time.perf_counter() - started:.1f} s")


def refuse_overwriting_inputs(inputs, outputs) -> None:
    """Check every output before a long run; refuse (exit 2) one that is an input.

    ``inputs`` are the paths the command reads; ``outputs`` maps an option
    name to a path or None (not given).  Each output must pass
    :func:`polind.io.check_output_path` with those inputs (an output never
    replaces an input, also through a link; ``-`` is standard output), and
    no two outputs may be one file.
    """
    from polind import io

    given = [(option, path) for option, path in outputs.items() if path is not None]
    for index, (option, path) in enumerate(given):
        io.check_output_path(path, inputs)
        for other_option, other in given[:index]:
            try:
                same = os.fspath(path) == os.fspath(other) == io.STDOUT
                io.check_output_path(path, [other])
            except InputError:
                same = True
            if same:
                raise InputError(f"{path}: given as both {other_option} and {option}; expected "
                                 "two different outputs.")


def _holdout_option(command):
    return click.option("--holdout", "holdout", default=None, metavar="F",
                        type=click.FloatRange(0.0, 1.0, min_open=True, max_open=True),
                        help="Fit the first 1-F of the samples (by time) and report the RMS "
                             "error on the rest.")(command)


@cli.command()
@model_argument
@click.option("--data", "-d", "data_path", required=True, type=_file_path(), metavar="DATA.csv",
              help="Measured t, one of x [m] / v [m/s], F [N], optionally normal_load [N].")
@output_option
@click.option("--plot", "plot_path", default=None, type=_file_path(), metavar="FILE",
              help="Also write a PNG of measured against fitted force.")
@_holdout_option
def fit(model_path, data_path, output_path, plot_path, holdout):
    """Identify the [fit] free parameters of MODEL from measured data.

    The model's values are the starting point; [fit] free names the keys to
    identify and [fit.bounds] bounds them (without bounds a key gets default
    bounds derived from the data).  Writes FITTED.toml: [model] with the
    identified values and [fit.result] (rms_error, holdout_rms_error with
    --holdout, iterations, warnings, value and standard error of every free
    key).  Each warning is also one line on standard error.
    """
    from polind import identification, io

    refuse_overwriting_inputs([model_path, data_path],
                              {"--output": output_path, "--plot": plot_path})
    with blame(model_path):
        document = io.read_model_file(model_path)
        model, free, bounds = identification.parse_fit(document)
    io.check_table_memory(data_path, identification.fit_bytes_per_sample(model, free),
                          f"fitting {len(free)} free key{'s' if len(free) != 1 else ''} to")
    data = read_samples(data_path, **io.MEASUREMENT_COLUMNS)
    with progress(description="fit", unit=" simulations") as bar:
        def advance(evaluations, rms):
            bar.set_postfix_str(f"rms {rms:.4g} N", refresh=False)
            bar.update()

        with blame(data_path):
            # The fit's warnings reach standard error as UserWarnings, one line each (main).
            result = identification.identify(model, data, free=free, bounds=bounds,
                                             holdout=holdout, callback=advance)
    if plot_path is not None:
        identification.plot_fit(data, result, plot_path)
    io.write_model_file(output_path, result.to_document())
    # With an output on standard output ('-'), the readable text goes to standard error.
    streamed = io.STDOUT in (os.fspath(output_path), os.fspath(plot_path or ""))
    click.echo(result.summary(), err=streamed)
    files = [os.fspath(path) for path in (output_path, plot_path)
             if path is not None and os.fspath(path) != io.STDOUT]
    if files:
        click.echo(f"wrote {' and '.join(files)}", err=streamed)


@cli.command()
@click.argument("model_paths", metavar="MODEL...", nargs=-1, required=True, type=_file_path())
@click.option("--data", "-d", "data_path", required=True, type=_file_path(), metavar="DATA.csv",
              help="Measured t, one of x [m] / v [m/s], F [N], optionally normal_load [N].")
@_holdout_option
@click.option("--output", "-o", "output_path", default=None, type=_file_path(),
              metavar="TABLE.csv", help="Also write the table as CSV ('-': standard output).")
@click.option("--plot", "plot_path", default=None, type=_file_path(), metavar="PNG",
              help="Also write a PNG of measured and predicted force of every model.")
def compare(model_paths, data_path, holdout, output_path, plot_path):
    """Fit each MODEL to the same data and compare them: one row per model.

    Each model file's values are its starting point and its [fit] table its
    free keys and bounds (default: the model's usual keys, bounds from the
    data).  The table: model (the file's name), free parameters (count),
    RMS error in sample and on the held-out part (--holdout F: the last F of
    the samples, predicted by continuing each fitted run), AIC and BIC of
    the fitted part (n ln(RSS/n) + 2k and + k ln n).  --plot draws measured
    and predicted force against time and position, the held-out part shaded.
    """
    from polind import comparison, identification, io

    refuse_overwriting_inputs([*model_paths, data_path],
                              {"--output": output_path, "--plot": plot_path})
    stems = [Path(path).stem for path in model_paths]
    documents = {}
    per_sample = 0.0              # the models are fitted one after another: the largest fit
    for path, stem in zip(model_paths, stems):
        label = stem if stems.count(stem) == 1 else os.fspath(path)
        if label in documents:
            raise InputError(f"{path}: the model file is given twice; expected each MODEL once.")
        with blame(path):
            documents[label] = io.read_model_file(path)
            model, free, _ = identification.parse_fit(documents[label])
        per_sample = max(per_sample, identification.fit_bytes_per_sample(model, free))
    io.check_table_memory(data_path, per_sample, "fitting the models to")
    data = read_samples(data_path, **io.MEASUREMENT_COLUMNS)
    with progress(total=len(documents), description="compare", unit=" models") as bar:
        def advance(done, total, label):
            bar.update(done - bar.n)

        with blame(data_path):
            table = comparison.compare(documents, data, holdout=holdout, progress=advance)
    # With an output on standard output ('-'), the readable text goes to standard error.
    written = [os.fspath(path) for path in (output_path, plot_path) if path is not None]
    streamed = io.STDOUT in written
    click.echo(table.table(), err=streamed)
    if output_path is not None:
        io.atomic_write_text(output_path, table.to_csv())
    if plot_path is not None:
        table.plot(plot_path, title=f"{data_path}: measured and predicted friction force")
    files = [path for path in written if path != io.STDOUT]
    if files:
        click.echo(f"wrote {' and '.join(files)}", err=streamed)


@cli.command()
@click.argument("sweep_path", metavar="SWEEP.toml", type=_file_path())
@click.option("--output", "-o", "output_path", required=True, type=_file_path(),
              metavar="RESULTS", help="The results table, .parquet or .csv. Rows are added as "
                                      "runs finish; the same command again computes only the "
                                      "runs that are missing.")
@click.option("--workers", "-w", default=None, type=click.IntRange(min=1), metavar="N",
              help="Local worker threads (default: the number of cores).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run on an existing Dask distributed cluster (tcp://HOST:PORT) instead of "
                   "local threads; its workers need polind installed.")
@click.option("--yes", "-y", is_flag=True,
              help="Run a sweep of more than 10,000 runs (refused without it).")
@click.option("--plot", "plot_path", default=None, type=_file_path(), metavar="PNG",
              help="Also draw each metric against the swept parameters: a line over one, a "
                   "map over the first two.")
def sweep(sweep_path, output_path, workers, scheduler, yes, plot_path):
    """Many runs of one model over a grid or a sample of its parameters.

    SWEEP.toml names the model file, a [system] file (or a motion file), the
    metrics, the design (grid, latin-hypercube or random) and
    [sweep.parameters]: dotted keys into [model] and [system], each with
    values or a range (README, "Sweeps").  RESULTS has one row per run: run,
    the parameter values, the metrics, status ("ok" or the run's error) and
    seconds.  A failed run is a row and the sweep goes on; Ctrl-C stops it
    with every finished row kept.
    """
    from polind.sweeps import MAX_RUNS, SweepInterrupted, load_sweep, plot_results
    from polind.sweeps import sweep as run_sweep

    if workers is not None and scheduler is not None:
        raise InputError("--workers and --scheduler: give one (local threads or a Dask "
                         "cluster), not both.")
    with blame(sweep_path):
        plan = load_sweep(sweep_path)
    refuse_overwriting_inputs(plan.inputs, {"--output": output_path, "--plot": plot_path})
    with progress(description="sweep", unit=" runs") as bar:
        def advance(done, total, failed):
            if bar.total != total:
                bar.reset(total=total)
            bar.set_postfix_str(f"{failed} failed", refresh=False)
            bar.update(done - bar.n)

        try:
            summary = run_sweep(plan, output_path, workers=workers, scheduler=scheduler,
                                max_runs=None if yes else MAX_RUNS, progress=advance)
        except SweepInterrupted as stopped:
            bar.close()
            click.echo(f"{output_path}: stopped with {stopped.done} of {stopped.runs} runs "
                       f"written; run the same command again to compute the rest", err=True)
            raise
    if plot_path is not None:
        plot_results(summary.table, plan, plot_path)
    lost = f", {summary.lost} lost by the cluster (run again)" if summary.lost else ""
    click.echo(f"{output_path}: {summary.runs} runs: {summary.computed} computed in "
               f"{summary.seconds:.1f} s ({summary.failed} failed){lost}, "
               f"{summary.existing} already there")
    if plot_path is not None:
        click.echo(f"wrote {plot_path}")


# --- the entry point ------------------------------------------------------------------------

def _one_line(text) -> str:
    return " ".join(str(text).split())


def _debugging() -> bool:
    return os.environ.get("POLIND_DEBUG", "") not in ("", "0")


def _report(kind: str, message: str) -> None:
    if _debugging():
        traceback.print_exc(file=sys.stderr)
    sys.stderr.write(f"{_PROGRAM}: {kind}: {_one_line(message)}\n")
    sys.stderr.flush()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    _report("warning", str(message))


def _run(argv) -> int:
    """Run the command line; return the exit status."""
    try:
        with warnings.catch_warnings():
            # A library warning (a load signal a model ignores, ...) is one line on stderr.
            warnings.simplefilter("default")
            warnings.showwarning = _show_warning
            status = cli.main(args=argv, prog_name=_PROGRAM, standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:
        # A bare `polind` asks what it can do: the help, and success.
        click.echo(exc.format_message())
        return 0
    except click.ClickException as exc:
        _report("error", exc.format_message())
        return 2
    except InputError as exc:
        _report("error", str(exc))
        return 2
    except click.Abort:
        _report("error", "interrupted")
        return 130
    except Exception as exc:  # noqa: BLE001 - the last resort: exit 1 with one line
        _report("internal error", f"{type(exc).__name__}: {exc}")
        return 1
    finally:
        from polind.resources import set_memory_limit

        set_memory_limit(None)      # a --max-memory ends with its command
    # standalone_mode=False returns the exit code of --help/--version, else
    # the command's return value (None): commands do not choose statuses.
    return status if isinstance(status, int) else 0


def main(argv=None) -> None:
    """The ``polind`` console script: run the command line and exit with its status."""
    status = _run(argv)
    # Every output is written and closed by now.  Without this, the interpreter's last
    # garbage collections walk every object numba and SciPy created (0.2 to 0.4 s after
    # a simulate); frozen objects are skipped, and atexit handlers still run.
    import gc

    gc.freeze()
    sys.exit(status)


if __name__ == "__main__":
    main()
