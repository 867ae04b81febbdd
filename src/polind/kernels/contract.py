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
sample of a run).  ``tangent`` gives ``dF/dw`` of a step of length ``step``
from ``state`` at a small ``w``, as ``k step + c``: ``k`` the summed stiffness
of what sticks (0 for a memoryless model), ``c`` the rate terms.  The
one-degree-of-freedom solver takes its first Newton step with it (any
positive estimate is safe there: it brackets and falls back to bisection);
:func:`polind.control.linearize` reads the stuck body's stiffness and
damping from it.

The implicit solvers (the body's, the series spring's) evaluate the force
of a step at trial velocities without keeping the state it leaves: by
default they copy the state into scratch, step the copy and take the
tangent there.  One of polind's element models also has a *read-only
trial* (:func:`no_trial` documents it), which computes that force and
tangent in one pass over its elements without writing the state.

Everything else — prescribed paths (:func:`run_steps`), the implicit body of
:mod:`polind.kernels.dynamics`, the series spring of
:mod:`polind.kernels.series`, :class:`polind.Stepper`, a user's own
``@njit`` loop — is written once on top of these three functions.  The
templates here and there take the model's functions as arguments and are
inlined; the runners that call them with one model's functions are written
once too, in :mod:`polind.kernels.template`, from which every model's
runner module is generated (:mod:`polind.kernels.generate`).
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.interpreted import call_once

# Codes of :func:`check_times` and :func:`cut_path` (with the index of the first bad sample).
#: Code: every sample is valid.
VALID = 0
#: Code: a sample that is not finite.
NOT_FINITE = 1
#: Code: ``t[k] <= t[k - 1]``.
NOT_INCREASING = 2
#: Code: finite samples, but non-finite step velocities or positions.
OVERFLOW = 3
#: Code of :func:`run_motion`: a sample time that is not finite or not after its
#: predecessor (the caller names which, as :func:`check_times` would).
BAD_TIME = 4


@jit(inline="always")
def sample_load(loads, constant_load, k):
    """The normal load at sample ``k``: ``loads[k]``, or the constant when ``loads`` is empty."""
    return loads[k] if loads.shape[0] > 0 else constant_load


@jit(inline="always")
def run_steps(step, scalars, table, state, step_length, displacement, step_velocity,
              sample_velocity, loads, constant_load, lo, hi, out_force):
    """Run a model over the samples ``lo + 1 .. hi - 1`` of a prescribed path.

    Arrays are indexed by the sample a step ends at (entry ``k`` of
    ``step_length``, ``displacement`` and ``step_velocity`` is the step from
    sample ``k - 1`` to ``k``).  Sample ``lo`` is taken as done: the first
    sample of a run is Python's (:meth:`polind.models.kernel.StepKernel.run`,
    the model's ``force`` at its state), else the last of the previous
    chunk.  ``loads`` holds the normal load at every sample, or is empty for
    ``constant_load``.
    """
    for k in range(lo + 1, hi):
        out_force[k] = step(scalars, table, state, step_length[k], displacement[k],
                            step_velocity[k], sample_velocity[k],
                            sample_load(loads, constant_load, k))


@jit(fastmath=False)
def motion_step(by_velocity, t0, t1, m0, m1, x0):
    """``(h, dx, w, x1, code)`` of the step from sample 0 to 1 of a prescribed motion (:func:`cut_path`).

    ``m`` are positions (``by_velocity`` false: ``w = (m1 - m0) / h``) or
    velocities (``w = (m0 + m1) / 2``, ``dx = w h``, ``x1 = x0 + dx``).
    ``code`` is :data:`NOT_FINITE` for a non-finite ``m1``, :data:`OVERFLOW`
    for a non-finite step velocity (positions) or ``x1`` (velocities), else
    :data:`VALID`.  Compiled without fast-math, on its own, so that the
    arithmetic is :func:`cut_path`'s (and :class:`polind.Stepper`'s) bit for
    bit in every loop that calls it, and so that the finiteness tests stand:
    with reassociation allowed, LLVM proves ``isfinite`` of a computed value
    true.
    """
    h = t1 - t0
    if not math.isfinite(m1):
        return h, 0.0, 0.0, x0, NOT_FINITE
    if by_velocity:
        w = 0.5 * (m0 + m1)
        dx = w * h
        x1 = x0 + dx
        return h, dx, w, x1, VALID if math.isfinite(x1) else OVERFLOW
    dx = m1 - m0
    w = dx / h
    return h, dx, w, m1, VALID if math.isfinite(w) else OVERFLOW


def first_motion_sample(force, scalars, table, state, source_t, source_motion, t, motion,
                        by_velocity, start_position, start_velocity, continuing, position,
                        velocity, loads, constant_load, lo, hi, out_force):
    """Copy and check sample ``lo``, the first of a motion, and its force: ``(code, index)``.

    Plain Python, called once per run before :func:`run_motion` (or a
    model's blocks) takes the samples after it: the force at the start is
    the model's ``force`` at its state, at the first sample's velocity —
    the given velocity, ``start_velocity`` when the motion ``continuing`` a
    run starts at sample 0, else the first step's (:func:`motion_step`, the
    same arithmetic as every later step), or ``start_velocity`` for a motion
    of one sample.  Fills ``t``, ``motion`` and ``velocity`` (positions
    given) or ``position`` (``start_position``, velocities given) at ``lo``
    and ``out_force[lo]``; returns the codes of :func:`run_motion` for a bad
    sample ``lo`` or ``lo + 1``.  Kept out of the compiled loop so that the
    loop a run needs compiles without it; the force is
    :func:`polind.kernels.interpreted.call_once`'s (by Python where the
    model's ``force`` is compiled without fastmath: the same bits, nothing
    compiled).
    """
    t[lo] = source_t[lo]
    motion[lo] = source_motion[lo]
    if not math.isfinite(t[lo]):
        return BAD_TIME, lo
    if not math.isfinite(motion[lo]):
        return NOT_FINITE, lo
    if by_velocity:
        if lo == 0:
            position[0] = start_position
        sample_velocity = motion[lo]
    else:
        if lo == 0 and continuing:
            sample_velocity = start_velocity
        elif lo + 1 < hi:
            t1 = source_t[lo + 1]
            if not (t1 > t[lo] and t1 < math.inf):
                return BAD_TIME, lo + 1
            # The compiled motion_step, for its arithmetic (and by_velocity, as run_motion
            # passes it, for one compiled signature).
            h, dx, sample_velocity, x1, code = motion_step(by_velocity, t[lo], t1, motion[lo],
                                                           source_motion[lo + 1], 0.0)
            if code != VALID:
                return code, lo + 1
        else:
            sample_velocity = start_velocity
        velocity[lo] = sample_velocity
    out_force[lo] = call_once(force, scalars, table, state, sample_velocity,
                              sample_load.py_func(loads, constant_load, lo))
    return VALID, -1


@jit(inline="always")
def run_motion(step, scalars, table, state, source_t, source_motion, t, motion, by_velocity,
               position, velocity, loads, constant_load, lo, hi, out_force):
    """Copy, check and cut the samples ``lo + 1 .. hi - 1`` and run the model over them, in one pass.

    The loop of :func:`polind.simulate`: it reads the sample times
    ``source_t`` and the ``source_motion`` (positions, or velocities with
    ``by_velocity``), copies them into ``t`` and ``motion`` (which may be the
    same arrays as the sources), checks the times (finite, increasing) and
    the motion as :func:`check_times` and :func:`cut_path` would, and fills
    the other of ``position``/``velocity`` and ``out_force``, with no step
    arrays and no separate copying or checking pass in between.  Sample
    ``lo`` is already done: the first sample of a run by
    :func:`first_motion_sample`, else the last of the previous chunk.
    Returns ``(code, index)`` for the first bad sample it meets:
    :data:`BAD_TIME` for a time that is not finite or not after its
    predecessor, else :func:`cut_path`'s codes for the motion; the caller
    re-checks the whole input to name the error as a full check would.
    """
    for k in range(lo + 1, hi):
        t0 = source_t[k - 1]
        t1 = source_t[k]
        m1 = source_motion[k]
        t[k] = t1
        motion[k] = m1
        # NaN fails the first test, +inf the second; t0 was checked at its own sample.
        if not (t1 > t0 and t1 < math.inf):
            return BAD_TIME, k
        h, dx, w, x1, code = motion_step(by_velocity, t0, t1, source_motion[k - 1], m1,
                                         position[k - 1])
        if code != VALID:
            return code, k
        if by_velocity:
            position[k] = x1
            sample_velocity = m1
        else:
            velocity[k] = w
            sample_velocity = w
        out_force[k] = step(scalars, table, state, h, dx, w, sample_velocity,
                            sample_load(loads, constant_load, k))
    return VALID, -1


@jit(inline="always")
def cut_sample(t_in, x_in, t_out, x_out, i):
    """Copy and cut sample ``i + 1`` of a block of positions: ``(h, dx, w, ok)``.

    The per-sample part of a blocked motion kernel's first pass (the
    arithmetic of :func:`motion_step`): ``t_in``/``x_in`` are the sources
    from the sample before the block, ``t_out``/``x_out`` the copies from
    the block's first sample.  ``ok`` is false for a time that is not finite
    or not after its predecessor (checked with its own sample) or a step
    velocity that is not finite; NaN fails every comparison.  No branch, so
    a loop over the block that calls it vectorises; the caller counts the
    bad samples and lets :func:`run_motion` find and report the first.
    """
    t0 = t_in[i]
    t1 = t_in[i + 1]
    t_out[i] = t1
    x_out[i] = x_in[i + 1]
    h = t1 - t0
    dx = x_in[i + 1] - x_in[i]
    w = dx / h
    return h, dx, w, (t1 > t0) & (t1 < math.inf) & (abs(w) < math.inf)


@jit(inline="always")
def block_views(source_t, source_motion, t, motion, velocity, out_force, a, hi, size):
    """The block of up to ``size`` samples from ``a`` (before ``hi``), as views indexed from 0.

    ``(b, t_in, x_in, t_out, x_out, w_out, f_out)``: ``b = min(a + size,
    hi)``, the sample after the block; the sources from the sample before
    the block (:func:`cut_sample`), the copies, step velocities and forces
    from its first sample.  Indexed from 0, the compiler sees non-negative
    indices and vectorises the block's loops.
    """
    b = a + size
    if b > hi:      # min(a + size, hi), without compiling numba's min of two ints
        b = hi
    return (b, source_t[a - 1:b], source_motion[a - 1:b], t[a:b], motion[a:b], velocity[a:b],
            out_force[a:b])


def no_blocks(scalars, by_velocity):
    """A model without a blocked motion path (:mod:`polind.kernels.template`): never."""
    return False


def no_block(scalars, table, state, source_t, source_motion, t, motion, velocity, out_force, a,
             hi):
    """The blocked motion of a model without one: never called (:func:`no_blocks` is false)."""
    raise AssertionError("no_block is never called: no_blocks is false")


@jit(inline="always")
def no_load_change(scalars, table, state, sample_velocity, normal_load):
    """What a model whose state does not follow the normal load does where it changes: nothing.

    A mounted path (the runners' ``mounted_path``, :mod:`polind.kernels.template`) brings
    the model's real state to a new load before the spring's trials, which
    run on copies, with the model's ``load`` function: its ``force`` (the
    default: Pol-Ind's restarts its element table there), or this one for
    a model whose ``force`` changes nothing (every model of polind but
    Pol-Ind along a varying load), so that the mounted path compiles no
    ``force``.  Returns 0.0, never read.
    """
    return 0.0


@jit(inline="always")
def no_trial(scalars, table, state, out, keep, step, displacement, step_velocity,
             sample_velocity, normal_load):
    """The read-only trial of a model without one: ``(NaN, NaN, -1)``, never read.

    A model may supply ``trial(scalars, table, state, out, keep, step,
    displacement, step_velocity, sample_velocity, normal_load) -> (F, dF/dw,
    written)``: the force ``step`` would return and its derivative in the
    step velocity ``w`` (the solvers take Newton steps with it; where the
    force is piecewise linear in ``w``, the ``tangent`` of the state the
    step leaves), computed without writing ``state``.  ``written``
    is -1 where it cannot (the caller then steps a copy of the state, as for
    a model without one); else the number ``m`` of leading entries of
    ``out`` that hold the state after the step (its other entries are
    ``state``'s own), which may be 0 unless ``keep``: with ``keep`` the
    caller means to take that state if the step is accepted.  ``out`` is the
    caller's scratch: a trial may write it with or without ``keep``.  Inlined, so
    that the callers' test of ``written`` folds away.
    """
    return math.nan, math.nan, -1


def check_times(t):
    """``(code, index)``: the first non-finite sample time, else the first not after its predecessor.

    NumPy, not a kernel: a few passes over the times, once per motion, and
    nothing for the compiler to do.
    """
    finite = np.isfinite(t)
    if not finite.all():
        return NOT_FINITE, int(np.argmin(finite))
    increasing = t[1:] > t[:-1]
    if not increasing.all():
        return NOT_INCREASING, int(np.argmin(increasing)) + 1
    return VALID, -1


def cut_path(t, motion, by_velocity, start_position, start_velocity, continuing, step,
             displacement, step_velocity, sample_velocity, position):
    """Cut a prescribed motion into steps at constant velocity (the user guide).

    ``motion`` is the positions (``by_velocity`` false: linear between
    samples, step velocity ``(x[k] - x[k-1]) / h``, reported at sample ``k``;
    at sample 0 the first step's, or ``start_velocity`` when ``continuing``)
    or the velocities (each step at the mean of its end samples, positions
    the trapezoidal integral from ``start_position``, added in order: a
    cumulative sum).  Fills the five arrays indexed by the sample a step ends
    at (entry 0 of ``step``, ``displacement`` and ``step_velocity`` is 0);
    ``position`` is filled only with velocities.  ``t`` has at least two
    samples and is checked (:func:`check_times`).  Plain IEEE arithmetic in
    NumPy, element by element the same operations as :func:`motion_step`
    (and so as :func:`run_motion` and :class:`polind.Stepper`), bit for
    bit.  Returns ``(code, index)``: :data:`NOT_FINITE` for a non-finite
    motion sample, :data:`OVERFLOW` where finite samples give a non-finite
    step velocity or position, else :data:`VALID`.
    """
    finite = np.isfinite(motion)
    if not finite.all():
        return NOT_FINITE, int(np.argmin(finite))
    step[0] = displacement[0] = step_velocity[0] = 0.0
    np.subtract(t[1:], t[:-1], out=step[1:])
    with np.errstate(over="ignore", invalid="ignore"):
        if by_velocity:
            np.add(motion[:-1], motion[1:], out=step_velocity[1:])
            np.multiply(step_velocity[1:], 0.5, out=step_velocity[1:])
            np.multiply(step_velocity[1:], step[1:], out=displacement[1:])
            displacement[0] = start_position        # the sum starts there; reset below
            np.cumsum(displacement, out=position)
            displacement[0] = 0.0
            sample_velocity[:] = motion
            finite = np.isfinite(position)
        else:
            np.subtract(motion[1:], motion[:-1], out=displacement[1:])
            np.divide(displacement[1:], step[1:], out=step_velocity[1:])
            sample_velocity[1:] = step_velocity[1:]
            sample_velocity[0] = start_velocity if continuing else step_velocity[1]
            finite = np.isfinite(step_velocity)
    if not finite.all():
        return OVERFLOW, int(np.argmin(finite))
    return VALID, -1
