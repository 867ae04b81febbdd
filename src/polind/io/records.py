"""Instrument records as the instrument wrote them, read through a data description.

A record from a rig comes in the instrument's layout: its own column names,
a tab or a semicolon between fields, µN and mm, its own sign of friction, a
position that does not start at zero, unloaded samples at both ends.  A
*data description* (the user guide's :ref:`formats-data-description`) is a
small TOML file beside it that says how to read it, so that no conversion
code is written::

    [data]
    file = "run1.tsv"                 # relative to this file; CSV, TSV or Parquet
    delimiter = "\\t"                  # default: guessed from the header
    columns = { t = "Time [s]", x = "Position [mm]", F = "Friction [uN]", normal_load = "Normal [uN]" }
    units = { x = "mm", F = "uN", normal_load = "uN" }   # converted to SI on reading
    sign = { F = -1 }                 # the instrument's sign convention
    zero = ["x"]                      # subtract the first kept sample
    window = [0.5, 213.0]             # s: keep only these times

:func:`read_description` reads and checks one (:class:`DataDescription`);
:func:`read_record` reads the record it describes into SI units (or a plain
motion or data table, CSV or Parquet, as it is), which is what ``--data`` of
``polind fit`` and ``polind compare`` and ``--input`` of ``polind simulate``
take; :func:`is_description` tells the two apart by the name (``.toml``) and
:func:`record_files` names the files a record reads.  Units are converted
by the unit library pint (imported when a description names a unit).

Every mistake in a description raises :class:`~polind.errors.InputError`
naming the description and its key (``data.units.F``); a bad row of the
instrument's file names that file, its row and its column.
"""

from __future__ import annotations

import functools
import math
import os
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from polind.errors import InputError, describe
from polind.io.columns import check_values, is_parquet
from polind.io.documents import check_tables, read_document
from polind.io.tables import read_motion_csv, read_table_columns

__all__ = ["DESCRIPTION_KEYS", "RECORD_UNITS", "DataDescription", "is_description",
           "read_description", "read_record", "record_files", "si_factor"]

#: The keys of a ``[data]`` table.
DESCRIPTION_KEYS = ("file", "delimiter", "columns", "units", "sign", "zero", "window")

#: The columns of a record, each with the SI unit :func:`read_record` gives it in (a
#: ``units`` entry must have its dimension).
RECORD_UNITS = {"t": "s", "x": "m", "v": "m/s", "F": "N", "normal_load": "N"}

# A dimension in words, for a message (pint's form otherwise).
_DIMENSION_WORDS = {"s": "a time", "m": "a length", "m/s": "a velocity", "N": "a force"}
_UNIT_EXAMPLES = {"s": "s, ms, min", "m": "m, mm, um", "m/s": "m/s, mm/s, um/s",
                  "N": "N, mN, uN"}
_MOTION = ("x", "v")


def is_description(path) -> bool:
    """Whether ``path`` names a data description rather than a table: it ends in ``.toml``."""
    return os.fspath(path).lower().endswith(".toml")


@dataclass(frozen=True)
class DataDescription:
    """A checked data description, as :func:`read_description` returns it.

    Attributes
    ----------
    path : pathlib.Path
        The description file.
    file : pathlib.Path
        The instrument's file it describes (``file``, resolved against the
        description's folder).
    delimiter : str or None
        The field separator of a text file; None: guessed from its header.
    columns : dict of str to str
        The record's column (``t``, ``x`` or ``v``, ``F``, ``normal_load``)
        to the file's column name.
    units : dict of str to str
        The unit of a record's column in the file, as written (``"uN"``);
        a column without one is in SI already.
    scale : dict of str to float
        Each record column's factor to SI units times its ``sign`` (1.0 for
        a column without either).
    zero : tuple of str
        The columns whose first kept sample is subtracted.
    window : tuple of float or None
        ``(t0, t1)`` [s]: the times kept, both ends included; None: all.
    """

    path: Path
    file: Path
    delimiter: str | None
    columns: dict
    units: dict
    scale: dict
    zero: tuple
    window: tuple | None


@functools.lru_cache(maxsize=1)
def _unit_registry():
    import pint

    return pint.UnitRegistry()


def si_factor(unit: str, si: str) -> float:
    """The factor from ``unit`` to the SI unit ``si`` (pint), or an error without a key.

    Raises ``ValueError`` with what is wrong (not a unit, another dimension);
    :func:`read_description` names the key.

    Examples
    --------
    >>> si_factor("mm", "m"), si_factor("µN", "N")
    (0.001, 1e-06)
    """
    registry = _unit_registry()
    try:
        parsed = registry.Unit(unit)
    except Exception:                      # noqa: BLE001 - whatever pint refuses is no unit
        raise ValueError(f"{unit!r} is not a unit; expected {_DIMENSION_WORDS[si]} unit "
                         f"such as {_UNIT_EXAMPLES[si]}") from None
    target = registry.Unit(si)
    if parsed.dimensionality != target.dimensionality:
        found = next((words for symbol, words in _DIMENSION_WORDS.items()
                      if registry.Unit(symbol).dimensionality == parsed.dimensionality),
                     "of dimension " + str(parsed.dimensionality))
        raise ValueError(f"{unit!r} is {found}; expected {_DIMENSION_WORDS[si]} unit such as "
                         f"{_UNIT_EXAMPLES[si]}")
    return float(registry.Quantity(1.0, parsed).to(target).magnitude)


class _Keys:
    """The messages about one description's keys: each names the file and the key."""

    def __init__(self, name):
        self.name = name

    def error(self, key, what) -> InputError:
        return InputError(f"{self.name}: key 'data.{key}': {what}")

    def table(self, data, key, required=False) -> dict:
        value = data.get(key, None)
        if value is None:
            if required:
                raise InputError(f"{self.name}: no key 'data.{key}'; expected the table of "
                                 f"the record's columns, e.g. {{ t = \"Time [s]\", x = ... }}")
            return {}
        if not isinstance(value, dict):
            raise self.error(key, f"expected a table such as {{ F = ... }}, got {describe(value)}")
        return value

    def record_column(self, key, column, columns):
        if column not in columns:
            raise self.error(f"{key}.{column}", f"not a column of data.columns; expected one of "
                             f"{', '.join(columns)} (the record's names, not the file's)")


def read_description(path) -> DataDescription:
    """Read and check a data description (:ref:`formats-data-description`).

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file with a ``[data]`` table.

    Returns
    -------
    DataDescription
        Its keys, checked, with ``file`` resolved against the description's
        folder and every unit's factor to SI.

    Raises
    ------
    InputError
        Naming the description and the key: no ``[data]`` table, an unknown
        key, a ``file`` that is not a file name, a ``delimiter`` that is not
        one character, an unknown column, no ``t``, both or neither of
        ``x`` and ``v``, two columns read from one, a unit that is not a unit
        or has the wrong dimension (a force in mm), a sign other than +1 or
        -1, a ``zero`` of unknown columns, a ``window`` that is not two
        increasing times.  The file itself is read by :func:`read_record`.

    Examples
    --------
    >>> from polind import datasets
    >>> description = read_description(datasets.tribometer_description_path())
    >>> description.columns["F"], description.units["F"], description.scale["F"]
    ('Friction [uN]', 'uN', -1e-06)
    """
    name = os.fspath(path)
    document = read_document(path)
    check_tables(name, document, required=("data",), allowed=("data",))
    data = document["data"]
    keys = _Keys(name)
    for key in data:
        if key not in DESCRIPTION_KEYS:
            raise InputError(f"{name}: unknown key 'data.{key}'; expected one of: "
                             f"{', '.join(DESCRIPTION_KEYS)}")
    file = data.get("file")
    if not isinstance(file, str) or not file.strip():
        what = "missing" if file is None else f"got {describe(file)}"
        raise InputError(f"{name}: key 'data.file': {what}; expected the name of the "
                         f"instrument's file (CSV, TSV or Parquet), relative to this file")
    delimiter = data.get("delimiter")
    if delimiter is not None:
        if not isinstance(delimiter, str) or len(delimiter) != 1 or delimiter in "\"\r\n":
            raise keys.error("delimiter", f"expected one character such as \"\\t\", \",\" or "
                                          f"\";\", got {describe(delimiter)}")
        if is_parquet(file):
            raise keys.error("delimiter", "a Parquet file has no delimiter; leave it out")
    columns = keys.table(data, "columns", required=True)
    for key, column in columns.items():
        if key not in RECORD_UNITS:
            raise InputError(f"{name}: unknown key 'data.columns.{key}'; expected t, x or v, "
                             f"and optionally F, normal_load")
        if not isinstance(column, str) or not column.strip():
            raise keys.error(f"columns.{key}", f"expected the name of a column of the file, "
                                                f"got {describe(column)}")
    if "t" not in columns:
        raise keys.error("columns", "no 't'; expected the file's column of time")
    motion = [key for key in _MOTION if key in columns]
    if len(motion) != 1:
        if motion:
            raise InputError(f"{name}: keys 'data.columns.x' and 'data.columns.v': both given; "
                             f"expected exactly one (a position or a velocity)")
        raise keys.error("columns", "neither 'x' nor 'v'; expected exactly one (the file's "
                                    "column of position or of velocity)")
    seen = {}
    for key, column in columns.items():
        if column in seen:
            raise keys.error(f"columns.{key}", f"{column!r} is data.columns.{seen[column]} too; "
                                               f"expected a column of the file for each")
        seen[column] = key
    units = keys.table(data, "units")
    scale = {key: 1.0 for key in columns}
    for key, unit in units.items():
        keys.record_column("units", key, columns)
        if not isinstance(unit, str):
            raise keys.error(f"units.{key}", f"expected a unit such as "
                                             f"{_UNIT_EXAMPLES[RECORD_UNITS[key]]}, got "
                                             f"{describe(unit)}")
        try:
            scale[key] = si_factor(unit, RECORD_UNITS[key])
        except ValueError as exc:
            raise keys.error(f"units.{key}", str(exc)) from None
    for key, sign in keys.table(data, "sign").items():
        keys.record_column("sign", key, columns)
        if isinstance(sign, bool) or sign not in (1, -1):
            raise keys.error(f"sign.{key}", f"expected 1 or -1, got {describe(sign)}")
        if key == "t" and sign == -1:
            raise keys.error("sign.t", "time runs forward; expected 1 (or no sign for t)")
        scale[key] = -scale[key] if sign == -1 else scale[key]
    zero = data.get("zero", [])
    if not isinstance(zero, list) or not all(isinstance(key, str) for key in zero):
        raise keys.error("zero", f"expected a list of columns such as [\"x\"], got "
                                 f"{describe(zero)}")
    for key in zero:
        if key not in columns:
            raise keys.error("zero", f"{key!r} is not a column of data.columns; expected some "
                                     f"of {', '.join(columns)}")
        if zero.count(key) > 1:
            raise keys.error("zero", f"{key!r} is listed twice; expected each column once")
    window = data.get("window")
    if window is not None:
        if not (isinstance(window, list) and len(window) == 2
                and all(isinstance(end, (int, float)) and not isinstance(end, bool)
                        and math.isfinite(end) for end in window)
                and window[0] < window[1]):
            raise keys.error("window", f"expected two times [t0, t1] in s with t0 < t1, got "
                                       f"{describe(window)}")
        window = (float(window[0]), float(window[1]))
    return DataDescription(path=Path(path), file=Path(path).parent / file,
                           delimiter=delimiter, columns=dict(columns), units=dict(units),
                           scale=scale, zero=tuple(zero), window=window)


def _check_file(name, description) -> None:
    """Refuse (InputError naming the description and its key) a ``data.file`` that is no file."""
    file = description.file
    try:
        info = os.stat(file)
    except FileNotFoundError:
        problem = "no such file"
    except OSError as exc:
        problem = f"cannot read the file: {exc.strerror or exc}"
    else:
        problem = ("is a directory" if stat.S_ISDIR(info.st_mode) else
                   None if os.access(file, os.R_OK) else "cannot read the file: permission denied")
    if problem is not None:
        raise InputError(f"{name}: key 'data.file': {file}: {problem}; expected the "
                         f"instrument's file (CSV, TSV or Parquet), named relative to the "
                         f"folder of {name}")


def _conversion(description, key, zero=True) -> str:
    """The keys of a description that convert a record column, in words for a message."""
    words = [f"data.units.{key} = {description.units[key]!r}"] \
        if key in description.units else []
    if description.scale[key] < 0.0:
        words.append(f"data.sign.{key} = -1")
    if zero and key in description.zero:
        words.append("data.zero: less the first kept sample")
    return f"{'; '.join(words)} of {description.path}"


def _converted(description, key, raw, rows_of, zero=True) -> np.ndarray:
    """A record column in SI: ``raw`` times its factor and sign, less its first sample for a
    ``zero`` column (``zero`` True); an InputError naming the file, its column and the row of
    the first value that does not stay finite (``1e300`` in ``YN``)."""
    scale = description.scale[key]
    with np.errstate(over="ignore", invalid="ignore"):
        values = raw * scale if scale != 1.0 else raw.copy()
        if zero and key in description.zero:
            values = values - values[0]
    finite = np.isfinite(values)
    if finite.all():
        return values
    index = int(np.argmin(finite))
    raise InputError(f"{description.file}: row {rows_of([index])[0]}, column "
                     f"{description.columns[key]!r}: {float(raw[index])!r} is "
                     f"{float(values[index])!r} {RECORD_UNITS[key]} in SI units "
                     f"({_conversion(description, key, zero)}); expected a value that stays "
                     f"finite in SI units")


def _check_times(description, raw, t, rows_of, zero=False) -> None:
    """Refuse (InputError naming the file, column and row) times that increase in the file
    (``raw``) but not in SI (``t``, less its first sample when ``zero``): two times the
    conversion rounds to one."""
    same = np.flatnonzero(t[1:] <= t[:-1])
    if same.size:
        k = int(same[0]) + 1
        row, previous = rows_of([k, k - 1])
        raise InputError(f"{description.file}: row {row}, column {description.columns['t']!r}: "
                         f"{float(raw[k])!r} after {float(raw[k - 1])!r} on row {previous} is "
                         f"{float(t[k])!r} s after {float(t[k - 1])!r} s in SI units "
                         f"({_conversion(description, 't', zero)}); "
                         f"expected times that stay distinct in SI units")


def record_files(path) -> list[Path]:
    """The files a record reads: a table itself, or a description and the file it names.

    A command checks its outputs against these (an output never replaces an
    input) and sizes the last one before reading it.
    """
    if is_description(path):
        return [Path(path), read_description(path).file]
    return [Path(path)]


def read_record(path, require=("t",), one_of=_MOTION, optional=("F", "normal_load"), *,
                progress=None) -> dict[str, np.ndarray]:
    """Read a record in SI units: through a data description, or a table as it is.

    Parameters
    ----------
    path : str or os.PathLike
        A data description (a name ending in ``.toml``,
        :ref:`formats-data-description`), or a motion or data table (CSV or
        Parquet with the columns ``t``, ``x`` or ``v``, ``F``,
        ``normal_load``, in SI units; read by
        :func:`polind.io.read_motion_csv`).
    require, one_of, optional : sequence of str
        The columns the caller needs, needs one of, and takes when present
        (default: ``t``, one of ``x``/``v``, optionally ``F`` and
        ``normal_load``; a fit needs ``F`` too:
        ``read_record(path, **polind.io.MEASUREMENT_COLUMNS)``).  A column a
        description names and the caller does not take is not returned.
    progress : callable, optional
        ``progress(done, total)`` [bytes of the file], as the file is read.

    Returns
    -------
    dict of str to numpy.ndarray
        float64 arrays of one length: ``t`` [s] strictly increasing, ``x``
        [m] or ``v`` [m/s], and ``F`` [N], ``normal_load`` [N] (positive)
        when present; what :func:`polind.identify`, :func:`polind.compare`
        and :func:`polind.simulate` take.

    Raises
    ------
    InputError
        A mistake in the description, naming it and its key (see
        :func:`read_description`; and: a ``file`` that names no file, a
        column the caller requires that it does not name, a column missing
        from the file's header, a window outside the record or keeping fewer
        than two samples); a bad row of the file, naming the file, the row
        and the column (text where a number was expected, a time that does
        not increase; a non-finite value or a normal load that is not
        positive among the kept samples; a value that its conversion to SI
        makes infinite, such as ``1e300`` in ``YN``, or times that it makes
        equal).

    Notes
    -----
    In this order: the columns are read (quoted numbers, a byte-order mark,
    ``\\r\\n`` line ends, blank lines and the NUL padding of a
    preallocated file are read as ``polind.io.tables`` reads them),
    converted to SI (pint) and multiplied by their ``sign``, the samples
    whose times lie in ``window`` kept, and the first kept sample of each
    ``zero`` column subtracted; every value of the record is then finite.

    Examples
    --------
    >>> from polind import datasets
    >>> record = read_record(datasets.tribometer_description_path())
    >>> list(record), float(record["t"][0]), float(record["x"][0])
    (['t', 'x', 'F', 'normal_load'], 6.789, 0.0)
    """
    if not is_description(path):
        return read_motion_csv(path, require, one_of, optional, progress=progress)
    description = read_description(path)
    name, file = os.fspath(path), os.fspath(description.file)
    columns = description.columns
    for key in require:
        if key not in columns:
            raise InputError(f"{name}: key 'data.columns': no '{key}'; expected the file's "
                             f"column of {key} (needed here)")
    taken = (*require, *one_of, *optional)
    keys = [key for key in RECORD_UNITS if key in columns and key in taken]
    wanted = [columns[key] for key in keys]

    def select(_, row, header):
        for key, column in zip(keys, wanted):
            if header.count(column) != 1:
                where = "" if row is None else f" (row {row})"
                found = ("has no column" if column not in header else
                         f"has {header.count(column)} columns named")
                hint = ("" if len(header) > 1 else
                        " (one column: is data.delimiter the file's separator?)")
                raise InputError(f"{name}: key 'data.columns.{key}': {file}{where} {found} "
                                 f"{column!r}; its columns: "
                                 f"{', '.join(repr(text) for text in header)}{hint}")
        return wanted

    _check_file(name, description)
    table, rows_of = read_table_columns(
        file, select, ", ".join(repr(column) for column in wanted),
        delimiter=description.delimiter, min_rows=2, progress=progress)
    time_column = columns["t"]
    check_values(file, {time_column: table[time_column]}, rows_of, min_rows=2,
                 increasing=time_column, positive=())
    t = _converted(description, "t", table[time_column], rows_of, zero=False)
    _check_times(description, table[time_column], t, rows_of)
    first, end = 0, t.size
    if description.window is not None:
        low, high = description.window
        if low < t[0] or high > t[-1]:
            raise InputError(f"{name}: key 'data.window': [{low!r}, {high!r}] s reaches outside "
                             f"the record, which spans {float(t[0])!r} s to {float(t[-1])!r} s; expected "
                             f"times within it")
        first, end = int(np.searchsorted(t, low, "left")), int(np.searchsorted(t, high, "right"))
        if end - first < 2:
            raise InputError(f"{name}: key 'data.window': [{low!r}, {high!r}] s keeps "
                             f"{end - first} sample{'s' if end - first != 1 else ''}; expected "
                             f"at least 2")
    kept = {column: table[column][first:end] for column in wanted}

    def kept_rows(indices):
        return rows_of([first + int(k) for k in indices])

    check_values(file, kept, kept_rows, min_rows=2, increasing=None, positive=())
    record = {key: _converted(description, key, kept[column], kept_rows)
              for key, column in zip(keys, wanted)}
    if "t" in record and "t" in description.zero:
        _check_times(description, kept[time_column], record["t"], kept_rows, zero=True)
    load = record.get("normal_load")
    if load is not None and not (load > 0.0).all():
        index = int(np.argmax(~(load > 0.0)))
        raw = float(kept[columns["normal_load"]][index])
        raise InputError(f"{file}: row {rows_of([first + index])[0]}, column "
                         f"{columns['normal_load']!r}: expected a positive normal load, got "
                         f"{raw!r} (in SI with the sign of {name}: {float(load[index])!r} N)")
    return record
