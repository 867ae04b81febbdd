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
  (and the traceback when the environment variable ``POLIND_DEBUG`` is set);
- 130 interrupted: SIGINT (Ctrl-C), SIGTERM or SIGHUP, at any moment of the
  run (:class:`Interrupted`), with no output and no temporary file left.

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
import signal
import sys
import threading
import time
import traceback
import warnings

__all__ = ["Interrupted", "check_interrupted", "cli", "commit_begins", "main", "progress"]


# --- the signals of a terminal --------------------------------------------------------------
# Set up before anything else is imported, so that a signal during the imports ends the
# run as cleanly as one during a command: every signal a terminal sends (Ctrl-C's SIGINT,
# SIGTERM, the SIGHUP of a closed terminal) ends it with status 130 and no output.

#: The signals that end a run (those the platform has).
SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                if hasattr(signal, name))


class Interrupted(KeyboardInterrupt):
    """A terminal's signal ended the run: a ``KeyboardInterrupt``, whichever signal it was,
    so that every ``except KeyboardInterrupt`` of polind (a sweep's, click's) handles it."""

    def __init__(self, number):
        super().__init__(number)
        self.number = number


class _Signals:
    """What :func:`_on_signal` does, by the phase of the run, and what it has seen.

    ``phase``: "starting" (the program's modules are being imported: a signal is
    only noted, :func:`main` stops at its first line), "running" (a signal raises
    :class:`Interrupted` where the program is), "committing" (the output is
    complete and being put in place: a signal is too late to undo it and waits
    for the exit, whose status is the command's).  ``received``: the first signal
    of the run before its commit (a signal whose exception a library swallowed is
    still here: :func:`check_interrupted` raises it again); ``raised``: when
    :class:`Interrupted` was last raised (a second signal within a second does not
    break the clean-up of the first).
    """

    phase = "running"
    received = None
    raised = -1e300
    #: The handlers replaced (to put back after an in-process :func:`main`), None: none.
    replaced = None
    #: The ``sys.unraisablehook`` replaced with them.
    unraisable = None


def _on_signal(number, frame):
    if _Signals.phase == "committing":
        return
    if _Signals.received is None:
        _Signals.received = number
    if _Signals.phase == "starting":
        return
    now = time.monotonic()
    if now - _Signals.raised < 1.0:
        return
    _Signals.raised = now
    raise Interrupted(number)


def _handle_signals() -> None:
    """Take the terminal's signals with :func:`_on_signal` (the main thread only, once).

    A signal the process was started ignoring (``nohup``'s SIGHUP, a background
    job's SIGINT) stays ignored: whoever started it asked for that.
    """
    if _Signals.replaced is not None or threading.current_thread() is not threading.main_thread():
        return
    _Signals.replaced = {number: signal.getsignal(number) for number in SIGNALS}
    for number, handler in _Signals.replaced.items():
        if handler is not signal.SIG_IGN:
            signal.signal(number, _on_signal)
    _Signals.unraisable = sys.unraisablehook
    sys.unraisablehook = _on_unraisable


def _on_unraisable(unraisable) -> None:
    """Drop an :class:`Interrupted` raised where Python cannot raise it (a ctypes callback
    of numba's compiler prints it as "Exception ignored ... Traceback"): the signal is in
    ``_Signals.received``, and :func:`check_interrupted` raises it again; pass anything
    else to the hook it replaced."""
    if isinstance(unraisable.exc_value, Interrupted):
        return
    (_Signals.unraisable or sys.__unraisablehook__)(unraisable)


def _restore_signals() -> None:
    """Put back the handlers :func:`_handle_signals` replaced (a :func:`main` called from
    Python, whose process goes on)."""
    for number, handler in (_Signals.replaced or {}).items():
        signal.signal(number, signal.SIG_DFL if handler is None else handler)
    if _Signals.replaced is not None:
        sys.unraisablehook = _Signals.unraisable or sys.__unraisablehook__
    _Signals.replaced = None


def _started_as_the_program() -> bool:
    """Whether this process is the ``polind`` program (its script or ``python -m polind``),
    not a Python session or a test that imports the package."""
    started = sys.modules.get("__main__")
    spec = getattr(started, "__spec__", None)
    if spec is not None:
        return spec.name in ("polind.__main__", "polind.cli.__main__")
    script = os.path.basename(getattr(started, "__file__", None) or "")
    return os.path.splitext(script)[0].removesuffix("-script") == "polind"


_PROGRAM = _started_as_the_program()
if _PROGRAM:
    _Signals.phase = "starting"
    _handle_signals()


def check_interrupted() -> None:
    """Raise :class:`Interrupted` if a signal came before this point of the run.

    Its first exception may have been swallowed by a library (pyarrow imports
    pandas lazily, in code that drops exceptions): the commands call this after
    reading, as they advance and before writing, so that the run stops anyway.
    """
    if _Signals.received is not None and _Signals.phase != "committing":
        raise Interrupted(_Signals.received)


def commit_begins() -> None:
    """The command's output is complete and about to be put in place.

    A signal received before now stops it here (:func:`check_interrupted`); one
    received from now on waits for the end of the run, which has succeeded: the
    run ends either with status 130 and no output, or with its output and status
    0, never with both or neither.
    """
    check_interrupted()
    _Signals.phase = "committing"
    if _Signals.replaced is not None:
        # The writer takes SIGTERM and SIGHUP while it writes (to remove its temporary
        # file); its handlers would undo a complete output.
        for number in SIGNALS:
            if signal.getsignal(number) is not signal.SIG_IGN:
                signal.signal(number, _on_signal)


def _interrupted_status() -> int:
    number = _Signals.received
    name = f" ({signal.Signals(number).name})" if number not in (None, signal.SIGINT) else ""
    _report("error", f"interrupted{name}")
    return 130


import click  # noqa: E402 - after the signal handlers (the slowest import of the program)

# The commands register on the group when their modules are imported.
from polind.cli import compiling, exports, fitting, reports, runs, surfaces  # noqa: E402,F401
from polind.cli.common import PROGRAM, cli, progress  # noqa: E402
from polind.errors import InputError  # noqa: E402


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
    """Run the command line; return the exit status.

    A terminal's signal (:data:`SIGNALS`) received during the run makes it 130,
    whatever the command did after it (a library that swallowed its exception
    and failed later, a command that went on to its end).
    """
    if _Signals.phase == "starting":       # the program's run: a signal of its imports
        _Signals.phase = "running"
        if _Signals.received is not None:
            return _interrupted_status()
    else:                                   # one of the runs of a Python session
        _Signals.received, _Signals.raised = None, -1e300
        _Signals.phase = "running"
    status = _command_status(argv)
    if _Signals.received is not None and status != 130:
        status = _interrupted_status()
    return status


def _command_status(argv) -> int:
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
    except click.Abort:
        return _interrupted_status()
    except Exception as exc:  # noqa: BLE001 - each kind of error gets its status below
        if _Signals.received is not None:
            return _interrupted_status()     # the error followed the signal (a half import)
        return _error_status(exc)
    finally:
        from polind.resources import set_memory_limit

        set_memory_limit(None)      # a --max-memory ends with its command
    # standalone_mode=False returns the exit code of --help/--version, else
    # the command's return value (None): commands do not choose statuses.
    return status if isinstance(status, int) else 0


def _error_status(exc) -> int:
    """The status of an error a command raised, reported in one line."""
    if isinstance(exc, click.ClickException):
        _report("error", exc.format_message())
        return 2
    if isinstance(exc, InputError):
        _report("error", str(exc))
        return 2
    if isinstance(exc, OSError) and exc.errno in _UNWRITABLE:
        # What the command prints found standard output full or gone (its files are
        # written through polind.io, which names them): the user's device, not polind.
        _report("error", f"standard output: cannot write: {exc.strerror or exc}")
        return 2
    _report("internal error", f"{type(exc).__name__}: {exc}")
    return 1


def main(argv=None) -> None:
    """The ``polind`` console script: run the command line and exit with its status.

    From its first line on, SIGINT, SIGTERM and SIGHUP end the run with status
    130, no output and no temporary file (:class:`Interrupted`); one that came
    while the modules were imported ends it here.
    """
    _handle_signals()
    try:
        status = _run(argv)
    except KeyboardInterrupt:       # a signal in the first or last lines of _run
        status = _interrupted_status()
    # The status is decided: a signal from now on waits for the exit.
    _Signals.phase = "committing"
    if not _PROGRAM:
        _restore_signals()          # a Python session goes on with its own handlers
    else:
        # The interpreter's finalisation puts back the default handlers of every signal a
        # Python function handles, and a signal then killed a finished run (status -15
        # after its complete output); an ignored signal stays ignored to the exit.
        for number in SIGNALS:
            signal.signal(number, signal.SIG_IGN)
    # Every output is written and closed by now.  Without this, the interpreter's last
    # garbage collections walk every object numba and SciPy created (0.2 to 0.4 s after
    # a simulate); frozen objects are skipped, and atexit handlers still run.
    import gc

    gc.freeze()
    sys.exit(status)
