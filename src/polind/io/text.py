"""A text file as polind's readers take it: UTF-8, newlines as ``\\n``.

Model, system and CSV files are text.  :func:`read_text` reads one whole,
drops a byte-order mark, turns ``\\r\\n`` and ``\\r`` into ``\\n`` (so that
rows are counted as an editor counts lines) and raises
:class:`~polind.errors.InputError` naming the file when it is missing, a
directory, unreadable or not UTF-8 (with the row of the first bad byte).
"""

from __future__ import annotations

import os
from pathlib import Path

from polind.errors import InputError

__all__ = ["read_bytes", "read_text"]


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


def read_text(path) -> str:
    """The file's text (UTF-8, a byte-order mark dropped, newlines as ``\\n``)."""
    name = os.fspath(path)
    data = read_bytes(path)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(f"{name}: row {line}: expected UTF-8 text, got the byte "
                         f"{data[exc.start:exc.start + 1]!r}") from None
    return text.replace("\r\n", "\n").replace("\r", "\n")
