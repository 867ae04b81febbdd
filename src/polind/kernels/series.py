"""A mounted contact (:mod:`polind.kernels.mount`): the series spring solved per step.

Series compliance (the user guide, "Series compliance")
-------------------------------------------------------
The prescribed displacement ``x`` is that of the far end of a spring of
stiffness ``k_s``; the contact moves by ``u`` and at every sample::

    F = k_s (x - u) = F_contact(u)

Over a step ``x`` advances by ``dx`` and the contact by ``du = h w`` at the
constant contact velocity ``w``, with the model's own exact update at ``w``.
With ``F_prev`` the spring's force at the previous sample, the step solves::

    k_s h w + F_contact(w) = F_prev + k_s dx

which is the implicit equation of a body with ``inertia = k_s h`` and a
known right-hand side (:func:`polind.kernels.dynamics.solve_step`, the same
safeguarded secant/bisection search with the model's tangent).  Where the
contact force is non-decreasing in ``u`` (the Maxwell-slip family) the root
is unique and, ``F_contact`` being piecewise linear in ``w`` there, found
exactly; where it can fall (a Stribeck dip) the search starts from ``w =
0`` and brackets outwards, i.e. it takes a root near the previous ``u``.  A
memoryless contact holds (``w = 0``, ``F = F_prev + k_s dx``) while that
force is within its ``g(0)``.  The contact's rate terms (``sigma2 v``,
LuGre's ``sigma1 dz/dt``) are taken at the contact velocity ``w``.
``k_s = inf`` is the rigid mount: the model's own step, unchanged.

The force reported at a sample is the contact's, which equals the spring's
``k_s (x - u)`` to the solver's tolerance (``1e-13`` of the force scale).
The first sample of a run reports the spring's force of the state (0 for a
model at rest): the spring carries what the contact carries.

The loops themselves are each model's runners (:mod:`polind.kernels.template`):
its ``spring_trial`` (the contact's force and tangent at a trial velocity),
``mounted_step`` (the spring's solve, compiled on its own), ``mounted_path``
and the body of a mounted contact (``mounted_body_trial``), all kept in
numba's on-disk cache like the model's other runners.  They are written in
the template itself, not inlined from here: numba copies an inlined
function's whole IR once per block of it (its ``InlineInlinables`` pass), so
a solver inlined one level deeper cost each model's ``mounted_step`` 0.45 s
more to compile.  What more than one runner uses stays here.
"""

from __future__ import annotations

from polind.kernels import jit
from polind.kernels.mount import CONTACT_POSITION, CONTACT_VELOCITY, SPRING_FORCE


@jit(inline="always")
def mounted_commit(mounted_step, mount, scalars, table, state, scratch, step, displacement,
                   step_velocity, sample_velocity, normal_load):
    """``mounted_step`` on the real state, remembering the spring's force and the contact.

    ``mounted_step`` is a model's runner of that name
    (:mod:`polind.kernels.template`).
    """
    force, contact_displacement, contact_velocity = mounted_step(
        mount, scalars, table, state, scratch, step, displacement, step_velocity,
        sample_velocity, normal_load)
    mount[SPRING_FORCE] = force
    mount[CONTACT_POSITION] += contact_displacement
    mount[CONTACT_VELOCITY] = contact_velocity
    return force


def mounted_sample(runners, mount, scalars, table, state, scratch, path, step, displacement,
                   step_velocity, sample_velocity, previous_load, normal_load):
    """One sample of a mounted contact, called from Python: a one-step path of its runners.

    ``runners`` are the model's (:mod:`polind.kernels.template`); ``path`` is
    a (6, 2) float64 work array; ``previous_load`` the load of the sample
    before (NaN if unknown: the model is then brought to ``normal_load``
    first, as the runners' ``mounted_path`` does whenever the load changes).
    Returns the force [N]; ``state`` and ``mount`` are advanced.
    """
    path[0, 1], path[1, 1], path[2, 1], path[3, 1] = step, displacement, step_velocity, \
        sample_velocity
    path[4, 0], path[4, 1] = previous_load, normal_load
    runners.mounted_path(mount, scalars, table, state, scratch, path[0], path[1], path[2],
                         path[3], path[4], normal_load, 0, 2, path[5])
    return float(path[5, 1])
