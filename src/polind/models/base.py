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
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from polind.errors import InputError
from polind.models.checks import call_declared, check_scales, check_sizes, check_step_parts
from polind.models.kernel import (SCALARS_OFFSET, STATE_OFFSET, TABLE_OFFSET, StepFunctions,
                                  StepKernel, page_placed)
from polind.models.registry import MODEL_TYPES, register_model
from polind.models.params import Param, Table, validate_table
from polind.models.state import Path, State


def register(cls):
    """polind's own models register with :func:`register_model`, as a class decorator.

    Without calling their methods at import (that would load numba): the
    conformance tests hold polind's own models to the contract.
    """
    return register_model(cls, check=False)


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


@dataclass(frozen=True)
class SpecialCase:
    """A model that another contains as a special case (the user guide, :ref:`guide-fit-starts`).

    :meth:`polind.FrictionModel.special_case` returns one: identification fits the
    contained model first and starts the containing model from that fit too,
    so the containing model never ends worse in sample than the model it
    contains (where its free keys can reproduce it).

    Attributes
    ----------
    kind : type
        The contained model's class (:meth:`polind.FrictionModel.contains`).
    model : FrictionModel
        The contained model at the containing model's values: the start of its fit.
    free : tuple of str
        The contained model's keys to fit: those the containing model's free
        keys can reproduce.
    lift : callable
        ``lift(fitted)``: a model of the containing type whose force equals
        that of the fitted contained model ``fitted`` (identification takes
        its free keys from it and keeps the others).
    description : str
        What the special case is, for the ``start`` of a fit's result
        (``"maxwell-slip (gms with Fs = Fc)"``).
    """

    kind: type
    model: "FrictionModel"
    free: tuple
    lift: Callable
    description: str


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
      ``characteristic_scales``, ``phenomena`` and ``fit_defaults``, and for
      identification ``structured_starts`` and ``contains`` /
      ``special_case`` (the starting points of a fit).

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
    #: When to use it, a paragraph (reST; the guide's "Which one to use").
    advice: ClassVar[str] = ""
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
        if not isinstance(cls.parameters, (tuple, list)):
            return          # not a declaration: register_model refuses it, naming it
        own = {getattr(entry, "key", None) for entry in cls.parameters}
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
    def file_keys(cls) -> tuple:
        """The dotted keys whose values are files the model reads (declared ``kind="path"``).

        Relative to the model file in a file, absolute once read
        (:func:`polind.models.read_model_document`); inputs no output of a command may
        replace.
        """
        def walk(entries, prefix):
            for entry in entries:
                if isinstance(entry, Table):
                    yield from walk(entry.entries, f"{prefix}{entry.key}.")
                elif entry.kind == "path":
                    yield prefix + entry.key
        return tuple(walk(cls.parameters, ""))

    @classmethod
    def files_in(cls, table) -> list:
        """``(sub-table, key, value)`` of each file key present in a ``[model]`` table (a dict).

        ``sub-table`` is the dict holding the key (to rewrite it in place); a value
        that is not a non-empty string is the model's to reject and is left out.
        """
        found = []
        for dotted in cls.file_keys():
            *tables, key = dotted.split(".")
            entries = table
            for name in tables:
                entries = entries.get(name) if isinstance(entries, dict) else None
            if isinstance(entries, dict) and isinstance(entries.get(key), str) \
                    and entries[key]:
                found.append((entries, key, entries[key]))
        return found

    def files(self) -> list:
        """The files this model reads (absolute paths once read from a model file)."""
        return [value for _, _, value in self.files_in(self._params)]

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
        """The model's numba ``step``, ``force`` and ``tangent`` (:class:`polind.StepFunctions`)."""
        raise NotImplementedError(f"The {type(self).__name__} model does not supply "
                                  "step_functions().")

    def fixed_load_step_functions(self, state: State) -> StepFunctions | None:
        """Lighter step functions for a run that never leaves the model's own load, or None.

        Asked by :meth:`step_kernel` for a run at the model's constant load
        from ``state`` (``fixed_load=True``).  A model whose step also
        handles a changing normal load may return functions without that
        path, which then need not be compiled; the arrays stay those of
        :meth:`kernel_arrays`.  Default: None (the model's own
        :meth:`step_functions` serve every run).
        """
        return None

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

    def structured_starts(self, path: Path, force: np.ndarray, free: list) -> dict:
        """Starting models of a fit computed from the structure of a record.

        Identification (:ref:`guide-fit-starts`) fits from each of them too and
        keeps the best fit.  A start need only set the keys it estimates:
        identification takes the ``free`` keys from it and keeps this model's
        other values.

        Parameters
        ----------
        path : Path
            The fitted samples' motion (positions [m], velocities [m/s]).
        force : ndarray
            The measured force at each sample [N].
        free : list of str
            The keys the fit frees.

        Returns
        -------
        dict
            ``{label: model of this type}`` (default: none).  A start the
            record cannot give (an :class:`~polind.InputError`) is left out.
        """
        return {}

    @classmethod
    def contains(cls) -> type | None:
        """The model class this one contains as a special case, or None (default)."""
        return None

    def special_case(self, free: list, path: Path) -> SpecialCase | None:
        """The special case of :meth:`contains` to fit first, for a fit freeing ``free``.

        ``path`` is the motion of the fitted samples (a special case may need
        its speeds).  None (the default) when the model contains none or
        when the free keys cannot reproduce it.
        """
        return None

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

    def check_numbers(self) -> None:
        """Finite or refused: numbers its arithmetic can take, else an InputError naming them.

        Every float parameter is 0 or of a physical size and the
        characteristic scales are finite and normal, their force levels
        resolved (:mod:`polind.models.checks`).  Checked once per model,
        before its first state or kernel is built.
        """
        if self.__dict__.get("_numbers_checked"):
            return
        check_sizes(self.type, self.parameters, self._params)
        check_scales(self.type, call_declared(self, "characteristic_scales"))
        self._numbers_checked = True

    def initial_state(self, normal_load=None) -> State:
        """The state at rest before any motion (all internal variables zero)."""
        self.check_numbers()
        variables = call_declared(self, "initial_variables", normal_load)
        try:
            return State(self.type, variables=variables)
        except InputError as error:
            raise InputError(f"The model class {type(self).__name__}'s initial_variables() "
                             f"must give a dict of finite arrays: {error}") from None

    def _state_keys(self) -> tuple:
        if self.state_keys is not None:
            return tuple(self.state_keys)
        return tuple(self.initial_variables(None))

    def check_state(self, state: State) -> None:
        """A state must belong to this model, have its shapes and hold finite numbers."""
        if state.model_type != self.type:
            raise InputError(f"The state is of a '{state.model_type}' model but the model is "
                             f"'{self.type}'.")
        state.check_finite()
        expected = self.initial_variables(None)
        for key, value in expected.items():
            if key not in state.variables:
                raise InputError(f"The state lacks its '{key}' entry for a {self.type} model.")
            if np.shape(state.variables[key]) != np.shape(value):
                raise InputError(f"The state's '{key}' has {np.size(state.variables[key])} "
                                 f"entries; the {self.type} model has {np.size(value)}.")

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
                    varying_load=None, fixed_load=False) -> StepKernel:
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
        fixed_load : bool, default False
            The run stays at the model's own constant load (no ``normal_load``
            given, none passed to the functions but the kernel's ``normal_load``):
            the model may then give lighter functions
            (:meth:`fixed_load_step_functions`), which compile faster and must
            not be stepped at another load.

        Returns
        -------
        StepKernel
            Its ``state`` array is a copy: stepping it leaves ``state`` as it was.
        """
        self.check_numbers()
        if state is None:
            state = self.initial_state(normal_load)
        else:
            self.check_state(state)
            state.check_entries(self)       # the one check of every model's given state
        functions = None
        if fixed_load and normal_load is None and not varying_load:
            functions = self.fixed_load_step_functions(state)
        if functions is None:
            functions = call_declared(self, "step_functions")
        arrays = call_declared(self, "kernel_arrays", state)
        check_step_parts(self, functions, arrays, state.variables)
        scalars, table = arrays
        if varying_load is None:
            varying_load = normal_load is not None
        mount = self.mount_array(state, varying_load)
        rest_capacity = self.rest_capacity()
        if mount is not None and self.series_stiffness < math.inf:
            rest_capacity = None     # the spring is state: the mounted contact is not memoryless
        return StepKernel(
            step=functions.step, force=functions.force, tangent=functions.tangent,
            runners=functions.runner_module(),
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
