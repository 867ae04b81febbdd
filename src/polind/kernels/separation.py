"""The separation under a normal load, inside numba kernels (MODELS.md 7.3–7.4).

Kernel versions of the Greenwood–Williamson load integrals and of the
safeguarded Newton iteration of :mod:`polind.contact.separation`, so that a
model kernel can re-solve the separation ``d`` for a new normal load at
every sample without returning to Python:

- :func:`gw_half_integer_pair`: ``(F_{1/2}(s), F_{3/2}(s))`` with
  ``F_m(s) = ∫_s^∞ (t - s)^m phi(t) dt``, the same branches, formulas and
  Taylor cut-off as :func:`polind.contact.greenwood.half_integer_pair`
  (modified Bessel functions of order ±1/4, ±3/4 from SciPy, through
  :mod:`polind.kernels.special`);
- :func:`statistical_load_and_slope` and :func:`direct_load_and_slope`:
  ``(N(d), dN/dd)`` of the statistical (Gaussian) and the direct
  (summed summits) surface, as their ``load_and_slope`` methods;
- :func:`newton_separation`: Newton on ``log N(d) = log N_app`` kept in a
  bracket, bisection when a step leaves it, stopping at
  ``|N(d) - N_app| <= 1e-10 N_app``, returning the best ``d`` seen if the
  bracket shrinks to adjacent doubles; :func:`predicted_start` is the warm
  start from the previous solution and :func:`direct_lower_bound` the lower
  end of a direct surface's bracket.

A surface is passed as plain numbers and arrays: ``kind`` (:data:`STATISTICAL`
or :data:`DIRECT`), the statistical surface's ``load_scale`` =
``(4/3) eta A0 E* sqrt(R) sigma_a^(3/2)`` and ``height_std`` = ``sigma_a``,
the direct surface's ``heights`` (sorted ascending, distinct), ``counts``
(summits at each height, float) and ``hertz`` = ``(4/3) E* sqrt(R)``, and the
``addresses`` of :func:`polind.kernels.special.special_addresses`.  Arguments
a kind does not use may be anything of the right type (e.g. empty arrays).

These kernels are compiled without ``fastmath``: the ``F_{3/2}`` of
``s > 0`` is a difference of two terms that cancel by a factor of about
``s²/1.5`` (70 at ``s = 10``), so a fused multiply-add there would move the
result by tens of ulps, and the Newton path (iterations, stopping,
best-so-far) should be exactly that of the Python formulas.  For the same
reason they are not ``inline="always"``: inlined into a caller, they would
take the caller's fastmath flags.

Cost: a statistical load evaluation is two SciPy ``kve`` calls (``s > 0``)
or four ``ive`` calls (``s < 0``), 0.5–1.1 µs, nearly all of it inside
SciPy's AMOS code; a slowly varying load needs one evaluation per sample
after :func:`predicted_start`.  A direct evaluation is a sum over the
summits above ``d``.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.special import ive, kve

__all__ = [
    "STATISTICAL",
    "DIRECT",
    "RELATIVE_TOLERANCE",
    "MAX_ITERATIONS",
    "gw_half_integer_pair",
    "tail_moments",
    "statistical_load_and_slope",
    "direct_load_and_slope",
    "surface_load_and_slope",
    "direct_lower_bound",
    "predicted_start",
    "newton_separation",
    "newton_separation_counted",
    "newton_separation_series",
]

#: Surface kinds of the ``kind`` argument.
STATISTICAL, DIRECT = 0, 1

#: Required accuracy of the load balance, ``|N(d) - N_app| <= tol N_app``.
RELATIVE_TOLERANCE = 1e-10

#: Enough for bisection alone to shrink any float bracket to adjacent floats.
MAX_ITERATIONS = 2200

# The constants of polind.contact.greenwood, recomputed here because kernels
# must not import the contact layer (tests check that they are equal).
_SQRT_PI = math.sqrt(math.pi)
_SQRT_2 = math.sqrt(2.0)
# F_m(0) = 2^(m/2) Γ((m+1)/2) / (2√π), half the absolute moment E|Z|^m.
_F_MINUS_HALF_0 = 2.0**-0.25 * math.gamma(0.25) / (2.0 * _SQRT_PI)
_F_HALF_0 = 2.0**0.25 * math.gamma(0.75) / (2.0 * _SQRT_PI)
_F_THREE_HALVES_0 = 2.0**0.75 * math.gamma(1.25) / (2.0 * _SQRT_PI)
# Below this |s| the Bessel forms lose their scale (0·∞); the Taylor series'
# neglected s² term is then below 1e-16 relative.
_TAYLOR_BELOW = 1e-8
_GAUSS_DIVISOR = 4.0 * _SQRT_PI
_NEGATIVE_SCALE = _SQRT_PI / (4.0 * _SQRT_2)


@jit(fastmath=False)
def gw_half_integer_pair(s, addresses):
    """``(F_{1/2}(s), F_{3/2}(s))`` of the standard normal density (MODELS.md 7.3).

    The formulas of :func:`polind.contact.greenwood.half_integer_pair`:
    ``s > 1e-8`` with ``kve`` of orders 1/4 and 3/4, ``s < -1e-8`` with
    ``ive`` of orders ±1/4, ±3/4, both at ``w = s²/4``, and the first-order
    Taylor series about 0 in between.

    Parameters
    ----------
    s : float
        Normalised separation ``d / sigma_a`` [-].
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses`.

    Returns
    -------
    tuple of float
        ``F_{1/2}(s)`` and ``F_{3/2}(s)``; ``(0, 0)`` at ``+inf``,
        ``(inf, inf)`` at ``-inf``, NaN for NaN.
    """
    if s > _TAYLOR_BELOW:
        if s == math.inf:
            return 0.0, 0.0
        w = 0.25 * s * s
        k_quarter = kve(0.25, w, addresses)
        k_three_quarters = kve(0.75, w, addresses)
        gauss = math.exp(-0.5 * s * s) / _GAUSS_DIVISOR
        root = math.sqrt(s)
        f_half = s * root * gauss * (k_three_quarters - k_quarter)
        # F_{3/2} = F_{-1/2}/2 - s F_{1/2} (integration by parts).
        return f_half, root * gauss * k_quarter - s * f_half
    if s < -_TAYLOR_BELOW:
        if s == -math.inf:
            return math.inf, math.inf
        x = -s
        w = 0.25 * x * x
        i_quarter = ive(0.25, w, addresses) + ive(-0.25, w, addresses)
        i_three_quarters = ive(0.75, w, addresses) + ive(-0.75, w, addresses)
        root = math.sqrt(x)
        f_half = _NEGATIVE_SCALE * x * root * (i_quarter + i_three_quarters)
        # Both terms are positive here: no cancellation for s < 0.
        return f_half, _NEGATIVE_SCALE * root * i_quarter + x * f_half
    if s != s:
        return math.nan, math.nan
    return _F_HALF_0 - 0.5 * _F_MINUS_HALF_0 * s, _F_THREE_HALVES_0 - 1.5 * _F_HALF_0 * s


@jit(fastmath=False)
def statistical_load_and_slope(d, load_scale, height_std, addresses):
    """``(N(d), dN/dd)`` of the Gaussian surface summed statistically (MODELS.md 7.3).

    ``N = load_scale F_{3/2}(d/sigma_a)``, ``dN/dd = -(3/2) load_scale
    F_{1/2}(d/sigma_a) / sigma_a``, as
    :meth:`polind.contact.surface.StatisticalSurface.load_and_slope`.

    Parameters
    ----------
    d : float
        Separation [m].
    load_scale : float
        ``(4/3) eta A0 E* sqrt(R) sigma_a^(3/2)`` [N].
    height_std : float
        ``sigma_a`` [m].
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses`.

    Returns
    -------
    tuple of float
        ``N(d)`` [N] and ``dN/dd`` [N/m] (negative).
    """
    f_half, f_three_halves = gw_half_integer_pair(d / height_std, addresses)
    return load_scale * f_three_halves, -1.5 * load_scale / height_std * f_half


@jit(fastmath=False)
def tail_moments(heights, counts, d):
    """Sums over the summits above ``d`` of ``counts * delta^p``, ``p = 0, 1/2, 1, 3/2``.

    ``heights`` is sorted ascending, so the summits in contact are a tail;
    summing it from its lowest member adds the small terms first.  The one
    sum behind every total of a direct surface
    (:class:`polind.contact.surface.DirectSurface`) and its load here.
    """
    start = np.searchsorted(heights, d, side="right")
    number = 0.0
    root_sum = 0.0
    linear_sum = 0.0
    load_sum = 0.0
    for i in range(start, heights.size):
        delta = heights[i] - d
        root = math.sqrt(delta)
        weight = counts[i]
        number += weight
        root_sum += weight * root
        linear_sum += weight * delta
        load_sum += weight * delta * root
    return number, root_sum, linear_sum, load_sum


@jit(fastmath=False)
def direct_load_and_slope(d, heights, counts, hertz):
    """``(N(d), dN/dd)`` of a finite set of summits, a plain sum (MODELS.md 7.1, approach I).

    ``N = hertz sum c_i (h_i - d)^(3/2)`` and ``dN/dd = -(3/2) hertz sum
    c_i (h_i - d)^(1/2)`` over the summits above ``d``, summed from the lowest
    of them (small terms first) by :func:`tail_moments`, as
    :meth:`polind.contact.surface.DirectSurface.load_and_slope` sums them.

    Parameters
    ----------
    d : float
        Separation [m].
    heights : numpy.ndarray
        Summit heights [m], sorted ascending.
    counts : numpy.ndarray
        Summits at each height (float).
    hertz : float
        ``(4/3) E* sqrt(R)`` [N/m^(3/2)]: one summit carries ``hertz delta^(3/2)``.

    Returns
    -------
    tuple of float
        ``N(d)`` [N] and ``dN/dd`` [N/m] (negative, 0 with no summit in contact).
    """
    _, root_sum, _, load_sum = tail_moments(heights, counts, d)
    return hertz * load_sum, -1.5 * hertz * root_sum


@jit(fastmath=False)
def surface_load_and_slope(d, kind, load_scale, height_std, heights, counts, hertz, addresses):
    """``(N(d), dN/dd)`` of either surface kind: the load the Newton iteration balances.

    Parameters
    ----------
    d : float
        Separation [m].
    kind : int
        :data:`STATISTICAL` or :data:`DIRECT`.
    load_scale, height_std, heights, counts, hertz, addresses
        The surface (see the module notes); a kind ignores the others' arguments.

    Returns
    -------
    tuple of float
        ``N(d)`` [N] and ``dN/dd`` [N/m].
    """
    if kind == STATISTICAL:
        return statistical_load_and_slope(d, load_scale, height_std, addresses)
    return direct_load_and_slope(d, heights, counts, hertz)


@jit(fastmath=False)
def direct_lower_bound(load, heights, counts, hertz):
    """A separation at which a direct surface carries at least ``load``.

    The highest summits alone, carrying the whole load, need a larger
    interference than the real contact, where lower summits help, so
    ``N(d) >= load`` at ``d = h_max - (load / (c_max hertz))^(2/3)``.

    Parameters
    ----------
    load : float
        Normal load [N], positive.
    heights, counts : numpy.ndarray
        Summit heights [m] (sorted ascending) and counts.
    hertz : float
        ``(4/3) E* sqrt(R)`` [N/m^(3/2)].

    Returns
    -------
    float
        The lower end of the Newton bracket [m].
    """
    return heights[-1] - (load / (counts[-1] * hertz)) ** (2.0 / 3.0)


@jit(fastmath=False)
def predicted_start(d, value, slope, load):
    """Warm start: one Newton step on ``log N`` from the last solution.

    Parameters
    ----------
    d : float
        The previous separation [m].
    value, slope : float
        ``N(d)`` [N] and ``dN/dd`` [N/m] there (as returned by
        :func:`newton_separation`).
    load : float
        The new normal load [N], positive.

    Returns
    -------
    float
        The starting separation [m]; ``d`` itself if no summit touched there.
    """
    if value > 0.0 and slope < 0.0:
        return d - (math.log(value) - math.log(load)) * value / slope
    return d


@jit(fastmath=False)
def newton_separation_counted(load, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz,
                              addresses):
    """:func:`newton_separation` that also returns the number of load evaluations.

    Returns
    -------
    d, value, slope : float
        As :func:`newton_separation`.
    evaluations : int
        Load evaluations used (1 if ``start`` already meets the tolerance).
    """
    log_load = math.log(load)
    # Clamp as Python's min(max(start, lo), hi) does.
    d = start
    if lo > d:
        d = lo
    if hi < d:
        d = hi
    best_d = d
    best_error = math.inf
    best_value = math.nan
    best_slope = math.nan
    iteration = 0
    for iteration in range(1, MAX_ITERATIONS + 1):
        value, slope = surface_load_and_slope(d, kind, load_scale, height_std, heights, counts, hertz,
                                              addresses)
        error = abs(value - load)
        if error < best_error:
            best_d = d
            best_error = error
            best_value = value
            best_slope = slope
        if error <= RELATIVE_TOLERANCE * load:
            return d, value, slope, iteration
        # Keep the root bracketed: N decreases with d.
        if value > load:
            lo = d
        else:
            hi = d
        if value > 0.0 and slope < 0.0:
            candidate = d - (math.log(value) - log_load) * value / slope
        else:
            # No asperity touches at d (N = 0): no Newton information.
            candidate = math.nan
        if not (lo < candidate and candidate < hi):
            candidate = 0.5 * (lo + hi)
        if candidate == d or not (lo < candidate and candidate < hi):
            # The bracket has shrunk to adjacent floats: d is as good as
            # double precision allows.
            break
        d = candidate
    return best_d, best_value, best_slope, iteration


@jit(fastmath=False)
def newton_separation(load, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz, addresses):
    """Separation ``d`` with ``N(d) = load``: safeguarded Newton on ``log N`` (MODELS.md 7.4).

    The root is kept in the bracket ``[lo, hi]`` (``N(lo) >= load >= N(hi)``);
    each step is a Newton step on ``log N(d) - log load``, replaced by
    bisection when it would leave the bracket.  Stops when
    ``|N(d) - load| <= 1e-10 load``, or when the bracket has shrunk to
    adjacent doubles, returning then the best ``d`` evaluated.  The same
    iteration as :mod:`polind.contact.separation`, step for step.

    Parameters
    ----------
    load : float
        Normal load [N], positive (not checked).
    start : float
        Starting separation [m] (clamped into the bracket), e.g.
        :func:`predicted_start` of the previous sample.
    lo, hi : float
        The bracket [m]: statistical surface ``sigma_a`` times (-5, 10);
        direct surface :func:`direct_lower_bound` and the highest summit.
    kind : int
        :data:`STATISTICAL` or :data:`DIRECT`.
    load_scale, height_std : float
        The statistical surface (see the module notes).
    heights, counts : numpy.ndarray
        The direct surface (float64, heights ascending).
    hertz : float
        ``(4/3) E* sqrt(R)`` [N/m^(3/2)] of the direct surface.
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses`.

    Returns
    -------
    d : float
        Separation [m].
    value, slope : float
        ``N(d)`` [N] and ``dN/dd`` [N/m], for the next :func:`predicted_start`.
    """
    d, value, slope, _ = newton_separation_counted(load, start, lo, hi, kind, load_scale, height_std, heights,
                                                   counts, hertz, addresses)
    return d, value, slope


@jit(fastmath=False)
def newton_separation_series(loads, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz,
                             addresses, out_separation, out_evaluations):
    """Separation at every sample of a load series, each warm-started from the previous one.

    The first sample starts at ``start``; every later one at
    :func:`predicted_start` of the previous solution, and a load equal to the
    previous one reuses its separation (0 evaluations).  Every sample is
    solved by :func:`newton_separation` in ``[lo, hi]``, except that a direct
    surface's lower end is :func:`direct_lower_bound` of each sample's load.

    Parameters
    ----------
    loads : numpy.ndarray
        Normal loads [N], each positive and reachable (not checked).
    start : float
        Starting separation [m] of the first sample.
    lo : float
        Lower end of the bracket [m] for a statistical surface
        (``-5 sigma_a``); ignored for a direct surface.
    hi : float
        Upper end of the bracket [m].
    kind, load_scale, height_std, heights, counts, hertz, addresses
        The surface, as :func:`newton_separation`.
    out_separation : numpy.ndarray
        Filled with the separation [m] at every sample.
    out_evaluations : numpy.ndarray of int64
        Filled with the load evaluations at every sample.
    """
    previous_load = math.nan
    d = start
    value = math.nan
    slope = math.nan
    for index in range(loads.size):
        load = loads[index]
        if load == previous_load:
            out_separation[index] = d
            out_evaluations[index] = 0
            continue
        low = lo
        if kind == DIRECT:
            low = direct_lower_bound(load, heights, counts, hertz)
        if index > 0:
            # The previous solution and its slope predict this one to second
            # order in the load change: one evaluation saved per sample.
            d = predicted_start(d, value, slope, load)
        d, value, slope, evaluations = newton_separation_counted(
            load, d, low, hi, kind, load_scale, height_std, heights, counts, hertz, addresses
        )
        out_separation[index] = d
        out_evaluations[index] = evaluations
        previous_load = load
