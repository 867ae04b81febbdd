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
locators.  :func:`install` puts the locator first in numba's list; importing
``polind.kernels`` calls it, before any kernel is compiled.
"""

from __future__ import annotations

import hashlib
import os
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


def install() -> None:
    """Put :class:`KernelCacheLocator` first among numba's cache locators (once)."""
    implementation = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # numba < 0.62
    classes = implementation._locator_classes
    if KernelCacheLocator not in classes:
        classes.insert(0, KernelCacheLocator)
