"""Where a fit of the Pol-Ind model starts (:ref:`guide-fit-starts`).

:class:`~polind.models.PolInd` asks this module for its structured start
(the record's force level and presliding range on its own elements) and for
the special case it contains: with ``mu_k = mu_s`` its Stribeck curve is flat,
and its elements, built from the surface, form a Maxwell-slip model (the
user guide, :ref:`guide-pol-ind-law`: with ``C -> inf`` and ``|v| << vs``;
with a flat curve a slipping element holds its share whatever ``C``).
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError
from polind.models.base import SpecialCase
from polind.models.maxwell_slip import MaxwellSlip

__all__ = ["structured_starts", "special_case"]

#: The keys of the rate-state law: not free in the Maxwell-slip limit.
_RATE_KEYS = ("attraction", "kinetic_coefficient", "stribeck_velocity", "stribeck_exponent")
#: The Stribeck velocity of the limit, in units of the record's largest speed: the curve
#: then stays within 1e-6 of mu_s N at every speed of the record.
_FLAT_CURVE = 1e3


def _mean_slip(stiffness, capacity) -> float:
    """The force-weighted mean slip distance of an element set [m]."""
    stiffness, capacity = np.asarray(stiffness, float), np.asarray(capacity, float)
    loaded = (stiffness > 0.0) & (capacity > 0.0)
    if not loaded.any():
        return math.nan
    slip = capacity[loaded] / stiffness[loaded]
    return float(np.sum(capacity[loaded] * slip) / np.sum(capacity[loaded]))


def structured_starts(model, path, force, free) -> dict:
    """The record's levels on the model's own elements.

    The NNLS element set of the record (:meth:`MaxwellSlip.from_presliding
    <polind.models.MaxwellSlip.from_presliding>`) gives its sliding level
    ``sum W``: ``mu_s = mu_k = sum W / N`` at the model's normal load.
    Without a series compliance, ``surface.height_std`` is also scaled by the
    ratio of the NNLS set's force-weighted mean slip distance to that of the
    model's elements (a slip distance grows about in proportion to the
    roughness).  With a compliance the presliding range is partly the
    spring's, and the roughness is kept.
    """
    try:
        nnls = MaxwellSlip.from_presliding(path, force)
    except InputError:
        return {}
    q = nnls.params
    level = math.fsum(q["breakaway_force"])
    load = model.constant_load
    mu = level / load
    changes = {"static_coefficient": mu, "kinetic_coefficient": mu}
    params = model.params
    surface = params["surface"]
    try:
        levelled = model.with_params(**changes)
        if model.series_stiffness == math.inf and surface.get("height_std") is not None:
            elements = levelled.gms_parameters()
            own = _mean_slip(elements["stiffness"], mu * load * np.asarray(elements["weight"]))
            wanted = _mean_slip(q["stiffness"], q["breakaway_force"])
            if math.isfinite(own) and own > 0.0 and math.isfinite(wanted):
                scaled = surface["height_std"] * wanted / own
                changes["surface"] = {**surface, "height_std": scaled}
                levelled = model.with_params(**changes)
                levelled.gms_parameters()           # a surface that carries the load
    except InputError:
        return {}
    return {"the record's levels on its own elements (NNLS)": levelled}


def special_case(model, free, path) -> SpecialCase | None:
    """Pol-Ind with a flat Stribeck curve: the Maxwell-slip model of its elements.

    Its fit frees the model's free keys other than the rate-state ones
    (``attraction``, ``kinetic_coefficient``, ``stribeck_velocity``,
    ``stribeck_exponent``), with the Stribeck velocity at 1000 times the
    record's largest speed (the curve flat at ``mu_s N``).  The fitted limit
    lifts to ``mu_k = mu_s`` when ``kinetic_coefficient`` is free (the
    Stribeck velocity back at its start), else keeps the flat curve's
    Stribeck velocity.
    """
    contained = tuple(key for key in free if key not in _RATE_KEYS)
    if not contained:
        return None
    speed = float(np.max(np.abs(path.sample_velocity))) or 1.0
    start = model.with_params(stribeck_velocity=_FLAT_CURVE * speed)
    velocity = model.params["stribeck_velocity"]

    def lift(fitted):
        if "kinetic_coefficient" not in free:
            return fitted
        static = fitted.params["static_coefficient"]
        return fitted.with_params(kinetic_coefficient=static, stribeck_velocity=velocity)

    return SpecialCase(type(model), start, contained, lift,
                       "maxwell-slip limit of pol-ind (mu_k = mu_s)")
