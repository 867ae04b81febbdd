"""The one-degree-of-freedom integrator as numba kernels (:ref:`guide-systems`).

A body of mass ``m`` obeys ``m a = F_applied(t, x) - F`` with
``F_applied = k_d (v_d t - x) + offset + rate t + amplitude sin(2 pi f t)``
and ``F`` the friction force of any polind model.

The step
--------
Over a step of length ``h`` the body moves at a constant *step velocity*
``w`` (``x_{n+1} = x_n + h w``: the path is linear between samples, as for
:func:`polind.simulate` with ``x``), and every friction model has an exact
(or unconditionally stable) update at constant velocity, so the friction
force at the end of the step is a function ``F(w)`` of the one unknown.  A
*trial* evaluates it on a scratch copy of the model state; the accepted
``w`` is *committed* with the same update, so the model state follows the
body's own path exactly as ``simulate(model, t, x=x)`` advances it.  The
momentum equation is implicit:

* ``BDF2`` (default): ``(3 x_{n+1} - 4 x_n + x_{n-1}) / 2h = v_{n+1}`` and
  ``m (3 v_{n+1} - 4 v_n + v_{n-1}) / 2h = F_applied(t_{n+1}, x_{n+1}) - F``;
  with ``v_{n+1} = (3 w - w_n) / 2`` this is one scalar equation in ``w``.
  The friction's rate terms (``sigma2 v``, LuGre's ``sigma1 dz/dt``) are taken
  at ``v_{n+1}``, the body's velocity at the sample (at the step velocity
  they would cost an O(h) error).  Second order, and L-stable: element
  springs with ``k h^2 / m`` of 1e6 are damped within a few steps instead of
  ringing at the Nyquist frequency, which is what the trapezoidal/midpoint
  rule does (its amplification tends to -1 for stiff modes, and a body that
  stops gets ``v_{n+1} = -v_n``).
* ``EULER``: backward Euler, ``v_{n+1} = w``; first order, L-stable, and
  the whole result is then exactly ``simulate(model, t, x=x)``'s.

BDF2 starts (and, for the memoryless models, restarts after a stuck step)
with one backward-Euler step.  In both schemes the residual is
``R(w) = inertia w + F(w) - known`` with ``inertia = c m / h + k_d h > 0``:
the friction force is the only nonlinear term.

Second order needs the model's own relaxation to be resolved by the step.
Where it is much faster (a GMS element with ``C h / (alpha_i g) >> 1``,
LuGre's ``sigma0 |v| h / g >> 1``) the state sits on the steady value of
the step velocity, i.e. half a step late, and the scheme is first order
there; it is never worse than backward Euler.

Convergence, measured
---------------------
Against SciPy's Radau (rtol 1e-12), max ``|x - x_ref|``:

================  =======  =======  =======  =======  =======  =======  =======
h [s]             1e-3     5e-4     2e-4     1e-4     5e-5     2e-5     1e-5
LuGre sliding     5.9e-4   4.1e-4   1.4e-4   4.6e-5   1.3e-5   2.4e-6   6.1e-7
LuGre stick-slip  1.4e-4   3.8e-5   6.3e-6   1.6e-6   4.4e-7   1.4e-7   1.4e-6
================  =======  =======  =======  =======  =======  =======  =======

(sliding: ``k_d = 20``, ``v_d = 0.05``, offset 1 N, started at ``v_d``,
2 s; stick-slip: the 1995 case, two cycles, 20 s.)  Sliding is second order
once the step resolves the bristle relaxation (2e-4 s here).  Stick-slip is
second order down to 2e-5 s and then *worse*: positions are floats, so the
step velocity matters only to within ``ulp(x_n) / h`` (below), a quantum
that grows as ``h`` shrinks and with ``|x|`` (started at ``x = 1e3`` m the
error at ``h = 1e-4`` is 8e-5).  A creeping LuGre stick phase moves at
velocities of that order, and is resolved no better.  Carrying the position
in two floats would remove the floor but also the exact rest of a stuck body
(which the quantum gives); it is not done.  Take ``h >= 2e-5`` s for
positions of order 1 m, or measure ``x`` from a nearby origin.

The solve
---------
``R`` is evaluated first at ``w = 0`` (nothing moves: the model state is
unchanged).  ``x_n + h w`` is rounded to a float, so ``w`` only matters to
within ``ulp(x_n) / h``: if the balancing motion is below half of that, the
body does not move, ``w = 0`` exactly, and a resting body never creeps by
itself.  Otherwise the root lies on the side ``-sgn R(0)``; it is bracketed
(starting from the previous step's velocity, or a Newton step with the
model's tangent) and refined by Newton steps where the model's read-only
trial gives the derivative ``dF/dw`` of its force and the residual rises
there, else by secant steps, safeguarded by bisection.  For the
Maxwell-slip family ``F(w)`` is piecewise linear (the kinks are elements
changing between stick and slip), so either iteration is the active-set
iteration and ends in a few steps; on GMS elements below a few Stribeck
velocities ``F`` also moves with ``g(w)``, which the derivative includes
(on a measured Pol-Ind map behind a spring: 3.8 trials per moving step
against 4.6 with secant steps).

Two model families are discontinuous at ``w = 0``:

* Coulomb and Stribeck have the set-valued friction ``[-Fs, Fs]`` there and
  are evaluated at the step velocity.  If ``|known| <= Fs`` the body is
  stuck: ``w = 0``, ``v = 0`` and the friction is the balancing force
  ``known``.
* GMS (and Pol-Ind): an element in slip relaxes towards ``alpha_i g(0)`` at a
  rate ``C`` that does not vanish as ``v -> 0+``, while at ``v = 0`` nothing
  changes.  When the root lies inside that jump the step takes the smallest
  motion ``x`` can represent in that direction (one unit in the last place),
  which lets the slip law act; the following steps settle the body
  elastically.

The model
---------
The friction model enters only through the stepping contract of
:mod:`polind.kernels.contract`: its ``step`` and ``tangent`` functions, its
``scalars``, ``table`` and flat ``state``, a typical force ``force_scale``
(the residual tolerance scales with it) and, for a memoryless model, its
``rest_capacity`` ``g(0)`` (``memoryless`` true).  Nothing here knows which
model it runs.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.mount import load_ratio
from polind.kernels.stribeck import sign

# Momentum schemes (the ``method`` argument).
BDF2 = 0
EULER = 1

RTOL = 1e-13           # residual tolerance relative to |known| + force_scale
MAX_ITERATIONS = 200
#: A trial after a residual within this many tolerances is likely the last, and keeps its
#: state for a caller that reuses it (:func:`solve_step`'s ``reuse``).
KEEP_BELOW = 1e7
#: The same after a Newton step with the trial's exact ``dF/dw``, which converges faster:
#: on a measured map behind a spring, three of four trials after a residual below this
#: were the last.
KEEP_BELOW_NEWTON = 1e9


@jit(inline="always")
def bare_trial(step_function, tangent_function, trial_function, memoryless, mount, scalars,
               table, state, scratch, velocity, step, sample_slope, sample_offset, normal_load,
               keep):
    """``(F(w), tangent, written, exact)`` without touching ``state``.

    The model's read-only ``trial_function``
    (:func:`polind.kernels.contract.no_trial`, given ``scratch`` and
    ``keep``) where it has one and it answers, its tangent ``dF/dw``
    (``exact`` true); else the update runs on ``scratch``, a copy of
    ``state``, and the model's tangent is taken there (``exact`` false).
    ``written``: the leading entries of ``scratch`` that hold the state
    after the step (:func:`solve_step`).  A memoryless model is evaluated at the step
    velocity, so that ``w = 0`` is its stick; a model with state takes its
    rate terms at the body's velocity at the sample, ``sample_slope * w +
    sample_offset``.  ``mount`` is not used: this is the trial of a model
    with nothing around its contact (:mod:`polind.kernels.series` has the
    trial of a mounted one).
    """
    sample_velocity = velocity if memoryless else sample_slope * velocity + sample_offset
    force, tangent, written = trial_function(scalars, table, state, scratch, keep, step,
                                             velocity * step, velocity, sample_velocity,
                                             normal_load)
    answered = written >= 0
    if answered:
        return force, tangent, written, answered
    n = state.shape[0]
    work = scratch[:n]
    for i in range(n):      # a loop: `work[:] = state` compiles NumPy's shape-error message (5 s)
        work[i] = state[i]
    force = step_function(scalars, table, work, step, velocity * step, velocity,
                          sample_velocity, normal_load)
    return force, tangent_function(scalars, table, work, step), n, answered


@jit(inline="always")
def bare_commit(step_function, mount, scalars, table, state, scratch, step, displacement,
                step_velocity, sample_velocity, normal_load):
    """Advance ``state`` over the accepted step and return the force (nothing around the contact)."""
    return step_function(scalars, table, state, step, displacement, step_velocity,
                         sample_velocity, normal_load)


@jit(inline="always")
def solve_step(trial, tangent_function, memoryless, rest_capacity, force_scale,
               mount, scalars, table, state, scratch, inertia, known, guess, step, position,
               sample_slope, sample_offset, normal_load, reuse):
    """Solve ``inertia w + F(w) = known`` for the step velocity ``w``.

    ``trial(memoryless, mount, scalars, table, state, scratch, w, step,
    sample_slope, sample_offset, normal_load, keep)`` evaluates ``(F(w),
    dF/dw, written, exact)`` without touching ``state`` (``scratch`` is its
    work space; ``written``: see below; ``exact``: the tangent is the
    derivative of that ``F``, not the model's tangent of the state, and the
    step after it is Newton's where the residual rises): a model's :func:`bare_trial`
    or the trial of a mounted contact (:mod:`polind.kernels.series`) with
    the model's functions bound, compiled on its own (the runners'
    ``trial``, :mod:`polind.kernels.template`), so that the model's step is
    not inlined at each of the solver's calls.  ``tangent_function`` is the
    model's (a memoryless model's tangent at rest).  The body's velocity at the end of the step, at which the friction's rate
    terms are taken, is ``sample_slope * w + sample_offset``.  Returns
    ``(w, held, F, written)``; ``held`` is true when a memoryless model
    sticks (``w = 0`` and the friction is ``known``).  ``F`` is the trial's
    force at the returned ``w`` and ``written`` the number of leading
    entries of ``scratch`` that hold the state after that trial's step (the
    rest is ``state``'s own) when the returned ``w`` is the last trial's,
    else NaN and 0.  With ``reuse`` (a caller that takes that state instead
    of stepping again: the runners' ``mounted_step``, :mod:`polind.kernels.template`) the
    trials that are likely the last (the residual before them within
    :data:`KEEP_BELOW` tolerances, :data:`KEEP_BELOW_NEWTON` after a Newton
    step) ask the model to keep their state
    (``keep``); otherwise the scratch a model's read-only trial writes is not taken.

    A memoryless model's ``rest_capacity`` is that at the mount's reference
    load, scaled by ``load_ratio`` (:mod:`polind.kernels.mount`).

    ``position`` is ``x_n``.  The new position ``x_n + h w`` is rounded to a
    float, so ``w`` matters only to within ``quantum = ulp(x_n) / h``: the
    residual is converged below ``RTOL * (|known| + force_scale)`` or below
    what half a quantum of motion changes, and a body whose balancing motion
    is below half a quantum stays exactly where it is.
    """
    quantum = (np.nextafter(abs(position), np.inf) - abs(position)) / step
    tolerance = max(RTOL * (abs(known) + force_scale), 0.5 * inertia * quantum)
    if memoryless:
        capacity = rest_capacity * load_ratio(mount, normal_load)
        if abs(known) <= capacity:
            return 0.0, True, math.nan, 0
        direction = sign(known)
        residual_at_zero = direction * capacity - known  # R(0+) or R(0-)
        tangent_at_zero = tangent_function(scalars, table, state, step)
    else:
        # keep: a computed false (bool(0)), of the type of the loop's `keep` below
        # (bool(...), computed with or without reuse): a literal False here would
        # compile the trial, and the model's step inlined in it, a second time.
        force, tangent_at_zero, written, _ = trial(memoryless, mount, scalars, table, state,
                                                   scratch, 0.0, step, sample_slope,
                                                   sample_offset, normal_load, bool(0))
        residual_at_zero = force - known
        if abs(residual_at_zero) <= max(tolerance,
                                         0.5 * (inertia + tangent_at_zero) * quantum):
            return 0.0, False, force, written
        direction = -sign(residual_at_zero)
    # The least motion in that direction: one unit in the last place of x.
    least = (np.nextafter(position, direction * np.inf) - position) / step
    # Bracket: R(low) < 0 < R(high); the root lies on the side `direction` of 0.
    if direction > 0.0:
        low, high = 0.0, np.inf
        low_residual, high_residual = residual_at_zero, np.inf
    else:
        low, high = -np.inf, 0.0
        low_residual, high_residual = -np.inf, residual_at_zero
    if guess * direction > 0.0:
        velocity = guess
    else:
        velocity = -residual_at_zero / (inertia + tangent_at_zero)
    last_velocity = 0.0
    last_residual = residual_at_zero
    best_velocity = least
    best_residual = np.inf
    jump_checked = False
    keep_below = KEEP_BELOW
    for iteration in range(MAX_ITERATIONS):
        keep = bool(reuse and abs(last_residual) <= keep_below * tolerance)
        force, tangent, written, exact = trial(memoryless, mount, scalars, table, state,
                                               scratch, velocity, step, sample_slope,
                                               sample_offset, normal_load, keep)
        residual = inertia * velocity + force - known
        if abs(residual) < best_residual:
            best_velocity, best_residual = velocity, abs(residual)
        if abs(residual) <= tolerance:
            return velocity, False, force, written
        if residual < 0.0:
            low, low_residual = velocity, residual
        else:
            high, high_residual = velocity, residual
        # Newton with the trial's own dF/dw (exact) where the residual rises
        # there; else the secant through the last two points (exact on a
        # linear piece of F); else Newton with the model's tangent (at least
        # the inertia).
        newton = inertia + tangent
        keep_below = KEEP_BELOW
        if exact and newton > 0.0 and newton < np.inf:
            slope = newton
            keep_below = KEEP_BELOW_NEWTON
        else:
            slope = (residual - last_residual) / (velocity - last_velocity)
            if not (slope > 0.0 and slope < np.inf):
                slope = inertia + max(tangent, 0.0) if exact else newton
        candidate = velocity - residual / slope
        slow = abs(residual) > 0.5 * abs(last_residual)
        if math.isinf(low) or math.isinf(high):
            # Still open on one side: when progress stalls, at least double.
            if slow:
                if direction > 0.0:
                    candidate = max(candidate, 2.0 * low)
                else:
                    candidate = min(candidate, 2.0 * high)
        else:
            if not (low < candidate < high) or slow:
                if (low == 0.0 or high == 0.0) and not jump_checked:
                    # The root may sit in the jump of F at w = 0: try the least motion.
                    jump_checked = True
                    candidate = least
                else:
                    candidate = 0.5 * (low + high)
            width = high - low
            if width <= 4e-16 * max(abs(low), abs(high)) or width <= abs(least):
                if low != 0.0 and high != 0.0:
                    return best_velocity, False, math.nan, 0     # a kink at machine resolution
                # The root lies within the least motion of x.  A jump of F at
                # w = 0 (a GMS element in slip relaxes at a rate that does not
                # vanish as w -> 0; the set-valued Coulomb/Stribeck force) needs
                # the least motion, to let the slip law act; otherwise take the
                # nearer end.
                end_velocity = high if direction > 0.0 else low
                end_residual = high_residual if direction > 0.0 else low_residual
                continuous_gap = 2.0 * (inertia + tangent_at_zero) * abs(least) + 2.0 * tolerance
                if memoryless or abs(end_residual - residual_at_zero) > continuous_gap \
                        or abs(end_residual) < abs(residual_at_zero):
                    return end_velocity, False, math.nan, 0
                return 0.0, False, math.nan, 0
        last_velocity, last_residual = velocity, residual
        velocity = candidate
    return best_velocity, False, math.nan, 0




@jit(inline="always")
def applied_force(time, position, drive_stiffness, drive_velocity, offset, rate, amplitude,
                  angular_frequency):
    """F_applied(t, x) [N]: the drive spring plus the applied force (:ref:`guide-systems`)."""
    return (drive_stiffness * (drive_velocity * time - position) + offset + rate * time
            + amplitude * math.sin(angular_frequency * time))


@jit(fastmath=False)
def rounded_motion(position, step, velocity):
    """``x_{n+1} = x_n + h w`` rounded to a float, and the increment it really is.

    Without fast-math: reassociation would simplify ``(x + h w) - x`` to
    ``h w``, and the model would be advanced by a step other than the one the
    stored positions show.
    """
    new_position = position + step * velocity
    return new_position, new_position - position


@jit(fastmath=False)
def momentum_terms(second_order, mass, drive_stiffness, step, external, velocity,
                   previous_velocity, previous_step_velocity):
    """``(sample_slope, sample_offset, inertia, known)`` of a step's implicit equation.

    ``inertia w + F(w) = known``, with the body's velocity at the sample
    ``sample_slope w + sample_offset``: BDF2 when ``second_order``, else
    backward Euler (the module notes).
    """
    if second_order:
        # v_{n+1} = (3 w - w_n) / 2 and m (3 v_{n+1} - 4 v_n + v_{n-1}) / 2h = ...
        inertia = 2.25 * mass / step + drive_stiffness * step
        known = mass / step * (0.75 * previous_step_velocity + 2.0 * velocity
                               - 0.5 * previous_velocity) + external
        return 1.5, -0.5 * previous_step_velocity, inertia, known
    return 1.0, 0.0, mass / step + drive_stiffness * step, mass / step * velocity + external


@jit(inline="always")
def body_step(trial, commit, tangent_function, memoryless, rest_capacity,
              force_scale, mount, scalars, table, state, scratch, method, mass, drive_stiffness,
              step, external, position, velocity, previous_velocity, previous_step_velocity,
              history, normal_load):
    """One implicit step of the body (the scheme of the module notes).

    ``external`` is the force on the body over the step other than friction,
    with the drive spring taken at the previous position (its stiffness
    ``drive_stiffness`` enters the implicit equation).  ``velocity`` and
    ``previous_velocity`` are ``v_n`` and ``v_{n-1}``; ``history`` whether a
    BDF2 step may use them.  ``trial`` as in :func:`solve_step`; ``state``
    is committed in place by ``commit(mount, scalars, table, state, scratch,
    step, displacement, step_velocity, sample_velocity, normal_load)``
    (:func:`bare_commit` or a mounted contact's, with the model's functions
    bound, to match ``trial``).

    Returns ``(x, v, F, step_velocity, history)`` at the end of the step.

    The momentum terms and the new position are computed by functions
    compiled without fast-math (:func:`momentum_terms`,
    :func:`rounded_motion`): ``known`` cancels terms of order ``m v / h``, and
    a fused multiply-add that one caller's optimiser forms and another's does
    not would make a :class:`polind.Body` differ from ``simulate_system``.
    """
    sample_slope, sample_offset, inertia, known = momentum_terms(
        method == BDF2 and history, mass, drive_stiffness, step, external, velocity,
        previous_velocity, previous_step_velocity)
    step_velocity, stuck, _, _ = solve_step(trial, tangent_function, memoryless,
                                            rest_capacity, force_scale, mount, scalars, table,
                                            state, scratch, inertia, known,
                                            previous_step_velocity, step, position,
                                            sample_slope, sample_offset, normal_load, False)
    if stuck:
        return position, 0.0, known, 0.0, False
    new_position, displacement = rounded_motion(position, step, step_velocity)
    step_velocity = displacement / step
    new_velocity = sample_slope * step_velocity + sample_offset
    sample_velocity = step_velocity if memoryless else new_velocity
    friction = commit(mount, scalars, table, state, scratch, step, displacement, step_velocity,
                      sample_velocity, normal_load)
    return new_position, new_velocity, friction, step_velocity, True


@jit(inline="always")
def integrate_system_with(stepper, arguments):
    """Integrate the 1-DOF system over the samples ``t``; fill the output arrays.

    ``arguments`` is the tuple ``(memoryless, rest_capacity, force_scale,
    scalars, table, state, t, mass, drive_stiffness, drive_velocity, offset,
    rate, amplitude, frequency, applied_steps, method, normal_load, x, v,
    force, applied, start, stop, carry, mount)``.  ``stepper`` is one model's
    :func:`body_step` with its functions bound (the ``body_step`` or
    ``mounted_body_step`` of its runners, :mod:`polind.kernels.template`):
    ``stepper(memoryless, rest_capacity, force_scale, mount, scalars, table,
    state, scratch, method, mass, drive_stiffness, step, external, position,
    velocity, previous_velocity, previous_step_velocity, history,
    normal_load)``.

    On entry ``x[0]``, ``v[0]`` and ``force[0]`` hold the initial position,
    velocity and friction force, and ``state`` the model state; on exit
    ``state`` is the final state.  The model state is committed at the step
    velocity ``(x[k] - x[k-1]) / (t[k] - t[k-1])`` computed from the stored
    samples, exactly as ``simulate(model, t, x=x)`` advances it; the rate
    terms of the force are taken at the body's velocity ``v[k]`` (which is
    the step velocity under backward Euler).

    With a non-empty ``applied_steps`` (one force per step, held over it) the
    body is driven by those forces instead of the drive parameters, and
    ``applied[k]`` is the force applied from sample ``k`` on (the last sample
    repeats the last step's).

    The run covers the steps ending at samples ``start .. stop - 1``
    (``start >= 1``), so a long run can be cut into chunks; ``carry`` holds
    what a step needs from the one before it besides the samples: the last
    step velocity and whether a BDF2 history exists (1.0) or not (0.0).
    Start a run with ``carry = [v[0], 0.0]``.
    """
    (memoryless, rest_capacity, force_scale, scalars, table, state, t, mass, drive_stiffness,
     drive_velocity, offset, rate, amplitude, frequency, applied_steps, method, normal_load,
     x, v, force, applied, start, stop, carry, mount) = arguments
    angular_frequency = 2.0 * math.pi * frequency
    # Two state-sized work arrays: a trial's state and, for a contact behind a
    # series spring, the trials of its own solve.
    scratch = np.empty(2 * state.shape[0])
    driven = applied_steps.shape[0] > 0
    previous_step_velocity = carry[0]
    history = carry[1] != 0.0   # a BDF2 step needs one regular step before it
    for k in range(start, stop):
        step = t[k] - t[k - 1]
        if driven:
            external = applied_steps[k - 1]
        else:
            external = applied_force(t[k], x[k - 1], drive_stiffness, drive_velocity, offset,
                                     rate, amplitude, angular_frequency)
        previous_velocity = v[k - 2] if k >= 2 else v[k - 1]
        x[k], v[k], force[k], previous_step_velocity, history = stepper(
            memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch, method, mass, drive_stiffness, step, external, x[k - 1],
            v[k - 1], previous_velocity, previous_step_velocity, history, normal_load)
        if driven:
            applied[k] = applied_steps[k] if k < applied_steps.shape[0] else applied_steps[k - 1]
        else:
            applied[k] = applied_force(t[k], x[k], drive_stiffness, drive_velocity, offset,
                                       rate, amplitude, angular_frequency)
    carry[0] = previous_step_velocity
    carry[1] = 1.0 if history else 0.0


@jit(inline="always")
def advance_body_with(stepper, arguments):
    """One step of :class:`polind.Body`: :func:`body_step` with its state in ``body``.

    ``arguments`` is the tuple ``(memoryless, rest_capacity, force_scale,
    scalars, table, state, scratch, method, mass, step, external, body,
    normal_load, mount)``; ``scratch`` has twice the length of ``state``;
    ``body`` is ``[x_n, v_n, v_{n-1}, w_n, history, friction]`` and is
    updated in place.  The same arithmetic as
    :func:`integrate_system_with` driven by ``applied_steps``, so a loop
    of these equals one run of it.
    """
    (memoryless, rest_capacity, force_scale, scalars, table, state, scratch, method, mass, step,
     external, body, normal_load, mount) = arguments
    x, v, friction, step_velocity, history = stepper(
        memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch, method, mass, 0.0, step, external, body[0],
        body[1], body[2], body[3], body[4] != 0.0, normal_load)
    body[2] = body[1]
    body[0] = x
    body[1] = v
    body[3] = step_velocity
    body[4] = 1.0 if history else 0.0
    body[5] = friction


@jit(fastmath=False)
def clock_step(clock):
    """The step from sample ``n`` to ``n + 1`` of ``clock = [t_0, n, h]``, or NaN if it is lost.

    ``(t_0 + (n + 1) h) - (t_0 + n h)``, the step of the sample times as
    :func:`polind.simulate_system` computes them (without fast-math: a fused
    multiply-add or a reassociation would give another step than the Python
    side of :class:`polind.Body` computes).  NaN when the rounding of the
    absolute time takes more than 1e-6 of ``h`` from it.
    """
    start, steps, length = clock[0], clock[1], clock[2]
    step = (start + (steps + 1.0) * length) - (start + steps * length)
    if not abs(step - length) <= 1e-6 * length:
        return np.nan
    return step


@jit(inline="always")
def body_advance_with(stepper, memoryless, rest_capacity, force_scale, mount, scalars, table,
                      state, scratch, method, mass, clock, body, normal_load, applied_force):
    """One step of :class:`polind.Body` from its own arrays: ``(x, v, F)`` at its end.

    ``body`` is ``[x_n, v_n, v_{n-1}, w_n, history, friction]`` and ``clock``
    ``[t_0, n, h]`` (:func:`clock_step`); both, ``state`` and (behind a
    series spring) ``mount`` are advanced in place.  A lost step
    (:func:`clock_step`) changes nothing and returns NaNs.  The arithmetic of
    :func:`advance_body_with`.
    """
    step = clock_step(clock)
    if step != step:
        return np.nan, np.nan, np.nan
    x, v, friction, step_velocity, history = stepper(
        memoryless, rest_capacity, force_scale, mount, scalars, table, state, scratch, method,
        mass, 0.0, step, applied_force, body[0], body[1], body[2], body[3], body[4] != 0.0,
        normal_load)
    body[2] = body[1]
    body[0] = x
    body[1] = v
    body[3] = step_velocity
    body[4] = 1.0 if history else 0.0
    body[5] = friction
    clock[1] += 1.0
    return x, v, friction


@jit(inline="always")
def body_batch_with(stepper, memoryless, rest_capacity, force_scale, mounts, scalars, table,
                    states, scratch, method, masses, clock, bodies, applied_forces, normal_load,
                    out):
    """One step of every body of a :class:`polind.BodyBatch`, each as :func:`body_advance_with`.

    ``mounts``, ``states`` and ``bodies`` have one row per body, ``masses``
    and ``applied_forces`` one entry; all share the contact law (``scalars``,
    ``table``) and ``clock``.  ``out`` (3, n) receives ``x``, ``v`` and
    ``F``.  Returns False (and changes nothing) for a lost step.
    """
    step = clock_step(clock)
    if step != step:
        return False
    for i in range(states.shape[0]):
        body = bodies[i]
        x, v, friction, step_velocity, history = stepper(
            memoryless, rest_capacity, force_scale, mounts[i], scalars, table, states[i],
            scratch, method, masses[i], 0.0, step, applied_forces[i], body[0], body[1], body[2],
            body[3], body[4] != 0.0, normal_load)
        body[2] = body[1]
        body[0] = x
        body[1] = v
        body[3] = step_velocity
        body[4] = 1.0 if history else 0.0
        body[5] = friction
        out[0, i] = x
        out[1, i] = v
        out[2, i] = friction
    clock[1] += 1.0
    return True
