"""Parameter identification: fit a friction model to measured force.

The user guide, :ref:`guide-identification`; the ``[fit]`` table, :ref:`formats-fit`.

Three tools, from general to structured:

* :func:`identify` -- bounded nonlinear least squares on the simulated force
  (``scipy.optimize.least_squares``, trust-region-reflective) for any model
  of polind: the model's current values are the starting point, ``free``
  names the keys to identify and ``bounds`` limits them.  Standard errors come
  from the Jacobian at the solution.  This is ``polind fit``.
* :func:`identify_maxwell_slip` and :func:`identify_gms` -- the element set
  of a Maxwell-slip structure (:ref:`guide-maxwell-slip`, :ref:`guide-gms`) from a
  presliding record by
  non-negative least squares, a good starting point for :func:`identify`.
  Once the slip distances ``D_i`` are fixed, element ``i`` of a Maxwell-slip
  model has the deflection ``z_i`` of a spring whose deflection is clipped to
  ``[-D_i, D_i]``; that deflection depends on the path and on ``D_i`` alone,
  and the element force is ``k_i z_i = W_i (z_i / D_i)``.  The total force is
  therefore *linear* in the break-away forces: ``F = A W`` with
  ``A[k, i] = z_i(x_k) / D_i`` in ``[-1, 1]``, and ``W >= 0`` is an NNLS
  problem over a grid of slip distances.
* :func:`identify_stribeck` -- the static Stribeck curve (:ref:`guide-stribeck-curve`)
  from steady-state ``(v, F)`` points.

:func:`plot_fit` draws measured against fitted force (``polind fit --plot``).

Parametrisation
---------------
The optimiser works on internal variables that all start at 0:

* a parameter declared positive (stiffnesses, forces, velocities, the
  attraction ``C``, ...) is fitted on a log scale, ``p = p0 exp(u)``: it
  stays strictly positive (the default lower bound 0 is exclusive), and a
  step means the same *relative* change whether ``p`` is 1e-6 or 1e6;
* any other number (non-negative ones such as ``viscous_coefficient`` and
  ``bristle_damping``, which may start at and reach 0) is fitted on a linear
  scale ``p = p0 + s u``, ``s = |p0|`` or, for a start of 0, a scale set by
  the parameter's unit and the data (e.g. RMS force / RMS velocity for
  N s/m);
* a list (``stiffness``) is free as a whole vector, each entry mapped as
  above; a weight vector that must sum to 1 (``weight`` of GMS) is mapped
  through ``w = softmax(u_1 .. u_{n-1}, 0)`` so it stays positive and sums
  to 1 (it takes no bounds);
* the Leuven ``breakaway_force`` list must sum to ``static_force``: when
  ``breakaway_force`` is free, ``static_force`` follows its sum; when only
  ``static_force`` is free, ``breakaway_force`` is scaled with it.

The Jacobian is taken by forward differences of a fixed step in these
variables.  A trial point whose parameters the model rejects (a load its
surface cannot carry, say) or where its force is not finite costs a large
constant residual, so the solver backs off instead of stopping.

Standard errors are ``sqrt(diag(cov))`` with ``cov = s^2 (J^T J)^-1``,
``s^2 = RSS / (n - p)``, ``J`` the Jacobian of the force residuals at the
solution, carried to the physical parameters by the derivative of the
mapping (the delta method).  A direction the data cannot determine (``J``
rank-deficient) gives an infinite standard error to every parameter it
involves.

Safe fits (:ref:`guide-fit-warnings`)
-------------------------------------
A free key without ``[fit.bounds]`` gets default bounds derived from the
fitted data by its unit (:func:`default_bounds`; the table is there and on the
documentation's file formats page), never an unbounded range.  Every fit lists its ``warnings``: a
parameter that ended at a bound, one the data do not determine (standard
error larger than its value, or not finite), a data column or signal the
model does not use, a start outside the default bounds, a solver that
stopped early.  ``holdout=F`` fits the first ``1 - F`` of the record and
scores the prediction of the rest.  The columns of the finite-difference
Jacobian run on threads (the numba kernels release the GIL).
"""

from __future__ import annotations

import math
import os
import threading
import time
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError
from polind.resources import check_memory
from polind.validation import check_number, describe
from polind.models import FrictionModel, model_from_dict
from polind.models.params import Param, Table
from polind.simulate import as_samples, make_path, simulate

__all__ = ["FitResult", "identify", "parse_fit", "default_bounds", "identify_maxwell_slip",
           "identify_gms", "identify_stribeck", "plot_fit"]

_FIT_KEYS = ("free", "bounds", "result")
_DATA_KEYS = ("t", "x", "v", "F", "normal_load")
# Linear bounds for the bounded kinds, kept strictly inside the open ends.
_KIND_BOUNDS = {
    "positive": (0.0, math.inf),
    "nonnegative": (0.0, math.inf),
    "any": (-math.inf, math.inf),
    "poisson": (-1.0 + 1e-9, 0.5 - 1e-9),
    "fraction": (1e-12, 1.0),
}
# Largest |log change| a log-scaled parameter may take (keeps exp() finite and positive).
_LOG_LIMIT = 600.0


# --- the measured data ----------------------------------------------------------------------

def _uses_load(model: FrictionModel) -> bool:
    """Whether a normal-load signal changes the model's force (Pol-Ind, or a reference_load)."""
    uses = getattr(model, "uses_normal_load", None)
    return bool(model.takes_normal_load if uses is None else uses)


@dataclass(frozen=True)
class _Data:
    t: np.ndarray
    force: np.ndarray
    x: np.ndarray | None
    v: np.ndarray | None
    normal_load: np.ndarray | None

    @property
    def size(self) -> int:
        return self.t.shape[0]

    @property
    def scale(self) -> float:
        """The size of the measured force [N]."""
        return float(np.max(np.abs(self.force)))

    def motion(self) -> dict:
        return {"x": self.x} if self.x is not None else {"v": self.v}

    def simulate(self, model) -> np.ndarray:
        """The model's force along the data (the measured load only for a model that uses it)."""
        load = self.normal_load if _uses_load(model) else None
        return simulate(model, self.t, normal_load=load, **self.motion()).force

    def path(self):
        return make_path(self.t, **self.motion())

    def head(self, n: int) -> "_Data":
        """The first ``n`` samples (the fitted part of a hold-out split), checked again."""
        part = {key: None if value is None else value[:n] for key, value in
                (("t", self.t), ("force", self.force), ("x", self.x), ("v", self.v),
                 ("normal_load", self.normal_load))}
        return _checked(**part, where=f" of the fitted part (the first {n} samples)")


def _columns(data) -> tuple[Mapping, list[str]]:
    """The data as a mapping, and the columns of a data frame that identification does not use.

    A pandas ``DataFrame`` (anything with ``columns`` that is not a mapping:
    pandas itself is not imported) may carry other columns; they are left out
    and reported.  A plain mapping must hold the data columns only.
    """
    if isinstance(data, Mapping) or not hasattr(data, "columns"):
        return data, []
    names = list(data.columns)
    used = {str(name): data[name] for name in names if str(name) in _DATA_KEYS}
    return used, [str(name) for name in names if str(name) not in _DATA_KEYS]


def measured_data(data, *, normal_load_ok: bool = True, model: FrictionModel | None = None,
                 notes: list | None = None) -> _Data:
    """Check the data (``t``, one of ``x``/``v``, ``F``, optional ``normal_load``).

    ``normal_load_ok=False`` refuses a load column (the NNLS structure fits);
    for a ``model`` that ignores a load it is dropped with a note in ``notes``.
    Columns of a data frame that are not data columns are dropped, also with
    a note.
    """
    data, unused = _columns(data)
    if not isinstance(data, Mapping):
        raise InputError(f"The 'data' must be a mapping of columns or a data frame (t, x or v, "
                         f"F, optionally normal_load). Got {describe(data)} instead.")
    for key in data:
        if key not in _DATA_KEYS:
            raise InputError(f"Unknown data column '{key}'; expected t, one of x and v, F, and "
                             "optionally normal_load.")
    for key in ("t", "F"):
        if key not in data:
            raise InputError(f"The data lack the '{key}' column; expected t, one of x and v, F, "
                             "and optionally normal_load.")
    if ("x" in data) == ("v" in data):
        raise InputError("The data need exactly one of the columns 'x' (displacement) and 'v' "
                         "(velocity). Got " + ("both." if "x" in data else "neither."))
    t = as_samples("t", data["t"])
    n = t.shape[0]
    force = as_samples("F", data["F"], n)
    x = as_samples("x", data["x"], n) if "x" in data else None
    v = as_samples("v", data["v"], n) if "v" in data else None
    load = None
    if data.get("normal_load") is not None:
        if not normal_load_ok:
            raise InputError("A 'normal_load' column does not apply here: the Maxwell-slip "
                             "element fit uses t, x or v and F only.")
        load = as_samples("normal_load", data["normal_load"], n, positive=True)
        if model is not None and not _uses_load(model):
            load = None
            if notes is not None:
                hint = (" (give it a 'reference_load' to scale its friction with the load)"
                        if model.declaration("reference_load") is not None else "")
                notes.append(f"The 'normal_load' column is not used: the {model.type} model "
                             f"ignores a normal load{hint}.")
    if unused and notes is not None:
        notes.append(f"The data column{'s' if len(unused) > 1 else ''} "
                     f"{', '.join(repr(name) for name in unused)} "
                     f"{'are' if len(unused) > 1 else 'is'} not used: identification reads t, "
                     "x or v, F and normal_load.")
    return _checked(t, force, x, v, load)


def _checked(t, force, x, v, normal_load, where: str = "") -> _Data:
    """A _Data after the checks that make a record worth fitting (named for ``where``)."""
    n = t.shape[0]
    if n < 3:
        raise InputError(f"Identification needs at least 3 samples{where}. Got {n} samples "
                         "of 't'.")
    make_path(t, x=x, v=v)          # t strictly increasing, named in the error
    if x is not None and np.ptp(x) == 0.0:
        raise InputError(f"The 'x' samples{where} never change (all {float(x[0])!r}): the data "
                         "hold no motion, so no friction parameter can be identified.")
    if v is not None and not np.any(v):
        raise InputError(f"The 'v' samples{where} are all 0: the data hold no motion, so no "
                         "friction parameter can be identified.")
    if np.ptp(force) == 0.0:
        raise InputError(f"The 'F' samples{where} are all equal ({float(force[0])!r}): a "
                         "constant force carries no information to identify parameters from.")
    return _Data(t=t, force=force, x=x, v=v, normal_load=normal_load)


def _typical_scale(unit: str, data: _Data) -> float:
    """A natural size for a parameter of this unit in these data (linear scaling of a 0 start)."""
    path = data.path()
    force = float(np.sqrt(np.mean(data.force ** 2)))
    speed = float(np.sqrt(np.mean(path.sample_velocity ** 2))) or 1.0
    span = float(np.ptp(path.x)) or 1.0
    duration = float(data.t[-1] - data.t[0])
    return {"N": force, "N s/m": force / speed, "N/m": force / span, "m/s": speed, "m": span,
            "N/s": force / duration, "s": duration}.get(unit, 1.0) or 1.0


# --- default bounds from the data -------------------------------------------------------------

@dataclass(frozen=True)
class _Scales:
    """The sizes of a record that the default bounds are derived from."""

    force: float       # A: the force amplitude, max |F| [N]
    speed: float       # V: the largest sample speed [m/s]
    span: float        # L: the displacement range, max x - min x [m]
    step: float        # h: the median time step [s]

    @classmethod
    def of(cls, data: _Data) -> "_Scales":
        path = data.path()
        return cls(force=data.scale, speed=float(np.max(np.abs(path.sample_velocity))),
                   span=float(np.ptp(path.x)), step=float(np.median(np.diff(data.t))))


@dataclass(frozen=True)
class _Rule:
    """Default bounds ``[low, high] x scale`` of a parameter unit; ``scale`` from the data."""

    scale: object            # _Scales -> float
    low: float
    high: float
    words: str               # what the scale is, for the warnings

    def describe(self, factor: float, scale: float, unit: str) -> str:
        return f"{factor:g} x {scale:.4g} {unit}, {self.words}"


#: The default bounds of a free parameter without [fit.bounds], by the unit of its
#: declaration (never an unbounded range).  The documentation's file formats page shows
#: this table (docs/_ext/polind_docs.py reads it).
DEFAULT_RANGES = {
    "N": _Rule(lambda s: s.force, 1e-3, 10.0, "the force amplitude A = max |F|"),
    "m/s": _Rule(lambda s: s.speed, 1e-3, 10.0, "the largest speed V of the record"),
    "N s/m": _Rule(lambda s: s.force / s.speed, 1e-3, 10.0, "A / V (force amplitude / speed)"),
    "N/m": _Rule(lambda s: s.force / s.span, 1e-2, 1e6,
                 "A / L (force amplitude / displacement range)"),
    "m": _Rule(lambda s: s.span, 1e-6, 10.0, "the displacement range L"),
    "N/s": _Rule(lambda s: s.force / s.step, 1e-6, 1e3, "A / h (force amplitude / time step)"),
    "s": _Rule(lambda s: s.step, 0.1, 1e6, "the median time step h"),
}
#: Any other unit (dimensionless, or one the record gives no scale of: 1/m^2, m^2, Pa):
#: a decade either side of the start.
UNSCALED_RANGE = (0.1, 10.0)


def _default_range(declaration: Param, start: np.ndarray, scales: _Scales):
    """``(low, high, low_origin, high_origin)``: the default bounds of a free parameter."""
    kind_low, kind_high = _KIND_BOUNDS[declaration.bound]
    if math.isfinite(kind_low) and math.isfinite(kind_high):
        origin = f"the end of the range of a {declaration.bound} parameter"
        return kind_low, kind_high, origin, origin
    rule = DEFAULT_RANGES.get(declaration.unit)
    if rule is not None:
        scale = rule.scale(scales)
        low, high = rule.low * scale, rule.high * scale
        low_origin, high_origin = (
            f"the default from the data: {rule.describe(factor, scale, declaration.unit)}"
            for factor in (rule.low, rule.high))
    else:
        size = np.abs(start)
        smallest = float(size[size > 0].min()) if np.any(size > 0) else 1.0
        largest = float(size.max()) if np.any(size > 0) else 1.0
        low, high = UNSCALED_RANGE[0] * smallest, UNSCALED_RANGE[1] * largest
        low_origin = f"the default, {UNSCALED_RANGE[0]:g} x the start"
        high_origin = f"the default, {UNSCALED_RANGE[1]:g} x the start"
    if declaration.bound == "nonnegative":
        low, low_origin = 0.0, "0: the parameter cannot be negative"
    elif declaration.bound == "any":
        low, low_origin = -high, high_origin.replace("default", "default (negated)", 1)
    return low, high, low_origin, high_origin


# --- free keys, bounds and their mapping to the optimiser's variables -------------------------

def _fittable_keys(model: FrictionModel) -> list[str]:
    def walk(entries, prefix):
        for entry in entries:
            if isinstance(entry, Table):
                yield from walk(entry.entries, f"{prefix}{entry.key}.")
            elif entry.kind in ("float", "list", "pair") and entry.fittable:
                yield f"{prefix}{entry.key}"
    return list(walk(model.parameters, ""))


def _get(params: dict, key: str):
    value = params
    for part in key.split("."):
        value = value[part]
    return value


def _has(params: dict, key: str) -> bool:
    try:
        _get(params, key)
    except (KeyError, TypeError):
        return False
    return True


def _set(params: dict, key: str, value) -> None:
    *parents, last = key.split(".")
    table = params
    for part in parents:
        table = table[part]
    table[last] = value


def _flatten(table: Mapping, prefix: str = "") -> dict:
    """Nested tables (TOML dotted keys) to dotted names: ``surface.height_std``."""
    flat = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            flat.update(_flatten(value, f"{prefix}{key}."))
        else:
            flat[f"{prefix}{key}"] = value
    return flat


@dataclass
class _Free:
    """One free key and its mapping ``u -> physical value`` (``u = 0`` is the start)."""

    key: str
    start: np.ndarray                  # physical start values (1-D)
    is_list: bool
    mapping: str                       # "log", "linear" or "simplex"
    low: float
    high: float
    scale: float = 1.0
    low_origin: str = ""               # where each bound comes from, for the warnings
    high_origin: str = ""

    @property
    def size(self) -> int:
        return self.start.size - 1 if self.mapping == "simplex" else self.start.size

    def physical(self, u: np.ndarray) -> np.ndarray:
        if self.mapping == "log":
            return self.start * np.exp(np.clip(u, -_LOG_LIMIT, _LOG_LIMIT))
        if self.mapping == "linear":
            return self.start + self.scale * u
        logits = np.log(self.start) - math.log(self.start[-1]) + np.append(u, 0.0)
        weights = np.exp(logits - logits.max())
        return weights / weights.sum()

    def derivative(self, u: np.ndarray) -> np.ndarray:
        """d(physical)/du, shape (start.size, size)."""
        value = self.physical(u)
        if self.mapping == "log":
            return np.diag(value)
        if self.mapping == "linear":
            return np.eye(self.size) * self.scale
        return (np.diag(value) - np.outer(value, value))[:, :-1]

    def internal_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        if self.mapping == "simplex":
            return np.full(self.size, -np.inf), np.full(self.size, np.inf)
        with np.errstate(divide="ignore"):
            if self.mapping == "log":
                low = np.log(self.low / self.start) if self.low > 0.0 else np.full(self.size,
                                                                                  -np.inf)
                high = np.log(self.high / self.start)
            else:
                low = (self.low - self.start) / self.scale
                high = (self.high - self.start) / self.scale
        return np.minimum(low, 0.0), np.maximum(high, 0.0)

    def output(self, values: np.ndarray):
        return [float(v) for v in values] if self.is_list else float(values[0])


def _free_keys(model: FrictionModel, free) -> list[str]:
    if free is None:
        # The model's default free keys that its parameters have (a Pol-Ind model
        # on a file of measured summits has no surface.height_std).
        params = model.params
        free = [key for key in model.fit_defaults if _has(params, key)]
        if not free:
            raise InputError(f"Name the free parameters of the {model.type} model: give "
                             "'free' (a list of keys) or a model document with a [fit] table.")
    if isinstance(free, str):
        free = [free]
    if not isinstance(free, (list, tuple)) or not free:
        raise InputError(f"The 'free' list of [fit] must be a non-empty list of parameter keys. "
                         f"Got {describe(free)} instead.")
    keys = []
    params = model.params
    for key in free:
        if not isinstance(key, str):
            raise InputError(f"The 'free' list of [fit] must hold parameter keys (strings). "
                             f"Got {describe(key)} instead.")
        if key in keys:
            raise InputError(f"The free key '{key}' appears twice in the 'free' list of [fit].")
        declaration = model.declaration(key)
        if declaration is None:
            raise InputError(f"The free key '{key}' is not a parameter of the {model.type} "
                             f"model; expected one of: {', '.join(_fittable_keys(model))}.")
        if isinstance(declaration, Table):
            entries = ", ".join(f"'{key}.{entry.key}'" for entry in declaration.entries)
            raise InputError(f"The free key '{key}' of {model.type} is a table; name its "
                             f"entries instead ({entries}).")
        if declaration.kind not in ("float", "list", "pair"):
            what = {"int": "an integer", "str": "a choice of words", "path": "a file"}
            raise InputError(f"The free key '{key}' of {model.type} is "
                             f"{what.get(declaration.kind, declaration.kind)}, not a continuous "
                             "parameter; only numbers and lists of numbers can be identified.")
        try:
            _get(params, key)
        except (KeyError, TypeError):
            # An optional table the model does not have ([model.compliance]).
            *parents, last = key.split(".")
            table = f"[model.{'.'.join(parents)}]" if parents else "[model]"
            raise InputError(f"The free key '{key}' of {model.type} has no starting value; "
                             f"give '{last}' a value in {table} of the model.") from None
        keys.append(key)
    model.check_free_keys(keys)
    return keys


def _pair(key: str, value) -> tuple[float, float]:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or any(isinstance(b, bool) or not isinstance(b, (int, float, np.integer,
                                                              np.floating)) for b in value)):
        raise InputError(f"The bounds of '{key}' in [fit.bounds] must be a pair [low, high] of "
                         f"numbers. Got {describe(value)} instead.")
    low, high = float(value[0]), float(value[1])
    if math.isnan(low) or math.isnan(high):
        raise InputError(f"The bounds of '{key}' in [fit.bounds] must be numbers, not NaN. "
                         f"Got {describe(value)} instead.")
    if not low < high:
        raise InputError(f"The bounds of '{key}' in [fit.bounds] must have low < high. "
                         f"Got [{low!r}, {high!r}] instead.")
    return low, high


def _bounds(model: FrictionModel, keys: list[str], bounds) -> dict[str, tuple[float, float]]:
    """Check [fit.bounds]: free keys only, pairs low < high that hold the starting value."""
    if bounds is None:
        return {}
    if not isinstance(bounds, Mapping):
        raise InputError(f"The [fit.bounds] table must map free keys to [low, high]. Got "
                         f"{describe(bounds)} instead.")
    flat = _flatten(bounds)
    for key in flat:
        if key not in keys:
            raise InputError(f"The bounds key '{key}' in [fit.bounds] is not a free key; "
                             f"free keys: {', '.join(keys)}.")
        if key in model.simplex_keys:
            raise InputError(f"The bounds key '{key}' in [fit.bounds] takes no bounds: the "
                             "weights are kept positive and summing to 1 by construction.")
    pairs = {key: _pair(key, value) for key, value in flat.items()}
    params = model.params
    for key, (low, high) in pairs.items():
        declaration = model.declaration(key)
        if declaration is not None and declaration.bound in ("positive", "nonnegative") \
                and low < 0.0:
            raise InputError(f"The bounds of '{key}' in [fit.bounds] must have low >= 0: the "
                             f"parameter is {declaration.bound}. Got [{low!r}, {high!r}] "
                             "instead.")
        start = np.atleast_1d(np.asarray(_get(params, key), dtype=np.float64))
        outside = (start < low) | (start > high)
        if np.any(outside):
            raise InputError(f"The bounds [{low!r}, {high!r}] of '{key}' in [fit.bounds] "
                             f"exclude its starting value {float(start[np.argmax(outside)])!r}.")
    return pairs


def _build_free(model: FrictionModel, keys, bounds, data: _Data,
                notes: list | None = None) -> list[_Free]:
    """The free keys with their mappings and bounds: given ones, else the defaults.

    A start outside its default bounds widens them to include it (with a note).
    """
    params = model.params
    scales = _Scales.of(data)
    frees = []
    for key in keys:
        declaration: Param = model.declaration(key)
        value = _get(params, key)
        is_list = isinstance(value, list)
        start = np.atleast_1d(np.asarray(value, dtype=np.float64))
        kind_low, kind_high = _KIND_BOUNDS[declaration.bound]
        if key in model.simplex_keys:
            # Positive and summing to 1 by construction: (0, 1), never reached.
            mapping = "simplex"
            low, high, low_origin, high_origin = 0.0, 1.0, "", ""
        else:
            mapping = "log" if declaration.bound == "positive" else "linear"
            if key in bounds:
                low, high = max(kind_low, bounds[key][0]), min(kind_high, bounds[key][1])
                low_origin = high_origin = "given in [fit.bounds]"
            else:
                low, high, low_origin, high_origin = _default_range(declaration, start, scales)
                # (not for a start that misses by rounding: 1e-3 V is the start 1e-4 itself)
                below = float(start.min()) < low * (1.0 - 1e-9)
                above = float(start.max()) > high * (1.0 + 1e-9)
                if (below or above) and notes is not None:
                    notes.append(f"The start {describe(value)} of '{key}' lies outside its "
                                 f"default bounds [{low:.4g}, {high:.4g}] derived from the data; "
                                 "they were widened to include it. Check the start, or give "
                                 f"'{key}' in [fit.bounds].")
                if below:
                    low, low_origin = float(start.min()), "the start, below the default"
                if above:
                    high, high_origin = float(start.max()), "the start, above the default"
        nonzero = np.abs(start[start != 0.0])
        scale = float(nonzero.mean()) if nonzero.size else _typical_scale(declaration.unit, data)
        frees.append(_Free(key, start, is_list, mapping, low, high, scale, low_origin,
                           high_origin))
    return frees


def default_bounds(model, data, *, free=None) -> dict[str, tuple[float, float]]:
    """The bounds a fit without ``[fit.bounds]`` gives each free key, from the data.

    By the unit the model declares for the parameter, with ``A = max |F|``
    the force amplitude, ``V`` the largest speed, ``L`` the displacement
    range (``max x - min x``) and ``h`` the median time step of the data:

    ======== ================================== =========================================
    unit     range                              e.g.
    ======== ================================== =========================================
    N        [1e-3, 10] x A                     ``coulomb_force``, ``static_force``
    m/s      [1e-3, 10] x V                     ``stribeck_velocity``
    N s/m    [1e-3, 10] x A / V                 ``viscous_coefficient``, ``bristle_damping``
    N/m      [1e-2, 1e6] x A / L                ``stiffness``, ``compliance.stiffness``
    m        [1e-6, 10] x L                     ``surface.height_std``
    N/s      [1e-6, 1e3] x A / h                ``attraction``
    s        [0.1, 1e6] x h                     (a time constant)
    other    [0.1, 10] x the start              friction coefficients, exponents, moduli
    ======== ================================== =========================================

    A parameter that cannot be negative (``viscous_coefficient``,
    ``bristle_damping``) keeps 0 as its lower bound; one whose kind has a
    finite range (a Poisson ratio) keeps that range; a parameter of any sign
    gets ``[-high, high]``; the weights of GMS take no bounds (they stay
    in (0, 1) and sum to 1 by construction).  For a list key the range holds
    every entry (``other``: from its smallest to its largest start).  A start
    outside its range widens the range to include it, with a warning.  With
    a hold-out the scales come from the fitted part only.

    Parameters
    ----------
    model : FrictionModel or dict
        A model or a model document, as :func:`identify` takes it.
    data : mapping of str to array_like, or a data frame
        As :func:`identify`.
    free : list of str, optional
        The free keys (default: the document's ``[fit] free`` or the model's
        ``fit_defaults``).

    Returns
    -------
    dict
        ``{key: (low, high)}`` for each free key (``(0, 1)`` for the weights
        of GMS), in the parameter's unit.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import default_bounds
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> data = {"t": t, "x": 1e-3 * np.sin(2 * np.pi * t), "F": 2.0 * np.cos(2 * np.pi * t)}
    >>> default_bounds(model, data)
    {'coulomb_force': (0.002, 20.0)}
    """
    start, keys, _ = parse_fit(model, free=free)
    measured = measured_data(data, model=start)
    return {free.key: (float(free.low), float(free.high))
            for free in _build_free(start, keys, {}, measured)}


def _split(frees: list[_Free], u: np.ndarray) -> list[np.ndarray]:
    out, offset = [], 0
    for free in frees:
        out.append(u[offset:offset + free.size])
        offset += free.size
    return out


def _model_at(model: FrictionModel, frees: list[_Free], u: np.ndarray) -> FrictionModel:
    start = model.params
    params = model.params
    for free, part in zip(frees, _split(frees, u)):
        _set(params, free.key, free.output(free.physical(part)))
    model.couple_fit(params, [free.key for free in frees], start)
    return type(model)(**params)


# --- the result -----------------------------------------------------------------------------

@dataclass(frozen=True)
class FitResult:
    """The outcome of an identification.

    Attributes
    ----------
    model : FrictionModel
        The model with the identified values.
    start : FrictionModel
        The starting model.
    free : tuple of str
        The identified keys (dotted for nested ones).
    bounds : dict
        The bounds given per key, ``[low, high]`` (keys without bounds absent).
    values, standard_errors : dict
        Per free key its identified value and standard error (floats, or
        lists for list keys), in the parameter's unit.  An infinite standard
        error marks a value the data do not determine.
    rms_error : float
        Root-mean-square of ``F_model - F_measured`` over the fitted samples [N].
    iterations : int
        Iterations of the trust-region-reflective solver (its Jacobian
        evaluations, one per iteration).
    evaluations : int
        Model simulations in all, finite-difference ones included.
    success : bool
        Whether the solver met a convergence test (not the evaluation limit).
    message : str
        The solver's reason for stopping.
    force : ndarray
        The fitted model's force at every sample of the data [N] (with a
        hold-out, the fitted part and the prediction of the rest, one run).
    warnings : tuple of str
        What the user should know about the fit (:ref:`guide-fit-warnings`): a
        parameter at a bound, one the data do not determine, a column or
        signal the model does not use, ...; empty when all is well.
    holdout_rms_error : float or None
        RMS of ``F_model - F_measured`` over the held-out samples [N]; None
        without a hold-out.
    fitted_samples : int
        The number of samples fitted (the first ones of the data).
    parameter_count : int
        The number of free values the solver varied (a list key counts its
        entries; the GMS weights, which sum to 1, one fewer).
    """

    model: FrictionModel
    start: FrictionModel
    free: tuple
    bounds: dict
    values: dict
    standard_errors: dict
    rms_error: float
    iterations: int
    evaluations: int
    success: bool
    message: str
    force: np.ndarray = field(repr=False)
    warnings: tuple = ()
    holdout_rms_error: float | None = None
    fitted_samples: int = 0
    parameter_count: int = 0

    def __repr__(self):
        held_out = ("" if self.holdout_rms_error is None
                    else f", holdout_rms_error {self.holdout_rms_error:.4g} N")
        return (f"FitResult({self.model.type}, free {', '.join(self.free) or 'nothing'} "
                f"({self.parameter_count} values), rms_error {self.rms_error:.4g} N"
                f"{held_out} on {self.fitted_samples} samples, "
                f"{'converged' if self.success else 'not converged'} after "
                f"{self.iterations} iterations, {len(self.warnings)} warnings)")

    @property
    def aic(self) -> float:
        """Akaike's information criterion of the fitted part (lower is better).

        ``n ln(RSS / n) + 2 k``: minus twice the Gaussian log-likelihood of the
        ``n`` fitted residuals at the maximum-likelihood variance ``RSS / n``,
        without the constant ``n (1 + ln 2 pi)`` that every model fitted to
        the same samples shares, plus twice the ``k`` free values
        (``parameter_count``).  Only differences between models fitted
        to the same samples mean anything.
        """
        n = self.fitted_samples
        return n * math.log(self.rms_error ** 2) + 2.0 * self.parameter_count \
            if self.rms_error > 0.0 else -math.inf

    @property
    def bic(self) -> float:
        """The Bayesian (Schwarz) criterion: ``n ln(RSS / n) + k ln n``, as :attr:`aic`."""
        n = self.fitted_samples
        return n * math.log(self.rms_error ** 2) + self.parameter_count * math.log(n) \
            if self.rms_error > 0.0 else -math.inf

    def to_fit_table(self) -> dict:
        """The ``[fit.result]`` table of a fitted model file (:ref:`formats-fit`).

        ``{"rms_error": ..., "holdout_rms_error": ... (with a hold-out),
        "iterations": ..., "warnings": [...], key: {"value": ...,
        "standard_error": ...}, ...}``; a dotted key stays one key
        (``[fit.result."surface.height_std"]`` in TOML).
        """
        table = {"rms_error": float(self.rms_error)}
        if self.holdout_rms_error is not None:
            table["holdout_rms_error"] = float(self.holdout_rms_error)
        table["iterations"] = int(self.iterations)
        table["warnings"] = list(self.warnings)
        for key in self.free:
            table[key] = {"value": self.values[key], "standard_error": self.standard_errors[key]}
        return table

    def to_document(self) -> dict:
        """The model-file document ``polind fit`` writes.

        ``[model]`` with the identified values, ``[fit]`` with ``free``, the
        given ``bounds`` (if any) and ``result`` (:meth:`to_fit_table`).  Write
        it with :func:`polind.io.write_model_file`; read back with
        :func:`polind.load_model` (the ``[fit]`` table is ignored there) or
        passed again to :func:`identify` to continue from the identified values.
        """
        fit = {"free": list(self.free)}
        if self.bounds:
            fit["bounds"] = {key: list(pair) for key, pair in self.bounds.items()}
        fit["result"] = self.to_fit_table()
        return {"model": self.model.to_dict()["model"], "fit": fit}

    def summary(self) -> str:
        """A few lines for a terminal: the RMS errors and each key's value and standard error."""
        held_out = ("" if self.holdout_rms_error is None
                    else f", holdout_rms_error = {self.holdout_rms_error:.6g} N")
        lines = [f"{self.model.type}: rms_error = {self.rms_error:.6g} N{held_out}, "
                 f"iterations = {self.iterations}" + ("" if self.success else
                                                      f" (stopped: {self.message})")]
        for key in self.free:
            value = np.atleast_1d(self.values[key])
            error = np.atleast_1d(self.standard_errors[key])
            shown = ", ".join(f"{a:.6g} +- {b:.2g}" for a, b in zip(value, error))
            lines.append(f"  {key} = {shown}")
        return "\n".join(lines)


def _standard_errors(frees, u, jac, residual) -> list[np.ndarray]:
    """Physical standard errors from the Jacobian in the optimiser's variables (delta method)."""
    n, p = jac.shape
    variance = float(residual @ residual) / (n - p)
    _, singular, vt = np.linalg.svd(jac, full_matrices=False)
    tol = singular.max(initial=0.0) * max(n, p) * np.finfo(float).eps
    kept = singular > tol
    transform = np.zeros((sum(f.start.size for f in frees), p))
    row = col = 0
    for free, part in zip(frees, _split(frees, u)):
        block = free.derivative(part)
        transform[row:row + block.shape[0], col:col + block.shape[1]] = block
        row, col = row + block.shape[0], col + block.shape[1]
    mapped = transform @ vt[kept].T / singular[kept]
    errors = np.sqrt(variance * np.sum(mapped ** 2, axis=1))
    if not kept.all():
        undetermined = np.any(np.abs(transform @ vt[~kept].T) > 1e-8 * np.abs(transform).max(),
                              axis=1)
        errors[undetermined] = np.inf
    out, row = [], 0
    for free in frees:
        out.append(errors[row:row + free.start.size])
        row += free.start.size
    return out


def _fit_warnings(model, frees, values, errors, success, message) -> list[str]:
    """A parameter at a bound, a parameter the data do not determine, a solver stopped early."""
    notes = []
    if not success:
        notes.append(f"The solver stopped before converging ({message}); the values are its "
                     "last iterate. Allow more evaluations or start closer.")
    for free, value, error in zip(frees, values, errors):
        several = value.size > 1
        for index, (entry, spread) in enumerate(zip(value, error)):
            name = f"{free.key}[{index}]" if several else free.key
            for side, bound, origin in (("lower", free.low, free.low_origin),
                                        ("upper", free.high, free.high_origin)):
                if (free.mapping == "simplex" or not math.isfinite(bound)
                        or (free.mapping == "log" and bound <= 0.0)):
                    continue
                tolerance = 1e-6 * (abs(bound) if bound != 0.0 else free.scale)
                if abs(entry - bound) <= tolerance:
                    notes.append(f"The '{name}' parameter of {model.type} ended at its {side} "
                                 f"bound {bound:.6g} ({origin}); the data would move it "
                                 "further: widen its [fit.bounds] or fix it.")
            if not math.isfinite(spread) or spread > abs(entry):
                why = ("a standard error that is not finite" if not math.isfinite(spread)
                       else f"a standard error of {spread:.2g}, larger than the value")
                notes.append(f"The '{name}' parameter of {model.type} is not identifiable from "
                             f"these data ({entry:.6g} with {why}); fix it, or fit data that "
                             "excite it.")
    return notes


def _result(model, start, frees, u, bounds, force, data, iterations, evaluations, success,
            message, jac=None, notes=(), record=None):
    """The FitResult; with ``record`` (the whole data of a hold-out split) its tail is scored."""
    residual = force - data.force
    values, standard_errors, physical, spreads = {}, {}, [], []
    errors = (_standard_errors(frees, u, jac, residual) if jac is not None
              else [np.full(free.start.size, np.nan) for free in frees])
    for free, part, error in zip(frees, _split(frees, u), errors):
        value = free.physical(part)
        values[free.key] = free.output(value)
        standard_errors[free.key] = free.output(error)
        physical.append(value)
        spreads.append(error)
    notes = list(notes)
    if jac is not None:
        notes += _fit_warnings(model, frees, physical, spreads, success, message)
    held_out = None
    if record is not None:
        # The held-out prediction continues the fitted part: one run over the whole record.
        whole = record.simulate(model)
        tail = whole[data.size:] - record.force[data.size:]
        held_out = float(np.sqrt(np.mean(tail ** 2)))
        force = whole
    return FitResult(model=model, start=start, free=tuple(f.key for f in frees),
                     bounds={key: tuple(pair) for key, pair in bounds.items()}, values=values,
                     standard_errors=standard_errors,
                     rms_error=float(np.sqrt(np.mean(residual ** 2))), iterations=int(iterations),
                     evaluations=int(evaluations), success=bool(success), message=str(message),
                     force=force, warnings=tuple(notes), holdout_rms_error=held_out,
                     fitted_samples=int(data.size),
                     parameter_count=int(sum(free.size for free in frees)))


# --- nonlinear least squares ------------------------------------------------------------------

def _model_and_fit_table(model):
    """A model and the [fit] table of a model document (empty for a bare model)."""
    if isinstance(model, FrictionModel):
        return model, {}
    if not isinstance(model, Mapping):
        raise InputError(f"The 'model' must be a polind model or a model document "
                         f"({{'model': {{...}}, 'fit': {{...}}}}). Got {describe(model)} instead.")
    document = dict(model)
    fit = document.get("fit", {}) if "model" in document else {}
    if not isinstance(fit, Mapping):
        raise InputError(f"The [fit] table must be a table with 'free' and optionally 'bounds'. "
                         f"Got {describe(fit)} instead.")
    for key in fit:
        if key not in _FIT_KEYS:
            raise InputError(f"Unknown key 'fit.{key}' in the [fit] table; expected 'free' and "
                             "optionally 'bounds' (a previous 'result' is ignored).")
    return model_from_dict(document), dict(fit)


def parse_fit(model, *, free=None, bounds=None) -> tuple[FrictionModel, list[str], dict]:
    """Check the model side of an identification: the model, its free keys and bounds.

    :func:`identify` calls it first; the command line calls it on its own to
    blame the model file (and not the data file) for a bad ``[fit]`` table.

    Parameters
    ----------
    model : FrictionModel or dict
        A model, or a model document with an optional ``[fit]`` table.
    free, bounds
        As :func:`identify` (given, they replace the document's).

    Returns
    -------
    (FrictionModel, list of str, dict)
        The starting model, the free keys, and the bounds ``{key: (low, high)}``.

    Raises
    ------
    InputError
        Naming the key: bad parameters, an unknown key in ``[fit]``, a free
        key the model does not have or that is not a number or a list of
        numbers, a free key twice, bounds for a key that is not free, bounds
        that are not a pair, have ``low >= high`` or exclude the starting value.
    """
    start, fit = _model_and_fit_table(model)
    keys = _free_keys(start, free if free is not None else fit.get("free"))
    pairs = _bounds(start, keys, bounds if bounds is not None else fit.get("bounds"))
    return start, keys, pairs


# What a fit holds per sample of the data [bytes] (tracemalloc's peak: 528 bytes at 8 free
# values, 1873 at 32): the data's checked copies and paths, one simulation with its
# residual on each Jacobian thread, and per free value the Jacobian's column, its stacked
# copy and the solver's scaled copies and factors.
_FIT_BYTES = 96.0
_FIT_BYTES_PER_THREAD = 40.0
_FIT_BYTES_PER_VALUE = 64.0
# The element fit per sample (480 bytes at 24 slip distances): the data and a path, and
# per slip distance the unit element's response, its stacked and scaled copies.
_ELEMENT_FIT_BYTES = 96.0
_ELEMENT_FIT_BYTES_PER_COLUMN = 24.0


def fit_bytes_per_sample(model: FrictionModel, free) -> float:
    """The memory :func:`identify` holds per sample of the data [bytes], an estimate.

    ``model`` and ``free`` as :func:`parse_fit` returns them: each free key
    counts its values (an element list each element), and the Jacobian's
    threads are counted as if every core ran one.
    """
    values = sum(np.atleast_1d(np.asarray(_get(model.params, key))).size for key in free)
    threads = max(1, min(os.cpu_count() or 1, values))
    return _FIT_BYTES + _FIT_BYTES_PER_THREAD * threads + _FIT_BYTES_PER_VALUE * values


def holdout_split(holdout, size: int) -> int | None:
    """The number of fitted samples for a hold-out fraction (None: fit them all)."""
    if holdout is None:
        return None
    if (isinstance(holdout, bool) or not isinstance(holdout, (int, float, np.integer,
                                                              np.floating))
            or not 0.0 < float(holdout) < 1.0):
        raise InputError(f"The 'holdout' fraction must be a number between 0 and 1 (exclusive): "
                         f"the share of the samples, at the end, kept out of the fit. Got "
                         f"{describe(holdout)} instead.")
    fitted = int(round((1.0 - float(holdout)) * size))
    if fitted >= size:
        raise InputError(f"The 'holdout' fraction {float(holdout)!r} of {size} samples holds "
                         "out none of them; expected a larger fraction or more samples.")
    return fitted


#: A simulation of the data shorter than this [s] runs the Jacobian on one thread by
#: default: the threads' overhead, and their contention with the BLAS's own threads
#: (which spin between the solver's matrix products), eat the gain.
_THREADED_SIMULATION = 5e-3


def _worker_count(workers, columns: int, seconds: float) -> int:
    """Threads for the Jacobian's columns (``seconds``: one simulation of the data)."""
    if workers is None:
        if seconds < _THREADED_SIMULATION:
            return 1
        return max(1, min(os.cpu_count() or 1, columns))
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise InputError(f"The number of 'workers' must be a positive integer. Got "
                         f"{describe(workers)} instead.")
    return int(min(workers, max(columns, 1)))


def identify(model, data, *, free=None, bounds=None, holdout=None, max_evaluations=None,
             tolerance=1e-8, diff_step=1e-6, x_scale=1.0, callback=None,
             workers=None) -> FitResult:
    """Identify free parameters of a friction model from measured force.

    Bounded nonlinear least squares on ``F_model(t; p) - F_measured``
    (``scipy.optimize.least_squares``, trust-region-reflective, Jacobian by
    forward differences), started from the model's current values.  The
    simulation starts from rest (all internal states zero) at the first
    sample, so the record should start with the contact at rest or
    its first sliding stroke will take a transient to forget the start.

    Parameters
    ----------
    model : FrictionModel or dict
        The starting point: a model, or a model document ``{"model": {...},
        "fit": {"free": [...], "bounds": {...}}}`` as read from a model file
        (:func:`polind.io.read_model_file`).
    data : mapping of str to array_like, or a pandas DataFrame
        ``t`` [s] strictly increasing, exactly one of ``x`` [m] and ``v``
        [m/s], ``F`` [N] the measured friction force (positive when it resists
        positive motion), optionally ``normal_load`` [N] (a positive load at
        every sample).  A model that ignores a normal load (one without
        ``reference_load``, except pol-ind) is fitted without the column,
        with a warning.  A data frame (anything with ``columns`` that is not
        a mapping; pandas is not imported) may hold other columns too: they
        are not used and the warnings name them.  A mapping must hold the
        data columns only.
    free : list of str, optional
        Keys to identify, dotted for nested keys (``"surface.height_std"``,
        ``"compliance.stiffness"``); a list-valued key (``stiffness``) is free
        as a whole vector.  Default: the document's ``[fit] free``; without
        one (a bare model, or no ``free`` in ``[fit]``), the model's own
        ``fit_defaults`` (:class:`polind.FrictionModel`).
    bounds : dict, optional
        Per free key ``[low, high]`` in the parameter's unit (one pair for all
        entries of a list key).  Default: the document's ``[fit.bounds]``; a
        free key without bounds gets the default bounds derived from the
        data by its unit (:func:`~polind.identification.default_bounds`), never an unbounded range.
    holdout : float, optional
        A fraction ``F`` in (0, 1): fit the first ``round((1 - F) n)`` of the
        ``n`` samples (the earliest: ``t`` increases) and report the RMS error
        on the rest as ``holdout_rms_error``.  The held-out prediction
        continues the fitted part: the fitted model is simulated over the
        whole record from rest, one run, and its tail is scored (not a run
        restarted from rest at the split).  The default bounds come from the
        fitted part only.
    max_evaluations : int, optional
        Most solver function evaluations (``max_nfev``; default
        ``100 * number of variables``).
    tolerance : float
        ``ftol`` and ``xtol`` of the solver (relative change of the cost and
        of the variables).
    diff_step : float
        Step of the forward-difference Jacobian in the optimiser's variables:
        a log-scaled parameter moves by ``diff_step`` relatively, a linear one
        by ``diff_step`` times its scale.
    x_scale : float or "jac"
        The solver's variable scaling (``least_squares``'s ``x_scale``); the
        default 1 trusts the parametrisation above (one unit of each variable
        is a factor e, or one scale, of its parameter).
    callback : callable, optional
        Called as ``callback(evaluations, rms_error)`` after each simulation
        (e.g. to drive a progress bar; calls are serialised, but may come
        from worker threads); ``rms_error`` is ``inf`` at a trial point
        whose parameters the model rejects (such points cost the solver a
        large constant residual, so it backs off).
    workers : int, optional
        Threads that simulate the columns of the finite-difference Jacobian
        side by side (the numba kernels release the GIL).  Default: the
        number of cores, at most one per column, when one simulation of the
        data takes more than 5 ms (a long record, Pol-Ind under a varying
        load); one thread for quicker ones, where the threads' overhead and
        the BLAS's own threads eat the gain.  The result does not depend on
        it.

    Returns
    -------
    FitResult
        Its ``warnings`` are also issued as ``UserWarning``.

    Raises
    ------
    InputError
        Bad data (too few samples, fewer than free values + 1, no motion, a
        constant force, NaN, non-increasing ``t``), a bad ``holdout``, or a
        bad ``[fit]`` (unknown or non-numeric free key, a free key without a
        starting value, bounds for a key that is not free, low >= high,
        bounds that exclude the starting value), naming the key or column;
        a fit whose estimated memory (``fit_bytes_per_sample`` times the
        samples) passes the limit of :mod:`polind.resources`.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import identify
    >>> true = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                          "coulomb_force": 1.0}})
    >>> t = np.linspace(0.0, 2.0, 201)
    >>> x = 1e-4 * np.sin(np.pi * t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    >>> start = true.with_params(stiffness=3e4, coulomb_force=2.0)
    >>> fit = identify(start, data, free=["stiffness", "coulomb_force"])
    >>> round(fit.values["stiffness"]), round(fit.values["coulomb_force"], 6)
    (100000, 1.0)
    >>> fit.warnings
    ()
    """
    from scipy.optimize import least_squares

    max_evaluations = None if max_evaluations is None else check_number(
        "identify", "max_evaluations", max_evaluations, "positive", integer=True)
    tolerance = check_number("identify", "tolerance", tolerance, "positive")
    if tolerance < 1e-15:
        raise InputError(f"The 'tolerance' parameter of identify must be at least 1e-15 (above "
                         f"machine precision). Got {tolerance!r} instead.")
    diff_step = check_number("identify", "diff_step", diff_step, "positive")
    if diff_step >= 1.0:
        raise InputError(f"The 'diff_step' parameter of identify must be below 1 (a relative "
                         f"step). Got {diff_step!r} instead.")
    start, keys, given_bounds = parse_fit(model, free=free, bounds=bounds)
    notes = []
    record = measured_data(data, model=start, notes=notes)
    fitted_samples = holdout_split(holdout, record.size)
    measured = record if fitted_samples is None else record.head(fitted_samples)
    frees = _build_free(start, keys, given_bounds, measured, notes)
    n_variables = sum(f.size for f in frees)
    check_memory(record.size * fit_bytes_per_sample(start, keys),
                 f"Fitting {n_variables} free values to {record.size:.3g} samples of data")
    if measured.size <= n_variables:
        raise InputError(f"Identification of {n_variables} parameter values needs more samples "
                         f"than that. Got {measured.size} samples of 't'"
                         + ("." if fitted_samples is None else " in the fitted part."))
    low, high = (np.concatenate(parts) if parts else np.empty(0)
                 for parts in zip(*(f.internal_bounds() for f in frees)))

    # The solver's variables are 1 + u (u = 0 at the start): its first trust radius is
    # |x0| (one unit per variable: a factor e for a log-scaled parameter), and x0 stays
    # away from 0 where scipy's relative steps would vanish.
    low, high = low + 1.0, high + 1.0
    evaluations = 0
    counting = threading.Lock()
    last = {}
    threads = pool = None        # the Jacobian's worker threads, while the solver runs
    # What a trial point the model rejects (e.g. a load its surface cannot carry) or
    # where it blows up costs: far more than any sensible fit, so the solver backs off.
    penalty = 10.0 * measured.scale

    def evaluate(x):
        """The residual at x, or None where the parameters make no valid model."""
        nonlocal evaluations
        try:
            force = measured.simulate(_model_at(start, frees, x - 1.0))
        except InputError:
            residual = None
        else:
            residual = force - measured.force
            if not np.all(np.isfinite(residual)):
                residual = None
        with counting:
            evaluations += 1
            if callback is not None:
                rms = math.inf if residual is None else float(np.sqrt(np.mean(residual ** 2)))
                callback(evaluations, rms)
        return residual

    def residuals(x):
        if np.array_equal(last.get("x"), x):        # the start, simulated once below
            return last["residual"]
        residual = evaluate(x)
        if residual is None:
            residual = np.full(measured.size, penalty)
        last["x"], last["residual"] = x.copy(), residual
        return residual

    def jacobian(x):
        """Forward differences with a fixed step in the solver's variables (backward at an
        upper bound or where the forward point is invalid); the residual at x is the one
        the solver has just evaluated.  Columns are independent simulations: on threads."""
        base = last["residual"] if np.array_equal(last.get("x"), x) else residuals(x)

        def column(j):
            forward = diff_step if x[j] + diff_step <= high[j] else -diff_step
            for step in (forward, -forward):
                moved = x.copy()
                moved[j] += step
                residual = evaluate(moved)
                if residual is not None:
                    return (residual - base) / step
            return np.zeros(base.size)

        nonlocal pool
        columns, rest = [], range(x.size)
        if threads is None:
            # The first column, timed, decides how many threads the others get.
            clock = time.perf_counter()
            columns.append(column(0))
            threads_for(_worker_count(workers, x.size, time.perf_counter() - clock))
            rest = range(1, x.size)
        columns += pool.map(column, rest) if pool is not None else map(column, rest)
        return np.column_stack(columns)

    def threads_for(count):
        nonlocal threads, pool
        threads = count
        if count > 1:
            from concurrent.futures import ThreadPoolExecutor
            pool = ThreadPoolExecutor(max_workers=count, thread_name_prefix="polind-fit")

    first = measured.simulate(start)
    if not np.all(np.isfinite(first)):
        raise InputError(f"The starting {start.type} model gives a non-finite force on these "
                         "data; check its parameters.")
    last["x"], last["residual"] = np.ones(n_variables), first - measured.force
    holdout_record = None if fitted_samples is None else record
    if n_variables == 0:
        result = _result(start, start, frees, np.zeros(0), given_bounds, first, measured, 0, 1,
                         True, "nothing to identify", notes=notes, record=holdout_record)
    else:
        if workers is not None:
            threads_for(_worker_count(workers, n_variables, math.inf))
        try:
            solution = least_squares(residuals, np.ones(n_variables), jac=jacobian,
                                     bounds=(low, high), method="trf", x_scale=x_scale,
                                     ftol=tolerance, xtol=tolerance, gtol=tolerance,
                                     max_nfev=max_evaluations)
        finally:
            if pool is not None:
                pool.shutdown()
        solution.x = solution.x - 1.0
        fitted = _model_at(start, frees, solution.x)
        force = measured.simulate(fitted)
        result = _result(fitted, start, frees, solution.x, given_bounds, force, measured,
                         solution.njev or 0, evaluations, solution.status > 0, solution.message,
                         jac=solution.jac, notes=notes, record=holdout_record)
    for note in result.warnings:
        warnings.warn(note, UserWarning, stacklevel=2)
    return result


# --- structure: Maxwell-slip elements by NNLS ----------------------------------------------------

def _slip_grid(path, slip_distances, n):
    if slip_distances is None:
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1):
            raise InputError(f"The number of slip distances 'n' must be a positive integer. "
                             f"Got {describe(n)} instead.")
        span = float(np.ptp(path.x))
        return np.geomspace(span * 1e-3, span, int(n))
    grid = as_samples("slip_distances", slip_distances, positive=True)
    if grid.size == 0:
        raise InputError("The 'slip_distances' must hold at least one distance [m]. Got none.")
    return np.unique(grid)


def _element_responses(data: _Data, grid):
    """A[k, i] = z_i(x_k) / D_i: the clipped deflection of a unit element of slip distance D_i."""
    columns = []
    for distance in grid:
        unit = model_from_dict({"model": {"type": "maxwell-slip", "stiffness": [1.0],
                                          "breakaway_force": [float(distance)]}})
        columns.append(simulate(unit, data.t, **data.motion()).force / distance)
    return np.column_stack(columns)


def identify_maxwell_slip(data, slip_distances=None, n=24, *, viscous=False):
    """A Maxwell-slip element set from a presliding record, by non-negative least squares.

    With the slip distances ``D_i`` fixed on a grid, the force is linear in
    the break-away forces: ``F = sum_i W_i z_i(x) / D_i (+ sigma2 v)``, where
    ``z_i`` is the deflection of element ``i``, clipped to ``[-D_i, D_i]``
    along the path (it depends on the path and ``D_i`` only).
    ``scipy.optimize.nnls`` finds ``W_i >= 0``; elements with ``W_i = 0`` are
    dropped, and ``k_i = W_i / D_i``.  The elements start unloaded at the
    first sample.  Noiseless data from a Maxwell-slip model whose slip
    distances are on the grid are recovered exactly.

    Parameters
    ----------
    data : mapping of str to array_like
        ``t`` [s], one of ``x`` [m] / ``v`` [m/s], ``F`` [N].
    slip_distances : array_like, optional
        The grid of slip distances [m]; default ``n`` distances spaced
        logarithmically from 1e-3 to 1 times the displacement range of the data.
    n : int
        Number of grid points when ``slip_distances`` is not given.
    viscous : bool
        Also fit ``viscous_coefficient`` (sigma2 >= 0, a column ``v``).

    Returns
    -------
    FrictionModel
        A ``maxwell-slip`` model (elements ordered by slip distance).

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import identify_maxwell_slip
    >>> true = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 2.0]}})
    >>> t = np.linspace(0.0, 1.0, 401)
    >>> x = 4e-5 * np.sin(2 * np.pi * t) * (1 - t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    >>> fit = identify_maxwell_slip(data, slip_distances=[1e-6, 5e-6, 2e-5])
    >>> np.round(fit.params["breakaway_force"], 9).tolist()
    [1.0, 2.0]
    """
    from scipy.optimize import nnls

    measured = measured_data(data, normal_load_ok=False)
    path = measured.path()
    grid = _slip_grid(path, slip_distances, n)
    columns = grid.size + bool(viscous)
    check_memory(measured.size * (_ELEMENT_FIT_BYTES + _ELEMENT_FIT_BYTES_PER_COLUMN * columns),
                 f"The element fit of {grid.size} slip distances to {measured.size:.3g} "
                 f"samples of data")
    design = _element_responses(measured, grid)
    if viscous:
        design = np.column_stack([design, path.sample_velocity])
    # Columns of very different size (the viscous one) are scaled to unit norm for NNLS.
    norms = np.linalg.norm(design, axis=0)
    norms[norms == 0.0] = 1.0
    coefficients, _ = nnls(design / norms, measured.force, maxiter=50 * design.shape[1])
    coefficients = coefficients / norms
    weights = coefficients[:grid.size]
    active = weights > 1e-12 * max(weights.max(initial=0.0), 1e-300)
    if not active.any():
        raise InputError("The 'F' samples show no presliding force that a Maxwell-slip element "
                         "set with non-negative break-away forces can carry.")
    params = {"stiffness": (weights[active] / grid[active]).tolist(),
              "breakaway_force": weights[active].tolist()}
    if viscous:
        params["viscous_coefficient"] = float(coefficients[-1])
    return model_from_dict({"model": {"type": "maxwell-slip", **params}})


def identify_gms(data, slip_distances=None, n=24, *, model=None):
    """A GMS starting model: element stiffnesses and weights from :func:`identify_maxwell_slip`.

    GMS with ``Fs = Fc`` and a large attraction ``C`` is the Maxwell-slip
    model with ``W_i = alpha_i Fc`` (:ref:`guide-gms`), so the NNLS element set
    gives ``alpha_i = W_i / sum W`` and ``k_i``; the Coulomb force is
    ``sum W`` (the sliding force of the record).

    Parameters
    ----------
    data, slip_distances, n
        As :func:`identify_maxwell_slip`.
    model : FrictionModel, optional
        A ``gms`` model whose ``attraction``, Stribeck velocity, exponent,
        shape and ``viscous_coefficient`` are kept, and whose ratio
        ``static_force / coulomb_force`` is applied.  Without it:
        ``Fs = Fc = sum W``, ``stribeck_velocity`` the median speed of the
        moving samples, and ``C = 10 v max_i k_i`` with ``v`` that speed (a
        slip relaxation length ``alpha_i g / C`` well below every slip
        distance, i.e. close to Maxwell-slip).

    Returns
    -------
    FrictionModel
        A ``gms`` model.
    """
    slip = identify_maxwell_slip(data, slip_distances, n)
    stiffness = np.asarray(slip.params["stiffness"])
    breakaway = np.asarray(slip.params["breakaway_force"])
    total = float(breakaway.sum())
    weight = breakaway / total
    weight[-1] = 1.0 - weight[:-1].sum()
    elements = {"stiffness": stiffness.tolist(), "weight": weight.tolist()}
    if model is not None:
        if not isinstance(model, FrictionModel) or model.type != "gms":
            raise InputError(f"The 'model' of identify_gms must be a gms model. Got "
                             f"{describe(model)} instead.")
        p = model.params
        ratio = p["static_force"] / p["coulomb_force"]
        return model.with_params(**elements, coulomb_force=total, static_force=total * ratio)
    measured = measured_data(data, normal_load_ok=False)
    speed = np.abs(measured.path().sample_velocity)
    typical = float(np.median(speed[speed > 0.0]))
    return model_from_dict({"model": {"type": "gms", **elements,
                                      "attraction": 10.0 * typical * float(stiffness.max()),
                                      "coulomb_force": total, "static_force": total,
                                      "stribeck_velocity": typical}})


# --- structure: the static Stribeck curve ------------------------------------------------------

def identify_stribeck(v, F, *, model=None, free=None, bounds=None, stribeck_shape="exponential",
                      **options) -> FitResult:
    """The Stribeck curve ``F = g(v) sgn(v) + sigma2 v`` from steady-state points.

    Parameters
    ----------
    v : array_like
        Sliding velocities [m/s] of the steady-state points (either sign).
    F : array_like
        The steady friction force at each [N].
    model : FrictionModel, optional
        A ``stribeck`` model to start from.  Default: estimates from the
        points -- ``Fc`` the median ``|F|`` of the fastest fifth, ``Fs`` the
        largest ``|F|`` of the slowest fifth, ``vs`` the speed where ``|F|``
        is nearest to halfway between them, ``delta = 2``, ``sigma2 = 0``.
    free : list of str, optional
        Default ``coulomb_force, static_force, stribeck_velocity,
        stribeck_exponent``; add ``viscous_coefficient`` to fit sigma2.
    bounds : dict, optional
        As :func:`identify`.
    stribeck_shape : {"exponential", "rational"}
        The shape of the default starting model.
    **options
        Passed to :func:`identify` (``max_evaluations``, ``tolerance``, ...).

    Returns
    -------
    FitResult
        Its ``model`` is a ``stribeck`` model.

    Examples
    --------
    >>> import numpy as np
    >>> from polind.identification import identify_stribeck
    >>> v = np.geomspace(1e-5, 1e-1, 30)
    >>> F = 1.0 + 0.5 * np.exp(-(v / 1e-3) ** 2)
    >>> fit = identify_stribeck(v, F)
    >>> [round(fit.values[k], 6) for k in ("coulomb_force", "static_force", "stribeck_velocity")]
    [1.0, 1.5, 0.001]
    """
    v = as_samples("v", v)
    force = as_samples("F", F, v.shape[0])
    if model is None:
        speed, level = np.abs(v), force * np.sign(v)
        moving = speed > 0.0
        if not moving.any():
            raise InputError("The 'v' samples are all 0: steady-state points need motion.")
        speed, level = speed[moving], level[moving]
        order = np.argsort(speed)
        fifth = max(1, order.size // 5)
        coulomb = float(np.median(level[order[-fifth:]]))
        static = float(np.max(level[order[:fifth]]))
        coulomb = coulomb if coulomb > 0.0 else float(np.abs(level).mean()) or 1.0
        static = static if static > 0.0 else coulomb
        halfway = np.argmin(np.abs(level - 0.5 * (coulomb + static)))
        velocity = float(speed[halfway]) if static != coulomb else float(np.median(speed))
        model = model_from_dict({"model": {"type": "stribeck", "coulomb_force": coulomb,
                                           "static_force": static, "stribeck_velocity": velocity,
                                           "stribeck_exponent": 2.0,
                                           "stribeck_shape": stribeck_shape}})
    elif not isinstance(model, FrictionModel) or model.type != "stribeck":
        raise InputError(f"The 'model' of identify_stribeck must be a stribeck model. Got "
                         f"{describe(model)} instead.")
    if free is None:
        free = ["coulomb_force", "static_force", "stribeck_velocity", "stribeck_exponent"]
    # A memoryless model's force at sample k depends on v[k] only: the points form a "path".
    points = {"t": np.arange(v.shape[0], dtype=np.float64), "v": v, "F": force}
    return identify(model, points, free=free, bounds=bounds, **options)


# --- the comparison figure ---------------------------------------------------------------------

def _labelled(results) -> list[tuple[str, FrictionModel]]:
    if isinstance(results, (FitResult, FrictionModel)):
        results = [results]
    items = results.items() if isinstance(results, Mapping) else [(None, r) for r in results]
    out = []
    for label, item in items:
        model = item.model if isinstance(item, FitResult) else item
        if not isinstance(model, FrictionModel):
            raise InputError(f"plot_fit takes FitResults or models. Got {describe(item)} instead.")
        out.append((label or model.type, model))
    return out


def plot_fit(data, results, path, *, window=None, title=None, dpi=120) -> None:
    """Write a PNG of measured against fitted force (``polind fit --plot FILE``).

    Three panels: force over the whole record, force over a time window (a
    few strokes, to see the shape), and force against position.  Each model
    is simulated again on ``data``, so results fitted on a decimated record
    can be drawn against the full one.

    Parameters
    ----------
    data : mapping of str to array_like
        As :func:`identify`; a ``normal_load`` column goes to the models that
        take one (pol-ind) only.
    results : FitResult, FrictionModel, a sequence of them, or a mapping label -> one
        The fitted models (labelled by model type unless a mapping is given).
    path : str or os.PathLike
        The PNG to write.
    window : (float, float), optional
        Start and end [s] of the middle panel; default a tenth of the record
        around its middle.
    title : str, optional
    dpi : int
    """
    from io import BytesIO

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from polind import io

    measured = measured_data(data)
    labelled = _labelled(results)
    position = measured.path().x
    t = measured.t
    if window is None:
        middle, half = 0.5 * (t[0] + t[-1]), 0.05 * (t[-1] - t[0])
        window = (middle - half, middle + half)
    inside = (t >= window[0]) & (t <= window[1])
    if inside.sum() < 2:
        inside[:] = True

    figure = Figure(figsize=(11, 11), layout="constrained")
    FigureCanvasAgg(figure)
    over_time, zoomed, against_x = figure.subplots(3, 1, height_ratios=(1, 1, 1.4))
    for axes, mask in ((over_time, slice(None)), (zoomed, inside)):
        axes.plot(t[mask], measured.force[mask], color="black", lw=1.6, label="measured")
    against_x.plot(position * 1e3, measured.force, color="black", lw=0.8, label="measured")
    for label, model in labelled:
        force = measured.simulate(model)
        rms = float(np.sqrt(np.mean((force - measured.force) ** 2)))
        text = f"{label} (RMS {rms:.3g} N)"
        over_time.plot(t, force, lw=1.0, label=text)
        zoomed.plot(t[inside], force[inside], lw=1.2, label=text)
        against_x.plot(position * 1e3, force, lw=0.8, alpha=0.7, label=text)
    over_time.set(xlabel="time t [s]", ylabel="friction force F [N]",
                  title=title or "Measured and fitted friction force")
    zoomed.set(xlabel="time t [s]", ylabel="friction force F [N]",
               title=f"window {window[0]:.4g} s to {window[1]:.4g} s")
    against_x.set(xlabel="position x [mm]", ylabel="friction force F [N]",
                  title="force against position")
    for axes in (over_time, zoomed, against_x):
        axes.grid(alpha=0.3)
    zoomed.legend(loc="best", fontsize=8)
    against_x.legend(loc="best", fontsize=8)
    buffer = BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png")
    io.atomic_write_bytes(path, buffer.getvalue())      # the output rules of every command
