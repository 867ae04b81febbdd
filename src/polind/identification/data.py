"""The measured data of an identification: its columns, their checks and the hold-out split.

:func:`measured_data` checks a record (``t``, one of ``x``/``v``, ``F``,
optionally ``normal_load``) and returns it as a :class:`MeasuredData`, which
simulates a model along it; :func:`holdout_split` turns a hold-out fraction
into the number of fitted samples.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.models import FrictionModel
from polind.simulation import as_samples, make_path, simulate
from polind.validation import describe

__all__ = ["MeasuredData", "measured_data", "holdout_split"]

_DATA_KEYS = ("t", "x", "v", "F", "normal_load")


def _uses_load(model: FrictionModel) -> bool:
    """Whether a normal-load signal changes the model's force (Pol-Ind, or a reference_load)."""
    uses = getattr(model, "uses_normal_load", None)
    return bool(model.takes_normal_load if uses is None else uses)


@dataclass(frozen=True)
class MeasuredData:
    """A checked record, as :func:`measured_data` returns it.

    Attributes
    ----------
    t : ndarray
        Sample times [s], strictly increasing.
    force : ndarray
        The measured friction force [N].
    x, v : ndarray or None
        Positions [m] or velocities [m/s]: exactly one is given.
    normal_load : ndarray or None
        The normal load [N] at every sample, or None (no column, or a model
        that ignores it).
    """

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

    def head(self, n: int) -> "MeasuredData":
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
                 notes: list | None = None) -> MeasuredData:
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


def _checked(t, force, x, v, normal_load, where: str = "") -> MeasuredData:
    """A MeasuredData after the checks that make a record worth fitting (named for ``where``)."""
    n = t.shape[0]
    if n < 3:
        raise InputError(f"Identification needs at least 3 samples{where}. Got {n} samples "
                         "of 't'.")
    path = make_path(t, x=x, v=v)   # t strictly increasing, named in the error
    if x is not None and np.ptp(x) == 0.0:
        raise InputError(f"The 'x' samples{where} never change (all {float(x[0])!r}): the data "
                         "hold no motion, so no friction parameter can be identified.")
    if v is not None and not np.any(v):
        raise InputError(f"The 'v' samples{where} are all 0: the data hold no motion, so no "
                         "friction parameter can be identified.")
    if v is not None and np.ptp(path.x) == 0.0:
        # (v = +a, -a, +a...: each step's mean velocity is 0; or speeds too small for a
        # float's position to move)
        raise InputError(f"The 'v' samples{where} integrate to a position that never changes "
                         f"(all {float(path.x[0])!r} m at the sample times): the data hold no "
                         "displacement, so no friction parameter can be identified.")
    if np.ptp(force) == 0.0:
        raise InputError(f"The 'F' samples{where} are all equal ({float(force[0])!r}): a "
                         "constant force carries no information to identify parameters from.")
    return MeasuredData(t=t, force=force, x=x, v=v, normal_load=normal_load)



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

