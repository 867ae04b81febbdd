"""numba kernels: arrays and floats in, arrays out, no Python objects.

All numba options live here, in one place: every kernel is compiled with
:data:`JIT_OPTIONS` so the command line reuses numba's on-disk cache instead
of recompiling on every run.  ``fastmath`` is limited to the flags that let
LLVM vectorise sums (reassociation, no signed zeros; reciprocal approximation
is *not* enabled).  Contraction (fusing a multiply and an add where the
compiler sees fit) is left out: a kernel loaded from the cache then rounded
differently from the same kernel compiled in the process, so a result
depended on the cache; the hot polynomial fuses explicitly
(:func:`polind.kernels.fastexp.fma`).  NaN and infinity
keep their IEEE meaning, because inputs are validated before they reach a
kernel and a NaN that appears anyway must stay visible.
"""

from __future__ import annotations

from numba import njit

from polind.kernels import cache as _cache

# Before any kernel is compiled: cached kernels keyed by every kernel source (kernels.cache).
_cache.install()

FASTMATH = frozenset({"reassoc", "nsz"})
# no_cfunc_wrapper: numba otherwise compiles, with every kernel, a C-callable wrapper that
# only a first-class function value (a kernel passed where a function type is expected)
# calls; polind passes none, and the wrappers cost a few percent of a cold compilation.
JIT_OPTIONS = {"cache": True, "nogil": True, "fastmath": set(FASTMATH), "error_model": "numpy",
               "no_cfunc_wrapper": True}


def jit(function=None, **overrides):
    """``numba.njit`` with the project's options (``cache=True`` and the fastmath set above)."""
    options = {**JIT_OPTIONS, **overrides}
    if function is None:
        return lambda f: njit(**options)(f)
    return njit(**options)(function)


def compiled_entry(function, *arguments):
    """The compiled wrapper of ``function`` for the types of ``arguments``, or ``function`` itself.

    A numba dispatcher works out the types of its arguments at every call
    (about 0.15 µs for three arrays and five floats, as much as a bare call
    costs); the wrapper of one compiled signature skips that and converts
    each argument as the signature says.  For a caller whose every later
    call passes arguments of the same types as ``arguments``
    (:class:`polind.Stepper`).  Compiles that signature (or loads it from
    numba's cache) without calling ``function``; anything that is not a
    numba dispatcher, or a signature numba refuses, gives ``function``.
    """
    from numba import typeof
    from numba.core.dispatcher import Dispatcher

    if not isinstance(function, Dispatcher):
        return function
    types = tuple(typeof(argument) for argument in arguments)
    try:
        function.compile(types)
    except Exception:       # noqa: BLE001 - the dispatcher then reports it at the first call
        return function
    result = function.overloads.get(types)
    return getattr(result, "entry_point", function) if result is not None else function
