"""Experiment 2, presliding hysteresis with non-local memory (:ref:`guide-phenomenon-presliding`).

:func:`presliding_memory` drives the displacement along :data:`MEMORY_PATH`
(a virgin loading, the major loop and loops nested inside it, all within
the presliding range) and checks that every inner loop closes on its
reversal point (:data:`MEMORY_CLOSURES`) and is wiped out: the path then
follows the branch it would have followed without the loop
(:data:`MEMORY_BRANCHES`), within :data:`MEMORY_TOLERANCE`.
"""

from __future__ import annotations

import numpy as np

from polind.errors import InputError
from polind.phenomena.common import (
    PhenomenonResult,
    experiment_result,
    friction_levels,
    velocity_scale,
)
from polind.simulation import simulate

__all__ = ["MEMORY_PATH", "MEMORY_CLOSURES", "MEMORY_BRANCHES", "MEMORY_TOLERANCE",
           "presliding_memory"]

#: The displacement path of the presliding experiment, in units of its amplitude: a virgin
#: loading to +1, the major reversal to -1, then loops nested inside it
#: (:ref:`guide-phenomenon-presliding`).
MEMORY_PATH = (0.0, 1.0, -1.0, 0.6, -0.2, 0.3, -0.2, -0.5, 0.6, 1.0)
#: (closing vertex, reversal it returns to, the loop's other reversal), indices into MEMORY_PATH.
MEMORY_CLOSURES = ((6, 4, 5), (8, 3, 7), (9, 1, 2))
#: (first, last vertex of a leg of MEMORY_PATH, reference path without the inner loops
#: whose last leg covers the same displacements): the branch after a wipe-out.
MEMORY_BRANCHES = ((6, 7, (0.0, 1.0, -1.0, 0.6, -0.5)), (8, 9, (0.0, 1.0, -1.0, 1.0)))
_GRID = 100                       # samples per unit amplitude: every vertex is a sample
#: A loop *closes* (and a branch resumes) when the force misses by less than this fraction
#: of the loop's (the major loop's) force span.
MEMORY_TOLERANCE = 1e-6


def _polyline(vertices, amplitude, speed):
    """A path through ``vertices`` (units of ``amplitude``) at constant speed.

    Returns ``(t, x, grid, corners)``: ``grid`` the integer displacement in
    units of ``amplitude / _GRID`` (the same displacement gets the same
    integer on every leg) and ``corners`` the sample index of every vertex.
    """
    grid = [round(vertices[0] * _GRID)]
    corners = [0]
    for start, end in zip(vertices[:-1], vertices[1:]):
        a, b = round(start * _GRID), round(end * _GRID)
        step = 1 if b > a else -1
        grid.extend(range(a + step, b + step, step))
        corners.append(len(grid) - 1)
    grid = np.asarray(grid, dtype=np.int64)
    x = grid * (amplitude / _GRID)
    t = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(x))) / speed))
    return t, x, grid, corners


def presliding_memory(model, *, amplitude=None, speed=None) -> PhenomenonResult:
    """Presliding hysteresis with nested reversals: do inner loops close and get wiped out?

    The displacement follows :data:`~polind.phenomena.presliding.MEMORY_PATH`
    at a constant speed, every reversal a sample.  For each closure of
    :data:`~polind.phenomena.presliding.MEMORY_CLOSURES` the force when the
    path comes back to a reversal point is compared with the force it had
    there; for each leg of :data:`~polind.phenomena.presliding.MEMORY_BRANCHES`
    the force after the closure is compared with a run along the same path
    without the inner loops (the branch it would have followed had they never
    happened).

    Parameters
    ----------
    model : polind.FrictionModel
    amplitude : float, optional
        The largest displacement [m]; default 0.8 of the model's presliding
        range (:class:`~polind.phenomena.FrictionLevels`).
    speed : float, optional
        [m/s], the same on every leg; default ``1e-3 vs`` (deep inside the
        presliding regime of the rate-state models).

    Returns
    -------
    PhenomenonResult
        metrics: ``closure_mismatch`` (per closure and the largest, each
        relative to its loop's force span), ``loops_close`` (per closure:
        its mismatch below
        :data:`~polind.phenomena.presliding.MEMORY_TOLERANCE`),
        ``branch_mismatch`` (relative to the major loop's span),
        ``major_loop_span`` [N].
        ``passed``: both below 1e-6 -- the non-local memory of the
        Maxwell-slip family.  LuGre has a single state and no such memory:
        its loops do not close.
    """
    levels = friction_levels(model)
    if amplitude is None:
        if levels.presliding_range <= 0.0:
            raise InputError(f"presliding_memory needs a model with a presliding range; a "
                             f"{model.type} model has none (give an 'amplitude' in m).")
        amplitude = 0.8 * levels.presliding_range
    amplitude = float(amplitude)
    speed = 1e-3 * velocity_scale(levels) if speed is None else float(speed)
    t, x, grid, corners = _polyline(MEMORY_PATH, amplitude, speed)
    force = simulate(model, t, x=x).force
    closures = []
    for close, reversal, other in MEMORY_CLOSURES:
        span = abs(force[corners[reversal]] - force[corners[other]])
        mismatch = abs(force[corners[close]] - force[corners[reversal]])
        closures.append(mismatch / span)
    major_span = abs(force[corners[1]] - force[corners[2]])
    branches = []
    reference_branches = []
    for first, last, vertices in MEMORY_BRANCHES:
        t_ref, x_ref, grid_ref, corners_ref = _polyline(vertices, amplitude, speed)
        f_ref = simulate(model, t_ref, x=x_ref).force
        leg = slice(corners_ref[-2], corners_ref[-1] + 1)
        lookup = dict(zip(grid_ref[leg].tolist(), f_ref[leg]))
        index = np.arange(corners[first], corners[last] + 1)
        expected = np.array([lookup[g] for g in grid[index].tolist()])
        branches.append(float(np.max(np.abs(force[index] - expected))) / major_span)
        reference_branches.append((x[index], expected))
    worst_closure = max(closures)
    worst_branch = max(branches)
    closed = [mismatch < MEMORY_TOLERANCE for mismatch in closures]
    passed = all(closed) and worst_branch < MEMORY_TOLERANCE
    metrics = {"closure_mismatch": worst_closure, "closure_mismatches": closures,
               "loops_close": closed, "branch_mismatch": worst_branch,
               "major_loop_span": major_span,
               "amplitude": amplitude}
    settings = {"amplitude": amplitude, "speed": speed,
                "path": [v * amplitude for v in MEMORY_PATH]}
    data = {"t": t, "x": x, "force": force, "corners": np.asarray(corners),
            "closures": MEMORY_CLOSURES, "reference_branches": reference_branches}
    if passed:
        note = (f"every inner loop closes on its reversal point (largest mismatch "
                f"{worst_closure:.1e} of the loop's span) and is wiped out")
    else:
        note = (f"the loops do not close: the force misses the reversal point by up to "
                f"{worst_closure:.1%} of the loop's span (no non-local memory)")
    return experiment_result("presliding_memory", levels, passed, metrics, settings, data, note)
