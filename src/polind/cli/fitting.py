"""Fitting models to measured data: ``polind fit`` and ``polind compare``."""

from __future__ import annotations

import os
from pathlib import Path

import click

from polind.cli.common import (blame, cli, file_path, model_argument, model_inputs,
                               output_option, progress, read_samples,
                               refuse_overwriting_inputs)
from polind.errors import InputError


def _holdout_option(command):
    return click.option("--holdout", "holdout", default=None, metavar="F",
                        type=click.FloatRange(0.0, 1.0, min_open=True, max_open=True),
                        help="Fit the first 1-F of the samples (by time) and report the RMS "
                             "error on the rest.")(command)


def _starts_option(command):
    return click.option("--starts", "starts", default=None, metavar="N",
                        type=click.IntRange(min=1),
                        help="Fit from N starting points and keep the best: the model's values, "
                             "then the fit of the model it contains, its structured starts and "
                             "Latin-hypercube points in the bounds. Default: all of the model's "
                             "own starts and 2 spread points; 1: the model's values "
                             "only.")(command)


@cli.command()
@model_argument
@click.option("--data", "-d", "data_path", required=True, type=file_path(), metavar="DATA.csv",
              help="Measured t, one of x [m] / v [m/s], F [N], optionally normal_load [N]; "
                   "or a data description (.toml) of an instrument's file.")
@output_option
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="FILE",
              help="Also write a PNG of measured against fitted force.")
@_holdout_option
@_starts_option
def fit(model_path, data_path, output_path, plot_path, holdout, starts):
    """Identify the [fit] free parameters of MODEL from measured data.

    The model's values are the starting point; [fit] free names the keys to
    identify and [fit.bounds] bounds them (without bounds a key gets default
    bounds derived from the data).  The fit starts from several points and
    keeps the best (--starts).  Writes FITTED.toml: [model] with the
    identified values and [fit.result] (rms_error, holdout_rms_error with
    --holdout, iterations, start, starts, warnings, value and standard error
    of every free key).  Each warning is also one line on standard error.
    """
    from polind import identification, io
    from polind.models import read_model_document

    data_files = io.record_files(data_path)      # a data description names its file
    refuse_overwriting_inputs([*model_inputs(model_path), *data_files],
                              {"--output": output_path, "--plot": plot_path})
    with blame(model_path):
        document = read_model_document(model_path)
        model, free, bounds = identification.parse_fit(document)
    io.check_table_memory(data_files[-1], identification.fit_bytes_per_sample(model, free),
                          f"fitting {len(free)} free key{'s' if len(free) != 1 else ''} to")
    data = read_samples(data_path, **io.MEASUREMENT_COLUMNS)
    with progress(description="fit", unit=" simulations") as bar:
        def advance(evaluations, rms):
            bar.set_postfix_str(f"rms {rms:.4g} N", refresh=False)
            bar.update()

        with blame(data_path):
            # The fit's warnings reach standard error as UserWarnings, one line each (main).
            result = identification.identify(model, data, free=free, bounds=bounds,
                                             holdout=holdout, starts=starts, callback=advance)
    # The fitted model and its figure appear together, or neither does.
    figure = None if plot_path is None else identification.plot_fit(data, result, None)
    text = io.model_file_text(result.to_document(),
                              as_json=Path(output_path).suffix.lower() == ".json")
    io.write_together({output_path: text, plot_path: figure})
    # With an output on standard output ('-'), the readable text goes to standard error.
    streamed = io.STDOUT in (os.fspath(output_path), os.fspath(plot_path or ""))
    click.echo(result.summary(), err=streamed)
    files = [os.fspath(path) for path in (output_path, plot_path)
             if path is not None and os.fspath(path) != io.STDOUT]
    if files:
        click.echo(f"wrote {' and '.join(files)}", err=streamed)


@cli.command()
@click.argument("model_paths", metavar="MODEL...", nargs=-1, required=True, type=file_path())
@click.option("--data", "-d", "data_path", required=True, type=file_path(), metavar="DATA.csv",
              help="Measured t, one of x [m] / v [m/s], F [N], optionally normal_load [N]; "
                   "or a data description (.toml) of an instrument's file.")
@_holdout_option
@click.option("--output", "-o", "output_path", default=None, type=file_path(),
              metavar="TABLE.csv", help="Also write the table as CSV ('-': standard output).")
@click.option("--plot", "plot_path", default=None, type=file_path(), metavar="PNG",
              help="Also write a PNG of measured and predicted force of every model.")
@_starts_option
def compare(model_paths, data_path, holdout, output_path, plot_path, starts):
    """Fit each MODEL to the same data and compare them: one row per model.

    Each model file's values are its starting point and its [fit] table its
    free keys and bounds (default: the model's usual keys, bounds from the
    data).  The table: model (the file's name), free parameters (count),
    RMS error in sample and on the held-out part (--holdout F: the last F of
    the samples, predicted by continuing each fitted run), AIC and BIC of
    the fitted part (n ln(RSS/n) + 2k and + k ln n).  A model that contains
    another given model (GMS contains Maxwell-slip, LuGre Stribeck) also
    starts from that model's fit.  --plot draws measured and predicted force
    against time and position, the held-out part shaded.
    """
    from polind import identification, io
    from polind.models import read_model_document

    data_files = io.record_files(data_path)      # a data description names its file
    refuse_overwriting_inputs([*(path for model in model_paths for path in model_inputs(model)),
                               *data_files],
                              {"--output": output_path, "--plot": plot_path})
    stems = [Path(path).stem for path in model_paths]
    documents = {}
    per_sample = 0.0              # the models are fitted one after another: the largest fit
    for path, stem in zip(model_paths, stems):
        label = stem if stems.count(stem) == 1 else os.fspath(path)
        if label in documents:
            raise InputError(f"{path}: the model file is given twice; expected each MODEL once.")
        with blame(path):
            documents[label] = read_model_document(path)
            model, free, _ = identification.parse_fit(documents[label])
        per_sample = max(per_sample, identification.fit_bytes_per_sample(model, free))
    io.check_table_memory(data_files[-1], per_sample, "fitting the models to")
    data = read_samples(data_path, **io.MEASUREMENT_COLUMNS)
    with progress(total=len(documents), description="compare", unit=" models") as bar:
        def advance(done, total, label):
            bar.update(done - bar.n)

        with blame(data_path):
            table = identification.compare(documents, data, holdout=holdout,
                                           progress=advance, starts=starts)
    # With an output on standard output ('-'), the readable text goes to standard error.
    written = [os.fspath(path) for path in (output_path, plot_path) if path is not None]
    streamed = io.STDOUT in written
    click.echo(table.table(), err=streamed)
    # The table and the figure appear together, or neither does.
    figure = None if plot_path is None else table.plot(
        None, title=f"{data_path}: measured and predicted friction force")
    io.write_together({output_path: None if output_path is None else table.to_csv(),
                       plot_path: figure})
    files = [path for path in written if path != io.STDOUT]
    if files:
        click.echo(f"wrote {' and '.join(files)}", err=streamed)
