"""A table sized before it is read, and refused when reading it would pass the memory limit.

:func:`table_size` gives the rows and columns of a CSV or Parquet table from
its first bytes or its metadata, without reading it all (and without opening
a pipe, whose data would be lost); :func:`check_table_memory` refuses, with an
:class:`~polind.errors.InputError` naming the file, a table whose reading and
use would pass :func:`polind.resources.memory_limit`.  :func:`header_line`
finds a CSV file's header in its first :data:`HEADER_BYTES`, for the sizes
here and for the fast reader of :mod:`polind.io.tables`, and
:func:`guess_delimiter` its field separator.
"""

from __future__ import annotations

import math
import os
import stat

from polind.io.columns import is_parquet
from polind.resources import check_memory

__all__ = ["DELIMITERS", "HEADER_BYTES", "READ_BYTES_PER_NUMBER", "SAMPLES",
           "check_table_memory", "guess_delimiter", "header_line", "table_size"]


#: A CSV file's header must lie in its first bytes, for its size and for the fast reader.
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


def table_size(path) -> tuple[int, int, bool]:
    """``(rows, columns, exact)`` of a CSV or Parquet table, without reading all of it.

    A Parquet file's metadata gives them exactly.  A CSV file's columns are
    those of its header, and its data rows are counted in a file of 64 KiB or
    less; a bigger one's are its size over the shortest mean length of the
    rows in its first 64 KiB and in ``SAMPLES`` stretches spread over
    the rest of it (``exact`` False), so that long rows at its start do not
    hide short ones after.  A file that cannot be read gives ``(0, 0, True)``:
    its reader names the problem.
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
            size = os.fstat(stream.fileno()).st_size
            prefix = stream.read(HEADER_BYTES)
            header = header_line(prefix)
            if header is None:
                return 0, 0, True
            stretches = [] if len(prefix) == size else \
                _stretches(stream, header[2], size)
    except OSError:
        return 0, 0, True
    _, text, offset = header
    columns = text.count(guess_delimiter(text)) + 1
    body = prefix[offset:].replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    if len(prefix) == size:
        return sum(1 for line in body.split(b"\n") if line.strip()), columns, True
    # The shortest row is a digit and a comma per column: never fewer rows than that allows.
    mean = min([_mean_row(body), *(_mean_row(stretch) for stretch in stretches)],
               default=None) or 2.0 * columns
    return math.ceil((size - offset) / mean), columns, False


#: Stretches of a big CSV file, spread over it, whose rows size it (with its first 64 KiB).
SAMPLES = 16
_STRETCH_BYTES = 1 << 12


def _stretches(stream, offset, size) -> list[bytes]:
    """``SAMPLES`` stretches of a file's bytes after ``offset``, evenly spread over it."""
    out = []
    span = max(size - offset - _STRETCH_BYTES, 0)
    for index in range(1, SAMPLES + 1):
        stream.seek(offset + span * index // SAMPLES)
        out.append(stream.read(_STRETCH_BYTES))
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
