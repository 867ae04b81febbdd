"""Experiment 4, non-drifting (:ref:`guide-phenomena`): a body pushed below break-away.

:func:`non_drifting` drives a body (:ref:`guide-systems`) by the force
``0.5 Fc + 0.4 Fc sin(2 pi t)``, always below break-away, and measures its
advance per cycle.  The phenomenon appears when the advance dies away (the
Maxwell-slip family shakes down); LuGre drifts by the same step every
cycle (Dupont et al. 2002).
"""

from __future__ import annotations

import numpy as np

from polind.phenomena.common import (
    PhenomenonResult,
    body_mass,
    experiment_result,
    friction_levels,
    presliding_period,
    run_system,
    thin,
)

__all__ = ["non_drifting"]


def non_drifting(model, *, cycles=10, mass=None, time_step=None) -> PhenomenonResult:
    """A force-driven body below break-away: ``F_a = 0.5 Fc + 0.4 Fc sin(2 pi t)`` (7.7, 4).

    The body starts at rest; its advance per cycle is the change of its
    cycle-mean position from one cycle to the next.  The Maxwell-slip family
    shakes down onto a periodic orbit (the advance dies away); LuGre advances
    by the same amount every cycle (about 6.6 µm with the 1995 parameters and
    ``m = 1 kg``; Dupont et al. 2002).

    Parameters
    ----------
    model : polind.FrictionModel
    cycles : int
        Number of 1 s forcing cycles.
    mass : float, optional
        [kg]; default ``Fc / (1 N) kg`` (the LuGre reference body scaled to
        the model's force level).
    time_step : float, optional
        [s]; default a tenth of the body's presliding period, at most 1 ms.

    Returns
    -------
    PhenomenonResult
        metrics: ``advance_per_cycle`` [m] (cycles-1 values), ``first_advance``,
        ``last_advance``, ``decay`` (last / first), ``drifts`` (the last three
        advances positive and within 1 % of each other: a steady drift) and
        ``steady_advance`` [m] (the last advance).  ``passed`` (non-drifting
        appears): the last advance is below 1e-3 of the first, or below 1e-6
        of the presliding range.
    """
    levels = friction_levels(model)
    fc = levels.coulomb_force
    mass = body_mass(levels) if mass is None else float(mass)
    if time_step is None:
        period = presliding_period(levels, mass)
        time_step = min(1e-3, period / 10.0) if period else 1e-3
    res = run_system(model, mass=mass, duration=float(cycles), time_step=time_step,
                     offset=0.5 * fc, amplitude=0.4 * fc, frequency=1.0)
    cycle = np.minimum(np.floor(res.t * (1.0 + 1e-12)).astype(np.int64), cycles - 1)
    counts = np.bincount(cycle, minlength=cycles)
    means = np.bincount(cycle, weights=res.x, minlength=cycles) / counts
    advance = np.diff(means)
    first, last = float(advance[0]), float(advance[-1])
    tail = advance[-3:]
    drifts = bool(np.all(tail > 0.0) and np.ptp(tail) <= 0.01 * float(np.mean(tail)))
    passed = abs(last) <= max(1e-3 * abs(first), 1e-6 * levels.presliding_range)
    metrics = {"advance_per_cycle": advance, "first_advance": first, "last_advance": last,
               "decay": abs(last / first) if first else None, "drifts": drifts,
               "steady_advance": last, "cycle_mean_position": means}
    settings = {"mass": mass, "time_step": time_step, "cycles": cycles,
                "applied_force": f"{0.5 * fc:g} + {0.4 * fc:g} sin(2 pi t) N"}
    data = {"t": thin(res.t), "x": thin(res.x), "applied": thin(res.applied),
            "cycle_mean_position": means, "advance": advance}
    if passed and first == 0.0:
        note = "the body does not move: its static friction holds it"
    elif passed:
        note = (f"the body shakes down: its advance per cycle falls from {first:.3g} m to "
                f"{last:.1e} m")
    elif drifts:
        note = f"the body drifts by {last * 1e6:.3g} µm every cycle, for ever"
    else:
        note = f"the advance per cycle does not die away (last {last:.3g} m)"
    return experiment_result("non_drifting", levels, passed, metrics, settings, data, note)
