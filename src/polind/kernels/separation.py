"""The separation under a normal load, inside numba kernels.

Kernel versions of the safeguarded Newton iteration of
:mod:`polind.contact.separation`, so that a model kernel can re-solve the
separation ``d`` for a new normal load at every sample without returning
to Python.  The load integrals they balance are the Greenwood–Williamson
functions of :mod:`polind.kernels.greenwood`:

- :func:`statistical_load_and_slope` and :func:`direct_load_and_slope`:
  ``(N(d), dN/dd)`` of the statistical (Gaussian, with the fast pair
  :func:`~polind.kernels.greenwood.gw_half_integer_pair_fast`) and the
  direct (summed summits, :func:`~polind.kernels.greenwood.tail_moments`)
  surface;
- :func:`newton_separation`: Newton on ``log N(d) = log N_app`` kept in a
  bracket, bisection when a step leaves it, stopping at
  ``|N(d) - N_app| <= 1e-10 N_app`` (statistical surface: ``0.9e-10``, see
  :data:`STATISTICAL_STOP`), returning the best ``d`` seen if the bracket
  shrinks to adjacent doubles (:func:`statistical_newton_counted` and
  :func:`direct_newton_counted`: the same for one kind, compiled without the
  other's load); :func:`statistical_start` is the start for a
  statistical surface (the inverse polynomials of ``F_{3/2}``,
  :func:`~polind.kernels.greenwood.inverse_at`, accurate enough that the
  first evaluation meets the tolerance), :func:`predicted_start` the warm
  start of a direct surface from the previous solution and
  :func:`direct_lower_bound` the lower end of a direct surface's bracket;
- :func:`statistical_separation`, :func:`statistical_separation_at` and
  :func:`statistical_separation_only`: a statistical surface's separation
  at the cost a model kernel can pay per sample;
  :func:`newton_separation_series` a whole load series.

The mathematics is in the user guide: :ref:`guide-pol-ind-summation` and
:ref:`guide-pol-ind-separation`.

A surface is passed as plain numbers and arrays: ``kind`` (:data:`STATISTICAL`
or :data:`DIRECT`), the statistical surface's ``load_scale`` =
``(4/3) eta A0 E* sqrt(R) sigma_a^(3/2)`` and ``height_std`` = ``sigma_a``,
the direct surface's ``heights`` (sorted ascending, distinct), ``counts``
(summits at each height, float) and ``hertz`` = ``(4/3) E* sqrt(R)``, and the
``addresses`` of :func:`polind.kernels.special.special_addresses`.  Arguments
a kind does not use may be anything of the right type (e.g. empty arrays).

These kernels are compiled without ``fastmath``, as the functions of
:mod:`polind.kernels.greenwood` are: the Newton path (iterations, stopping,
best-so-far) should be exactly that of the Python formulas.

Because the Newton iteration balances the fast ``N(d)``, it stops for a
statistical surface at ``0.9e-10 N_app`` (:data:`STATISTICAL_STOP`): the
1e-11 left covers both the approximation and the exact formulas' own error,
so ``|N(d) - N_app| <= 1e-10 N_app`` holds with either.  From
:func:`statistical_start` (the inverse polynomials, error in ``s`` below
2e-12) the first evaluation meets the tolerance, so a changed load costs
one ``log``, two polynomial pieces and one ``exp``, about 50 ns.  A direct
evaluation is a sum over the summits above ``d``.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.greenwood import (FAST_RANGE, INVERSE_PIECES, fast_pair, gw_half_integer_pair_fast,
                                      inverse_at, inverse_position, tail_moments)
from polind.kernels.special import IVE, KVE

__all__ = [
    "STATISTICAL",
    "DIRECT",
    "RELATIVE_TOLERANCE",
    "STATISTICAL_STOP",
    "MAX_ITERATIONS",
    "statistical_load_and_slope",
    "direct_load_and_slope",
    "surface_load_and_slope",
    "direct_lower_bound",
    "predicted_start",
    "statistical_start",
    "statistical_separation",
    "statistical_separation_at",
    "statistical_separation_only",
    "newton_separation",
    "newton_iteration",
    "newton_separation_counted",
    "statistical_newton_counted",
    "direct_newton_counted",
    "newton_separation_series",
]

#: Surface kinds of the ``kind`` argument: floats, as a model's float64 scalars hold
#: them and every caller, compiled or Python, passes them (an int constant would be
#: typed as a literal of its own and compile the solver once more).
STATISTICAL, DIRECT = 0.0, 1.0

#: Required accuracy of the load balance, ``|N(d) - N_app| <= tol N_app``.
RELATIVE_TOLERANCE = 1e-10

#: Where the iteration stops for a statistical surface, relative to ``N_app``:
#: its ``N(d)`` is the fast pair's, within 5e-15 of the true value and
#: within 3e-12 of the exact Bessel formulas', so stopping 1e-11 short of
#: :data:`RELATIVE_TOLERANCE` keeps the balance to 1e-10 by either measure.
STATISTICAL_STOP = 0.9 * RELATIVE_TOLERANCE

#: Enough for bisection alone to shrink any float bracket to adjacent floats.
MAX_ITERATIONS = 2200

_FAST_LOWER, _FAST_UPPER = FAST_RANGE


@jit(fastmath=False)
def statistical_start(load, load_scale, height_std):
    """Where :func:`newton_separation` starts on a statistical surface, from the inverse of its load.

    ``sigma_a s`` with ``F_{3/2}(s) = load / load_scale``, ``s`` from the
    piecewise polynomials of ``log F_{3/2}``
    (:func:`~polind.kernels.greenwood.inverse_at`; error in ``s`` below
    2e-12, so the load there is within 3e-11 of ``load`` and the first
    evaluation meets :data:`STATISTICAL_STOP`).  A
    load beyond the ends of :data:`~polind.kernels.greenwood.FAST_RANGE`
    gives the nearer end.

    Parameters
    ----------
    load : float
        Normal load [N], positive.
    load_scale, height_std : float
        The statistical surface (see the module notes).

    Returns
    -------
    float
        The starting separation [m].
    """
    position = inverse_position(load / load_scale)
    if not position > 0.0:
        # Beyond s = 10.5 (or NaN).
        position = 0.0
    if position > INVERSE_PIECES:
        position = INVERSE_PIECES
    return height_std * inverse_at(position)


@jit(fastmath=False)
def statistical_load_and_slope(d, load_scale, height_std, addresses):
    """``(N(d), dN/dd)`` of the Gaussian surface summed statistically (:ref:`guide-pol-ind-summation`).

    ``N = load_scale F_{3/2}(d/sigma_a)``, ``dN/dd = -(3/2) load_scale
    F_{1/2}(d/sigma_a) / sigma_a``, the formulas of
    :meth:`polind.contact.surface.StatisticalSurface.hertz_load_and_slope` with
    the fast pair (:func:`~polind.kernels.greenwood.gw_half_integer_pair_fast`):
    within 5e-15 of the true values, within 3e-12 of the exact Bessel pair's.

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
    f_half, f_three_halves = gw_half_integer_pair_fast(d / height_std, addresses)
    return load_scale * f_three_halves, -1.5 * load_scale / height_std * f_half



@jit(fastmath=False)
def direct_load_and_slope(d, heights, counts, hertz):
    """``(N(d), dN/dd)`` of a finite set of summits, a plain sum (approach I, :ref:`guide-pol-ind-summation`).

    ``N = hertz sum c_i (h_i - d)^(3/2)`` and ``dN/dd = -(3/2) hertz sum
    c_i (h_i - d)^(1/2)`` over the summits above ``d``, summed from the lowest
    of them (small terms first) by
    :func:`~polind.kernels.greenwood.tail_moments`, as
    :meth:`polind.contact.surface.DirectSurface.hertz_load_and_slope` sums them.

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


@jit(inline="always")
def newton_iteration(load_and_slope, stop, load, start, lo, hi, surface):
    """The iteration of :func:`newton_separation_counted` on ``load_and_slope``, stopping at ``stop N_app``.

    ``load_and_slope(d, surface)`` returns ``(N(d), dN/dd)`` of the surface
    ``surface`` (a tuple of what it needs: ``_statistical_surface``,
    ``_direct_surface``, or a model kernel's evaluation that also fills
    its element rows at ``d``,
    :func:`polind.kernels.pol_ind.direct_rows_surface`).  Returns ``(d,
    N(d), dN/dd, evaluations, last)``: ``last`` is the ``d`` of the last
    evaluation (``d`` itself unless the bracket shrank to adjacent doubles
    first and an earlier ``d`` was better).
    """
    tolerance = stop * load
    # log(load) only once a Newton step is needed (a good start needs none).
    log_load = math.nan
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
        value, slope = load_and_slope(d, surface)
        error = abs(value - load)
        if error < best_error:
            best_d = d
            best_error = error
            best_value = value
            best_slope = slope
        if error <= tolerance:
            return d, value, slope, iteration, d
        # Keep the root bracketed: N decreases with d.
        if value > load:
            lo = d
        else:
            hi = d
        if value > 0.0 and slope < 0.0:
            if log_load != log_load:
                log_load = math.log(load)
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
    return best_d, best_value, best_slope, iteration, d


@jit(inline="always")
def _statistical_surface(d, surface):
    """:func:`statistical_load_and_slope`; ``surface`` is ``(load_scale, height_std, addresses)``."""
    load_scale, height_std, addresses = surface
    return statistical_load_and_slope(d, load_scale, height_std, addresses)


@jit(inline="always")
def _direct_surface(d, surface):
    """:func:`direct_load_and_slope`; ``surface`` is ``(heights, counts, hertz)``."""
    heights, counts, hertz = surface
    return direct_load_and_slope(d, heights, counts, hertz)


@jit(fastmath=False)
def statistical_newton_counted(load, start, lo, hi, kind, load_scale, height_std, heights, counts,
                               hertz, addresses):
    """:func:`newton_separation_counted` of a statistical surface (``kind`` is not read).

    The same iteration, stops and results, to the bit, compiled without the
    direct surface's sums: what :func:`polind.contact.separation.solve_separation`
    runs for a statistical surface, so that a process solving one compiles
    one kind.
    """
    # The fast statistical N(d) stops short of the tolerance (STATISTICAL_STOP).
    d, value, slope, evaluations, _ = newton_iteration(
        _statistical_surface, STATISTICAL_STOP, load, start, lo, hi,
        (load_scale, height_std, addresses))
    return d, value, slope, evaluations


@jit(fastmath=False)
def direct_newton_counted(load, start, lo, hi, kind, load_scale, height_std, heights, counts,
                          hertz, addresses):
    """:func:`newton_separation_counted` of a direct surface (``kind`` is not read).

    As :func:`statistical_newton_counted`, without the statistical surface's pair.
    """
    d, value, slope, evaluations, _ = newton_iteration(
        _direct_surface, RELATIVE_TOLERANCE, load, start, lo, hi, (heights, counts, hertz))
    return d, value, slope, evaluations


@jit(fastmath=False)
def newton_separation_counted(load, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz,
                              addresses):
    """:func:`newton_separation` that also returns the number of load evaluations.

    :func:`statistical_newton_counted` or :func:`direct_newton_counted` by ``kind``.

    Returns
    -------
    d, value, slope : float
        As :func:`newton_separation`.
    evaluations : int
        Load evaluations used (1 if ``start`` already meets the tolerance).
    """
    if kind == STATISTICAL:
        return statistical_newton_counted(load, start, lo, hi, kind, load_scale, height_std,
                                          heights, counts, hertz, addresses)
    return direct_newton_counted(load, start, lo, hi, kind, load_scale, height_std, heights,
                                 counts, hertz, addresses)


@jit(fastmath=False)
def newton_separation(load, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz, addresses):
    """Separation ``d`` with ``N(d) = load``: safeguarded Newton on ``log N``.

    The root is kept in the bracket ``[lo, hi]`` (``N(lo) >= load >= N(hi)``);
    each step is a Newton step on ``log N(d) - log load``, replaced by
    bisection when it would leave the bracket.  Stops when
    ``|N(d) - load| <= 1e-10 load`` (a statistical surface, whose ``N`` is
    the fast pair's: ``<= 0.9e-10 load``, :data:`STATISTICAL_STOP`), or when
    the bracket has shrunk to adjacent doubles, returning then the best ``d``
    evaluated.  :mod:`polind.contact.separation` runs this kernel
    (:ref:`guide-pol-ind-separation`).

    Parameters
    ----------
    load : float
        Normal load [N], positive (not checked).
    start : float
        Starting separation [m] (clamped into the bracket), e.g.
        :func:`statistical_start` of the load, or for a direct surface
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
def statistical_separation(load, lo, hi, load_scale, height_std, addresses):
    """:func:`newton_separation` of a statistical surface from :func:`statistical_start`, cheaply.

    The first evaluation, at ``statistical_start`` clamped into ``[lo, hi]``,
    is made here, and meets :data:`STATISTICAL_STOP` for any load the
    surface can carry; only if it does not (a load outside the bracket's
    range) does :func:`newton_separation_counted` run, from the same start.
    So the result is that of ``newton_separation_counted(load,
    statistical_start(...), lo, hi, STATISTICAL, ...)`` exactly, without the
    cost of its call when one evaluation is enough: what a model kernel pays
    per sample of a varying load.

    Parameters
    ----------
    load : float
        Normal load [N], positive (not checked).
    lo, hi : float
        The bracket [m], ``sigma_a`` times (-5, 10).
    load_scale, height_std : float
        The statistical surface (see the module notes).
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses`.

    Returns
    -------
    d, value, slope : float
        As :func:`newton_separation`.
    evaluations : int
        Load evaluations: 1, or 1 + those of the Newton iteration (which
        repeats the first).
    """
    return statistical_separation_at(load, lo, hi, load_scale, height_std, addresses[KVE],
                                     addresses[IVE])


@jit(fastmath=False)
def statistical_separation_at(load, lo, hi, load_scale, height_std, kve_address, ive_address):
    """:func:`statistical_separation` with the two addresses as numbers, not an array.

    What a model kernel calls once per sample of a varying load: with no
    array among its arguments, nothing is reference-counted on the way
    (each count is an atomic operation that also stops the processor from
    overlapping the solve with the element update around it).  An
    addresses array is made only if the Newton iteration has to run.
    """
    d = statistical_start(load, load_scale, height_std)
    # Clamp as newton_separation_counted does.
    if lo > d:
        d = lo
    if hi < d:
        d = hi
    # statistical_load_and_slope at d, branch for branch.
    s = d / height_std
    if _FAST_LOWER <= s and s < _FAST_UPPER:
        f_half, f_three_halves = fast_pair(s)
        value = load_scale * f_three_halves
        slope = -1.5 * load_scale / height_std * f_half
        if abs(value - load) <= STATISTICAL_STOP * load:
            return d, value, slope, 1
    addresses = np.empty(2)
    addresses[KVE] = kve_address
    addresses[IVE] = ive_address
    value, slope = statistical_load_and_slope(d, load_scale, height_std, addresses)
    if abs(value - load) <= STATISTICAL_STOP * load:
        return d, value, slope, 1
    # Empty summit arrays made here: a global array is a read-only constant to numba,
    # a type of its own (another compile of the solver).
    no_summits = np.empty(0)
    d, value, slope, evaluations = statistical_newton_counted(load, d, lo, hi, STATISTICAL,
                                                              load_scale, height_std, no_summits,
                                                              no_summits, 0.0, addresses)
    return d, value, slope, 1 + evaluations


@jit(fastmath=False)
def statistical_separation_only(load, lo, hi, load_scale, height_std, kve_address, ive_address):
    """The separation of :func:`statistical_separation_at` alone, without its check inside the bracket.

    For a load whose start (:func:`statistical_start`) lies strictly inside
    ``[lo, hi]`` and inside :data:`~polind.kernels.greenwood.FAST_RANGE`
    (not at an end it was clamped to) this returns the start itself, which
    :func:`statistical_separation_at` returns as well after one evaluation
    of ``N(d)`` that confirms the balance: the inverse polynomials put it
    within 2e-12 of the true ``s``, within 3e-11 of the load (measured at
    12,000 points over :data:`~polind.kernels.greenwood.FAST_RANGE` and at
    2,000 loads over a surface's load range, in the tests), so that evaluation always passes
    there.  Skipping it cuts the separation of a model kernel's load update
    from about 50 ns to 10-17 ns (the evaluation waits for the start, and
    ``exp`` waits for it).  A start on or beyond an end of the bracket (a
    load the polynomials do not cover, or NaN) goes to
    :func:`statistical_separation_at`, with its Newton fallback.  What a
    model kernel needs is ``d``; ``N(d)`` and ``dN/dd`` serve only the warm
    start of a direct surface.
    """
    position = inverse_position(load / load_scale)
    if 0.0 < position and position < INVERSE_PIECES:
        # statistical_start, not clamped: s inside FAST_RANGE.
        d = height_std * inverse_at(position)
        if lo < d and d < hi:
            return d
    return statistical_separation_at(load, lo, hi, load_scale, height_std, kve_address,
                                     ive_address)[0]


@jit(fastmath=False)
def newton_separation_series(loads, start, lo, hi, kind, load_scale, height_std, heights, counts, hertz,
                             addresses, out_separation, out_evaluations):
    """Separation at every sample of a load series, each later one started as a model kernel starts it.

    The first sample starts at ``start``; every later one is solved as a
    model kernel solves it: :func:`statistical_separation` (statistical
    surface: one evaluation), or :func:`newton_separation` from
    :func:`predicted_start` of the previous solution (direct surface), and a
    load equal to the previous one reuses its separation (0 evaluations).
    The bracket is ``[lo, hi]``, except that a direct surface's lower end is
    :func:`direct_lower_bound` of each sample's load.

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
        if index > 0 and kind == STATISTICAL:
            d, value, slope, evaluations = statistical_separation(load, lo, hi, load_scale, height_std,
                                                                  addresses)
        else:
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
