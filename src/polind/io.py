"""polind's files: model, system and motion files, and writes that are atomic.

The formats are those of the user guide's :ref:`formats-model-files`: model files (``[model]`` and an
optional ``[fit]``, TOML or JSON), one-degree-of-freedom system files
(``[system]``, :ref:`formats-system`), and CSV tables of samples with a header
row (``t`` and one of ``x``, ``v``; optionally ``normal_load``; ``F`` for
measured data), or Parquet tables with the same columns when the name ends
in ``.parquet``.  This module holds no physics: it reads, checks the shape of
what it read, and writes.  The models validate their own parameters.

Big tables go at disk speed: pyarrow's C reader parses a CSV file of 1 MiB or
more (Python's row-by-row reader takes any file it refuses, and names the bad
row), and its writer formats a big table on every core.  Every float64 reads
back bit for bit.  A table is sized before it is read (:func:`table_size`) and
refused when reading it would pass the memory limit (:mod:`polind.resources`);
:func:`check_table_memory` adds what a command does with the rows.

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
import stat
import tempfile
import tomllib
from pathlib import Path

import numpy as np

from polind.errors import InputError, describe
from polind.resources import check_memory

__all__ = [
    "MEASUREMENT_COLUMNS",
    "MOTION_COLUMNS",
    "STDOUT",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_path",
    "check_table_memory",
    "read_csv_columns",
    "read_heights_csv",
    "read_model_file",
    "read_motion_csv",
    "read_parquet_columns",
    "read_system_file",
    "save_model",
    "table_size",
    "write_csv_atomic",
    "write_model_file",
    "write_parquet_atomic",
]

#: Columns of a prescribed motion (``polind simulate --input``).
MOTION_COLUMNS = {"require": ("t",), "one_of": ("x", "v"), "optional": ("normal_load",)}
#: Columns of measured data (``polind fit --data``).
MEASUREMENT_COLUMNS = {"require": ("t", "F"), "one_of": ("x", "v"), "optional": ("normal_load",)}


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


def read_document(path) -> dict:
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


def check_tables(name, document, required, allowed):
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
    """Read a model file (:ref:`formats-model-files`) without validating parameters.

    Parameters
    ----------
    path : str or os.PathLike
        A TOML file, or JSON if its name ends in ``.json`` (any other name is
        read as TOML).

    Returns
    -------
    dict
        The document: a ``"model"`` table and, if present, a ``"fit"`` table.
        A relative ``model.discretisation.heights_file`` or
        ``model.surface.topography`` is made absolute against the model
        file's directory.

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
    document = read_document(path)
    check_tables(name, document, required=("model",), allowed=("model", "fit"))
    # Files a model names are relative to the model file.  A value that is
    # not a string is the model's to reject.
    folder = os.path.dirname(os.path.abspath(name))
    for entries, key, value in named_files(document["model"]):
        if isinstance(value, str) and value and not os.path.isabs(value):
            entries[key] = os.path.normpath(os.path.join(folder, value))
    return document


#: The files a ``[model]`` table may name, as ``(sub-table, key)``: relative to
#: the model file in a file, absolute once read.
MODEL_FILE_KEYS = (("discretisation", "heights_file"), ("surface", "topography"))


def named_files(model_table):
    """``(sub-table, key, value)`` for each of :data:`MODEL_FILE_KEYS` (value None when absent)."""
    for table, key in MODEL_FILE_KEYS:
        entries = model_table.get(table) if isinstance(model_table, dict) else None
        value = entries.get(key) if isinstance(entries, dict) else None
        yield entries, key, value


def _expected_columns(require, one_of, optional) -> str:
    parts = list(require)
    if one_of:
        parts.append("one of " + " or ".join(one_of))
    if optional:
        parts.append("optionally " + " or ".join(optional))
    return ", ".join(parts)


def _check_header(name, row, columns, require, one_of, optional):
    """The columns of a table: named, each once, all allowed, the required ones present.

    ``row`` is the header's line number in a CSV file; None for a Parquet file
    (its columns are named in its schema, not on a row).
    """
    where = f"{name}: row {row}: " if row is not None else f"{name}: "
    allowed = (*require, *one_of, *optional)
    expected = _expected_columns(require, one_of, optional)
    seen = set()
    for index, column in enumerate(columns, start=1):
        if not column:
            raise InputError(f"{where}column {index} of the header has no name; "
                             f"expected the columns {expected}")
        if column in seen:
            raise InputError(f"{where}duplicated column '{column}'; "
                             f"each column may appear once")
        if column not in allowed:
            raise InputError(f"{where}unknown column '{column}'; "
                             f"allowed columns: {', '.join(allowed)}")
        seen.add(column)
    for column in require:
        if column not in seen:
            raise InputError(f"{where}missing column '{column}' in the header; "
                             f"expected the columns {expected}")
    present = [column for column in one_of if column in seen]
    if one_of and len(present) != 1:
        choices = " and ".join(f"'{column}'" for column in one_of)
        if present:
            raise InputError(f"{where}doubled motion column: the header has both "
                             f"{choices}; expected exactly one")
        raise InputError(f"{where}the header has none of the columns {choices}; "
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


def _read_csv_carefully(name, require, one_of, optional, min_rows):
    """Python's reader: the columns, and the line number of every data row.

    It names the first bad row and column of any file, and it is the
    reference the fast reader must agree with.
    """
    lines = _read_text(name).split("\n")
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
    del rows, lines
    table = {column: np.ascontiguousarray(values[:, j]) for j, column in enumerate(columns)}
    return table, row_numbers


# A CSV file from this size on is read by pyarrow's C reader (a smaller one by Python:
# as fast, without importing pyarrow).
_FAST_READ_BYTES = 1 << 20
# The header must lie in the file's first bytes for the fast reader.
_HEADER_BYTES = 1 << 16


def _header_line(prefix):
    """``(row, text, end)`` of the first non-blank line in a file's first bytes, else None.

    ``row`` is its line number, ``end`` the offset just after its newline.
    Lines end as :func:`_read_text` ends them (``\\n``, ``\\r\\n`` or ``\\r``)
    and a byte-order mark is skipped.  None when the header does not end within
    ``prefix`` or is not UTF-8: the careful reader then reads the file.
    """
    start = 3 if prefix.startswith(b"\xef\xbb\xbf") else 0
    row = 1
    while True:
        ends = [end for end in (prefix.find(b"\n", start), prefix.find(b"\r", start)) if end >= 0]
        if not ends:
            return None
        end = min(ends)
        after = end + 1
        if prefix[end:after] == b"\r":
            if after == len(prefix):
                return None                       # "\r" or "\r\n": the next read would tell
            if prefix[after:after + 1] == b"\n":
                after += 1
        try:
            text = prefix[start:end].decode("utf-8")
        except UnicodeDecodeError:
            return None
        if text.strip():
            return row, text, after
        row, start = row + 1, after


def _read_csv_fast(name, require, one_of, optional, progress=None):
    """pyarrow's C reader: the columns of a big well-formed file, else None.

    None means "read it carefully": a file that is small or not a regular
    file, a header that is not where this reader looks or has a mistake, and
    any row pyarrow refuses (it parses numbers exactly as ``float`` does, but
    refuses more: quotes, whitespace-only lines, ``1_000``...).  Truly empty
    lines are skipped, as the careful reader skips them.
    """
    try:
        # Looked at before opening: a pipe opened here would lose what it carries.
        info = os.stat(name)
        if not stat.S_ISREG(info.st_mode) or info.st_size < _FAST_READ_BYTES:
            return None
        with open(name, "rb") as stream:
            header = _header_line(stream.read(_HEADER_BYTES))
    except OSError:
        return None                               # the careful reader names the problem
    if header is None:
        return None
    header_row, text, offset = header
    columns = [column.strip() for column in text.split(",")]
    try:
        _check_header(name, header_row, columns, require, one_of, optional)
    except InputError:
        return None                               # named by the careful reader, as it always was

    import pyarrow as pa
    import pyarrow.csv as pacsv

    float64 = pa.float64()
    size = info.st_size
    batches = []
    try:
        with pa.OSFile(name, "r") as source:
            source.seek(offset)
            reader = pacsv.open_csv(
                source,
                read_options=pacsv.ReadOptions(column_names=columns, block_size=1 << 21),
                parse_options=pacsv.ParseOptions(delimiter=",", quote_char=False,
                                                  escape_char=False, ignore_empty_lines=True),
                convert_options=pacsv.ConvertOptions(
                    column_types={column: float64 for column in columns}, null_values=[],
                    strings_can_be_null=False, quoted_strings_can_be_null=False))
            for batch in reader:
                batches.append(batch)
                if progress is not None:
                    progress(min(source.tell(), size), size)
    except (pa.ArrowException, OSError, ValueError):
        return None
    if not batches or sum(batch.num_rows for batch in batches) == 0:
        return None
    held = [pa.Table.from_batches(batches)]
    del batches, reader
    return _numpy_columns(held, columns)


def _numpy_columns(held, columns):
    """The columns of the pyarrow table in ``held`` (a list, emptied: the table is freed a
    column at a time) as writeable float64 arrays."""
    import pyarrow as pa

    table = held.pop()
    rows = table.num_rows
    arrays = {}
    for column in columns:
        values = np.empty(rows)
        offset = 0
        for chunk in table.column(column).chunks:
            values[offset:offset + len(chunk)] = chunk.to_numpy(zero_copy_only=False)
            offset += len(chunk)
        arrays[column] = values
        table = table.drop_columns([column])
    del table
    pa.default_memory_pool().release_unused()
    return arrays


def _csv_row_lines(name, indices):
    """The line numbers of data rows ``indices`` (0: the first row after the header) of a CSV
    file, with lines and blank lines counted as the careful reader counts them."""
    wanted = set(int(index) for index in indices)
    found = {}
    index = -2                                    # the header is the first non-blank line
    with open(name, encoding="utf-8-sig", newline=None) as stream:
        for number, line in enumerate(stream, start=1):
            if not line.strip():
                continue
            index += 1
            if index in wanted:
                found[index] = number
                if len(found) == len(wanted):
                    break
    return [found[int(index)] for index in indices]


def _check_values(name, table, rows_of, *, min_rows, increasing, positive):
    """The rules on values, in this order: finite, positive, enough rows, increasing.

    ``rows_of(indices)`` gives the rows (as a message names them) of array
    indices, only when a rule is broken.
    """
    columns = list(table)
    first = None
    for column in columns:
        finite = np.isfinite(table[column])
        if not finite.all():
            index = int(np.argmin(finite))
            if first is None or index < first[0]:  # the first in the file: by row, then column
                first = (index, column)
    if first is not None:
        index, column = first
        raise InputError(f"{name}: row {rows_of([index])[0]}, column '{column}': "
                         f"expected a finite number, got {float(table[column][index])!r}")
    for column in positive:
        if column in table:
            bad = np.flatnonzero(table[column] <= 0.0)
            if bad.size:
                raise InputError(f"{name}: row {rows_of([bad[0]])[0]}, column '{column}': "
                                 f"expected a positive number, got "
                                 f"{float(table[column][bad[0]])!r}")
    rows = table[columns[0]].shape[0]
    if rows < min_rows:
        raise InputError(f"{name}: expected at least {min_rows} data rows, got {rows}")
    if increasing is not None and increasing in table:
        values = table[increasing]
        # values[k] <= values[k - 1] is diff <= 0 for finite floats, without an array of diffs
        bad = np.flatnonzero(values[1:] <= values[:-1])
        if bad.size:
            k = int(bad[0]) + 1
            row, previous = rows_of([k, k - 1])
            raise InputError(f"{name}: row {row}, column '{increasing}': expected "
                             f"values that increase strictly, got {float(values[k])!r} after "
                             f"{float(values[k - 1])!r} on row {previous}")


def _is_parquet(path) -> bool:
    """Whether a motion, data or result file is Parquet: its name ends in ``.parquet``."""
    return os.fspath(path).lower().endswith(".parquet")


# Memory of reading a table [bytes]: the fast readers' peak per number (pyarrow's table and
# the NumPy columns side by side; 48 bytes a row measured for t,x at 1e7 rows), and Python's
# row-by-row reader's per byte of the file (its text, lines and rows; it reads a file the
# fast reader refuses).
_READ_BYTES_PER_NUMBER = 24
_CAREFUL_READ_BYTES_PER_BYTE = 6


def table_size(path) -> tuple[int, int, bool]:
    """``(rows, columns, exact)`` of a CSV or Parquet table, without reading all of it.

    A Parquet file's metadata gives them exactly.  A CSV file's columns are
    those of its header, and its data rows are counted in a file of 64 KiB or
    less; a bigger one's are its size over the mean length of the rows in
    its first 64 KiB (``exact`` False).  A file that cannot be read gives
    ``(0, 0, True)``: its reader names the problem.
    """
    name = os.fspath(path)
    if _is_parquet(name):
        try:
            import pyarrow.parquet as pq

            metadata = pq.read_metadata(name)
        except Exception:                      # noqa: BLE001 - the reader names it
            return 0, 0, True
        return int(metadata.num_rows), int(metadata.num_columns), True
    try:
        if not stat.S_ISREG(os.stat(name).st_mode):
            return 0, 0, True        # a pipe is not opened twice (its data would be lost)
        with open(name, "rb") as stream:
            size = os.fstat(stream.fileno()).st_size
            prefix = stream.read(_HEADER_BYTES)
    except OSError:
        return 0, 0, True
    header = _header_line(prefix)
    if header is None:
        return 0, 0, True
    _, text, offset = header
    columns = text.count(",") + 1
    body = prefix[offset:].replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    if len(prefix) == size:
        return sum(1 for line in body.split(b"\n") if line.strip()), columns, True
    complete = body[:body.rfind(b"\n") + 1]
    rows = sum(1 for line in complete.split(b"\n") if line.strip())
    # The shortest row is a digit and a comma per column: never fewer rows than that allows.
    mean = len(complete) / rows if rows else 2.0 * columns
    return math.ceil((size - offset) / mean), columns, False


def check_table_memory(path, bytes_per_row=0.0, use="reading") -> None:
    """Refuse (InputError naming the file) a table whose reading and use would pass the limit.

    The estimate, made before anything is read: the rows of
    :func:`table_size` times the fast reader's peak per row
    (``_READ_BYTES_PER_NUMBER`` a number) and ``bytes_per_row`` that the
    caller's run holds per row besides.  ``use`` names the run in the
    message (``"simulating"``...).  The limit is
    :func:`polind.resources.memory_limit` (``--max-memory``).
    """
    name = os.fspath(path)
    rows, columns, exact = table_size(name)
    check_memory(rows * (_READ_BYTES_PER_NUMBER * columns + bytes_per_row),
                 f"{name}: {use} its {rows:.3g} rows of {columns} column"
                 f"{'s' if columns != 1 else ''}"
                 f"{'' if exact else ' (estimated from the size of the file)'}")


def read_csv_columns(path, require, one_of=(), optional=(), *, min_rows=1,
                     increasing=None, positive=(), progress=None) -> dict[str, np.ndarray]:
    """Read a CSV table of numbers with a header row, checking its columns.

    A name ending in ``.parquet`` is read by :func:`read_parquet_columns`
    instead, with the same rules.

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
    progress : callable, optional
        ``progress(done, total)`` [bytes of the file], called as the file is
        read (a small file: once, at the end).

    Returns
    -------
    dict of str to numpy.ndarray
        The present columns, each a 1-D float64 array, read to the bit
        (``float`` of each field).

    Raises
    ------
    InputError
        Naming the file and the row (line number) or column: empty file, no
        data rows, unknown/duplicated/missing columns, neither or both of
        ``one_of``, a row with the wrong number of fields, text where a number
        was expected, NaN or infinity, too few rows, a non-increasing value
        in the ``increasing`` column, a value <= 0 in a ``positive`` column.

    Notes
    -----
    A file of 1 MiB or more is read by pyarrow's C reader, at disk speed.
    Any file it refuses, and any NaN or infinity, is read again by Python's
    row-by-row reader, which names the first bad row; the two agree on every
    value and every message.
    """
    name = os.fspath(path)
    rules = {"min_rows": min_rows, "increasing": increasing, "positive": positive}
    if _is_parquet(name):
        return read_parquet_columns(name, require, one_of, optional, progress=progress, **rules)
    check_table_memory(name)
    table = _read_csv_fast(name, require, one_of, optional, progress)
    if table is not None:
        if all(np.isfinite(values).all() for values in table.values()):
            _check_values(name, table, lambda indices: _csv_row_lines(name, indices), **rules)
            _report_read(name, progress)
            return table
        del table     # a NaN or an infinity: named by the careful reader as the text has it
    _check_careful_memory(name)
    table, row_numbers = _read_csv_carefully(name, require, one_of, optional, min_rows)
    _check_values(name, table, lambda indices: [row_numbers[index] for index in indices],
                  **rules)
    _report_read(name, progress)
    return table


def _check_careful_memory(name):
    """Refuse reading a big file row by row (the fast reader refused it) beyond the limit."""
    try:
        size = os.path.getsize(name)
    except OSError:
        return                                    # the careful reader names the problem
    if size >= _FAST_READ_BYTES:
        check_memory(size * _CAREFUL_READ_BYTES_PER_BYTE,
                     f"{name}: reading its {size / 1e6:.3g} MB row by row (a row that the "
                     f"fast reader does not take, such as a nan, a quote or a blank line "
                     f"with spaces)")


def _report_read(name, progress):
    """Tell ``progress`` that the whole file is read."""
    if progress is not None:
        size = os.path.getsize(name)
        progress(size, size)


def read_parquet_columns(path, require, one_of=(), optional=(), *, min_rows=1,
                         increasing=None, positive=(), progress=None) -> dict[str, np.ndarray]:
    """Read a Parquet table of numbers, with the rules of :func:`read_csv_columns`.

    Columns of integers or floats are read as float64.  A message names the
    file and the column, and the row where a value breaks a rule; rows of a
    Parquet file are counted from 1 (it has no header row).

    Raises
    ------
    InputError
        As :func:`read_csv_columns`, and: not a Parquet file, a column that
        is not numbers, a missing value (null).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> write_csv_atomic(folder / "m.parquet", {"t": [0.0, 1.0], "x": [0.0, 1e-6]})
    >>> read_parquet_columns(folder / "m.parquet", ["t", "x"])["x"]
    array([0.e+00, 1.e-06])
    """
    name = os.fspath(path)
    try:
        info = os.stat(name)
    except FileNotFoundError:
        raise InputError(f"{name}: no such file") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read the file: {exc.strerror or exc}") from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{name}: is a directory; expected a file")
    check_table_memory(name)

    import pyarrow as pa
    import pyarrow.parquet as pq

    try:
        parquet = pq.ParquetFile(name)
    except OSError as exc:
        raise InputError(f"{name}: cannot read the file: {exc.strerror or exc}") from None
    except (pa.ArrowException, ValueError) as exc:
        raise InputError(f"{name}: not a Parquet file ({exc})") from None
    try:
        schema = parquet.schema_arrow
        columns = list(schema.names)
        _check_header(name, None, columns, require, one_of, optional)
        for field in schema:
            if not (pa.types.is_integer(field.type) or pa.types.is_floating(field.type)):
                raise InputError(f"{name}: column '{field.name}': expected numbers, "
                                 f"got values of type {field.type}")
        rows = parquet.metadata.num_rows
        if rows == 0:
            raise InputError(f"{name}: no data rows; expected at least {min_rows} "
                             f"row{'s' if min_rows != 1 else ''} of numbers")
        groups, done = [], 0
        for index in range(parquet.num_row_groups):
            groups.append(parquet.read_row_group(index, columns=columns))
            done += groups[-1].num_rows
            if progress is not None:
                progress(info.st_size * done // rows, info.st_size)
        table = pa.concat_tables(groups)
        del groups
    except InputError:
        raise
    except OSError as exc:
        raise InputError(f"{name}: cannot read the file: {exc.strerror or exc}") from None
    except (pa.ArrowException, ValueError) as exc:
        raise InputError(f"{name}: not a valid Parquet file ({exc})") from None
    finally:
        parquet.close()
    for column in columns:
        if table.column(column).null_count:
            missing = table.column(column).is_null().to_numpy(zero_copy_only=False)
            raise InputError(f"{name}: row {int(np.argmax(missing)) + 1}, column '{column}': "
                             f"expected a number, got a missing value (null)")
    held = [table]
    del table
    table = _numpy_columns(held, columns)
    _check_values(name, table, lambda indices: [int(index) + 1 for index in indices],
                  min_rows=min_rows, increasing=increasing, positive=positive)
    _report_read(name, progress)
    return table


def read_motion_csv(path, require=MOTION_COLUMNS["require"], one_of=MOTION_COLUMNS["one_of"],
                    optional=MOTION_COLUMNS["optional"], *,
                    positive=("normal_load",), progress=None) -> dict[str, np.ndarray]:
    """Read a table of samples in time: a prescribed motion or measured data.

    The rules of :func:`read_csv_columns`, with at least two rows, the time
    ``t`` strictly increasing (when ``t`` is a column) and a ``normal_load``
    column positive.  The defaults are the
    motion file of ``polind simulate`` (``t``, one of ``x``/``v``, optionally
    ``normal_load``); measured data for ``polind fit`` is
    ``read_motion_csv(path, **MEASUREMENT_COLUMNS)`` (adds ``F``).  A name
    ending in ``.parquet`` is read as Parquet (same columns).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV or Parquet file.
    require, one_of, optional, positive : sequence of str
        Column names, as in :func:`read_csv_columns`.
    progress : callable, optional
        ``progress(done, total)`` [bytes of the file], as the file is read.

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
                            positive=positive, progress=progress)


def read_heights_csv(path) -> np.ndarray:
    """Measured asperity summit heights [m]: a CSV with one column ``h``.

    The ``heights_file`` of a direct-summation Pol-Ind model (:ref:`formats-measured-surface`).
    """
    return read_csv_columns(path, require=("h",))["h"]


# --- the [system] table ------------------------------------------------------------------


def read_system_file(path) -> dict:
    """Read a one-degree-of-freedom system file (:ref:`formats-system`).

    Only the file is checked here: its keys and values are checked by
    :func:`polind.load_system`, which declares them (:mod:`polind.dynamics`)
    and gives a bad value the message a :class:`polind.System` built in
    Python gives, after the file's name.

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
        The ``[system]`` table as the file has it.

    Raises
    ------
    InputError
        Naming the file: missing or unreadable, not valid TOML/JSON, no
        ``[system]`` table, or a top-level key other than ``system``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> system = pathlib.Path(tempfile.mkdtemp()) / "system.toml"
    >>> _ = system.write_text("[system]\\nmass = 1.0\\nduration = 2.0\\ntime_step = 0.01\\n"
    ...                       "[system.force]\\namplitude = 0.4\\nfrequency = 1.0\\n")
    >>> read_system_file(system)["force"]
    {'amplitude': 0.4, 'frequency': 1.0}
    """
    document = read_document(path)
    check_tables(os.fspath(path), document, required=("system",), allowed=("system",))
    return document["system"]


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
def atomic_open(path, binary=False):
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
    with atomic_open(path, binary=True) as stream:
        stream.write(data)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` newlines) to ``path`` atomically."""
    with atomic_open(path) as stream:
        stream.write(text)


def _table_columns(columns):
    """The names and float64 arrays of a table to write; ValueError for a malformed one."""
    names = list(columns)
    for column in names:
        if not column or any(character in column for character in ",\n\r"):
            raise ValueError(f"A CSV column name must be non-empty without commas or "
                             f"newlines. Got {column!r}.")
    arrays = [np.asarray(columns[column], dtype=np.float64) for column in names]
    lengths = {column: array.shape for column, array in zip(names, arrays)}
    if any(array.ndim != 1 for array in arrays) or len(set(lengths.values())) > 1:
        raise ValueError(f"CSV columns must be 1-D arrays of one length. Got shapes {lengths}.")
    return names, arrays


def write_csv_atomic(path, columns, progress=None) -> None:
    """Write columns of numbers as CSV with full float precision, atomically.

    A name ending in ``.parquet`` is written as Parquet instead
    (:func:`write_parquet_atomic`).

    Parameters
    ----------
    path : str or os.PathLike
        The output file; it appears (or is replaced) only once the whole table
        is written.  ``-`` is standard output.
    columns : dict of str to array_like
        Column name to 1-D array, all of one length, in the order they are
        written.  Each value is written as the shortest decimal that reads
        back to the same float64 bit for bit (``nan``, ``inf``, ``-inf`` for
        the non-finite ones); a big table is formatted by pyarrow's C writer
        on every core, a small one by Python, to the same text.
    progress : callable, optional
        ``progress(done, total)`` [rows], called as the rows are written.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "out.csv"
    >>> write_csv_atomic(out, {"t": [0.0, 0.1], "F": [1.0, -1e-7]})
    >>> print(out.read_text(), end="")
    t,F
    0,1
    0.1,-1e-7
    """
    names, arrays = _table_columns(columns)
    if _is_parquet(path):
        _write_parquet(path, names, arrays, progress)
        return
    rows = arrays[0].shape[0] if arrays else 0
    with atomic_open(path) as stream:
        stream.write(",".join(names) + "\n")
        done = 0
        for text in _format_rows(arrays):
            stream.write(text)
            if progress is not None:
                done = min(done + _ROWS_PER_CHUNK, rows)
                progress(done, rows)


def write_parquet_atomic(path, columns, progress=None) -> None:
    """Write columns of numbers as a Parquet file (float64 columns), atomically.

    ``columns`` and ``progress`` as in :func:`write_csv_atomic`; the file
    reads back with :func:`read_parquet_columns` to the bit.
    """
    names, arrays = _table_columns(columns)
    _write_parquet(path, names, arrays, progress)


# Rows of a Parquet row group (pyarrow's default).
_PARQUET_ROWS = 1 << 20


def _write_parquet(path, names, arrays, progress=None):
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table(dict(zip(names, arrays)))
    rows = table.num_rows
    with atomic_open(path, binary=True) as stream:
        with pq.ParquetWriter(stream, table.schema) as writer:
            for start in range(0, max(rows, 1), _PARQUET_ROWS):
                writer.write_table(table.slice(start, _PARQUET_ROWS))
                if progress is not None:
                    progress(min(start + _PARQUET_ROWS, rows), rows)


# Tables of this many numbers and more are formatted by pyarrow (smaller ones by Python,
# which needs no import); both write the same text.
_FAST_WRITE_NUMBERS = 1 << 13
# Rows of CSV text formatted at a time (small enough that the buffers are reused, not
# mapped afresh for every chunk).
_ROWS_PER_CHUNK = 1 << 13


def _format_rows(table, rows_per_chunk=None):
    """The rows of a table of floats as CSV text (no header), a chunk of rows at a time.

    ``table`` is a 2-D array or a sequence of 1-D columns of one length;
    ``rows_per_chunk`` defaults to ``_ROWS_PER_CHUNK``.  Every number is the
    shortest text that reads back to the same float64.
    """
    rows_per_chunk = rows_per_chunk or _ROWS_PER_CHUNK
    columns = [table[:, j] for j in range(table.shape[1])] if isinstance(table, np.ndarray) \
        else list(table)
    if not columns or columns[0].shape[0] == 0:
        return
    rows = columns[0].shape[0]
    if rows * len(columns) >= _FAST_WRITE_NUMBERS:
        yield from _arrow_csv_rows(columns, rows_per_chunk)
        return
    for start in range(0, rows, rows_per_chunk):
        chunk = [column[start:start + rows_per_chunk].tolist() for column in columns]
        yield "".join(",".join(map(number_text, row)) + "\n" for row in zip(*chunk))


def number_text(value: float) -> str:
    """The shortest decimal that reads back to ``value``, laid out as pyarrow writes it.

    Python's ``repr`` gives the shortest digits; pyarrow writes them in
    positional notation for decimal exponents -6 to 9 (``0.000001``,
    ``3000000000``, ``1``, ``-0``) and else as ``1.5e-7``, ``1e+10``.
    """
    if value != value:
        return "nan"
    if value == math.inf or value == -math.inf:
        return "inf" if value > 0 else "-inf"
    if value == 0.0:
        return "-0" if math.copysign(1.0, value) < 0 else "0"
    sign = "-" if value < 0 else ""
    mantissa, _, exponent = repr(abs(value)).partition("e")
    whole, _, fraction = mantissa.partition(".")
    digits = whole + fraction
    significant = digits.lstrip("0")
    # value = 0.<significant> * 10**point = <first digit>.<the others> * 10**(point - 1)
    point = len(whole) - (len(digits) - len(significant)) + int(exponent or 0)
    significant = significant.rstrip("0")
    power = point - 1
    if -6 <= power <= 9:
        if point <= 0:
            return f"{sign}0.{'0' * -point}{significant}"
        if point >= len(significant):
            return sign + significant + "0" * (point - len(significant))
        return f"{sign}{significant[:point]}.{significant[point:]}"
    fraction = f".{significant[1:]}" if len(significant) > 1 else ""
    return f"{sign}{significant[0]}{fraction}e{'+' if power > 0 else '-'}{abs(power)}"


def _arrow_csv_rows(columns, rows_per_chunk):
    """CSV text of the columns by pyarrow's writer, chunks formatted on all cores, in order."""
    import collections
    from concurrent.futures import ThreadPoolExecutor

    import pyarrow as pa
    import pyarrow.csv as pacsv

    names = [f"c{index}" for index in range(len(columns))]
    options = pacsv.WriteOptions(include_header=False, batch_size=4096)
    rows = columns[0].shape[0]

    def chunk_text(start):
        batch = pa.record_batch([pa.array(column[start:start + rows_per_chunk])
                                 for column in columns], names=names)
        sink = pa.BufferOutputStream()
        pacsv.write_csv(batch, sink, options)
        return str(sink.getvalue(), "ascii")

    workers = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") \
        else (os.cpu_count() or 1)
    pool = ThreadPoolExecutor(max(1, workers))
    pending = collections.deque()
    try:
        for start in range(0, rows, rows_per_chunk):
            pending.append(pool.submit(chunk_text, start))
            if len(pending) > workers:        # a few chunks ahead, never the whole table
                yield pending.popleft().result()
        while pending:
            yield pending.popleft().result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


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


def model_file_text(document: dict, *, as_json=False) -> str:
    """The text of a model file holding ``document``: TOML (tomli-w), or indented JSON.

    Floats are written so that they read back bit for bit; ``None`` entries
    are left out (an absent key means its default).
    """
    plain = plain_data(document)
    if as_json:
        return json.dumps(plain, indent=2) + "\n"
    import tomli_w

    return tomli_w.dumps(plain)


def write_model_file(path, document: dict) -> None:
    """Write a model-file document (``{"model": {...}, "fit": {...}}``) atomically.

    TOML, or JSON (indented) if the name ends in ``.json``; the inverse of
    :func:`read_model_file`.
    """
    atomic_write_text(path, model_file_text(document,
                                            as_json=Path(path).suffix.lower() == ".json"))


def save_model(model, path) -> None:
    """Write ``model`` to a model file that :func:`polind.load_model` reads back equal.

    Parameters
    ----------
    model : polind.FrictionModel
        Any registered model type, with its nested tables, ``reference_load``
        and ``[model.compliance]``.
    path : str or os.PathLike
        TOML, or JSON (indented) if the name ends in ``.json``; ``-`` writes
        to standard output.  Written like every polind output
        (:ref:`cli-exit-status`): through a temporary file that replaces an existing
        file only once the whole model is on disk; a directory, or the
        model's own ``heights_file`` or ``topography``, is refused with an
        :class:`~polind.InputError`.

    A relative ``discretisation.heights_file`` or ``surface.topography`` is
    written as an absolute path (the file the model reads now), so the saved
    model reads the same summits wherever it is saved.

    Examples
    --------
    >>> import pathlib, tempfile, polind
    >>> model = polind.model_from_dict({"model": {"type": "lugre", "bristle_stiffness": 1e5,
    ...     "bristle_damping": 316.0, "viscous_coefficient": 0.4, "coulomb_force": 1.0,
    ...     "static_force": 1.5, "stribeck_velocity": 1e-3}})
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "lugre.toml"
    >>> polind.save_model(model, path)
    >>> polind.load_model(path) == model
    True
    """
    # A model is known by what it does (io sits below the models and does not import them).
    document = model.to_dict() if callable(getattr(model, "to_dict", None)) else None
    if not (isinstance(document, dict) and isinstance(document.get("model"), dict)
            and "type" in document["model"]):
        raise InputError(f"save_model needs a polind.FrictionModel. Got {describe(model)} "
                         f"instead.")
    # The files the model reads: written absolute, and never replaced by the model file.
    inputs = []
    for entries, key, value in named_files(document["model"]):
        if value:
            entries[key] = os.path.abspath(value)
            inputs.append(entries[key])
    check_output_path(path, inputs=inputs)
    write_model_file(path, document)
