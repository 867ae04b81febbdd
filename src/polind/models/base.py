"""What every friction model shares: parameters, state, the stepping contract.

A model is a validated parameter set plus a kernel (a stepper owns its
bookkeeping, a model supplies only the physics).  :func:`polind.simulate`
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
from polind.models.params import Param, Table, validate_table

from polind.models.registry import MODEL_TYPES, model_class, register_model  # noqa: F401

#: polind's own models register with the same function, as a class decorator.
register = register_model


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


def scales(static_force, coulomb_force, viscous_coefficient=0.0, curve=None,
           presliding_range=0.0, presliding_stiffness=0.0, **extra) -> dict:
    """The characteristic scales of a model (see :meth:`FrictionModel.characteristic_scales`).

    ``static_force`` and ``coulomb_force`` [N] (the break-away and sliding
    levels), ``viscous_coefficient`` [N s/m], ``curve`` (a parameter dict
    with the Stribeck velocity, exponent and shape, or None without a
    Stribeck curve), ``presliding_range`` [m] and ``presliding_stiffness``
    [N/m]; ``extra`` may give ``bristle_stiffness`` [N/m],
    ``relaxation_rate`` [N/s] or ``relaxation_length`` [m] (how fast the
    force follows a velocity change).
    """
    out = {"static_force": float(static_force), "coulomb_force": float(coulomb_force),
           "viscous_coefficient": float(viscous_coefficient),
           "stribeck_velocity": None, "stribeck_exponent": 2.0,
           "stribeck_shape": "exponential",
           "presliding_range": float(presliding_range),
           "presliding_stiffness": float(presliding_stiffness)}
    if curve is not None:
        out.update({key: curve[key] for key in ("stribeck_velocity", "stribeck_exponent",
                                                "stribeck_shape")})
    out.update({key: float(value) for key, value in extra.items()})
    return out


def element_scales(stiffness, capacity) -> tuple:
    """``(presliding_range, presliding_stiffness)`` of elements in parallel: max W/k, sum k."""
    stiffness = np.asarray(stiffness, dtype=np.float64)
    capacity = np.asarray(capacity, dtype=np.float64)
    return float(np.max(capacity / stiffness)), float(np.sum(stiffness))


@dataclass(frozen=True)
class StepFunctions:
    """A model's numba functions of the stepping contract (:mod:`polind.kernels.contract`).

    ``step``, ``force`` and ``tangent`` are ``@njit`` functions with the
    signatures documented there.  Optionally, specialisations of the
    templates with the model's functions as globals, each taking the
    template's arguments after its first two: ``path``
    (``polind.kernels.contract.run_steps_any``, with ``step`` inlined),
    ``integrate`` (``polind.kernels.dynamics.integrate_system_template``),
    ``body`` (``polind.kernels.dynamics.advance_body_template``) and
    ``motion`` (``polind.kernels.contract.run_motion``, the loop of
    :func:`polind.simulate`).  numba can keep those in its
    on-disk cache, which it cannot do for a template given functions as
    arguments; without them the generic templates run the model, compiled
    once per process.
    """

    step: object
    force: object
    tangent: object
    path: object = None
    integrate: object = None
    body: object = None
    motion: object = None


#: Where a kernel's arrays start within a 4096-byte page (:func:`page_placed`): the
#: table (read in the element loops), the state (written there) half a page away,
#: the scalars (written per sample by a varying load) between.
TABLE_OFFSET, STATE_OFFSET, SCALARS_OFFSET = 0, 2048, 3072


def page_placed(values, offset=0):
    """A C-contiguous float64 copy of ``values`` starting ``offset`` bytes into a 4096-byte page.

    Two things about where an array starts cost an element loop time, both
    measured on the 1024-element Maxwell-slip benchmark.  An array that
    straddles cache lines at a varying offset (NumPy aligns to 16 bytes) ran
    up to 1.5 times slower.  A load whose address agrees with that of an
    earlier store in its low 12 bits waits for it (4K aliasing): with the
    element forces 64 bytes past the element table within a page,
    ``simulate`` took 47 ms instead of 25-27 ms.  Placing each array at a
    fixed ``offset`` (a multiple of 64) within a page settles both, so a
    kernel's arrays are placed with :data:`TABLE_OFFSET`,
    :data:`STATE_OFFSET` and :data:`SCALARS_OFFSET`.
    """
    values = np.asarray(values, dtype=np.float64)
    buffer = np.empty(values.size + 1024)
    start = (-(buffer.ctypes.data // 8)) % 512 + offset // 8
    placed = buffer[start:start + values.size].reshape(values.shape)
    placed[...] = values
    return placed


@dataclass
class StepKernel:
    """A model ready to be stepped by compiled code: its functions and flat arrays.

    The three arrays are what the model's numba functions take: ``scalars``
    (float64, 1-D), ``table`` (float64, 2-D, one column per element) and
    ``state`` (float64, 1-D, advanced in place).  From a user's own
    ``@njit`` loop::

        kernel = model.step_kernel()
        force = kernel.step(kernel.scalars, kernel.table, kernel.state,
                            h, dx, dx / h, dx / h, kernel.normal_load)

    Attributes
    ----------
    step, force, tangent : numba functions
        See :mod:`polind.kernels.contract`.
    path, integrate, body : numba function or None
        The model's specialised templates (:class:`StepFunctions`), if any.
    scalars, table, state : ndarray
        The model's parameters and its state, laid out for its functions.
    normal_load : float
        The model's own constant normal load [N] (0 for models without one).
    force_scale : float
        A typical friction force [N] (the solvers' tolerances scale with it).
    rest_capacity : float or None
        For a memoryless model, the largest force it holds at rest (``g(0)``,
        its friction is set-valued there); None for models with state (and
        for a memoryless contact behind a series spring: the spring is state).
    mount : ndarray or None
        What sits around the contact (:mod:`polind.kernels.mount`): a series
        spring, a normal-load scaling; None when nothing does.  A mounted
        model runs through :mod:`polind.kernels.series`, and ``step`` is then
        the bare contact's.
    """

    step: object
    force: object
    tangent: object
    path: object
    integrate: object
    body: object
    scalars: np.ndarray
    table: np.ndarray
    state: np.ndarray
    normal_load: float
    force_scale: float
    rest_capacity: float | None
    mount: np.ndarray | None = None
    motion: object = None

    def __post_init__(self):
        # A trial's state and, behind a series spring, the spring's own solve.
        self.scratch = np.empty(2 * self.state.shape[0])

    def first_force(self, sample_velocity, normal_load=None):
        """The force at the state without moving (the first sample of a run) [N].

        Behind a series spring it is the spring's force (0 at rest); else the
        model's ``force`` at ``sample_velocity``, scaled by the load.
        """
        from polind.kernels.mount import first_force

        load = self.normal_load if normal_load is None else normal_load
        return first_force(self.force, self.mount, self.scalars, self.table, self.state,
                           sample_velocity, load)

    def run(self, step, displacement, step_velocity, sample_velocity, loads, lo, hi, first,
            out_force):
        """Run the path arrays (indexed by the sample a step ends at) over ``lo .. hi - 1``."""
        loads = _NO_LOADS if loads is None else loads
        if self.mount is not None:
            from polind.kernels.series import run_mounted
            run_mounted(self.step, self.force, self.tangent, self.mount, self.scalars,
                        self.table, self.state, self.scratch, step, displacement,
                        step_velocity, sample_velocity, loads, self.normal_load, lo, hi, first,
                        out_force)
        elif self.path is not None:
            self.path(self.scalars, self.table, self.state, step, displacement, step_velocity,
                      sample_velocity, loads, self.normal_load, lo, hi, first, out_force)
        else:
            from polind.kernels.contract import run_steps_any
            run_steps_any(self.step, self.force, self.scalars, self.table, self.state, step,
                          displacement, step_velocity, sample_velocity, loads,
                          self.normal_load, lo, hi, first, out_force)

    def run_motion(self, source_t, source_motion, t, motion, by_velocity, start_position,
                   start_velocity, continuing, position, velocity, loads, lo, hi, first,
                   out_force):
        """``polind.kernels.contract.run_motion`` with this model's functions: ``(code, index)``.

        Copies ``source_t`` and ``source_motion`` into ``t`` and ``motion`` (they
        may be the same arrays) as it checks and runs them.  Not for a mounted
        model (a series spring or a load scaling), which runs from step arrays
        (:meth:`run`).
        """
        loads = _NO_LOADS if loads is None else loads
        arguments = (self.scalars, self.table, self.state, source_t, source_motion, t, motion,
                     by_velocity, start_position, start_velocity, continuing, position,
                     velocity, loads, self.normal_load, lo, hi, first, out_force)
        if self.motion is not None:
            return self.motion(*arguments)
        from polind.kernels.contract import run_motion_any
        return run_motion_any(self.step, self.force, *arguments)

    def integrate_system(self, *args):
        """``polind.kernels.dynamics.integrate_system_template`` with this model's functions.

        ``args`` are the template's arguments without the final ``mount``
        (added here).
        """
        if self.mount is not None:
            from polind.kernels.series import integrate_system_mounted
            integrate_system_mounted(self.step, self.tangent, args + (self.mount,))
        elif self.integrate is not None:
            self.integrate(args + (_RIGID,))
        else:
            from polind.kernels.dynamics import integrate_system
            integrate_system(self.step, self.tangent, args + (_RIGID,))

    def advance_body(self, *args):
        """``polind.kernels.dynamics.advance_body_template`` with this model's functions.

        ``args`` are the template's arguments without the final ``mount``
        (added here); its ``scratch`` is the kernel's ``scratch`` array.
        """
        if self.mount is not None:
            from polind.kernels.series import advance_body_mounted
            advance_body_mounted(self.step, self.tangent, args + (self.mount,))
        elif self.body is not None:
            self.body(args + (_RIGID,))
        else:
            from polind.kernels.dynamics import advance_body
            advance_body(self.step, self.tangent, args + (_RIGID,))


_NO_LOADS = np.zeros(0)
# The mount of a model with nothing around its contact (polind.kernels.mount slots:
# an infinitely stiff spring, no reference load).
_RIGID = np.array([math.inf] + [0.0] * 8)

#: The keys every model has besides its own (the user guide, "Normal load for every
#: model" and "Series compliance"): added to each subclass's ``parameters``.
REFERENCE_LOAD = Param("reference_load", default=None, unit="N",
          description=("Reference normal load :math:`N_0`: the load the force levels were "
                       "measured at. With it, a normal-load signal scales the force "
                       "(:ref:`guide-normal-load`); without it the signal is ignored."), symbol="N_0")
COMPLIANCE = Table("compliance", (Param("stiffness", unit="N/m",
          description=("Series stiffness :math:`k_s` of the rig, holders and bodies."), symbol="k_s"),), default=None,
          description=("Optional table: a linear spring in series with the contact "
                       "(:ref:`guide-series-compliance`)."))


class FrictionModel:
    """Base class of every friction model: a validated parameter set and its step.

    A model is one class (STYLE: a new kind is one class, the base class does
    the rest).  A subclass declares

    * ``type`` (the name used in model files) and ``parameters`` (a tuple of
      :class:`~polind.models.params.Param`), optionally ``_check`` for rules
      across parameters;
    * ``initial_variables`` (the state at rest, a dict of float64 arrays) and
      ``state_keys`` (their order in the flat state array; by default the
      order of ``initial_variables``);
    * ``step_functions`` (its numba ``step``, ``force`` and ``tangent``) and
      ``kernel_arrays`` (its ``scalars`` and ``table``);
    * optionally ``force_scale``, ``rest_capacity`` (memoryless models),
      ``characteristic_scales``, ``phenomena`` and ``fit_defaults``.

    :func:`polind.simulate`, :class:`polind.Stepper`, :class:`polind.Body`,
    :func:`polind.simulate_system`, identification, the phenomena and the
    benchmark all work from these.  :func:`polind.register_model` makes a
    subclass defined outside polind usable in model files.
    """

    type: ClassVar[str] = ""
    #: The model's name in prose and tables ("Generalized Maxwell-slip (GMS)").
    title: ClassVar[str] = ""
    #: What the model is for, one sentence (the README's and the guide's model tables).
    purpose: ClassVar[str] = ""
    #: The label of the user guide's section with its equations (e.g. ``"guide-gms"``), or "".
    guide: ClassVar[str] = ""
    #: Whether the model is a set of elements whose count ``example()`` can choose.
    has_elements: ClassVar[bool] = False
    #: Whether the model is built from contact mechanics (:meth:`contact` gives its surface,
    #: separation and elements: ``polind surface``).
    has_contact: ClassVar[bool] = False
    parameters: ClassVar[tuple] = ()
    takes_normal_load: ClassVar[bool] = False
    state_keys: ClassVar[tuple | None] = None
    #: The phenomena (the user guide, "Friction phenomena") the model is credited with beyond those
    #: that follow from its scales (a Stribeck dip gives the Stribeck effect and
    #: stick-slip, every model breaks away): any of "presliding_memory",
    #: "frictional_lag" (shown where the curve has a dip), "non_drifting".
    phenomena: ClassVar[frozenset] = frozenset()
    #: The keys :func:`polind.identify` frees when none are named.
    fit_defaults: ClassVar[tuple] = ()
    #: List keys kept positive and summing to 1 while fitted (GMS weights).
    simplex_keys: ClassVar[tuple] = ()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        # Every model may be mounted: a series spring, and (models without a
        # load of their own) a reference load for the load-proportional form.
        common = (COMPLIANCE,) if cls.takes_normal_load else (REFERENCE_LOAD, COMPLIANCE)
        own = {entry.key for entry in cls.parameters}
        cls.parameters = tuple(cls.parameters) + tuple(entry for entry in common
                                                       if entry.key not in own)

    def __init__(self, **params):
        clean = validate_table(self.type, self.parameters, params)
        self._check(clean)
        self._params = clean

    @classmethod
    def declaration(cls, key: str):
        """The :class:`~polind.models.params.Param` (or ``Table``) declared for a key, or None.

        Nested keys are named with a dot (``"surface.height_std"``).
        """
        entries = cls.parameters
        parts = key.split(".")
        for depth, part in enumerate(parts):
            found = next((entry for entry in entries if entry.key == part), None)
            if found is None or depth == len(parts) - 1:
                return found
            if not isinstance(found, Table):
                return None
            entries = found.entries
        return None

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
        """The model-file document (:meth:`to_dict`) as JSON text."""
        return json.dumps(self.to_dict(), allow_nan=False)

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

    # --- what a subclass supplies --------------------------------------------------------

    @classmethod
    def example_parameters(cls, elements: int | None = None) -> dict:
        """A representative ``[model]`` table without ``type`` (see ``example()``)."""
        raise NotImplementedError(f"The {cls.__name__} model gives no example parameters.")

    @classmethod
    def example(cls, elements: int | None = None) -> "FrictionModel":
        """A representative model of this type: the parameters the documentation,
        ``polind bench`` and the tests use.

        Parameters
        ----------
        elements : int, optional
            For a model of elements (``has_elements``), their number; default the
            model's own representative count.  Ignored by the other models.
        """
        return cls(**cls.example_parameters(elements))

    def contact(self, normal_load=None):
        """The contact mechanics at ``normal_load`` [N] (default the model's own load).

        Only models built from contact mechanics have one (``has_contact``); for
        any other this is an :class:`~polind.InputError`.
        """
        having = ", ".join(f"'{name}'" for name, cls in MODEL_TYPES.items() if cls.has_contact)
        raise InputError(f"The {self.type} model has no contact mechanics (a surface, a "
                         f"separation, elements); expected a model of type {having or 'none'}.")

    def peers(self) -> dict:
        """The models ``polind demo`` runs beside this one: ``{label: (model, description)}``.

        Default: none (the demo then shows this model alone).
        """
        return {}

    def initial_variables(self, normal_load=None) -> dict:
        """The internal variables at rest before any motion (float64 arrays)."""
        return {}

    def step_functions(self) -> StepFunctions:
        """The model's numba ``step``, ``force`` and ``tangent`` (and optional ``path``)."""
        raise NotImplementedError(f"The {type(self).__name__} model does not supply "
                                  "step_functions().")

    def kernel_arrays(self, state: State) -> tuple:
        """``(scalars, table)``: the float64 arrays its numba functions read."""
        raise NotImplementedError(f"The {type(self).__name__} model does not supply "
                                  "kernel_arrays().")

    def force_scale(self) -> float:
        """A typical friction force [N]: solver tolerances scale with it."""
        return 1.0

    def rest_capacity(self) -> float | None:
        """Memoryless models: the largest force held at rest (``g(0)``); else None."""
        return None

    def characteristic_scales(self) -> dict | None:
        """The force, velocity and length scales the phenomena experiments are sized by.

        A dict as ``polind.models.base.scales`` builds it, or None: a model that declares no
        scales cannot be run through the phenomena (they say so).
        """
        return None

    @classmethod
    def check_free_keys(cls, keys: list) -> None:
        """Refuse a set of free keys that cannot be fitted together (InputError)."""

    @classmethod
    def couple_fit(cls, params: dict, keys: list, start: dict) -> None:
        """Keep rules across parameters true while the free ``keys`` move (in place)."""

    def load_bounds(self, state: State) -> tuple | None:
        """``(low, high)``: the normal loads [N] a run from ``state`` may use (None: no load)."""
        return None

    def check_loads(self, loads: np.ndarray, state: State) -> None:
        """Raise InputError for normal loads [N] (positive, finite) the model cannot run at."""

    @property
    def constant_load(self) -> float:
        """The model's own normal load [N] when no signal is given (0: none).

        For a model that scales with the load, its ``reference_load``.
        """
        return float(self._params.get("reference_load") or 0.0)

    def viscous_coefficient(self) -> float:
        """sigma2 [N s/m]: the part of the force a normal load does not scale (user guide)."""
        return float(self._params.get("viscous_coefficient", 0.0))

    # --- what sits around the contact (the same for every model) -------------------------

    @property
    def reference_load(self) -> float | None:
        """N0 [N] of the load-proportional form, or None (the model ignores a load signal)."""
        return self._params.get("reference_load")

    @property
    def series_stiffness(self) -> float:
        """k_s [N/m] of ``[model.compliance]``; ``inf`` without one (a rigid mount)."""
        compliance = self._params.get("compliance")
        return math.inf if compliance is None else float(compliance["stiffness"])

    @property
    def uses_normal_load(self) -> bool:
        """Whether a normal-load signal changes the force (Pol-Ind, or a ``reference_load``)."""
        return bool(self.takes_normal_load) or self.reference_load is not None

    def mount_array(self, state: State, varying_load: bool) -> np.ndarray | None:
        """The :mod:`polind.kernels.mount` array of a run from ``state``, or None if nothing is mounted.

        A load scaling is mounted when the run may see loads other than the
        reference (``varying_load``); a series spring always.  Behind a
        spring the run starts with the spring carrying ``state.force``.
        """
        stiffness = self.series_stiffness
        scaling = self.reference_load is not None and varying_load
        if stiffness == math.inf and not scaling:
            return None
        from polind.kernels.mount import make_mount
        compliant = stiffness < math.inf
        spring_force = state.force if compliant else 0.0
        return make_mount(
            stiffness=stiffness, reference_load=self.reference_load if scaling else 0.0,
            viscous=self.viscous_coefficient(), rest_capacity=self.rest_capacity(),
            force_scale=self.force_scale(), spring_force=spring_force,
            contact_position=state.position - (spring_force / stiffness if compliant else 0.0))

    # --- the stepping contract, built from the above -------------------------------------

    def initial_state(self, normal_load=None) -> State:
        """The state at rest before any motion (all internal variables zero)."""
        return State(self.type, variables=self.initial_variables(normal_load))

    def _state_keys(self) -> tuple:
        if self.state_keys is not None:
            return tuple(self.state_keys)
        return tuple(self.initial_variables(None))

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

    def flat_state(self, state: State) -> np.ndarray:
        """The state's variables as one float64 array, in ``state_keys`` order."""
        parts = [np.asarray(state.variables[key], dtype=np.float64).reshape(-1)
                 for key in self._state_keys()]
        return np.concatenate(parts) if parts else np.zeros(0)

    def unflatten_state(self, flat: np.ndarray, state: State) -> None:
        """Write a flat state array back into ``state.variables`` (copies)."""
        offset = 0
        for key in self._state_keys():
            size = np.size(state.variables[key])
            state.variables[key] = np.array(flat[offset:offset + size], dtype=np.float64)
            offset += size

    def step_kernel(self, state: State | None = None, normal_load=None, *,
                    varying_load=None) -> StepKernel:
        """The model as compiled code can step it: functions and flat arrays.

        Parameters
        ----------
        state : State, optional
            Start from this state (a result's ``final_state``); default: at rest.
        normal_load : array_like, optional
            The normal loads [N] the run will see (a Pol-Ind model builds its
            element table for the largest).
        varying_load : bool, optional
            Whether the run may see loads other than the model's own
            (default: whether ``normal_load`` is given); a model with a
            ``reference_load`` is then mounted with its load scaling.

        Returns
        -------
        StepKernel
            Its ``state`` array is a copy: stepping it leaves ``state`` as it was.
        """
        if state is None:
            state = self.initial_state(normal_load)
        else:
            self.check_state(state)
        functions = self.step_functions()
        scalars, table = self.kernel_arrays(state)
        for name, values in (("scalars", scalars), ("table", table)):
            if np.isnan(np.asarray(values, dtype=np.float64)).any():
                raise InputError(f"The {self.type} model's parameters give NaN in its kernel "
                                 f"{name} (a value too large or too small for double "
                                 f"precision?); expected parameters of a physical size.")
        if varying_load is None:
            varying_load = normal_load is not None
        mount = self.mount_array(state, varying_load)
        rest_capacity = self.rest_capacity()
        if mount is not None and self.series_stiffness < math.inf:
            rest_capacity = None     # the spring is state: the mounted contact is not memoryless
        return StepKernel(
            step=functions.step, force=functions.force, tangent=functions.tangent,
            path=functions.path, integrate=functions.integrate, body=functions.body,
            motion=functions.motion,
            scalars=page_placed(scalars, SCALARS_OFFSET),
            table=page_placed(np.atleast_2d(table), TABLE_OFFSET),
            state=page_placed(self.flat_state(state), STATE_OFFSET),
            normal_load=float(self.constant_load), force_scale=float(self.force_scale()),
            rest_capacity=rest_capacity, mount=mount)

    def _advance(self, path: Path, state: State, normal_load) -> np.ndarray:
        """Run the model over ``path`` from ``state`` (updated in place); return forces."""
        kernel = self.step_kernel(state, normal_load)
        out = np.empty(path.t.shape[0])
        loads = None if normal_load is None else np.asarray(normal_load, dtype=np.float64)
        kernel.run(path.step, path.displacement, path.step_velocity, path.sample_velocity,
                   loads, 0, out.shape[0], True, out)
        self.unflatten_state(kernel.state, state)
        return out
