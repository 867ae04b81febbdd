"""Checks on the numbers the contact mechanics uses, with the project's one message template.

The contact functions are public and usable without a model file, so they
check what they are given; the checks and their messages are those of
:mod:`polind.validation`, shared with :mod:`polind.models.params` (``The
'surface.height_std' parameter of pol-ind must be positive. Got 0.0
instead.``), named with the dotted model key where there is one.
"""

from __future__ import annotations

from polind.validation import check_number

__all__ = ["finite_number", "positive_number", "poisson_ratio", "element_count"]

_OWNER = "pol-ind"


def finite_number(value, name: str) -> float:
    """Return ``value`` as a float if it is a finite real number, else raise."""
    return check_number(_OWNER, name, value, "any")


def positive_number(value, name: str) -> float:
    """Return ``value`` as a float if it is a positive finite real number, else raise."""
    return check_number(_OWNER, name, value, "positive")


def poisson_ratio(value, name: str) -> float:
    """Return a Poisson ratio as a float if it lies in (-1, 0.5], else raise."""
    return check_number(_OWNER, name, value, "poisson")


def element_count(value, name: str, maximum: int) -> int:
    """Return a positive integer not above ``maximum``, else raise."""
    return check_number(_OWNER, name, value, "positive", integer=True, maximum=maximum)
