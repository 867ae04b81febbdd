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
           "check_output_path", "write_together"]


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
    handlers; elsewhere the signals keep their handlers, and so does a signal
    that is ignored (``nohup`` ignores SIGHUP: the write goes on).
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminate(number, frame):
        raise _Terminated(number)

    names = [name for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
             and signal.getsignal(getattr(signal, name)) is not signal.SIG_IGN]
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


def _cannot_write(name, error) -> InputError:
    """The one-line refusal of an output that could not be written (an OSError)."""
    where = "standard output" if name == STDOUT else name
    return InputError(f"{where}: cannot write: {error.strerror or error}")


def _is_stream(name) -> bool:
    """Standard output, or an existing FIFO or device: written to directly, never replaced."""
    if name == STDOUT:
        return True
    target = os.path.realpath(name)
    return os.path.exists(target) and not os.path.isfile(target)


@contextlib.contextmanager
def _stream_open(name, binary):
    """Standard output or an existing FIFO or device, its write errors an InputError."""
    try:
        if name == STDOUT:
            import sys

            stream = sys.stdout.buffer if binary else sys.stdout
            yield stream
            stream.flush()
            return
        with open(os.path.realpath(name), "wb" if binary else "w",
                  **({} if binary else {"encoding": "utf-8", "newline": "\n"})) as stream:
            yield stream
    except OSError as exc:
        raise _cannot_write(name, exc) from None


@contextlib.contextmanager
def _temporary_beside(name, binary=True, replace=True):
    """Yield ``(stream, path)`` of a temporary file beside the output ``name`` (a link's target).

    At the end of the block its whole content is flushed to disk, it gets the
    output's permissions and, with ``replace``, it replaces the output.  Any
    failure removes it (an OSError becomes an InputError naming the output).
    """
    target = os.path.realpath(name)
    try:
        handle, temporary = tempfile.mkstemp(dir=os.path.dirname(target), suffix=".tmp",
                                             prefix=f".{os.path.basename(target)}.")
    except OSError as exc:
        raise _cannot_write(name, exc) from None
    try:
        if binary:
            stream = os.fdopen(handle, "wb")
        else:
            stream = os.fdopen(handle, "w", encoding="utf-8", newline="\n")
        with stream:
            yield stream, temporary
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, _new_file_mode(target))
        if replace:
            os.replace(temporary, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        if isinstance(exc, OSError):
            raise _cannot_write(name, exc) from exc
        raise


@contextlib.contextmanager
def atomic_open(path, binary=False):
    """Yield a stream for the output ``path``; a regular file appears only on success.

    * ``-``: standard output.
    * An existing FIFO or device (``/dev/stdout``, a named pipe): opened and
      written directly; it is never replaced by a regular file.
    * Otherwise a temporary file beside the target (a symlink's target: the
      link stays a link) that replaces it only once the whole content is on
      disk; any failure, Ctrl-C, SIGTERM or SIGHUP removes it.

    A failed write (a full disk or device, a closed standard output) is an
    :class:`~polind.errors.InputError` naming the output.
    """
    name = os.fspath(path)
    check_output_path(name)
    if _is_stream(name):
        with _stream_open(name, binary) as stream:
            yield stream
        return
    with _removing_on_signals(), _temporary_beside(name, binary) as (stream, _):
        yield stream


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: all of it, or nothing changes."""
    with atomic_open(path, binary=True) as stream:
        stream.write(data)


def atomic_write_text(path, text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` newlines) to ``path`` atomically."""
    with atomic_open(path) as stream:
        stream.write(text)


def write_together(outputs) -> None:
    """Write the outputs of one command: all of them, or none changes.

    Parameters
    ----------
    outputs : mapping of path to bytes or str
        Each output (``-`` standard output, a FIFO or device, or a file) and
        its whole content (a ``str`` is written as UTF-8); a path that is
        None is skipped.

    Every file's content is first put on disk beside it; then the streams
    (standard output, devices) are written; then the files replace their
    targets.  A failure at any point (a full disk or device, Ctrl-C,
    SIGTERM, SIGHUP) removes the temporary files and puts back the files
    already replaced, so that no output of a failed command appears and no
    existing file changes; it is an :class:`~polind.errors.InputError`
    naming the output.  What a stream took cannot be taken back: streams
    are written last but one, just before the files appear.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> write_together({folder / "a.csv": "t\\n0\\n", folder / "a.png": b"PNG"})
    >>> sorted(path.name for path in folder.iterdir())
    ['a.csv', 'a.png']
    """
    items = [(os.fspath(path), data.encode("utf-8") if isinstance(data, str) else bytes(data))
             for path, data in dict(outputs).items() if path is not None]
    for name, _ in items:
        check_output_path(name)
    staged, replaced = [], []
    with _removing_on_signals():
        try:
            for name, data in items:
                if not _is_stream(name):
                    with _temporary_beside(name, replace=False) as (stream, temporary):
                        stream.write(data)
                    staged.append((name, temporary))
            for name, data in items:
                if _is_stream(name):
                    with _stream_open(name, binary=True) as stream:
                        stream.write(data)
            for name, temporary in staged:
                target = os.path.realpath(name)
                backup = _keep_aside(target)
                try:
                    os.replace(temporary, target)
                except OSError as exc:
                    if backup is not None:
                        os.unlink(backup)
                    raise _cannot_write(name, exc) from None
                replaced.append((target, backup))
        except BaseException:
            for target, backup in reversed(replaced):
                with contextlib.suppress(OSError):
                    if backup is None:
                        os.unlink(target)
                    else:
                        os.replace(backup, target)
            replaced = []
            raise
        finally:
            for _, temporary in staged:
                with contextlib.suppress(OSError):
                    os.unlink(temporary)
            for _, backup in replaced:
                if backup is not None:
                    with contextlib.suppress(OSError):
                        os.unlink(backup)


def _keep_aside(target):
    """A hard link to an existing ``target`` (to put it back), or None when there is none."""
    if not os.path.exists(target):
        return None
    folder, base = os.path.split(target)
    for attempt in range(100):
        backup = os.path.join(folder, f".{base}.{os.getpid()}.{attempt}.kept.tmp")
        try:
            os.link(target, backup)
            return backup
        except FileExistsError:
            continue
        except OSError:
            return None             # no hard links here: the old file cannot be put back
    return None
