"""Experiment 3, frictional lag (:ref:`guide-phenomenon-lag`): sliding hysteresis.

:func:`frictional_lag` oscillates the sliding velocity,
``v(t) = v0 + va sin(2 pi f t)`` with ``v > 0``, at several frequencies and
measures the area of each force-velocity loop
(:func:`polind.phenomena.cycle_area`).  The phenomenon appears when every
loop circulates in the lag direction (the force higher while ``v`` rises)
and its area grows with the frequency.
"""

from __future__ import annotations

import math

import numpy as np

from polind.phenomena.common import (
    PhenomenonResult,
    cycle_area,
    experiment_result,
    friction_levels,
    velocity_scale,
)
from polind.resources import check_memory
from polind.simulation import BYTES_PER_SAMPLE, simulate

__all__ = ["frictional_lag"]


def _nice(value):
    """One significant digit (1, 2 or 5 times a power of ten): readable frequencies."""
    exponent = math.floor(math.log10(value))
    mantissa = value / 10.0 ** exponent
    return min((1.0, 2.0, 5.0, 10.0), key=lambda m: abs(math.log(mantissa / m))) * 10.0 ** exponent


#: The most coarse steps the frictional-lag experiment spends on its warm-up slide.
_WARM_UP_STEPS = 200_000


def frictional_lag(model, *, frequencies=None, mean_velocity=None, velocity_amplitude=None,
                   periods=2, steps_per_lag=50, plot_points=1500) -> PhenomenonResult:
    """Sliding hysteresis: ``v(t) = v0 + va sin(2 pi f t)`` with ``v > 0`` (:ref:`guide-phenomenon-lag`).

    Parameters
    ----------
    model : polind.FrictionModel
    frequencies : sequence of float, optional
        [Hz], sorted here; default four decades up to ``1 / (2 pi tau)``, ``tau`` the
        model's lag time at ``v0``
        (:meth:`FrictionLevels.lag_time <polind.phenomena.FrictionLevels.lag_time>`),
        rounded to 1, 2 or 5 times a power of ten; 1 Hz to 1 kHz for a model
        without lag.
    mean_velocity, velocity_amplitude : float, optional
        v0 and va [m/s]; default ``vs`` and ``0.9 vs``: the velocity sweeps
        the falling part of the Stribeck curve.
    periods : int
        Periods simulated (more if sliding 50 presliding ranges takes longer);
        the last one is the loop.
    steps_per_lag : int
        Time steps per lag time (the step's half length is a numerical lag
        of its own, kept at 1 % of the model's).

    Returns
    -------
    PhenomenonResult
        metrics: ``frequency``, ``loop_area`` (``closed integral F dv``,
        [N m/s], positive in the lag direction) and ``relative_area`` (over
        the box ``2 va Fs``) per frequency.  ``passed``: every loop in the
        lag direction with a relative area above 1e-6, and the area growing
        with the frequency.
    """
    levels = friction_levels(model)
    vs = velocity_scale(levels)
    v0 = vs if mean_velocity is None else float(mean_velocity)
    va = 0.9 * v0 if velocity_amplitude is None else float(velocity_amplitude)
    lag = levels.lag_time(v0)
    if frequencies is None:
        top = 1.0 / (2.0 * math.pi * lag) if lag else 1000.0
        frequencies = [_nice(top * 10.0 ** k) for k in range(-3, 1)]
    frequencies = sorted(float(f) for f in frequencies)
    areas, loops = [], []
    for frequency in frequencies:
        period = 1.0 / frequency
        step = min(period / 400.0, lag / steps_per_lag) if lag else period / 400.0
        per_period = int(math.ceil(period / step))
        # Before the loop, slide far enough to leave the presliding start behind:
        # at least 50 presliding ranges.  Periods beyond the simulated ones run at
        # up to _WARM_UP_STEPS coarse steps in all (the exact updates are stable
        # at any step, and the fine steps of the last periods resolve the lag
        # again within a few lag times), so that a model whose lag is tiny
        # against its presliding range (a lightly loaded Pol-Ind contact) does
        # not ask for billions of samples.
        warm_up = math.ceil(50.0 * levels.presliding_range / (v0 * period))
        coarse_periods = max(0, warm_up - (periods - 1))
        # Checked before t and v are made (16 bytes a sample here, simulate's own after).
        samples = periods * per_period + 1 + (min(coarse_periods * 400, _WARM_UP_STEPS)
                                              if coarse_periods else 0)
        check_memory(samples * (16 + BYTES_PER_SAMPLE),
                     f"The frictional-lag run at {frequency:.6g} Hz ({samples:.3g} samples)")
        fine = np.arange(periods * per_period + 1) * (period / per_period)
        if coarse_periods:
            coarse_steps = min(coarse_periods * 400, _WARM_UP_STEPS)
            coarse = np.linspace(0.0, coarse_periods * period, coarse_steps + 1)
            t = np.concatenate((coarse, coarse[-1] + fine[1:]))
        else:
            t = fine
        velocity = v0 + va * np.sin(2.0 * math.pi * frequency * t)
        res = simulate(model, t, v=velocity)
        last = slice(len(t) - per_period - 1, len(t))
        areas.append(cycle_area(res.v[last], res.force[last]))
        thin = max(1, per_period // plot_points)
        loops.append((res.v[last][::thin], res.force[last][::thin]))
    relative = [area / (2.0 * va * levels.static_force) for area in areas]
    growing = all(b > a for a, b in zip(areas[:-1], areas[1:]))
    passed = min(relative) > 1e-6 and growing
    metrics = {"frequency": frequencies, "loop_area": areas, "relative_area": relative,
               "area_grows_with_frequency": growing}
    settings = {"mean_velocity": v0, "velocity_amplitude": va, "lag_time": lag,
                "frequencies": frequencies, "periods": periods}
    curve_velocity = np.linspace(v0 - va, v0 + va, 200)
    data = {"loops": loops, "curve_velocity": curve_velocity,
            "curve_force": levels.steady_force(curve_velocity)}
    if passed:
        note = (f"the force is higher while the velocity rises; the loop area grows from "
                f"{relative[0]:.1e} to {relative[-1]:.1e} of the box as f rises from "
                f"{frequencies[0]:g} to {frequencies[-1]:g} Hz")
    else:
        largest = max(relative, key=abs)
        note = ("no lag loop: the force is the same while the velocity rises and falls"
                if largest == 0.0 else f"no lag loop: largest relative area {largest:.1e}")
    return experiment_result("frictional_lag", levels, passed, metrics, settings, data, note)
