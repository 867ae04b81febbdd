"""Structure files (:ref:`formats-structure`): ``[structure]``, its contacts and its run.

A structure file is TOML (or JSON by extension, read by
:func:`polind.io.read_document` like every polind document)::

    [structure]
    mass = [[1.0, 0.0], [0.0, 0.5]]          # kg, n x n (a number for n = 1)
    stiffness = [[2e4, 0.0], [0.0, 0.0]]     # N/m, optional
    damping = [[2.0, 0.0], [0.0, 0.0]]       # N s/m, optional

    [[structure.contacts]]
    model = "joint.toml"                     # a model file, relative to this file
    dofs = [0, 1]                            # u = q_0 - q_1; [0]: q_0 against the ground

    [structure.run]
    duration = 0.2                           # s
    time_step = 1e-5                         # s
    [structure.run.force]                    # f_i(t) = offset_i + amplitude_i sin(2 pi frequency t)
    amplitude = [20.0, 0.0]                  # N
    frequency = 50.0                         # Hz

The run may instead be solved by harmonic balance: ``kind =
"frequency_response"`` (``omega_range``, ``force``, ...) or ``kind =
"backbone"`` (``amplitudes``, ``mode``, ...), read by
:mod:`polind.structures.frequency_files` into a
:class:`~polind.structures.FrequencyResponseRun` or a
:class:`~polind.structures.BackboneRun`.

:func:`load_structure` reads one into a :class:`~polind.Structure` and its
run; :func:`structure_from_dict` builds them from the parsed document.  Every
run has the methods ``polind structure`` calls whatever its kind: ``solve``
(the run itself), ``columns`` (its table), ``figure`` (its PNG) and
``summary`` (one line).  Every key is declared here (:data:`STRUCTURE_KEYS`,
:data:`CONTACT_KEYS`, :data:`RUN_KEYS`, :data:`FORCE_KEYS`) or in
:mod:`~polind.structures.frequency_files`: an unknown key
is an :class:`~polind.InputError` naming it, its table and the known keys,
and a bad value names its dotted key (``structure.contacts[1].dofs``), the
file and what is expected.  The matrices are then checked by
:class:`~polind.Structure` itself (symmetric, positive-definite mass), and
each contact's model by the model (:func:`polind.model_from_dict`), its
message after the contact's key.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe

__all__ = ["CONTACT_KEYS", "FORCE_KEYS", "RUN_KEYS", "RUN_KINDS", "STRUCTURE_KEYS",
           "StructureRun", "load_structure", "structure_files", "structure_from_dict"]

#: The keys of ``[structure]``.
STRUCTURE_KEYS = ("mass", "stiffness", "damping", "contacts", "run")
#: The keys of each ``[[structure.contacts]]`` entry.
CONTACT_KEYS = ("model", "dofs")
#: The keys of ``[structure.run]`` for a run of kind ``"time"`` (the default).
RUN_KEYS = ("kind", "duration", "time_step", "initial_position", "initial_velocity", "method",
            "force")
#: The keys of ``[structure.run.force]``.
FORCE_KEYS = ("offset", "amplitude", "frequency")
#: The kinds of run a structure file may ask for: in time, and by harmonic balance
#: (:mod:`polind.structures.frequency_files`, whose keys are declared there).
RUN_KINDS = ("time", "frequency_response", "backbone")
#: The integration schemes of ``method`` (those of :func:`polind.simulate_structure`).
METHODS = ("bdf2", "euler")

#: What a run keeps per sample and coordinate (q, dq, applied) and per contact [bytes].
_BYTES_PER_COORDINATE = 24
_BYTES_PER_CONTACT = 8


@dataclass(frozen=True)
class StructureRun:
    """The time run of a structure file's ``[structure.run]`` (:ref:`formats-structure`).

    Attributes
    ----------
    duration, time_step : float
        Length of the run and sample spacing (the integration step) [s].
    initial_position, initial_velocity : ndarray
        ``q`` [m] and ``q'`` [m/s] at ``t = 0``, ``(n,)``.
    method : str
        ``"bdf2"`` or ``"euler"``.
    offset, amplitude : ndarray
        The applied force ``f_i(t) = offset_i + amplitude_i sin(2 pi frequency t)``
        [N], ``(n,)``.
    frequency : float
        [Hz].
    kind : str
        ``"time"``.

    Examples
    --------
    >>> import numpy as np
    >>> run = StructureRun(duration=1.0, time_step=0.25, amplitude=np.array([2.0]),
    ...                    frequency=1.0)
    >>> run.times
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    >>> run.applied(run.times)[:, 0].round(12)
    array([ 0.,  2.,  0., -2., -0.])
    """

    duration: float
    time_step: float
    initial_position: np.ndarray | None = None
    initial_velocity: np.ndarray | None = None
    method: str = "bdf2"
    offset: np.ndarray | None = None
    amplitude: np.ndarray | None = None
    frequency: float = 0.0
    kind: str = "time"

    @property
    def times(self) -> np.ndarray:
        """The sample times [s]: every ``time_step`` from 0 up to ``duration``."""
        steps = int(math.floor(self.duration / self.time_step * (1.0 + 1e-12)))
        return np.arange(steps + 1, dtype=np.float64) * self.time_step

    def applied(self, t) -> np.ndarray:
        """The applied forces [N] at the times ``t``: ``(len(t), n)``."""
        t = np.asarray(t, dtype=np.float64).reshape(-1, 1)
        offset = np.zeros(1) if self.offset is None else self.offset
        amplitude = np.zeros(1) if self.amplitude is None else self.amplitude
        return offset + amplitude * np.sin(2.0 * np.pi * self.frequency * t)

    #: What the progress of :meth:`solve` counts.
    progress_unit = " steps"

    def simulate(self, structure, *, progress=None):
        """Run it: :func:`polind.simulate_structure` of ``structure`` over :attr:`times`."""
        from polind.structures.core import simulate_structure

        t = self.times
        force = np.broadcast_to(self.applied(t), (t.shape[0], structure.size))
        return simulate_structure(structure, t, force=np.ascontiguousarray(force),
                                  initial_position=self.initial_position,
                                  initial_velocity=self.initial_velocity, method=self.method,
                                  progress=progress)

    def solve(self, structure, *, progress=None):
        """Run it (:meth:`simulate`): the name every kind of run shares."""
        return self.simulate(structure, progress=progress)

    def columns(self, result) -> dict:
        """The table of a result: ``t, q_0..q_{n-1}, dq_0..dq_{n-1}, F_0..F_{m-1}``."""
        n, m = result.q.shape[1], result.contact_forces.shape[1]
        columns = {"t": result.t}
        columns.update({f"q_{i}": result.q[:, i] for i in range(n)})
        columns.update({f"dq_{i}": result.dq[:, i] for i in range(n)})
        columns.update({f"F_{c}": result.contact_forces[:, c] for c in range(m)})
        return columns

    def figure(self, result, structure, *, source=None) -> bytes:
        """The PNG of a result (:func:`polind.structures.plot_structure`): a driven run's
        loops are drawn bold over their last period."""
        from polind.structures.plot import plot_structure

        driven = self.frequency > 0.0 and self.amplitude is not None and self.amplitude.any()
        return plot_structure(result, structure, None,
                              last_cycle=1.0 / self.frequency if driven else None,
                              title=(f"{source}: " if source else "") + "the response")

    def summary(self, result) -> str:
        """One line: the samples, coordinates and contacts, and any step short of tolerance."""
        n, m = result.q.shape[1], result.contact_forces.shape[1]
        short = f"; {result.unconverged_steps} steps short of the contacts' solver " \
            "tolerance" if result.unconverged_steps else ""
        return (f"{len(result.t)} samples, {n} coordinates, {m} contact"
                f"{'s' if m != 1 else ''}{short}")


# --- checks of single values ------------------------------------------------------------

def _fail(key, expected, value):
    raise InputError(f"key '{key}': expected {expected}; got {describe(value)}")


def _known(table, allowed, where, key_prefix):
    """Every key of ``table`` is one of ``allowed``: else an error naming it and its table."""
    for key in table:
        if key not in allowed:
            raise InputError(f"unknown key '{key_prefix}{key}' in [{where}]; expected one of: "
                             f"{', '.join(allowed)}")


def _table(key, value):
    if not isinstance(value, dict):
        _fail(key, f"a table ([{key}])", value)
    return value


def key_number(key, value, bound="any", index=None):
    """The value of ``key``: a finite float (a positive one for ``bound="positive"``).

    An :class:`~polind.InputError` naming the dotted key otherwise (this module's
    and :mod:`polind.structures.frequency_files`' message).
    """
    where = "" if index is None else f" at index {index}"
    expected = {"positive": "a positive number", "nonnegative": "a non-negative number",
                "any": "a finite number"}[bound]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"key '{key}': expected {expected}; got {describe(value)}{where}")
    try:
        number = float(value)
    except OverflowError:
        raise InputError(f"key '{key}': expected {expected} of double precision; got "
                         f"{describe(value)}{where}") from None
    if not math.isfinite(number) or (bound == "positive" and not number > 0.0) \
            or (bound == "nonnegative" and not number >= 0.0):
        raise InputError(f"key '{key}': expected {expected}; got {describe(value)}{where}")
    return number


def _count(count, noun):
    return f"{count} {noun}{'' if count == 1 else 's'}"


def key_vector(key, value, n):
    """The value of ``key``: ``n`` finite numbers, one per coordinate (a number for ``n = 1``)."""
    expected = f"a list of {n} numbers, one per coordinate" + \
        (" (or a number)" if n == 1 else "")
    if n == 1 and not isinstance(value, list):
        return np.array([key_number(key, value)])
    if not isinstance(value, list):
        _fail(key, expected, value)
    if len(value) != n:
        raise InputError(f"key '{key}': expected {expected}; got {_count(len(value), 'number')}")
    return np.array([key_number(key, item, index=i) for i, item in enumerate(value)])


def _matrix(key, value, n=None):
    """A square matrix of finite numbers (a number for 1 x 1); ``n`` rows if given."""
    shape = "n x n" if n is None else f"{n} x {n}"
    expected = f"an {shape} matrix (a list of rows, each a list of numbers)" \
        if n is None else f"a {shape} matrix (a list of {n} rows of {n} numbers)"
    if n is not None:
        expected += ", the shape of 'structure.mass'"
    if not isinstance(value, list):
        if n in (None, 1) and not isinstance(value, (dict, str)):
            return np.array([[key_number(key, value)]])
        _fail(key, expected + (" or a number" if n in (None, 1) else ""), value)
    rows = len(value)
    if rows == 0 or (n is not None and rows != n):
        raise InputError(f"key '{key}': expected {expected}; got {_count(rows, 'row')}")
    matrix = np.empty((rows, rows))
    for i, row in enumerate(value):
        if not isinstance(row, list) or len(row) != rows:
            got = _count(len(row), "number") if isinstance(row, list) else describe(row)
            raise InputError(f"key '{key}': expected {expected}; got {got} in row {i}")
        for j, item in enumerate(row):
            matrix[i, j] = key_number(key, item, index=f"[{i}, {j}]")
    return matrix


def _dofs(key, value, n):
    expected = (f"[i] (coordinate i against the ground) or [i, j] (u = q_i - q_j), "
                f"coordinates 0 to {n - 1}")
    if isinstance(value, int) and not isinstance(value, bool):
        value = [value]
    if not isinstance(value, list) or not 1 <= len(value) <= 2:
        _fail(key, expected, value)
    if len(value) == 2 and value[1] is None:         # JSON's [i, null]
        value = value[:1]
    for index, dof in enumerate(value):
        if isinstance(dof, bool) or not isinstance(dof, int) or not 0 <= dof < n:
            raise InputError(f"key '{key}': expected {expected}; got {describe(dof)} at index "
                             f"{index}")
    if len(value) == 2 and value[0] == value[1]:
        raise InputError(f"key '{key}': expected two different coordinates; got "
                         f"{describe(value)}")
    return tuple(value)


# --- the document -----------------------------------------------------------------------

def _model(key, value, base_dir):
    """The model of a contact: a model file (relative to ``base_dir``) or an inline table."""
    from polind.models import MODEL_TYPES, load_model, model_from_dict

    if isinstance(value, str) and value:
        path = value if os.path.isabs(value) else os.path.join(base_dir, value)
        try:
            return load_model(path)
        except InputError as error:
            raise InputError(f"key '{key}' ({value!r}): {error}") from None
    if not isinstance(value, dict):
        _fail(key, "a model file name, or a model table ([structure.contacts.model] with "
                   "the keys of a [model] table)", value)
    table = dict(value)
    cls = MODEL_TYPES.get(table.get("type")) if isinstance(table.get("type"), str) else None
    if cls is not None:
        # The files an inline model names (heights_file, topography) are relative to the
        # structure file, as those of a model file are relative to the model file.
        table = _copy_tables(table)
        for entries, name, path in cls.files_in(table):
            if not os.path.isabs(path):
                entries[name] = os.path.normpath(os.path.join(base_dir, path))
    try:
        return model_from_dict({"model": table})
    except InputError as error:
        raise InputError(f"key '{key}': {error}") from None


def _copy_tables(table):
    return {key: _copy_tables(item) if isinstance(item, dict) else item
            for key, item in table.items()}


def _contact_kernel(key, model):
    """The model's kernels, built now so that a model that gives none is blamed on its key."""
    try:
        return model.step_kernel(fixed_load=True)
    except InputError as error:
        raise InputError(f"key '{key}': {error}") from None


def _run(table, n, m):
    """The run of a ``[structure.run]`` table: a :class:`StructureRun`, or by harmonic balance."""
    from polind.structures.frequency_files import HARMONIC_KINDS, harmonic_run

    kind = table.get("kind", "time")
    if not isinstance(kind, str) or kind not in RUN_KINDS:
        _fail("structure.run.kind", ", ".join(f"'{k}'" for k in RUN_KINDS[:-1])
              + f" or '{RUN_KINDS[-1]}'", kind)
    if kind in HARMONIC_KINDS:
        return harmonic_run(table, kind, n, m)
    for other in HARMONIC_KINDS:
        if other in table:
            raise InputError(f"unknown key 'structure.run.{other}' in [structure.run]; a "
                             f"'{other}' run is kind = '{other}' with its keys in "
                             f"[structure.run] itself")
    _known(table, RUN_KEYS, "structure.run", "structure.run.")
    for key in ("duration", "time_step"):
        if key not in table:
            raise InputError(f"missing key 'structure.run.{key}' in [structure.run]; a time "
                             f"run needs duration and time_step [s]")
    duration = key_number("structure.run.duration", table["duration"], "positive")
    step = key_number("structure.run.time_step", table["time_step"], "positive")
    if step > duration:
        raise InputError(f"key 'structure.run.time_step': expected at most the duration "
                         f"({duration!r} s); got {step!r}")
    method = table.get("method", "bdf2")
    if method not in METHODS:
        _fail("structure.run.method", " or ".join(f"'{k}'" for k in METHODS), method)
    values = {}
    for key in ("initial_position", "initial_velocity"):
        if key in table:
            values[key] = key_vector(f"structure.run.{key}", table[key], n)
    if "force" in table:
        force = _table("structure.run.force", table["force"])
        _known(force, FORCE_KEYS, "structure.run.force", "structure.run.force.")
        for key in ("offset", "amplitude"):
            if key in force:
                values[key] = key_vector(f"structure.run.force.{key}", force[key], n)
        if "amplitude" in force and "frequency" not in force:
            raise InputError("missing key 'structure.run.force.frequency' in "
                             "[structure.run.force]; an amplitude needs its frequency [Hz]")
        if "frequency" in force:
            values["frequency"] = key_number("structure.run.force.frequency", force["frequency"],
                                          "nonnegative")
    run = StructureRun(duration=duration, time_step=step, method=method, **values)
    from polind.resources import check_memory

    samples = duration / step
    check_memory(samples * (8 + _BYTES_PER_COORDINATE * n + _BYTES_PER_CONTACT * m),
                 f"The structure's duration / time_step ({samples:.3g} samples)")
    return run


def structure_from_dict(document, base_dir="."):
    """A :class:`~polind.Structure` and its run from a structure-file document.

    Parameters
    ----------
    document : dict
        ``{"structure": {...}}`` as :func:`polind.io.read_document` reads a
        structure file (the bare ``[structure]`` table is accepted too).
    base_dir : str or os.PathLike, default "."
        The folder relative model files (and an inline model's files) are
        read from: the structure file's.

    Returns
    -------
    (Structure, run or None)
        The run (a :class:`~polind.structures.StructureRun`, a
        :class:`~polind.structures.FrequencyResponseRun` or a
        :class:`~polind.structures.BackboneRun`, by its
        ``kind``) is None without a ``[structure.run]`` table.

    Raises
    ------
    InputError
        Naming the dotted key (``structure.contacts[1].model``) and what is
        expected; not the file (:func:`polind.load_structure` puts its name first).

    Examples
    --------
    >>> structure, run = structure_from_dict({"structure": {
    ...     "mass": 1.0,
    ...     "contacts": [{"model": {"type": "coulomb", "coulomb_force": 1.0}, "dofs": [0]}],
    ...     "run": {"duration": 1.0, "time_step": 0.01}}})
    >>> structure
    Structure(1 coordinate, 1 contact: coulomb on (0, None))
    """
    from polind.structures.core import Structure, kernel_family

    if not isinstance(document, dict):
        _fail("structure", "a table ([structure])", document)
    if "structure" in document:
        for key in document:
            if key != "structure":
                raise InputError(f"unknown top-level key '{key}'; expected [structure]")
        table = document["structure"]
    else:
        table = document                 # the bare [structure] table
    table = _table("structure", table)
    _known(table, STRUCTURE_KEYS, "structure", "structure.")
    if "mass" not in table:
        raise InputError("missing key 'structure.mass' in [structure]; expected the mass "
                         "matrix [kg] (n x n, or a number for one coordinate)")
    mass = _matrix("structure.mass", table["mass"])
    n = mass.shape[0]
    matrices = {}
    try:
        structure = Structure(mass)
    except InputError as error:
        raise InputError(f"key 'structure.mass': {error}") from None
    for key in ("stiffness", "damping"):
        if key in table:
            matrices[key] = _matrix(f"structure.{key}", table[key], n)
            try:
                Structure(mass, **{key: matrices[key]})
            except InputError as error:
                raise InputError(f"key 'structure.{key}': {error}") from None
    if matrices:
        structure = Structure(mass, **matrices)
    contacts = table.get("contacts")
    if contacts is None:
        raise InputError("the [structure] table has no contacts; expected at least one "
                         "[[structure.contacts]] with model and dofs")
    if not isinstance(contacts, list) or not contacts:
        _fail("structure.contacts", "a list of contact tables ([[structure.contacts]])",
              contacts)
    family = None
    for c, contact in enumerate(contacts):
        key = f"structure.contacts[{c}]"
        contact = _table(key, contact)
        _known(contact, CONTACT_KEYS, key, f"{key}.")
        for name in CONTACT_KEYS:
            if name not in contact:
                raise InputError(f"missing key '{key}.{name}' in [{key}]; a contact needs "
                                 f"model (a file or a table) and dofs")
        dofs = _dofs(f"{key}.dofs", contact["dofs"], n)
        model = _model(f"{key}.model", contact["model"], os.fspath(base_dir))
        kernel = _contact_kernel(f"{key}.model", model)
        if family is None:
            family, first_type = kernel_family(kernel), model.type
        elif kernel_family(kernel) != family:
            raise InputError(f"key '{key}.model': a '{model.type}' contact cannot join the "
                             f"'{first_type}' one of structure.contacts[0]: the contacts of a "
                             f"structure must share one model family's kernels (today's "
                             f"limit of the structure driver)")
        try:
            structure.add_contact(model, dofs)
        except InputError as error:
            raise InputError(f"key '{key}': {error}") from None
    run = None
    if "run" in table:
        run = _run(_table("structure.run", table["run"]), n, len(contacts))
    return structure, run


def load_structure(path):
    """Read a structure file (TOML, or JSON by extension; :ref:`formats-structure`).

    Parameters
    ----------
    path : str or os.PathLike
        The file: ``[structure]`` with ``mass``, ``stiffness``, ``damping``,
        ``[[structure.contacts]]`` (``model``, ``dofs``) and optionally
        ``[structure.run]``.  Model files are relative to its folder.

    Returns
    -------
    (Structure, run or None)
        The structure, and its run (None without ``[structure.run]``): a
        :class:`~polind.structures.StructureRun`, a
        :class:`~polind.structures.FrequencyResponseRun` or a
        :class:`~polind.structures.BackboneRun`;
        ``run.solve(structure)`` runs it.

    Raises
    ------
    InputError
        One line that starts with the file's name and names the key.

    Examples
    --------
    >>> import pathlib, tempfile, polind
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "structure.toml"
    >>> _ = path.write_text('''
    ... [structure]
    ... mass = [[1.0, 0.0], [0.0, 0.5]]
    ... stiffness = [[100.0, 0.0], [0.0, 0.0]]
    ... [[structure.contacts]]
    ... dofs = [0, 1]
    ... [structure.contacts.model]
    ... type = "maxwell-slip"
    ... stiffness = [1e5, 5e4]
    ... breakaway_force = [0.5, 0.5]
    ... [structure.run]
    ... duration = 0.01
    ... time_step = 1e-4
    ... ''')
    >>> structure, run = polind.load_structure(path)
    >>> structure, run.times.size
    (Structure(2 coordinates, 1 contact: maxwell-slip on (0, 1)), 101)
    """
    from polind import io

    name = os.fspath(path)
    document = io.read_document(path)
    io.check_tables(name, document, required=("structure",), allowed=("structure",))
    try:
        return structure_from_dict(document, os.path.dirname(os.path.abspath(name)))
    except InputError as error:
        raise InputError(f"{name}: {error}") from None


def structure_files(path) -> list:
    """The structure file and every file it reads: contact model files and their files.

    No output of a command may replace any of them.  Read leniently: a file
    that cannot be read, or a contact that is not what it should be, names
    nothing more here (:func:`polind.load_structure` reports the problem).
    """
    from polind import io
    from polind.models import MODEL_TYPES, document_files, read_model_document

    files = [path]
    try:
        document = io.read_document(path)
    except InputError:
        return files
    base_dir = os.path.dirname(os.path.abspath(os.fspath(path)))
    table = document.get("structure")
    contacts = table.get("contacts") if isinstance(table, dict) else None
    for contact in contacts if isinstance(contacts, list) else ():
        model = contact.get("model") if isinstance(contact, dict) else None
        if isinstance(model, str) and model:
            model_path = model if os.path.isabs(model) else os.path.join(base_dir, model)
            files.append(model_path)
            try:
                files.extend(document_files(read_model_document(model_path)))
            except InputError:
                pass
        elif isinstance(model, dict) and isinstance(model.get("type"), str) \
                and model["type"] in MODEL_TYPES:
            files.extend(value if os.path.isabs(value) else os.path.join(base_dir, value)
                         for value in document_files({"model": model}))
    return files
