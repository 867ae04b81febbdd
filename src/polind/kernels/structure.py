"""The structure driver as a numba template: ``n`` coordinates, ``m`` contacts (:ref:`guide-structures`).

A structure obeys

    M q'' + C q' + K q + sum_c b_c^T F_c(b_c q) = f(t)

where each contact ``c`` acts on the relative displacement ``u_c = b_c q``
(``+1`` on one coordinate and ``-1`` on another, or one entry for a
contact to the ground) with any polind model, mounted as in
:mod:`polind.kernels.mount` (a rigid mount is ``k_s = inf``).

The step
--------
The one-degree-of-freedom step of :mod:`polind.kernels.dynamics`,
generalised.  Over a step of length ``h`` every coordinate moves at a
constant step velocity (``q_{n+1} = q_n + h W``); BDF2 (backward Euler for
the first step, and after a step in which a set-valued Coulomb or Stribeck
contact sticks, as the body does) gives the linear part

    A W + sum_c b_c^T F_c(w_c) = r,    w_c = b_c W,
    A = 2.25 M / h + 1.5 C + h K        (Euler: M / h + C + h K)

with ``r`` the known terms.  ``A`` is symmetric positive definite for a
positive-definite ``M`` and positive semi-definite ``C``, ``K``.  The
coordinates are condensed onto the contacts: with ``G = B A^-1 B^T``
(symmetric positive semi-definite: two contacts on one relative
displacement make it singular) and ``w0 = B A^-1 r`` the velocities the
contacts would have without their forces, the contact velocities solve

    r(w) = w - w0 + G F(w) = 0.

One contact (the common joint, ``m = 1``) is one scalar equation,
``(1 / G) w + F(w) = w0 / G``: the body's ``inertia w + F(w) = known``,
solved by the body's own safeguarded solver
(:func:`polind.kernels.dynamics.solve_step`), Newton or secant steps on the
contact's own trial and tangent, bracketed, with the exact stick of a
set-valued contact and the rest of a contact whose balancing motion is
below the rounding of its coordinates.  Several contacts are solved by
Newton on ``r`` with the Jacobian ``I + G diag(dF_c/dw_c)`` from each
contact's own tangent (a step that does not lower the residual is halved),
and where that does not converge, or a contact is set-valued, by nonlinear
block Gauss–Seidel: each sweep solves each contact's scalar equation with
the others' forces held, ``(1 / G_cc) w_c + F_c(w_c) = (w0_c - sum_{d != c}
G_cd F_d) / G_cc``, which converges for contact forces non-decreasing in
their own velocity (every Maxwell-slip-family contact) but slowly for
stiff contacts in parallel; either stops when the whole residual is below
the solver's tolerance.  The coordinates' step velocities follow as ``W = A^-1 (r - B^T F)``; each coordinate is rounded
(``q_n + h W``) and each contact is committed along the increment of
``b_c q`` the rounded coordinates really make, so a contact's state follows
the structure's own path exactly as ``simulate`` would advance it.

A structure of one coordinate and one contact to the ground skips the
condensation (``1 / G = A``, ``w0 / G = r``): it is a :class:`polind.Body` driven
by the applied force, with the arithmetic of
:func:`polind.kernels.dynamics.momentum_terms` (up to the contact's trial,
which is the mounted one here, where the bare body takes the model's
read-only trial: for GMS the solver's iterations then differ, and the two
agree to a few 1e-12 of the force range rather than bit for bit).

Nothing here knows which model a contact runs: the contact enters through
its runners' mounted trial, commit and scalar solve
(:mod:`polind.kernels.template`: ``mounted_structure``; a rigid mount steps
the bare contact), and every contact of one structure shares one model
family's runners.  Everything that does not call the model
is compiled once, here, for every model; the loop that calls it is inlined
into each model's runners.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.dynamics import BDF2

#: Newton iterations over several contacts before the sweeps take over.
NEWTON_ITERATIONS = 60
#: Gauss–Seidel sweeps over the contacts before a step gives up converging.
MAX_SWEEPS = 500
#: The residual of several contacts is converged below this, relative to their forces.
CONTACT_RTOL = 1e-12

# Slots of the contact table ``contacts`` (int64, one row per contact).
#: Slot: the coordinate with +1 in ``b_c``.
FIRST = 0
#: Slot: the coordinate with -1 in ``b_c``, or -1 for a contact to the ground.
SECOND = 1
#: Slot: +1 (a ground contact's sign of ``u = SIGN * q[FIRST]``).
SIGN = 2


@jit(fastmath=False)
def structure_terms(second_order, mass, damping, stiffness, step, applied, position, velocity,
                    previous_velocity, previous_step_velocity, matrix, known):
    """Fill ``matrix = A`` and ``known = r`` of one step (the module notes); returns ``sample_slope``.

    Without fast-math, as :func:`polind.kernels.dynamics.momentum_terms`, with
    its association, so that one coordinate without damping or stiffness
    gives the body's ``inertia`` and ``known`` bit for bit.
    """
    n = matrix.shape[0]
    for i in range(n):
        total = applied[i]
        for j in range(n):
            if second_order:
                matrix[i, j] = 2.25 * mass[i, j] / step + 1.5 * damping[i, j] \
                    + stiffness[i, j] * step
                total += (mass[i, j] / step * (0.75 * previous_step_velocity[j]
                                              + 2.0 * velocity[j] - 0.5 * previous_velocity[j])
                          + 0.5 * damping[i, j] * previous_step_velocity[j]
                          - stiffness[i, j] * position[j])
            else:
                matrix[i, j] = mass[i, j] / step + damping[i, j] + stiffness[i, j] * step
                total += mass[i, j] / step * velocity[j] - stiffness[i, j] * position[j]
        known[i] = total
    return 1.5 if second_order else 1.0


@jit
def relative(contacts, c, values):
    """``b_c values``: the contact's relative part of a vector over the coordinates."""
    first = values[contacts[c, FIRST]]
    second = contacts[c, SECOND]
    if second >= 0:
        return first - values[second]
    return contacts[c, SIGN] * first


@jit
def contact_scale(contacts, c, position):
    """The coordinate whose rounding limits the contact's motion (the larger), signed as ``u``."""
    first = position[contacts[c, FIRST]]
    second = contacts[c, SECOND]
    if second >= 0:
        other = position[second]
        return first if abs(first) >= abs(other) else -other
    return contacts[c, SIGN] * first


@jit
def contact_arrays(scalars, scalar_bounds, tables, table_bounds, table_rows, states,
                   state_bounds, c):
    """Contact ``c``'s scalars, table and state: views of the packed arrays."""
    columns = (table_bounds[c + 1] - table_bounds[c]) // table_rows
    return (scalars[scalar_bounds[c]:scalar_bounds[c + 1]],
            tables[table_bounds[c]:table_bounds[c + 1]].reshape((table_rows, columns)),
            states[state_bounds[c]:state_bounds[c + 1]])


@jit
def condense(refactor, matrix, known, contacts, factor, columns, couple, free, free_contact,
             work):
    """``free = A^-1 r`` and ``free_contact = w0 = B A^-1 r``; with ``refactor`` first A's factor,
    ``columns = A^-1 B^T`` and ``couple = G = B A^-1 B^T`` (the module notes)."""
    n = matrix.shape[0]
    m = contacts.shape[0]
    if refactor:
        cholesky(matrix, factor)
        for c in range(m):
            for i in range(n):
                free[i] = 0.0
            if contacts[c, SECOND] >= 0:
                free[contacts[c, FIRST]] = 1.0
                free[contacts[c, SECOND]] = -1.0
            else:
                free[contacts[c, FIRST]] = float(contacts[c, SIGN])
            cholesky_solve(factor, free, work)
            for i in range(n):
                columns[i, c] = free[i]
        for c in range(m):
            for d in range(m):
                couple[c, d] = relative(contacts, c, columns[:, d])
    for i in range(n):
        free[i] = known[i]
    cholesky_solve(factor, free, work)
    for c in range(m):
        free_contact[c] = relative(contacts, c, free)


@jit
def own_equation(single, c, matrix, known, contacts, couple, free_contact, force_contact):
    """``(inertia, known)`` of contact ``c``'s scalar equation, the other contacts' forces held.

    ``(1 / G_cc) w_c + F_c(w_c) = (w0_c - sum_{d != c} G_cd F_d) / G_cc``; for
    one coordinate and one contact the body's own ``A`` and ``r``.
    """
    if single:
        return matrix[0, 0], float(contacts[0, SIGN]) * known[0]
    own = free_contact[c]
    for d in range(contacts.shape[0]):
        if d != c:
            own -= couple[c, d] * force_contact[d]
    inertia = 1.0 / couple[c, c]
    return inertia, own * inertia


@jit
def residuals(couple, free_contact, velocity_contact, force_contact, force_scale, contacts,
              position, step, out):
    """``r = w - w0 + G F`` into ``out``; ``(sum of (r_c / G_cc)^2, every r_c within tolerance)``.

    Measured as a force (``r_c / G_cc``, what the body's solver measures), a
    contact is converged within :data:`CONTACT_RTOL` of its forces or within
    half of what the rounding of its coordinates lets it move.
    """
    m = couple.shape[0]
    merit = 0.0
    within = True
    for c in range(m):
        coupled = 0.0
        for d in range(m):
            coupled += couple[c, d] * force_contact[d]
        residual = velocity_contact[c] - free_contact[c] + coupled
        out[c] = residual
        inertia = 1.0 / couple[c, c]
        scaled = residual * inertia
        merit += scaled * scaled
        scale = abs(contact_scale(contacts, c, position))
        quantum = (np.nextafter(scale, np.inf) - scale) / step
        tolerance = max(CONTACT_RTOL * (abs(free_contact[c]) * inertia + force_scale[c]
                                        + abs(coupled) * inertia), 0.5 * inertia * quantum)
        within = within and abs(scaled) <= tolerance
    return merit, within


@jit
def newton_step(couple, tangent_contact, residual_contact, velocity_contact, last_velocity,
                direction, jacobian):
    """A Newton step on ``r(w)``: ``(I + G diag(dF/dw)) d = -r``, ``w <- w + d`` (``last_velocity``: ``w``)."""
    m = couple.shape[0]
    for c in range(m):
        for d in range(m):
            jacobian[c, d] = couple[c, d] * tangent_contact[d]
        jacobian[c, c] += 1.0
        direction[c] = -residual_contact[c]
        last_velocity[c] = velocity_contact[c]
    lu_solve(jacobian, direction)
    for c in range(m):
        velocity_contact[c] = last_velocity[c] + direction[c]


@jit
def advance_coordinates(single, contacts, position, step, velocity_contact, free, columns,
                        force_contact, any_held, slope, offset, new_position, step_velocity,
                        new_velocity):
    """The coordinates after the step: ``W = A^-1 (r - B^T F)``, rounded; their velocities."""
    n = position.shape[0]
    if single:
        step_velocity[0] = contacts[0, SIGN] * velocity_contact[0]
    else:
        for i in range(n):
            total = free[i]
            for c in range(contacts.shape[0]):
                total -= columns[i, c] * force_contact[c]
            step_velocity[i] = total
    for i in range(n):
        new_position[i], displacement = rounded(position[i], step, step_velocity[i])
        step_velocity[i] = displacement / step
        if any_held:
            new_velocity[i] = step_velocity[i]
        else:
            new_velocity[i] = slope * step_velocity[i] + offset[i]


@jit(inline="always")
def integrate_structure_with(trial, commit, solve, arguments):
    """Integrate a structure over the samples ``start .. stop - 1`` (the module notes).

    ``trial``, ``commit`` and ``solve`` are one model's mounted runners
    (:mod:`polind.kernels.template`); ``solve`` is
    :func:`polind.kernels.dynamics.solve_step` with the trial bound.
    ``arguments`` is the tuple ``(memoryless, rest_capacity, force_scale,
    mounts, scalars, scalar_bounds, tables, table_bounds, table_rows,
    states, state_bounds, loads, contacts, mass, damping, stiffness, t,
    applied, method, q, dq, forces, carry, unconverged, start, stop)``:

    * per contact ``c``: ``memoryless[c]`` (1.0 for a set-valued contact),
      ``rest_capacity[c]``, ``force_scale[c]``, ``mounts[c]`` (its mount,
      advanced in place), its scalars, table (``table_rows`` rows) and state
      (advanced in place), stored flat between their ``bounds``, its normal
      load ``loads[c]`` and its row of ``contacts`` (:data:`FIRST`,
      :data:`SECOND`, :data:`SIGN`);
    * ``mass``, ``damping``, ``stiffness``: ``(n, n)``; ``t`` the sample
      times; ``applied`` ``(len(t), n)``, the force at each sample (the step
      ending at sample ``k`` takes ``applied[k]``);
    * ``q``, ``dq`` ``(len(t), n)`` and ``forces`` ``(len(t), m)``: filled
      from sample ``start`` on (sample ``start - 1`` is given);
    * ``carry``: ``n`` previous step velocities, ``m`` previous contact step
      velocities, and whether a BDF2 history exists (1.0 or 0.0);
      ``unconverged[0]`` counts the steps whose iteration over several
      contacts did not converge (they keep the last sweep).
    """
    (memoryless, rest_capacity, force_scale, mounts, scalars, scalar_bounds, tables,
     table_bounds, table_rows, states, state_bounds, loads, contacts, mass, damping, stiffness,
     t, applied, method, q, dq, forces, carry, unconverged, start, stop) = arguments
    n = mass.shape[0]
    m = contacts.shape[0]
    largest = 0
    for c in range(m):
        largest = max(largest, state_bounds[c + 1] - state_bounds[c])
    scratch = np.empty(2 * largest + 2)
    matrix = np.empty((n, n))
    known = np.empty(n)
    factor = np.empty((n, n))
    columns = np.empty((n, m))
    free = np.empty(n)
    work = np.empty(n)
    couple = np.empty((m, m))
    jacobian = np.empty((m, m))
    free_contact = np.empty(m)
    tangent_contact = np.empty(m)
    residual_contact = np.empty(m)
    last_velocity = np.empty(m)
    direction = np.empty(m)
    velocity_contact = np.empty(m)
    force_contact = np.empty(m)
    held = np.zeros(m, dtype=np.bool_)
    step_velocity = np.empty(n)
    new_position = np.empty(n)
    new_velocity = np.empty(n)
    offset = np.empty(n)
    previous_step = carry[:n].copy()
    previous_contact = carry[n:n + m].copy()
    history = carry[n + m] != 0.0
    single = n == 1 and m == 1
    set_valued = False
    for c in range(m):
        set_valued = set_valued or memoryless[c] != 0.0
    factored_step = math.nan
    factored_order = False
    for k in range(start, stop):
        step = t[k] - t[k - 1]
        second_order = method == BDF2 and history
        for i in range(n):
            offset[i] = -0.5 * previous_step[i] if second_order else 0.0
        previous = dq[k - 2] if k >= 2 else dq[k - 1]
        slope = structure_terms(second_order, mass, damping, stiffness, step, applied[k],
                                q[k - 1], dq[k - 1], previous, previous_step, matrix, known)
        if not single:
            # A's factor, A^-1 B^T and G are kept while the step and the scheme stay.
            refactor = step != factored_step or second_order != factored_order
            condense(refactor, matrix, known, contacts, factor, columns, couple, free,
                     free_contact, work)
            factored_step = step
            factored_order = second_order
        for c in range(m):
            velocity_contact[c] = previous_contact[c]
            force_contact[c] = forces[k - 1, c]
            held[c] = False
        converged = False
        if m > 1 and not set_valued:
            # Newton on r(w) = w - w0 + G F(w) with each contact's own tangent, halving
            # a step that does not lower the residual.
            last_merit = math.inf
            fraction = 1.0
            for iteration in range(NEWTON_ITERATIONS):
                for c in range(m):
                    c_scalars, c_table, c_state = contact_arrays(
                        scalars, scalar_bounds, tables, table_bounds, table_rows, states,
                        state_bounds, c)
                    contact_offset = -0.5 * previous_contact[c] if second_order else 0.0
                    force, tangent, _, _ = trial(memoryless[c] != 0.0, mounts[c], c_scalars, c_table,
                                                 c_state, scratch, velocity_contact[c], step,
                                                 slope, contact_offset, loads[c], bool(0))
                    force_contact[c] = force
                    tangent_contact[c] = tangent if tangent > 0.0 else 0.0
                merit, within = residuals(couple, free_contact, velocity_contact,
                                          force_contact, force_scale, contacts, q[k - 1], step,
                                          residual_contact)
                if within:
                    converged = True
                    break
                if merit >= last_merit and fraction > 1e-6:
                    fraction *= 0.5
                    for c in range(m):
                        velocity_contact[c] = last_velocity[c] + fraction * direction[c]
                    continue
                last_merit = merit
                fraction = 1.0
                newton_step(couple, tangent_contact, residual_contact, velocity_contact,
                            last_velocity, direction, jacobian)
            if not converged and last_merit < math.inf:
                for c in range(m):          # the sweeps start from the best Newton point
                    velocity_contact[c] = last_velocity[c]
        if not converged:
            # One contact: its scalar equation, by the body's solver.  Several: nonlinear
            # block Gauss-Seidel, each contact's scalar equation with the others held (the
            # exact stick of set-valued contacts included).
            for sweep in range(1 if m == 1 else MAX_SWEEPS):
                for c in range(m):
                    own_inertia, own = own_equation(single, c, matrix, known, contacts, couple,
                                                    free_contact, force_contact)
                    c_scalars, c_table, c_state = contact_arrays(
                        scalars, scalar_bounds, tables, table_bounds, table_rows, states,
                        state_bounds, c)
                    is_memoryless = memoryless[c] != 0.0
                    contact_offset = -0.5 * previous_contact[c] if second_order else 0.0
                    velocity, stuck, force, _ = solve(
                        is_memoryless, rest_capacity[c], force_scale[c], mounts[c], c_scalars,
                        c_table, c_state, scratch, own_inertia, own, velocity_contact[c], step,
                        contact_scale(contacts, c, q[k - 1]), slope, contact_offset, loads[c])
                    held[c] = stuck
                    if stuck:
                        force = own
                    elif force != force:
                        force, _, _, _ = trial(is_memoryless, mounts[c], c_scalars, c_table,
                                               c_state, scratch, velocity, step, slope,
                                               contact_offset, loads[c], bool(0))
                    velocity_contact[c] = velocity
                    force_contact[c] = force
                if m == 1:
                    converged = True
                    break
                merit, within = residuals(couple, free_contact, velocity_contact,
                                          force_contact, force_scale, contacts, q[k - 1], step,
                                          residual_contact)
                if within:
                    converged = True
                    break
        if not converged:
            unconverged[0] += 1
        any_held = False
        for c in range(m):
            any_held = any_held or held[c]
        advance_coordinates(single, contacts, q[k - 1], step, velocity_contact, free, columns,
                            force_contact, any_held, slope, offset, new_position,
                            step_velocity, new_velocity)
        # Each contact along the increment of b_c q the rounded coordinates make.
        for c in range(m):
            if held[c]:
                forces[k, c] = force_contact[c]
                previous_contact[c] = 0.0
                continue
            c_scalars, c_table, c_state = contact_arrays(
                scalars, scalar_bounds, tables, table_bounds, table_rows, states,
                state_bounds, c)
            if single:
                displacement = contacts[0, SIGN] * (new_position[0] - q[k - 1, 0])
            else:
                displacement = relative(contacts, c, new_position) \
                    - relative(contacts, c, q[k - 1])
            contact_velocity = displacement / step
            sample_velocity = contact_velocity if memoryless[c] != 0.0 \
                else relative(contacts, c, new_velocity)
            forces[k, c] = commit(mounts[c], c_scalars, c_table, c_state, scratch, step,
                                  displacement, contact_velocity, sample_velocity, loads[c])
            previous_contact[c] = contact_velocity
        for i in range(n):
            q[k, i] = new_position[i]
            dq[k, i] = new_velocity[i]
            previous_step[i] = step_velocity[i]
        history = not any_held
    for i in range(n):
        carry[i] = previous_step[i]
    for c in range(m):
        carry[n + c] = previous_contact[c]
    carry[n + m] = 1.0 if history else 0.0


@jit(fastmath=False)
def rounded(position, step, velocity):
    """``q + h w`` rounded, and the increment it really is (:func:`polind.kernels.dynamics.rounded_motion`)."""
    new_position = position + step * velocity
    return new_position, new_position - position


@jit
def cholesky(matrix, factor):
    """The lower Cholesky factor of the symmetric positive-definite ``matrix``, into ``factor``.

    The structure's matrices are a few coordinates and contacts across:
    NumPy's LAPACK solvers inside a kernel cost numba some 15 s to compile
    for nothing a small dense factorization needs.  A non-positive pivot
    (an indefinite ``K``) leaves NaN, which the caller's residual shows.
    """
    n = matrix.shape[0]
    for j in range(n):
        total = matrix[j, j]
        for p in range(j):
            total -= factor[j, p] * factor[j, p]
        pivot = math.sqrt(total) if total > 0.0 else math.nan
        factor[j, j] = pivot
        for i in range(j + 1, n):
            value = matrix[i, j]
            for p in range(j):
                value -= factor[i, p] * factor[j, p]
            factor[i, j] = value / pivot
        for i in range(j):
            factor[i, j] = 0.0


@jit
def cholesky_solve(factor, values, work):
    """Solve ``L L^T x = values`` in place (``factor`` from :func:`cholesky`)."""
    n = factor.shape[0]
    for i in range(n):
        total = values[i]
        for p in range(i):
            total -= factor[i, p] * work[p]
        work[i] = total / factor[i, i]
    for i in range(n - 1, -1, -1):
        total = work[i]
        for p in range(i + 1, n):
            total -= factor[p, i] * values[p]
        values[i] = total / factor[i, i]


@jit
def lu_solve(matrix, values):
    """Solve ``matrix x = values`` in place, by Gaussian elimination with partial pivoting.

    A Newton step over the contacts (``m x m``, a few across): see
    :func:`cholesky` for why not LAPACK.  ``matrix`` is overwritten.
    """
    n = matrix.shape[0]
    for j in range(n):
        pivot = j
        for i in range(j + 1, n):
            if abs(matrix[i, j]) > abs(matrix[pivot, j]):
                pivot = i
        if pivot != j:
            for p in range(n):
                matrix[j, p], matrix[pivot, p] = matrix[pivot, p], matrix[j, p]
            values[j], values[pivot] = values[pivot], values[j]
        for i in range(j + 1, n):
            ratio = matrix[i, j] / matrix[j, j]
            for p in range(j, n):
                matrix[i, p] -= ratio * matrix[j, p]
            values[i] -= ratio * values[j]
    for i in range(n - 1, -1, -1):
        total = values[i]
        for p in range(i + 1, n):
            total -= matrix[i, p] * values[p]
        values[i] = total / matrix[i, i]
