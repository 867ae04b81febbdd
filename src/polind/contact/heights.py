"""Summit heights as the direct surface keeps them: sorted, merged, read from a file.

The part of :class:`polind.contact.surface.DirectSurface` that turns given
summit heights (with counts and radii of their own, or not) into the sorted
arrays every sum over the summits in contact runs on, and the reader of a
file of measured summit heights (:ref:`guide-pol-ind-summation`).
"""

from __future__ import annotations

import csv
import math
import os

import numpy as np

from polind.errors import InputError, describe

__all__ = ["sorted_heights", "summit_groups", "read_summit_heights"]


def _positive_array(values, name, shape) -> np.ndarray:
    """A float array of ``shape`` with every entry positive and finite, else InputError."""
    array = np.asarray(values, dtype=float)
    if array.shape != shape:
        raise InputError(
            f"The asperity '{name}' of pol-ind must match the heights, shape {shape}. "
            f"Got shape {array.shape}."
        )
    bad = np.flatnonzero(~(np.isfinite(array) & (array > 0.0)))
    if bad.size:
        raise InputError(
            f"The asperity '{name}' of pol-ind must be positive and finite. "
            f"Got {float(array[bad[0]])!r} at index {bad[0]}."
        )
    return array


def sorted_heights(heights, counts, radii=None, radius=1.0):
    """Validate, sort ascending and merge equal heights.

    Returns ``(heights, counts, weights, area_weights)``: ``weights`` are
    ``c_i sqrt(R_i / radius)`` and ``area_weights`` ``c_i R_i / radius``;
    without ``radii`` both are the ``counts`` array itself.
    """
    values = np.asarray(heights, dtype=float)
    if values.ndim != 1 or values.size == 0:
        raise InputError(
            f"The summit 'heights' of pol-ind must be a non-empty 1-D list of numbers. "
            f"Got shape {values.shape}."
        )
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError(
            f"The summit 'heights' of pol-ind must be finite. "
            f"Got {float(values[bad[0]])!r} at index {bad[0]}."
        )
    columns = []
    if counts is not None:
        columns.append(_positive_array(counts, "counts", values.shape))
    if radii is not None:
        ratio = _positive_array(radii, "radii", values.shape) / radius
        number = columns[0] if columns else np.ones_like(values)
        columns = [number, number * np.sqrt(ratio), number * ratio]
    if not columns:
        # All weights are 1: a plain sort is about twice as fast as argsort.
        values = np.sort(values)
        columns = [np.ones_like(values)]
    else:
        order = np.argsort(values, kind="stable")
        values = values[order]
        columns = [column[order] for column in columns]
    # Equal heights become one summit group: same interference; counts,
    # weights and areas add.
    starts = np.flatnonzero(np.concatenate(([True], values[1:] != values[:-1])))
    if starts.size != values.size:
        columns = [np.add.reduceat(column, starts) for column in columns]
        values = values[starts]
    columns = [np.ascontiguousarray(column) for column in columns]
    if len(columns) == 1:
        columns = columns * 3
    return (np.ascontiguousarray(values), *columns)


def summit_groups(heights, counts, radii, radius):
    """Summits sorted ascending by height, merged only where height *and* radius are equal.

    What elastic-plastic sums need (:ref:`guide-pol-ind-plasticity`): beyond
    yield a summit's load is no longer its Hertz weight times a law of the
    reference radius, so summits of different radii at one height stay apart.
    ``heights``, ``counts`` and ``radii`` are validated arrays of one length
    (``counts`` and ``radii`` positive); where every height is distinct the
    result is the arrays of :func:`sorted_heights` in the same order.

    Returns
    -------
    tuple of numpy.ndarray
        ``(heights, counts, weights, radii)`` with the Hertz weights
        ``weights = counts sqrt(radii / radius)``.
    """
    order = np.lexsort((radii, heights))
    heights, counts, radii = heights[order], counts[order], radii[order]
    starts = np.flatnonzero(np.concatenate(([True], (heights[1:] != heights[:-1])
                                            | (radii[1:] != radii[:-1]))))
    if starts.size != heights.size:
        counts = np.add.reduceat(counts, starts)
        heights, radii = heights[starts], radii[starts]
    weights = counts * np.sqrt(radii / radius)
    return tuple(np.ascontiguousarray(column) for column in (heights, counts, weights, radii))


def read_summit_heights(path) -> np.ndarray:
    """Read measured summit heights from a CSV file.

    The file has a header row naming a column ``h`` (other columns are
    ignored) and one summit per row, heights in metres measured from the
    reference plane of the separation.  Blank lines are skipped.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    numpy.ndarray
        The heights [m], in file order.

    Raises
    ------
    polind.InputError
        If the file cannot be read, has no ``h`` column or no rows, or a row
        holds something other than one finite number in that column; the
        message names the file and the line.
    """
    name = os.fspath(path)
    what = f"The heights file '{name}' of pol-ind"
    try:
        with open(name, newline="", encoding="utf-8-sig") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"{what} cannot be read: {error}.") from None
    lines = [(number, row) for number, row in enumerate(rows, start=1) if any(f.strip() for f in row)]
    if not lines:
        raise InputError(f"{what} is empty; expected a header 'h' and one summit height per row.")
    header_line, header = lines[0]
    names = [field.strip() for field in header]
    if "h" not in names:
        raise InputError(
            f"{what} must have a header naming a column 'h' (summit heights in metres). "
            f"Got header {describe(names)} on line {header_line}."
        )
    column = names.index("h")
    heights = np.empty(len(lines) - 1)
    for index, (line, row) in enumerate(lines[1:]):
        text = row[column].strip() if column < len(row) else ""
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or len(row) != len(header):
            raise InputError(
                f"{what} has a bad row {index + 1} (line {line}): {describe(','.join(row))}; "
                f"expected {len(header)} field(s) with a finite summit height in metres in column 'h'."
            )
        heights[index] = value
    if heights.size == 0:
        raise InputError(f"{what} has no data rows; expected one summit height per row.")
    return heights
