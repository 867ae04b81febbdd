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

    With ``check`` (the default), what can be called on the class is called
    now: its ``example_parameters()`` (when it defines them) build a model
    whose ``initial_variables()``, ``characteristic_scales()``,
    ``step_functions()`` and ``kernel_arrays()`` must give what the stepping
    contract takes, so that a wrong declaration (``step_functions()``
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


def _check_declarations(cls) -> None:
    """Call what can be called on a model class; an InputError names a method that is wrong."""
    from polind.models.base import FrictionModel
    from polind.models.checks import call_declared

    if not isinstance(getattr(cls, "parameters", None), tuple):
        raise InputError(f"The model class {cls.__name__} must declare 'parameters' as a tuple "
                         f"of polind Param and Table entries. Got "
                         f"{describe(getattr(cls, 'parameters', None))} instead.")
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
    call_declared(model, "step_kernel")


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
    except Exception as error:       # a plugin's own import failure, whatever it is
        raise InputError(f"{where} failed to load: {type(error).__name__}: {error}") from None
    if not (isinstance(cls, type) and issubclass(cls, FrictionModel)):
        raise InputError(f"{where} is not a subclass of polind.FrictionModel. "
                         f"Got {describe(cls)} instead.")
    if getattr(cls, "type", None) != entry_point.name:
        raise InputError(f"{where} declares the type '{entry_point.name}' but its class "
                         f"{cls.__name__} has type {describe(getattr(cls, 'type', None))}; "
                         f"expected the two to agree.")
    try:
        register_model(cls, replace=_REGISTRY.get(cls.type) is cls)
    except InputError as error:
        raise InputError(f"{where}: {error}") from None
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
