"""How much memory a run may take, checked before it allocates (the user guide, "Limits").

A run estimates what it will allocate (samples times the bytes each sample
costs) and refuses with an :class:`~polind.errors.InputError` that names the
setting and the estimate when it would pass the limit: by default half of the
memory the machine has available when the check runs, or the limit set with
:func:`set_memory_limit` (the command line's ``--max-memory``).
"""

from __future__ import annotations

import os

from polind.errors import InputError

__all__ = ["available_memory", "memory_limit", "set_memory_limit", "check_memory"]

_LIMIT: float | None = None
# Below this estimate [bytes] the default limit (half of the available memory) is taken to
# pass without asking the system: a machine that cannot spare it could not run Python's
# numba and NumPy either.
_NEVER_REFUSED = 16e6


def available_memory() -> float:
    """The memory the machine has available now [bytes] (Linux ``MemAvailable``, else free pages)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as stream:
            for line in stream:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return float("inf")


def set_memory_limit(limit_bytes: float | None) -> None:
    """Set the limit [bytes] every later check uses; None restores the default (half available)."""
    global _LIMIT
    if limit_bytes is not None and not (isinstance(limit_bytes, (int, float))
                                        and limit_bytes > 0):
        raise InputError(f"The memory limit must be a positive number of bytes. "
                         f"Got {limit_bytes!r} instead.")
    _LIMIT = None if limit_bytes is None else float(limit_bytes)


def given_memory_limit() -> float | None:
    """The limit [bytes] :func:`set_memory_limit` set, or None (the default is in force).

    What a process that starts another passes on, so that the new one refuses
    what this one would (:func:`polind.demo.run_demo`'s processes).
    """
    return _LIMIT


def memory_limit() -> float:
    """The limit [bytes] in force: the one set, else half of :func:`available_memory`."""
    return _LIMIT if _LIMIT is not None else 0.5 * available_memory()


def _size(count: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if count >= scale:
            return f"{count / scale:.3g} {unit}"
    return f"{count:.0f} B"


def check_memory(estimate: float, what: str) -> None:
    """Refuse (InputError) a run whose ``estimate`` [bytes] passes the limit.

    ``what`` names the setting that asks for it, e.g. ``"the system's duration /
    time_step (1e9 samples)"``.  Under the default limit an estimate below 16 MB
    passes without reading the system's memory (cheap enough for every call).
    """
    if _LIMIT is None and estimate < _NEVER_REFUSED:
        return                  # without reading /proc/meminfo: small runs check often
    limit = memory_limit()
    if estimate > limit:
        source = "set by --max-memory" if _LIMIT is not None else \
            "half of the memory available now; --max-memory changes it"
        raise InputError(f"{what} needs about {_size(estimate)} of memory; the limit is "
                         f"{_size(limit)} ({source}).")
