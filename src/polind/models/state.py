"""The state of a run and the path it follows (:ref:`guide-simulate-path`).

:class:`Path` is a prescribed motion cut into steps; :class:`State` is what a
model carries from one run to the next, with its JSON form.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from polind.errors import InputError, describe
from polind.models.checks import LARGEST
from polind.models.registry import model_class

#: The variable of a :class:`polind.Body`'s state that carries its integrator's history
#: (``polind.stepper.HISTORY``): the one a state may hold beside its model's variables.
BODY_KEY = "body"


@dataclass(frozen=True)
class Path:
    """A prescribed motion cut into steps at constant velocity (:ref:`guide-simulate-path`).

    Arrays have one entry per sample; entry ``k`` of ``step``,
    ``displacement`` and ``step_velocity`` describes the step that *ends* at
    sample ``k`` (entry 0 is unused and zero).
    """

    t: np.ndarray
    x: np.ndarray
    step: np.ndarray
    displacement: np.ndarray
    step_velocity: np.ndarray
    sample_velocity: np.ndarray


@dataclass
class State:
    """The state of a model after a run, enough to continue it exactly.

    ``variables`` holds the model's internal state as float64 arrays
    (``element_force`` for the Maxwell-slip family, ``slip_direction`` for
    GMS-type elements, ``deflection`` for LuGre and Leuven, ...).  ``time``,
    ``position``, ``velocity`` and ``force`` are those of the last sample.
    """

    model_type: str
    time: float = 0.0
    position: float = 0.0
    velocity: float = 0.0
    force: float = 0.0
    variables: dict = field(default_factory=dict)

    _SCALARS: ClassVar[tuple] = ("time", "position", "velocity", "force")

    def __post_init__(self):
        self.check_finite()

    def check_finite(self) -> None:
        """Refuse (InputError) a state whose numbers are not all finite, naming the entry.

        Checked when a state is built and again when a model is given one
        (:meth:`polind.FrictionModel.check_state`): its variables may have
        been changed in between.  The scalars become Python floats.
        """
        for key in self._SCALARS:
            value = getattr(self, key)
            if not (isinstance(value, (int, float, np.integer, np.floating))
                    and not isinstance(value, bool) and _finite_float(value)):
                raise InputError(f"The '{key}' of a State must be a finite number. Got "
                                 f"{describe(value)} instead.")
            setattr(self, key, float(value))
        if not isinstance(self.variables, dict):
            raise InputError(f"The variables of a State must be a dict of arrays. Got "
                             f"{describe(self.variables)} instead.")
        for key, value in self.variables.items():
            try:
                finite = bool(np.isfinite(np.asarray(value, dtype=np.float64)).all())
            except (TypeError, ValueError, OverflowError):
                finite = False
            if not finite:
                raise InputError(f"The '{key}' variable of a State must hold finite numbers. "
                                 f"Got {describe(value)} instead.")

    def check_entries(self, model) -> None:
        """Refuse (InputError) a state that ``model`` cannot continue exactly.

        The one check of a state given to a model, whatever the model
        (:meth:`polind.FrictionModel.step_kernel` makes it, after the model's
        own :meth:`~polind.FrictionModel.check_state`): an entry the model
        does not have (a misspelt key of an edited state file), named with
        the keys expected, and a number that is not finite or is larger than
        a model's numbers may be (:data:`polind.models.checks.LARGEST`: the
        model's arithmetic would overflow to infinity), named with its key.
        """
        self.check_finite()
        known = dict.fromkeys(model.state_keys or ())
        for key in self.variables:
            if key != BODY_KEY and key not in known:
                known.update(dict.fromkeys(model.initial_variables(None)))    # (once)
                if key not in known:
                    expected = ", ".join(("type",) + self._SCALARS + tuple(known) + (BODY_KEY,))
                    raise InputError(f"The state has an entry '{key}' that a {model.type} "
                                     f"model's state does not have; expected its keys: "
                                     f"{expected}.")
        for key in self._SCALARS:
            _check_size(key, np.array([getattr(self, key)]))
        for key, value in self.variables.items():
            _check_size(key, np.asarray(value, dtype=np.float64).reshape(-1))

    def copy(self) -> "State":
        """A deep copy (the variables' arrays copied too)."""
        return State(self.model_type, self.time, self.position, self.velocity, self.force,
                     {key: np.array(value, dtype=np.float64, copy=True)
                      for key, value in self.variables.items()})

    def to_dict(self) -> dict:
        """A JSON-able dict: ``type``, the scalars, and each variable as a list."""
        out = {"type": self.model_type}
        out.update({key: float(getattr(self, key)) for key in self._SCALARS})
        out.update({key: np.asarray(value, dtype=np.float64).tolist()
                    for key, value in self.variables.items()})
        return out

    def to_json(self) -> str:
        """The state as JSON text (:meth:`to_dict`); :meth:`from_json` reads it back."""
        return json.dumps(self.to_dict(), allow_nan=False)

    @classmethod
    def from_dict(cls, data: dict) -> "State":
        """Rebuild a state from :meth:`to_dict` output (or its JSON)."""
        if not isinstance(data, dict) or not isinstance(data.get("type"), str):
            raise InputError(f"A saved state must be a table with a 'type' key. "
                             f"Got {describe(data)} instead.")
        model_class(data["type"], "in a saved state")
        scalars = {}
        for key in cls._SCALARS:
            value = data.get(key, 0.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not _finite_float(value):
                raise InputError(f"The '{key}' entry of a saved state must be a finite number. "
                                 f"Got {describe(value)} instead.")
            scalars[key] = float(value)
            _check_size(key, np.array([scalars[key]]))
        variables = {}
        for key, value in data.items():
            if key == "type" or key in cls._SCALARS:
                continue
            try:
                array = np.array(value, dtype=np.float64).reshape(-1)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"The '{key}' entry of a saved state must be a list of numbers. "
                                 f"Got {describe(value)} instead.") from None
            if not np.all(np.isfinite(array)):
                raise InputError(f"The '{key}' entry of a saved state must be finite. "
                                 f"Got {describe(value)} instead.")
            _check_size(key, array)
            variables[key] = array
        return cls(data["type"], variables=variables, **scalars)

    @classmethod
    def from_json(cls, text: str) -> "State":
        """Rebuild a state from :meth:`to_json` text (InputError for anything else)."""
        if not isinstance(text, (str, bytes, bytearray)):
            raise InputError(f"State.from_json needs JSON text. Got {describe(text)} instead.")
        try:
            data = json.loads(text)
        except ValueError as error:
            raise InputError(f"A saved state must be JSON text: {error}.") from None
        return cls.from_dict(data)


def _finite_float(value) -> bool:
    """Whether a Python number is a finite double (a 400-digit integer is not)."""
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _check_size(key, array) -> None:
    """Refuse a state's entry with a number beyond :data:`LARGEST` in magnitude (naming it)."""
    large = np.flatnonzero(~(np.abs(array) <= LARGEST))
    if large.size:
        index = int(large[0])
        where = f" at index {index}" if array.shape[0] > 1 else ""
        raise InputError(f"The '{key}' entry of a state must hold finite numbers of a physical "
                         f"size, at most {LARGEST:g} in magnitude (a model's arithmetic "
                         f"multiplies them). Got {float(array[index])!r}{where} instead.")
