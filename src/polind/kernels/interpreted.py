"""A kernel run by Python: the same source, for a call too rare to be worth compiling.

A process that calls a kernel once (a model built at one normal load solves
its separation once) pays numba's compilation of the kernel and of every
kernel it calls — for Pol-Ind's separation about 0.9 s on a cold cache, three
times the work of a whole run at that load.  :func:`interpreted` gives the
kernel's own Python function instead, with every kernel it calls replaced by
its interpreted version in turn, so the call compiles nothing.

The results are the compiled kernel's, to the bit, where the compiled
arithmetic is IEEE's: for kernels compiled without ``fastmath`` (no
reassociation; no fused multiply-add: ``polind.kernels`` enables no
contraction), whose ``math`` calls reach the same C library as Python's.
:func:`interpreted` refuses a kernel compiled with ``fastmath`` (a kernel
inlined into its caller is compiled with its caller's options, so only the
kernels compiled on their own are checked).  A kernel that calls machine
code through an address (:mod:`polind.kernels.special`) has a Python twin
registered with :func:`register_twin`, the same function called from Python;
so has an intrinsic (``select``, :mod:`polind.kernels.select`).

Python checks what numba does not: a division by zero or an integer
conversion of NaN raises instead of giving ``inf`` or an undefined
integer.  NumPy's floating-point warnings are off during a call (numba's
arithmetic is IEEE's and warns of nothing: an overflow is ``inf``).
Interpret only kernels whose inputs are checked before (the kernels
interpreted in polind say so where they are used).
"""

from __future__ import annotations

import functools
import types

import numpy as np
from numba.core.dispatcher import Dispatcher

__all__ = ["interpreted", "register_twin", "call_once"]

_TWINS: dict = {}


def register_twin(kernel, function):
    """Run ``function`` wherever :func:`interpreted` meets ``kernel``.

    ``kernel``: a kernel or an intrinsic Python cannot run.
    """
    _TWINS[kernel] = function
    _CACHE.pop(kernel, None)
    _ROOTS.pop(kernel, None)


def _is_twinned(value):
    """Whether ``value`` (any global of a kernel) has a registered twin."""
    try:
        return value in _TWINS
    except TypeError:           # unhashable: not a kernel
        return False


_CACHE: dict = {}


def interpreted(kernel):
    """``kernel``'s Python function, calling the interpreted versions of the kernels it calls.

    Parameters
    ----------
    kernel : numba dispatcher
        A kernel compiled without ``fastmath`` (see the module notes).

    Returns
    -------
    function
        The same source as a Python function; results to the bit.

    Raises
    ------
    ValueError
        If ``kernel``, or a kernel it calls that is not inlined, is
        compiled with ``fastmath``.
    """
    if kernel not in _ROOTS:
        function = _interpreted(kernel, root=True)

        @functools.wraps(function)
        def quietly(*arguments):
            with np.errstate(all="ignore"):
                return function(*arguments)

        _ROOTS[kernel] = quietly
    return _ROOTS[kernel]


_ROOTS: dict = {}

#: Kernels :func:`call_once` has run once in this process.
_CALLED: set = set()


def _interpreted(kernel, root):
    if _is_twinned(kernel):
        return _TWINS[kernel]
    if kernel in _CACHE:
        return _CACHE[kernel]
    options = kernel.targetoptions
    if (root or options.get("inline", "never") == "never") and options.get("fastmath"):
        name = kernel.py_func.__qualname__
        raise ValueError(f"kernel {name} is compiled with fastmath: Python would round it "
                         f"differently, so it cannot be interpreted")
    function = kernel.py_func
    names = dict(function.__globals__)
    for name in function.__code__.co_names:
        value = names.get(name)
        if isinstance(value, Dispatcher) or _is_twinned(value):
            names[name] = _interpreted(value, root=False)
    result = types.FunctionType(function.__code__, names, function.__name__,
                                function.__defaults__, function.__closure__)
    result.__doc__ = function.__doc__
    result.__qualname__ = function.__qualname__
    _CACHE[kernel] = result
    return result


def call_once(kernel, *arguments):
    """``kernel(*arguments)`` for a call made once per run, compiled only where it must be.

    By Python (:func:`interpreted`: nothing compiled, the compiled kernel's
    results to the bit) where the kernel can be interpreted; compiled where
    it cannot (a kernel compiled with ``fastmath``, or not a numba kernel at
    all) and where Python's arithmetic stops that numba's does not (a
    division by zero, an overflow: numba gives ``inf`` or NaN there, which
    is the result the caller gets; and an intrinsic without a Python twin).
    For the first sample of a run, whose force alone would otherwise
    compile the model's ``force`` (LuGre's: a quarter of a second).

    Python only the first time a process calls ``kernel``, compiled from the
    second on: a process that runs once (``polind simulate``) compiles
    nothing for it, one that runs many times (a fit, a sweep) compiles it
    once and then pays a compiled call (LuGre's force: 0.4 µs against 5 µs
    in Python, a 1024-element model's 1.1 µs against 0.1 ms).  The same
    bits either way.
    """
    if kernel in _CALLED:
        return kernel(*arguments)
    _CALLED.add(kernel)
    try:
        function = interpreted(kernel) if isinstance(kernel, Dispatcher) else kernel
    except ValueError:
        return kernel(*arguments)
    if function is kernel:
        return kernel(*arguments)
    try:
        return function(*arguments)
    except (ArithmeticError, ValueError, NotImplementedError):
        # NotImplementedError: an intrinsic without a Python twin.
        return kernel(*arguments)
