"""Writing tables of numbers: CSV at full precision, or Parquet, through the safe writer.

:func:`write_csv_atomic` writes columns of float64 as CSV, each number the
shortest decimal that reads back to the same bits (:func:`number_text`), or
as Parquet when the name ends in ``.parquet`` (:func:`write_parquet_atomic`).
A big table is formatted by pyarrow's C writer on every core, a small one by
Python, to the same text.  The file is written by
:func:`polind.io.output.atomic_open`: it appears, or replaces an existing
one, only once the whole table is on disk.
"""

from __future__ import annotations

import math
import os

import numpy as np

from polind.io.columns import is_parquet
from polind.io.output import atomic_open

__all__ = ["number_text", "write_csv_atomic", "write_parquet_atomic"]


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
    if is_parquet(path):
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
