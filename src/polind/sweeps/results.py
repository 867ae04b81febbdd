"""The results table of a sweep: one row per run, written as runs finish, read back.

The table (Parquet or CSV) has the columns :attr:`polind.sweeps.Sweep.columns`:
``run`` (the run's index in the design), the parameter values, the metrics,
``status`` (``"ok"`` or the run's one-line error) and ``seconds``.
:class:`Results` holds a sweep's output: the rows already in the file (a
sweep started again on the same output computes only the runs that are
missing) and the rows added as runs finish.  :func:`read_results` reads a
table back, sorted by run.

A sweep owns its results table:

- one writer at a time: :class:`Results` holds the output's lock
  (:func:`polind.io.writer_lock`) from before it reads the file until the
  last row is written; a second sweep on the same output is refused;
- the record of what was run (:meth:`polind.sweeps.Sweep.record`: the
  fingerprint of the model, the system or motion and the metrics, and the
  SHA-256 of every file the runs read by name) is kept in the Parquet
  file's metadata, or beside a CSV file in ``.NAME.sweep.json``; a resume
  whose record differs is refused, naming a file whose contents changed;
- a file is checked to be this sweep's results table before anything is
  written to it: its header, its record, its column types and every row;
  a file that is not (another sweep's, a CSV of something else, a file
  that is not UTF-8 or not Parquet) is refused with an
  :class:`~polind.errors.InputError` naming what is wrong, and left as it
  was.  Only then is a row cut short by a killed sweep (a CSV's last line
  without its newline) dropped.
"""

from __future__ import annotations

import contextlib
import csv
import json
import math
import os
import threading
import time
from io import StringIO

from polind.errors import InputError, describe
from polind.io import atomic_open, atomic_write_text, number_text, writer_lock
from polind.io.text import read_bytes
from polind.sweeps.design import Sweep
from polind.sweeps.runs import one_line

__all__ = ["Results", "read_results", "record_path"]

# A finished row waits at most this long before a rewrite of a Parquet output starts
# [s] (the table's rewrite then takes its time), unless the table is so long that
# its rewrites would take more than a tenth of the time: then up to ten times the
# last rewrite, as long as the wait and the rewrite together stay within
# _MOST_SECONDS_LOST, what a kill -9 may lose.
_FLUSH_SECONDS = 1.0
_MOST_SECONDS_LOST = 2.0

# The key of the sweep's metadata in a Parquet output (the name of the module that first
# wrote it, kept so that the outputs of earlier sweeps are still found).
_METADATA_KEY = b"polind.sweep"


def record_path(path) -> str:
    """Where a CSV results table keeps its record: ``.NAME.sweep.json`` beside it."""
    folder, base = os.path.split(os.path.realpath(os.fspath(path)))
    return os.path.join(folder, f".{base}.sweep.json")


def _csv_lines(name, data: bytes) -> tuple[list[str], int]:
    """The complete lines of a CSV file's bytes, and where its complete lines end.

    A last line without its newline (a row cut short by a killed sweep) is
    not among them.  Bytes that are not UTF-8 are an InputError naming the row.
    """
    end = data.rfind(b"\n") + 1
    try:
        text = data[:end].decode("utf-8")
    except UnicodeDecodeError as error:
        row = data[:error.start].count(b"\n") + 1
        raise InputError(f"{name}: row {row}: expected UTF-8 text, got the byte "
                         f"{data[error.start:error.start + 1]!r}; not a sweep's results "
                         f"table") from None
    return text.splitlines(), end


class Results:
    """The output table of a sweep: the rows already there, and the rows added as runs finish.

    Used as a context manager: entering it takes the output's lock and reads
    and checks what the file holds (refusing a file that is not this
    sweep's, before anything is written); leaving it writes the rows not yet
    written and lets go of the lock.  CSV rows are appended to the file as
    they come (a row per line, in the order runs finish).  A Parquet file is
    rewritten whole, atomically, by a thread of its own, about a second after
    a row was added (whether or not more rows come; see ``_wait``), and at
    the end, its rows sorted by run, with the sweep's record in its metadata:
    a ``kill -9`` loses the rows of the last two seconds at most.
    """

    def __init__(self, path, plan: Sweep, design: list[tuple]):
        self.path = os.fspath(path)
        self.plan = plan
        self.design = design
        self.columns = plan.columns
        self.parquet = self.path.lower().endswith(".parquet")
        self.rows: dict[int, dict] = {}
        self.pending: list[dict] = []
        self.first_pending = None       # when the oldest row not yet written was added
        self.flush_costs = [0.0]        # of the last rewrites [s] (none yet: no wait longer)
        self.written = 0                # rows in the Parquet file (those read, then written)
        self.record = None
        self.cut = None                 # where a CSV's complete lines end, if a row was cut
        self._held = None
        # The rows, between the sweep and the Parquet writer's thread (held briefly), and
        # the file (held for a write: one at a time).
        self._lock = threading.Condition(threading.RLock())
        self._writing = threading.Lock()
        self._writer = None
        self._closing = False
        self._failure = None            # what the writer's thread met, raised by add()

    def __enter__(self) -> "Results":
        held = contextlib.ExitStack()
        held.enter_context(writer_lock(self.path, "another sweep"))
        try:
            self.record = self.plan.record()
            if self.parquet:
                # Now, not in the first rewrite (the rows would wait for it): pyarrow, and
                # pandas, which pyarrow imports (when installed) at its first array.
                import pyarrow as pa
                import pyarrow.parquet  # noqa: F401

                pa.array([0.0])
            if os.path.exists(self.path):
                self._read(self.design)
            if self.parquet:
                self._writer = threading.Thread(target=self._write_in_time, daemon=True,
                                                name="polind-sweep-writer")
                self._writer.start()
        except BaseException:
            self._stop_writer()
            held.close()
            raise
        self._held = held
        return self

    def __exit__(self, *exc_info):
        try:
            self._stop_writer()
            self.flush()
        finally:
            self._held.close()
            self._held = None

    def _stop_writer(self):
        """End the Parquet writer's thread (after the rewrite it may be doing)."""
        if self._writer is None:
            return
        with self._lock:
            self._closing = True
            self._lock.notify_all()
        self._writer.join()
        self._writer = None

    def _wait(self) -> float:
        """How long the oldest unwritten row may wait for its rewrite to start [s].

        A second, or longer for a table whose last three rewrites all took over
        a tenth of that (a long table): ten times the quickest of them, but no
        more than leaves that rewrite within ``_MOST_SECONDS_LOST`` in all.
        """
        cost = min(self.flush_costs)
        return max(_FLUSH_SECONDS, min(10.0 * cost, _MOST_SECONDS_LOST - cost))

    def _write_in_time(self):
        """The Parquet writer's thread: each added row is written within ``_wait``."""
        while True:
            with self._lock:
                if self._closing:
                    return
                if self.first_pending is None:
                    self._lock.wait()
                    continue
                left = self.first_pending + self._wait() - time.monotonic()
                if left > 0.0:
                    self._lock.wait(left)
                    continue
            try:
                self.flush()
            except BaseException as error:  # noqa: BLE001 - the sweep raises it
                with self._lock:
                    self._failure = error
                return

    def check_writable(self) -> None:
        """Refuse (InputError) an existing table that cannot take the rows to come.

        A table made read-only (no write permission for anyone) is refused
        even where the user could write it all the same (root).
        """
        if os.path.exists(self.path) and (not os.access(self.path, os.W_OK)
                                          or not os.stat(self.path).st_mode & 0o222):
            raise InputError(f"{self.path}: the results table is read-only; a sweep adds its "
                             f"rows to it: expected a file it may write, or another --output")

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

    def _check_record(self, record):
        """The record of the sweep that made the file must be this sweep's."""
        if not isinstance(record, dict):
            raise self._refuse(f"its record of the sweep that made it is "
                               f"{describe(record)}, not a table of what was run")
        if record.get("fingerprint") == self.record["fingerprint"]:
            return
        files = record.get("files")
        if isinstance(files, dict):
            for name, digest in self.record["files"].items():
                if name in files and files[name] != digest:
                    raise self._refuse(f"{name} changed since its rows were computed (its "
                                       f"contents are not those the runs read)")
        raise self._refuse(f"it was made from another model, system, motion or metric list "
                           f"than {self.plan.name}")

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
        for _, row in rows:
            self.rows.setdefault(row["run"], row)
        self.written = len(self.rows)

    def _read_parquet(self):
        import pyarrow as pa
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
        held = {"int": pa.types.is_integer, "str": pa.types.is_string,
                "float": lambda kind: pa.types.is_floating(kind) or pa.types.is_integer(kind)}
        for key, kind in self._kinds().items():
            column = table.column(key)
            if not held[kind](column.type):
                raise self._refuse(f"its column '{key}' holds values of type {column.type}; "
                                   f"expected {'words' if kind == 'str' else kind + 's'}")
            if column.null_count:
                raise self._refuse(f"its column '{key}' has missing values (null)")
        metadata = (table.schema.metadata or {}).get(_METADATA_KEY)
        if metadata is None:
            raise self._refuse("it holds no record of the sweep that made it (the Parquet "
                               "metadata 'polind.sweep')")
        try:
            record = json.loads(metadata)
        except (ValueError, RecursionError):
            raise self._refuse("its record of the sweep that made it (the Parquet metadata "
                               "'polind.sweep') is not JSON") from None
        self._check_record(record)
        columns = table.to_pydict()
        return [(number + 1, {key: columns[key][number] for key in self.columns})
                for number in range(table.num_rows)]

    def _read_csv(self):
        kinds = self._kinds()
        data = read_bytes(self.path, "a sweep's results table")
        if not data:
            return []                   # nothing there to lose: the table starts here
        lines, end = _csv_lines(self.path, data)
        if not lines:
            raise self._refuse("it holds no header row of a results table (a first line "
                               "without its newline)")
        header = next(csv.reader(lines[:1]))
        if header != self.columns:
            raise self._refuse(f"its columns ({', '.join(header)}) are not those of "
                               f"{self.plan.name} ({', '.join(self.columns)})")
        self._check_record(self._csv_record())
        rows = []
        for number, fields in enumerate(csv.reader(lines[1:]), start=2):
            if len(fields) != len(header):
                raise self._refuse(f"row {number} has {len(fields)} fields, not {len(header)}")
            row = {}
            try:
                for key, text in zip(header, fields):
                    kind = kinds[key]
                    row[key] = int(text) if kind == "int" else float(text) \
                        if kind == "float" else text
            except ValueError:
                raise self._refuse(f"row {number}, column '{key}': {describe(text)} is not a "
                                   f"{kinds[key]} number") from None
            rows.append((number, row))
        if end < len(data):
            self.cut = end              # dropped before the first row is appended
        return rows

    def _csv_record(self):
        name = record_path(self.path)
        try:
            with open(name, encoding="utf-8") as stream:
                text = stream.read()
        except FileNotFoundError:
            raise self._refuse(f"it holds no record of the sweep that made it ({name} is "
                               f"missing)") from None
        except (OSError, UnicodeDecodeError) as error:
            raise self._refuse(f"its record {name} cannot be read ({one_line(error)})") \
                from None
        try:
            return json.loads(text)
        except (ValueError, RecursionError):
            raise self._refuse(f"its record {name} is not JSON") from None

    # -- writing

    def add(self, row: dict) -> None:
        """Add a finished run's row: appended to a CSV now, to a Parquet file within a second."""
        with self._lock:
            if self._failure is not None:
                failure, self._failure = self._failure, None
                raise failure
            self.pending.append(row)
            self.rows[row["run"]] = row
            if self.first_pending is None:
                self.first_pending = time.monotonic()
                self._lock.notify_all()
        if not self.parquet:
            self.flush()

    def flush(self) -> None:
        """Put every added row in the file.

        The rows are taken under the lock and written outside it, so that the
        sweep adds rows while a long table is rewritten; a write that fails
        (or is interrupted) puts them back, to be written by the next one.
        """
        with self._writing:
            with self._lock:
                # A Parquet file holds every row: it is behind until it holds as many.
                if not self.pending and not (self.parquet and self.written < len(self.rows)):
                    return
                pending, first = self.pending, self.first_pending
                self.pending, self.first_pending = [], None
                rows = {**self.rows, **{row["run"]: row for row in pending}} \
                    if self.parquet else None
            started = time.monotonic()
            try:
                if self.parquet:
                    self._write_parquet(rows)
                else:
                    self._append_csv(pending)
            except BaseException:
                with self._lock:
                    self.pending = pending + self.pending
                    self.first_pending = first
                raise
            self.flush_costs = [*self.flush_costs[-2:], time.monotonic() - started]
            if self.parquet:
                self.written = len(rows)

    def _append_csv(self, pending):
        buffer = StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        new = not os.path.exists(self.path) or os.path.getsize(self.path) == 0
        if new:
            writer.writerow(self.columns)
        for row in pending:
            writer.writerow([number_text(row[key]) if isinstance(row[key], float)
                             else str(row[key]) for key in self.columns])
        if new:
            # The record first: a table is never without it.
            atomic_write_text(record_path(self.path), json.dumps(self.record) + "\n")
            atomic_write_text(self.path, buffer.getvalue())
            return
        try:
            if self.cut is not None:
                # A row cut short by a killed sweep: it was never a finished row.
                with open(self.path, "r+b") as stream:
                    stream.truncate(self.cut)
                self.cut = None
            with open(self.path, "a", encoding="utf-8", newline="\n") as stream:
                stream.write(buffer.getvalue())
        except OSError as error:
            raise InputError(f"{self.path}: cannot write: {error.strerror or error}") from None

    def _write_parquet(self, rows):
        import pyarrow as pa
        import pyarrow.parquet as pq

        types_of = {"int": pa.int64(), "float": pa.float64(), "str": pa.string()}
        kinds = self._kinds()
        metadata = {_METADATA_KEY: json.dumps(self.record).encode()}
        schema = pa.schema([(key, types_of[kinds[key]]) for key in self.columns],
                           metadata=metadata)
        ordered = [rows[index] for index in sorted(rows)]
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

    Rows of the same run found twice are kept once, the first; a CSV's last
    row cut short (a killed sweep) is left out.  From a CSV, every column but
    ``run`` and the words (``status``, word parameters) is read as floats.

    Raises
    ------
    InputError
        Naming the file: missing or unreadable, not UTF-8 or not Parquet, or
        not a sweep's results table (no ``run`` column of whole numbers).
    """
    name = os.fspath(path)
    if name.lower().endswith(".parquet"):
        columns = _parquet_columns(name)
    else:
        lines, _ = _csv_lines(name, read_bytes(name, "a sweep's results table"))
        reader = csv.reader(lines)
        header = next(reader, [])
        columns = {key: [] for key in header}
        for number, fields in enumerate(reader, start=2):
            if len(fields) != len(header):
                raise InputError(f"{name}: row {number} has {len(fields)} fields, not "
                                 f"{len(header)} as its header; expected a sweep's results "
                                 f"table")
            for key, text in zip(header, fields):
                columns[key].append(text)
        for key, values in columns.items():
            if key not in ("run", "status"):
                with contextlib.suppress(ValueError):
                    columns[key] = [float(value) for value in values]
    runs = columns.get("run")
    if runs is None:
        raise InputError(f"{name}: has no 'run' column; expected a sweep's results table")
    indices = []
    for value in runs:
        try:
            indices.append(_run_index(value))
        except (TypeError, ValueError):
            raise InputError(f"{name}: its 'run' column holds {describe(value)}; expected "
                             f"whole numbers (a sweep's results table)") from None
    columns["run"] = indices
    first = {}
    for position, index in enumerate(columns["run"]):
        first.setdefault(index, position)
    order = [first[index] for index in sorted(first)]
    return {key: [values[position] for position in order] for key, values in columns.items()}


def _run_index(value) -> int:
    """A run's index from a table cell (an int, or its text); ValueError for anything else."""
    if isinstance(value, bool) or not isinstance(value, (int, str)):
        raise ValueError(value)
    return int(value)


def _parquet_columns(name) -> dict:
    """The columns of a Parquet file as lists; an InputError naming it if it is not one."""
    import pyarrow.parquet as pq

    if not os.path.exists(name):
        raise InputError(f"{name}: no such file; expected a sweep's results table")
    try:
        return pq.read_table(name).to_pydict()
    except Exception as error:  # noqa: BLE001 - any unreadable file is refused the same way
        raise InputError(f"{name}: cannot be read as Parquet ({one_line(error)}); expected a "
                         f"sweep's results table") from None
