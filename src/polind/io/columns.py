"""What a table of samples holds, whatever its format: its columns and the rules on them.

A motion file (:data:`MOTION_COLUMNS`) or a measured-data file
(:data:`MEASUREMENT_COLUMNS`) is a CSV table with a header row, or a Parquet
table when its name ends in ``.parquet`` (:func:`is_parquet`).  Both formats
obey the same rules, checked here once for every reader: the header names
each allowed column once, with the required ones and exactly one of a choice
(:func:`check_header`); the values are finite, positive where they must be,
enough and increasing where they must be (:func:`check_values`).  Every
broken rule raises :class:`~polind.errors.InputError` naming the file, the
row and the column.
"""

from __future__ import annotations

import os

import numpy as np

from polind.errors import InputError

__all__ = ["MEASUREMENT_COLUMNS", "MOTION_COLUMNS", "check_header", "check_values",
           "expected_columns", "is_parquet"]


#: Columns of a prescribed motion (``polind simulate --input``).
MOTION_COLUMNS = {"require": ("t",), "one_of": ("x", "v"), "optional": ("normal_load",)}
#: Columns of measured data (``polind fit --data``).
MEASUREMENT_COLUMNS = {"require": ("t", "F"), "one_of": ("x", "v"), "optional": ("normal_load",)}


def is_parquet(path) -> bool:
    """Whether a motion, data or result file is Parquet: its name ends in ``.parquet``."""
    return os.fspath(path).lower().endswith(".parquet")


def expected_columns(require, one_of, optional) -> str:
    """The columns a table may have, in words for a message (``t, one of x or v, ...``)."""
    parts = list(require)
    if one_of:
        parts.append("one of " + " or ".join(one_of))
    if optional:
        parts.append("optionally " + " or ".join(optional))
    return ", ".join(parts)


def check_header(name, row, columns, require, one_of, optional):
    """The columns of a table: named, each once, all allowed, the required ones present.

    ``row`` is the header's line number in a CSV file; None for a Parquet file
    (its columns are named in its schema, not on a row).
    """
    where = f"{name}: row {row}: " if row is not None else f"{name}: "
    allowed = (*require, *one_of, *optional)
    expected = expected_columns(require, one_of, optional)
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


def check_values(name, table, rows_of, *, min_rows, increasing, positive):
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
