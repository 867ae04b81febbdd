"""Where the fits of an identification start (:ref:`guide-fit-starts`).

:func:`identify <polind.identification.identify>` fits from several starting
points and keeps the fit with the smallest sum of squares in sample.  In
order:

1. the model's own values (the model file's ``[model]``);
2. starting models given by the caller (``extra_starts``: :func:`polind.compare`
   passes the fitted models of other rows that this model contains);
3. the fit of the special case the model contains
   (:meth:`polind.FrictionModel.special_case`: Maxwell-slip in GMS, Stribeck in
   LuGre, the Maxwell-slip limit of Pol-Ind), lifted to a start of the model;
4. the model's structured starts (:meth:`polind.FrictionModel.structured_starts`:
   the NNLS element set of the Maxwell-slip family, the Stribeck curve from the
   samples as steady points, the record's levels on Pol-Ind's elements);
5. points spread over the bounds: a Latin hypercube (``scipy.stats.qmc``,
   seeded, so a fit is reproducible) in the box of the optimiser's variables,
   log-uniform for a parameter fitted on a log scale.

A start is projected onto the free keys (the other keys keep the model's
values) and clipped into the bounds; one the record cannot give, or equal to
an earlier one, is left out.  ``starts=N`` keeps the first ``N`` of 1-4 and
fills up to ``N`` with spread points; the default keeps all of 1-4 and adds
:data:`DEFAULT_SPREAD_STARTS` spread points.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping

import numpy as np

from polind.errors import InputError
from polind.identification.data import MeasuredData
from polind.identification.parameters import FreeParameter, variables_of
from polind.models import FrictionModel
from polind.validation import describe

__all__ = ["DEFAULT_SPREAD_STARTS", "SPREAD_SPAN", "GIVEN_START", "check_starts",
           "check_extra_starts",
           "spread_points", "starting_points"]

#: Latin hypercube points a fit starts from besides the model's own starts, by default.
DEFAULT_SPREAD_STARTS = 2
#: A variable without a finite bound is spread this far (in the optimiser's units: a
#: factor e^3 for a log-scaled parameter) on that side of its start.
SPREAD_SPAN = 3.0
#: The label of the model's own values among the starts.
GIVEN_START = "the model's values"


def check_starts(starts) -> int | None:
    """``starts`` as :func:`~polind.identification.identify` takes it: None or an integer >= 1."""
    if starts is None:
        return None
    if isinstance(starts, bool) or not isinstance(starts, (int, np.integer)) or starts < 1:
        raise InputError(f"The number of 'starts' must be a positive integer (the starting "
                         f"points of the fit). Got {describe(starts)} instead.")
    return int(starts)


def check_extra_starts(extra_starts, start) -> dict:
    """``extra_starts`` as a dict label -> model of the start's type (InputError otherwise)."""
    if extra_starts is None:
        return {}
    if not isinstance(extra_starts, Mapping):
        raise InputError(f"The 'extra_starts' of identify must be a mapping label -> model. Got "
                         f"{describe(extra_starts)} instead.")
    for label, model in extra_starts.items():
        if type(model) is not type(start):
            raise InputError(f"The extra start '{label}' of identify must be a {start.type} "
                             f"model, as the model fitted. Got {describe(model)} instead.")
    return dict(extra_starts)


def spread_points(frees: list[FreeParameter], count: int, seed: int = 0) -> np.ndarray:
    """``count`` Latin-hypercube points in the box of the optimiser's variables.

    Shape ``(count, variables)``.  A side without a finite bound (the GMS
    weights) reaches :data:`SPREAD_SPAN` beyond the start.
    """
    from scipy.stats import qmc

    if not frees or count < 1:
        return np.zeros((max(count, 0), sum(f.size for f in frees)))
    low, high = (np.concatenate(parts) for parts in zip(*(f.internal_bounds() for f in frees)))
    if low.size == 0:
        return np.zeros((count, 0))
    low = np.where(np.isfinite(low), low, np.minimum(high, 0.0) - SPREAD_SPAN)
    high = np.where(np.isfinite(high), high, np.maximum(low, 0.0) + SPREAD_SPAN)
    sample = qmc.LatinHypercube(d=low.size, seed=seed).random(count)
    return low + sample * (high - low)


def _projected(frees, make) -> np.ndarray | None:
    """The variables of the model ``make()`` gives, or None where it cannot give one."""
    try:
        model = make()
    except InputError:
        return None
    return None if model is None else variables_of(frees, model)


def starting_points(start: FrictionModel, keys: list[str], frees: list[FreeParameter],
                    measured: MeasuredData, *, starts: int | None = None,
                    spread: int = DEFAULT_SPREAD_STARTS,
                    extra_starts: Mapping | None = None,
                    fit_special_case: Callable | None = None) -> Iterator[tuple[str, np.ndarray]]:
    """``(label, variables)`` of each starting point, in the order of the module docstring.

    ``fit_special_case(case)`` fits a :class:`~polind.models.base.SpecialCase`
    and returns the fitted contained model (or None); it runs only when its
    start is reached.  Without it the special case is not tried.
    """
    entries: list[tuple[str, Callable]] = [(GIVEN_START, lambda: start)]
    for label, model in (extra_starts or {}).items():
        entries.append((str(label), lambda model=model: model))
    path = measured.path()
    if fit_special_case is not None:
        try:
            case = start.special_case(list(keys), path)
        except InputError:
            case = None
        if case is not None:
            def lifted(case=case):
                fitted = fit_special_case(case)
                return None if fitted is None else case.lift(fitted)
            entries.append((f"the fitted {case.description}", lifted))
    if starts is None or len(entries) < starts:
        try:
            structured = start.structured_starts(path, measured.force, list(keys))
        except InputError:
            structured = {}
        entries += [(label, lambda model=model: model) for label, model in structured.items()]
    if starts is not None:
        entries, spread = entries[:starts], max(0, starts - len(entries))
    seen = []

    def new(u):
        if u is None or any(np.array_equal(u, other) for other in seen):
            return False
        seen.append(u)
        return True

    for index, (label, make) in enumerate(entries):
        # The model's values are the origin of the variables: u = 0.
        u = np.zeros(sum(f.size for f in frees)) if index == 0 else _projected(frees, make)
        if new(u):
            yield label, u
    for index, u in enumerate(spread_points(frees, spread), start=1):
        if new(u):
            yield f"Latin hypercube point {index} of {spread}", u
