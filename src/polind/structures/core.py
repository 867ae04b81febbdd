"""Structures of many coordinates and contacts (:ref:`guide-structures`): :class:`Structure`.

A structure is ``n`` coordinates with mass, damping and stiffness matrices
and any number of contacts, each a polind model acting on one coordinate
against the ground or between two coordinates::

    M q'' + C q' + K q + sum_c b_c^T F_c(b_c q) = f(t)

This module validates the matrices and contacts, packs the contacts' flat
arrays for the structure driver (:mod:`polind.kernels.structure`, which
holds the integrator and explains the scheme) and wraps the result.  A
contact's force is its model's own along the structure's path: its state is
advanced exactly as ``polind.simulate(model, t, x=u_c)`` advances it along
its relative displacement ``u_c``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from polind.dynamics import initial_friction
from polind.errors import InputError, describe
from polind.kernels import dynamics as dynamics_kernel
from polind.kernels.mount import N_MOUNT
from polind.models import FrictionModel, State
from polind.models.kernel import RIGID
from polind.simulation import sample_times, summary_repr

__all__ = ["Structure", "StructureResult", "simulate_structure"]

METHODS = {"bdf2": dynamics_kernel.BDF2, "euler": dynamics_kernel.EULER}

# Steps per kernel call: long runs report progress between chunks.
_CHUNK = 1 << 15


def _matrix(name, value, size=None):
    """A finite square float64 matrix (a scalar is 1 x 1); InputError naming ``name``."""
    if isinstance(value, bool):
        raise InputError(f"The '{name}' matrix of Structure must be numbers. Got "
                         f"{describe(value)} instead.")
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"The '{name}' matrix of Structure must be numbers. Got "
                         f"{describe(value)} instead.") from None
    if array.ndim == 0:
        array = array.reshape(1, 1)
    if array.ndim != 2 or array.shape[0] != array.shape[1]:
        raise InputError(f"The '{name}' matrix of Structure must be square (n x n). Got "
                         f"shape {array.shape} instead.")
    if size is not None and array.shape[0] != size:
        raise InputError(f"The '{name}' matrix of Structure must be {size} x {size}, the "
                         f"shape of 'mass'. Got {array.shape[0]} x {array.shape[1]} instead.")
    _refuse_non_finite(array, f"The '{name}' matrix of Structure",
                       lambda i, j: f"at [{i}, {j}]")
    return array


def _refuse_non_finite(array, owner, where):
    """InputError for the first non-finite entry of a 2-D ``array``: ``owner``, the value, ``where(i, j)``."""
    bad = np.argwhere(~np.isfinite(array))
    if bad.size:
        i, j = bad[0]
        raise InputError(f"{owner} must be finite. Got {float(array[i, j])!r} {where(i, j)} "
                         f"instead.")


def _symmetric(name, array):
    scale = np.abs(array).max(initial=0.0)
    asymmetry = np.abs(array - array.T).max(initial=0.0)
    if asymmetry > 1e-12 * scale:
        i, j = np.unravel_index(np.argmax(np.abs(array - array.T)), array.shape)
        raise InputError(f"The '{name}' matrix of Structure must be symmetric. Got "
                         f"{float(array[i, j])!r} at [{i}, {j}] and {float(array[j, i])!r} at [{j}, {i}] "
                         f"instead.")


@dataclass(frozen=True)
class Contact:
    """One contact of a :class:`Structure`: its model and the coordinates it joins.

    ``u = q[first] - q[second]``, or ``u = q[first]`` for a contact to the
    ground (``second`` None).
    """

    model: FrictionModel
    first: int
    second: int | None


class Structure:
    """Coordinates with mass, damping and stiffness, and friction contacts between them.

    Parameters
    ----------
    mass : array_like
        M [kg]: ``n x n``, symmetric positive definite (a scalar for ``n = 1``).
    stiffness : array_like, optional
        K [N/m]: ``n x n`` (default zeros).
    damping : array_like, optional
        C [N s/m]: ``n x n`` (default zeros).

    Examples
    --------
    Two masses joined by a Maxwell-slip joint, the first held by a spring:

    >>> import polind
    >>> joint = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e5, 5e4], "breakaway_force": [0.5, 0.5]}})
    >>> s = polind.Structure(mass=[[1.0, 0.0], [0.0, 0.5]],
    ...                      stiffness=[[100.0, 0.0], [0.0, 0.0]])
    >>> s.add_contact(joint, dofs=(0, 1))
    >>> s
    Structure(2 coordinates, 1 contact: maxwell-slip on (0, 1))
    """

    def __init__(self, mass, stiffness=None, damping=None):
        mass = _matrix("mass", mass)
        n = mass.shape[0]
        _symmetric("mass", mass)
        try:
            np.linalg.cholesky(mass)
        except np.linalg.LinAlgError:
            smallest = float(np.linalg.eigvalsh(mass).min())
            raise InputError(f"The 'mass' matrix of Structure must be positive definite. Got "
                             f"a smallest eigenvalue of {smallest!r} instead.") from None
        self.mass = mass
        self.stiffness = np.zeros((n, n)) if stiffness is None else _matrix("stiffness",
                                                                            stiffness, n)
        self.damping = np.zeros((n, n)) if damping is None else _matrix("damping", damping, n)
        self.contacts: list[Contact] = []

    @property
    def size(self) -> int:
        """The number of coordinates ``n``."""
        return self.mass.shape[0]

    def add_contact(self, model, dofs):
        """Add a contact: ``model`` on ``u = q[dofs[0]] - q[dofs[1]]``.

        Parameters
        ----------
        model : FrictionModel
            Any polind model (with its compliance and its reference load);
            validated here.  Every contact of one structure must share one
            model family's compiled kernels (today's limit of the driver).
        dofs : tuple
            ``(i, j)`` for a contact between coordinates ``i`` and ``j``;
            ``(i,)`` or ``(i, None)`` for a contact to the ground.
        """
        if not isinstance(model, FrictionModel):
            raise InputError(f"The 'model' of a Structure contact must be a polind friction "
                             f"model (load_model or model_from_dict). Got {describe(model)} "
                             f"instead.")
        model.check_numbers()
        first, second = self._dofs(dofs)
        self.contacts.append(Contact(model, first, second))

    def _dofs(self, dofs):
        if isinstance(dofs, (int, np.integer)) and not isinstance(dofs, bool):
            dofs = (dofs,)
        if not isinstance(dofs, (tuple, list)) or not 1 <= len(dofs) <= 2:
            raise InputError(f"The 'dofs' of a Structure contact must be (i,), (i, None) or "
                             f"(i, j). Got {describe(dofs)} instead.")
        values = []
        for index, dof in enumerate(dofs):
            if dof is None and index == 1:
                values.append(None)
                continue
            if isinstance(dof, bool) or not isinstance(dof, (int, np.integer)):
                raise InputError(f"The 'dofs' of a Structure contact must be coordinate "
                                 f"indices. Got {describe(dof)} at index {index} instead.")
            if not 0 <= dof < self.size:
                raise InputError(f"The 'dofs' of a Structure contact must be coordinates 0 to "
                                 f"{self.size - 1}. Got {int(dof)} at index {index} instead.")
            values.append(int(dof))
        if len(values) == 1:
            values.append(None)
        if values[0] == values[1]:
            raise InputError(f"The 'dofs' of a Structure contact must be two different "
                             f"coordinates. Got ({values[0]}, {values[1]}) instead.")
        return values[0], values[1]

    def __repr__(self):
        parts = [f"{c.model.type} on ({c.first}, {c.second})" for c in self.contacts]
        count = len(self.contacts)
        text = f"{self.size} coordinate{'s' if self.size != 1 else ''}, {count} contact" \
               f"{'s' if count != 1 else ''}"
        return f"Structure({text}{': ' + ', '.join(parts) if parts else ''})"


@dataclass
class StructureResult:
    """The result of :func:`simulate_structure`.

    Attributes
    ----------
    t : ndarray
        Sample times [s], ``(len(t),)``.
    q, dq : ndarray
        Coordinates [m] and their velocities [m/s], ``(len(t), n)``.
    contact_forces : ndarray
        Each contact's friction force [N] (on its first coordinate it acts as
        ``-F``, on its second as ``+F``), ``(len(t), n_contacts)``.
    applied : ndarray
        The applied forces [N], ``(len(t), n)``.
    final_states : list of State
        Each contact model's state at the last sample.
    unconverged_steps : int
        Steps whose sweeps over several contacts did not reach the solver's
        tolerance (0 for one contact).
    """

    t: np.ndarray
    q: np.ndarray
    dq: np.ndarray
    contact_forces: np.ndarray
    applied: np.ndarray
    final_states: list = field(default_factory=list)
    unconverged_steps: int = 0

    def __repr__(self):
        return summary_repr(self, {"q": "m", "dq": "m/s", "contact_forces": "N"})


def _applied(force, t, n):
    """The applied forces ``(len(t), n)`` from an array, a callable or None."""
    if force is None:
        return np.zeros((t.shape[0], n))
    if callable(force):
        rows = []
        for time in t.tolist():         # floats (a NumPy scalar's repr is not its number)
            try:
                value = np.asarray(force(time), dtype=np.float64)
            except (TypeError, ValueError) as error:
                raise InputError(f"The 'force' callable of simulate_structure must return "
                                 f"{n} numbers. At t = {time!r} it raised: {error}") from None
            if value.shape not in ((n,),) and not (n == 1 and value.shape == ()):
                raise InputError(f"The 'force' callable of simulate_structure must return "
                                 f"{n} numbers. Got shape {value.shape} at t = {time!r} "
                                 f"instead.")
            rows.append(value.reshape(n))
        array = np.array(rows)
    else:
        try:
            array = np.array(force, dtype=np.float64)
        except (TypeError, ValueError):
            raise InputError(f"The 'force' of simulate_structure must be numbers. Got "
                             f"{describe(force)} instead.") from None
        if n == 1 and array.ndim == 1:
            array = array.reshape(-1, 1)
        if array.shape != (t.shape[0], n):
            raise InputError(f"The 'force' of simulate_structure must have shape "
                             f"(len(t), n) = ({t.shape[0]}, {n}). Got {array.shape} instead.")
    _refuse_non_finite(array, "The 'force' of simulate_structure",
                       lambda k, i: f"at sample {k}, coordinate {i}")
    return np.ascontiguousarray(array)


def _vector(name, value, n):
    if value is None:
        return np.zeros(n)
    try:
        array = np.array(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"The '{name}' of simulate_structure must be {n} numbers. Got "
                         f"{describe(value)} instead.") from None
    if array.shape != (n,):
        raise InputError(f"The '{name}' of simulate_structure must be {n} numbers. Got "
                         f"{array.shape[0]} instead.")
    if not np.isfinite(array).all():
        raise InputError(f"The '{name}' of simulate_structure must be finite. Got "
                         f"{array.tolist()!r} instead.")
    return array


def simulate_structure(structure, t, *, force=None, initial_position=None,
                       initial_velocity=None, method="bdf2", progress=None) -> StructureResult:
    """Simulate a structure with friction contacts (:ref:`guide-structures`).

    Each step is implicit in the contacts: the coordinates are condensed
    onto the contacts' relative velocities, and each contact's force at the
    end of the step is its model's own exact update at its step velocity,
    solved with the momentum equation (:mod:`polind.kernels.structure`).  A
    stuck joint holds exactly however stiff it is, and the step length is
    not limited by ``sqrt(m / k)`` of the joints; the scheme is BDF2, second
    order.

    Parameters
    ----------
    structure : Structure
        Matrices and contacts (at least one contact).
    t : array_like
        Sample times [s], strictly increasing.
    force : array_like or callable, optional
        Applied forces [N]: ``(len(t), n)``, or ``f(t) -> (n,)``; the step
        ending at sample ``k`` takes ``force[k]`` (default: none).
    initial_position, initial_velocity : array_like, optional
        ``q`` [m] and ``q'`` [m/s] at ``t[0]`` (default zeros).  Every
        contact starts from its model's virgin state.
    method : {"bdf2", "euler"}, default "bdf2"
        The implicit scheme (see :func:`polind.simulate_system`).
    progress : callable, optional
        Called as ``progress(done, total)`` (steps) during long runs.

    Returns
    -------
    StructureResult

    Examples
    --------
    A mass on a Coulomb contact, pushed below its friction, does not move:

    >>> import numpy as np, polind
    >>> s = polind.Structure(mass=2.0)
    >>> s.add_contact(polind.model_from_dict({"model": {"type": "coulomb",
    ...                                                 "coulomb_force": 1.0}}), dofs=(0,))
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> res = polind.simulate_structure(s, t, force=np.full((101, 1), 0.5))
    >>> float(np.abs(res.q).max()), float(res.contact_forces[-1, 0])
    (0.0, 0.5)
    """
    if not isinstance(structure, Structure):
        raise InputError(f"The 'structure' of simulate_structure must be a polind.Structure. "
                         f"Got {describe(structure)} instead.")
    if method not in METHODS:
        raise InputError(f"The 'method' of simulate_structure must be one of 'bdf2', 'euler'. "
                         f"Got {describe(method)} instead.")
    if not structure.contacts:
        raise InputError("The structure of simulate_structure has no contacts: add one with "
                         "Structure.add_contact(model, dofs).")
    t = sample_times(t)
    n = structure.size
    applied = _applied(force, t, n)
    q0 = _vector("initial_position", initial_position, n)
    v0 = _vector("initial_velocity", initial_velocity, n)
    packed = _pack(structure.contacts)
    m = len(structure.contacts)
    samples = t.shape[0]
    q = np.empty((samples, n))
    dq = np.empty((samples, n))
    forces = np.empty((samples, m))
    q[0], dq[0] = q0, v0
    for c, kernel in enumerate(packed.kernels):
        velocity = float(_relative(structure.contacts[c], v0))
        # a set-valued contact at rest holds nothing yet, as a Body's first friction
        forces[0, c] = initial_friction(kernel, velocity, 0.0)
    carry = np.concatenate([v0, [float(_relative(contact, v0)) for contact in
                                 structure.contacts], [0.0]])
    unconverged = np.zeros(1, dtype=np.int64)
    for start in range(1, samples, _CHUNK):
        stop = min(start + _CHUNK, samples)
        packed.run((
            packed.memoryless, packed.rest_capacity, packed.force_scale, packed.mounts,
            packed.scalars, packed.scalar_bounds, packed.tables, packed.table_bounds,
            packed.table_rows, packed.states, packed.state_bounds, packed.loads,
            packed.contacts, structure.mass, structure.damping, structure.stiffness, t,
            applied, METHODS[method], q, dq, forces, carry, unconverged, start, stop))
        if progress is not None:
            progress(stop - 1, samples - 1)
    final_states = []
    for c, (contact, kernel) in enumerate(zip(structure.contacts, packed.kernels)):
        state = contact.model.initial_state()
        lo, hi = packed.state_bounds[c], packed.state_bounds[c + 1]
        contact.model.unflatten_state(packed.states[lo:hi], state)
        state.time = float(t[-1])
        state.position = float(_relative(contact, q[-1]))
        state.velocity = float(_relative(contact, dq[-1]))
        state.force = float(forces[-1, c])
        final_states.append(state)
    return StructureResult(t=t, q=q, dq=dq, contact_forces=forces, applied=applied,
                           final_states=final_states, unconverged_steps=int(unconverged[0]))


def _relative(contact, values):
    if contact.second is None:
        return values[contact.first]
    return values[contact.first] - values[contact.second]


@dataclass
class _Packed:
    kernels: list
    run: object
    memoryless: np.ndarray
    rest_capacity: np.ndarray
    force_scale: np.ndarray
    mounts: np.ndarray
    scalars: np.ndarray
    scalar_bounds: np.ndarray
    tables: np.ndarray
    table_bounds: np.ndarray
    table_rows: int
    states: np.ndarray
    state_bounds: np.ndarray
    loads: np.ndarray
    contacts: np.ndarray


def kernel_family(kernel):
    """What contacts of one structure must share: their runners and the rows of their table."""
    return kernel.runners, kernel.table.shape[0]


def _bounds(arrays):
    return np.concatenate([[0], np.cumsum([a.size for a in arrays])]).astype(np.int64)


def _pack(contacts) -> _Packed:
    """The contacts' kernels as the flat arrays of :func:`polind.kernels.structure.integrate_structure_with`."""
    kernels = [contact.model.step_kernel(fixed_load=True) for contact in contacts]
    runners, rows = kernel_family(kernels[0])
    for contact, kernel in zip(contacts, kernels):
        if kernel_family(kernel) != (runners, rows):
            raise InputError(f"The contacts of a Structure must share one model family's "
                             f"kernels (today's limit of the structure driver). Got "
                             f"'{contacts[0].model.type}' and '{contact.model.type}' "
                             f"instead.")
    mounts = np.empty((len(kernels), N_MOUNT))
    for c, kernel in enumerate(kernels):
        mounts[c] = RIGID if kernel.mount is None else kernel.mount
    rows_of = np.array([[contact.first, -1 if contact.second is None else contact.second, 1]
                        for contact in contacts], dtype=np.int64)
    return _Packed(
        kernels=kernels,
        run=runners.mounted_structure,
        memoryless=np.array([0.0 if k.rest_capacity is None else 1.0 for k in kernels]),
        rest_capacity=np.array([0.0 if k.rest_capacity is None else float(k.rest_capacity)
                                for k in kernels]),
        force_scale=np.array([float(k.force_scale) for k in kernels]),
        mounts=mounts,
        scalars=np.concatenate([k.scalars.reshape(-1) for k in kernels]),
        scalar_bounds=_bounds([k.scalars for k in kernels]),
        tables=np.concatenate([k.table.reshape(-1) for k in kernels]),
        table_bounds=_bounds([k.table for k in kernels]),
        table_rows=int(rows),
        states=np.concatenate([k.state.reshape(-1) for k in kernels]),
        state_bounds=_bounds([k.state for k in kernels]),
        loads=np.array([float(k.normal_load) for k in kernels]),
        contacts=rows_of)
