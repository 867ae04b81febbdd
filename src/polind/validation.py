"""Checks on single numbers with the project's one message template (bottom layer).

Shared by the model tables (:mod:`polind.models.params`) and the contact
mechanics (:mod:`polind.contact`), which sits below the models and so cannot
import from them.  Every failure raises :class:`~polind.errors.InputError`
with one message form, e.g. ``The 'surface.height_std' parameter of pol-ind
must be positive. Got 0.0 instead.``
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe

__all__ = ["check_number"]

BOUNDS = {
    "positive": (lambda x: x > 0.0, "positive"),
    "nonnegative": (lambda x: x >= 0.0, "non-negative"),
    "any": (lambda x: True, "finite"),
    # Outside (-1, 0.5] the elastic energy of an isotropic solid is not positive.
    "poisson": (lambda x: -1.0 < x <= 0.5, "in the range (-1, 0.5]"),
    "fraction": (lambda x: 0.0 < x <= 1.0, "in the range (0, 1]"),
    # The exponent of an Iwan density phi^chi: integrable at 0 only for chi > -1.
    "iwan_exponent": (lambda x: -1.0 < x <= 0.0, "in the range (-1, 0]"),
}


@dataclass
class Context:
    model_type: str
    prefix: str = ""

    def name(self, key):
        return f"{self.prefix}{key}"

    def fail(self, key, expected, value, where=""):
        raise InputError(f"The '{self.name(key)}' parameter of {self.model_type} must be "
                         f"{expected}. Got {describe(value)}{where} instead.")


@dataclass(frozen=True)
class _Bounded:
    """A key and its bound: what :func:`check_bound` reads of a ``Param``."""

    key: str
    bound: str = "positive"


def parse_number(ctx, key, value, integer=False, index=None):
    where = "" if index is None else f" at index {index}"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        ctx.fail(key, "an integer" if integer else "a number", value, where)
    try:
        number = float(value)
    except OverflowError:      # an integer beyond double precision (e.g. 400 digits)
        ctx.fail(key, "a finite number of double precision (below 1.8e308)",
                 f"an integer of about {int(int(value).bit_length() * 0.30103) + 1} digits",
                 where)
    if integer and not number.is_integer():
        ctx.fail(key, "an integer", value, where)
    if not math.isfinite(number):
        ctx.fail(key, "finite", value, where)
    return number


def check_bound(ctx, param, number, index=None):
    """``param`` has a ``key`` and a ``bound`` (a key of ``BOUNDS``): a ``Param`` or ``_Bounded``."""
    test, text = BOUNDS[param.bound]
    if not test(number):
        where = "" if index is None else f" at index {index}"
        ctx.fail(param.key, text, number, where)


def check_number(owner, key, value, bound="any", *, integer=False, maximum=None):
    """One number checked with the message template of this module.

    For code outside a model table (the contact mechanics' public
    functions): ``key`` is named as given, ``bound`` is one of the bounds of
    :class:`polind.models.params.Param` (``"positive"``, ``"nonnegative"``,
    ``"any"``, ``"poisson"``, ``"fraction"``); an integer may have an upper
    ``maximum``.

    >>> check_number("pol-ind", "normal_load", 2, "positive")
    2.0
    >>> check_number("pol-ind", "surface.height_std", 0.0, "positive")
    Traceback (most recent call last):
    ...
    polind.errors.InputError: The 'surface.height_std' parameter of pol-ind must be positive. Got 0.0 instead.
    """
    ctx = Context(owner)
    number = parse_number(ctx, key, value, integer=integer)
    number = int(number) if integer else number
    check_bound(ctx, _Bounded(key, bound=bound), number)
    if maximum is not None and number > maximum:
        ctx.fail(key, f"at most {maximum}", value)
    return int(number) if integer else number


def check_samples(owner, key, values, *, at_least=1):
    """A 1-D array of finite numbers (``at_least`` of them), with this module's message form.

    For the samples a function of arrays takes (a record's ``u`` and ``F``, a
    period's displacement, a list of amplitudes): the first bad one is named
    by its index.

    >>> check_samples("hysteresis_loop", "u", [0.0, 1.0]).tolist()
    [0.0, 1.0]
    >>> check_samples("backbone", "amplitudes", [1e-5, float("nan")])
    Traceback (most recent call last):
    ...
    polind.errors.InputError: The 'amplitudes' of backbone must be finite. Got nan at index 1 instead.
    """
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"The '{key}' of {owner} must be a 1-D array of numbers. Got "
                         f"{describe(values)} instead.") from None
    if array.ndim != 1:
        raise InputError(f"The '{key}' of {owner} must be a 1-D array of numbers. Got an array "
                         f"of shape {array.shape} instead.")
    if array.shape[0] < at_least:
        raise InputError(f"The '{key}' of {owner} must have at least {at_least} sample"
                         f"{'s' if at_least != 1 else ''}. Got {array.shape[0]} instead.")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise InputError(f"The '{key}' of {owner} must be finite. Got "
                         f"{float(array[bad[0]])!r} at index {int(bad[0])} instead.")
    return array
