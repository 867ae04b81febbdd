"""Experiment 6, break-away (:ref:`guide-phenomena`): the force at break-away versus the force rate.

:func:`breakaway` pushes a body at rest (:ref:`guide-systems`) by a force
ramp ``F_a = rate t`` at several rates and records the applied force when
the body breaks away.  The phenomenon appears when the slowest,
quasi-static ramp breaks it away within 2 % of the static level Fs.
"""

from __future__ import annotations

import math

import numpy as np

from polind.phenomena.common import (
    PhenomenonResult,
    body_mass,
    experiment_result,
    friction_levels,
    presliding_period,
    run_system,
    thin,
    velocity_scale,
)

__all__ = ["breakaway"]


def breakaway(model, *, ramp_times=None, threshold_velocity=None, steps=15000) -> PhenomenonResult:
    """Break-away force versus the rate of the applied force ramp ``F_a = rate t`` (7.7, 6).

    The body (mass ``Fc / (1 N) kg``) starts at rest; the ramp reaches Fs in
    ``ramp_time``.  The body has *broken away* when its velocity first
    exceeds ``threshold_velocity`` (default ``vs``: by then the friction has
    fallen from Fs by ``(1 - 1/e)`` of the way to Fc; 1 mm/s for a model
    without a Stribeck curve); the break-away force is the applied force at
    that sample.

    Parameters
    ----------
    model : polind.FrictionModel
    ramp_times : sequence of float, optional
        [s] to reach Fs; default: the slowest is quasi-static (at least 1e4
        presliding periods ``2 pi sqrt(m / K)``, K the presliding stiffness,
        and slow enough that the body's own acceleration to the threshold
        velocity adds less than 0.2 % of Fs), then 10, 100 and 1000 times
        faster, to where inertia shows.
    threshold_velocity : float, optional
        [m/s].
    steps : int
        Time steps per run (each runs to 1.5 Fs).

    Returns
    -------
    PhenomenonResult
        metrics: ``rate`` [N/s], ``breakaway_force`` [N], ``breakaway_ratio``
        (over Fs) and ``breakaway_displacement`` [m] per rate, and
        ``rate_effect`` (ratio at the fastest minus at the slowest rate).
        ``passed``: at the slowest rate the break-away force is within 2 % of Fs.
    """
    levels = friction_levels(model)
    fs = levels.static_force
    mass = body_mass(levels)
    period = presliding_period(levels, mass)
    threshold = velocity_scale(levels) if threshold_velocity is None else float(threshold_velocity)
    if ramp_times is None:
        # The slowest ramp must be quasi-static for the body too: after break-away
        # it needs about sqrt(2 m v_threshold / rate) to reach the threshold, while
        # the ramp adds sqrt(2 m v_threshold rate) to the applied force; keep that
        # below 0.2 % of Fs.  And at least 1e4 presliding periods.
        quasi_static = fs / ((0.002 * fs) ** 2 / (2.0 * mass * threshold))
        slowest = max(1e4 * period if period else 10.0, quasi_static)
        ramp_times = [slowest, slowest / 10.0, slowest / 100.0, slowest / 1000.0]
    ramp_times = sorted((float(r) for r in ramp_times), reverse=True)
    rates, forces, displacements, runs = [], [], [], []
    for ramp in ramp_times:
        rate = fs / ramp
        duration = 1.5 * ramp
        res = run_system(model, mass=mass, duration=duration, time_step=duration / steps,
                         rate=rate)
        moving = np.flatnonzero(res.v > threshold)
        k = int(moving[0]) if moving.size else None
        rates.append(rate)
        forces.append(float(res.applied[k]) if k is not None else math.nan)
        displacements.append(float(res.x[k]) if k is not None else math.nan)
        runs.append({"applied": thin(res.applied), "x": thin(res.x), "v": thin(res.v)})
    ratio = [force / fs for force in forces]
    passed = math.isfinite(ratio[0]) and abs(ratio[0] - 1.0) < 0.02
    metrics = {"rate": rates, "breakaway_force": forces, "breakaway_ratio": ratio,
               "breakaway_displacement": displacements, "static_force": fs,
               "rate_effect": ratio[-1] - ratio[0]}
    settings = {"mass": mass, "ramp_times": ramp_times, "threshold_velocity": threshold,
                "steps": steps}
    data = {"runs": runs, "rate": np.asarray(rates), "ratio": np.asarray(ratio)}
    if passed:
        trend = "rises" if ratio[-1] > ratio[0] else "falls"
        note = (f"a slow ramp breaks the body away at {ratio[0]:.4f} Fs; the break-away force "
                f"{trend} to {ratio[-1]:.3f} Fs at {rates[-1]:.3g} N/s")
    else:
        note = f"a slow ramp breaks the body away at {ratio[0]:.4f} Fs, not at Fs"
    return experiment_result("breakaway", levels, passed, metrics, settings, data, note)
