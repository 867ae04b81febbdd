"""numba kernels: arrays and floats in, arrays out, no Python objects.

All numba options live here (STYLE.md): every kernel is compiled with
:data:`JIT_OPTIONS` so the command line reuses numba's on-disk cache instead
of recompiling on every run.  ``fastmath`` is limited to the flags that let
LLVM vectorise sums and fuse multiply-adds (reassociation, contraction, no
signed zeros, reciprocal approximation is *not* enabled); NaN and infinity
keep their IEEE meaning, because inputs are validated before they reach a
kernel and a NaN that appears anyway must stay visible.
"""

from __future__ import annotations

from numba import njit

FASTMATH = frozenset({"reassoc", "contract", "nsz"})
JIT_OPTIONS = {"cache": True, "nogil": True, "fastmath": set(FASTMATH), "error_model": "numpy"}


def jit(function=None, **overrides):
    """``numba.njit`` with the project's options (``cache=True`` and the fastmath set above)."""
    options = {**JIT_OPTIONS, **overrides}
    if function is None:
        return lambda f: njit(**options)(f)
    return njit(**options)(function)


_UNCACHED = {}


def for_functions(template, *functions):
    """``template`` ready to be called with these function arguments.

    numba's on-disk cache keys a compiled version by its argument types, and
    the type of a function argument refers to the function object itself: a
    version compiled for a function defined outside polind (a model of the
    user's own, in a script or a notebook) would be written to polind's
    cache and fail to load once that function is gone.  The template is
    therefore compiled again without the on-disk cache, once per process.
    """
    # Measured: even polind's own functions, as argument types, do not match
    # the cache index in a new process (it grows by an entry per process and
    # its save fails after about a dozen).  So every template that takes
    # functions is compiled once per process, never cached.
    twin = _UNCACHED.get(template)
    if twin is None:
        options = {**JIT_OPTIONS, **template.targetoptions, "cache": False}
        options.pop("nopython", None)          # implied by njit
        twin = _UNCACHED[template] = njit(**options)(template.py_func)
    return twin
