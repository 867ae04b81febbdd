"""Model and system files: TOML or JSON documents, read, checked for shape and written.

The formats are those of the user guide's :ref:`formats-model-files`: model
files (``[model]`` and an optional ``[fit]``, TOML or JSON; read by
:func:`read_model_file`, written by :func:`write_model_file` and
:func:`save_model`) and one-degree-of-freedom system files (``[system]``,
:ref:`formats-system`; read by :func:`read_system_file`).  A file is JSON
when its name ends in ``.json``, TOML otherwise.  This module holds no
physics: it reads, checks the shape of what it read (:func:`check_tables`),
and writes; the models validate their own parameters.  The files a model
names (its ``file_keys``) are relative to the model file in a file and
absolute once read.

Every problem with a file raises :class:`~polind.errors.InputError` with a
one-line message that starts with the file's path.  Every file is written
through :mod:`polind.io.output`: all of it, or nothing changes.
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from pathlib import Path

import numpy as np

from polind.errors import InputError, describe
from polind.io.output import atomic_write_text, check_output_path
from polind.io.text import read_text

__all__ = ["check_tables", "model_file_text", "plain_data",
           "read_document", "read_model_file", "read_system_file", "save_model",
           "write_model_file"]


# --- reading -----------------------------------------------------------------------------


def _reject_duplicate_keys(pairs):
    table = {}
    for key, value in pairs:
        if key in table:
            raise ValueError(f"duplicated key {key!r}")
        table[key] = value
    return table


#: The deepest nesting of tables and lists a document may have (polind's files need 4).
MAX_NESTING = 32


def _nesting(value, depth=0) -> int:
    """How deeply tables and lists nest in a parsed document (stops past MAX_NESTING)."""
    if depth > MAX_NESTING or not isinstance(value, (dict, list)):
        return depth
    items = value.values() if isinstance(value, dict) else value
    return max((_nesting(item, depth + 1) for item in items), default=depth + 1)


def read_document(path) -> dict:
    """Parse a TOML or JSON file (JSON if the name ends in ``.json``) into a dict.

    A document nested more than ``MAX_NESTING`` tables and lists deep
    is refused (a parser would run out of stack on a deep enough one), as is
    an integer of more digits than Python converts (4300).
    """
    name = os.fspath(path)
    text = read_text(path)
    nested = InputError(f"{name}: tables and lists nest too deeply; expected a document "
                        f"nested at most {MAX_NESTING} levels deep")
    if Path(path).suffix.lower() == ".json":
        try:
            document = json.loads(text, object_pairs_hook=_reject_duplicate_keys)
        except json.JSONDecodeError as exc:
            raise InputError(f"{name}: not valid JSON: {exc.msg} "
                             f"(at line {exc.lineno}, column {exc.colno})") from None
        except ValueError as exc:  # a duplicated key, an integer of too many digits
            raise InputError(f"{name}: not valid JSON: {exc}") from None
        except RecursionError:
            raise nested from None
        if not isinstance(document, dict):
            raise InputError(f"{name}: expected a JSON object at the top level, "
                             f"got {type(document).__name__}")
    else:
        try:
            document = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"{name}: not valid TOML: {exc}") from None
        except ValueError as exc:  # an integer of too many digits
            raise InputError(f"{name}: not valid TOML: {exc}") from None
        except RecursionError:
            raise nested from None
    if _nesting(document) > MAX_NESTING:
        raise nested
    return document


def check_tables(name, document, required, allowed):
    """Top-level keys: each required one present and a table, none unknown."""
    for key in document:
        if key not in allowed:
            raise InputError(f"{name}: unknown top-level key '{key}'; allowed: "
                             + ", ".join(f"[{table}]" for table in allowed))
    for key in allowed:
        if key in document and not isinstance(document[key], dict):
            raise InputError(f"{name}: '{key}' must be a table ([{key}]), "
                             f"got {describe(document[key])}")
    for key in required:
        if key not in document:
            raise InputError(f"{name}: no [{key}] table; expected a [{key}] table")


def read_model_file(path) -> dict:
    """Read a model file (:ref:`formats-model-files`) without validating parameters.

    Parameters
    ----------
    path : str or os.PathLike
        A TOML file, or JSON if its name ends in ``.json`` (any other name is
        read as TOML).

    Returns
    -------
    dict
        The document: a ``"model"`` table and, if present, a ``"fit"`` table.
        Read as written: the files a model names stay relative to the model
        file here (:func:`polind.models.read_model_document` makes them absolute).

    Raises
    ------
    InputError
        The file is missing or unreadable, is not valid TOML/JSON (the
        parser's line and column are given), has no ``[model]`` table, or has
        a top-level key other than ``model`` and ``fit``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "m.toml").write_text('[model]\\ntype = "coulomb"\\ncoulomb_force = 1.0\\n')
    >>> read_model_file(folder / "m.toml")
    {'model': {'type': 'coulomb', 'coulomb_force': 1.0}}
    """
    name = os.fspath(path)
    document = read_document(path)
    check_tables(name, document, required=("model",), allowed=("model", "fit"))
    return document


def read_system_file(path) -> dict:
    """Read a one-degree-of-freedom system file (:ref:`formats-system`).

    Only the file is checked here: its keys and values are checked by
    :func:`polind.load_system`, which declares them (:mod:`polind.dynamics`)
    and gives a bad value the message a :class:`polind.System` built in
    Python gives, after the file's name.

    Parameters
    ----------
    path : str or os.PathLike
        TOML (or JSON if the name ends in ``.json``) with a ``[system]`` table:
        ``mass`` [kg], ``duration`` [s], ``time_step`` [s], and at least one
        of ``[system.spring_drive]`` (``stiffness`` [N/m] >= 0, ``velocity``
        [m/s]) and ``[system.force]`` (``offset`` [N], ``rate`` [N/s],
        ``amplitude`` [N], ``frequency`` [Hz] >= 0; each defaults to 0).

    Returns
    -------
    dict
        The ``[system]`` table as the file has it.

    Raises
    ------
    InputError
        Naming the file: missing or unreadable, not valid TOML/JSON, no
        ``[system]`` table, or a top-level key other than ``system``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> system = pathlib.Path(tempfile.mkdtemp()) / "system.toml"
    >>> _ = system.write_text("[system]\\nmass = 1.0\\nduration = 2.0\\ntime_step = 0.01\\n"
    ...                       "[system.force]\\namplitude = 0.4\\nfrequency = 1.0\\n")
    >>> read_system_file(system)["force"]
    {'amplitude': 0.4, 'frequency': 1.0}
    """
    document = read_document(path)
    check_tables(os.fspath(path), document, required=("system",), allowed=("system",))
    return document["system"]


# --- writing -----------------------------------------------------------------------------


def plain_data(value, *, for_toml=True):
    """Python types TOML and JSON can hold: numpy scalars/arrays and tuples become
    floats and lists, paths strings.  For TOML (``for_toml=True``) ``None`` entries
    are dropped (TOML has no null: an absent key means its default); for JSON
    non-finite floats become ``None`` (``null``), which strict JSON readers need."""
    if isinstance(value, dict):
        return {str(key): plain_data(item, for_toml=for_toml) for key, item in value.items()
                if not (for_toml and item is None)}
    if isinstance(value, (list, tuple, np.ndarray)):
        items = value.tolist() if isinstance(value, np.ndarray) else value
        return [plain_data(item, for_toml=for_toml) for item in items]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if not for_toml and isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def model_file_text(document: dict, *, as_json=False) -> str:
    """The text of a model file holding ``document``: TOML (tomli-w), or indented JSON.

    Floats are written so that they read back bit for bit; ``None`` entries
    are left out (an absent key means its default).
    """
    plain = plain_data(document)
    if as_json:
        return json.dumps(plain, indent=2) + "\n"
    import tomli_w

    return tomli_w.dumps(plain)


def write_model_file(path, document: dict) -> None:
    """Write a model-file document (``{"model": {...}, "fit": {...}}``) atomically.

    TOML, or JSON (indented) if the name ends in ``.json``; the inverse of
    :func:`read_model_file`.
    """
    atomic_write_text(path, model_file_text(document,
                                            as_json=Path(path).suffix.lower() == ".json"))


def save_model(model, path) -> None:
    """Write ``model`` to a model file that :func:`polind.load_model` reads back equal.

    Parameters
    ----------
    model : polind.FrictionModel
        Any registered model type, with its nested tables, ``reference_load``
        and ``[model.compliance]``.
    path : str or os.PathLike
        TOML, or JSON (indented) if the name ends in ``.json``; ``-`` writes
        to standard output.  Written like every polind output
        (:ref:`cli-exit-status`): through a temporary file that replaces an existing
        file only once the whole model is on disk; a directory, or the
        model's own ``heights_file`` or ``topography``, is refused with an
        :class:`~polind.InputError`.

    A relative ``discretisation.heights_file`` or ``surface.topography`` is
    written as an absolute path (the file the model reads now), so the saved
    model reads the same summits wherever it is saved.

    Examples
    --------
    >>> import pathlib, tempfile, polind
    >>> model = polind.model_from_dict({"model": {"type": "lugre", "bristle_stiffness": 1e5,
    ...     "bristle_damping": 316.0, "viscous_coefficient": 0.4, "coulomb_force": 1.0,
    ...     "static_force": 1.5, "stribeck_velocity": 1e-3}})
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "lugre.toml"
    >>> polind.save_model(model, path)
    >>> polind.load_model(path) == model
    True
    """
    # A model is known by what it does (io sits below the models and does not import them).
    document = model.to_dict() if callable(getattr(model, "to_dict", None)) else None
    if not (isinstance(document, dict) and isinstance(document.get("model"), dict)
            and "type" in document["model"]):
        raise InputError(f"save_model needs a polind.FrictionModel. Got {describe(model)} "
                         f"instead.")
    # The files the model reads (it declares them): written absolute, and never replaced
    # by the model file.
    inputs = []
    files_in = getattr(model, "files_in", None)
    for entries, key, value in (files_in(document["model"]) if callable(files_in) else ()):
        entries[key] = os.path.abspath(value)
        inputs.append(entries[key])
    check_output_path(path, inputs=inputs)
    write_model_file(path, document)
