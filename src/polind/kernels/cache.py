"""numba's on-disk cache of polind's kernels, made unable to go stale.

numba keys a cached function by the contents of the one file it is defined
in.  A kernel that inlines a function of another file (``kernels/static.py``
calls the Stribeck curve of ``kernels/stribeck.py``) would then load a cache
compiled with the old version of that function after it changed: numba
documents that its cache does not see changes in other files.

:class:`KernelCacheLocator` keys every compiled function of a polind source
file by a hash of *all* of polind's compiled sources (:func:`sources_stamp`:
every ``.py`` file of ``polind.kernels`` and the file itself), and stores
it under a folder named by that hash, so a change to any kernel source makes
every cached kernel that might use it compile again, and an old cache is never
read.  The folder is under ``NUMBA_CACHE_DIR`` when the user sets it (numba's
own rule), else in the ``__pycache__`` beside the source, else in numba's
user-wide cache folder.  Functions outside polind are left to numba's own
locators.  When no locator can write (a read-only install without a
writable ``NUMBA_CACHE_DIR``), the last, :class:`TemporaryCacheLocator`,
keeps any function's cache in a folder of the user's under the temporary
directory (:func:`temporary_base`), and says so once in a warning.
:func:`install` puts the locators in numba's list; importing
``polind.kernels`` calls it, before any kernel is compiled.
"""

from __future__ import annotations

import hashlib
import os
import stat
import tempfile
import warnings
from functools import lru_cache
from pathlib import Path

from numba.core import caching, config

#: The folder of polind's sources: files under it are polind's kernels to cache.
#: (Its value, a path on the machine that built the documentation, is not shown.)
#:
#: :meta hide-value:
PACKAGE_DIR = Path(__file__).resolve().parents[1]
KERNELS_DIR = Path(__file__).resolve().parent


def _kernel_sources() -> list[str]:
    """The path of every ``.py`` file under :data:`KERNELS_DIR`, sorted.

    Listed with :func:`os.scandir`, skipping ``__pycache__`` (which holds no
    source, but numba's cache files when ``NUMBA_CACHE_DIR`` is unset): this
    runs for every kernel numba creates, loads or saves, and ``Path.rglob``
    took 2 ms a call, half a second of a process that loads its kernels.
    """
    files, folders = [], [str(KERNELS_DIR)]
    while folders:
        with os.scandir(folders.pop()) as entries:
            for entry in entries:
                if entry.is_dir():
                    if entry.name != "__pycache__":
                        folders.append(entry.path)
                elif entry.name.endswith(".py"):
                    files.append(entry.path)
    return sorted(files)


def _kernel_files() -> list[Path]:
    """:func:`_kernel_sources` as paths."""
    return [Path(path) for path in _kernel_sources()]


@lru_cache(maxsize=None)
def _stamp(files: tuple) -> str:
    digest = hashlib.sha256()
    for path, _, _ in files:
        digest.update(path.encode())
        with open(path, "rb") as handle:
            digest.update(handle.read())
    return digest.hexdigest()[:16]


def sources_stamp(py_file) -> str:
    """A hash of the kernel sources and ``py_file``, recomputed when any of them changes."""
    files = []
    for path in {*_kernel_sources(), os.path.abspath(py_file)}:
        status = os.stat(path)
        files.append((path, status.st_mtime_ns, status.st_size))
    return _stamp(tuple(sorted(files)))


def _is_polind_source(py_file) -> bool:
    try:
        return Path(py_file).resolve().is_relative_to(PACKAGE_DIR)
    except (OSError, ValueError):
        return False


class KernelCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """Where numba caches a function of a polind source file, keyed by every kernel source."""

    def __init__(self, py_func, py_file, base):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = os.path.join(base, f"polind-{sources_stamp(py_file)}")

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return sources_stamp(self._py_file)

    @classmethod
    def from_function(cls, py_func, py_file):
        if not os.path.exists(py_file) or not _is_polind_source(py_file):
            return None
        if config.CACHE_DIR:
            bases = [os.path.join(config.CACHE_DIR,
                                  cls.get_suitable_cache_subpath(py_file))]
        else:
            from numba.misc.appdirs import AppDirs

            user_wide = AppDirs(appname="numba", appauthor=False).user_cache_dir
            bases = [os.path.join(os.path.dirname(py_file), "__pycache__"),
                     os.path.join(user_wide, cls.get_suitable_cache_subpath(py_file))]
        for base in bases:
            locator = cls(py_func, py_file, base)
            try:
                locator.ensure_cache_path()
            except OSError:
                continue
            return locator
        return None


@lru_cache(maxsize=None)
def temporary_base() -> str | None:
    """The folder numba's cache falls back to: the user's own under the temporary directory.

    ``polind-numba-cache-<uid>``, kept from one run to the next, used only if it
    is a directory of this user's that no one else can write (a cache file is
    code that numba loads); else a fresh folder for this process; None when the
    temporary directory cannot be written either.
    """
    user = os.getuid() if hasattr(os, "getuid") else "user"
    folder = os.path.join(tempfile.gettempdir(), f"polind-numba-cache-{user}")
    try:
        os.makedirs(folder, mode=0o700, exist_ok=True)
        status = os.lstat(folder)
        own = not hasattr(os, "getuid") or status.st_uid == os.getuid()
        if stat.S_ISDIR(status.st_mode) and own and not status.st_mode & 0o022:
            return folder
    except OSError:
        pass
    try:
        return tempfile.mkdtemp(prefix="polind-numba-cache-")
    except OSError:
        return None


_NOTED = []


def _temporary_locator(cls, py_func, py_file, wanted):
    """``cls``'s locator in :func:`temporary_base` (None if it cannot be written), with a
    warning, once per process, that ``wanted`` could not be."""
    base = temporary_base()
    if base is None:
        return None
    locator = cls(py_func, py_file, os.path.join(base, cls.get_suitable_cache_subpath(py_file)))
    try:
        locator.ensure_cache_path()
    except OSError:
        return None
    if not _NOTED:
        _NOTED.append(base)
        warnings.warn(f"numba's cache folder {wanted} cannot be written; the "
                      f"compiled kernels are cached in {base} instead (set NUMBA_CACHE_DIR to "
                      f"a writable folder to keep them)", UserWarning, stacklevel=2)
    return locator


class TemporaryCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """numba's last locator, when no other can write: :func:`temporary_base`.

    A polind kernel gets a :class:`KernelCacheLocator` there (keyed by every
    kernel source), any other function (a plugin's) this one.
    """

    def __init__(self, py_func, py_file, cache_path):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = cache_path

    def get_cache_path(self):
        return self._cache_path

    @classmethod
    def from_function(cls, py_func, py_file):
        if not os.path.exists(py_file):
            return None
        kind = KernelCacheLocator if _is_polind_source(py_file) else cls
        return _temporary_locator(kind, py_func, py_file, config.CACHE_DIR or os.path.join(
            os.path.dirname(py_file), "__pycache__"))


def install() -> None:
    """Put :class:`KernelCacheLocator` first among numba's cache locators and
    :class:`TemporaryCacheLocator` last (once)."""
    implementation = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # numba < 0.62
    classes = implementation._locator_classes
    if KernelCacheLocator not in classes:
        classes.insert(0, KernelCacheLocator)
    if TemporaryCacheLocator not in classes:
        classes.append(TemporaryCacheLocator)
