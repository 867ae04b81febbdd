"""What every friction model shares: parameters, state, the stepping contract.

A model is a validated parameter set plus a kernel (STYLE.md: a stepper owns
its bookkeeping, a model supplies only the physics).  :func:`polind.simulate`
turns the prescribed motion into a :class:`Path` of steps; each model's
``_advance`` runs its numba kernel over the path, updating a :class:`State`
in place, and returns the force at every sample.
"""

from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from polind.errors import InputError, describe
from polind.models.params import validate_table

MODEL_TYPES: dict[str, type] = {}


def register(cls):
    """Class decorator: make a model available under its ``type`` name."""
    MODEL_TYPES[cls.type] = cls
    return cls


@dataclass(frozen=True)
class Path:
    """A prescribed motion cut into steps at constant velocity (INTERFACE.md).

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

    def copy(self) -> "State":
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
        return json.dumps(self.to_dict())

    @classmethod
    def from_dict(cls, data: dict) -> "State":
        """Rebuild a state from :meth:`to_dict` output (or its JSON)."""
        if not isinstance(data, dict) or not isinstance(data.get("type"), str):
            raise InputError(f"A saved state must be a table with a 'type' key. "
                             f"Got {describe(data)} instead.")
        if data["type"] not in MODEL_TYPES:
            raise InputError(f"Unknown model type '{data['type']}' in a saved state; expected one "
                             f"of: {', '.join(sorted(MODEL_TYPES))}.")
        scalars = {}
        for key in cls._SCALARS:
            value = data.get(key, 0.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value):
                raise InputError(f"The '{key}' entry of a saved state must be a finite number. "
                                 f"Got {describe(value)} instead.")
            scalars[key] = float(value)
        variables = {}
        for key, value in data.items():
            if key == "type" or key in cls._SCALARS:
                continue
            try:
                array = np.array(value, dtype=np.float64).reshape(-1)
            except (TypeError, ValueError):
                raise InputError(f"The '{key}' entry of a saved state must be a list of numbers. "
                                 f"Got {describe(value)} instead.") from None
            if not np.all(np.isfinite(array)):
                raise InputError(f"The '{key}' entry of a saved state must be finite. "
                                 f"Got {describe(value)} instead.")
            variables[key] = array
        return cls(data["type"], variables=variables, **scalars)

    @classmethod
    def from_json(cls, text: str) -> "State":
        return cls.from_dict(json.loads(text))


class FrictionModel:
    """Base class: a validated parameter set and a kernel.

    Subclasses declare ``type``, ``parameters`` (a tuple of
    :class:`~polind.models.params.Param`), optionally ``_check`` for rules
    across parameters, and implement ``initial_variables`` and ``_advance``.
    """

    type: ClassVar[str] = ""
    parameters: ClassVar[tuple] = ()
    takes_normal_load: ClassVar[bool] = False

    def __init__(self, **params):
        clean = validate_table(self.type, self.parameters, params)
        self._check(clean)
        self._params = clean

    @classmethod
    def _check(cls, params: dict) -> None:
        """Rules that span several parameters (equal lengths, sums)."""

    @property
    def params(self) -> dict:
        """A copy of the validated parameters (keys of the model file)."""
        return copy.deepcopy(self._params)

    def to_dict(self) -> dict:
        """The model-file document: ``{"model": {"type": ..., ...}}``."""
        return {"model": {"type": self.type, **copy.deepcopy(self._params)}}

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    def with_params(self, **changes) -> "FrictionModel":
        """A new model with some parameters replaced (validated again)."""
        params = self.params
        params.update(changes)
        return type(self)(**params)

    def __eq__(self, other):
        return type(other) is type(self) and other._params == self._params

    def __repr__(self):
        shown = ", ".join(f"{key}={value!r}" for key, value in self._params.items())
        return f"{type(self).__name__}({shown})"

    def _array(self, key):
        return np.asarray(self._params[key], dtype=np.float64)

    # --- the stepping contract ---------------------------------------------------------

    def initial_state(self, normal_load=None) -> State:
        """The state at rest before any motion (all internal variables zero)."""
        return State(self.type, variables=self.initial_variables(normal_load))

    def initial_variables(self, normal_load=None) -> dict:
        return {}

    def check_state(self, state: State) -> None:
        """A state must belong to this model and have its shapes."""
        if state.model_type != self.type:
            raise InputError(f"The state is of a '{state.model_type}' model but the model is "
                             f"'{self.type}'.")
        expected = self.initial_variables(None)
        for key, value in expected.items():
            if key not in state.variables:
                raise InputError(f"The state lacks its '{key}' entry for a {self.type} model.")
            if state.variables[key].shape != np.shape(value):
                raise InputError(f"The state's '{key}' has {state.variables[key].size} entries; "
                                 f"the {self.type} model has {np.size(value)}.")

    def _advance(self, path: Path, state: State, normal_load) -> np.ndarray:
        """Run the kernel over ``path`` from ``state`` (updated in place); return forces."""
        raise NotImplementedError
