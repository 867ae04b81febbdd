"""numba kernels: arrays and floats in, arrays out, no Python objects.

All numba options live here, in one place: every kernel is compiled with
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

