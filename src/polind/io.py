"""polind's files: model, system and motion files, and writes that are atomic.

The formats are those of INTERFACE.md: model files (``[model]`` and an
optional ``[fit]``, TOML or JSON), one-degree-of-freedom system files
(``[system]``, MODELS.md section 8), and CSV tables of samples with a header
row (``t`` and one of ``x``, ``v``; optionally ``normal_load``; ``F`` for
measured data).  This module holds no physics: it reads, checks the shape of
what it read, and writes.  The models validate their own parameters.

Every problem with a file raises :class:`~polind.errors.InputError` with a
one-line message that starts with the file's path and names the row (its
line number in the file, the header being row 1), the column or the key, the
value received and what was expected.  Rows are numbered as lines of the
file, so that an editor's line number or a spreadsheet's row number points at
the offending row.

Every writer goes through one temporary file in the target's directory that
replaces the target only once the whole content is on disk: a failed run
leaves no output file, and an existing one untouched.  ``-`` writes to
standard output; an existing FIFO or device is written to directly, never
replaced; a symlink is followed (its target replaced, the link kept); and
:func:`check_output_path` refuses an output that is one of a command's
inputs.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from polind.errors import InputError, describe

__all__ = [
    "MEASUREMENT_COLUMNS",
    "MOTION_COLUMNS",
    "STDOUT",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_path",
    "read_csv_columns",
    "read_heights_csv",
    "read_model_file",
    "read_motion_csv",
    "read_system_file",
    "write_csv_atomic",
    "write_model_file",
]

#: Columns of a prescribed motion (``polind simulate --input``).
MOTION_COLUMNS = {"require": ("t",), "one_of": ("x", "v"), "optional": ("normal_load",)}
#: Columns of measured data (``polind fit --data``).
MEASUREMENT_COLUMNS = {"require": ("t", "F"), "one_of": ("x", "v"), "optional": ("normal_load",)}

# Full float precision: 17 significant digits read back to the same double.
_FLOAT_FORMAT = "%.17g"


# --- reading ---------------------------------------------------------------------------


def _read_text(path) -> str:
    """The file's text (UTF-8, a byte-order mark dropped, newlines as ``\\n``)."""
    name = os.fspath(path)
    try:
        data = Path(path).read_bytes()
    except FileNotFoundError:
        raise InputError(f"{name}: no such file") from None
    except IsADirectoryError:
        raise InputError(f"{name}: is a directory; expected a file") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read the file: {exc.strerror or exc}") from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(f"{name}: row {line}: expected UTF-8 text, got the byte "
                         f"{data[exc.start:exc.start + 1]!r}") from None
    return text.replace("\r\n", "\n").replace("\r", "\n")


def _reject_duplicate_keys(pairs):
    table = {}
    for key, value in pairs:
        if key in table:
            raise ValueError(f"duplicated key {key!r}")
        table[key] = value
    return table


def _read_document(path) -> dict:
    """Parse a TOML or JSON file (JSON if the name ends in ``.json``) into a dict."""
    name = os.fspath(path)
    text = _read_text(path)
    if Path(path).suffix.lower() == ".json":
        try:
            document = json.loads(text, object_pairs_hook=_reject_duplicate_keys)
        except json.JSONDecodeError as exc:
            raise InputError(f"{name}: not valid JSON: {exc.msg} "
                             f"(at line {exc.lineno}, column {exc.colno})") from None
        except ValueError as exc:  # a duplicated key
            raise InputError(f"{name}: not valid JSON: {exc}") from None
        if not isinstance(document, dict):
            raise InputError(f"{name}: expected a JSON object at the top level, "
                             f"got {type(document).__name__}")
        return document
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{name}: not valid TOML: {exc}") from None


def _check_tables(name, document, required, allowed):
    """Top-level keys: each required one present and a table, none unknown."""
    for key in document:
        if key not in allowed:
            raise InputError(f"{name}: unknown top-level key '{key}'; allowed: "
                             + ", ".join(f"[{table}]" for table in allowed))
    for key in allowed:
        if key in document and not isinstance(document[key], dict):
            raise InputError(f"{name}: '{key}' must be a table ([{key}]), "
                             f"got {describe(document[key])}")
    for key in required:
        if key not in document:
            raise InputError(f"{name}: no [{key}] table; expected a [{key}] table")


def read_model_file(path) -> dict:
    """Read a model file (INTERFACE.md "Model files") without validating parameters.

    Parameters
    ----------
    path : str or os.PathLike
        A TOML file, or JSON if its name ends in ``.json`` (any other name is
        read as TOML).

    Returns
    -------
    dict
        The document: a ``"model"`` table and, if present, a ``"fit"`` table.
        A relative ``model.discretisation.heights_file`` is made absolute
        against the model file's directory.

    Raises
    ------
    InputError
        The file is missing or unreadable, is not valid TOML/JSON (the
        parser's line and column are given), has no ``[model]`` table, or has
        a top-level key other than ``model`` and ``fit``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "m.toml").write_text('[model]\\ntype = "coulomb"\\ncoulomb_force = 1.0\\n')
    >>> read_model_file(folder / "m.toml")
    {'model': {'type': 'coulomb', 'coulomb_force': 1.0}}
    """
    name = os.fspath(path)
    document = _read_document(path)
    _check_tables(name, document, required=("model",), allowed=("model", "fit"))
    discretisation = document["model"].get("discretisation")
    if isinstance(discretisation, dict):
        heights = discretisation.get("heights_file")
        # A heights_file that is not a string is the model's to reject.
        if isinstance(heights, str) and heights and not os.path.isabs(heights):
            folder = os.path.dirname(os.path.abspath(name))
            discretisation["heights_file"] = os.path.normpath(os.path.join(folder, heights))
    return document


def _expected_columns(require, one_of, optional) -> str:
    parts = list(require)
    if one_of:
        parts.append("one of " + " or ".join(one_of))
    if optional:
        parts.append("optionally " + " or ".join(optional))
    return ", ".join(parts)


def _check_header(name, row, columns, require, one_of, optional):
    allowed = (*require, *one_of, *optional)
    expected = _expected_columns(require, one_of, optional)
    seen = set()
    for index, column in enumerate(columns, start=1):
        if not column:
            raise InputError(f"{name}: row {row}: column {index} of the header has no name; "
                             f"expected the columns {expected}")
        if column in seen:
            raise InputError(f"{name}: row {row}: duplicated column '{column}'; "
                             f"each column may appear once")
        if column not in allowed:
            raise InputError(f"{name}: row {row}: unknown column '{column}'; "
                             f"allowed columns: {', '.join(allowed)}")
        seen.add(column)
    for column in require:
        if column not in seen:
            raise InputError(f"{name}: row {row}: missing column '{column}' in the header; "
                             f"expected the columns {expected}")
    present = [column for column in one_of if column in seen]
    if one_of and len(present) != 1:
        choices = " and ".join(f"'{column}'" for column in one_of)
        if present:
            raise InputError(f"{name}: row {row}: doubled motion column: the header has both "
                             f"{choices}; expected exactly one")
        raise InputError(f"{name}: row {row}: the header has none of the columns {choices}; "
                         f"expected exactly one")


def _parse_rows(name, columns, rows) -> np.ndarray:
    """The data rows as an (n_rows, n_columns) float64 array.

    numpy's parser takes the common case at C speed; if it refuses anything,
    the rows are read one by one to name the first bad row and column.
    """
    try:
        values = np.loadtxt([line for _, line in rows], delimiter=",", comments=None,
                            dtype=np.float64, ndmin=2)
        if values.shape == (len(rows), len(columns)):
            return values
    except ValueError:
        pass
    values = np.empty((len(rows), len(columns)))
    for index, (row, line) in enumerate(rows):
        fields = line.split(",")
        if len(fields) != len(columns):
            raise InputError(f"{name}: row {row}: expected {len(columns)} comma-separated "
                             f"fields ({','.join(columns)}), got {len(fields)}")
        for column_index, (column, text) in enumerate(zip(columns, fields)):
            text = text.strip()
            try:
                if "_" in text:  # float() accepts 1_000; a data file should not
                    raise ValueError(text)
                values[index, column_index] = float(text)
            except ValueError:
                raise InputError(f"{name}: row {row}, column '{column}': expected a number, "
                                 f"got {describe(text)}") from None
    return values


def read_csv_columns(path, require, one_of=(), optional=(), *, min_rows=1,
                     increasing=None, positive=()) -> dict[str, np.ndarray]:
    """Read a CSV table of numbers with a header row, checking its columns.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file: a header row naming the columns, then one row of numbers
        per sample, fields separated by commas.  Blank lines are skipped;
        whitespace around names and numbers is ignored.
    require : sequence of str
        Columns that must be present.
    one_of : sequence of str
        Exactly one of these columns must be present (empty: no such rule).
    optional : sequence of str
        Columns that may be present.  Any column not named in ``require``,
        ``one_of`` or ``optional`` is an error.
    min_rows : int
        Fewest data rows accepted.
    increasing : str, optional
        A column whose values must increase strictly down the file.
    positive : sequence of str
        Columns whose values must be positive (e.g. a normal load).

    Returns
    -------
    dict of str to numpy.ndarray
        The present columns, each a 1-D float64 array.

    Raises
    ------
    InputError
        Naming the file and the row (line number) or column: empty file, no
        data rows, unknown/duplicated/missing columns, neither or both of
        ``one_of``, a row with the wrong number of fields, text where a number
        was expected, NaN or infinity, too few rows, a non-increasing value
        in the ``increasing`` column, a value <= 0 in a ``positive`` column.
    """
    name = os.fspath(path)
    lines = _read_text(path).split("\n")
    rows = [(number, line) for number, line in enumerate(lines, start=1) if line.strip()]
    if not rows:
        raise InputError(f"{name}: the file is empty; expected a header row with the columns "
                         f"{_expected_columns(require, one_of, optional)}")
    (header_row, header), rows = rows[0], rows[1:]
    columns = [column.strip() for column in header.split(",")]
    _check_header(name, header_row, columns, require, one_of, optional)
    if not rows:
        raise InputError(f"{name}: no data rows after the header (row {header_row}); "
                         f"expected at least {min_rows} row{'s' if min_rows != 1 else ''} "
                         f"of numbers")
    values = _parse_rows(name, columns, rows)
    row_numbers = [row for row, _ in rows]

    finite = np.isfinite(values)
    if not finite.all():
        index, column_index = np.argwhere(~finite)[0]
        raise InputError(f"{name}: row {row_numbers[index]}, column '{columns[column_index]}': "
                         f"expected a finite number, got {float(values[index, column_index])!r}")
    for column in positive:
        if column in columns:
            bad = np.flatnonzero(values[:, columns.index(column)] <= 0.0)
            if bad.size:
                raise InputError(f"{name}: row {row_numbers[bad[0]]}, column '{column}': "
                                 f"expected a positive number, got "
                                 f"{float(values[bad[0], columns.index(column)])!r}")
    if len(rows) < min_rows:
        raise InputError(f"{name}: expected at least {min_rows} data rows, got {len(rows)}")
    if increasing is not None and increasing in columns:
        column = values[:, columns.index(increasing)]
        bad = np.flatnonzero(np.diff(column) <= 0.0)
        if bad.size:
            k = bad[0] + 1
            raise InputError(f"{name}: row {row_numbers[k]}, column '{increasing}': expected "
                             f"values that increase strictly, got {float(column[k])!r} after "
                             f"{float(column[k - 1])!r} on row {row_numbers[k - 1]}")
    return {column: np.ascontiguousarray(values[:, j]) for j, column in enumerate(columns)}


def read_motion_csv(path, require=MOTION_COLUMNS["require"], one_of=MOTION_COLUMNS["one_of"],
                    optional=MOTION_COLUMNS["optional"], *,
                    positive=("normal_load",)) -> dict[str, np.ndarray]:
    """Read a table of samples in time: a prescribed motion or measured data.

    The rules of :func:`read_csv_columns`, with at least two rows, the time
    ``t`` strictly increasing (when ``t`` is a column) and a ``normal_load``
    column positive.  The defaults are the
    motion file of ``polind simulate`` (``t``, one of ``x``/``v``, optionally
    ``normal_load``); measured data for ``polind fit`` is
    ``read_motion_csv(path, **MEASUREMENT_COLUMNS)`` (adds ``F``).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    require, one_of, optional, positive : sequence of str
        Column names, as in :func:`read_csv_columns`.

    Returns
    -------
    dict of str to numpy.ndarray
        The present columns as float64 arrays, e.g. ``{"t": ..., "x": ...}``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> motion = pathlib.Path(tempfile.mkdtemp()) / "motion.csv"
    >>> _ = motion.write_text("t,x\\n0,0\\n0.5,1e-6\\n1,2e-6\\n")
    >>> read_motion_csv(motion)["x"]
    array([0.e+00, 1.e-06, 2.e-06])
    """
    return read_csv_columns(path, require, one_of, optional, min_rows=2, increasing="t",
                            positive=positive)


def read_heights_csv(path) -> np.ndarray:
    """Measured asperity summit heights [m]: a CSV with one column ``h``.

    The ``heights_file`` of a direct-summation Pol-Ind model (INTERFACE.md).
    """
    return read_csv_columns(path, require=("h",))["h"]


# --- the [system] table ------------------------------------------------------------------

_REQUIRED = object()

# Each key: (default or _REQUIRED, the range it must lie in).
_SYSTEM_SCHEMA = {
    "system": {
        "mass": (_REQUIRED, "positive"),
        "duration": (_REQUIRED, "positive"),
        "time_step": (_REQUIRED, "positive"),
    },
    "system.spring_drive": {
        "stiffness": (_REQUIRED, "non-negative"),
        "velocity": (_REQUIRED, "finite"),
    },
    "system.force": {
        "offset": (0.0, "finite"),
        "rate": (0.0, "finite"),
        "amplitude": (0.0, "finite"),
        "frequency": (0.0, "non-negative"),
    },
}
_RANGES = {
    "positive": lambda value: value > 0.0,
    "non-negative": lambda value: value >= 0.0,
    "finite": lambda value: True,
}
_SYSTEM_SUBTABLES = ("spring_drive", "force")


def _system_table(name, where, table) -> dict:
    """Check one table of the system file against its schema; return its floats."""
    schema = _SYSTEM_SCHEMA[where]
    subtables = _SYSTEM_SUBTABLES if where == "system" else ()
    for key in table:
        if key not in schema and key not in subtables:
            allowed = ", ".join((*schema, *subtables))
            raise InputError(f"{name}: unknown key '{where}.{key}'; expected one of: {allowed}")
    clean = {}
    for key, (default, allowed_range) in schema.items():
        value = table.get(key, default)
        if value is _REQUIRED:
            raise InputError(f"{name}: missing key '{where}.{key}'")
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(value):
            raise InputError(f"{name}: key '{where}.{key}' must be a finite number, "
                             f"got {describe(value)}")
        if not _RANGES[allowed_range](value):
            raise InputError(f"{name}: key '{where}.{key}' must be {allowed_range}, "
                             f"got {describe(value)}")
        clean[key] = float(value)
    return clean


def read_system_file(path) -> dict:
    """Read a one-degree-of-freedom system file (INTERFACE.md, MODELS.md section 8).

    Parameters
    ----------
    path : str or os.PathLike
        TOML (or JSON if the name ends in ``.json``) with a ``[system]`` table:
        ``mass`` [kg], ``duration`` [s], ``time_step`` [s], and at least one
        of ``[system.spring_drive]`` (``stiffness`` [N/m] >= 0, ``velocity``
        [m/s]) and ``[system.force]`` (``offset`` [N], ``rate`` [N/s],
        ``amplitude`` [N], ``frequency`` [Hz] >= 0; each defaults to 0).

    Returns
    -------
    dict
        ``mass``, ``duration``, ``time_step`` (floats), ``spring_drive`` and
        ``force`` (dicts of floats, or ``None`` when the table is absent).

    Raises
    ------
    InputError
        Naming the file and the key: unknown or missing keys, values that are
        not finite numbers, a non-positive mass, duration or time step, a time
        step longer than the duration, a negative spring stiffness or force
        frequency, neither drive present.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> system = pathlib.Path(tempfile.mkdtemp()) / "system.toml"
    >>> _ = system.write_text("[system]\\nmass = 1.0\\nduration = 2.0\\ntime_step = 0.01\\n"
    ...                       "[system.force]\\namplitude = 0.4\\nfrequency = 1.0\\n")
    >>> read_system_file(system)["force"]
    {'offset': 0.0, 'rate': 0.0, 'amplitude': 0.4, 'frequency': 1.0}
    """
    name = os.fspath(path)
    document = _read_document(path)
    _check_tables(name, document, required=("system",), allowed=("system",))
    table = document["system"]
    system = _system_table(name, "system", table)
    if system["time_step"] > system["duration"]:
        raise InputError(f"{name}: key 'system.time_step' must not exceed system.duration "
                         f"({system['duration']!r}), got {system['time_step']!r}")
    for key in _SYSTEM_SUBTABLES:
        if key not in table:
            system[key] = None
            continue
        if not isinstance(table[key], dict):
            raise InputError(f"{name}: 'system.{key}' must be a table ([system.{key}]), "
                             f"got {describe(table[key])}")
        system[key] = _system_table(name, f"system.{key}", table[key])
    if system["spring_drive"] is None and system["force"] is None:
        raise InputError(f"{name}: [system] has no drive; expected a [system.spring_drive] "
                         f"or a [system.force] table (or both)")
    return system


# --- writing -----------------------------------------------------------------------------


#: The output name that means standard output.
STDOUT = "-"


def _same_file(one, other) -> bool:
    """Whether two paths name one file (after links), existing or not."""
    try:
        return os.path.samefile(one, other)
    except OSError:
        return os.path.realpath(one) == os.path.realpath(other)


def check_output_path(path, inputs=()) -> None:
    """Fail early if ``path`` cannot become an output file.

    ``-`` (standard output) always can.  Otherwise the path must not name
    a directory (or end in a separator), its directory must exist and be
    writable, and it must not be one of ``inputs`` (the files the command
    reads: an output never replaces an input, also through a link).
    Commands call this before a long run so that a typo in ``--output`` is
    reported at once.
    """
    name = os.fspath(path)
    if name == STDOUT:
        return
    if name.endswith((os.sep, "/")) or os.path.isdir(name):
        raise InputError(f"{name}: is a directory; expected a file name to write")
    for source in inputs:
        if source is not None and _same_file(name, os.fspath(source)):
            raise InputError(f"{name}: is also an input of this command ({os.fspath(source)}); "
                             f"expected another file name, so that no input is overwritten")
    target = os.path.realpath(name)
    folder = os.path.dirname(target)
    if os.path.exists(target) and not os.path.isfile(target):
        return              # a FIFO or a device: written to directly, never replaced
    if not os.path.isdir(folder):
        raise InputError(f"{name}: cannot write: the directory {folder!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{name}: cannot write: the directory {folder!r} is not writable")


def _new_file_mode(name) -> int:
    """The permissions the output should have: an existing file's, else the umask's."""
    try:
        return os.stat(name).st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


class _Terminated(BaseException):
    """SIGTERM or SIGHUP while an output is being written (its temporary file is removed)."""


@contextlib.contextmanager
def _removing_on_signals():
    """Turn SIGTERM and SIGHUP into an exception while a temporary file exists.

    SIGINT is already KeyboardInterrupt.  Only the main thread can set
    handlers; elsewhere the signals keep their handlers.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(number, frame):
        raise _Terminated(number)

    names = [name for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]
    previous = {name: signal.signal(getattr(signal, name), terminate) for name in names}
    try:
        yield
    except _Terminated as exc:
        # Cleaned up by the caller; now die of the signal as the process would have.
        number = exc.args[0]
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)
        previous = {}
        signal.raise_signal(number)
        raise SystemExit(128 + number) from None
    finally:
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)


@contextlib.contextmanager
def _atomic_open(path, binary=False):
    """Yield a stream for the output ``path``; a regular file appears only on success.

    * ``-``: standard output.
    * An existing FIFO or device (``/dev/stdout``, a named pipe): opened and
      written directly; it is never replaced by a regular file.
    * Otherwise a temporary file beside the target (a symlink's target: the
      link stays a link) that replaces it only once the whole content is on
      disk; any failure, Ctrl-C, SIGTERM or SIGHUP removes it.
    """
    name = os.fspath(path)
    check_output_path(name)
    if name == STDOUT:
        import sys

        stream = sys.stdout.buffer if binary else sys.stdout
        yield stream
        stream.flush()
        return
    target = os.path.realpath(name)
    if os.path.exists(target) and not os.path.isfile(target):
        try:
            stream = open(target, "wb" if binary else "w",
                          **({} if binary else {"encoding": "utf-8", "newline": "\n"}))
        except OSError as exc:
            raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from None
        with stream:
            yield stream
        return
    folder = os.path.dirname(target)
    with _removing_on_signals():
        try:
            handle, temporary = tempfile.mkstemp(dir=folder, suffix=".tmp",
                                                 prefix=f".{os.path.basename(target)}.")
        except OSError as exc:
            raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from None
        try:
            if binary:
                stream = os.fdopen(handle, "wb")
            else:
                stream = os.fdopen(handle, "w", encoding="utf-8", newline="\n")
            with stream:
                yield stream
                stream.flush()
                os.fsync(stream.fileno())
            os.chmod(temporary, _new_file_mode(target))
            os.replace(temporary, target)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            if isinstance(exc, OSError):
                raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from exc
            raise


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: all of it, or nothing changes."""
    with _atomic_open(path, binary=True) as stream:
        stream.write(data)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` newlines) to ``path`` atomically."""
    with _atomic_open(path) as stream:
        stream.write(text)


def write_csv_atomic(path, columns) -> None:
    """Write columns of numbers as CSV with full float precision, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The output file; it appears (or is replaced) only once the whole table
        is written.
    columns : dict of str to array_like
        Column name to 1-D array, all of one length, in the order they are
        written.  Values are written with ``%.17g``, which reads back to the
        same float64 bit for bit.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "out.csv"
    >>> write_csv_atomic(out, {"t": [0.0, 0.1], "F": [1.0, -1.0]})
    >>> print(out.read_text(), end="")
    t,F
    0,1
    0.10000000000000001,-1
    """
    names = list(columns)
    for column in names:
        if not column or any(character in column for character in ",\n\r"):
            raise ValueError(f"A CSV column name must be non-empty without commas or "
                             f"newlines. Got {column!r}.")
    arrays = [np.asarray(columns[column], dtype=np.float64) for column in names]
    lengths = {column: array.shape for column, array in zip(names, arrays)}
    if any(array.ndim != 1 for array in arrays) or len(set(lengths.values())) > 1:
        raise ValueError(f"CSV columns must be 1-D arrays of one length. Got shapes {lengths}.")
    table = np.column_stack(arrays) if arrays else np.empty((0, 0))
    with _atomic_open(path) as stream:
        stream.write(",".join(names) + "\n")
        for text in _format_rows(table):
            stream.write(text)


def _format_rows(table, rows_per_chunk=8192):
    """The rows of a 2-D float table as CSV text, a chunk of rows at a time.

    One ``%`` per chunk on Python floats: about twice as fast as ``np.savetxt``.
    """
    if table.size == 0:
        return
    row_format = ",".join([_FLOAT_FORMAT] * table.shape[1]) + "\n"
    for start in range(0, table.shape[0], rows_per_chunk):
        chunk = table[start:start + rows_per_chunk]
        yield (row_format * chunk.shape[0]) % tuple(chunk.ravel().tolist())


def plain_data(value, *, for_toml=True):
    """Python types TOML and JSON can hold: numpy scalars/arrays and tuples become
    floats and lists, paths strings.  For TOML (``for_toml=True``) ``None`` entries
    are dropped (TOML has no null: an absent key means its default); for JSON
    non-finite floats become ``None`` (``null``), which strict JSON readers need."""
    if isinstance(value, dict):
        return {str(key): plain_data(item, for_toml=for_toml) for key, item in value.items()
                if not (for_toml and item is None)}
    if isinstance(value, (list, tuple, np.ndarray)):
        items = value.tolist() if isinstance(value, np.ndarray) else value
        return [plain_data(item, for_toml=for_toml) for item in items]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if not for_toml and isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_model_file(path, document: dict) -> None:
    """Write a model-file document (``{"model": {...}, "fit": {...}}``) atomically.

    TOML, or JSON (indented) if the name ends in ``.json``; the inverse of
    :func:`read_model_file`.
    """
    plain = plain_data(document)
    if Path(path).suffix.lower() == ".json":
        text = json.dumps(plain, indent=2) + "\n"
    else:
        import tomli_w

        text = tomli_w.dumps(plain)
    atomic_write_text(path, text)
