"""Finite or refused: the checks a model passes before it is stepped.

A model's parameters are validated one by one when it is built
(:mod:`polind.models.params`); what they give together is checked here,
once per model, when it is made ready to step
(:meth:`polind.FrictionModel.step_kernel`), for every model alike (polind's
own and a user's, :func:`polind.register_model`):

- :func:`check_sizes`: every number of the model is 0 or between
  :data:`SMALLEST` and :data:`LARGEST` in magnitude, so that a product or a
  quotient of any three of them is a finite, normal double (no overflow to
  infinity, no underflow to zero or to a subnormal, where the model's
  arithmetic would give NaN);
- :func:`check_scales`: the characteristic scales are finite and normal, and
  the force levels of one model lie within the resolution of a double of
  each other (the smaller is not lost in the round-off of the larger);
- :func:`check_step_parts`: what the model's own methods return has the
  shapes the stepping contract takes (a :class:`polind.StepFunctions` of numba
  functions, float64 arrays), each failure naming the method.

Every failure is an :class:`~polind.errors.InputError` naming the key, the
scale or the method.
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError, describe
from polind.models.kernel import StepFunctions
from polind.models.params import Table

__all__ = ["LARGEST", "SMALLEST", "check_scales", "check_sizes", "check_step_parts",
           "call_declared"]

#: The largest magnitude of a model's number: its cube is a finite double.
LARGEST = 1e100
#: The smallest non-zero magnitude of a model's number: its cube is a normal double.
SMALLEST = 1e-100
# Force levels of one model further apart than this cannot both be resolved (1 / eps).
_RESOLVED_RATIO = 1.0 / np.finfo(np.float64).eps


def _numbers(entries, table, prefix=""):
    """``(dotted key, index or None, value)`` of every float of a validated ``[model]`` table."""
    for entry in entries:
        value = table.get(entry.key) if isinstance(table, dict) else None
        if value is None:
            continue
        if isinstance(entry, Table):
            yield from _numbers(entry.entries, value, f"{prefix}{entry.key}.")
        elif entry.kind == "float":
            yield prefix + entry.key, None, value
        elif entry.kind in ("list", "pair"):
            for index, item in enumerate(value):
                yield prefix + entry.key, index, item


def check_sizes(model_type, entries, params) -> None:
    """Refuse a number of the model too large or too small for its arithmetic (naming the key).

    ``entries`` are the model's declarations, ``params`` its validated
    table.  Zero is allowed where the declaration allows it.
    """
    for key, index, value in _numbers(entries, params):
        size = abs(float(value))
        if size != 0.0 and not SMALLEST <= size <= LARGEST:
            where = "" if index is None else f" at index {index}"
            raise InputError(f"The '{key}' parameter of {model_type} must be of a physical size, "
                             f"0 or between {SMALLEST:g} and {LARGEST:g} in magnitude (the "
                             f"model's arithmetic multiplies and divides its numbers). Got "
                             f"{describe(value)}{where} instead.")


def _normal(value) -> bool:
    return value == 0.0 or (math.isfinite(value) and abs(value) >= _TINY)


def _all_normal(array) -> bool:
    """Whether every entry is 0 or a finite normal double (no NaN, infinity or subnormal)."""
    size = np.abs(array)
    return bool(np.isfinite(size).all() and not ((size > 0.0) & (size < _TINY)).any())


_TINY = np.finfo(np.float64).tiny


def check_scales(model_type, scales) -> None:
    """Refuse characteristic scales that are not finite and normal, or force levels unresolved.

    ``scales`` is :meth:`polind.FrictionModel.characteristic_scales` (None: none declared).
    """
    if not scales:
        return
    for key, value in scales.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) \
                and not _normal(float(value)):
            raise InputError(f"The {model_type} model's parameters give its {key} = "
                             f"{float(value)!r}, beyond double precision; expected parameters "
                             f"of a physical size.")
    levels = {key: abs(float(scales[key])) for key in ("static_force", "coulomb_force")
              if isinstance(scales.get(key), (int, float)) and scales[key] != 0.0}
    if len(levels) == 2:
        (low_key, low), (high_key, high) = sorted(levels.items(), key=lambda item: item[1])
        if high > low * _RESOLVED_RATIO:
            raise InputError(f"The {model_type} model's {low_key} ({low!r} N) and {high_key} "
                             f"({high!r} N) differ by more than double precision resolves (a "
                             f"factor {_RESOLVED_RATIO:.2g}); expected force levels closer "
                             f"together.")


def call_declared(owner, name, *args):
    """The method ``name`` of a model (``owner``: the model or its class) called, a failure named.

    A model of one's own (a class defined outside polind) may fail in its own
    code: its exception becomes an InputError naming the class and the
    method, so that the author knows where to look.  polind's own models'
    exceptions go on as they are (a bug of polind's, an internal error).
    """
    cls = owner if isinstance(owner, type) else type(owner)
    method = getattr(owner, name)
    if cls.__module__.split(".")[0] == "polind":
        return method(*args)
    try:
        return method(*args)
    except InputError:
        raise
    except Exception as error:  # noqa: BLE001 - the model's own code, whatever it raises
        raise InputError(f"The model class {cls.__name__}'s {name}() failed: "
                         f"{type(error).__name__}: {error}") from None


def _is_numba_function(function) -> bool:
    # A numba dispatcher (@njit) keeps the Python function it compiles.
    return callable(function) and callable(getattr(function, "py_func", None))


def check_step_parts(model, functions, arrays, variables) -> None:
    """What a model's methods returned, checked against the stepping contract.

    ``functions`` from ``step_functions()``, ``arrays`` from
    ``kernel_arrays(state)``, ``variables`` from ``initial_variables()``.
    """
    owner = f"The model class {type(model).__name__}'s"
    if not isinstance(functions, StepFunctions):
        raise InputError(f"{owner} step_functions() must return a polind.StepFunctions (its "
                         f"numba step, force and tangent). Got {describe(functions)} instead.")
    for field in ("step", "force", "tangent"):
        if not _is_numba_function(getattr(functions, field)):
            raise InputError(f"{owner} step_functions() must give a numba function (@njit) as "
                             f"its '{field}'. Got {describe(getattr(functions, field))} "
                             f"instead.")
    if not (isinstance(arrays, tuple) and len(arrays) == 2):
        raise InputError(f"{owner} kernel_arrays() must return a pair (scalars, table) of "
                         f"float64 arrays. Got {describe(arrays)} instead.")
    for name, value, ndim in (("scalars", arrays[0], 1), ("table", arrays[1], 2)):
        try:
            array = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            array = None
        if array is None or array.ndim not in (ndim, 1):
            raise InputError(f"{owner} kernel_arrays() must give its {name} as a "
                             f"{ndim}-D array of numbers. Got {describe(value)} instead.")
        if not _all_normal(array):
            raise InputError(f"The {model.type} model's parameters give a value that is not a "
                             f"finite, normal double in its kernel {name} (a value too large "
                             f"or too small for double precision); expected parameters of a "
                             f"physical size.")
    try:
        clean = isinstance(variables, dict) and all(
            np.asarray(value, dtype=np.float64).ndim <= 1 for value in variables.values())
    except (TypeError, ValueError):
        clean = False
    if not clean:
        raise InputError(f"{owner} initial_variables() must return a dict of 1-D arrays of "
                         f"numbers. Got {describe(variables)} instead.")
