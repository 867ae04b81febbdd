"""The results table of a sweep: one row per run, written as runs finish, read back.

The table (Parquet or CSV) has the columns :attr:`polind.sweeps.Sweep.columns`:
``run`` (the run's index in the design), the parameter values, the metrics,
``status`` (``"ok"`` or the run's one-line error) and ``seconds``.
:class:`Results` holds a sweep's output: the rows already in the file (a
sweep started again on the same output computes only the runs that are
missing, and refuses an output made by another sweep) and the rows added as
runs finish.  :func:`read_results` reads a table back, sorted by run.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import time
from io import StringIO

from polind.errors import InputError
from polind.io import atomic_open, atomic_write_text, number_text
from polind.sweeps.design import Sweep
from polind.sweeps.runs import one_line

__all__ = ["Results", "read_results"]

# Between two rewrites of a Parquet output at least this long, and ten times as
# long as the last rewrite took (a long table is rewritten less often).
_FLUSH_SECONDS = 1.0

# The key of the sweep's metadata in a Parquet output (the name of the module that first
# wrote it, kept so that the outputs of earlier sweeps are still found).
_METADATA_KEY = b"polind.sweep"


class Results:
    """The output table of a sweep: the rows already there, and the rows added as runs finish.

    CSV rows are appended to the file as they come (a row per line, in the
    order runs finish).  A Parquet file is rewritten whole, atomically, at
    most every ``_FLUSH_SECONDS`` and at the end, its rows sorted by run;
    its metadata records the sweep's :meth:`~polind.sweeps.Sweep.fingerprint`.
    """

    def __init__(self, path, plan: Sweep, design: list[tuple]):
        self.path = os.fspath(path)
        self.plan = plan
        self.columns = plan.columns
        self.parquet = self.path.lower().endswith(".parquet")
        self.rows: dict[int, dict] = {}
        self.pending: list[dict] = []
        self.last_flush = time.monotonic()
        self.flush_cost = 0.0
        if os.path.exists(self.path):
            self._read(design)

    # -- types of the columns

    def _kinds(self) -> dict:
        kinds = {"run": "int", "status": "str", "seconds": "float"}
        kinds.update({axis.key: ("str" if axis.kind == "path" else axis.kind)
                      for axis in self.plan.axes})
        kinds.update({metric.name: "float" for metric in self.plan.metrics})
        return kinds

    # -- reading what is there

    def _refuse(self, message: str) -> InputError:
        return InputError(f"{self.path}: {message}; the output of another sweep is never mixed "
                          f"with this one's: give another --output, or remove the file to "
                          f"start again")

    def _read(self, design):
        rows = self._read_parquet() if self.parquet else self._read_csv()
        runs = len(design)
        # In run order (a file holds its rows in the order runs finished), so that a
        # mismatch names the same run whatever the engine and its timing were.
        rows.sort(key=lambda numbered: (numbered[1]["run"], numbered[0]))
        for number, row in rows:
            index = row["run"]
            if not 0 <= index < runs:
                raise self._refuse(f"row {number} is run {index}, which {self.plan.name} "
                                   f"does not have ({runs} runs)")
            for key, want in zip(self.plan.keys, design[index]):
                got = row[key]
                same = (math.isclose(got, want, rel_tol=1e-12, abs_tol=0.0)
                        if isinstance(want, float) else got == want)
                if not same:
                    raise self._refuse(f"row {number} (run {index}) has {key} = {got!r} where "
                                       f"{self.plan.name} gives {want!r}")
            self.rows.setdefault(index, row)

    def _read_parquet(self):
        import pyarrow.parquet as pq

        try:
            table = pq.read_table(self.path)
        except Exception as error:  # noqa: BLE001 - any unreadable file is refused the same way
            raise InputError(f"{self.path}: cannot read the existing output ({one_line(error)}); "
                             f"expected the Parquet table of an earlier run of this sweep") \
                from None
        if table.column_names != self.columns:
            raise self._refuse(f"its columns ({', '.join(table.column_names)}) are not those of "
                               f"{self.plan.name} ({', '.join(self.columns)})")
        metadata = json.loads((table.schema.metadata or {}).get(_METADATA_KEY, b"{}"))
        if metadata.get("fingerprint") != self.plan.fingerprint():
            raise self._refuse(f"it was made from another model, system, motion or metric list "
                               f"than {self.plan.name}")
        columns = table.to_pydict()
        return [(number + 1, {key: columns[key][number] for key in self.columns})
                for number in range(table.num_rows)]

    def _read_csv(self):
        kinds = self._kinds()
        with open(self.path, "rb") as stream:
            data = stream.read()
        if data and not data.endswith(b"\n"):
            # A row cut short by a killed process: it was never a finished row.
            cut = data.rfind(b"\n") + 1
            data = data[:cut]
            with open(self.path, "r+b") as stream:
                stream.truncate(cut)
        if not data:
            return []
        lines = data.decode("utf-8").splitlines()
        reader = csv.reader(lines)
        header = next(reader)
        if header != self.columns:
            raise self._refuse(f"its columns ({', '.join(header)}) are not those of "
                               f"{self.plan.name} ({', '.join(self.columns)})")
        rows = []
        for number, fields in enumerate(reader, start=2):
            if len(fields) != len(header):
                raise self._refuse(f"row {number} has {len(fields)} fields, not {len(header)}")
            row = {}
            try:
                for key, text in zip(header, fields):
                    kind = kinds[key]
                    row[key] = int(text) if kind == "int" else float(text) \
                        if kind == "float" else text
            except ValueError:
                raise self._refuse(f"row {number}, column '{key}': {text!r} is not a "
                                   f"{kinds[key]} number") from None
            rows.append((number, row))
        return rows

    # -- writing

    def add(self, row: dict) -> None:
        self.rows[row["run"]] = row
        self.pending.append(row)
        if not self.parquet:
            self.flush()
        elif time.monotonic() - self.last_flush >= max(_FLUSH_SECONDS, 10.0 * self.flush_cost):
            self.flush()

    def flush(self) -> None:
        """Put every added row in the file."""
        if not self.pending:
            return
        started = time.monotonic()
        if self.parquet:
            self._write_parquet()
        else:
            self._append_csv()
        self.pending = []
        self.last_flush = time.monotonic()
        self.flush_cost = self.last_flush - started

    def _append_csv(self):
        buffer = StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        new = not os.path.exists(self.path) or os.path.getsize(self.path) == 0
        if new:
            writer.writerow(self.columns)
        for row in self.pending:
            writer.writerow([number_text(row[key]) if isinstance(row[key], float)
                             else str(row[key]) for key in self.columns])
        if new:
            atomic_write_text(self.path, buffer.getvalue())
            return
        try:
            with open(self.path, "a", encoding="utf-8", newline="\n") as stream:
                stream.write(buffer.getvalue())
        except OSError as error:
            raise InputError(f"{self.path}: cannot write: {error.strerror or error}") from None

    def _write_parquet(self):
        import pyarrow as pa
        import pyarrow.parquet as pq

        types_of = {"int": pa.int64(), "float": pa.float64(), "str": pa.string()}
        kinds = self._kinds()
        metadata = {_METADATA_KEY: json.dumps({
            "fingerprint": self.plan.fingerprint(), "sweep": self.plan.name,
            "runs": self.plan.runs}).encode()}
        schema = pa.schema([(key, types_of[kinds[key]]) for key in self.columns],
                           metadata=metadata)
        ordered = [self.rows[index] for index in sorted(self.rows)]
        table = pa.table({key: [row[key] for row in ordered] for key in self.columns},
                         schema=schema)
        with atomic_open(self.path, binary=True) as stream:
            pq.write_table(table, stream)

    def table(self) -> dict:
        """Every row (those found and those added), sorted by run: column name to list."""
        ordered = [self.rows[index] for index in sorted(self.rows)]
        return {key: [row[key] for row in ordered] for key in self.columns}


def read_results(path) -> dict:
    """A sweep's results table, its rows sorted by run: column name to list.

    Rows of the same run found twice (two sweeps written to one output at
    once) are kept once, the first.  From a CSV, every column but ``run``
    and the words (``status``, word parameters) is read as floats.
    """
    name = os.fspath(path)
    if name.lower().endswith(".parquet"):
        import pyarrow.parquet as pq

        columns = pq.read_table(name).to_pydict()
    else:
        with open(name, newline="", encoding="utf-8") as stream:
            lines = stream.read()
        if not lines.endswith("\n"):
            lines = lines[:lines.rfind("\n") + 1]
        reader = csv.reader(lines.splitlines())
        header = next(reader, ["run"])
        columns = {key: [] for key in header}
        for fields in reader:
            for key, text in zip(header, fields):
                columns[key].append(text)
        for key, values in columns.items():
            if key == "run":
                columns[key] = [int(value) for value in values]
            elif key != "status":
                with contextlib.suppress(ValueError):
                    columns[key] = [float(value) for value in values]
    first = {}
    for position, index in enumerate(columns["run"]):
        first.setdefault(index, position)
    order = [first[index] for index in sorted(first)]
    return {key: [values[position] for position in order] for key, values in columns.items()}
