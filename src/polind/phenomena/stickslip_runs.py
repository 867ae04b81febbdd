"""Experiment 5, stick-slip (:ref:`guide-phenomenon-stick-slip`): a spring-driven body.

:func:`stick_slip` pulls a body (:ref:`guide-systems`) through a spring at
a constant drive velocity, in three runs: the reference set-up of Canudas
de Wit et al. (1995) from rest, scaled to the model's force level, and two
runs started in steady sliding, at a low drive velocity (on the falling
branch of the Stribeck curve) and a high one.  The phenomenon appears when
the body sticks and slips periodically at the low velocity and slides
steadily at the high one.
"""

from __future__ import annotations

import numpy as np

from polind.phenomena.common import (
    PhenomenonResult,
    body_mass,
    experiment_result,
    friction_levels,
    run_system,
    thin,
    velocity_scale,
)

__all__ = ["stick_slip"]


def _stick_episodes(t, v, drive_velocity):
    """Start times of the stick episodes: ``v`` falls below ``0.1 v_d`` and stays low
    until it rises above ``0.5 v_d`` (so the ringing of a stopping body, which
    bounces a little above ``0.1 v_d``, does not count twice)."""
    enter = v < 0.1 * drive_velocity
    event = np.where(enter, 1, np.where(v > 0.5 * drive_velocity, -1, 0))
    last_event = np.maximum.accumulate(np.where(event != 0, np.arange(v.shape[0]), 0))
    stuck = event[last_event] == 1
    return t[1:][stuck[1:] & ~stuck[:-1]]


_KICK = 1e-3


def _stick_slip_run(model, levels, *, mass, stiffness, drive_velocity, duration, time_step,
                    from_rest):
    """One spring-driven run, classified over its second half (see :func:`stick_slip`)."""
    start = {}
    if not from_rest:
        # Steady sliding (moving with the drive, the spring balancing the steady friction),
        # kicked by 0.1 % of the drive velocity: the run then tests the stability of
        # sliding, not the rounding of its start.
        start = {"initial_velocity": (1.0 + _KICK) * drive_velocity,
                 "initial_position": -float(levels.steady_force(drive_velocity)) / stiffness}
    res = run_system(model, mass=mass, duration=duration, time_step=time_step,
                     spring_stiffness=stiffness, drive_velocity=drive_velocity, **start)
    late = res.t >= 0.5 * duration
    v = res.v[late]
    starts = _stick_episodes(res.t[late], v, drive_velocity)
    stuck_fraction = float(np.mean(v < 0.1 * drive_velocity))
    spring = res.applied[late]
    amplitude = 0.5 * float(np.ptp(spring))
    intervals = np.diff(starts)
    period = float(np.mean(intervals)) if intervals.size else None
    periodic = intervals.size >= 2 and float(np.ptp(intervals)) <= 0.1 * period
    sticks = bool(periodic and stuck_fraction >= 0.2
                  and amplitude > 0.01 * levels.coulomb_force)
    steady = bool(stuck_fraction == 0.0 and amplitude < 0.05 * levels.coulomb_force)
    metrics = {"drive_velocity": drive_velocity, "spring_stiffness": stiffness, "mass": mass,
               "from_rest": from_rest, "duration": float(res.t[-1] - res.t[0]),
               "time_step": float(res.t[1] - res.t[0]), "stick_episodes": int(starts.size),
               "period": period, "stuck_fraction": stuck_fraction,
               "spring_force_amplitude": amplitude,
               "spring_force_range": [float(spring.min()), float(spring.max())],
               "sticks_and_slips": sticks, "slides_steadily": steady}
    data = {"t": thin(res.t), "spring_force": thin(res.applied), "friction": thin(res.force),
            "v": thin(res.v)}
    return metrics, data


def stick_slip(model, *, low_velocity=None, high_velocity=None) -> PhenomenonResult:
    """Spring-driven body at a low and a high drive velocity (:ref:`guide-phenomenon-stick-slip`).

    Three runs, all with the body mass ``m = Fc / (1 N) kg``:

    * ``reference``: the set-up of Canudas de Wit et al. (1995) scaled to the
      model's force level: from rest, ``k_d = 2 N/m`` per newton of Fc,
      ``v_d = 100 vs`` (for LuGre with the 1995 parameters exactly
      ``m = 1 kg, k_d = 2 N/m, v_d = 0.1 m/s``), 50 s.
    * ``low`` and ``high``: does steady sliding last?  The body starts in
      steady sliding (moving with the drive, the spring balancing the steady
      friction), kicked by 0.1 % of the drive velocity, with a stiffer spring ``k_d = 1000 N/m`` per newton of Fc
      (a stick-slip cycle of about a second at the low velocity), for 10 s,
      at ``v_d = vs`` (on the falling branch of the Stribeck curve, where
      sliding is unstable) and at ``v_d = 100 vs`` (beyond it).  Started from
      rest instead, a body without viscous damping (the default Pol-Ind has
      ``sigma2 = 0``) never loses its start-up oscillation at any drive
      velocity, so rest would not tell the two velocities apart.

    Each run is judged over its second half.  The body is *stuck* while
    ``v < 0.1 v_d`` (a stopping body may spring back a little: LuGre's
    bristles do).  It *sticks and slips* when stick episodes recur at least
    three times with intervals within 10 % of their mean, it is stuck at
    least a fifth of the time, and the spring force swings by more than 1 %
    of Fc; it *slides steadily* when it is never stuck and the spring force
    swings by less than 5 % of Fc.  (An undamped body with ``Fs = Fc``, such
    as Maxwell-slip started from rest, oscillates with a velocity that only
    touches zero once a cycle: neither.)

    Returns
    -------
    PhenomenonResult
        metrics: per run (``reference``, ``low``, ``high``) the
        ``drive_velocity`` [m/s], ``spring_stiffness`` [N/m], ``mass`` [kg],
        ``duration`` and ``time_step`` [s] of the run, ``period`` [s],
        ``spring_force_amplitude`` [N], ``stick_episodes``,
        ``sticks_and_slips``, ``slides_steadily``.  settings: ``mass`` and
        per run its ``stiffness``, ``drive_velocity``, ``duration``,
        ``time_step`` and ``from_rest`` (``reference_duration``, ...).
        ``passed``: the low run sticks and slips and the high run slides steadily.
    """
    levels = friction_levels(model)
    fc = levels.coulomb_force
    vs = velocity_scale(levels)
    mass = body_mass(levels)
    low_velocity = vs if low_velocity is None else float(low_velocity)
    high_velocity = 100.0 * vs if high_velocity is None else float(high_velocity)
    runs = {
        "reference": dict(stiffness=2.0 * fc, drive_velocity=100.0 * vs, duration=50.0,
                          time_step=1e-3, from_rest=True),
        "low": dict(stiffness=1000.0 * fc, drive_velocity=low_velocity, duration=10.0,
                    time_step=1e-4, from_rest=False),
        "high": dict(stiffness=1000.0 * fc, drive_velocity=high_velocity, duration=10.0,
                     time_step=1e-4, from_rest=False),
    }
    metrics, data = {}, {}
    for name, run in runs.items():
        metrics[name], data[name] = _stick_slip_run(model, levels, mass=mass, **run)
    passed = metrics["low"]["sticks_and_slips"] and metrics["high"]["slides_steadily"]
    settings = {"mass": mass, **{f"{name}_{key}": value for name, run in runs.items()
                                 for key, value in run.items()}}
    low, high = metrics["low"], metrics["high"]
    if passed:
        note = (f"at v_d = {low_velocity:g} m/s the body sticks and slips every "
                f"{low['period']:.3g} s (spring force swinging by {low['spring_force_amplitude']:.3g}"
                f" N); at {high_velocity:g} m/s it slides steadily")
    else:
        note = (f"no stick-slip at the low drive velocity" if not low["sticks_and_slips"] else
                f"the high-velocity run does not slide steadily "
                f"(spring force swinging by {high['spring_force_amplitude']:.3g} N)")
    return experiment_result("stick_slip", levels, passed, metrics, settings, data, note)
