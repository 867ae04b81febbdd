"""Greenwood–Williamson integrals of the Gaussian summit-height distribution.

The user guide, :ref:`guide-pol-ind-summation`.

``F_m(s) = ∫_s^∞ (t - s)^m phi(t) dt`` with ``phi`` the standard normal
density, in the normalised variable ``s = d / sigma_a``.  The statistical
surface needs ``F_0`` (asperities in contact), ``F_1`` (real area),
``F_{3/2}`` (normal load) and ``F_{1/2}`` (its slope, since
``dF_m/ds = -m F_{m-1}``).

Representations, chosen for relative accuracy over ``s`` in [-5, 10] (the
range the separation solver allows).  The separation solver itself runs on
the kernels' piecewise-polynomial pair
(:func:`polind.kernels.greenwood.gw_half_integer_pair_fast`, 5e-15
relative); these are the references it is tested against:

- ``F_0 = erfc(s/√2)/2``; ``F_1 = phi(s) - s F_0(s)``, written with
  ``erfcx`` for ``s >= 0`` so that nothing underflows before the difference.
- ``F_{1/2}``, ``F_{3/2}``: ``F_m(s) = Γ(m+1) phi(s) e^{s²/4} D_{-m-1}(s)``
  with the parabolic-cylinder functions of half-integer order written as
  modified Bessel functions of order ±1/4, ±3/4 at ``w = s²/4``:

  * ``s > 0``:  ``F_{-1/2} = √s e^{-s²/2} K_{1/4}(w) / (2√π)``,
    ``F_{1/2} = s^{3/2} e^{-s²/2} [K_{3/4}(w) - K_{1/4}(w)] / (4√π)``;
  * ``s = -x < 0``: ``F_{-1/2} = √π √x [I_{-1/4} + I_{1/4}](w) e^{-w} / (2√2)``,
    ``F_{1/2} = √π x^{3/2} [I_{-3/4} + I_{-1/4} + I_{1/4} + I_{3/4}](w) e^{-w} / (4√2)``;
  * then ``F_{3/2} = F_{-1/2}/2 - s F_{1/2}`` (integration by parts);
  * ``|s| < 1e-8``: first-order Taylor series about 0, because the Bessel
    forms are ``0·∞`` at ``s = 0``.

  These formulas have one implementation, compiled:
  :func:`polind.kernels.greenwood.gw_half_integer_pair`, which the kernels
  call and which :func:`half_integer_pair` calls on one float and
  :func:`gw_integral` on every element of an array
  (:func:`polind.kernels.greenwood.gw_half_integer_pairs`).
  The exponentially scaled ``scipy.special.kve``/``ive`` keep every factor in
  range.  ``scipy.special.pbdv`` was rejected: its relative error reaches
  1e-9 near ``s = 6`` and it is about 5x slower.  Measured against
  arbitrary-precision quadrature on [-5, 10]: relative error below 4e-13 for
  ``F_{1/2}`` and 3e-12 for ``F_{3/2}`` (largest near ``s = 2.8``, where
  ``K_{3/4} - K_{1/4}`` cancels most), below 1e-14 for ``F_0`` and ``F_1``.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy import special

from polind.errors import InputError, describe
from polind.kernels.greenwood import gw_half_integer_pair, gw_half_integer_pairs
from polind.kernels.interpreted import interpreted
from polind.kernels.special import special_addresses

__all__ = ["gw_integral", "half_integer_pair", "three_halves_inverse", "VALID_RANGE"]

#: The range of ``s = d / sigma_a`` over which the integrals are verified to
#: 1e-10 relative accuracy and which the separation solver accepts.
VALID_RANGE = (-5.0, 10.0)

_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)
_SQRT_2 = math.sqrt(2.0)


def _addresses():
    """SciPy's Bessel addresses as the model kernels hold them (float64, writable): one compile."""
    return special_addresses().astype(np.float64)


def half_integer_pair(s: float) -> tuple[float, float]:
    """``(F_{1/2}(s), F_{3/2}(s))`` for one float ``s``, as Python floats.

    :func:`polind.kernels.greenwood.gw_half_integer_pair`, the one
    implementation of the formulas above, run by Python
    (:func:`polind.kernels.interpreted.interpreted`: the compiled kernel's
    results to the bit, about 10 microseconds a call, nearly all of them in
    SciPy's Bessel functions), so that a process asking a few values of one
    surface (a model built at one load) compiles none of it.

    Parameters
    ----------
    s : float
        Normalised separation ``d / sigma_a`` [-].

    Returns
    -------
    tuple of float
        ``F_{1/2}(s)`` and ``F_{3/2}(s)``; ``(0, 0)`` at ``+inf``,
        ``(inf, inf)`` at ``-inf``, NaN for NaN.
    """
    return interpreted(gw_half_integer_pair)(float(s), _addresses())


def _upper_tail(s):
    """``F_0(s) = Q(s)``, the standard normal upper tail."""
    return 0.5 * special.erfc(s / _SQRT_2)


def _first_moment(s):
    """``F_1(s) = phi(s) - s Q(s)``."""
    s = np.asarray(s, dtype=float)
    with np.errstate(over="ignore", invalid="ignore"):
        # For s >= 0, pull e^{-s²/2} out of both terms (erfcx) so the
        # difference is formed before anything can underflow.
        scaled = np.exp(-0.5 * s * s) * (_INV_SQRT_2PI - 0.5 * s * special.erfcx(s / _SQRT_2))
        direct = _INV_SQRT_2PI * np.exp(-0.5 * s * s) - s * _upper_tail(s)
        value = np.where(s >= 0.0, scaled, direct)
    return np.where(s == np.inf, 0.0, value)


def gw_integral(m, s):
    """Greenwood–Williamson integral ``F_m(s) = ∫_s^∞ (t - s)^m phi(t) dt``.

    Parameters
    ----------
    m : {0, 0.5, 1, 1.5}
        Order: 0 gives the fraction of summits in contact, 1 the mean
        interference, 3/2 the Hertz load and 1/2 its slope
        (:ref:`guide-pol-ind-summation`).
    s : float or array_like
        Normalised separation ``d / sigma_a`` [-].  Accurate to 1e-10
        relative (measured: 3e-12) on :data:`VALID_RANGE` = [-5, 10].

    Returns
    -------
    numpy.ndarray or float
        ``F_m(s)``, same shape as ``s`` (a float for a scalar ``s``).

    Raises
    ------
    polind.InputError
        If ``m`` is not one of 0, 1/2, 1, 3/2.

    Examples
    --------
    >>> round(float(gw_integral(1.5, 0.0)), 6), round(float(gw_integral(1.5, 1.0)), 7)
    (0.43002, 0.0756682)
    """
    order = float(m) if isinstance(m, (int, float, np.integer, np.floating)) else None
    if order not in (0.0, 0.5, 1.0, 1.5):
        raise InputError(
            f"The order 'm' of gw_integral must be one of 0, 0.5, 1, 1.5. Got {describe(m)}."
        )
    s_array = np.asarray(s, dtype=float)
    if order == 0.0:
        value = _upper_tail(s_array)
    elif order == 1.0:
        value = _first_moment(s_array)
    elif s_array.ndim == 0:
        # One float: the scalar pair, run by Python (a process that asks one load of a
        # surface compiles nothing for it).
        value = half_integer_pair(float(s_array))[0 if order == 0.5 else 1]
    else:
        # The compiled pair at every element (polind.kernels.greenwood).
        f_half, f_three_halves = gw_half_integer_pairs(np.ravel(s_array), _addresses())
        value = (f_half if order == 0.5 else f_three_halves).reshape(s_array.shape)
    return float(value) if np.ndim(s) == 0 else value


@lru_cache(maxsize=1)
def _log_three_halves_table() -> tuple[np.ndarray, np.ndarray]:
    """``log F_{3/2}`` on a grid over a little more than :data:`VALID_RANGE`, increasing."""
    grid = np.linspace(VALID_RANGE[0] - 1.0, VALID_RANGE[1] + 1.0, 321)
    # gw_integral(1.5, grid) point by point with the scalar pair run by Python (about
    # 3 ms), so that a process that solves one separation (every Pol-Ind model's first
    # run) compiles neither pair; the same bits.
    values = np.array([half_integer_pair(float(s))[1] for s in grid])
    # Reversed so that the tabulated values increase, as np.interp needs.
    return np.log(values)[::-1].copy(), grid[::-1].copy()


def three_halves_inverse(value: float) -> float:
    """Approximate ``s`` with ``F_{3/2}(s) = value`` (a starting point for Newton).

    Linear interpolation of ``log F_{3/2}`` tabulated at spacing 0.05: the
    error in ``s`` is below 1e-3 inside :data:`VALID_RANGE`, so a Newton
    iteration from it needs two or three steps.  Outside the table the end
    values are returned.

    Parameters
    ----------
    value : float
        Target ``F_{3/2}`` [-], positive.

    Returns
    -------
    float
        Approximate normalised separation ``s`` [-].
    """
    log_values, grid = _log_three_halves_table()
    return float(np.interp(math.log(value), log_values, grid))
