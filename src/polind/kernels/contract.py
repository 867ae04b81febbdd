"""The stepping contract every friction model fulfils, as numba templates.

A model supplies three numba functions over three flat arrays (its
``scalars``, its 2-D ``table`` of per-element parameters, and its ``state``)::

    step(scalars, table, state, step, displacement, step_velocity,
         sample_velocity, normal_load) -> F
    force(scalars, table, state, sample_velocity, normal_load) -> F
    tangent(scalars, table, state, step) -> dF/dw

``step`` advances ``state`` in place over one step of length ``step`` [s]
at the constant velocity ``step_velocity`` [m/s] (``displacement`` [m] is
its increment) and returns the friction force [N] at the sample that ends
the step; rate terms (``sigma2 v``, LuGre's ``sigma1 dz/dt``) are taken at
``sample_velocity``, the velocity reported at that sample.  ``normal_load``
[N] is the normal load at that sample (models without load dependence ignore
it).  ``force`` is the force at the current state without moving (the first
sample of a run).  ``tangent`` estimates ``dF/dw`` after a step at ``w`` (a
first Newton step of the one-degree-of-freedom solver; any positive estimate
is safe, since the solver brackets and falls back to bisection).

Everything else — prescribed paths (:func:`run_steps`), the implicit body of
:mod:`polind.kernels.dynamics`, :class:`polind.Stepper`, a user's own
``@njit`` loop — is written once on top of these three functions.  The
templates take the model's functions as arguments; a model that wants its
step inlined into the loop (worth it when a step costs nanoseconds) defines a
one-line specialised runner that calls the template with its own functions
as globals, because numba inlines ``inline="always"`` functions it sees as
globals but not functions passed as arguments.
"""

from __future__ import annotations

from polind.kernels import jit


@jit(inline="always")
def sample_load(loads, constant_load, k):
    """The normal load at sample ``k``: ``loads[k]``, or the constant when ``loads`` is empty."""
    return loads[k] if loads.shape[0] > 0 else constant_load


@jit(inline="always")
def run_steps(step, force, scalars, table, state, step_length, displacement, step_velocity,
              sample_velocity, loads, constant_load, lo, hi, first, out_force):
    """Run a model over the samples ``lo .. hi - 1`` of a prescribed path.

    Arrays are indexed by the sample a step ends at (entry ``k`` of
    ``step_length``, ``displacement`` and ``step_velocity`` is the step from
    sample ``k - 1`` to ``k``).  With ``first`` the force at sample ``lo`` is
    the model's force at its state; otherwise sample ``lo`` is taken as
    already computed (a chunk that continues the previous one).  ``loads``
    holds the normal load at every sample, or is empty for ``constant_load``.
    """
    if first:
        out_force[lo] = force(scalars, table, state, sample_velocity[lo],
                              sample_load(loads, constant_load, lo))
    for k in range(lo + 1, hi):
        out_force[k] = step(scalars, table, state, step_length[k], displacement[k],
                            step_velocity[k], sample_velocity[k],
                            sample_load(loads, constant_load, k))


@jit(cache=False)
def run_steps_any(step, force, scalars, table, state, step_length, displacement, step_velocity,
                  sample_velocity, loads, constant_load, lo, hi, first, out_force):
    """:func:`run_steps` for any model's functions (passed as arguments, not inlined)."""
    run_steps(step, force, scalars, table, state, step_length, displacement, step_velocity,
              sample_velocity, loads, constant_load, lo, hi, first, out_force)
