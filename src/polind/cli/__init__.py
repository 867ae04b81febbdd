"""The ``polind`` command line (:ref:`cli`): parsing and printing only.

Each command is one small function registered on the :func:`cli` group; it
reads its files with :mod:`polind.io`, calls the library, and writes its
output with an atomic writer.  Commands never print errors or choose exit
statuses themselves: they raise, and :func:`main` turns what they raise into
the exit status of :ref:`cli-exit-status`:

- 0 success;
- 2 bad input (:class:`~polind.errors.InputError`, click usage errors), with
  exactly one line ``polind: error: <message>`` on standard error;
- 1 an internal error, one line ``polind: internal error: <type>: <message>``
  (and the traceback when the environment variable ``POLIND_DEBUG`` is set).

The modules, grouped by what the commands do:

- :mod:`polind.cli.common`: the group :func:`cli`, the options and the helpers
  the commands share;
- :mod:`polind.cli.runs`: ``simulate``, ``dynamics`` and ``sweep``;
- :mod:`polind.cli.fitting`: ``fit`` and ``compare``;
- :mod:`polind.cli.surfaces`: ``surface`` and ``topography``;
- :mod:`polind.cli.reports`: ``demo`` and ``bench``;
- :mod:`polind.cli.exports`: ``fmu``;
- :mod:`polind.cli.compiling`: ``precompile``;
- this package: :func:`main`, which runs the group and turns errors into exit
  statuses; importing it registers every command.

Adding a command (``demo``, ``dynamics``, ``fit``, ``surface``, ``bench``) is
one function in the module of its kind: decorate it with ``@cli.command()``,
take the model path with ``@model_argument`` and the output with
``@output_option`` (all from :mod:`polind.cli.common`), load the model with
:func:`load_model`, call :func:`check_output_path` on the output before any
long computation, show progress with :func:`progress`, and import the heavy
modules (numpy, the models, matplotlib) inside the function so that ``polind
--help`` stays fast.  A new command module is imported below.
"""

from __future__ import annotations

import errno
import os
import sys
import traceback
import warnings

import click

# The commands register on the group when their modules are imported.
from polind.cli import compiling, exports, fitting, reports, runs, surfaces  # noqa: F401
from polind.cli.common import PROGRAM, cli, progress
from polind.errors import InputError

__all__ = ["cli", "main", "progress"]


# --- the entry point ------------------------------------------------------------------------

def _one_line(text) -> str:
    return " ".join(str(text).split())


def _debugging() -> bool:
    return os.environ.get("POLIND_DEBUG", "") not in ("", "0")


def _report(kind: str, message: str) -> None:
    if _debugging():
        traceback.print_exc(file=sys.stderr)
    sys.stderr.write(f"{PROGRAM}: {kind}: {_one_line(message)}\n")
    sys.stderr.flush()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    _report("warning", str(message))


# The errors of a write to a full, failing or closed standard output.
_UNWRITABLE = {errno.ENOSPC, errno.EIO, errno.EPIPE, errno.EDQUOT, errno.EFBIG}


def _run(argv) -> int:
    """Run the command line; return the exit status."""
    try:
        with warnings.catch_warnings():
            # A library warning (a load signal a model ignores, ...) is one line on stderr.
            warnings.simplefilter("default")
            warnings.showwarning = _show_warning
            status = cli.main(args=argv, prog_name=PROGRAM, standalone_mode=False)
            sys.stdout.flush()
    except click.exceptions.NoArgsIsHelpError as exc:
        # A bare `polind` asks what it can do: the help, and success.
        click.echo(exc.format_message())
        return 0
    except click.ClickException as exc:
        _report("error", exc.format_message())
        return 2
    except InputError as exc:
        _report("error", str(exc))
        return 2
    except click.Abort:
        _report("error", "interrupted")
        return 130
    except OSError as exc:
        if exc.errno not in _UNWRITABLE:
            _report("internal error", f"{type(exc).__name__}: {exc}")
            return 1
        # What the command prints found standard output full or gone (its files are
        # written through polind.io, which names them): the user's device, not polind.
        _report("error", f"standard output: cannot write: {exc.strerror or exc}")
        return 2
    except Exception as exc:  # noqa: BLE001 - the last resort: exit 1 with one line
        _report("internal error", f"{type(exc).__name__}: {exc}")
        return 1
    finally:
        from polind.resources import set_memory_limit

        set_memory_limit(None)      # a --max-memory ends with its command
    # standalone_mode=False returns the exit code of --help/--version, else
    # the command's return value (None): commands do not choose statuses.
    return status if isinstance(status, int) else 0


def main(argv=None) -> None:
    """The ``polind`` console script: run the command line and exit with its status."""
    status = _run(argv)
    # Every output is written and closed by now.  Without this, the interpreter's last
    # garbage collections walk every object numba and SciPy created (0.2 to 0.4 s after
    # a simulate); frozen objects are skipped, and atexit handlers still run.
    import gc

    gc.freeze()
    sys.exit(status)
