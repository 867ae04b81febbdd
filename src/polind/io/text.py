"""A text file as polind's readers take it: UTF-8, newlines as ``\\n``.

Model, system and CSV files are text.  :func:`read_text` reads one whole,
drops a byte-order mark, turns ``\\r\\n`` and ``\\r`` into ``\\n`` (so that
rows are counted as an editor counts lines) and raises
:class:`~polind.errors.InputError` naming the file when it is missing, a
directory, unreadable or not UTF-8 (with the row of the first bad byte).

A table may end in NUL bytes: a logger that preallocates its file writes
its rows over the zeros, and leaves the rest.  The readers of tables read
the rows before that padding (:func:`padding_start` finds where it starts,
``read_text(path, padded=True)`` drops it), and refuse, naming the row, a
last row that the padding cuts short (no line end before the NULs: the
logger stopped in the middle of writing it).  A NUL anywhere else is no
padding: the row holding it is named as text where a number was expected.
"""

from __future__ import annotations

import os
from pathlib import Path

from polind.errors import InputError

__all__ = ["PADDING", "check_padding", "padding_start", "read_bytes", "read_text"]

#: The byte a preallocated file is padded with after its rows.
PADDING = b"\0"
# The first block read backwards from a file's end to find its padding [bytes]; each
# further block doubles, up to _PADDING_MAX_BLOCK.
_PADDING_BLOCK = 1 << 16
_PADDING_MAX_BLOCK = 1 << 24


def read_bytes(path, expected="a file") -> bytes:
    """The file's bytes; an InputError naming it and what was ``expected`` if it cannot be read."""
    name = os.fspath(path)
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        where = "" if expected == "a file" else f"; expected {expected}"
        raise InputError(f"{name}: no such file{where}") from None
    except IsADirectoryError:
        raise InputError(f"{name}: is a directory; expected {expected}") from None
    except OSError as exc:
        raise InputError(f"{name}: cannot read the file: {exc.strerror or exc}") from None


def padding_start(stream, size: int) -> int:
    """The offset where the trailing NUL padding of a binary ``stream`` of ``size`` bytes
    starts: ``size`` for a file without any, 0 for a file of NULs only.

    Reads backwards from the end, a block at a time (one byte for a file
    without padding); the stream's position is left anywhere.
    """
    if size <= 0:
        return 0
    stream.seek(size - 1)
    if stream.read(1) != PADDING:
        return size
    end, block = size - 1, _PADDING_BLOCK
    while end > 0:
        start = max(0, end - block)
        stream.seek(start)
        kept = stream.read(end - start).rstrip(PADDING)
        if kept:
            return start + len(kept)
        end, block = start, min(2 * block, _PADDING_MAX_BLOCK)
    return 0


def check_padding(name, data: bytes, padded: bool) -> None:
    """Refuse (InputError naming the row) a last row cut short by the padding after ``data``.

    ``data`` are the bytes before the padding (their end suffices: the last
    row and what precedes it), ``padded`` whether any padding follows them.
    Only the row count of the message reads all of ``data``.
    """
    if padded and data and data[-1:] not in (b"\n", b"\r"):
        text = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
        row = text.count(b"\n") + 1
        raise InputError(f"{name}: row {row}: cut short by the NUL padding after it (no line "
                         f"end before the NULs: a logger stopped while writing it?); expected "
                         f"complete rows before the padding: delete row {row}")


def read_text(path, padded: bool = False) -> str:
    """The file's text (UTF-8, a byte-order mark dropped, newlines as ``\\n``).

    ``padded`` (a table's reader): the NUL padding after its rows is dropped,
    and a last row it cuts short refused (:func:`check_padding`).
    """
    name = os.fspath(path)
    data = read_bytes(path)
    if padded and data.endswith(PADDING):
        kept = data.rstrip(PADDING)
        check_padding(name, kept, True)
        data = kept
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(f"{name}: row {line}: expected UTF-8 text, got the byte "
                         f"{data[exc.start:exc.start + 1]!r}") from None
    return text.replace("\r\n", "\n").replace("\r", "\n")
