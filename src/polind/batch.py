"""Many bodies on one contact law, stepped in one call: :class:`BodyBatch`.

``n`` bodies, each a :class:`polind.Body` of its own (own mass, position,
velocity and model state), share one friction model's parameters and one
time step; ``batch.step(forces)`` advances all of them by the same compiled
step a ``Body`` runs (the runners' ``body_batch``,
:mod:`polind.kernels.template`), in one loop over the bodies with no Python
per body.  Row ``i`` equals a ``Body`` stepped with ``forces[i]``, bit for
bit.  For 64 joints of a robot or 1,000 rollouts of a model-predictive
controller.
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError, describe
from polind.models import State
from polind.stepper import Body, check_model

__all__ = ["BodyBatch"]


def _per_body(name, value, count, kind=None):
    """A float per body from a number or an array of ``count`` numbers (InputError else)."""
    try:
        values = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"The '{name}' of BodyBatch must be a number or {count} numbers. "
                         f"Got {describe(value)} instead.") from None
    if values.ndim == 0:
        values = np.full(count, float(values))
    if values.shape != (count,):
        raise InputError(f"The '{name}' of BodyBatch must be a number or {count} numbers (one "
                         f"per body). Got an array of shape {values.shape} instead.")
    bad = ~np.isfinite(values) if kind is None else ~(np.isfinite(values) & (values > 0.0))
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        what = "finite" if kind is None else "positive and finite"
        raise InputError(f"The '{name}' of BodyBatch must be {what}. Got {float(values[index])!r} "
                         f"for body {index} instead.")
    return values


class BodyBatch:
    """``count`` bodies with friction on one contact law, stepped together.

    The user guide, :ref:`guide-body-batch`.

    Parameters
    ----------
    model : FrictionModel
        The contact law of every body; never mutated.
    count : int
        n, the number of bodies (at least 1).
    mass : float or array_like, default 1
        m [kg] of every body, or one per body; positive.
    time_step : float, default 1e-3
        h [s], the one step of all bodies.
    position, velocity : float or array_like, optional
        Initial positions [m] and velocities [m/s], one for all or one per
        body (default: 0, or those of a Body's ``state``).
    state : State, optional
        The model's state every body starts from (default: at rest); as for
        :class:`polind.Body` (a Body's ``state`` continues that body, in
        every row).
    method : {"bdf2", "euler"}, default "bdf2"
        The implicit momentum scheme (:class:`polind.Body`).

    Attributes
    ----------
    time : float
        The current sample [s], the same for all bodies.
    position, velocity, friction : ndarray
        Per body, at the current sample (copies).

    Notes
    -----
    The bodies run at the model's own normal load.  ``body(i)`` gives body
    ``i`` as an independent :class:`polind.Body` (a copy).

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 1.0}})
    >>> batch = polind.BodyBatch(model, 3, time_step=1e-3)
    >>> x, v, F = batch.step(np.array([0.5, 2.0, -2.0]))
    >>> F.tolist()                      # the first holds, the others slide
    [0.5, 1.0, -1.0]
    """

    def __init__(self, model, count, mass=1.0, time_step=1e-3, position=None, velocity=None,
                 state=None, method="bdf2"):
        check_model(model, "BodyBatch")
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise InputError(f"The 'count' of BodyBatch must be a whole number of bodies, at "
                             f"least 1. Got {describe(count)} instead.")
        count = int(count)
        if state is not None and not isinstance(state, State):
            raise InputError(f"The 'state' of BodyBatch must be a polind State. "
                             f"Got {describe(state)} instead.")
        masses = _per_body("mass", mass, count, "positive")
        positions = [None] * count if position is None else _per_body("position", position, count)
        velocities = [None] * count if velocity is None else _per_body("velocity", velocity, count)
        # Body 0 checks the rest and gives the shared arrays; each row starts as a Body would.
        first = Body(model, float(masses[0]), time_step, position=positions[0],
                     velocity=velocities[0], state=state, method=method)
        self._first = first
        self._count = count
        kernel = first._kernel
        self._kernel = kernel
        self._mounted = kernel.mount is not None
        size = kernel.state.shape[0]
        self._states = np.empty((count, size))
        self._bodies = np.empty((count, 6))
        self._mounts = np.empty((count, first._arguments[3].shape[0]))
        for i in range(count):
            same = (positions[i] in (None, first.position)
                    and velocities[i] in (None, first.velocity))
            body = first if same else Body(model, float(masses[i]), time_step,
                                           position=positions[i], velocity=velocities[i],
                                           state=state, method=method)
            self._states[i] = body._kernel.state
            self._bodies[i] = body._body
            self._mounts[i] = body._arguments[3]
        self._masses = masses
        self._clock = first._clock.copy()
        self._out = np.empty((3, count))
        self._load = float(kernel.normal_load)
        if first._last_load != self._load:
            # Back to the model's own load, as each Body's next step() would.
            for i in range(count):
                kernel.force(kernel.scalars, kernel.table, self._states[i],
                             float(self._bodies[i, 1]), self._load)
        runners = kernel.runners
        self._function = runners.mounted_body_batch if self._mounted else runners.body_batch
        self._scratch = kernel.scratch
        self._head = (first._memoryless, first._rest_capacity, float(kernel.force_scale),
                      self._mounts, kernel.scalars, kernel.table, self._states, self._scratch,
                      first._method, self._masses, self._clock, self._bodies)
        from polind.kernels import compiled_entry
        self._advance = compiled_entry(self._function, *self._head, np.zeros(count),
                                       self._load, self._out)

    def __len__(self):
        return self._count

    @property
    def time(self) -> float:
        return float(self._clock[0] + self._clock[1] * self._clock[2])

    @property
    def position(self) -> np.ndarray:
        return self._bodies[:, 0].copy()

    @property
    def velocity(self) -> np.ndarray:
        return self._bodies[:, 1].copy()

    @property
    def friction(self) -> np.ndarray:
        return self._bodies[:, 5].copy()

    def body(self, index) -> Body:
        """Body ``index`` as an independent :class:`polind.Body` at the current sample."""
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) \
                or not -self._count <= index < self._count:
            raise InputError(f"The 'index' of BodyBatch.body must be a body's index, "
                             f"0 .. {self._count - 1}. Got {describe(index)} instead.")
        twin = self._first.copy()
        twin._mass = float(self._masses[index])
        twin._kernel.state[:] = self._states[index]
        twin._body[:] = self._bodies[index]
        twin._clock[:] = self._clock
        if self._mounted:
            twin._kernel.mount[:] = self._mounts[index]
        twin._bind()
        return twin

    def step(self, applied_forces):
        """Hold ``applied_forces[i]`` [N] on body ``i`` over one step; return ``(x, v, F)``.

        ``applied_forces`` is a float64 array of ``count`` finite forces (a
        list is converted); the result is three new arrays of ``count``
        entries, the bodies at the end of the step.
        """
        forces = applied_forces
        if type(forces) is not np.ndarray or forces.dtype != np.float64 or forces.ndim != 1 \
                or not forces.flags.c_contiguous:
            try:
                forces = np.ascontiguousarray(applied_forces, dtype=np.float64)
            except (TypeError, ValueError):
                raise InputError(f"The 'applied_forces' of BodyBatch.step must be {self._count} "
                                 f"numbers. Got {describe(applied_forces)} instead.") from None
        if forces.shape != (self._count,):
            raise InputError(f"The 'applied_forces' of BodyBatch.step must have one force per "
                             f"body, shape ({self._count},). Got shape {forces.shape} instead.")
        total = forces.sum()
        if not -math.inf < total < math.inf:
            bad = np.flatnonzero(~np.isfinite(forces))
            if bad.shape[0]:
                raise InputError(f"The 'applied_forces' of BodyBatch.step must be finite. Got "
                                 f"{float(forces[bad[0]])!r} for body {int(bad[0])} instead.")
        if not self._advance(*self._head, forces, self._load, self._out):
            step = float(self._clock[2])       # (a NumPy scalar's repr is not its number)
            raise InputError(f"The 'time_step' of BodyBatch ({step!r} s) is lost in its time "
                             f"{self.time!r} s; expected a state whose time starts "
                             f"nearer 0.")
        out = self._out.copy()
        return out[0], out[1], out[2]
