"""What the six phenomenon experiments share (:ref:`guide-phenomena`).

* :class:`FrictionLevels` and :func:`friction_levels`: the scales of a
  friction model (its static and Coulomb forces, Stribeck velocity,
  presliding range and lag time) that every experiment is sized by, and
  :func:`velocity_scale`;
* :class:`PhenomenonResult`, what every experiment returns, and
  :func:`experiment_result`, which makes one and decides ``expected`` (does
  the user guide credit the model with the phenomenon,
  :ref:`guide-choosing-table`);
* :data:`PHENOMENA`, the keys of ``metrics.json``;
* :func:`cycle_area`, the signed area of a force-velocity loop (the
  frictional-lag experiment and :func:`polind.sweep`);
* the one-degree-of-freedom body of the non-drifting, stick-slip and
  break-away experiments (:ref:`guide-systems`): :func:`body_mass`,
  :func:`presliding_period`, :func:`run_system` and :func:`thin`.

The experiments themselves live one per module of :mod:`polind.phenomena`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError
from polind.io import plain_data
from polind.models.static import stribeck_curve

__all__ = [
    "PHENOMENA",
    "FrictionLevels",
    "PhenomenonResult",
    "friction_levels",
    "experiment_result",
    "velocity_scale",
    "cycle_area",
    "body_mass",
    "presliding_period",
    "run_system",
    "thin",
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
        One of :data:`~polind.phenomena.common.PHENOMENA` (the key of ``metrics.json``).
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


def experiment_result(phenomenon, levels, passed, metrics, settings, data, note=""):
    """The :class:`PhenomenonResult` of an experiment on a model with these levels.

    ``expected`` is decided here, from the phenomenon and the model's
    :class:`FrictionLevels`; ``passed`` is the experiment's own check.
    """
    return PhenomenonResult(phenomenon, levels.model_type, bool(passed),
                            _expected(phenomenon, levels), metrics, settings, data, note)


def velocity_scale(levels: FrictionLevels) -> float:
    """vs, or 1 mm/s for a model without a Stribeck curve (the default Pol-Ind vs)."""
    return levels.stribeck_velocity if levels.stribeck_velocity is not None else 1e-3


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


# --- the one-degree-of-freedom experiments (the user guide, 'One-degree-of-freedom systems')

def body_mass(levels: FrictionLevels) -> float:
    """1 kg per newton of Coulomb force: the LuGre reference body (m = 1 kg, Fc = 1 N) scaled,
    so the friction decelerates every body alike."""
    return levels.coulomb_force * 1.0


def presliding_period(levels: FrictionLevels, mass: float):
    """The period of the body on its presliding stiffness [s]; None for memoryless models."""
    if levels.presliding_stiffness <= 0.0:
        return None
    return 2.0 * math.pi * math.sqrt(mass / levels.presliding_stiffness)


def run_system(model, **kwargs):
    """:func:`polind.dynamics.simulate_system` on a :class:`polind.dynamics.System` of ``kwargs``.

    ``initial_position`` and ``initial_velocity``, if given, are the body's
    start; every other keyword is a field of the system.
    """
    from polind.dynamics import System, simulate_system

    start = {key: kwargs.pop(key) for key in ("initial_position", "initial_velocity")
             if key in kwargs}
    return simulate_system(model, System(**kwargs), **start)


def thin(array, points=4000):
    """Every n-th sample, so a figure gets at most about ``points`` of them."""
    return array[::max(1, array.shape[0] // points)]
