"""The one safe writer: every output file of polind is written through :func:`atomic_open`.

A write goes through one temporary file in the target's directory that
replaces the target only once the whole content is on disk: a failed run
(an error, Ctrl-C, SIGTERM or SIGHUP) leaves no output file, and an existing
one untouched.  ``-`` (:data:`STDOUT`) writes to standard output; an
existing FIFO or device is written to directly, never replaced; a symlink is
followed (its target replaced, the link kept).  :func:`check_output_path`
refuses, before a long run, an output that cannot be written or that is one
of a command's inputs.  :func:`atomic_write_bytes` and
:func:`atomic_write_text` write a whole content at once.
"""

from __future__ import annotations

import contextlib
import os
import tempfile

from polind.errors import InputError

__all__ = ["STDOUT", "atomic_open", "atomic_write_bytes", "atomic_write_text",
           "check_output_path"]


#: The output name that means standard output.
STDOUT = "-"


def _same_file(one, other) -> bool:
    """Whether two paths name one file (after links), existing or not."""
    try:
        return os.path.samefile(one, other)
    except OSError:
        return os.path.realpath(one) == os.path.realpath(other)


def check_output_path(path, inputs=()) -> None:
    """Fail early if ``path`` cannot become an output file.

    ``-`` (standard output) always can.  Otherwise the path must not name
    a directory (or end in a separator), its directory must exist and be
    writable, and it must not be one of ``inputs`` (the files the command
    reads: an output never replaces an input, also through a link).
    Commands call this before a long run so that a typo in ``--output`` is
    reported at once.
    """
    name = os.fspath(path)
    if name == STDOUT:
        return
    if name.endswith((os.sep, "/")) or os.path.isdir(name):
        raise InputError(f"{name}: is a directory; expected a file name to write")
    for source in inputs:
        if source is not None and _same_file(name, os.fspath(source)):
            raise InputError(f"{name}: is also an input of this command ({os.fspath(source)}); "
                             f"expected another file name, so that no input is overwritten")
    target = os.path.realpath(name)
    folder = os.path.dirname(target)
    if os.path.exists(target) and not os.path.isfile(target):
        return              # a FIFO or a device: written to directly, never replaced
    if not os.path.isdir(folder):
        raise InputError(f"{name}: cannot write: the directory {folder!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"{name}: cannot write: the directory {folder!r} is not writable")


def _new_file_mode(name) -> int:
    """The permissions the output should have: an existing file's, else the umask's."""
    try:
        return os.stat(name).st_mode & 0o7777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


class _Terminated(BaseException):
    """SIGTERM or SIGHUP while an output is being written (its temporary file is removed)."""


@contextlib.contextmanager
def _removing_on_signals():
    """Turn SIGTERM and SIGHUP into an exception while a temporary file exists.

    SIGINT is already KeyboardInterrupt.  Only the main thread can set
    handlers; elsewhere the signals keep their handlers.
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(number, frame):
        raise _Terminated(number)

    names = [name for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)]
    previous = {name: signal.signal(getattr(signal, name), terminate) for name in names}
    try:
        yield
    except _Terminated as exc:
        # Cleaned up by the caller; now die of the signal as the process would have.
        number = exc.args[0]
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)
        previous = {}
        signal.raise_signal(number)
        raise SystemExit(128 + number) from None
    finally:
        for name, handler in previous.items():
            signal.signal(getattr(signal, name), handler)


@contextlib.contextmanager
def atomic_open(path, binary=False):
    """Yield a stream for the output ``path``; a regular file appears only on success.

    * ``-``: standard output.
    * An existing FIFO or device (``/dev/stdout``, a named pipe): opened and
      written directly; it is never replaced by a regular file.
    * Otherwise a temporary file beside the target (a symlink's target: the
      link stays a link) that replaces it only once the whole content is on
      disk; any failure, Ctrl-C, SIGTERM or SIGHUP removes it.
    """
    name = os.fspath(path)
    check_output_path(name)
    if name == STDOUT:
        import sys

        stream = sys.stdout.buffer if binary else sys.stdout
        yield stream
        stream.flush()
        return
    target = os.path.realpath(name)
    if os.path.exists(target) and not os.path.isfile(target):
        try:
            stream = open(target, "wb" if binary else "w",
                          **({} if binary else {"encoding": "utf-8", "newline": "\n"}))
        except OSError as exc:
            raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from None
        with stream:
            yield stream
        return
    folder = os.path.dirname(target)
    with _removing_on_signals():
        try:
            handle, temporary = tempfile.mkstemp(dir=folder, suffix=".tmp",
                                                 prefix=f".{os.path.basename(target)}.")
        except OSError as exc:
            raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from None
        try:
            if binary:
                stream = os.fdopen(handle, "wb")
            else:
                stream = os.fdopen(handle, "w", encoding="utf-8", newline="\n")
            with stream:
                yield stream
                stream.flush()
                os.fsync(stream.fileno())
            os.chmod(temporary, _new_file_mode(target))
            os.replace(temporary, target)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
            if isinstance(exc, OSError):
                raise InputError(f"{name}: cannot write: {exc.strerror or exc}") from exc
            raise


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: all of it, or nothing changes."""
    with atomic_open(path, binary=True) as stream:
        stream.write(data)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` newlines) to ``path`` atomically."""
    with atomic_open(path) as stream:
        stream.write(text)
