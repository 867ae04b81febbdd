"""Parameters declared as data and checked in one place (model files, :ref:`formats-model-files`).

Each model lists its :class:`Param` entries; :func:`validate_table` checks a
``[model]`` table against them and builds every error message from one
template (:mod:`polind.validation`), e.g. ``The 'stiffness' parameter of
maxwell-slip must be positive. Got -3.0 at index 2.``  Nested tables (the
Pol-Ind ``surface``, ``materials`` and ``discretisation``) are declared with
:class:`Table` and named with a dot (``surface.height_std``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError, describe

# The number checks and their message template live in the bottom layer, so
# that the contact mechanics can use them too; re-exported here.
from polind.validation import BOUNDS, check_bound, Context, parse_number, check_number  # noqa: F401

REQUIRED = object()


@dataclass(frozen=True)
class Param:
    """One key of a model table.

    kind: ``"float"``, ``"int"``, ``"list"`` (non-empty list of floats),
    ``"pair"`` (a list of exactly two floats), ``"str"``, ``"path"`` or
    ``"bool"`` (``true`` or ``false``).
    """

    key: str
    kind: str = "float"
    bound: str = "positive"
    default: object = REQUIRED
    choices: tuple = ()
    unit: str = ""
    #: Whether :func:`polind.identify` may free it (a number describing how a
    #: measurement is read, such as a height map's pixel size, is not a model
    #: parameter to fit).
    fittable: bool = True
    #: What the key means, for the file-format tables of the documentation (reST,
    #: without unit, default or range: those come from the fields above).
    description: str = ""
    #: Its symbol in the user guide's equations (LaTeX, e.g. ``"\\sigma_0"``), or "".
    symbol: str = ""


@dataclass(frozen=True)
class Table:
    """A nested table of parameters (``[model.surface]``)."""

    key: str
    entries: tuple
    default: object = REQUIRED
    description: str = ""


def _validate_value(ctx, param, value):
    if param.kind == "bool":
        if not isinstance(value, (bool, np.bool_)):
            ctx.fail(param.key, "true or false", value)
        return bool(value)
    if param.kind in ("str", "path"):
        if not isinstance(value, str) or not value:
            ctx.fail(param.key, "a non-empty string", value)
        if param.choices and value not in param.choices:
            ctx.fail(param.key, "one of " + ", ".join(repr(c) for c in param.choices), value)
        return value
    if param.kind in ("list", "pair"):
        if isinstance(value, np.ndarray):
            value = value.tolist()
        if not isinstance(value, (list, tuple)):
            ctx.fail(param.key, "a list of numbers", value)
        if len(value) == 0:
            ctx.fail(param.key, "a non-empty list", value)
        if param.kind == "pair" and len(value) != 2:
            ctx.fail(param.key, "a list of two numbers (one per body)", value)
        numbers = []
        for index, item in enumerate(value):
            number = parse_number(ctx, param.key, item, index=index)
            check_bound(ctx, param, number, index)
            numbers.append(number)
        return numbers
    number = parse_number(ctx, param.key, value, integer=param.kind == "int")
    if param.kind == "int":
        number = int(number)
    check_bound(ctx, param, number)
    return number


def validate_table(model_type, entries, table, prefix=""):
    """Check ``table`` against the declared ``entries``; return a clean dict.

    Unknown keys, missing required keys, wrong types, non-finite and
    out-of-range values raise :class:`~polind.InputError` naming the key.  Defaults
    fill the keys that have one.
    """
    ctx = Context(model_type, prefix)
    if not isinstance(table, dict):
        raise InputError(f"The '{prefix.rstrip('.') or 'model'}' table of {model_type} must be "
                         f"a table of parameters. Got {describe(table)} instead.")
    known = {entry.key: entry for entry in entries}
    for key in table:
        if key not in known:
            allowed = ", ".join(sorted(known))
            raise InputError(f"Unknown key '{ctx.name(key)}' for a {model_type} model; "
                             f"expected one of: {allowed}.")
    clean = {}
    for entry in entries:
        if entry.key not in table:
            if entry.default is REQUIRED:
                raise InputError(f"Missing key '{ctx.name(entry.key)}' for a {model_type} model.")
            if entry.default is None:
                continue
            value = entry.default
        else:
            value = table[entry.key]
        if isinstance(entry, Table):
            clean[entry.key] = validate_table(model_type, entry.entries, value,
                                              prefix=f"{prefix}{entry.key}.")
        else:
            clean[entry.key] = _validate_value(ctx, entry, value)
    return clean


def same_length(model_type, table, keys):
    """Lists of one element set must have equal lengths."""
    lengths = {key: len(table[key]) for key in keys}
    if len(set(lengths.values())) > 1:
        text = ", ".join(f"'{key}' has {n}" for key, n in lengths.items())
        raise InputError(f"The element lists of {model_type} must have equal lengths; {text}.")


def sums_to(model_type, table, key, total, what):
    """A list that must sum to a given value within 1e-9 (relative)."""
    value = math.fsum(table[key])
    if abs(value - total) > 1e-9 * abs(total):
        raise InputError(f"The '{key}' parameter of {model_type} must sum to {what} "
                         f"({total!r}) within 1e-9. Got a sum of {value!r} instead.")


STRIBECK_PARAMS = (
    Param("coulomb_force", unit="N",
          description=("Coulomb (kinetic) friction level :math:`F_c`: the force of steady "
                       "sliding well above the Stribeck velocity."), symbol="F_c"),
    Param("static_force", unit="N",
          description=("Static friction level :math:`F_s`, the Stribeck curve at rest; "
                       ":math:`F_s < F_c` makes the friction velocity-strengthening."), symbol="F_s"),
    Param("stribeck_velocity", unit="m/s",
          description=("Stribeck velocity :math:`v_s`: the speed over which the force falls "
                       "from the static to the kinetic level."), symbol="v_s"),
    Param("stribeck_exponent", default=2.0,
          description=r"Stribeck exponent :math:`\delta` of the curve's shape.", symbol=r"\delta"),
    Param("stribeck_shape", kind="str", default="exponential",
          choices=("exponential", "rational"),
          description=('Shape of the Stribeck curve: ``"exponential"`` '
                       ':math:`e^{-|v/v_s|^\\delta}` or ``"rational"`` :math:`1/(1 + '
                       '|v/v_s|^\\delta)` (:ref:`guide-stribeck-curve`).')),
)

VISCOUS = Param("viscous_coefficient", bound="nonnegative", default=0.0, unit="N s/m",
          description=(r"Viscous coefficient :math:`\sigma_2`: the force :math:`\sigma_2 v` "
                       r"added to the friction (never scaled by a normal load)."), symbol=r"\sigma_2")
