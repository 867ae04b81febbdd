"""The model side of an identification: free keys, their bounds, the optimiser's variables.

:func:`parse_fit` checks a model (or a model document with a ``[fit]``
table), its free keys and their bounds; :func:`default_bounds` gives a free
key without ``[fit.bounds]`` its bounds from the data, by its unit
(:data:`DEFAULT_RANGES`); :func:`build_free` maps each free key to the
optimiser's variables (:class:`FreeParameter`) and :func:`model_at` builds
the model at a point of them.

The mappings (a log scale for a positive parameter, a linear one otherwise,
a softmax for weights that sum to 1) are those of the package's
"Parametrisation" (:mod:`polind.identification`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.identification.data import MeasuredData, measured_data
from polind.models import FrictionModel, model_from_dict
from polind.models.params import Param, Table
from polind.validation import describe

__all__ = ["DEFAULT_RANGES", "UNSCALED_RANGE", "FreeParameter", "parse_fit", "default_bounds",
           "fittable_keys", "param_value", "build_free", "split_variables", "variables_of",
           "model_at"]

_FIT_KEYS = ("free", "bounds", "result")
# Linear bounds for the bounded kinds, kept strictly inside the open ends.
_KIND_BOUNDS = {
    "positive": (0.0, math.inf),
    "nonnegative": (0.0, math.inf),
    "any": (-math.inf, math.inf),
    "poisson": (-1.0 + 1e-9, 0.5 - 1e-9),
    "fraction": (1e-12, 1.0),
    "iwan_exponent": (-1.0 + 1e-9, 0.0),
}
# Largest |log change| a log-scaled parameter may take (keeps exp() finite and positive).
_LOG_LIMIT = 600.0


def _typical_scale(unit: str, data: MeasuredData) -> float:
    """A natural size for a parameter of this unit in these data (linear scaling of a 0 start)."""
    path = data.path()
    force = float(np.sqrt(np.mean(data.force ** 2)))
    speed = float(np.sqrt(np.mean(path.sample_velocity ** 2))) or 1.0
    span = float(np.ptp(path.x)) or 1.0
    duration = float(data.t[-1] - data.t[0])
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        scale = {"N": force, "N s/m": np.divide(force, speed), "N/m": np.divide(force, span),
                 "m/s": speed, "m": span, "N/s": np.divide(force, duration),
                 "s": duration}.get(unit, 1.0)
    # a size the data make 0 or infinite (speeds that underflow): the unit size
    return float(scale) if math.isfinite(scale) and scale > 0.0 else 1.0


# --- default bounds from the data -------------------------------------------------------------

@dataclass(frozen=True)
class _Scales:
    """The sizes of a record that the default bounds are derived from."""

    force: np.float64  # A: the force amplitude, max |F| [N]
    speed: np.float64  # V: the largest sample speed [m/s]
    span: np.float64   # L: the displacement range, max x - min x [m]
    step: np.float64   # h: the median time step [s]

    @classmethod
    def of(cls, data: MeasuredData) -> "_Scales":
        path = data.path()
        # NumPy scalars: a quotient of the rules is inf or nan, not a ZeroDivisionError.
        return cls(force=np.float64(data.scale), speed=np.max(np.abs(path.sample_velocity)),
                   span=np.ptp(path.x), step=np.median(np.diff(data.t)))


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


def _default_range(key: str, declaration: Param, start: np.ndarray, scales: _Scales):
    """``(low, high, low_origin, high_origin)``: the default bounds of a free parameter.

    An InputError naming ``key`` when its scale from the data is 0 or not
    finite, or makes bounds that are (no range can be made of it).
    """
    kind_low, kind_high = _KIND_BOUNDS[declaration.bound]
    if math.isfinite(kind_low) and math.isfinite(kind_high):
        origin = f"the end of the range of a {declaration.bound} parameter"
        return kind_low, kind_high, origin, origin
    rule = DEFAULT_RANGES.get(declaration.unit)
    if rule is not None:
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            scale = float(rule.scale(scales))
            low, high = rule.low * scale, rule.high * scale
        if not (0.0 < low and math.isfinite(high)):
            raise InputError(f"The default bounds of '{key}' are [{rule.low:g}, {rule.high:g}] x "
                             f"{rule.words}, which is {scale:.4g} {declaration.unit} in these "
                             f"data: no range can be made of it. Give '{key}' its bounds in "
                             f"[fit.bounds] (or the 'bounds' of identify).")
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

def fittable_keys(model: FrictionModel) -> list[str]:
    """The keys of ``model`` that :func:`parse_fit` accepts as free (dotted for nested ones)."""
    def walk(entries, prefix):
        for entry in entries:
            if isinstance(entry, Table):
                yield from walk(entry.entries, f"{prefix}{entry.key}.")
            elif entry.kind in ("float", "list", "pair") and entry.fittable:
                yield f"{prefix}{entry.key}"
    return list(walk(model.parameters, ""))


def param_value(params: dict, key: str):
    """The value of a dotted key (``"surface.height_std"``) in a model's parameters."""
    value = params
    for part in key.split("."):
        value = value[part]
    return value


def _has(params: dict, key: str) -> bool:
    try:
        param_value(params, key)
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
class FreeParameter:
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

    def variables(self, value) -> np.ndarray | None:
        """The optimiser's variables of a physical value (the inverse of :meth:`physical`),
        clipped into the bounds; None for a value of another shape or that no variables give."""
        value = np.atleast_1d(np.asarray(value, dtype=np.float64))
        if value.shape != self.start.shape or not np.all(np.isfinite(value)):
            return None
        with np.errstate(divide="ignore", invalid="ignore"):
            if self.mapping == "log":
                u = np.log(value / self.start)
            elif self.mapping == "linear":
                u = (value - self.start) / self.scale
            else:
                u = (np.log(value) - math.log(value[-1])
                     - (np.log(self.start) - math.log(self.start[-1])))[:-1]
        low, high = self.internal_bounds()
        u = np.clip(u, low, high)
        return u if np.all(np.isfinite(u)) else None

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
                             f"model; expected one of: {', '.join(fittable_keys(model))}.")
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
            param_value(params, key)
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
    try:
        low, high = float(value[0]), float(value[1])
    except OverflowError:        # an integer beyond double precision (e.g. 400 digits)
        raise InputError(f"The bounds of '{key}' in [fit.bounds] must be numbers of double "
                         f"precision (below 1.8e308 in size). Got {describe(value)} "
                         f"instead.") from None
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
        start = np.atleast_1d(np.asarray(param_value(params, key), dtype=np.float64))
        outside = (start < low) | (start > high)
        if np.any(outside):
            raise InputError(f"The bounds [{low!r}, {high!r}] of '{key}' in [fit.bounds] "
                             f"exclude its starting value {float(start[np.argmax(outside)])!r}.")
    return pairs


def build_free(model: FrictionModel, keys, bounds, data: MeasuredData,
               notes: list | None = None) -> list[FreeParameter]:
    """The free keys with their mappings and bounds: given ones, else the defaults.

    A start outside its default bounds widens them to include it (with a note).
    """
    params = model.params
    scales = _Scales.of(data)
    frees = []
    for key in keys:
        declaration: Param = model.declaration(key)
        value = param_value(params, key)
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
                low, high, low_origin, high_origin = _default_range(key, declaration, start,
                                                                    scales)
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
        frees.append(FreeParameter(key, start, is_list, mapping, low, high, scale, low_origin,
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
    a hold-out the scales come from the fitted part only.  A scale the data
    make 0 or infinite (speeds too small for a float: ``A / V`` overflows)
    gives no range: an :class:`~polind.errors.InputError` names the key, to
    be given in ``[fit.bounds]``.  A record whose position never changes
    (``x`` constant, or a ``v`` that integrates to a constant position,
    such as ``+a, -a, +a...``) has ``L = 0``: it is refused before, as a
    record that holds no motion.

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
            for free in build_free(start, keys, {}, measured)}


def split_variables(frees: list[FreeParameter], u: np.ndarray) -> list[np.ndarray]:
    """The optimiser's variables ``u`` cut into each free key's part, in order."""
    out, offset = [], 0
    for free in frees:
        out.append(u[offset:offset + free.size])
        offset += free.size
    return out


def variables_of(frees: list[FreeParameter], model: FrictionModel) -> np.ndarray | None:
    """The optimiser's variables of the free keys' values in ``model`` (None if it has none).

    The other keys of ``model`` play no part: a start is projected onto the free keys.
    """
    params = model.params
    parts = []
    for free in frees:
        try:
            part = free.variables(param_value(params, free.key))
        except (KeyError, TypeError):
            return None
        if part is None:
            return None
        parts.append(part)
    return np.concatenate(parts) if parts else np.zeros(0)


def model_at(model: FrictionModel, frees: list[FreeParameter], u: np.ndarray) -> FrictionModel:
    """The model with its free keys at the optimiser's variables ``u`` (``u = 0``: ``model``)."""
    start = model.params
    params = model.params
    for free, part in zip(frees, split_variables(frees, u)):
        _set(params, free.key, free.output(free.physical(part)))
    model.couple_fit(params, [free.key for free in frees], start)
    return type(model)(**params)


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
