"""A table sized before it is read, and refused when reading it would pass the memory limit.

:func:`table_size` gives the rows and columns of a CSV or Parquet table from
its first bytes or its metadata, without reading it all (and without opening
a pipe, whose data would be lost); :func:`check_table_memory` refuses, with an
:class:`~polind.errors.InputError` naming the file, a table whose reading and
use would pass :func:`polind.resources.memory_limit`.  ``read_header``
finds a CSV file's header in its first bytes (:func:`header_line`), for the
sizes here and for the fast reader of :mod:`polind.io.tables`, and
:func:`guess_delimiter` its field separator.  A row may be of any length,
and a file may end in the NUL padding of a preallocated file
(``polind.io.text.padding_start``): neither is a row.
"""

from __future__ import annotations

import math
import os
import stat

from polind.io.columns import is_parquet
from polind.io.text import padding_start
from polind.resources import check_memory

__all__ = ["DELIMITERS", "HEADER_BYTES", "MAX_HEADER_BYTES", "READ_BYTES_PER_NUMBER",
           "SAMPLES", "check_table_memory", "guess_delimiter", "header_line", "read_header",
           "table_size"]


#: The first bytes of a CSV file read for its header (more when the header is longer).
HEADER_BYTES = 1 << 16


def header_line(prefix):
    """``(row, text, end)`` of the first non-blank line in a file's first bytes, else None.

    ``row`` is its line number, ``end`` the offset just after its newline.
    Lines end as :func:`~polind.io.text.read_text` ends them (``\\n``, ``\\r\\n`` or ``\\r``)
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


#: The delimiters :func:`guess_delimiter` recognises in a header, preferred in this
#: order when a header holds as many of two of them.
DELIMITERS = ("\t", ",", ";")


def guess_delimiter(header: str) -> str:
    """The delimiter of a table from its header line: the most frequent of :data:`DELIMITERS`.

    A header without any of them (a single column) is taken as comma-separated.

    Examples
    --------
    >>> guess_delimiter("Time [s]\\tNormal [uN]\\tPosition [mm]")
    '\\t'
    >>> guess_delimiter("t;x;F")
    ';'
    """
    counts = [header.count(delimiter) for delimiter in DELIMITERS]
    return DELIMITERS[counts.index(max(counts))] if max(counts) else ","


# Memory of reading a table [bytes]: the fast readers' peak per number (pyarrow's table and
# the NumPy columns side by side; 48 bytes a row measured for t,x at 1e7 rows).  Python's
# row-by-row reader, for a file the fast reader refuses, is checked by polind.io.tables.
READ_BYTES_PER_NUMBER = 24


def read_header(stream, end: int):
    """``(prefix, header)``: a binary stream's first bytes and :func:`header_line` of them.

    ``end`` is where the file's data end (``polind.io.text.padding_start``).
    The prefix is the first :data:`HEADER_BYTES`, or more, doubling, until it
    holds the whole header (a wide file's header may be longer), up to
    :data:`MAX_HEADER_BYTES`; it never reaches past ``end``.  ``header`` is
    None when no header ends within it or it is not UTF-8.
    """
    stream.seek(0)
    prefix = stream.read(min(HEADER_BYTES, end))
    header = header_line(prefix)
    while header is None and HEADER_BYTES <= len(prefix) < min(end, MAX_HEADER_BYTES):
        more = stream.read(min(len(prefix), end - len(prefix), MAX_HEADER_BYTES - len(prefix)))
        if not more:
            break                                 # the file shrank: its reader tells
        prefix += more
        header = header_line(prefix)
    return prefix, header


#: The most of a file's start ``read_header`` reads to find its header [bytes].
MAX_HEADER_BYTES = 1 << 24


def table_size(path) -> tuple[int, int, bool]:
    """``(rows, columns, exact)`` of a CSV or Parquet table, without reading all of it.

    A Parquet file's metadata gives them exactly.  A CSV file's columns are
    those of its header, and its data rows are counted in a file whose data
    lie in its first bytes (``read_header``); a bigger one's are its size
    over the shortest mean length of the rows in its first bytes and in
    ``SAMPLES`` stretches spread over the rest of it (``exact`` False), so
    that long rows at its start do not hide short ones after.  A stretch
    holds a few rows however long they are; where none holds a whole row,
    the shortest a row can be (a digit and a delimiter a column) sizes it.
    The NUL padding a preallocated file ends in is no rows
    (``polind.io.text.padding_start``).  A file that cannot be read
    gives ``(0, 0, True)``: its reader names the problem.
    """
    name = os.fspath(path)
    if is_parquet(name):
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
            end = padding_start(stream, os.fstat(stream.fileno()).st_size)
            prefix, header = read_header(stream, end)
            if header is None:
                return 0, 0, True
            _, text, offset = header
            body = prefix[offset:]
            if len(prefix) == end:
                lines = body.replace(b"\r\n", b"\n").replace(b"\r", b"\n").split(b"\n")
                return sum(1 for line in lines if line.strip()), _columns(text), True
            first = _mean_row(body)
            # A stretch holds a few rows: longer ones than the header's or the first rows'.
            length = max(_STRETCH_BYTES, 4 * len(text.encode("utf-8")), 4 * int(first or 0))
            stretches = _stretches(stream, len(prefix), end, min(length, _MAX_STRETCH_BYTES))
    except OSError:
        return 0, 0, True
    columns = _columns(text)
    means = [mean for mean in (first, *(_mean_row(stretch) for stretch in stretches))
             if mean is not None]
    # The shortest row is a digit and a delimiter per column: never fewer rows than that allows.
    mean = min(means, default=2.0 * columns)
    return math.ceil((end - offset) / mean), columns, False


def _columns(header: str) -> int:
    """The number of columns of a header line."""
    return header.count(guess_delimiter(header)) + 1


#: Stretches of a big CSV file, spread over it, whose rows size it (with its first bytes).
SAMPLES = 16
_STRETCH_BYTES = 1 << 12
_MAX_STRETCH_BYTES = 1 << 20


def _stretches(stream, start, end, length) -> list[bytes]:
    """``SAMPLES`` stretches of ``length`` bytes of a file between ``start`` and ``end``,
    evenly spread over it (the last ending at ``end``)."""
    out = []
    span = max(end - start - length, 0)
    for index in range(1, SAMPLES + 1):
        where = start + span * index // SAMPLES
        stream.seek(where)
        out.append(stream.read(min(length, end - where)))
    return out


def _mean_row(data: bytes):
    """The mean length [bytes] of the complete rows in a stretch of a file, or None if none.

    A stretch may start in the middle of a row: only the rows after its first
    line end and up to its last count.
    """
    data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    start, end = data.find(b"\n") + 1, data.rfind(b"\n") + 1
    if start <= 0 or end <= start:
        return None
    lines = data[start:end].split(b"\n")
    rows = sum(1 for line in lines if line.strip())
    return (end - start) / rows if rows else None


def check_table_memory(path, bytes_per_row=0.0, use="reading") -> None:
    """Refuse (InputError naming the file) a table whose reading and use would pass the limit.

    The estimate, made before anything is read: the rows of
    :func:`table_size` times the fast reader's peak per row
    (``READ_BYTES_PER_NUMBER`` a number) and ``bytes_per_row`` that the
    caller's run holds per row besides.  ``use`` names the run in the
    message (``"simulating"``...).  The limit is
    :func:`polind.resources.memory_limit` (``--max-memory``).
    """
    name = os.fspath(path)
    rows, columns, exact = table_size(name)
    check_memory(rows * (READ_BYTES_PER_NUMBER * columns + bytes_per_row),
                 f"{name}: {use} its {rows:.3g} rows of {columns} column"
                 f"{'s' if columns != 1 else ''}"
                 f"{'' if exact else ' (estimated from the size of the file)'}")
