"""Experiment 1, the Stribeck effect (:ref:`guide-phenomenon-stribeck`): steady sliding.

:func:`stribeck_effect` slides the model at constant velocities from
``1e-3 vs`` to ``1e3 vs`` until its force is steady and compares the forces
with the analytic steady curve ``g(v) + sigma2 v``
(:meth:`polind.phenomena.FrictionLevels.steady_force`).  The phenomenon
appears when the curve dips by more than 1 % below its low-velocity level
and the simulated forces follow it within 1e-6.
"""

from __future__ import annotations

import numpy as np

from polind.phenomena.common import (
    PhenomenonResult,
    experiment_result,
    friction_levels,
    velocity_scale,
)
from polind.simulation import simulate

__all__ = ["stribeck_effect"]


def _steady_force(model, levels, velocity, settle=50.0, samples=240):
    """The force after sliding at a constant velocity until every transient has died.

    The run covers ``settle`` presliding ranges and ``settle`` lag times.
    Every model integrates a constant-velocity step exactly (Leuven with an
    unconditionally stable implicit step), so a geometric time grid is
    enough: fine steps resolve the start, long steps reach the end.
    """
    lag = levels.lag_time(velocity) or 0.0
    duration = settle * max(levels.presliding_range / abs(velocity), lag, 1e-9)
    t = np.concatenate(([0.0], np.geomspace(duration * 1e-6, duration, samples - 1)))
    res = simulate(model, t, v=np.full(t.shape, velocity))
    return float(res.force[-1])


def stribeck_effect(model, *, decades=3.0, points=49) -> PhenomenonResult:
    """Steady sliding force over ``v`` from ``1e-3 vs`` to ``1e3 vs`` (:ref:`guide-phenomenon-stribeck`).

    The model slides at each constant velocity (log-spaced) until the force
    is steady; the result is compared with the analytic steady curve
    ``g(v) + sigma2 v`` (for Maxwell-slip the constant ``sum W_i``).

    Parameters
    ----------
    model : polind.FrictionModel
    decades : float
        The velocities span ``vs 10**-decades`` to ``vs 10**decades``.
    points : int
        Number of velocities.

    Returns
    -------
    PhenomenonResult
        metrics: ``force_at_lowest_velocity``, ``minimum_force``,
        ``velocity_at_minimum``, ``force_at_highest_velocity``, ``dip``
        (``(F(v_min) - min F) / F(v_min)``), ``max_relative_deviation`` from
        the analytic curve, and the sampled ``velocity`` and ``force``.
        ``passed``: dip > 1 % and deviation < 1e-6.

    Examples
    --------
    >>> import polind
    >>> lugre = polind.model_from_dict({"model": {"type": "lugre", "bristle_stiffness": 1e5,
    ...     "bristle_damping": 316.0, "viscous_coefficient": 0.4, "coulomb_force": 1.0,
    ...     "static_force": 1.5, "stribeck_velocity": 1e-3}})
    >>> result = stribeck_effect(lugre, points=13)
    >>> result.passed, round(result.metrics["force_at_lowest_velocity"], 4)
    (True, 1.5)
    """
    levels = friction_levels(model)
    vs = velocity_scale(levels)
    velocity = vs * np.logspace(-decades, decades, points)
    force = np.array([_steady_force(model, levels, v) for v in velocity])
    curve_velocity = vs * np.logspace(-decades, decades, 400)
    reference = levels.steady_force(velocity)
    deviation = float(np.max(np.abs(force - reference) / np.abs(reference)))
    lowest = float(force[0])
    k_min = int(np.argmin(force))
    dip = (lowest - float(force[k_min])) / lowest
    passed = dip > 0.01 and deviation < 1e-6
    metrics = {
        "force_at_lowest_velocity": lowest,
        "minimum_force": float(force[k_min]),
        "velocity_at_minimum": float(velocity[k_min]),
        "force_at_highest_velocity": float(force[-1]),
        "dip": dip,
        "max_relative_deviation": deviation,
        "velocity": velocity,
        "force": force,
    }
    settings = {"stribeck_velocity": vs, "lowest_velocity": float(velocity[0]),
                "highest_velocity": float(velocity[-1]), "points": points}
    data = {"velocity": velocity, "force": force, "curve_velocity": curve_velocity,
            "curve_force": levels.steady_force(curve_velocity)}
    if passed:
        note = (f"the steady force falls from {lowest:.4g} N at low velocity to "
                f"{metrics['minimum_force']:.4g} N and follows the Stribeck curve "
                f"(largest deviation {deviation:.1e})")
    elif dip <= 0.01:
        note = f"no dip: the steady force never falls below {lowest:.4g} N"
    else:
        note = f"the steady force misses the analytic curve by up to {deviation:.1e}"
    return experiment_result("stribeck", levels, passed, metrics, settings, data, note)
