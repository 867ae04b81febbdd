"""Single-asperity contact laws: Hertz, elastic slip, Cattaneo–Mindlin, Masing.

The user guide, :ref:`guide-pol-ind-asperity`.

One spherical summit of radius ``R`` pressed against a rigid flat by the
interference ``delta = h - d`` [m].  The normal law is Hertz's; the
tangential law is either the elastic-slip element of the modified
Maxwell-slip structure (stiffness ``8 G* a``, capacity ``mu P``) or the
Cattaneo–Mindlin partial-slip curve, with Masing's rule and the usual
loop-closing memory for displacement paths with reversals.

All functions accept numpy arrays (or scalars) for the displacement-like
argument and broadcast; a non-positive interference means no contact and
gives zero load, radius, stiffness and capacity.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from polind.errors import InputError

__all__ = [
    "hertz_load",
    "contact_radius",
    "tangential_stiffness",
    "slip_capacity",
    "mindlin_slip_displacement",
    "mindlin_force",
    "masing_force",
]


def hertz_load(interference, E_star: float, R: float):
    """Hertz normal load of one asperity, ``P = (4/3) E* sqrt(R) delta^(3/2)``.

    Parameters
    ----------
    interference : float or array_like
        Interference ``delta = h - d`` [m]; non-positive values (no contact)
        give zero load.
    E_star : float
        Effective modulus ``E*`` [Pa].
    R : float
        Summit radius [m].

    Returns
    -------
    numpy.ndarray or float
        Normal load ``P`` [N], same shape as ``interference``.

    Examples
    --------
    >>> round(float(hertz_load(1e-6, 1e11, 1e-4)), 9)   # (4/3) 1e11 1e-2 1e-9
    1.333333333
    """
    delta = np.maximum(np.asarray(interference, dtype=float), 0.0)
    return (4.0 / 3.0) * E_star * math.sqrt(R) * delta * np.sqrt(delta)


def contact_radius(interference, R: float):
    """Hertz contact radius ``a = sqrt(R delta)`` [m] (zero out of contact).

    Parameters
    ----------
    interference : float or array_like
        Interference ``delta`` [m].
    R : float
        Summit radius [m].

    Returns
    -------
    numpy.ndarray or float
        Contact radius ``a`` [m].
    """
    return np.sqrt(R * np.maximum(np.asarray(interference, dtype=float), 0.0))


def tangential_stiffness(interference, R: float, G_star: float):
    """Elastic tangential stiffness of one asperity, ``k_t = 8 G* a`` [N/m].

    This is the stiffness of the elastic-slip element of the Pol-Ind elements
    (:ref:`guide-pol-ind-elements`) and
    the initial slope of the Cattaneo–Mindlin curve.

    Parameters
    ----------
    interference : float or array_like
        Interference ``delta`` [m].
    R : float
        Summit radius [m].
    G_star : float
        Effective tangential modulus ``G*`` [Pa].

    Returns
    -------
    numpy.ndarray or float
        Tangential stiffness [N/m].
    """
    return 8.0 * G_star * contact_radius(interference, R)


def slip_capacity(interference, E_star: float, R: float, mu: float):
    """Tangential force at which one asperity slips, ``mu P`` [N].

    Parameters
    ----------
    interference : float or array_like
        Interference ``delta`` [m].
    E_star : float
        Effective modulus ``E*`` [Pa].
    R : float
        Summit radius [m].
    mu : float
        Static friction coefficient ``mu_s`` [-].

    Returns
    -------
    numpy.ndarray or float
        Slip (break-away) force of the asperity [N].
    """
    return mu * hertz_load(interference, E_star, R)


def mindlin_slip_displacement(P, a, mu: float, G_star: float):
    """Displacement at which Cattaneo–Mindlin contact slips fully, ``u* = 3 mu P / (16 G* a)`` [m].

    Parameters
    ----------
    P : float or array_like
        Normal load [N].
    a : float or array_like
        Contact radius [m].
    mu : float
        Friction coefficient [-].
    G_star : float
        Effective tangential modulus [Pa].

    Returns
    -------
    numpy.ndarray or float
        Full-slip displacement [m]; zero where the asperity carries no load.
    """
    P = np.asarray(P, dtype=float)
    a = np.asarray(a, dtype=float)
    loaded = (P > 0.0) & (a > 0.0)
    return np.where(loaded, 3.0 * mu * P / (16.0 * G_star * np.where(loaded, a, 1.0)), 0.0)


def mindlin_force(u, P, a, mu: float, G_star: float):
    """Cattaneo–Mindlin virgin curve of one asperity at constant normal load.

    ``Q(u) = mu P [1 - (1 - |u|/u*)^(3/2)] sgn(u)`` for ``|u| <= u*`` and
    ``mu P sgn(u)`` beyond, with ``u* = 3 mu P / (16 G* a)``; odd in ``u``,
    initial slope ``8 G* a``.

    Parameters
    ----------
    u : float or array_like
        Tangential displacement from the unloaded state [m].
    P : float or array_like
        Normal load [N].
    a : float or array_like
        Contact radius [m].
    mu : float
        Friction coefficient [-].
    G_star : float
        Effective tangential modulus [Pa].

    Returns
    -------
    numpy.ndarray or float
        Tangential force ``Q`` [N].

    Examples
    --------
    >>> P, a, mu, G = 1.0, 1e-5, 0.5, 1e10
    >>> u_star = 3 * mu * P / (16 * G * a)
    >>> float(mindlin_force(u_star, P, a, mu, G)), float(mindlin_force(-2 * u_star, P, a, mu, G))
    (0.5, -0.5)
    """
    u = np.asarray(u, dtype=float)
    capacity = mu * np.asarray(P, dtype=float)
    u_star = mindlin_slip_displacement(P, a, mu, G_star)
    # Fraction of u* reached, capped at full slip; the unloaded asperity
    # (u* = 0) carries nothing whatever the displacement.
    reached = np.minimum(np.abs(u) / np.where(u_star > 0.0, u_star, 1.0), 1.0)
    shape = 1.0 - (1.0 - reached) ** 1.5
    return np.where(u_star > 0.0, np.sign(u) * capacity * shape, 0.0)


@njit(cache=True)
def _mindlin_virgin(u, capacity, u_star):
    """Scalar Cattaneo–Mindlin virgin curve (``capacity = mu P``)."""
    if u_star <= 0.0:
        return 0.0
    reached = min(abs(u) / u_star, 1.0)
    value = capacity * (1.0 - (1.0 - reached) ** 1.5)
    return value if u >= 0.0 else -value


@njit(cache=True)
def _masing_path(displacement, capacity, u_star, out):
    """Masing/Iwan force along a path; reversal points kept on a stack.

    ``out[k]`` is the force at ``displacement[k]``; the path starts from the
    virgin state at ``u = 0``.
    """
    n = displacement.size
    # At most one reversal per sample, so n slots are enough.
    reversal_u = np.empty(n + 1)
    reversal_q = np.empty(n + 1)
    top = 0
    direction = 0
    previous_u = 0.0
    previous_q = 0.0
    for k in range(n):
        x = displacement[k]
        step = x - previous_u
        if step != 0.0:
            heading = 1 if step > 0.0 else -1
            if direction != 0 and heading != direction:
                reversal_u[top] = previous_u
                reversal_q[top] = previous_q
                top += 1
            direction = heading
            # Memory rule: a branch that passes the reversal point it was
            # heading back to closes that loop, and both reversals are
            # forgotten; the first branch off the virgin curve rejoins it at
            # the mirror image -u_1 of its reversal point.
            while top > 0:
                if top >= 2:
                    if direction * (x - reversal_u[top - 2]) >= 0.0:
                        top -= 2
                        continue
                elif direction * (x + reversal_u[0]) >= 0.0:
                    top = 0
                    continue
                break
            if top == 0:
                q = _mindlin_virgin(x, capacity, u_star)
            else:
                u_r = reversal_u[top - 1]
                q = reversal_q[top - 1] - 2.0 * _mindlin_virgin(0.5 * (u_r - x), capacity, u_star)
        else:
            q = previous_q
        out[k] = q
        previous_u = x
        previous_q = q


def masing_force(displacement, P: float, a: float, mu: float, G_star: float):
    """Tangential force of one asperity along a displacement path with reversals.

    The asperity starts unloaded at ``u = 0``; it follows the Cattaneo–Mindlin
    virgin curve (:func:`mindlin_force`) until the first reversal; from a
    reversal ``(u_r, Q_r)`` it follows Masing's branch
    ``Q = Q_r - 2 Q_virgin((u_r - u) / 2)``.  Reversal points are kept on a
    stack (Iwan's memory rules): a branch that reaches the reversal point
    where the previous branch began closes that loop, both points are wiped
    out and the path continues on the older branch; the first branch off the
    virgin curve rejoins it at ``-u_1``.  This is exact, the continuum limit
    of a Maxwell-slip (Iwan) model whose slip displacements are distributed
    to reproduce the Mindlin curve; turning points are the samples where the
    direction of motion changes.

    Parameters
    ----------
    displacement : array_like
        1-D tangential displacement path [m], one sample per entry.
    P : float
        Normal load, constant along the path [N].
    a : float
        Contact radius [m].
    mu : float
        Friction coefficient [-].
    G_star : float
        Effective tangential modulus [Pa].

    Returns
    -------
    numpy.ndarray
        Tangential force ``Q`` [N] at every sample.

    Examples
    --------
    >>> import numpy as np
    >>> P, a, mu, G = 1.0, 1e-5, 0.5, 1e10
    >>> u_star = 3 * mu * P / (16 * G * a)
    >>> path = u_star * np.array([0.5, 0.0, -0.5, 0.0, 0.5])
    >>> Q = masing_force(path, P, a, mu, G)
    >>> bool(np.isclose(Q[-1], Q[0]))            # the loop closes
    True
    """
    path = np.ascontiguousarray(displacement, dtype=float)
    if path.ndim != 1:
        raise InputError(
            f"The 'displacement' path of masing_force must be 1-D. Got shape {path.shape}."
        )
    u_star = float(mindlin_slip_displacement(P, a, mu, G_star))
    out = np.empty_like(path)
    _masing_path(path, float(mu * P), u_star, out)
    return out
