"""Frequency response curves by pseudo-arclength continuation (:ref:`guide-frequency-domain`).

The harmonic-balance equations ``r(x, omega) = 0`` of
:class:`~polind.structures.harmonic.PeriodicProblem` are followed along
their solution curve in ``(x, omega)``, ``x`` the contacts' oscillating
coefficients, so that a curve that folds back (a turning point, where the
response jumps in a sweep) is traced through its fold.  Each step:

1. the *tangent* ``tau`` of the curve at the last point solves
   ``[dr/dx, dr/domega; tau_prev^T] tau = [0; 1]`` (normalised), in scaled
   variables ``(x / x_s, omega / omega_s)``, so that ``tau`` keeps its
   direction through a fold;
2. the *predictor* is ``z_p = z + ds tau``;
3. the *corrector* solves ``r(z) = 0`` with ``tau . (z - z_p) = 0`` (the
   plane through the predictor normal to the tangent) by MINPACK's hybrid
   method from the tangent Jacobian (:func:`scipy.optimize.root`);
4. the step length ``ds`` halves when a correction fails or turns the
   tangent by more than 30 degrees, and grows by half after an easy one.

``dr/domega`` is a forward difference (a rate model's force depends on the
period; the linear part on ``omega`` through ``D_h``).  The stability of
the periodic solutions is not computed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg
import scipy.optimize

from polind.errors import InputError, describe
from polind.structures.harmonic import (PeriodicProblem, build_result,
                                        check_harmonics, response_amplitude,
                                        force_harmonics)
from polind.validation import check_number

__all__ = ["ContinuationError", "FrequencyResponse", "frequency_response"]


class _Rejected(Exception):
    """A trial point the continuation cannot evaluate (omega <= 0)."""


class ContinuationError(InputError):
    """A continuation that stopped before the end of its range; ``curve`` holds the points found."""

    def __init__(self, message, curve):
        super().__init__(message)
        self.curve = curve


@dataclass
class FrequencyResponse:
    """A frequency response curve: periodic steady states along a continuation.

    Attributes
    ----------
    omega : ndarray
        ``(P,)`` the fundamental frequency of each point [rad/s], in the
        order of the curve (it goes back where the curve folds).
    harmonics : ndarray
        ``(P, n, 2H + 1)`` each coordinate's coefficients
        ``[Q_0, Q_c1, Q_s1, ...]`` [m].
    contact_displacement, contact_force : ndarray
        ``(P, m, 2H + 1)`` each contact's relative displacement [m] and force [N].
    residual : ndarray
        ``(P,)`` each point's residual, relative to its displacement scale.
    evaluations : int
        The periodic evaluations of the contacts the whole curve took.
    """

    omega: np.ndarray
    harmonics: np.ndarray
    contact_displacement: np.ndarray
    contact_force: np.ndarray
    residual: np.ndarray
    evaluations: int = 0
    points: list = field(default_factory=list, repr=False)

    def amplitude(self, dof, harmonic=None):
        """``(P,)`` amplitudes [m] of coordinate ``dof``: the largest ``|q - Q_0|`` over each period, or one harmonic's."""
        return response_amplitude(self.harmonics, dof, harmonic)

    @property
    def turning_points(self):
        """Indices where ``omega`` changes direction along the curve (folds)."""
        d = np.sign(np.diff(self.omega))
        return np.flatnonzero(d[1:] * d[:-1] < 0) + 1

    def __len__(self):
        return self.omega.shape[0]

    def __repr__(self):
        if not len(self):
            return "FrequencyResponse(0 points)"
        return (f"FrequencyResponse({len(self)} points, omega {self.omega.min():.6g} to "
                f"{self.omega.max():.6g} rad/s, {len(self.turning_points)} turning points)")


def _curve(points, evaluations):
    if not points:
        empty = np.zeros((0,))
        return FrequencyResponse(omega=empty, harmonics=np.zeros((0, 0, 0)),
                                 contact_displacement=np.zeros((0, 0, 0)),
                                 contact_force=np.zeros((0, 0, 0)), residual=empty,
                                 evaluations=evaluations)
    return FrequencyResponse(
        omega=np.array([p.omega for p in points]),
        harmonics=np.array([p.harmonics for p in points]),
        contact_displacement=np.array([p.contact_displacement for p in points]),
        contact_force=np.array([p.contact_force for p in points]),
        residual=np.array([p.residual for p in points]),
        evaluations=evaluations, points=list(points))


def frequency_response(structure, omega_range, *, force=None, static_force=None,
                       harmonics=7, samples=None, step=None, max_points=2000,
                       tolerance=1e-9, progress=None) -> FrequencyResponse:
    """A frequency response curve by harmonic balance and continuation (:ref:`guide-frequency-domain`).

    Parameters
    ----------
    structure : Structure
        Matrices and contacts (at least one).
    omega_range : (float, float)
        The first and last fundamental frequency [rad/s], positive and
        different; the curve runs from the first to the last (downwards if
        the first is larger), through any turning points between.
    force, static_force : array_like
        The applied force's harmonics [N], as in :func:`polind.harmonic_balance`.
    harmonics : int, default 7
        ``H``.
    samples : int, optional
        ``N >= 4H + 1`` samples per period (default 128 for ``H <= 16``).
    step : float, optional
        The first step length along the curve, in units of the scaled
        variables (default: a fiftieth of the range).
    max_points : int, default 2000
        The most points of the curve.
    tolerance : float, default 1e-9
        The corrector's relative tolerance.
    progress : callable, optional
        Called as ``progress(omega, point_count)`` after each point.

    Returns
    -------
    FrequencyResponse

    Raises
    ------
    ContinuationError
        The continuation stopped before the end of the range (a step that
        could not be corrected at the smallest step length, or
        ``max_points``); its ``curve`` holds the points found, and its
        message the last frequency and residual.
    """
    owner = "frequency_response"
    try:
        start, stop = (float(value) for value in omega_range)
    except (TypeError, ValueError):
        raise InputError(f"The 'omega_range' of {owner} must be two frequencies (first, last) "
                         f"in rad/s. Got {describe(omega_range)} instead.") from None
    start = check_number(owner, "omega_range", start, "positive")
    stop = check_number(owner, "omega_range", stop, "positive")
    if start == stop:
        raise InputError(f"The 'omega_range' of {owner} must be two different frequencies. "
                         f"Got ({start!r}, {stop!r}) instead.")
    harmonics, samples = check_harmonics(owner, harmonics, samples)
    max_points = check_number(owner, "max_points", max_points, "positive", integer=True)
    tolerance = check_number(owner, "tolerance", tolerance, "positive")
    problem = PeriodicProblem(structure, harmonics, samples, owner, 2.0 * np.pi / start)
    applied = force_harmonics(structure, force, static_force, harmonics, owner)
    direction = 1.0 if stop > start else -1.0
    omega_scale = abs(stop - start)
    if step is None:
        step = 0.02
    step = check_number(owner, "step", step, "positive")

    # A point is accepted at a residual of 1e4 tolerances (1e-5 of the displacement scale
    # by default): the periodic evaluation of a rate model repeats to 1e-11 of its state.
    accept = 1e4 * tolerance
    x, evaluations, error, forces = problem.solve(problem.linear_guess(start, applied), start,
                                                  applied, tolerance, 400)
    if not error <= accept:
        raise ContinuationError(f"The continuation of {owner} could not start at omega = "
                                f"{start!r} rad/s: the residual is {error:.3g}.", _curve([], 0))
    points = [build_result(problem, x, forces, start, applied, error, evaluations)]
    # The displacement scale: the largest response of the stuck structure and of the
    # structure without its contacts' stiffness over the range, so that a resonance
    # peak is a step of the order of one in the scaled variables.
    x_scale = max(float(np.abs(x).max()), problem.linear_scale(applied, start, stop))
    if x_scale == 0.0:
        raise InputError(f"The 'force' of {owner} is zero: the response is zero at every "
                         f"frequency.")
    size = x.shape[0]

    def scaled(z):
        return z[:size] * x_scale, z[size] * omega_scale

    def augmented_jacobian(z, differences=False):
        xv, w = scaled(z)
        if not w > 0.0:
            raise _Rejected
        r, J, _ = problem.residual(xv, w, applied, differences=differences)
        dw = 1e-7 * max(w, omega_scale)
        r2, _ = problem.residual(xv, w + dw, applied, jacobian=False)
        column = (r2 - r) / dw * omega_scale / x_scale
        return r / x_scale, np.column_stack([J, column])

    z = np.append(x / x_scale, start / omega_scale)
    _, A = augmented_jacobian(z)
    seed = np.zeros(size + 1)
    seed[-1] = direction
    tau = scipy.linalg.solve(np.vstack([A, seed]), np.append(np.zeros(size), 1.0),
                             check_finite=False)
    tau /= np.linalg.norm(tau)
    ds = step
    smallest = step * 1e-4
    largest = 2.5 * step
    while True:
        while True:
            predictor = z + ds * tau

            for differences in (False, True):
                # The tangent Jacobian first; differences where it does not converge.
                def corrector(y, predictor=predictor, tau=tau, differences=differences):
                    r, A = augmented_jacobian(y, differences)
                    return (np.append(r, tau @ (y - predictor)), np.vstack([A, tau]))

                try:
                    solution = scipy.optimize.root(corrector, predictor, jac=True,
                                                   method="hybr",
                                                   options={"xtol": tolerance,
                                                            "maxfev": 200 if differences else 60})
                except (_Rejected, InputError):
                    # A trial at omega <= 0, or where a contact does not settle: a failed step.
                    solution = None
                    continue
                y = solution.x
                if solution.success:
                    break
            if solution is None:
                accepted = False
                reason = "left the positive frequencies or a contact's periodic state"
            else:
                xv, w = scaled(y)
                residual, forces = problem.residual(xv, w, applied, jacobian=False)
                error = float(np.abs(residual).max()) / max(float(np.abs(xv).max()), 1e-300)
                secant = (y - z) / max(np.linalg.norm(y - z), 1e-300)
                # A step that turns the curve by more than 45 degrees is shortened, unless it
                # is already short: then the curve has a corner (where a joint starts to slip).
                turn = float(secant @ tau)
                accepted = error <= accept and w > 0 and (
                    turn > np.cos(np.radians(45)) or (turn > 0.0 and ds <= 64 * smallest))
                reason = f"did not converge (residual {error:.3g})"
            if accepted:
                break
            ds *= 0.5
            if ds < smallest:
                curve = _curve(points, problem.evaluations)
                raise ContinuationError(
                    f"The continuation of {owner} stopped at omega = {float(points[-1].omega)!r} "
                    f"rad/s: the next step {reason} at the smallest step length. The "
                    f"{len(points)} points found are kept.", curve)
        # The secant predicts the next step: it keeps its direction through a fold.
        tau = secant
        z = y                                     # (xv, w) and its forces: the accepted point
        if direction * (w - stop) >= 0:
            # Past the end: the last point is solved at the end frequency itself.
            end, _, error, forces = problem.solve(xv, stop, applied, tolerance, 400)
            if error <= accept:
                points.append(build_result(problem, end, forces, stop, applied, error, 0))
            break
        points.append(build_result(problem, xv, forces, w, applied, error, 0))
        if progress is not None:
            progress(w, len(points))
        if len(points) >= max_points:
            curve = _curve(points, problem.evaluations)
            raise ContinuationError(f"The continuation of {owner} reached its 'max_points' "
                                    f"({max_points}) at omega = {float(w)!r} rad/s (residual "
                                    f"{error:.3g}) before the end of its range.", curve)
        if not differences and solution.nfev <= 12:
            ds = min(ds * 1.5, largest)
    return _curve(points, problem.evaluations)
