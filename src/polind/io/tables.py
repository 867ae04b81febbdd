"""Reading tables of numbers: CSV and Parquet, motion, measured data and summit heights.

:func:`read_csv_columns` reads a CSV table with a header row, or a Parquet
table (:func:`read_parquet_columns`) when the name ends in ``.parquet``,
under the rules of :mod:`polind.io.columns`; :func:`read_motion_csv` reads a
motion or measured-data file (``t`` increasing, at least two rows) and
:func:`read_heights_csv` a file of summit heights.  :func:`read_table_columns`
is the reader under them all: the columns a caller picks from the header of
a delimited text (comma, tab, semicolon...) or Parquet file, as float64
arrays, with the rows to name in a message; :mod:`polind.io.records` reads an
instrument's file through it.

Files are read as spreadsheets write them: a byte-order mark, ``\\r\\n`` line
ends, blank lines (trailing or between rows) and numbers in double quotes
(``"1.5"``) are read as lines and numbers.  Rows may be of any length (an
instrument's file of hundreds of channels).  The NUL bytes a preallocated
logger file ends in are padding, not rows: the rows before them are read,
and a last row they cut short (no line end before them) is refused, naming
its row (:mod:`polind.io.text`).

Big tables go at disk speed: pyarrow's C reader parses a CSV file of 1 MiB or
more (Python's row-by-row reader takes any file it refuses, and names the bad
row), and every float64 reads back bit for bit.  A table is sized before it
is read and refused when reading it would pass the memory limit
(:func:`polind.io.sizing.check_table_memory`).  Rows are numbered as lines
of the file, the header being row 1, so that an editor's line number or a
spreadsheet's row number points at the offending row.
"""

from __future__ import annotations

import csv
import os
import stat

import numpy as np

from polind.errors import InputError, describe
from polind.io.columns import (
    MOTION_COLUMNS,
    check_header,
    check_values,
    expected_columns,
    is_parquet,
)
from polind.io.sizing import (READ_BYTES_PER_NUMBER, check_table_memory, guess_delimiter,
                               read_header)
from polind.io.text import padding_start, read_text
from polind.resources import check_memory

__all__ = ["read_csv_columns", "read_heights_csv",
           "read_motion_csv", "read_parquet_columns", "read_table_columns"]

_DELIMITER_NAMES = {"\t": "tab", ",": "comma", ";": "semicolon", " ": "space"}


def _fields(line: str, delimiter: str) -> list[str]:
    """The fields of a line, whitespace stripped and double quotes removed (``"1.5"``)."""
    if '"' in line:
        try:
            return [field.strip() for field in
                    next(csv.reader([line], delimiter=delimiter, skipinitialspace=True))]
        except csv.Error:     # a field too long for the csv module: not a number either
            pass
    return [field.strip() for field in line.split(delimiter)]


def _parse_rows(name, columns, kept, rows, delimiter) -> np.ndarray:
    """The ``kept`` columns of the data rows as an (n_rows, n_kept) float64 array.

    numpy's parser takes the common case (every field a number, no quotes) at
    C speed; if it refuses anything, the rows are read one by one to name the
    first bad row and column.
    """
    indices = [columns.index(column) for column in kept]
    try:
        values = np.loadtxt([line for _, line in rows], delimiter=delimiter, comments=None,
                            dtype=np.float64, ndmin=2)
        if values.shape == (len(rows), len(columns)):
            return values[:, indices]
    except ValueError:
        pass
    separated = _DELIMITER_NAMES.get(delimiter, repr(delimiter))
    values = np.empty((len(rows), len(kept)))
    for index, (row, line) in enumerate(rows):
        fields = _fields(line, delimiter)
        if len(fields) != len(columns):
            listed = delimiter.join(columns) if delimiter != "\t" else ", ".join(columns)
            raise InputError(f"{name}: row {row}: expected {len(columns)} {separated}-separated "
                             f"fields ({listed}), got {len(fields)}")
        for value_index, (column, column_index) in enumerate(zip(kept, indices)):
            text = fields[column_index]
            try:
                if "_" in text:  # float() accepts 1_000; a data file should not
                    raise ValueError(text)
                values[index, value_index] = float(text)
            except ValueError:
                raise InputError(f"{name}: row {row}, column '{column}': expected a number, "
                                 f"got {describe(text)}") from None
    return values


def _read_csv_carefully(name, select, expected, min_rows, delimiter=","):
    """Python's reader: the columns ``select`` keeps, and the line number of every data row.

    It names the first bad row and column of any file, and it is the
    reference the fast reader must agree with.  ``delimiter`` None: guessed
    from the header; ``expected``: the columns in words, for an empty file.
    """
    lines = read_text(name, padded=True).split("\n")
    rows = [(number, line) for number, line in enumerate(lines, start=1) if line.strip()]
    if not rows:
        raise InputError(f"{name}: the file is empty; expected a header row with the columns "
                         f"{expected}")
    (header_row, header), rows = rows[0], rows[1:]
    delimiter = delimiter or guess_delimiter(header)
    columns = _fields(header, delimiter)
    kept = select(name, header_row, columns)
    if not rows:
        raise InputError(f"{name}: no data rows after the header (row {header_row}); "
                         f"expected at least {min_rows} row{'s' if min_rows != 1 else ''} "
                         f"of numbers")
    values = _parse_rows(name, columns, kept, rows, delimiter)
    row_numbers = [row for row, _ in rows]
    del rows, lines
    table = {column: np.ascontiguousarray(values[:, j]) for j, column in enumerate(kept)}
    return table, row_numbers


# A CSV file from this size on is read by pyarrow's C reader (a smaller one by Python:
# as fast, without importing pyarrow).
_FAST_READ_BYTES = 1 << 20
# Memory of Python's row-by-row reader per byte of the file [bytes] (its text, lines and
# rows; it reads a file the fast reader refuses).  The fast reader's is that of
# polind.io.sizing.check_table_memory.
_CAREFUL_READ_BYTES_PER_BYTE = 6


def _read_csv_fast(name, select, delimiter=",", progress=None):
    """pyarrow's C reader: the columns ``select`` keeps of a big well-formed file, else None.

    None means "read it carefully": a file that is small or not a regular
    file, a header that is not where this reader looks or has a mistake, and
    any row pyarrow refuses (it parses numbers exactly as ``float`` does, but
    refuses more: whitespace, whitespace-only lines, ``1_000``...).  Truly
    empty lines are skipped, as the careful reader skips them; a field in
    double quotes is read without them, as the careful reader reads it.  Rows
    of any length are read, and only the columns kept are converted (a wide
    instrument file goes at the speed of its bytes); the NUL padding of a
    preallocated file is not read, and a last row it cuts short is left to
    the careful reader, which names it.
    """
    try:
        # Looked at before opening: a pipe opened here would lose what it carries.
        info = os.stat(name)
        if not stat.S_ISREG(info.st_mode) or info.st_size < _FAST_READ_BYTES:
            return None
        with open(name, "rb") as stream:
            end = padding_start(stream, info.st_size)    # the NUL padding is no rows
            header = read_header(stream, end)[1]
            if header is not None and header[2] < end < info.st_size:
                stream.seek(end - 1)
                if stream.read(1) not in (b"\n", b"\r"):
                    return None                   # a row cut short: the careful reader names it
    except OSError:
        return None                               # the careful reader names the problem
    if header is None:
        return None
    header_row, text, offset = header
    delimiter = delimiter or guess_delimiter(text)
    try:
        columns = _fields(text, delimiter)
        kept = select(name, header_row, columns)
    except InputError:
        return None                               # named by the careful reader, as it always was

    import pyarrow as pa
    import pyarrow.csv as pacsv

    float64 = pa.float64()
    size = info.st_size
    batches = []
    try:
        with pa.OSFile(name, "r") as file:
            file.seek(offset)
            source, base = file, 0
            if end < size:
                # The rows before the NUL padding, as one buffer: pyarrow reads a stream to
                # its end.
                check_memory(end - offset, f"{name}: reading its {(end - offset) / 1e6:.3g} MB "
                                           f"of rows before the NUL padding")
                source, base = pa.BufferReader(file.read_buffer(end - offset)), offset
            reader = pacsv.open_csv(
                source,
                read_options=pacsv.ReadOptions(column_names=columns, block_size=1 << 21),
                parse_options=pacsv.ParseOptions(delimiter=delimiter, quote_char='"',
                                                  double_quote=True, escape_char=False,
                                                  newlines_in_values=False,
                                                  ignore_empty_lines=True),
                convert_options=pacsv.ConvertOptions(
                    column_types={column: float64 for column in kept}, include_columns=kept,
                    null_values=[], strings_can_be_null=False,
                    quoted_strings_can_be_null=False))
            rows = 0
            for batch in reader:
                batches.append(batch)
                rows += batch.num_rows
                # The rows were counted from samples of the file before reading: a file
                # whose sampled rows were longer than the rest is stopped at the limit.
                check_memory(rows * READ_BYTES_PER_NUMBER * len(kept),
                             f"{name}: reading more than {rows:.3g} rows of {len(kept)} "
                             f"column{'s' if len(kept) != 1 else ''}")
                if progress is not None:
                    progress(min(base + source.tell(), size), size)
    except InputError:
        raise
    except (pa.ArrowException, OSError, ValueError):
        return None
    if not batches or sum(batch.num_rows for batch in batches) == 0:
        return None
    held = [pa.Table.from_batches(batches)]
    del batches, reader
    return _numpy_columns(held, kept)
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



def read_table_columns(path, select, expected, *, delimiter=",", min_rows=1, progress=None):
    """Read the columns a caller picks from the header of a text or Parquet table.

    The reader under every table of polind: :func:`read_csv_columns` picks
    the columns of a motion or data file, :func:`polind.io.read_record` those
    a data description names.  The values are not checked (a caller checks
    the rows it keeps, with :func:`polind.io.columns.check_values`).

    Parameters
    ----------
    path : str or os.PathLike
        A text file with a header row, then one row of numbers per sample
        (blank lines skipped, whitespace around names and numbers ignored,
        fields in double quotes read without them), or a Parquet file when
        the name ends in ``.parquet``.
    select : callable
        ``select(name, row, columns)`` is given the file's name, the header's
        line number (None for Parquet) and the header's column names; it
        returns the names to read, each once, or raises
        :class:`~polind.errors.InputError` naming what is wrong.
    expected : str
        The columns in words (``"t, one of x or v"``), for the message on an
        empty file.
    delimiter : str or None
        The field separator of a text file (one character); None: guessed
        from the header (:func:`polind.io.sizing.guess_delimiter`).
    min_rows : int
        The fewest data rows the caller needs, for the message on a file
        without any.
    progress : callable, optional
        ``progress(done, total)`` [bytes of the file], as the file is read.

    Returns
    -------
    columns : dict of str to numpy.ndarray
        The columns ``select`` returned, each a 1-D float64 array, read to
        the bit (``float`` of each field).  Non-finite values are included.
    rows_of : callable
        ``rows_of(indices)``: the rows of the file (lines of a text file,
        the header being row 1; rows from 1 in a Parquet file) of array
        indices, for a message.

    Raises
    ------
    InputError
        Naming the file and the row or column: a missing, empty or unreadable
        file, no data rows, a row with the wrong number of fields, text where
        a number was expected, and whatever ``select`` raises.
    """
    name = os.fspath(path)
    if is_parquet(name):
        return _read_parquet(name, select, min_rows, progress)
    check_table_memory(name)
    table = _read_csv_fast(name, select, delimiter, progress)
    if table is not None:
        if all(np.isfinite(values).all() for values in table.values()):
            _report_read(name, progress)
            return table, lambda indices: _csv_row_lines(name, indices)
        del table     # a NaN or an infinity: named by the careful reader as the text has it
    _check_careful_memory(name)
    table, row_numbers = _read_csv_carefully(name, select, expected, min_rows, delimiter)
    _report_read(name, progress)
    return table, lambda indices: [row_numbers[index] for index in indices]


def _checked_header(require, one_of, optional):
    """A ``select`` of :func:`read_table_columns`: every column, by the rules of a header."""
    def select(name, row, columns):
        check_header(name, row, columns, require, one_of, optional)
        return columns
    return select


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
        whitespace around names and numbers is ignored; a name or number in
        double quotes (``"1.5"``, as spreadsheets write them) is read
        without them; a byte-order mark and ``\\r\\n`` line ends are read.
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
    select = _checked_header(require, one_of, optional)
    if is_parquet(name):
        return read_parquet_columns(name, require, one_of, optional, min_rows=min_rows,
                                    increasing=increasing, positive=positive,
                                    progress=progress)
    table, rows_of = read_table_columns(name, select, expected_columns(require, one_of, optional),
                                        min_rows=min_rows, progress=progress)
    check_values(name, table, rows_of, min_rows=min_rows, increasing=increasing,
                 positive=positive)
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
                     f"fast reader does not take, such as a nan, spaces around a "
                     f"number or a blank line with spaces)")


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
    >>> from polind.io import write_csv_atomic
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> write_csv_atomic(folder / "m.parquet", {"t": [0.0, 1.0], "x": [0.0, 1e-6]})
    >>> read_parquet_columns(folder / "m.parquet", ["t", "x"])["x"]
    array([0.e+00, 1.e-06])
    """
    name = os.fspath(path)
    table, rows_of = _read_parquet(name, _checked_header(require, one_of, optional), min_rows,
                                   progress)
    check_values(name, table, rows_of, min_rows=min_rows, increasing=increasing,
                 positive=positive)
    return table


def _read_parquet(name, select, min_rows, progress):
    """The columns ``select`` keeps of a Parquet file, and ``rows_of`` (rows from 1)."""
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
        columns = select(name, None, list(schema.names))
        for column in columns:
            field = schema.field(column)
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
    _report_read(name, progress)
    return table, lambda indices: [int(index) + 1 for index in indices]
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
