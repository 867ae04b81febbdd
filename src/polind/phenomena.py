"""The six friction phenomena (:ref:`guide-phenomena`): the experiments, their metrics and their checks.

Each experiment runs one friction model through a prescribed motion
(:func:`polind.simulate`) or a one-degree-of-freedom system (:ref:`guide-systems`)
(:func:`polind.dynamics.simulate_system`) and returns a
:class:`PhenomenonResult`: the arrays its figure shows (``data``), the
numbers that measure the phenomenon (``metrics``), the inputs used
(``settings``) and ``passed`` -- whether the phenomenon *appears* in this
run, decided by a check that can fail.  ``expected`` says whether the user
guide credits the model with the phenomenon (:ref:`guide-choosing-table`); a model behaves as documented when
the two agree (:attr:`PhenomenonResult.as_expected`).  So LuGre's
non-drifting result has ``passed = False`` (it drifts: Dupont et al. 2002)
and ``expected = False``; Maxwell-slip, being rate independent, shows no
Stribeck effect and no frictional lag.

Every length, time and force of an experiment is scaled by the model's own
levels (:func:`friction_levels`): its static and Coulomb forces, Stribeck
velocity, presliding range and lag time.  The same experiment then fits the
1 N LuGre model of 1995 and a 15 N Pol-Ind contact whose presliding range is
a few tens of nanometres.

When ``passed`` is true (the phenomenon appears):

* :func:`stribeck_effect`: the steady force at ``1e-3 vs`` exceeds the
  curve's minimum by more than 1 % (the dip) and every steady force matches
  the analytic curve within 1e-6;
* :func:`presliding_memory`: every inner loop closes on its starting
  reversal point and the path then follows the branch it would have
  followed without the loop, within 1e-6 of the loop's force span
  (wipe-out: non-local memory);
* :func:`frictional_lag`: every loop circulates in the lag direction (the
  force is higher while v rises), with an area above 1e-6 of the box
  ``2 va Fs``, and the area grows with the frequency;
* :func:`non_drifting`: the advance per cycle of the force-driven body dies
  away: the last cycle's is below 1e-3 of the first's (or below 1e-6 of the
  presliding range);
* :func:`stick_slip`: at the low drive velocity the body sticks and slips
  periodically, at the high one it slides steadily;
* :func:`breakaway`: at the slowest force ramp the break-away force is
  within 2 % of the static level Fs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError
from polind.io import plain_data
from polind.models.static import stribeck_curve
from polind.resources import check_memory
from polind.simulate import BYTES_PER_SAMPLE, simulate

__all__ = [
    "PHENOMENA",
    "FrictionLevels",
    "PhenomenonResult",
    "friction_levels",
    "stribeck_effect",
    "presliding_memory",
    "frictional_lag",
    "non_drifting",
    "stick_slip",
    "breakaway",
]

#: The keys of ``metrics.json`` (:ref:`formats-results`), in the order of :ref:`guide-phenomena`.
PHENOMENA = ("stribeck", "presliding_memory", "frictional_lag", "non_drifting", "stick_slip",
             "breakaway")



# --- the model's own scales ---------------------------------------------------------------

@dataclass(frozen=True)
class FrictionLevels:
    """The scales of a friction model that the experiments are sized by.

    Attributes
    ----------
    model_type : str
    static_force : float
        Fs [N]: the break-away level (``mu_s N`` for Pol-Ind, ``sum W_i`` for
        Maxwell-slip).
    coulomb_force : float
        Fc [N]: the sliding level far above the Stribeck velocity (``mu_k N``
        for Pol-Ind; ``sum W_i`` for Maxwell-slip, which is rate independent).
    stribeck_velocity : float or None
        vs [m/s]; None for models without a Stribeck curve.
    stribeck_exponent : float
    stribeck_shape : str
    viscous_coefficient : float
        sigma2 [N s/m].
    presliding_range : float
        [m]: the displacement over which the presliding force builds up: the
        largest element slip distance ``W_i / k_i`` (``alpha_i Fs / k_i`` for
        GMS) for the Maxwell-slip family, ``Fs / sigma0`` for LuGre,
        ``Fc / sigma0`` for Dahl, 0 for the memoryless models.
    presliding_stiffness : float
        [N/m]: the initial slope of the presliding curve (``sum k_i``, or
        sigma0); 0 for the memoryless models.
    bristle_stiffness : float or None
        sigma0 [N/m] of LuGre (its lag time is ``g(v) / (sigma0 |v|)``).
    relaxation_rate : float or None
        ``C / max(alpha_i)`` [N/s] of the rate-state element models (GMS,
        Pol-Ind): the slowest element relaxes in ``g(v) / relaxation_rate``.
    relaxation_length : float or None
        [m] of the Leuven model: its state follows a velocity change within
        about a presliding range of sliding, in ``relaxation_length / |v|``.
    credited : frozenset of str
        The phenomena the model class is credited with beyond what its scales
        imply (:attr:`polind.FrictionModel.phenomena`).

    Each model supplies these through its ``characteristic_scales``; nothing
    here knows which model it is.
    """

    model_type: str
    static_force: float
    coulomb_force: float
    stribeck_velocity: float | None
    stribeck_exponent: float
    stribeck_shape: str
    viscous_coefficient: float
    presliding_range: float
    presliding_stiffness: float
    bristle_stiffness: float | None = None
    relaxation_rate: float | None = None
    relaxation_length: float | None = None
    credited: frozenset = frozenset()

    def stribeck(self, v):
        """g(v) [N], the steady-sliding magnitude without the viscous term."""
        v = np.asarray(v, dtype=np.float64)
        if self.stribeck_velocity is None:
            return np.full(v.shape, self.coulomb_force)
        return stribeck_curve(v, self.coulomb_force, self.static_force, self.stribeck_velocity,
                              self.stribeck_exponent, self.stribeck_shape)

    def steady_force(self, v):
        """The analytic steady-sliding force ``g(v) sgn(v) + sigma2 v`` [N] at velocities v."""
        v = np.asarray(v, dtype=np.float64)
        return self.stribeck(v) * np.sign(v) + self.viscous_coefficient * v

    def lag_time(self, v):
        """How long the force takes to follow a velocity change at ``v`` [s]; None if instant."""
        if self.bristle_stiffness is not None:
            return float(self.stribeck(v)) / (self.bristle_stiffness * abs(v))
        if self.relaxation_rate is not None:
            return float(self.stribeck(v)) / self.relaxation_rate
        if self.relaxation_length is not None:
            return self.relaxation_length / abs(v)
        return None

    @property
    def has_stribeck_dip(self) -> bool:
        """Whether the steady curve falls from Fs to a lower Fc (velocity weakening)."""
        return self.stribeck_velocity is not None and self.static_force > self.coulomb_force


def friction_levels(model) -> FrictionLevels:
    """The force, velocity, length and time scales of a friction model.

    Parameters
    ----------
    model : polind.FrictionModel

    Returns
    -------
    FrictionLevels

    Examples
    --------
    >>> import polind
    >>> model = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 2.0]}})
    >>> levels = friction_levels(model)
    >>> levels.static_force, levels.presliding_range
    (3.0, 2e-05)
    """
    scales = model.characteristic_scales()
    if scales is None:
        raise InputError(f"The {model.type} model declares no characteristic scales "
                         f"(FrictionModel.characteristic_scales), so the phenomena "
                         f"experiments cannot be sized for it.")
    return FrictionLevels(model.type, credited=frozenset(model.phenomena), **scales)


def _expected(phenomenon: str, levels: FrictionLevels) -> bool:
    """Whether the user guide credits a model (with these levels) with the phenomenon.

    Stribeck effect and stick-slip need velocity weakening (``Fs > Fc``);
    frictional lag needs a lag and a sloped curve for it to show on.  Every
    model breaks away near its static level when the force rises slowly
    (:ref:`guide-demo`, :ref:`guide-choosing-table`).
    """
    if phenomenon in ("stribeck", "stick_slip"):
        return levels.has_stribeck_dip
    if phenomenon == "frictional_lag":
        return phenomenon in levels.credited and levels.has_stribeck_dip
    if phenomenon in ("presliding_memory", "non_drifting"):
        return phenomenon in levels.credited
    return True


# --- the result ---------------------------------------------------------------------------

@dataclass
class PhenomenonResult:
    """One experiment on one model.

    Attributes
    ----------
    phenomenon : str
        One of :data:`PHENOMENA` (the key of ``metrics.json``).
    model_type : str
    passed : bool
        The phenomenon appears in this run (the experiment's check).
    expected : bool
        The user guide credits this model with the phenomenon
        (:ref:`guide-choosing-table`).
    metrics : dict
        The numbers that measure it (floats, lists of floats, booleans); JSON-able.
    settings : dict
        The experiment's inputs (velocities, masses, frequencies, ...); JSON-able.
    data : dict of str to ndarray
        The arrays its figure shows.
    note : str
        One sentence on how to read the result for this model.
    """

    phenomenon: str
    model_type: str
    passed: bool
    expected: bool
    metrics: dict
    settings: dict
    data: dict = field(repr=False, default_factory=dict)
    note: str = ""

    @property
    def as_expected(self) -> bool:
        """The model behaves as the user guide says: the phenomenon appears iff it is expected."""
        return self.passed == self.expected

    def to_dict(self) -> dict:
        """The JSON-able summary: ``passed``, ``expected``, metrics and settings (no arrays)."""
        return {"passed": bool(self.passed), "expected": bool(self.expected),
                "as_expected": bool(self.as_expected), **plain_data(self.metrics, for_toml=False),
                "settings": plain_data(self.settings, for_toml=False), "note": self.note}


def _result(phenomenon, levels, passed, metrics, settings, data, note=""):
    return PhenomenonResult(phenomenon, levels.model_type, bool(passed),
                            _expected(phenomenon, levels), metrics, settings, data, note)


def velocity_scale(levels: FrictionLevels) -> float:
    """vs, or 1 mm/s for a model without a Stribeck curve (the default Pol-Ind vs)."""
    return levels.stribeck_velocity if levels.stribeck_velocity is not None else 1e-3


# --- 1. the Stribeck effect ---------------------------------------------------------------

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
    return _result("stribeck", levels, passed, metrics, settings, data, note)


# --- 2. presliding hysteresis with non-local memory ------------------------------------------

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

    The displacement follows :data:`MEMORY_PATH` at a constant speed, every
    reversal a sample.  For each closure of :data:`MEMORY_CLOSURES` the force
    when the path comes back to a reversal point is compared with the force
    it had there; for each leg of :data:`MEMORY_BRANCHES` the force after
    the closure is compared with a run along the same path without the
    inner loops (the branch it would have followed had they never happened).

    Parameters
    ----------
    model : polind.FrictionModel
    amplitude : float, optional
        The largest displacement [m]; default 0.8 of the model's presliding
        range (:class:`FrictionLevels`).
    speed : float, optional
        [m/s], the same on every leg; default ``1e-3 vs`` (deep inside the
        presliding regime of the rate-state models).

    Returns
    -------
    PhenomenonResult
        metrics: ``closure_mismatch`` (per closure and the largest, each
        relative to its loop's force span), ``loops_close`` (per closure:
        its mismatch below :data:`MEMORY_TOLERANCE`), ``branch_mismatch``
        (relative to the major loop's span), ``major_loop_span`` [N].
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
    return _result("presliding_memory", levels, passed, metrics, settings, data, note)


# --- 3. frictional lag --------------------------------------------------------------------

def _nice(value):
    """One significant digit (1, 2 or 5 times a power of ten): readable frequencies."""
    exponent = math.floor(math.log10(value))
    mantissa = value / 10.0 ** exponent
    return min((1.0, 2.0, 5.0, 10.0), key=lambda m: abs(math.log(mantissa / m))) * 10.0 ** exponent


def cycle_area(velocity, force):
    """The signed area ``closed integral of F dv`` of one loop [N m/s] (trapezoid).

    Positive when the loop circulates in the lag direction: higher force
    while the velocity rises than while it falls.  The force is taken
    relative to its first sample, which keeps the large constant part of the
    force out of the sum (a constant force gives exactly 0), and that part
    is added back as ``F_0 (v_end - v_start)``, exactly 0 for a closed loop
    and what the trapezoid gives for one whose ends differ (a sweep's loop
    between two up-crossings).  An area that rounding alone can make --
    forces known to 64 ulps around the loop's travel ``sum |dv|``, plus the
    rounding of the sum -- is reported as 0, not as a noise of either sign.
    """
    force = np.asarray(force, dtype=np.float64)
    velocity = np.asarray(velocity, dtype=np.float64)
    dv = np.diff(velocity)
    relative = force - float(force[0])
    terms = 0.5 * (relative[1:] + relative[:-1]) * dv
    area = float(np.sum(terms)) + float(force[0]) * float(velocity[-1] - velocity[0])
    eps = float(np.finfo(np.float64).eps)
    rounding = eps * (64.0 * float(np.max(np.abs(force))) * float(np.sum(np.abs(dv)))
                      + terms.shape[0] * float(np.sum(np.abs(terms))))
    return area if abs(area) > rounding else 0.0


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
        model's lag time at ``v0`` (:meth:`FrictionLevels.lag_time`), rounded
        to 1, 2 or 5 times a power of ten; 1 Hz to 1 kHz for a model without
        lag.
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
    return _result("frictional_lag", levels, passed, metrics, settings, data, note)


# --- the one-degree-of-freedom experiments (the user guide, 'One-degree-of-freedom systems')

def _body_mass(levels: FrictionLevels) -> float:
    """1 kg per newton of Coulomb force: the LuGre reference body (m = 1 kg, Fc = 1 N) scaled,
    so the friction decelerates every body alike."""
    return levels.coulomb_force * 1.0


def _presliding_period(levels: FrictionLevels, mass: float):
    """The period of the body on its presliding stiffness [s]; None for memoryless models."""
    if levels.presliding_stiffness <= 0.0:
        return None
    return 2.0 * math.pi * math.sqrt(mass / levels.presliding_stiffness)


def _run_system(model, **kwargs):
    from polind.dynamics import System, simulate_system

    start = {key: kwargs.pop(key) for key in ("initial_position", "initial_velocity")
             if key in kwargs}
    return simulate_system(model, System(**kwargs), **start)


def _thin(array, points=4000):
    """Every n-th sample, so a figure gets at most about ``points`` of them."""
    return array[::max(1, array.shape[0] // points)]


# --- 4. non-drifting ----------------------------------------------------------------------

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
    mass = _body_mass(levels) if mass is None else float(mass)
    if time_step is None:
        period = _presliding_period(levels, mass)
        time_step = min(1e-3, period / 10.0) if period else 1e-3
    res = _run_system(model, mass=mass, duration=float(cycles), time_step=time_step,
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
    data = {"t": _thin(res.t), "x": _thin(res.x), "applied": _thin(res.applied),
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
    return _result("non_drifting", levels, passed, metrics, settings, data, note)


# --- 5. stick-slip --------------------------------------------------------------------------

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
    res = _run_system(model, mass=mass, duration=duration, time_step=time_step,
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
    data = {"t": _thin(res.t), "spring_force": _thin(res.applied), "friction": _thin(res.force),
            "v": _thin(res.v)}
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
    mass = _body_mass(levels)
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
    return _result("stick_slip", levels, passed, metrics, settings, data, note)


# --- 6. break-away --------------------------------------------------------------------------

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
    mass = _body_mass(levels)
    period = _presliding_period(levels, mass)
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
        res = _run_system(model, mass=mass, duration=duration, time_step=duration / steps,
                          rate=rate)
        moving = np.flatnonzero(res.v > threshold)
        k = int(moving[0]) if moving.size else None
        rates.append(rate)
        forces.append(float(res.applied[k]) if k is not None else math.nan)
        displacements.append(float(res.x[k]) if k is not None else math.nan)
        runs.append({"applied": _thin(res.applied), "x": _thin(res.x), "v": _thin(res.v)})
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
    return _result("breakaway", levels, passed, metrics, settings, data, note)
