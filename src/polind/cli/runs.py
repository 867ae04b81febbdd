"""Runs: ``polind simulate``, ``polind dynamics``, ``polind structure`` and ``polind sweep``."""

from __future__ import annotations

import os

import click

from polind.cli.common import (advancing, blame, check_output_path, cli, file_path,
                               load_model, model_argument, model_inputs, output_option,
                               progress, read_samples, refuse_overwriting_inputs,
                               write_samples)
from polind.errors import InputError


@cli.command()
@model_argument
@click.option("--input", "-i", "motion_path", required=True, type=file_path(),
              metavar="MOTION.csv",
              help="Prescribed motion: header with t and one of x [m], v [m/s]; "
                   "optionally normal_load [N] (pol-ind); or a data description (.toml) of "
                   "an instrument's file.")
@output_option
def simulate(model_path, motion_path, output_path):
    """Friction force along a prescribed motion.

    Writes OUT.csv with the header t,x,v,F (SI units, full float precision);
    MOTION and OUT may be Parquet files (.parquet), OUT may be - (stdout).
    MOTION may be a data description (.toml): an instrument's file, its
    columns, units, sign and window.
    """
    import polind
    from polind import io
    from polind.simulation import BYTES_PER_SAMPLE

    motion_files = io.record_files(motion_path)  # a data description names its file
    refuse_overwriting_inputs([*model_inputs(model_path), *motion_files],
                              {"--output": output_path})
    check_output_path(output_path)
    model = load_model(model_path)
    io.check_table_memory(motion_files[-1], BYTES_PER_SAMPLE, "simulating")
    motion = read_samples(motion_path, **io.MOTION_COLUMNS)
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
@click.option("--system", "-s", "system_path", required=True, type=file_path(),
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

    refuse_overwriting_inputs([*model_inputs(model_path), system_path],
                              {"--output": output_path})
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
@click.argument("structure_path", metavar="STRUCTURE.toml", type=file_path())
@output_option
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="PNG",
              help="Also write a PNG: for a time run, the coordinates against time and each "
                   "contact's hysteresis loop; for a frequency_response, each coordinate's "
                   "amplitude against the frequency (turning points marked); for a backbone, "
                   "the frequency and the damping ratio against the modal amplitude.")
def structure(structure_path, output_path, plot_path):
    """A structure: n coordinates (mass, stiffness, damping) with friction contacts.

    STRUCTURE.toml has [structure] (mass, stiffness, damping matrices),
    [[structure.contacts]] (model: a model file or an inline [model] table;
    dofs: [i] or [i, j]) and [structure.run], whose kind says what to run,
    as the user guide's "Structures" describes:

    \b
    kind = "time" (the default): duration, time_step, initial_position,
      initial_velocity, method, [structure.run.force]. OUT.csv has
      t,q_0..q_{n-1},dq_0..dq_{n-1},F_0..F_{m-1} (F_c: contact c's friction
      force, -F_c on its first coordinate).
    kind = "frequency_response" (harmonic balance and continuation):
      omega_range [rad/s], force (each coordinate's cosine amplitude [N]),
      harmonics, samples, max_points. OUT.csv has one row per point of the
      curve: omega, amplitude_q_i (the largest abs(q_i - Q_0) over the period),
      every coordinate's harmonics q_i_0, q_i_c1, q_i_s1, ... and each
      contact's first-harmonic force amplitude F_c_1. A continuation that
      stops early writes the points found, then exits with status 2.
    kind = "backbone" (a nonlinear mode): amplitudes [m kg^0.5], mode,
      harmonics, samples. OUT.csv has amplitude, frequency [rad/s],
      damping_ratio and amplitude_q_i.

    SI units, full float precision; a .parquet OUT is written as Parquet, -
    to standard output.
    """
    from polind import io
    from polind.structures import ContinuationError, load_structure
    from polind.structures.files import structure_files

    refuse_overwriting_inputs(structure_files(structure_path),
                              {"--output": output_path, "--plot": plot_path})
    with blame(structure_path):
        built, run = load_structure(structure_path)
        if run is None:
            raise InputError("no [structure.run] table; expected one with duration and "
                             "time_step [s] (and optionally [structure.run.force]), or a "
                             "kind = 'frequency_response' or 'backbone' run")
    stopped = None
    with blame(structure_path), progress(description="structure",
                                         unit=run.progress_unit) as bar:
        try:
            result = run.solve(built, progress=advancing(bar))
        except ContinuationError as error:
            # The points found are written, then the error ends the run with status 2.
            stopped, result = error, error.curve
    if stopped is not None and not len(result):
        with blame(structure_path):
            raise stopped
    columns = run.columns(result)
    if plot_path is None:
        write_samples(output_path, columns)
    else:
        # The table and the figure appear together, or neither does.
        options = {"stopped": True} if stopped is not None else {}
        figure = run.figure(result, built, source=os.fspath(structure_path), **options)
        io.write_together({output_path: _table_bytes(output_path, columns),
                           plot_path: figure})
    streamed = io.STDOUT in (os.fspath(output_path), os.fspath(plot_path or ""))
    files = [os.fspath(path) for path in (output_path, plot_path)
             if path is not None and os.fspath(path) != io.STDOUT]
    written = f"wrote {' and '.join(files) or '-'}: {run.summary(result)}"
    if stopped is not None:
        with blame(structure_path):
            raise InputError(f"{stopped} {written[0].upper()}{written[1:]}.")
    click.echo(written, err=streamed)


def _table_bytes(output_path, columns) -> bytes:
    """The table ``write_samples`` would write to ``output_path`` (CSV or Parquet), as bytes."""
    import tempfile
    from pathlib import Path

    suffix = ".parquet" if Path(os.fspath(output_path)).suffix.lower() == ".parquet" \
        and os.fspath(output_path) != "-" else ".csv"
    with tempfile.TemporaryDirectory() as folder:
        staged = Path(folder) / f"table{suffix}"
        write_samples(staged, columns)
        return staged.read_bytes()


@cli.command()
@click.argument("sweep_path", metavar="SWEEP.toml", type=file_path())
@click.option("--output", "-o", "output_path", required=True, type=file_path(),
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
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="PNG",
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
