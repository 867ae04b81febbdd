"""What the commands of :mod:`polind.cli` share: the group, the options, the helpers.

:func:`cli` is the click group every command module registers on (its
``--max-memory`` sets :func:`polind.resources.set_memory_limit` for the
command); :func:`model_argument`, :func:`output_option` and
:func:`file_path` declare the file parameters; :func:`load_model`,
:func:`blame`, :func:`model_inputs`, :func:`check_output_path` and
:func:`refuse_overwriting_inputs` read and check the files (every file a command
reads, directly or through a model, is an input no output may replace);
:func:`progress`, :func:`read_samples` and :func:`write_samples` show progress.
Only click and :mod:`polind.errors` are imported here: the heavy modules are
imported inside the functions.
"""

from __future__ import annotations

import contextlib
import os
import sys
from pathlib import Path

import click

from polind import __version__
from polind.errors import InputError

__all__ = ["PROGRAM", "advancing", "blame", "check_output_path", "cli", "file_path",
           "load_model", "model_argument", "model_inputs", "output_option", "progress",
           "read_samples", "refuse_overwriting_inputs", "write_samples"]

#: The program's name: the group's, and the prefix of every message on standard error.
PROGRAM = "polind"


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


def file_path(**kwargs):
    """A path parameter; existence is checked by the reader, which names the file."""
    return _FilePath(dir_okay=False, path_type=Path, **kwargs)


def model_argument(command):
    """The ``MODEL`` argument: a model file (TOML, or JSON by extension)."""
    return click.argument("model_path", metavar="MODEL", type=file_path())(command)


def output_option(command):
    """The required ``--output`` option: the file written on success only."""
    return click.option("--output", "-o", "output_path", required=True, type=file_path(),
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
    is blamed on the model file, not on a motion or data file read later; a
    model of one's own (a plugin) has its compiled functions checked
    (``polind.models.registry.check_compiled``).
    """
    import polind
    from polind.cli import check_interrupted
    from polind.models.registry import check_compiled

    with blame(path):
        model = polind.load_model(path)
        # A plugin's functions that give no force are named here, not by numba in a run.
        check_compiled(model, model.step_kernel())
    check_interrupted()
    return model


def model_inputs(path) -> list:
    """A model file and the files it names (summit heights, a height map): all inputs.

    No output of a command may replace any of them.  A file that cannot be
    read names only itself here: reading it for the model reports the problem.
    """
    from polind.models import document_files, read_model_document

    try:
        document = read_model_document(path)
    except InputError:
        return [path]
    return [path, *document_files(document)]


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
    """A ``progress(done, total)`` callback that moves ``bar`` to ``done`` of ``total``.

    It is also where a long read, run or write stops for a signal whose
    exception a library swallowed (:func:`polind.cli.check_interrupted`).
    """
    from polind.cli import check_interrupted

    def advance(done, total):
        check_interrupted()
        bar.total = total
        bar.update(done - bar.n)
    return advance


def read_samples(path, **columns):
    """A motion or data file (CSV or Parquet, or a data description of an instrument's
    file: :func:`polind.io.read_record`), with a progress bar over its bytes."""
    from polind import io

    from polind.cli import check_interrupted

    with progress(description="read", unit="B", unit_scale=True) as bar:
        samples = io.read_record(path, progress=advancing(bar), **columns)
    check_interrupted()
    return samples


def write_samples(path, columns):
    """A table of samples (CSV or Parquet by extension), with a progress bar over its rows.

    The command's output: once its last row is written, a signal no longer
    stops the run (:func:`polind.cli.commit_begins`), so that the run ends
    with the whole file and status 0, or with no file and status 130.
    """
    from polind import io
    from polind.cli import check_interrupted, commit_begins

    check_interrupted()
    rows = len(next(iter(columns.values())))
    with progress(total=rows, description="write", unit=" rows") as bar:
        advance = advancing(bar)

        def written(done, total):
            advance(done, total)
            if done >= total:
                commit_begins()

        io.write_csv_atomic(path, columns, progress=written)


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


# --- the group ------------------------------------------------------------------------------

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


@click.group(name=PROGRAM, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", prog_name=PROGRAM,
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
