"""A contact over one period of a given motion: :func:`contact_period` (:ref:`guide-structures`).

The periodic evaluation of the stepping core (:mod:`polind.kernels.periodic`):
the force a contact gives along a prescribed periodic relative displacement,
in its periodic steady state, and the derivative of each sample's force in
that sample's displacement.  Harmonic balance with alternating
frequency–time takes its contact forces and its Newton Jacobian from here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError, describe
from polind.models import FrictionModel
from polind.models.kernel import RIGID
from polind.validation import check_number, check_samples

__all__ = ["ContactPeriod", "contact_period"]


@dataclass
class ContactPeriod:
    """The periodic steady state of a contact along one period.

    Attributes
    ----------
    t : ndarray
        The ``N`` sample times of the period [s], from 0.
    u : ndarray
        The relative displacement at those times [m].
    force : ndarray
        The contact force at each sample [N] in the steady state: ``force[j]``
        ends the step from sample ``j - 1`` (``force[0]`` the step that closes
        the period, from sample ``N - 1`` back to 0).
    tangent : ndarray
        ``dF_j / du_j`` [N/m]: the derivative of ``force[j]`` in ``u[j]`` with
        the history held (the model's tangent of the step, divided by its
        length; a series spring in series with it).  Exact for the
        Maxwell-slip family; for a rate model (LuGre, Dahl, GMS in slip) the
        stuck tangent of its state, an estimate while it slides
        (:mod:`polind.kernels.periodic`).
    cycles : int
        The periods stepped until the state repeated.
    """

    t: np.ndarray
    u: np.ndarray
    force: np.ndarray
    tangent: np.ndarray
    cycles: int


def contact_period(model, u, period, *, cycles=100, tolerance=1e-12, state=None):
    """A contact's force and tangent over one period of ``u``, in its periodic steady state.

    The contact starts from ``state`` (default: its virgin state) at ``u[0]``
    and is stepped along the samples of ``u``, linear between them and back
    to ``u[0]`` at the end of the period, with its model's exact update (as
    ``polind.simulate(model, t, x=u)`` steps it), period after period,
    until the state at the end of a period differs from that at its start
    by at most ``tolerance`` (relative).

    Parameters
    ----------
    model : FrictionModel
        Any polind model (with its compliance and reference load); at its
        own constant normal load.
    u : array_like
        ``N >= 2`` samples of the relative displacement [m] over one period,
        at the times ``j period / N``.
    period : float
        The period [s], positive.
    cycles : int, default 100
        The most periods stepped; an InputError names it if the state still
        changes then.
    tolerance : float, default 1e-12
        The relative change of the state over a period taken as periodic.
    state : State, optional
        The contact's state at ``u[0]`` to start from (for instance the last
        evaluation's ``final_state`` along a continuation).

    Returns
    -------
    ContactPeriod

    Examples
    --------
    One Maxwell-slip element along a sine of twice its slip distance: the
    force saturates at the element's break-away force.

    >>> import numpy as np, polind
    >>> from polind.structures import contact_period
    >>> element = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e5], "breakaway_force": [1.0]}})
    >>> u = 2e-5 * np.sin(2 * np.pi * np.arange(64) / 64)
    >>> res = contact_period(element, u, period=0.1)
    >>> float(res.force.max()), float(res.force.min()), res.cycles
    (1.0, -1.0, 2)
    """
    if not isinstance(model, FrictionModel):
        raise InputError(f"The 'model' of contact_period must be a polind friction model. Got "
                         f"{describe(model)} instead.")
    period = check_number("contact_period", "period", period, "positive")
    cycles = check_number("contact_period", "cycles", cycles, "positive", integer=True)
    tolerance = check_number("contact_period", "tolerance", tolerance, "nonnegative")
    samples = check_samples("contact_period", "u", u, at_least=2)
    count = samples.shape[0]
    kernel = model.step_kernel(state, fixed_load=True)
    mount = RIGID.copy() if kernel.mount is None else kernel.mount.copy()
    t = np.arange(count + 1) * (period / count)
    path = np.append(samples, samples[0])
    force = np.zeros(count + 1)
    tangent = np.zeros(count + 1)
    start_state = np.empty_like(kernel.state)
    start_mount = np.empty_like(mount)
    used = kernel.runners.period((
        kernel.rest_capacity is not None, mount, kernel.scalars, kernel.table, kernel.state,
        kernel.scratch, start_state, start_mount, t, path, kernel.normal_load, cycles,
        tolerance, force, tangent))
    if used < 0:
        raise InputError(f"The contact did not settle on a periodic state within the "
                         f"'cycles' of contact_period ({cycles}): give more cycles or a larger "
                         f"'tolerance' ({tolerance!r}).")
    # Sample N closes the period: it is sample 0 of the steady state.
    force[0], tangent[0] = force[count], tangent[count]
    return ContactPeriod(t=t[:count], u=samples, force=force[:count], tangent=tangent[:count],
                         cycles=int(used))
