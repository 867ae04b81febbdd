"""The metrics of a sweep: the numbers kept from each run, one column each.

A metric is a function of a run's output (:class:`RunOutput`: its time,
position, velocity, friction force and driving force, its system and model)
that returns one float, NaN where it is not defined.  :data:`METRICS` holds
them by name, :func:`register_metric` adds one, and :data:`NEEDS` says what a
metric needs beyond a run's force (a body, a drive spring, a periodic force),
which :class:`polind.sweeps.Sweep` checks when it is built.  The metrics
measure the phenomena (:ref:`guide-phenomena`) on the one-degree-of-freedom
systems (:ref:`guide-systems`); the file formats page lists them
(:ref:`formats-sweep`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from polind.dynamics import System
from polind.errors import InputError, describe
from polind.models import FrictionModel
from polind.phenomena import cycle_area, velocity_scale, friction_levels

__all__ = ["METRICS", "NEEDS", "Metric", "RunOutput", "register_metric"]

@dataclass(frozen=True)
class RunOutput:
    """What one run produced, as a metric sees it.

    Attributes
    ----------
    t, x, v, force : ndarray
        Time [s], position [m], velocity [m/s] and friction force [N].
    applied : ndarray or None
        The force driving the body [N] (the drive spring's plus the applied
        force), or None for a prescribed motion.
    system : System or None
        The run's one-degree-of-freedom system (None for a prescribed motion).
    model : FrictionModel
        The run's model.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    applied: np.ndarray | None
    system: System | None
    model: FrictionModel

    @property
    def second_half(self) -> np.ndarray:
        """The samples of the run's second half (``t >= t0 + (t_end - t0) / 2``), a mask."""
        return self.t >= self.t[0] + 0.5 * (self.t[-1] - self.t[0])


#: What a metric needs beyond a run's force, and how an error message says it.
NEEDS = {
    "any": "",
    "body": "a [system] (a body; not a prescribed motion)",
    "spring": "a [system.spring_drive] table",
    "periodic force": "a [system.force] table",
}


@dataclass(frozen=True)
class Metric:
    """One number computed from a run (a column of the results).

    ``compute(run)`` takes a :class:`RunOutput` and returns a float (NaN
    where the metric is not defined for that run, e.g. no stick-slip);
    ``needs`` is a key of :data:`NEEDS`, checked when a sweep is loaded.
    """

    name: str
    unit: str
    needs: str
    definition: str
    compute: Callable[[RunOutput], float] = field(compare=False)


#: The metrics a sweep can keep, by name (their ``definition``; the documentation's file
#: formats page lists them).
METRICS: dict[str, Metric] = {}


def register_metric(name: str, *, unit: str = None, definition: str = None,
                    needs: str = "any"):
    """Add a metric to :data:`METRICS` (a decorator for ``compute(run) -> float``).

    A metric defined in a script reaches Dask workers with the sweep (by
    value, as cloudpickle sends functions of ``__main__``).

    Parameters
    ----------
    name : str
        The metric's name, its column in the results table (no comma or newline).
    unit : str
        Its unit (``""`` for a number without one).
    definition : str
        What it is, in words (the documentation's file formats page lists it).
    needs : str, default "any"
        A key of :data:`NEEDS`.

    Raises
    ------
    InputError
        A name, unit or definition that is not text, a ``needs`` that is not
        a key of :data:`NEEDS`, a ``compute`` that is not callable.

    Examples
    --------
    >>> @register_metric("final_position", unit="m", needs="body",
    ...                  definition="x at the last sample")
    ... def final_position(run):
    ...     return float(run.x[-1])
    >>> METRICS["final_position"].unit
    'm'
    >>> del METRICS["final_position"]
    """
    if not isinstance(name, str) or not name or any(c in name for c in ",\n\r"):
        raise InputError(f"The 'name' of register_metric must be a non-empty string without "
                         f"commas or newlines (a column of the results). Got {describe(name)} "
                         f"instead.")
    for key, value in (("unit", unit), ("definition", definition)):
        if not isinstance(value, str) or (key == "definition" and not value.strip()):
            raise InputError(f"The '{key}' of metric '{name}' must be a string"
                             f"{' saying what it is' if key == 'definition' else ''}. Got "
                             f"{describe(value)} instead.")
    if not isinstance(needs, str) or needs not in NEEDS:
        raise InputError(f"The 'needs' of metric '{name}' must be one of: {', '.join(NEEDS)}. "
                         f"Got {describe(needs)} instead.")

    def add(compute):
        if not callable(compute):
            raise InputError(f"register_metric('{name}') decorates a function compute(run) -> "
                             f"float. Got {describe(compute)} instead.")
        METRICS[name] = Metric(name, unit, needs, definition, compute)
        return compute

    return add


@register_metric("mean_force", unit="N", definition="the mean of the friction force over the "
                                                    "run's samples")
def _mean_force(run):
    return float(np.mean(run.force))


@register_metric("max_force", unit="N", definition="the largest friction force over the run's "
                                                   "samples")
def _max_force(run):
    return float(np.max(run.force))


@register_metric("rms_force", unit="N", definition="the root mean square of the friction force "
                                                   "over the run's samples")
def _rms_force(run):
    return float(np.sqrt(np.mean(run.force * run.force)))


@register_metric("stick_slip_amplitude", unit="N", needs="spring",
                 definition="half the peak-to-peak of the force driving the body (the drive "
                            "spring's) over the second half of the run")
def _stick_slip_amplitude(run):
    return 0.5 * float(np.ptp(run.applied[run.second_half]))


def _slip_times(run) -> np.ndarray:
    """The times at which the body slips in the second half of the run.

    A slip is counted when the drive force falls below the lower quarter of
    its range (over the second half) after having been in its upper quarter:
    the sawtooth of stick-slip gives one per cycle, while the ringing of a
    body that has just stuck (on its contact's presliding stiffness, which
    may cross zero velocity many times a millisecond) gives none.
    """
    late = run.second_half
    t, force = run.t[late], run.applied[late]
    low, high = float(np.min(force)), float(np.max(force))
    if not high > low:
        return t[:0]
    quarter = 0.25 * (high - low)
    level = np.where(force > high - quarter, 1, np.where(force < low + quarter, -1, 0))
    last = np.maximum.accumulate(np.where(level != 0, np.arange(level.size), 0))
    held = level[last]
    return t[np.flatnonzero((held[1:] == -1) & (held[:-1] == 1)) + 1]


@register_metric("stick_slip_period", unit="s", needs="spring",
                 definition="the mean interval between successive slips in the second half "
                            "of the run, a slip being the drive force falling below the lower "
                            "quarter of its range after having been in its upper quarter; NaN "
                            "with fewer than two slips or when the body is never stuck there "
                            "(steady sliding)")
def _stick_slip_period(run):
    if not _stuck_fraction(run) > 0.0:
        return math.nan
    slips = _slip_times(run)
    return float(np.mean(np.diff(slips))) if slips.size >= 2 else math.nan


@register_metric("stuck_fraction", unit="1", needs="spring",
                 definition="the fraction of the samples of the second half of the run at "
                            "which the body is stuck (its speed in the drive's direction below "
                            "0.1 v_d); NaN without a drive velocity")
def _stuck_fraction(run):
    drive = run.system.drive_velocity
    if drive == 0.0:
        return math.nan
    late = run.second_half
    return float(np.mean(math.copysign(1.0, drive) * run.v[late] < 0.1 * abs(drive)))


@register_metric("advance_per_cycle", unit="m", needs="periodic force",
                 definition="the change of the body's cycle-mean position from the next-to-last "
                            "to the last complete cycle of the applied force (cycle k: "
                            "k/f <= t < (k+1)/f); NaN without two complete cycles")
def _advance_per_cycle(run):
    frequency = run.system.frequency
    if frequency <= 0.0:
        return math.nan
    cycle = np.floor(run.t * frequency * (1.0 + 1e-12)).astype(np.int64)
    complete = int(math.floor(float(run.t[-1]) * frequency * (1.0 + 1e-12)))
    if complete < 2:
        return math.nan
    inside = cycle < complete
    means = (np.bincount(cycle[inside], weights=run.x[inside], minlength=complete)
             / np.bincount(cycle[inside], minlength=complete))
    return float(means[-1] - means[-2])


@register_metric("breakaway_force", unit="N", needs="body",
                 definition="the force driving the body at the first sample where its speed "
                            "exceeds the model's Stribeck velocity (1 mm/s for a model without "
                            "one); NaN if it never does")
def _breakaway_force(run):
    threshold = velocity_scale(friction_levels(run.model))
    moving = np.flatnonzero(np.abs(run.v) > threshold)
    return float(run.applied[moving[0]]) if moving.size else math.nan


@register_metric("loop_area", unit="N m/s",
                 definition="the signed area closed integral F dv of the last velocity cycle "
                            "of the second half (between the last two upward crossings of the "
                            "middle of its velocity range), positive when the force is higher "
                            "while the velocity rises (frictional lag); NaN without a cycle")
def _loop_area_metric(run):
    late = run.second_half
    v, force = run.v[late], run.force[late]
    low, high = float(np.min(v)), float(np.max(v))
    if not high > low:
        return math.nan
    middle = 0.5 * (low + high)
    up = np.flatnonzero((v[:-1] < middle) & (v[1:] >= middle)) + 1
    if up.size < 2:
        return math.nan
    start, stop = int(up[-2]), int(up[-1])
    return cycle_area(v[start:stop + 1], force[start:stop + 1])

