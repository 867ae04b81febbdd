"""Harmonic balance of a structure with friction contacts (:ref:`guide-frequency-domain`).

The periodic steady state of :class:`~polind.structures.core.Structure`
under a periodic force of frequency ``omega`` is sought as a truncated
Fourier series of ``H`` harmonics,

    q(t) = Q_0 + sum_h (Q_ch cos h omega t + Q_sh sin h omega t),

with alternating frequency–time (AFT): each contact's relative displacement
is sampled at ``N`` points of the period, the contact is stepped along it
with its model's own exact update until its state repeats (the stepping
core's periodic evaluation, :mod:`polind.kernels.periodic`), and the
Fourier coefficients of the last period's force enter the balance

    (K - (h omega)^2 M + i h omega C) Q_h + B^T F_h = f_h .

Nothing here knows which model a contact is: it asks the contact's kernel
for its force and its tangent along the period.

Two choices make the problem well posed for contacts with memory:

- *Each contact starts unloaded at its mean displacement* over the period
  (a lead-in step from there to the period's first sample, then the
  periods): an element that never slips then carries ``k (u - U_0)``, the
  symmetric loop of a structure whose amplitude grew from rest.  A
  contact's force is therefore a function of ``u - U_0`` alone (every
  polind model is invariant to a shift of its displacement), so the
  oscillating harmonics are solved without the mean, and the mean follows
  from the static balance ``K Q_0 = f_0 - B^T F_0`` (least squares: a
  coordinate that only contacts hold has no definite mean, and the
  smallest one is taken).
- *The coordinates are condensed onto the contacts.*  With each contact's
  initial tangent ``k_c`` (a stuck joint's stiffness) added to the linear
  part, ``D_h = K - (h omega)^2 M + i h omega C + B^T diag(k_c) B`` stays
  regular whenever the structure does, and the nonlinear unknowns are the
  contacts' harmonics ``U_h`` only:

      r_h = U_h - B D_h^{-1} f_h + B D_h^{-1} B^T (F_h(U) - k_c U_h) = 0 .

The Newton Jacobian takes each sample's ``dF_j / du_j`` from the contact's
tangent along the period (``E diag(dF/du) T`` between the harmonics and the
samples); it is the exact derivative with the history held and an
approximation of the full one (a reversal point moves the loop that
follows), so the equations are solved by MINPACK's hybrid method
(:func:`scipy.optimize.root`, ``"hybr"``), which starts from that Jacobian
and refines it by rank-one updates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

from polind.errors import InputError, describe
from polind.models.kernel import RIGID
from polind.structures.core import Structure
from polind.validation import check_number

__all__ = ["HarmonicBalanceResult", "PeriodicProblem", "harmonic_balance",
           "default_samples"]

#: The fewest samples per period the default takes: with hysteretic contacts
#: ``4H + 1`` samples err by tenths of a per cent at ``H = 7``, 128 by 1e-4.
DEFAULT_SAMPLES = 128
#: The most periods a contact is stepped to reach its periodic state.
CYCLES = 1000
#: The relative change of a contact's state over a period taken as periodic.
PERIODIC_TOLERANCE = 1e-11


def default_samples(harmonics):
    """The samples per period of ``harmonics`` harmonics by default: a power of two, at least 128 and 8H."""
    return max(DEFAULT_SAMPLES, 1 << math.ceil(math.log2(8 * harmonics)))


def check_harmonics(owner, harmonics, samples):
    """``(H, N)`` validated: ``H >= 1`` and ``N >= 4H + 1`` (default :func:`default_samples`)."""
    harmonics = check_number(owner, "harmonics", harmonics, "positive", integer=True)
    if samples is None:
        return harmonics, default_samples(harmonics)
    samples = check_number(owner, "samples", samples, "positive", integer=True)
    if samples < 4 * harmonics + 1:
        raise InputError(f"The 'samples' of {owner} must be at least 4 harmonics + 1 = "
                         f"{4 * harmonics + 1} per period. Got {samples} instead.")
    return harmonics, samples


def basis(harmonics, samples):
    """``(T, E)``: the samples of ``[1, cos, sin, cos 2, sin 2, ...]`` and their inverse.

    ``T`` is ``(N, 2H + 1)``: ``x_j = T @ c`` for the real coefficients ``c =
    [c_0, c_1, s_1, ..., c_H, s_H]`` at ``theta_j = 2 pi j / N``; ``E`` is
    ``(2H + 1, N)``, the discrete Fourier coefficients, with ``E @ T = I``.
    """
    theta = 2.0 * np.pi * np.arange(samples) / samples
    T = np.ones((samples, 2 * harmonics + 1))
    for h in range(1, harmonics + 1):
        T[:, 2 * h - 1] = np.cos(h * theta)
        T[:, 2 * h] = np.sin(h * theta)
    E = T.T * (2.0 / samples)
    E[0] *= 0.5
    return T, E


class _PeriodicContact:
    """One contact's kernel, evaluated along prescribed periods (no validation per call)."""

    def __init__(self, contact):
        self.model = contact.model
        self.kernel = contact.model.step_kernel(None, fixed_load=True)
        kernel = self.kernel
        self.memoryless = kernel.rest_capacity is not None
        self.mount = RIGID.copy() if kernel.mount is None else kernel.mount.copy()
        self.virgin_state = kernel.state.copy()
        self.virgin_mount = self.mount.copy()
        self.start_state = np.empty_like(kernel.state)
        self.start_mount = np.empty_like(self.mount)
        self.lead_force = np.zeros(2)
        self.lead_tangent = np.zeros(2)

    def period(self, u, mean, period):
        """The force and ``dF/du`` at the ``N`` samples of ``u``, starting unloaded at ``mean``."""
        kernel = self.kernel
        count = u.shape[0]
        state = self.virgin_state.copy()
        mount = self.virgin_mount.copy()
        step = period / count
        run = kernel.runners.period
        # The lead-in: one step from the mean to the first sample.
        run((self.memoryless, mount, kernel.scalars, kernel.table, state, kernel.scratch,
             self.start_state, self.start_mount, np.array([0.0, step]),
             np.array([mean, u[0]]), kernel.normal_load, 1, math.inf, self.lead_force,
             self.lead_tangent))
        t = np.arange(count + 1) * step
        path = np.append(u, u[0])
        force = np.zeros(count + 1)
        tangent = np.zeros(count + 1)
        used = run((self.memoryless, mount, kernel.scalars, kernel.table, state,
                    kernel.scratch, self.start_state, self.start_mount, t, path,
                    kernel.normal_load, CYCLES, PERIODIC_TOLERANCE, force, tangent))
        if used < 0:
            raise InputError(f"A '{self.model.type}' contact did not settle on a periodic "
                             f"state within {CYCLES} periods at the period {period!r} s.")
        force[0], tangent[0] = force[count], tangent[count]
        return force[:count], tangent[:count]

    def initial_tangent(self, period, samples):
        """The contact's tangent at rest [N/m]: its stiffness while it sticks (``k_c``)."""
        _, tangent = self.period(np.zeros(samples), 0.0, period)
        value = float(np.max(tangent))
        return value if math.isfinite(value) else 0.0


def force_harmonics(structure, force, static_force, harmonics, owner):
    """The applied force's complex harmonics ``(H + 1, n)``: row 0 the static force, row h ``F`` of ``Re(F e^{i h w t})``."""
    n = structure.size
    out = np.zeros((harmonics + 1, n), dtype=np.complex128)
    for name, value, rows in (("force", force, slice(1, None)),
                              ("static_force", static_force, slice(0, 1))):
        if value is None:
            continue
        try:
            array = np.array(value, dtype=np.complex128)
        except (TypeError, ValueError):
            raise InputError(f"The '{name}' of {owner} must be numbers. Got "
                             f"{describe(value)} instead.") from None
        if array.ndim == 0 and n == 1:
            array = array.reshape(1, 1)
        elif array.ndim == 1 and array.shape[0] == n:
            array = array.reshape(1, n)
        elif not (array.ndim == 2 and array.shape[1] == n and name == "force"):
            raise InputError(f"The '{name}' of {owner} must be {n} numbers (one per "
                             f"coordinate){' or (K, n) harmonics 1 to K' if name == 'force' else ''}. "
                             f"Got shape {array.shape} instead.")
        if not np.isfinite(array).all():
            raise InputError(f"The '{name}' of {owner} must be finite. Got "
                             f"{array.tolist()!r} instead.")
        if name == "static_force" and np.any(array.imag != 0.0):
            raise InputError(f"The 'static_force' of {owner} must be real. Got "
                             f"{array.tolist()!r} instead.")
        if array.shape[0] > (harmonics if name == "force" else 1):
            raise InputError(f"The 'force' of {owner} has {array.shape[0]} harmonics, more "
                             f"than the 'harmonics' ({harmonics}) balanced.")
        start = rows.start
        out[start:start + array.shape[0]] = array
    return out


class PeriodicProblem:
    """The condensed harmonic-balance equations of a structure (this module's docstring).

    Parameters
    ----------
    structure : Structure
        At least one contact.
    harmonics, samples : int
        ``H`` and ``N`` (validated by the caller, :func:`check_harmonics`).
    owner : str
        The function named in error messages.
    """

    def __init__(self, structure, harmonics, samples, owner, reference_period):
        if not isinstance(structure, Structure):
            raise InputError(f"The 'structure' of {owner} must be a polind.Structure. Got "
                             f"{describe(structure)} instead.")
        if not structure.contacts:
            raise InputError(f"The structure of {owner} has no contacts: add one with "
                             f"Structure.add_contact(model, dofs).")
        self.structure = structure
        self.owner = owner
        self.harmonics = harmonics
        self.samples = samples
        n, m = structure.size, len(structure.contacts)
        self.n, self.m = n, m
        self.B = np.zeros((m, n))
        for c, contact in enumerate(structure.contacts):
            self.B[c, contact.first] = 1.0
            if contact.second is not None:
                self.B[c, contact.second] = -1.0
        self.contacts = [_PeriodicContact(contact) for contact in structure.contacts]
        self.T, self.E = basis(harmonics, samples)
        self.evaluations = 0
        self.stuck_tangents(reference_period)

    def stuck_tangents(self, period):
        """Take each contact's tangent at rest ``k_c`` at steps of ``period / N`` (a rate
        term's share depends on the step)."""
        self.k_c = np.array([contact.initial_tangent(period, self.samples)
                             for contact in self.contacts])
        self._contact_shift = np.kron(np.diag(self.k_c), np.eye(2 * self.harmonics))
        self._condensed = {}

    # -- the contacts along a period -------------------------------------------------------

    def contact_forces(self, coefficients, omega, differences=False):
        """Each contact's force coefficients ``(m, 2H + 1)`` and Jacobian ``(m, 2H, 2H)`` in its oscillating coefficients.

        The Jacobian is the tangent one (``E diag(dF/du) T``), or with
        ``differences`` forward differences of each oscillating coefficient
        (``2H`` more periods of each contact): exact where a reversal point
        moves the loop, which the tangent one is not.
        """
        period = 2.0 * np.pi / omega
        u = coefficients @ self.T.T                      # (m, N)
        forces = np.empty((self.m, 2 * self.harmonics + 1))
        jacobians = np.empty((self.m, 2 * self.harmonics, 2 * self.harmonics))
        osc_T = self.T[:, 1:]
        osc_E = self.E[1:]
        for c, contact in enumerate(self.contacts):
            mean = float(coefficients[c, 0])
            force, tangent = contact.period(u[c], mean, period)
            forces[c] = self.E @ force
            if not differences:
                jacobians[c] = osc_E @ (tangent[:, None] * osc_T)
                continue
            delta = 1e-7 * max(float(np.abs(coefficients[c, 1:]).max()), 1e-300)
            for k in range(2 * self.harmonics):
                shifted, _ = contact.period(u[c] + delta * osc_T[:, k], mean, period)
                jacobians[c, :, k] = osc_E @ (shifted - force) / delta
        self.evaluations += 1
        if not np.isfinite(forces).all():
            raise InputError(f"A contact's force of {self.owner} is not finite at "
                             f"omega = {omega!r} rad/s.")
        return forces, jacobians

    # -- the linear part --------------------------------------------------------------------

    def dynamic_stiffnesses(self, omega, k_c=None, xi=0.0):
        """``(H, n, n)``: ``K + B^T diag(k_c) B - (h w)^2 M + i h w (C - xi M)``, h = 1..H."""
        s = self.structure
        h = np.arange(1, self.harmonics + 1)[:, None, None]
        stiffness = s.stiffness if k_c is None else s.stiffness + self.B.T @ (k_c[:, None]
                                                                             * self.B)
        return stiffness - (h * omega) ** 2 * s.mass + 1j * h * omega * (s.damping
                                                                         - xi * s.mass)

    def condensed(self, omega, applied):
        """``(G_h, U_lin_h, G_real)`` for h = 1..H: ``B D_h^-1 B^T`` ``(H, m, m)``, ``B D_h^-1 f_h`` ``(H, m)``.

        ``G_real`` is ``G`` as the real matrix on the flattened coefficients
        (:func:`real_blocks`).  The last few frequencies' are kept: a
        continuation step evaluates the same ones many times.
        """
        key = (float(omega), id(applied))
        cached = self._condensed.get(key)
        if cached is not None:
            return cached
        G, linear = self._condense(omega, applied, self.k_c)
        if len(self._condensed) >= 4:
            self._condensed.pop(next(iter(self._condensed)))
        value = (G, linear, real_blocks(G))
        self._condensed[key] = value
        return value

    def _condense(self, omega, applied, k_c):
        D = self.dynamic_stiffnesses(omega, k_c)
        rhs = np.concatenate([np.broadcast_to(self.B.T, (self.harmonics,) + self.B.T.shape),
                              applied[1:, :, None]], axis=2)
        try:
            solved = np.linalg.solve(D, rhs)
        except np.linalg.LinAlgError:
            raise InputError(f"The structure of {self.owner} is singular at a harmonic of "
                             f"omega = {omega!r} rad/s (an undamped resonance): add damping or "
                             f"move the frequency.") from None
        return self.B @ solved[:, :, :self.m], (self.B @ solved[:, :, self.m:])[:, :, 0]

    def linear_scale(self, applied, start, stop, count=200):
        """The largest contact displacement [m] of the linear structure over ``[start, stop]``.

        Both with the contacts stuck (their tangents at rest) and without
        them: the scale of a frequency response's displacements.
        """
        largest = 0.0
        for k_c in (self.k_c, np.zeros_like(self.k_c)):
            for omega in np.linspace(start, stop, count):
                try:
                    linear = self._condense(omega, applied, k_c)[1]
                except InputError:
                    continue
                largest = max(largest, float(np.abs(linear).max()))
        return largest

    # -- the condensed residual ---------------------------------------------------------------

    def residual(self, x, omega, applied, condensed=None, jacobian=True, differences=False):
        """``r(x)`` and ``dr/dx`` of the oscillating contact coefficients ``x`` (``m 2H``)."""
        H, m = self.harmonics, self.m
        G, linear, Gr = self.condensed(omega, applied) if condensed is None else condensed
        coefficients = np.zeros((m, 2 * H + 1))
        coefficients[:, 1:] = x.reshape(m, 2 * H)
        forces, jacobians = self.contact_forces(coefficients, omega, differences)
        U = to_complex(coefficients)                     # (H, m)
        Fh = to_complex(forces)
        r = U - linear + np.einsum("hab,hb->ha", G, Fh - self.k_c * U)
        residual = to_real(r).reshape(-1)
        if not jacobian:
            return residual, forces
        JF = scipy.linalg.block_diag(*jacobians) - self._contact_shift
        return residual, np.eye(m * 2 * H) + Gr @ JF, forces

    def linear_guess(self, omega, applied):
        """The stuck structure's contact coefficients: ``U_h = B D_h^-1 f_h``."""
        return to_real(self.condensed(omega, applied)[1]).reshape(-1)

    def solve(self, x0, omega, applied, tolerance, max_iterations):
        """``(x, evaluations, error, forces)``: the oscillating contact coefficients at ``omega``
        from ``x0``, the periodic evaluations taken, the relative residual and the contacts'
        force coefficients at ``x``."""
        condensed = self.condensed(omega, applied)
        scale = max(float(np.abs(condensed[1]).max(initial=0.0)), float(np.abs(x0).max(initial=0.0)))
        if scale == 0.0:
            x = np.zeros_like(x0)
            return x, 0, 0.0, self.residual(x, omega, applied, condensed, jacobian=False)[1]

        before = self.evaluations
        x, error, forces = x0, math.inf, None
        for differences in (False, True):
            # The tangent Jacobian first; forward differences where it stalls.
            def fun(z, differences=differences):
                r, J, _ = self.residual(z * scale, omega, applied, condensed,
                                        differences=differences)
                return r / scale, J

            solution = scipy.optimize.root(fun, x / scale, jac=True, method="hybr",
                                           options={"xtol": tolerance,
                                                    "maxfev": max_iterations})
            trial = solution.x * scale
            r, trial_forces = self.residual(trial, omega, applied, condensed, jacobian=False)
            trial_error = float(np.abs(r).max()) / scale
            if trial_error < error:
                x, error, forces = trial, trial_error, trial_forces
            if error <= 1e3 * tolerance:
                break
        return x, self.evaluations - before, error, forces

    def coordinates(self, x, omega, applied, forces):
        """Every coordinate's coefficients ``(n, 2H + 1)`` and the contacts' ``(m, 2H + 1)``."""
        H, n, m = self.harmonics, self.n, self.m
        U = np.zeros((m, 2 * H + 1))
        U[:, 1:] = x.reshape(m, 2 * H)
        rhs = applied[1:] - (to_complex(forces) - self.k_c * to_complex(U)) @ self.B
        Qh = np.linalg.solve(self.dynamic_stiffnesses(omega, self.k_c), rhs[:, :, None])[:, :, 0]
        Q = np.zeros((n, 2 * H + 1))
        Q[:, 1:] = to_real(Qh)
        # The mean: K Q_0 = f_0 - B^T F_0, least squares (shift-invariant contacts).
        rhs = applied[0].real - self.B.T @ forces[:, 0]
        Q[:, 0] = np.linalg.lstsq(self.structure.stiffness, rhs, rcond=None)[0]
        return Q, self.B @ Q


def to_real(Qh):
    """``(H, rows)`` complex ``Q_c - i Q_s`` to ``(rows, 2H)`` real ``[c_1, s_1, c_2, s_2, ...]``."""
    H, n = Qh.shape
    out = np.empty((n, 2 * H))
    out[:, 0::2] = Qh.real.T
    out[:, 1::2] = -Qh.imag.T
    return out


def to_complex(coefficients):
    """``(rows, 2H + 1)`` real coefficients to ``(H, rows)`` complex ``c_h - i s_h``."""
    return (coefficients[:, 1::2] - 1j * coefficients[:, 2::2]).T


def real_blocks(G):
    """``(H, m, m)`` complex ``G_h`` as the real matrix acting on ``(m, 2H)`` coefficients (flattened).

    ``(a + i b)(z_c - i z_s) = (a z_c + b z_s) - i (a z_s - b z_c)``: the block
    of harmonic ``h`` is ``[[a, b], [-b, a]]`` on ``(z_c, z_s)``.
    """
    H, m, _ = G.shape
    a, b = G.real, G.imag                                  # (H, m, m)
    blocks = np.zeros((m, H, 2, m, H, 2))
    diagonal = np.arange(H)
    blocks[:, diagonal, 0, :, diagonal, 0] = a
    blocks[:, diagonal, 0, :, diagonal, 1] = b
    blocks[:, diagonal, 1, :, diagonal, 0] = -b
    blocks[:, diagonal, 1, :, diagonal, 1] = a
    return blocks.reshape(m * 2 * H, m * 2 * H)


@dataclass
class HarmonicBalanceResult:
    """One periodic steady state of :func:`harmonic_balance`.

    Attributes
    ----------
    omega : float
        The fundamental frequency [rad/s].
    harmonics : ndarray
        ``(n, 2H + 1)``: each coordinate's ``[Q_0, Q_c1, Q_s1, ..., Q_cH, Q_sH]`` [m].
    contact_displacement, contact_force : ndarray
        ``(m, 2H + 1)``: each contact's relative displacement [m] and force
        [N], in the same layout.
    residual : float
        The largest residual of the condensed equations, relative to the
        contacts' displacement scale.
    evaluations : int
        The periodic evaluations of the contacts the solution took.
    """

    omega: float
    harmonics: np.ndarray
    contact_displacement: np.ndarray
    contact_force: np.ndarray
    residual: float
    evaluations: int

    def amplitude(self, dof, harmonic=None):
        """The amplitude [m] of coordinate ``dof``: the largest ``|q - Q_0|`` over the period, or one harmonic's ``sqrt(c^2 + s^2)``."""
        return response_amplitude(self.harmonics[None], dof, harmonic)[0]

    def displacement(self, samples=256):
        """``(t, q)``: one period of every coordinate at ``samples`` times [s], [m]."""
        H = (self.harmonics.shape[1] - 1) // 2
        T, _ = basis(H, samples)
        t = np.arange(samples) * (2.0 * np.pi / self.omega / samples)
        return t, T @ self.harmonics.T


def response_amplitude(harmonics, dof, harmonic=None, samples=256):
    """``(P,)`` amplitudes of coordinate ``dof`` along ``(P, n, 2H + 1)`` coefficients."""
    count = harmonics.shape[1]
    if isinstance(dof, bool) or not isinstance(dof, (int, np.integer)) or not 0 <= dof < count:
        raise InputError(f"The 'dof' of amplitude must be a coordinate 0 to {count - 1}. Got "
                         f"{describe(dof)} instead.")
    H = (harmonics.shape[2] - 1) // 2
    values = harmonics[:, dof, :]
    if harmonic is not None:
        if isinstance(harmonic, bool) or not isinstance(harmonic, (int, np.integer)) \
                or not 1 <= harmonic <= H:
            raise InputError(f"The 'harmonic' of amplitude must be 1 to {H}. Got "
                             f"{describe(harmonic)} instead.")
        return np.hypot(values[:, 2 * harmonic - 1], values[:, 2 * harmonic])
    T, _ = basis(H, max(samples, 8 * H))
    return np.abs(values[:, 1:] @ T[:, 1:].T).max(axis=1)


def harmonic_balance(structure, omega, *, force=None, static_force=None, harmonics=7,
                     samples=None, initial=None, tolerance=1e-10, max_evaluations=400):
    """The periodic steady state of a structure under a periodic force (:ref:`guide-frequency-domain`).

    Harmonic balance with alternating frequency–time: each contact's force
    over a trial period is its model's own exact update along it, started
    unloaded at its mean displacement and stepped until its state repeats
    (this module's docstring gives the equations and the choices).

    Parameters
    ----------
    structure : Structure
        Matrices and contacts (at least one).
    omega : float
        The fundamental frequency [rad/s], positive.
    force : array_like, optional
        The applied force's harmonics [N]: ``(n,)`` for ``f(t) = Re(F e^{i
        omega t})`` (real ``F``: ``F cos omega t``), or ``(K, n)`` for the
        harmonics 1 to ``K <= H``.
    static_force : array_like, optional
        ``(n,)`` constant force [N] (a preload).
    harmonics : int, default 7
        ``H``: the harmonics balanced.
    samples : int, optional
        ``N >= 4H + 1`` samples per period (default
        :func:`~polind.structures.harmonic.default_samples`: 128 for ``H <= 16``; with
        hysteretic contacts ``4H + 1`` errs by tenths of a per cent).
    initial : HarmonicBalanceResult, optional
        A solution to start from (default: the stuck structure's response).
    tolerance : float, default 1e-10
        The solver's relative tolerance on the contacts' coefficients.
    max_evaluations : int, default 400
        The most periodic evaluations of the contacts.

    Returns
    -------
    HarmonicBalanceResult
    """
    owner = "harmonic_balance"
    omega = check_number(owner, "omega", omega, "positive")
    harmonics, samples = check_harmonics(owner, harmonics, samples)
    tolerance = check_number(owner, "tolerance", tolerance, "positive")
    max_evaluations = check_number(owner, "max_evaluations", max_evaluations, "positive",
                                   integer=True)
    problem = PeriodicProblem(structure, harmonics, samples, owner, 2.0 * np.pi / omega)
    applied = force_harmonics(structure, force, static_force, harmonics, owner)
    if initial is not None:
        if not isinstance(initial, HarmonicBalanceResult) or \
                initial.contact_displacement.shape != (problem.m, 2 * harmonics + 1):
            raise InputError(f"The 'initial' of {owner} must be a HarmonicBalanceResult of "
                             f"this structure with {harmonics} harmonics. Got "
                             f"{describe(initial)} instead.")
        x0 = initial.contact_displacement[:, 1:].reshape(-1)
    else:
        x0 = problem.linear_guess(omega, applied)
    x, evaluations, error, forces = problem.solve(x0, omega, applied, tolerance,
                                                  max_evaluations)
    if not error <= 1e3 * tolerance:
        raise InputError(f"The harmonic balance of {owner} did not converge at omega = "
                         f"{omega!r} rad/s: the residual is {error:.3g} of the displacement "
                         f"scale after {evaluations} evaluations. Give more 'harmonics', "
                         f"'samples' or 'max_evaluations', or start from a nearby 'initial'.")
    return build_result(problem, x, forces, omega, applied, error, evaluations)


def build_result(problem, x, forces, omega, applied, error, evaluations):
    """A :class:`HarmonicBalanceResult` from the solved oscillating contact coefficients ``x``
    and the contacts' force coefficients there (``forces``, from the residual's evaluation)."""
    Q, U = problem.coordinates(x, omega, applied, forces)
    return HarmonicBalanceResult(omega=float(omega), harmonics=Q, contact_displacement=U,
                                 contact_force=forces, residual=float(error),
                                 evaluations=int(evaluations))
