"""SciPy's exponentially scaled modified Bessel functions, callable from numba kernels.

The Greenwood–Williamson load integrals ``F_{1/2}`` and ``F_{3/2}``
(:ref:`guide-pol-ind-summation`) are written with ``kve`` and ``ive`` of orders ±1/4, ±3/4
(:func:`polind.kernels.greenwood.gw_half_integer_pair`; the separation
solver itself evaluates a faster polynomial approximation, and calls these
only outside its range).  Inside a kernel these are SciPy's own
compiled functions from :mod:`scipy.special.cython_special` (the ``double``
specialisations ``__pyx_fuse_1kve`` and ``__pyx_fuse_1ive``, the same code
as the ufuncs ``scipy.special.kve``/``ive``), not an approximation of ours:
a kernel gets from them what the ufuncs return, to the last bit.

Why the addresses are an argument: a function pointer that numba sees as a
global (a ``ctypes`` or ``cffi`` object, or an integer address frozen as a
constant) makes it refuse ``cache=True`` ("dynamic globals"), and every
kernel of this project is cached.  So :func:`special_addresses` returns the
two addresses in an array once per process, kernels take that array as an
ordinary run-time argument, and :func:`kve`/:func:`ive` call through it with
an intrinsic that converts the run-time integer to a function pointer.
The array may hold the addresses as int64 or as (integer-valued) float64,
so a caller can pack them into a float64 parameter vector; addresses are
below 2**53 on every supported platform, so float64 holds them exactly.
"""

from __future__ import annotations

import ctypes
from functools import cache

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import get_cython_function_address, intrinsic

from polind.kernels import jit
from polind.kernels.interpreted import register_twin

__all__ = ["kve", "ive", "special_addresses", "KVE", "IVE"]

#: Index of ``kve`` and of ``ive`` in the array of :func:`special_addresses`.
KVE, IVE = 0, 1

_MODULE = "scipy.special.cython_special"
# The C signature of a ``cpdef`` Cython function: the two doubles and the
# ``skip_dispatch`` flag Cython adds (ignored by module-level functions).
_SIGNATURE = "double (double, double, int __pyx_skip_dispatch)"
_NAMES = ("__pyx_fuse_1kve", "__pyx_fuse_1ive")


def _capsule_signature(name: str) -> str:
    """The C signature SciPy exports for ``name`` (the capsule's name)."""
    import scipy.special.cython_special as cython_special

    get_name = ctypes.pythonapi.PyCapsule_GetName
    get_name.restype = ctypes.c_char_p
    get_name.argtypes = [ctypes.py_object]
    return get_name(cython_special.__pyx_capi__[name]).decode()


@cache
def special_addresses() -> np.ndarray:
    """Addresses of SciPy's compiled ``kve`` and ``ive`` (double versions), for kernels.

    Computed once per process (the addresses change between processes, which
    is why kernels take them as an argument and never as a global).

    Returns
    -------
    numpy.ndarray of int64, shape (2,), read-only
        ``[address of kve, address of ive]`` (indices :data:`KVE`, :data:`IVE`).

    Raises
    ------
    RuntimeError
        If the installed SciPy exports these functions with another C
        signature than the one the kernels call them with.
    """
    addresses = []
    for name in _NAMES:
        # A call through a pointer of the wrong type would silently return
        # garbage or crash: check SciPy's declared signature first.
        signature = _capsule_signature(name)
        if signature != _SIGNATURE:
            raise RuntimeError(
                f"{_MODULE}.{name} has the C signature {signature!r}; polind's kernels "
                f"call it as {_SIGNATURE!r}. This SciPy version is not supported."
            )
        addresses.append(get_cython_function_address(_MODULE, name))
    array = np.array(addresses, dtype=np.int64)
    # Shared by every caller through the cache: nobody may overwrite it.
    array.setflags(write=False)
    return array


@intrinsic
def _call_double_double(typingctx, address, a, b):
    """Call the C function ``double f(double, double, int)`` at the run-time ``address``."""
    if not isinstance(address, (types.Integer, types.Float)):
        return None
    # Numba casts the arguments to these types before the call (a float
    # address is converted exactly: it holds an integer below 2**53).
    signature = types.float64(types.int64, types.float64, types.float64)

    def codegen(context, builder, sig, args):
        pointer, first, second = args
        double = ir.DoubleType()
        c_int = ir.IntType(32)
        function_type = ir.FunctionType(double, [double, double, c_int])
        # inttoptr of a run-time value: nothing process-specific is baked
        # into the compiled code, so it can be cached.
        function = builder.inttoptr(pointer, function_type.as_pointer())
        return builder.call(function, [first, second, ir.Constant(c_int, 0)])

    return signature, codegen


@jit
def kve(order, x, addresses):
    """Exponentially scaled modified Bessel function of the second kind, ``K_v(x) e^x``.

    SciPy's ``scipy.special.kve`` (its compiled double version), callable
    from a numba kernel.

    Parameters
    ----------
    order : float
        Order ``v``.
    x : float
        Argument, ``x >= 0``.
    addresses : numpy.ndarray
        The array of :func:`special_addresses` (int64 or float64 values).

    Returns
    -------
    float
        ``kve(order, x)``, bit for bit as ``scipy.special.kve``.
    """
    return _call_double_double(addresses[KVE], order, x)


@jit
def ive(order, x, addresses):
    """Exponentially scaled modified Bessel function of the first kind, ``I_v(x) e^{-|x|}``.

    SciPy's ``scipy.special.ive`` (its compiled double version), callable
    from a numba kernel.

    Parameters
    ----------
    order : float
        Order ``v`` (negative orders allowed).
    x : float
        Argument, ``x >= 0`` for non-integer orders.
    addresses : numpy.ndarray
        The array of :func:`special_addresses` (int64 or float64 values).

    Returns
    -------
    float
        ``ive(order, x)``, bit for bit as ``scipy.special.ive``.
    """
    return _call_double_double(addresses[IVE], order, x)


def _python_kve(order, x, addresses):
    """:func:`kve` run by Python (:mod:`polind.kernels.interpreted`): SciPy's ufunc, the same C code."""
    from scipy.special import kve as scipy_kve

    return float(scipy_kve(order, x))


def _python_ive(order, x, addresses):
    """:func:`ive` run by Python (:mod:`polind.kernels.interpreted`): SciPy's ufunc, the same C code."""
    from scipy.special import ive as scipy_ive

    return float(scipy_ive(order, x))


register_twin(kve, _python_kve)
register_twin(ive, _python_ive)
