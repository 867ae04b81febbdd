"""polind's files: model, system and motion files, and writes that are atomic.

The formats are those of the user guide's :ref:`formats-model-files`: model files (``[model]`` and an
optional ``[fit]``, TOML or JSON), one-degree-of-freedom system files
(``[system]``, :ref:`formats-system`), and CSV tables of samples with a header
row (``t`` and one of ``x``, ``v``; optionally ``normal_load``; ``F`` for
measured data), or Parquet tables with the same columns when the name ends
in ``.parquet``; and records as an instrument writes them, in its own columns
and units, read into SI units through a data description
(:ref:`formats-data-description`).  This package holds no physics: it reads,
checks the shape of what it read, and writes.  The models validate their own
parameters.

Big tables go at disk speed: pyarrow's C reader parses a CSV file of 1 MiB or
more (Python's row-by-row reader takes any file it refuses, and names the bad
row), and its writer formats a big table on every core.  Every float64 reads
back bit for bit.  A table is sized before it is read (:func:`table_size`) and
refused when reading it would pass the memory limit (:mod:`polind.resources`);
:func:`check_table_memory` adds what a command does with the rows.

Every problem with a file raises :class:`~polind.errors.InputError` with a
one-line message that starts with the file's path and names the row (its
line number in the file, the header being row 1), the column or the key, the
value received and what was expected.  Rows are numbered as lines of the
file, so that an editor's line number or a spreadsheet's row number points at
the offending row.

Every writer goes through one temporary file in the target's directory that
replaces the target only once the whole content is on disk: a failed run
leaves no output file, and an existing one untouched.  ``-`` writes to
standard output; an existing FIFO or device is written to directly, never
replaced; a symlink is followed (its target replaced, the link kept); and
:func:`check_output_path` refuses an output that is one of a command's
inputs.

The package, a module per idea (every name below is importable from
``polind.io``)::

    text          a text file as the readers take it (UTF-8, newlines)
    documents     model and system files (TOML/JSON): read, checked, written
    columns       the columns of a table of samples, and the rules on its values
    sizing        a table's rows before it is read; the memory check
    tables        reading tables: CSV (fast and careful readers) and Parquet
    records       an instrument's record through its data description, in SI units
    output        the one safe writer (atomic_open) and the output checks
    locking       one writer at a time for an output written over a long run
    table_output  writing tables: CSV to the bit, Parquet
"""

from polind.io.columns import MEASUREMENT_COLUMNS, MOTION_COLUMNS
from polind.io.documents import (
    check_tables,
    model_file_text,
    plain_data,
    read_document,
    read_model_file,
    read_system_file,
    save_model,
    write_model_file,
)
from polind.io.records import (
    DataDescription,
    is_description,
    read_description,
    read_record,
    record_files,
)
from polind.io.locking import lock_path, writer_lock
from polind.io.output import (
    STDOUT,
    atomic_open,
    atomic_write_bytes,
    atomic_write_text,
    check_output_path,
    write_together,
)
from polind.io.sizing import check_table_memory, table_size
from polind.io.table_output import number_text, write_csv_atomic, write_parquet_atomic
from polind.io.tables import (
    read_csv_columns,
    read_heights_csv,
    read_motion_csv,
    read_parquet_columns,
)

__all__ = [
    # documents: model and system files
    "check_tables",
    "model_file_text",
    "plain_data",
    "read_document",
    "read_model_file",
    "read_system_file",
    "save_model",
    "write_model_file",
    # columns and sizing: what a table holds, and what reading it costs
    "MEASUREMENT_COLUMNS",
    "MOTION_COLUMNS",
    "check_table_memory",
    "table_size",
    # records: an instrument's file through its data description
    "DataDescription",
    "is_description",
    "read_description",
    "read_record",
    "record_files",
    # tables: reading them
    "read_csv_columns",
    "read_heights_csv",
    "read_motion_csv",
    "read_parquet_columns",
    # output: the safe writer
    "STDOUT",
    "atomic_open",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_path",
    "write_together",
    # locking: one writer at a time
    "lock_path",
    "writer_lock",
    # table_output: writing tables
    "number_text",
    "write_csv_atomic",
    "write_parquet_atomic",
]
