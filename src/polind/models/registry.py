"""The model registry: which class a ``type`` names, and models from other packages.

polind's own models register when :mod:`polind.models` is imported; a model
defined elsewhere registers with :func:`register_model`; a package that ships
models declares them as entry points of the group ``polind.models`` (name:
the model's ``type``, value: ``"module:Class"``), which are loaded on the
first use of a type polind does not know (the convention of xarray's
backends and pytest's plugins; the user guide, :ref:`guide-own-models`).

:data:`MODEL_TYPES` is a read-only view: only :func:`register_model` and
:func:`unregister_model` change it.
"""

from __future__ import annotations

import threading
from types import MappingProxyType

from polind.errors import InputError, describe

#: The entry-point group a package declares its models in.
ENTRY_POINT_GROUP = "polind.models"

_REGISTRY: dict[str, type] = {}
_LOCK = threading.RLock()

#: Every registered model class by its ``type`` (read-only; in registration order).
MODEL_TYPES = MappingProxyType(_REGISTRY)


def register_model(cls, *, replace=False, check=True):
    """Make a :class:`~polind.FrictionModel` subclass usable everywhere under its ``type``.

    After ``polind.register_model(MyModel)`` the type can be named in model
    files (``type = "my-model"``) and runs in :func:`polind.simulate`,
    :class:`polind.Stepper`, :class:`polind.Body`,
    :func:`polind.simulate_system`, :func:`polind.identify` and sweeps,
    with no change to polind's own files.  The class must subclass
    :class:`~polind.FrictionModel`, name a new ``type`` (a non-empty string;
    pass ``replace=True`` to redefine one of your own) and supply
    ``step_functions`` and ``kernel_arrays``.  Returns the class, so it can
    be used as a decorator.

    Its ``parameters`` are checked first, whatever ``check`` says
    (``check_parameters``): an entry that is not a ``Param`` or ``Table``,
    an unknown ``kind`` or ``bound``, a repeated key or a default the entry
    refuses is an :class:`~polind.InputError` naming the class and the entry.

    With ``check`` (the default), what can be called on the class is called
    now: its ``example_parameters()`` (when it defines them) build a model
    whose ``initial_variables()``, ``characteristic_scales()``,
    ``step_functions()`` and ``kernel_arrays()`` must give what the stepping
    contract takes (its compiled functions returning numbers:
    ``check_compiled``), so that a wrong declaration (``step_functions()``
    returning a tuple, say) is an :class:`~polind.InputError` naming the
    method here rather than a failure inside a run.  A class without example
    parameters is checked the same way when a model of it is first stepped.
    polind's own models register without it (at import, numba unloaded).
    """
    from polind.models.base import FrictionModel

    if not (isinstance(cls, type) and issubclass(cls, FrictionModel)):
        raise InputError(f"register_model needs a subclass of polind.FrictionModel. "
                         f"Got {describe(cls)} instead.")
    name = getattr(cls, "type", "")
    if not isinstance(name, str) or not name:
        raise InputError(f"The model class {cls.__name__} must set 'type' to a non-empty "
                         f"string (its name in model files). Got {describe(name)} instead.")
    for method in ("step_functions", "kernel_arrays"):
        if getattr(cls, method) is getattr(FrictionModel, method):
            raise InputError(f"The model class {cls.__name__} must define {method}() "
                             f"(see polind.FrictionModel).")
    check_parameters(cls)
    _refuse_taken(name, cls, replace)
    if check:
        _check_declarations(cls)
    with _LOCK:
        _refuse_taken(name, cls, replace)       # again: registered meanwhile?
        _REGISTRY[name] = cls
    return cls


def _refuse_taken(name, cls, replace) -> None:
    with _LOCK:
        if name in _REGISTRY and _REGISTRY[name] is not cls and not replace:
            raise InputError(f"The model type '{name}' is already registered (by "
                             f"{_REGISTRY[name].__name__}); choose another name.")


#: The kinds a :class:`~polind.models.params.Param` may declare.
PARAM_KINDS = ("float", "int", "list", "pair", "str", "path", "bool")


def check_parameters(cls) -> None:
    """Refuse a model class whose ``parameters`` polind could not use, naming the entry.

    Each entry must be a :class:`~polind.Param` or :class:`~polind.Table` with a
    key that is a name (unique in its table), a known ``kind`` and ``bound``,
    ``choices`` of strings and a ``default`` its own checks accept (or none).
    """
    _check_entries(cls, getattr(cls, "parameters", None), "")


def _check_entries(cls, entries, prefix) -> None:
    from polind.models.params import REQUIRED, Param, Table

    owner = f"The model class {cls.__name__}"
    where = f"'{prefix.rstrip('.')}' table's entries" if prefix else "'parameters'"
    if not isinstance(entries, tuple):
        raise InputError(f"{owner} must declare its {where} as a tuple of polind Param and "
                         f"Table entries. Got {describe(entries)} instead.")
    seen = set()
    for index, entry in enumerate(entries):
        if not isinstance(entry, (Param, Table)):
            raise InputError(f"{owner} declares {describe(entry)} as entry {index} of its "
                             f"{where}; expected a polind Param or Table (such as "
                             f"polind.Param('stiffness', unit='N/m')).")
        key = entry.key
        if not (isinstance(key, str) and key.isidentifier()):
            raise InputError(f"{owner} declares a parameter whose key is {describe(key)} (entry "
                             f"{index} of its {where}); expected a name of letters, digits "
                             f"and underscores.")
        name = f"'{prefix}{key}'"
        if key in seen:
            raise InputError(f"{owner} declares the parameter {name} twice; expected each key "
                             f"once.")
        seen.add(key)
        if isinstance(entry, Table):
            if not (entry.default is REQUIRED or entry.default is None
                    or isinstance(entry.default, dict)):
                raise InputError(f"{owner} declares the table {name} with the default "
                                 f"{describe(entry.default)}; expected a dict, None or none.")
            _check_entries(cls, entry.entries, f"{prefix}{key}.")
        else:
            _check_param(cls, owner, name, entry, prefix)


def _check_param(cls, owner, name, entry, prefix) -> None:
    from polind.models.params import BOUNDS, REQUIRED, validate_table

    if entry.kind not in PARAM_KINDS:
        raise InputError(f"{owner} declares the parameter {name} of kind {describe(entry.kind)}; "
                         f"expected one of: {', '.join(PARAM_KINDS)}.")
    if entry.bound not in BOUNDS:
        raise InputError(f"{owner} declares the parameter {name} with the bound "
                         f"{describe(entry.bound)}; expected one of: {', '.join(BOUNDS)}.")
    if not (isinstance(entry.choices, tuple)
            and all(isinstance(choice, str) for choice in entry.choices)):
        raise InputError(f"{owner} declares the parameter {name} with the choices "
                         f"{describe(entry.choices)}; expected a tuple of strings.")
    for field in ("unit", "description", "symbol"):
        if not isinstance(getattr(entry, field), str):
            raise InputError(f"{owner} declares the parameter {name} with the {field} "
                             f"{describe(getattr(entry, field))}; expected a string.")
    if entry.default is REQUIRED or entry.default is None:
        return
    try:
        validate_table(getattr(cls, "type", cls.__name__), (entry,), {entry.key: entry.default},
                       prefix)
    except InputError as error:
        raise InputError(f"{owner} declares the parameter {name} with a default its own "
                         f"checks refuse: {error}") from None


def _check_declarations(cls) -> None:
    """Call what can be called on a model class; an InputError names a method that is wrong."""
    from polind.models.base import FrictionModel
    from polind.models.checks import call_declared

    if cls.example_parameters.__func__ is FrictionModel.example_parameters.__func__:
        return                          # nothing to build a model from: checked when stepped
    parameters = call_declared(cls, "example_parameters")
    if not isinstance(parameters, dict):
        raise InputError(f"The model class {cls.__name__}'s example_parameters() must return a "
                         f"dict of parameters. Got {describe(parameters)} instead.")
    try:
        model = cls(**parameters)
    except InputError as error:
        raise InputError(f"The model class {cls.__name__}'s example_parameters() give a model "
                         f"it refuses: {error}") from None
    except Exception as error:  # noqa: BLE001 - the class's own code
        raise InputError(f"The model class {cls.__name__} cannot be built from its "
                         f"example_parameters(): {type(error).__name__}: {error}") from None
    check_compiled(model, call_declared(model, "step_kernel"))


# --- what a model's compiled functions give ---------------------------------------------------

#: The stepping contract's functions and the numbers they take after the three arrays.
_FUNCTIONS = {"step": ("h", "dx", "step_velocity", "sample_velocity", "normal_load"),
              "force": ("sample_velocity", "normal_load"),
              "tangent": ("h",)}


def check_compiled(model, kernel) -> None:
    """Refuse a model of one's own whose step, force or tangent does not give a number.

    Each function of ``kernel`` (the model's :class:`~polind.models.kernel.StepKernel`)
    is compiled by numba for the arguments the runners pass it (the kernel's
    ``scalars``, ``table`` and ``state`` arrays, then float64 numbers), as a run
    would compile it (the run then finds it compiled).  A function numba cannot
    type, or one that returns something else than a number (a step that only
    raises returns nothing; an array is not a force), is an
    :class:`~polind.InputError` naming the model's plugin or class and the
    function, in one line, instead of numba's typing error from inside polind's
    runner.  polind's own models are not checked.
    """
    cls = type(model)
    if cls.__module__.split(".")[0] == "polind":
        return
    from numba import typeof, types
    from numba.core.errors import NumbaError

    arrays = tuple(typeof(array) for array in (kernel.scalars, kernel.table, kernel.state))
    for name, numbers in _FUNCTIONS.items():
        function = getattr(kernel, name)
        signature = arrays + (types.float64,) * len(numbers)
        try:
            function.compile(signature)
            returned = function.overloads[signature].signature.return_type
        except NumbaError as error:
            first = " ".join(str(error).split("\n")[:2])
            raise InputError(f"{model_origin(cls)}: its {name} function does not compile for "
                             f"the arguments polind passes it (scalars, table, state, "
                             f"{', '.join(numbers)}): {type(error).__name__}: "
                             f"{first[:300]}") from None
        if not isinstance(returned, (types.Float, types.Integer)):
            raise InputError(f"{model_origin(cls)}: its {name} function must return a number "
                             f"(a float). It returns {returned} instead"
                             + (" (it only raises)" if returned == types.none else "") + ".")


_ORIGINS: dict[type, str] = {}


def model_origin(cls) -> str:
    """Where a model class comes from, for messages: its plugin (entry point and package),
    else its class and module."""
    return _ORIGINS.get(cls) or f"The model class {cls.__module__}.{cls.__qualname__}"


def unregister_model(model_type: str) -> type:
    """Remove a registered type (a test's or a plugin's own model); returns its class.

    An unknown type is an :class:`~polind.InputError`.
    """
    with _LOCK:
        if model_type not in _REGISTRY:
            raise InputError(f"The model type {describe(model_type)} is not registered; "
                             f"registered: {', '.join(_REGISTRY)}.")
        return _REGISTRY.pop(model_type)


def _entry_points():
    from importlib.metadata import entry_points

    return entry_points(group=ENTRY_POINT_GROUP)


def _package_of(entry_point) -> str:
    dist = getattr(entry_point, "dist", None)
    name = getattr(dist, "name", None) if dist is not None else None
    return name or entry_point.value.partition(":")[0].partition(".")[0]


def _load_plugin(entry_point):
    """Import one entry point's class and register it, or fail naming its package."""
    from polind.models.base import FrictionModel

    package = _package_of(entry_point)
    where = f"The model plugin '{entry_point.name}' ({entry_point.value}) of the package " \
            f"'{package}'"
    try:
        cls = entry_point.load()
    except KeyboardInterrupt:
        raise
    except SystemExit as error:     # its import called sys.exit: not a model, whatever the code
        raise InputError(f"{where} failed to load: its import called sys.exit({error.code!r}); "
                         f"expected it to define its model class.") from None
    except BaseException as error:  # noqa: BLE001 - a plugin's own import failure, whatever it is
        raise InputError(f"{where} failed to load: {type(error).__name__}: {error}") from None
    if not (isinstance(cls, type) and issubclass(cls, FrictionModel)):
        raise InputError(f"{where} is not a subclass of polind.FrictionModel. "
                         f"Got {describe(cls)} instead.")
    if getattr(cls, "type", None) != entry_point.name:
        raise InputError(f"{where} declares the type '{entry_point.name}' but its class "
                         f"{cls.__name__} has type {describe(getattr(cls, 'type', None))}; "
                         f"expected the two to agree.")
    _ORIGINS[cls] = where
    try:
        register_model(cls, replace=_REGISTRY.get(cls.type) is cls)
    except InputError as error:
        message = str(error)
        raise InputError(message if message.startswith(where) else f"{where}: {message}") \
            from None
    return cls


def check_plugins() -> None:
    """Refuse an installed plugin that declares a type polind already has (naming its package)."""
    for entry_point in _entry_points():
        known = _REGISTRY.get(entry_point.name)
        if known is not None and f"{known.__module__}:{known.__qualname__}" != entry_point.value:
            raise InputError(f"The model plugin '{entry_point.name}' ({entry_point.value}) of "
                             f"the package '{_package_of(entry_point)}' declares the type "
                             f"'{entry_point.name}', which polind already has (by "
                             f"{known.__module__}.{known.__qualname__}); expected a new name.")


def model_class(model_type, what="for key 'type'"):
    """The class registered for ``model_type``, loading an installed plugin on first use.

    An unknown type is an :class:`~polind.InputError` listing the known types;
    a plugin that fails to load, or declares a type polind already has, is one
    naming its package.
    """
    if isinstance(model_type, str) and model_type in _REGISTRY:
        return _REGISTRY[model_type]
    if isinstance(model_type, str) and model_type:
        with _LOCK:
            if model_type not in _REGISTRY:
                check_plugins()
                for entry_point in _entry_points():
                    if entry_point.name == model_type:
                        return _load_plugin(entry_point)
            else:
                return _REGISTRY[model_type]
    raise InputError(f"Unknown model type {describe(model_type)} {what}; expected one of: "
                     + ", ".join(sorted(_REGISTRY)) + ".")


def load_plugins() -> dict:
    """Load every installed model plugin (for listings: the docs, ``polind bench``).

    Returns :data:`MODEL_TYPES` as a plain dict.
    """
    check_plugins()
    for entry_point in _entry_points():
        if entry_point.name not in _REGISTRY:
            _load_plugin(entry_point)
    return dict(_REGISTRY)
