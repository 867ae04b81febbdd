"""One module per friction model; importing this package registers them all."""

from polind.models.base import (FrictionModel, Path, SpecialCase, State, StepFunctions,
                                StepKernel)
from polind.models.registry import MODEL_TYPES, model_class, register_model, unregister_model
from polind.models.static import Coulomb, Stribeck
from polind.models.dahl import Dahl
from polind.models.lugre import LuGre
from polind.models.maxwell_slip import MaxwellSlip
from polind.models.gms import GMS
from polind.models.leuven import Leuven
from polind.models.pol_ind import PolInd

# Any other model module of this package registers too: a new built-in model is its
# module here and its kernel (nothing else in polind names it).
import importlib as _importlib
import pkgutil as _pkgutil

for _module in _pkgutil.iter_modules(__path__):
    _importlib.import_module(f"{__name__}.{_module.name}")

__all__ = ["MODEL_TYPES", "FrictionModel", "Path", "SpecialCase", "State", "StepFunctions",
           "StepKernel", "register_model", "unregister_model", "model_class", "Coulomb",
           "Stribeck", "Dahl", "LuGre", "MaxwellSlip", "GMS", "Leuven", "PolInd"]

from polind.errors import InputError as _InputError
from polind.errors import describe as _describe


def model_from_dict(document: dict) -> FrictionModel:
    """Build a model from a model-file document ``{"model": {"type": ..., ...}}``.

    The bare ``[model]`` table (a dict with a ``type`` key) is accepted too.
    A ``fit`` table beside ``model`` is allowed and ignored here (see
    :func:`polind.identify`).  Bad parameters raise :class:`polind.InputError`
    naming the key.
    """
    if not isinstance(document, dict):
        raise _InputError(f"A model must be a table. Got {_describe(document)} instead.")
    if "type" in document and "model" not in document:
        table = document
    else:
        unknown = sorted(set(document) - {"model", "fit"})
        if unknown:
            raise _InputError(f"Unknown top-level key '{unknown[0]}' in a model document; "
                              f"expected 'model' and optionally 'fit'.")
        if "model" not in document:
            raise _InputError("A model document needs a [model] table.")
        table = document["model"]
    if not isinstance(table, dict):
        raise _InputError(f"The [model] table must be a table. Got {_describe(table)} instead.")
    if "type" not in table:
        raise _InputError("Missing key 'type' in the [model] table; expected one of: "
                          + ", ".join(sorted(MODEL_TYPES)) + ".")
    cls = model_class(table["type"])
    params = {key: value for key, value in table.items() if key != "type"}
    return cls(**params)


def _document_class(document):
    """The registered class of a model document's type, or None (left for model_from_dict)."""
    table = document.get("model") if isinstance(document, dict) else None
    model_type = table.get("type") if isinstance(table, dict) else None
    if not isinstance(model_type, str):
        return None
    cls = MODEL_TYPES.get(model_type)
    if cls is None:
        try:
            cls = model_class(model_type)          # an installed plugin's type
        except _InputError:
            cls = None
    return cls


def read_model_document(path) -> dict:
    """Read a model file (TOML or JSON) as a document, its files made absolute.

    The files a model names (its :meth:`~polind.FrictionModel.file_keys`, such as
    Pol-Ind's ``discretisation.heights_file`` and ``surface.topography``) are
    relative to the model file; here they become absolute, so the document can
    be built anywhere.  A type polind does not know is left for
    :func:`model_from_dict` to report.
    """
    import os

    from polind import io

    document = io.read_model_file(path)
    cls = _document_class(document)
    if cls is not None:
        folder = os.path.dirname(os.path.abspath(os.fspath(path)))
        for entries, key, value in cls.files_in(document["model"]):
            if not os.path.isabs(value):
                entries[key] = os.path.normpath(os.path.join(folder, value))
    return document


def document_files(document) -> list:
    """The files a model document names (:meth:`~polind.FrictionModel.files_in` of its type).

    As written in the document: absolute once read by :func:`read_model_document`.
    A document of an unknown type names none (building it is refused).

    Examples
    --------
    >>> document_files({"model": {"type": "pol-ind",
    ...                            "discretisation": {"heights_file": "/data/h.csv"}}})
    ['/data/h.csv']
    """
    cls = _document_class(document)
    return [] if cls is None else [value for _, _, value in cls.files_in(document["model"])]


def load_model(path) -> FrictionModel:
    """Read a model file (TOML, or JSON with the same structure) and build the model.

    Errors name the file: ``model.toml: Unknown key 'stifness' ...``.
    """
    document = read_model_document(path)
    try:
        return model_from_dict(document)
    except _InputError as error:
        raise _InputError(f"{path}: {error}") from None


__all__ += ["model_from_dict", "load_model", "read_model_document", "document_files"]
