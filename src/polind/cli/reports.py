"""Reports: ``polind demo`` (the friction phenomena) and ``polind bench`` (the benchmark)."""

from __future__ import annotations

import os
from pathlib import Path

import click

from polind.cli.common import cli, file_path, load_model, progress
from polind.errors import InputError


@cli.command()
@click.option("--out", "out_dir", default="polind-report", show_default=True,
              type=click.Path(file_okay=False, path_type=Path),
              help="Directory for report.html, metrics.json and the PNGs.")
@click.option("--model", "model_path", default=None, type=file_path(), metavar="MODEL",
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


@cli.command()
@click.option("--model", "models", multiple=True, metavar="TYPE",
              help="Benchmark only this model type (repeatable). Default: every registered "
                   "model.")
@click.option("--big-files", "big_files", is_flag=True,
              help="Also time `polind simulate` along a 1e7-sample motion CSV (423 MB) end to "
                   "end: a minute or so, and 1.3 GB of temporary files.")
@click.option("--processes", "processes", is_flag=True,
              help="Also time whole `polind` processes (simulate of each model, with a "
                   "compliance, fit, demo) cold, with an empty numba cache, and warm: ten "
                   "minutes or more.")
def bench(models, big_files, processes):
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
    With --processes, last: whole `polind` processes, each first with an empty
    numba cache directory (NUMBA_CACHE_DIR; best of two, each with its own)
    and then with the cache it filled (best of two), and the ratios of those
    times against their targets.
    """
    from polind.bench import big_files as big, harness, processes as whole, ratios, surfaces
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
    if processes:
        click.echo("\n" + whole.format_processes([]))
        with progress(total=len(whole.case_names()), description="processes",
                      unit=" cases") as bar:
            def shown(row):
                bar.clear()
                click.echo(whole.format_processes([row]).splitlines()[-1])
                bar.update()

            rows = whole.run_processes(progress=shown)
        click.echo("\n" + whole.format_targets(whole.target_rows(rows)))
        note = whole.bytecode_note()
        if note:
            click.echo(note)
