"""Elastic-plastic asperities (Kogut–Etsion) inside numba kernels: the one implementation.

The single-asperity law of Kogut and Etsion (2002) with the yield inception
of Chang, Etsion and Bogy (1987), and the sums over a surface built from it,
as numba functions that the separation solver, the element tables and the
Pol-Ind step call (the NumPy layer, :mod:`polind.contact.plasticity`, calls
the same compiled functions).  The mathematics is in the user guide,
:ref:`guide-pol-ind-plasticity`.

One asperity of radius ``R`` yields at the critical interference
``w_c = c R`` with the *critical factor* ``c = (pi K H / (2 E*))^2``
(``K = 0.454 + 0.41 nu1``); there it carries ``P_c = p R^2`` with the
*plastic scale* ``p = (2/3) pi K H c`` and touches on ``A_c = pi c R^2``.
With ``w = delta / w_c``, :func:`kogut_etsion` gives ``P / P_c`` and
``A / A_c`` on the four ranges (Hertz up to ``w = 1``, then the published
fits, used as published, jumps included).

Every total is written as the elastic (Hertz) total plus an *excess* over
the asperities beyond yield, ``P - P_Hertz`` and ``A - A_Hertz``:

- the elastic part is computed by exactly the code of the elastic model
  (:mod:`polind.kernels.greenwood`, :mod:`polind.kernels.separation`), so
  a surface none of whose asperities reaches ``w_c`` (``H -> inf``) gives
  the elastic model's numbers to the bit (the excess is then exactly 0);
- :func:`direct_excess` sums the excess over the summits beyond yield (each
  with its own radius; sorted heights, so from ``d + c R_min`` up);
- :func:`statistical_excess` integrates it over the Gaussian, in the
  normalised height ``x = delta / sigma_a`` and the variable ``u = sqrt(x)``
  (smooth at the kinks' power laws), split at the three kinks
  ``x = omega, 6 omega, 110 omega`` (``omega = w_c / sigma_a``), each range
  cut into panels no wider than 1/4 in ``u`` nor wider than their own start
  (the power laws' branch point is ``u = 0``), 16-point Gauss–Legendre on each
  panel, up to where the Gaussian has fallen by ``e^-40`` from its largest
  value on the tail.  Measured against ``scipy.integrate.quad`` at 30 000
  points (``s`` in [-5, 10], ``omega`` from 1e-5 to 30): relative error of
  the totals below 1e-13 (the tests check 1e-10, the required tolerance).

These functions are compiled without ``fastmath``, as the elastic ones are.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.separation import direct_load_and_slope, statistical_load_and_slope

__all__ = [
    "RANGE_ENDS",
    "kogut_etsion",
    "kogut_etsion_load",
    "inverse_load_ratio",
    "excess_end",
    "direct_excess",
    "statistical_excess",
    "plastic_direct_load_and_slope",
    "plastic_statistical_load_and_slope",
    "plastic_lower_bound",
    "plastic_element_properties",
    "kogut_etsion_ratios",
    "statistical_excess_many",
    "direct_excess_many",
]

#: ``w = delta / w_c`` where the Kogut–Etsion ranges end (Hertz up to the first).
RANGE_ENDS = (1.0, 6.0, 110.0)
_SECOND, _THIRD = 6.0, 110.0

_GL_NODES, _GL_WEIGHTS = (np.ascontiguousarray(a) for a in np.polynomial.legendre.leggauss(16))
for _array in (_GL_NODES, _GL_WEIGHTS):
    _array.setflags(write=False)
# Panels in u = sqrt(delta / sigma_a): at most this wide (the Gaussian's scale in u
# is 0.2 or more on the tail of s in [-5, 10.5]) ...
_PANEL_WIDTH = 0.25
# ... and the Gaussian is integrated until it has fallen by e^-TAIL from its largest
# value on the tail (the excess grows like x^(3/2): ample margin for 1e-13).
_TAIL = 40.0
_INV_SQRT_2PI = 1.0 / math.sqrt(2.0 * math.pi)


@jit(fastmath=False)
def kogut_etsion(w, K):
    """``(P / P_c, A / A_c, d(P / P_c)/dw)`` of one asperity at ``w = delta / w_c > 0``.

    Hertz up to ``w = 1`` (``w^(3/2)``, ``w``), then Kogut–Etsion (2002):
    ``1.03 w^1.425`` and ``0.93 w^1.136`` up to 6, ``1.40 w^1.263`` and
    ``0.94 w^1.146`` up to 110, ``(3/K) w`` and ``2 w`` beyond.  A boundary
    belongs to the range below it.  (The powers as ``exp(b log w)`` with one
    ``log``: within a few ulps of ``w**b``, at two thirds of the cost.)

    Parameters
    ----------
    w : float
        Interference over the critical interference [-], positive.
    K : float
        The yield coefficient ``0.454 + 0.41 nu1`` [-].

    Returns
    -------
    tuple of float
        Load ratio, area ratio and the load ratio's slope in ``w``.
    """
    if w <= 1.0:
        root = math.sqrt(w)
        return w * root, w, 1.5 * root
    if w <= _SECOND:
        log_w = math.log(w)
        load = 1.03 * math.exp(1.425 * log_w)
        return load, 0.93 * math.exp(1.136 * log_w), 1.425 * load / w
    if w <= _THIRD:
        log_w = math.log(w)
        load = 1.40 * math.exp(1.263 * log_w)
        return load, 0.94 * math.exp(1.146 * log_w), 1.263 * load / w
    return 3.0 / K * w, 2.0 * w, 3.0 / K


@jit(fastmath=False)
def kogut_etsion_load(w, K):
    """``(P / P_c, d(P / P_c)/dw)`` of :func:`kogut_etsion` alone (what a load evaluation needs)."""
    if w <= 1.0:
        root = math.sqrt(w)
        return w * root, 1.5 * root
    if w <= _SECOND:
        load = 1.03 * math.exp(1.425 * math.log(w))
        return load, 1.425 * load / w
    if w <= _THIRD:
        load = 1.40 * math.exp(1.263 * math.log(w))
        return load, 1.263 * load / w
    return 3.0 / K * w, 3.0 / K


@jit(fastmath=False)
def inverse_load_ratio(ratio, K):
    """The smallest ``w`` with ``P / P_c >= ratio`` (:func:`kogut_etsion`), for ``ratio > 0``.

    Range by range: the first whose largest load reaches ``ratio``.  (With
    ``nu1`` above 0.41 the fully plastic fit starts below the end of the third
    range; the first range that reaches the load is still the smallest ``w``.)
    """
    if ratio <= 1.0:
        return ratio ** (2.0 / 3.0)
    if ratio <= 1.03 * _SECOND ** 1.425:
        return max((ratio / 1.03) ** (1.0 / 1.425), 1.0)
    if ratio <= 1.40 * _THIRD ** 1.263:
        return max((ratio / 1.40) ** (1.0 / 1.263), _SECOND)
    return max(ratio * K / 3.0, _THIRD)


@jit(fastmath=False)
def direct_excess(heights, counts, radii, d, critical_factor, K, smallest_radius, full):
    """Sums over the summits beyond yield of their excess over Hertz, and their count and load.

    A summit ``i`` above ``d`` is beyond yield when ``delta_i > c R_i``
    (``w_i > 1``); as ``heights`` are sorted ascending, the sum starts at the
    first above ``d + c R_min``.  In units of ``P_c / R_i^2`` and
    ``A_c / R_i^2`` (multiply the loads by the plastic scale ``p``, the
    areas by ``pi c``, the slope by ``p / c``):

    Returns
    -------
    tuple of float
        ``sum c_i R_i^2 (P/P_c - w^(3/2))`` (load excess),
        ``sum c_i R_i (dP/dw - 1.5 w^(1/2))`` (minus the slope excess), and,
        only if ``full`` (else 0), ``sum c_i R_i^2 (A/A_c - w)`` (area excess),
        ``sum c_i`` (summits beyond yield) and ``sum c_i R_i^2 P/P_c`` (their
        load).
    """
    start = np.searchsorted(heights, d + critical_factor * smallest_radius, side="right")
    load = 0.0
    slope = 0.0
    area = 0.0
    number = 0.0
    plastic = 0.0
    for i in range(start, heights.size):
        radius = radii[i]
        w = (heights[i] - d) / (critical_factor * radius)
        if w > 1.0:
            root = math.sqrt(w)
            scale = counts[i] * radius * radius
            if full:
                load_ratio, area_ratio, load_slope = kogut_etsion(w, K)
                area += scale * (area_ratio - w)
                number += counts[i]
                plastic += scale * load_ratio
            else:
                load_ratio, load_slope = kogut_etsion_load(w, K)
            load += scale * (load_ratio - w * root)
            slope += counts[i] * radius * (load_slope - 1.5 * root)
    return load, slope, area, number, plastic


@jit(fastmath=False)
def excess_end(s):
    """``x = delta / sigma_a`` beyond which :func:`statistical_excess` integrates nothing.

    Where the Gaussian has fallen by ``e^-40`` from its largest value on the
    tail above ``s``; decreasing in ``s``.  With ``omega`` at or beyond it
    the excess is exactly 0.
    """
    peak = s if s > 0.0 else 0.0
    return math.sqrt(peak * peak + 2.0 * _TAIL) - s


@jit(fastmath=False)
def statistical_excess(s, omega, K, full):
    """Integrals over the Gaussian tail beyond yield (:ref:`guide-pol-ind-plasticity`).

    With ``x = delta / sigma_a``, ``w = x / omega`` and ``phi`` the standard
    normal density, over ``x > omega`` (the module notes give the rule):

    Parameters
    ----------
    s : float
        Normalised separation ``d / sigma_a`` [-].
    omega : float
        Critical interference over ``sigma_a`` [-], positive.
    K : float
        Yield coefficient [-].
    full : bool
        Also the area excess and the plastic load (else 0).

    Returns
    -------
    tuple of float
        ``L = ∫ (P/P_c - w^(3/2)) phi(s + x) dx``, ``dL/ds``,
        ``∫ (A/A_c - w) phi(s + x) dx`` and ``∫ P/P_c phi(s + x) dx``.
    """
    end = excess_end(s)
    load = 0.0
    slope = 0.0
    area = 0.0
    plastic = 0.0
    lower = omega
    for kind in range(3):
        upper = omega * _SECOND if kind == 0 else (omega * _THIRD if kind == 1 else math.inf)
        if lower >= end:
            break
        if upper > end:
            upper = end
        u = math.sqrt(lower)
        u_end = math.sqrt(upper)
        while u < u_end:
            width = min(_PANEL_WIDTH, u)
            u_next = u + width if u + width < u_end else u_end
            half = 0.5 * (u_next - u)
            middle = 0.5 * (u_next + u)
            for k in range(_GL_NODES.size):
                node = middle + half * _GL_NODES[k]
                x = node * node
                w = x / omega
                t = s + x
                density = 2.0 * node * half * _GL_WEIGHTS[k] * _INV_SQRT_2PI * math.exp(-0.5 * t * t)
                if full:
                    load_ratio, area_ratio, _ = kogut_etsion(w, K)
                    area += (area_ratio - w) * density
                    plastic += load_ratio * density
                else:
                    load_ratio, _ = kogut_etsion_load(w, K)
                excess = (load_ratio - w * math.sqrt(w)) * density
                load += excess
                slope -= excess * t
            u = u_next
        lower = upper
    return load, slope, area, plastic


@jit(fastmath=False)
def plastic_statistical_load_and_slope(d, load_scale, height_std, addresses, excess_scale, omega, K):
    """``(N(d), dN/dd)`` of an elastic-plastic Gaussian surface summed statistically.

    The elastic :func:`~polind.kernels.separation.statistical_load_and_slope`
    (``load_scale = (4/3) eta A0 E* sqrt(R) sigma^(3/2)``) plus
    ``excess_scale`` (``eta A0 P_c``) times :func:`statistical_excess`.
    """
    value, slope = statistical_load_and_slope(d, load_scale, height_std, addresses)
    excess, excess_slope, _, _ = statistical_excess(d / height_std, omega, K, False)
    return value + excess_scale * excess, slope + excess_scale * excess_slope / height_std


@jit(fastmath=False)
def plastic_direct_load_and_slope(d, heights, weights, hertz, counts, radii, critical_factor,
                                  plastic_scale, K, smallest_radius):
    """``(N(d), dN/dd)`` of elastic-plastic summits: the elastic plain sum plus their excess.

    ``weights`` are the Hertz weights ``c_i sqrt(R_i / R)`` and ``hertz`` is
    ``(4/3) E* sqrt(R)`` (the elastic
    :func:`~polind.kernels.separation.direct_load_and_slope`); ``counts`` and
    ``radii`` the summits themselves (:func:`direct_excess`).
    """
    value, slope = direct_load_and_slope(d, heights, weights, hertz)
    excess, excess_slope, _, _, _ = direct_excess(heights, counts, radii, d, critical_factor, K,
                                                  smallest_radius, False)
    return value + plastic_scale * excess, slope - plastic_scale / critical_factor * excess_slope


@jit(fastmath=False)
def plastic_lower_bound(load, heights, counts, radii, critical_factor, plastic_scale, K):
    """A separation at which elastic-plastic summits carry at least ``load``.

    The highest summit alone carrying the whole load (the elastic
    :func:`~polind.kernels.separation.direct_lower_bound`, with the
    Kogut–Etsion law inverted by :func:`inverse_load_ratio`).
    """
    top = heights.size - 1
    radius = radii[top]
    ratio = load / (counts[top] * plastic_scale * radius * radius)
    return heights[top] - inverse_load_ratio(ratio, K) * critical_factor * radius


@jit(fastmath=False)
def plastic_element_properties(heights, weights, counts, radii, d, R, E_star, G_star, mu_s,
                               critical_factor, plastic_scale, K, out_k, out_W):
    """Stiffness and break-away force of elastic-plastic elements at separation ``d``.

    ``k_j = n_j 8 G* a(delta_j)``, ``a = sqrt(A / pi)``, and
    ``W_j = n_j mu_s P(delta_j)`` (:ref:`guide-pol-ind-plasticity`); an element
    within yield (``delta_j <= c R_j``) gets the numbers of the elastic
    :func:`polind.kernels.elements.element_properties` to the bit (its Hertz
    weight ``weights[j]`` and the reference radius ``R``), one out of
    contact ``k = W = 0``.
    """
    sqrt_R = math.sqrt(R)
    stiffness_scale = 8.0 * G_star * sqrt_R
    capacity_scale = mu_s * (4.0 / 3.0) * E_star * sqrt_R
    root_factor = math.sqrt(critical_factor)
    for j in range(heights.size):
        delta = heights[j] - d
        if delta > 0.0:
            radius = radii[j]
            w = delta / (critical_factor * radius)
            if w <= 1.0:
                root = math.sqrt(delta)
                out_k[j] = weights[j] * stiffness_scale * root
                out_W[j] = weights[j] * capacity_scale * delta * root
            else:
                load_ratio, area_ratio, _ = kogut_etsion(w, K)
                out_k[j] = counts[j] * 8.0 * G_star * radius * root_factor * math.sqrt(area_ratio)
                out_W[j] = counts[j] * mu_s * plastic_scale * radius * radius * load_ratio
        else:
            out_k[j] = 0.0
            out_W[j] = 0.0


@jit(fastmath=False)
def kogut_etsion_ratios(w, K, out_load, out_area):
    """:func:`kogut_etsion` at every ``w`` (0 where ``w <= 0``): ``P / P_c`` and ``A / A_c``."""
    for i in range(w.size):
        if w[i] > 0.0:
            out_load[i], out_area[i], _ = kogut_etsion(w[i], K)
        else:
            out_load[i] = 0.0
            out_area[i] = 0.0


@jit(fastmath=False)
def statistical_excess_many(s, omega, K, out):
    """:func:`statistical_excess` (``full``) at every ``s``; ``out`` is (n, 4)."""
    for i in range(s.size):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = statistical_excess(s[i], omega, K, True)


@jit(fastmath=False)
def direct_excess_many(heights, counts, radii, separations, critical_factor, K, smallest_radius, out):
    """:func:`direct_excess` at every separation; ``out`` is (n, 5)."""
    for i in range(separations.size):
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4] = direct_excess(
            heights, counts, radii, separations[i], critical_factor, K, smallest_radius, True)
