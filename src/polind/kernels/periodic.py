"""A contact's response over one period of a given motion, as a numba template (:ref:`guide-structures`).

The hook harmonic balance needs: the relative displacement ``u`` of a
contact is prescribed at ``N`` samples of one period (linear between them,
the last step closing the loop back to the first sample), the contact is
stepped along it with its model's own exact update, as
:func:`polind.simulate` with ``x`` would step it, period after period
from its state, until the state at the end of a period equals the state at
its start (within a tolerance): the periodic steady state.  Along the last
period it returns, at each sample ``j``, the force ``F_j`` and the
derivative of the step's force in the sample's displacement with the
history held,

    dF_j / du_j = (dF/dw)_j / h_j,

from the model's tangent at the state the step leaves (``k h + c``, the
stiffness of what sticks and the rate terms; behind a series spring ``k_s``
in series with it) — the Jacobian entries of an alternating
frequency–time Newton step.  For the Maxwell-slip family, whose force is
piecewise linear in the step, that is the derivative exactly; for a rate
model (LuGre, Dahl, GMS elements in slip) it is the stuck tangent of the
state, an estimate of the derivative while sliding, which a Newton step
needs and the periodic solution does not depend on.

Nothing here knows which model it runs: the contact enters through its
runners' mounted commit and its tangent (:mod:`polind.kernels.template`: the
runner ``period``); a contact with nothing around it has the rigid mount.
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.mount import CONTACT_VELOCITY, SPRING_FORCE, STIFFNESS
from polind.kernels.mount import load_ratio


@jit
def periodic_change(state, start_state, mount, start_mount):
    """The largest change of the state (and the mount's spring) over a period, relative to its size."""
    change = 0.0
    size = 0.0
    for i in range(state.shape[0]):
        change = max(change, abs(state[i] - start_state[i]))
        size = max(size, abs(state[i]))
    for slot in (SPRING_FORCE, CONTACT_VELOCITY):
        change = max(change, abs(mount[slot] - start_mount[slot]))
        size = max(size, abs(mount[slot]))
    return change / size if size > 0.0 else change


@jit(inline="always")
def periodic_with(commit, tangent, arguments):
    """Step a contact along one period until it repeats; fill its forces and tangents.

    ``arguments`` is ``(memoryless, mount, scalars, table, state, scratch,
    start_state, start_mount, t, u, normal_load, cycles, tolerance,
    out_force, out_tangent)``: ``t`` and ``u`` hold the ``N + 1`` samples
    of one period (``u[N] == u[0]``); ``state`` and ``mount`` are advanced
    in place (the state at the end of the last period); ``out_force`` and
    ``out_tangent`` (``N + 1``) receive, at samples ``1 .. N``, the force
    [N] and ``dF_j / du_j`` [N/m] of the last period (sample 0 is left as
    it is).  Returns the number of periods stepped, negative if the last
    still changed the state by more than ``tolerance`` (relative).
    """
    (memoryless, mount, scalars, table, state, scratch, start_state, start_mount, t, u,
     normal_load, cycles, tolerance, out_force, out_tangent) = arguments
    samples = t.shape[0]
    spring = mount[STIFFNESS]
    for cycle in range(cycles):
        for i in range(state.shape[0]):
            start_state[i] = state[i]
        for i in range(mount.shape[0]):
            start_mount[i] = mount[i]
        for j in range(1, samples):
            step = t[j] - t[j - 1]
            displacement = u[j] - u[j - 1]
            velocity = displacement / step
            out_force[j] = commit(mount, scalars, table, state, scratch, step, displacement,
                                  velocity, velocity, normal_load)
            slope = load_ratio(mount, normal_load) * tangent(scalars, table, state, step)
            if spring < math.inf:
                total = spring * step + slope
                slope = spring * step * slope / total if total > 0.0 else 0.0
            out_tangent[j] = slope / step
        # (The mount's contact position is where the contact went, not a state of it: the
        # spring's force and the contact's velocity are compared instead.)
        if periodic_change(state, start_state, mount, start_mount) <= tolerance:
            return cycle + 1
    return -cycles
