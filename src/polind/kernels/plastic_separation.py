"""The separation of an elastic-plastic surface under a normal load, inside numba kernels.

The safeguarded Newton iteration of :mod:`polind.kernels.separation` on the
elastic-plastic loads of :mod:`polind.kernels.plastic`
(:ref:`guide-pol-ind-plasticity`).  A separate path: the elastic kernels
run their own code, untouched, and a model with a hardness runs these.

The differences from the elastic iteration:

- the load is the elastic one plus the excess of the asperities beyond
  yield (:func:`plastic_load_and_slope`);
- a direct sum's ``N(d)`` jumps where a summit crosses a Kogut–Etsion range
  boundary (the published fits are discontinuous there), so an applied load
  may fall inside a jump and have no separation that carries it: the
  iteration also stops when its bracket is narrower than ``jump_width``
  (``1e-12 sigma_a``), at the best separation it evaluated, one side of the
  jump; the caller reports the load left unmatched
  (the ``unmatched_load`` of :class:`polind.contact.Contact`);
- every start is a warm start (:func:`~polind.kernels.separation.predicted_start`
  from the previous solution), for a statistical surface too: its ``N(d)``
  is a quadrature, with no inverse table.

A surface is passed as a float vector of the layout below (:data:`SIZE`
slots; the Pol-Ind step keeps one in its scalars) and four arrays: the
direct surface's ``heights`` (ascending), Hertz ``weights``
``c_i sqrt(R_i / R)``, ``counts`` ``c_i`` and ``radii`` ``R_i`` (empty for a
statistical surface).
"""

from __future__ import annotations

import math

from polind.kernels import jit
from polind.kernels.plastic import (plastic_direct_load_and_slope, plastic_lower_bound,
                                    plastic_statistical_load_and_slope)
from polind.kernels.separation import (DIRECT, MAX_ITERATIONS, RELATIVE_TOLERANCE, STATISTICAL,
                                       STATISTICAL_STOP, predicted_start)

__all__ = [
    "KIND", "LOAD_SCALE", "HEIGHT_STD", "EXCESS_SCALE", "OMEGA", "HERTZ", "CRITICAL_FACTOR",
    "PLASTIC_SCALE", "YIELD_COEFFICIENT", "SMALLEST_RADIUS", "JUMP_WIDTH", "ADDRESSES", "SIZE",
    "JUMP_FRACTION",
    "plastic_load_and_slope",
    "plastic_lower",
    "plastic_iteration",
    "plastic_newton",
    "plastic_separation_series",
]

# The surface vector.
KIND = 0                 # polind.kernels.separation STATISTICAL or DIRECT
LOAD_SCALE = 1           # statistical: (4/3) eta A0 E* sqrt(R) sigma^(3/2) [N]
HEIGHT_STD = 2           # statistical: sigma_a [m]
EXCESS_SCALE = 3         # statistical: eta A0 P_c [N]
OMEGA = 4                # statistical: w_c / sigma_a [-]
HERTZ = 5                # direct: (4/3) E* sqrt(R) [N/m^(3/2)]
CRITICAL_FACTOR = 6      # c: w_c = c R [-]
PLASTIC_SCALE = 7        # p: P_c = p R^2 [Pa]
YIELD_COEFFICIENT = 8    # K [-]
SMALLEST_RADIUS = 9      # direct: the smallest summit radius [m]
JUMP_WIDTH = 10          # direct: the narrowest bracket [m], 1e-12 sigma_a (statistical: 0)
ADDRESSES = 11           # two slots: polind.kernels.special.special_addresses()
#: Slots of the surface vector.
SIZE = 13

#: The narrowest bracket of a direct surface, as a fraction of its summit-height spread.
JUMP_FRACTION = 1e-12


@jit(fastmath=False)
def plastic_load_and_slope(d, surface, heights, weights, counts, radii):
    """``(N(d), dN/dd)`` of an elastic-plastic surface of either kind (the module notes).

    Parameters
    ----------
    d : float
        Separation [m].
    surface : numpy.ndarray
        The surface vector (:data:`SIZE` floats).
    heights, weights, counts, radii : numpy.ndarray
        The direct surface's summits (ignored for a statistical surface).

    Returns
    -------
    tuple of float
        ``N(d)`` [N] and ``dN/dd`` [N/m].
    """
    if surface[KIND] == STATISTICAL:
        return plastic_statistical_load_and_slope(
            d, surface[LOAD_SCALE], surface[HEIGHT_STD], surface[ADDRESSES:ADDRESSES + 2],
            surface[EXCESS_SCALE], surface[OMEGA], surface[YIELD_COEFFICIENT])
    return plastic_direct_load_and_slope(
        d, heights, weights, surface[HERTZ], counts, radii, surface[CRITICAL_FACTOR],
        surface[PLASTIC_SCALE], surface[YIELD_COEFFICIENT], surface[SMALLEST_RADIUS])


@jit(fastmath=False)
def plastic_lower(load, lower, surface, heights, counts, radii):
    """The lower end of the bracket: ``lower`` (statistical), else the highest summit alone.

    See :func:`polind.kernels.plastic.plastic_lower_bound`.
    """
    if surface[KIND] == DIRECT:
        return plastic_lower_bound(load, heights, counts, radii, surface[CRITICAL_FACTOR],
                                   surface[PLASTIC_SCALE], surface[YIELD_COEFFICIENT])
    return lower


@jit(inline="always")
def plastic_iteration(load_and_slope, load, start, lo, hi, surface, evaluation):
    """The iteration of :func:`plastic_newton` on ``load_and_slope(d, evaluation)``.

    ``(d, N(d), dN/dd, evaluations, last)``, ``last`` the ``d`` of the last
    evaluation.  ``surface`` is the surface vector (its kind and jump width);
    ``load_and_slope`` ``_plastic_surface`` (``evaluation`` its
    arguments) or a model kernel's evaluation that also fills its element rows
    (:func:`polind.kernels.pol_ind_plastic.plastic_capacities`).
    """
    statistical = surface[KIND] == STATISTICAL
    tolerance = (STATISTICAL_STOP if statistical else RELATIVE_TOLERANCE) * load
    width = surface[JUMP_WIDTH]
    log_load = math.log(load)
    d = min(max(start, lo), hi)
    best_d = d
    best_error = math.inf
    best_value = math.nan
    best_slope = math.nan
    iteration = 0
    for iteration in range(1, MAX_ITERATIONS + 1):
        value, slope = load_and_slope(d, evaluation)
        error = abs(value - load)
        if error < best_error:
            best_d = d
            best_error = error
            best_value = value
            best_slope = slope
        if error <= tolerance:
            return d, value, slope, iteration, d
        if value > load:
            lo = d
        else:
            hi = d
        if hi - lo <= width:
            # Inside a jump of N(d): no separation carries the load.
            break
        candidate = math.nan
        if value > 0.0 and slope < 0.0:
            candidate = d - (math.log(value) - log_load) * value / slope
        if not (lo < candidate and candidate < hi):
            candidate = 0.5 * (lo + hi)
        if candidate == d or not (lo < candidate and candidate < hi):
            break
        d = candidate
    return best_d, best_value, best_slope, iteration, d


@jit(inline="always")
def _plastic_surface(d, evaluation):
    """:func:`plastic_load_and_slope`; ``evaluation`` is ``(surface, heights, weights, counts, radii)``."""
    surface, heights, weights, counts, radii = evaluation
    return plastic_load_and_slope(d, surface, heights, weights, counts, radii)


@jit(fastmath=False)
def plastic_newton(load, start, lo, hi, surface, heights, weights, counts, radii):
    """Separation ``d`` with ``N(d) = load`` on an elastic-plastic surface, or the jump's ``d``.

    Newton on ``log N`` kept in the bracket ``[lo, hi]`` as
    :func:`polind.kernels.separation.newton_separation_counted` does, stopping
    at ``|N(d) - load| <= 1e-10 load`` (statistical: 0.9e-10, the elastic
    iteration's margin), or when the bracket is narrower than the surface's
    jump width or down to adjacent doubles: then at the best ``d`` evaluated.

    Returns
    -------
    d, value, slope : float
        Separation [m], ``N(d)`` [N] and ``dN/dd`` [N/m] there.
    evaluations : int
        Load evaluations used.
    """
    d, value, slope, evaluations, _ = plastic_iteration(
        _plastic_surface, load, start, lo, hi, surface, (surface, heights, weights, counts, radii))
    return d, value, slope, evaluations


@jit(fastmath=False)
def plastic_separation_series(loads, start, lo, hi, surface, heights, weights, counts, radii,
                              out_separation, out_evaluations):
    """Separation at every sample of a load series, each started as the Pol-Ind step starts it.

    The first sample from ``start``, every later one from
    :func:`~polind.kernels.separation.predicted_start` of the previous
    solution; a repeated load reuses it (0 evaluations).  The bracket is
    ``[lo, hi]``, a direct surface's lower end :func:`plastic_lower` of each
    load.
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
        if index > 0:
            d = predicted_start(d, value, slope, load)
        low = plastic_lower(load, lo, surface, heights, counts, radii)
        d, value, slope, evaluations = plastic_newton(load, d, low, hi, surface, heights, weights,
                                                      counts, radii)
        out_separation[index] = d
        out_evaluations[index] = evaluations
        previous_load = load
