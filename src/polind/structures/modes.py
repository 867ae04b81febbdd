"""Nonlinear modes of a jointed structure: the extended periodic motion concept (:ref:`guide-frequency-domain`).

A joint softens and damps a mode more as its amplitude grows.  The
extended periodic motion concept (Krack 2015) makes the damped mode a
periodic motion by adding the negative damping ``-xi M q'`` that feeds
back, per period, what the joints and ``C`` dissipate:

    M q'' + (C - xi M) q' + K q + B^T F(B q) = 0 .

Harmonic balance with alternating frequency–time (the contacts' forces and
tangents as in :mod:`polind.structures.harmonic`, each contact started
unloaded at its mean) gives, for each modal amplitude ``a``, the unknowns
``Q_h`` (every coordinate's oscillating harmonics), ``omega`` and ``xi``,
with two more equations: the first harmonic's mass-normalised amplitude
``Q_c1^T M Q_c1 + Q_s1^T M Q_s1 = a^2`` and its phase ``phi^T M Q_s1 = 0``
(``phi`` the linear mode with the contacts stuck).  The frequency is
``omega(a)`` and the damping ratio ``zeta(a) = xi / (2 omega)``; at small
damping it equals the energy definition ``D(a) / (2 pi omega^2 a^2)``, ``D``
the energy the structure dissipates per period.

The amplitudes are followed from the smallest, each point starting from the
last (a step that fails is halved, down to a thousandth).  Unlike the
frequency response, the coordinates are not condensed onto the contacts:
near a mode the dynamic stiffness that condensation inverts is singular by
construction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from polind.errors import InputError, describe
from polind.structures.harmonic import (PeriodicProblem, check_harmonics, real_blocks,
                                        response_amplitude)
from polind.validation import check_number, check_samples

__all__ = ["Backbone", "backbone"]


@dataclass
class Backbone:
    """Amplitude-dependent modal properties of :func:`backbone`.

    Attributes
    ----------
    amplitude : ndarray
        ``(P,)`` modal amplitudes ``a`` [m kg^0.5] (the first harmonic's
        ``sqrt(Q^T M Q)``; for one coordinate of mass ``m``, ``sqrt(m)`` times
        its displacement amplitude).
    frequency : ndarray
        ``(P,)`` ``omega(a)`` [rad/s].
    damping_ratio : ndarray
        ``(P,)`` ``zeta(a) = xi / (2 omega)`` (the joints' and ``C``'s).
    harmonics : ndarray
        ``(P, n, 2H + 1)`` each coordinate's coefficients [m].
    contact_force : ndarray
        ``(P, m, 2H + 1)`` each contact's force coefficients [N].
    linear_frequency : float
        The mode's frequency with the contacts stuck [rad/s].
    """

    amplitude: np.ndarray
    frequency: np.ndarray
    damping_ratio: np.ndarray
    harmonics: np.ndarray
    contact_force: np.ndarray
    linear_frequency: float

    def displacement_amplitude(self, dof, harmonic=None):
        """``(P,)`` amplitudes [m] of coordinate ``dof`` (largest ``|q - Q_0|``, or one harmonic's)."""
        return response_amplitude(self.harmonics, dof, harmonic)

    def __repr__(self):
        return (f"Backbone({self.amplitude.shape[0]} amplitudes, omega "
                f"{self.frequency.min():.6g} to {self.frequency.max():.6g} rad/s, zeta "
                f"{self.damping_ratio.min():.3g} to {self.damping_ratio.max():.3g})")


class _ModeProblem:
    """The EPMC equations of one mode in the unknowns ``y = [Q / a, omega / w0, xi / w0]``."""

    def __init__(self, problem, phi, w0):
        self.p = problem
        self.phi = phi
        self.w0 = w0
        H, n = problem.harmonics, problem.n
        self.size = n * 2 * H
        I = np.eye(2 * H)
        self.project = [np.kron(problem.B[c][None, :], I) for c in range(problem.m)]
        self.M = problem.structure.mass
        # The force balance is scaled by the mode's stiffness, so that its residual is
        # relative however stiff or heavy the structure is.
        self.stiffness = w0 ** 2 * float(np.abs(self.M).max())

    def linear(self, omega, xi):
        return real_blocks(self.p.dynamic_stiffnesses(omega, xi=xi))

    def equations(self, y, a, jacobian=True):
        p, H, n = self.p, self.p.harmonics, self.p.n
        Q = y[:self.size] * a
        omega, xi = y[self.size] * self.w0, y[self.size + 1] * self.w0
        coefficients = np.zeros((p.m, 2 * H + 1))
        coefficients[:, 1:] = (p.B @ Q.reshape(n, 2 * H))
        forces, jacobians = p.contact_forces(coefficients, omega)
        L = self.linear(omega, xi)
        r = L @ Q + (p.B.T @ forces[:, 1:]).reshape(-1)
        Qc1, Qs1 = Q.reshape(n, 2 * H)[:, 0], Q.reshape(n, 2 * H)[:, 1]
        amplitude = (Qc1 @ self.M @ Qc1 + Qs1 @ self.M @ Qs1 - a * a) / (a * a)
        phase = self.phi @ self.M @ Qs1 / a
        residual = np.concatenate([r / (a * self.stiffness), [amplitude, phase]])
        if not jacobian:
            return residual, forces
        J = L.copy()
        for c, P in enumerate(self.project):
            J += P.T @ jacobians[c] @ P
        full = np.zeros((self.size + 2, self.size + 2))
        full[:self.size, :self.size] = J / self.stiffness     # d(r/a)/d(Q/a), scaled
        for column, (dw, dxi) in ((self.size, (1e-7, 0.0)), (self.size + 1, (0.0, 1e-7))):
            shifted = y.copy()
            shifted[self.size] += dw
            shifted[self.size + 1] += dxi
            r2, _ = self.equations(shifted, a, jacobian=False)
            full[:, column] = (r2 - residual) / 1e-7
        grid = np.zeros((n, 2 * H))
        grid[:, 0] = 2 * self.M @ Qc1 / a
        grid[:, 1] = 2 * self.M @ Qs1 / a
        full[self.size, :self.size] = grid.reshape(-1)
        grid = np.zeros((n, 2 * H))
        grid[:, 1] = self.M @ self.phi
        full[self.size + 1, :self.size] = grid.reshape(-1)
        return residual, full


def backbone(structure, amplitudes, *, mode=0, harmonics=7, samples=None,
             tolerance=1e-10, progress=None) -> Backbone:
    """Amplitude-dependent frequency and damping of a mode (EPMC, :ref:`guide-frequency-domain`).

    Parameters
    ----------
    structure : Structure
        Matrices and contacts (at least one).
    amplitudes : array_like
        Modal amplitudes ``a`` [m kg^0.5], positive (the first harmonic's
        ``sqrt(Q^T M Q)``); solved in increasing order.
    mode : int, default 0
        Which linear mode (with the contacts stuck), by increasing frequency.
    harmonics : int, default 7
        ``H``.
    samples : int, optional
        ``N >= 4H + 1`` samples per period (default 128 for ``H <= 16``).
    tolerance : float, default 1e-10
        The solver's relative tolerance.
    progress : callable, optional
        Called as ``progress(amplitude, count)`` after each amplitude.

    Returns
    -------
    Backbone
    """
    owner = "backbone"
    values = check_samples(owner, "amplitudes", amplitudes)
    bad = np.flatnonzero(values <= 0)
    if bad.size:
        raise InputError(f"The 'amplitudes' of {owner} must be positive. Got "
                         f"{float(values[bad[0]])!r} at index {int(bad[0])} instead.")
    values = np.sort(values)
    harmonics, samples = check_harmonics(owner, harmonics, samples)
    tolerance = check_number(owner, "tolerance", tolerance, "positive")
    problem = PeriodicProblem(structure, harmonics, samples, owner, 1.0)
    n = problem.n
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) or not 0 <= mode < n:
        raise InputError(f"The 'mode' of {owner} must be a mode 0 to {n - 1}. Got "
                         f"{describe(mode)} instead.")
    stuck = structure.stiffness + problem.B.T @ (problem.k_c[:, None] * problem.B)
    eigenvalues, vectors = scipy.linalg.eigh(stuck, structure.mass)
    if eigenvalues[mode] <= 0:
        raise InputError(f"Mode {mode} of the structure of {owner} has no stiffness with its "
                         f"contacts stuck (eigenvalue {float(eigenvalues[mode])!r}): it has no "
                         f"vibration to follow.")
    w0 = float(np.sqrt(eigenvalues[mode]))
    phi = vectors[:, mode] / np.sqrt(vectors[:, mode] @ structure.mass @ vectors[:, mode])
    # The tangents at rest were taken at a period of 1 s; take them at the mode's.
    problem.stuck_tangents(2 * np.pi / w0)
    equations = _ModeProblem(problem, phi, w0)
    y = np.zeros(equations.size + 2)
    grid = np.zeros((n, 2 * harmonics))
    grid[:, 0] = phi
    y[:equations.size] = grid.reshape(-1)
    y[equations.size] = 1.0
    y[equations.size + 1] = float(phi @ structure.damping @ phi) / w0
    found = []
    previous = values[0]
    for target in values:
        a = previous
        step = target - previous
        while True:
            trial = min(a + step, target) if step > 0 else target
            solution = scipy.optimize.root(lambda z: equations.equations(z, trial), y,
                                           jac=True, method="hybr",
                                           options={"xtol": tolerance, "maxfev": 200})
            residual, _ = equations.equations(solution.x, trial, jacobian=False)
            error = float(np.abs(residual).max())
            if error <= 1e3 * tolerance:
                y, a = solution.x, trial
                if a >= target:
                    break
                step *= 1.5
                continue
            step *= 0.5
            if step < 1e-3 * max(target - previous, target * 1e-3) or trial == a:
                raise InputError(f"The backbone did not converge at the modal amplitude "
                                 f"{float(trial)!r} (relative residual {error:.3g}, frequency "
                                 f"{float(y[equations.size] * w0)!r} rad/s); the "
                                 f"{len(found)} amplitudes before it converged.")
        previous = target
        residual, forces = equations.equations(y, target, jacobian=False)
        Q = np.zeros((n, 2 * harmonics + 1))
        Q[:, 1:] = (y[:equations.size] * target).reshape(n, 2 * harmonics)
        Q[:, 0] = np.linalg.lstsq(structure.stiffness, -problem.B.T @ forces[:, 0],
                                  rcond=None)[0]
        omega, xi = y[equations.size] * w0, y[equations.size + 1] * w0
        found.append((target, omega, xi / (2 * omega), Q, forces))
        if progress is not None:
            progress(float(target), len(found))
    return Backbone(amplitude=np.array([f[0] for f in found]),
                    frequency=np.array([f[1] for f in found]),
                    damping_ratio=np.array([f[2] for f in found]),
                    harmonics=np.array([f[3] for f in found]),
                    contact_force=np.array([f[4] for f in found]),
                    linear_frequency=w0)
