"""One writer at a time: an output that is added to over a long run is locked while written.

A sweep's results table grows as runs finish, and a second sweep writing the
same table at the same time would lose rows of the first.  :func:`writer_lock`
holds an exclusive lock on a lock file beside the output (``.NAME.lock``),
taken with `filelock <https://py-filelock.readthedocs.io>`_: on POSIX an
``flock`` that the operating system releases when its process ends, however
it ends (SIGKILL included), so a crashed writer never leaves it stuck.  A
second writer is refused at once, with an :class:`~polind.errors.InputError`
naming the output.  The holder removes the lock file before it lets go of the
lock; a writer that finds the file gone after taking the lock took a file
that was being removed, and is refused as well.
"""

from __future__ import annotations

import contextlib
import os

from polind.errors import InputError

__all__ = ["lock_path", "writer_lock"]


def lock_path(path) -> str:
    """The lock file of the output ``path``: ``.NAME.lock`` beside it (beside a link's target)."""
    folder, base = os.path.split(os.path.realpath(os.fspath(path)))
    return os.path.join(folder, f".{base}.lock")


def _refusal(name, lock_file, what) -> InputError:
    return InputError(f"{name}: {what} is writing it now (it holds {lock_file}); expected one "
                      f"writer at a time: wait for it to finish, or give another output")


@contextlib.contextmanager
def writer_lock(path, what="another polind command"):
    """Hold the lock of the output ``path`` for the block; refuse if another writer holds it.

    Parameters
    ----------
    path : str or os.PathLike
        The output (a regular file, existing or not).
    what : str
        Who else may hold it, for the message (``"another sweep"``).

    Raises
    ------
    InputError
        Another process (or another call in this one) holds the lock, or the
        lock file cannot be created (the message names the output).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "results.csv"
    >>> with writer_lock(out):
    ...     with writer_lock(out, "another sweep"):
    ...         pass
    Traceback (most recent call last):
    ...
    polind.errors.InputError: ...results.csv: another sweep is writing it now ...
    """
    import filelock

    name = os.fspath(path)
    lock_file = lock_path(name)
    lock = filelock.FileLock(lock_file, timeout=0)
    try:
        lock.acquire()
    except filelock.Timeout:
        raise _refusal(name, lock_file, what) from None
    except OSError as exc:
        raise InputError(f"{name}: cannot lock it for writing ({lock_file}: "
                         f"{exc.strerror or exc})") from None
    if not os.path.exists(lock_file):
        # Taken on a lock file its holder was removing as it finished: it was writing.
        lock.release()
        raise _refusal(name, lock_file, what)
    try:
        yield
    finally:
        # Removed while held, so that nobody takes a lock file that is going away.
        with contextlib.suppress(OSError):
            os.unlink(lock_file)
        lock.release()
