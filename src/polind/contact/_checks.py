"""Checks on the numbers the contact mechanics uses, with the one message template.

Every failed check raises :class:`polind.errors.InputError` whose one-line
message names the parameter (dotted for nested model keys, e.g.
``'surface.height_std'``), the value received and what was expected.
"""

from __future__ import annotations

import math
import numbers

from polind.errors import InputError, describe

__all__ = ["finite_number", "positive_number", "poisson_ratio", "element_count"]

_OWNER = "pol-ind"


def finite_number(value, name: str) -> float:
    """Return ``value`` as a float if it is a finite real number, else raise."""
    # bool is an Integral: `True` as a modulus is a typo, not a number.
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(
            f"The '{name}' of {_OWNER} must be a finite number. Got {describe(value)}."
        )
    number = float(value)
    if not math.isfinite(number):
        raise InputError(
            f"The '{name}' of {_OWNER} must be a finite number. Got {describe(value)}."
        )
    return number


def positive_number(value, name: str) -> float:
    """Return ``value`` as a float if it is a positive finite real number, else raise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (
        math.isfinite(float(value)) and float(value) > 0.0
    ):
        raise InputError(
            f"The '{name}' of {_OWNER} must be a positive finite number. "
            f"Got {describe(value)}."
        )
    return float(value)


def poisson_ratio(value, name: str) -> float:
    """Return a Poisson ratio as a float if it lies in (-1, 0.5], else raise."""
    number = finite_number(value, name)
    # Outside (-1, 0.5] the elastic energy of an isotropic solid is not positive.
    if not -1.0 < number <= 0.5:
        raise InputError(
            f"The '{name}' of {_OWNER} must lie in (-1, 0.5]. Got {describe(value)}."
        )
    return number


def element_count(value, name: str, maximum: int) -> int:
    """Return a positive integer not above ``maximum``, else raise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not (
        1 <= int(value) <= maximum
    ):
        raise InputError(
            f"The '{name}' of {_OWNER} must be an integer from 1 to {maximum}. "
            f"Got {describe(value)}."
        )
    return int(value)
