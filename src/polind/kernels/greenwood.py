"""The Greenwood–Williamson functions inside numba kernels: the one implementation.

The integrals of the Gaussian summit-height distribution that the
statistical surface is made of, and the sums over summits that a direct
surface is made of, as numba functions: model kernels and the separation
solvers (:mod:`polind.kernels.separation`) call them per sample, and the
NumPy layer (:mod:`polind.contact.greenwood`, :mod:`polind.contact.surface`)
calls the same compiled functions, so every layer computes them with one
code.  With ``F_m(s) = ∫_s^∞ (t - s)^m phi(t) dt`` (``phi`` the standard
normal density):

- :func:`gw_half_integer_pair`: ``(F_{1/2}(s), F_{3/2}(s))`` from the
  modified Bessel functions of order ±1/4, ±3/4 (the parabolic-cylinder
  functions of half-integer order; SciPy's, through
  :mod:`polind.kernels.special`), with the Taylor series about 0; the
  formulas and their accuracy are in :mod:`polind.contact.greenwood`;
  :func:`gw_half_integer_pairs` is the same at every element of an array;
- :func:`gw_half_integer_pair_fast`: the same pair from piecewise
  polynomials on :data:`FAST_RANGE` (an approximation, relative error below
  5e-15 there; see "The fast pair" below), :func:`gw_half_integer_pair`
  outside it; :func:`fast_pair` is its polynomials alone;
- :func:`inverse_position` and :func:`inverse_at`: ``s`` from ``F_{3/2}(s)``,
  the inverse polynomials the separation solver starts from;
- :func:`tail_moments`: for a finite set of summits, the sums over those
  above ``d`` of ``c_i delta_i^p``, ``p = 0, 1/2, 1, 3/2`` (count, load
  slope, area and load of a direct surface).

The mathematics is in the user guide: :ref:`guide-pol-ind-summation`.

These functions are compiled without ``fastmath``: the ``F_{3/2}`` of
``s > 0`` is a difference of two terms that cancel by a factor of about
``s²/1.5`` (70 at ``s = 10``), so a fused multiply-add there would move the
result by tens of ulps.  For the same reason they are not
``inline="always"`` (inlined into a caller, they would take the caller's
fastmath flags), except the two small inverse functions, whose callers
compile without fastmath too.

The fast pair
-------------
The exact pair costs two SciPy ``kve`` calls (``s > 0``) or four ``ive``
calls (``s < 0``), 0.5–1.1 µs, nearly all of it inside SciPy's AMOS code;
a model that re-solves the separation at every sample cannot afford it.
:func:`gw_half_integer_pair_fast` is an approximation instead: on each of 32
pieces of width 1/2 covering :data:`FAST_RANGE` = [-5.5, 10.5) (the solver's
bracket ``sigma_a`` (-5, 10) with a margin) a polynomial of degree 12 in
the piece's own variable ``t`` in [-1, 1] gives ``F_m`` itself for
``s < 0`` (smooth, growing like ``|s|^m``) and ``F_m(s) / exp(-s²/2)``
for ``s >= 0`` (smooth, decaying like ``s^-(m+1)``), evaluated by Estrin's
scheme; the Gaussian factor is ``exp`` of the exactly split ``s²``.  The
coefficients are built at import (a few milliseconds, ``_build_tables``)
by Chebyshev interpolation of values computed without any cancellation:
``F_m(s) = sqrt(2/pi) ∫_0^∞ u^(2m+1) exp(-(s + u²)²/2) du`` has an even,
entire, super-exponentially decaying integrand, so the trapezoidal rule
with step 1/16 is exact to rounding (measured: 2e-16 against 30-digit
``mpmath``).  Measured against 34-digit ``mpmath`` at 6 500 points of the
range (and 40-digit values at every piece boundary, in the tests):
relative error below 2.6e-15 for both functions, truncation and rounding
together; :func:`gw_half_integer_pair_fast` documents 5e-15.  That
is more accurate than the Bessel formulas of the exact pair, whose
``K_{3/4} - K_{1/4}`` and ``F_{-1/2}/2 - s F_{1/2}`` cancel by up to 3e-12
(near ``s = 2.8``); the two pairs therefore differ by up to 3e-12 there and
by about 1e-14 elsewhere.

A second table, ``s`` as piecewise polynomials of ``log F_{3/2}``
(:data:`INVERSE_PIECES` = 65 pieces of degree 12, built from the first by
Newton at import; error in ``s`` below 2e-12), gives the inverse
(:func:`inverse_position`, :func:`inverse_at`): one ``log`` and one
polynomial piece.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.special import ive, kve

__all__ = [
    "FAST_RANGE",
    "INVERSE_PIECES",
    "gw_half_integer_pair",
    "gw_half_integer_pairs",
    "gw_half_integer_pair_fast",
    "fast_pair",
    "inverse_position",
    "inverse_at",
    "tail_moments",
]

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
    """``(F_{1/2}(s), F_{3/2}(s))`` of the standard normal density (:ref:`guide-pol-ind-summation`).

    The formulas of :mod:`polind.contact.greenwood`, whose
    :func:`~polind.contact.greenwood.half_integer_pair` and
    :func:`~polind.contact.greenwood.gw_integral` call this function:
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
def gw_half_integer_pairs(s, addresses):
    """:func:`gw_half_integer_pair` at every element of ``s``: the vectorised pair.

    What :func:`polind.contact.greenwood.gw_integral` evaluates arrays with.

    Parameters
    ----------
    s : numpy.ndarray
        Normalised separations ``d / sigma_a`` [-], one-dimensional.
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses`.

    Returns
    -------
    tuple of numpy.ndarray
        ``F_{1/2}`` and ``F_{3/2}`` at each ``s``, with the special values
        of :func:`gw_half_integer_pair`.
    """
    f_half = np.empty(s.size)
    f_three_halves = np.empty(s.size)
    for index in range(s.size):
        f_half[index], f_three_halves[index] = gw_half_integer_pair(s[index], addresses)
    return f_half, f_three_halves


# --------------------------------------------------------------------------- the fast pair

#: The range of ``s`` on which :func:`gw_half_integer_pair_fast` uses its polynomials.
FAST_RANGE = (-5.5, 10.5)
_FAST_LOWER, _FAST_UPPER = FAST_RANGE
_PIECE_WIDTH = 0.5
_PIECES = 32
# Piece variable t = (s - centre) * 4, exactly (the centres are multiples of 1/4).
_PIECE_SCALE = 2.0 / _PIECE_WIDTH
_DEGREE = 12                      # _estrin is written out for this degree
_COEFFICIENTS = _DEGREE + 1
# Pieces below this one (s < 0) hold F_m; from it on (s >= 0) F_m / exp(-s²/2).
_FIRST_GAUSSIAN_PIECE = 11
#: Pieces of the inverse polynomials (:func:`inverse_position`, :func:`inverse_at`).
INVERSE_PIECES = 65
# The trapezoidal rule of _quadrature_pair: step and end of the integration variable u.
_TRAPEZOID_STEP = 1.0 / 16.0
_TRAPEZOID_END = 7.0


def _quadrature_pair(s, scaled):
    """Build time: ``(F_{1/2}, F_{3/2})`` at the points ``s`` (NumPy), over ``exp(-s²/2)`` where ``scaled``.

    With ``t = s + u²``, ``F_m(s) = sqrt(2/pi) ∫_0^∞ u^(2m+1) exp(-(s + u²)²/2) du``:
    a sum of positive terms (no cancellation), and an integrand that is even
    in ``u``, entire, and decays like ``exp(-u⁴/2)``, so the trapezoidal rule
    converges geometrically in the step and is exact to rounding with step
    1/16 up to ``u = 7`` (the terms beyond are below 1e-300 on
    :data:`FAST_RANGE`).  Divided by ``exp(-s²/2)`` the exponent is
    ``-(s u² + u⁴/2)``, exact to rounding as well.
    """
    s = np.asarray(s, dtype=float)[..., None]
    u = np.arange(1, round(_TRAPEZOID_END / _TRAPEZOID_STEP) + 1) * _TRAPEZOID_STEP
    u2 = u * u
    exponent = np.where(np.asarray(scaled)[..., None], -(s * u2 + 0.5 * u2 * u2), -0.5 * (s + u2) ** 2)
    terms = u2 * np.exp(exponent)
    factor = math.sqrt(2.0 / math.pi) * _TRAPEZOID_STEP
    return factor * terms.sum(axis=-1), factor * (terms * u2).sum(axis=-1)


def _chebyshev_nodes():
    """The ``_DEGREE + 1`` Chebyshev points of the first kind in [-1, 1]."""
    return np.cos(np.pi * (np.arange(_COEFFICIENTS) + 0.5) / _COEFFICIENTS)


def _interpolate(values):
    """Monomial coefficients in ``t`` of the interpolants of ``values`` (rows) at :func:`_chebyshev_nodes`.

    First the Chebyshev coefficients (the discrete cosine transform of the
    values: what ``numpy.polynomial.chebyshev.chebfit`` gives at these
    points), then the monomial coefficients of ``T_0 .. T_12`` (the integer
    matrix of ``cheb2poly``, from ``T_{j+1} = 2 t T_j - T_{j-1}``).  In two
    steps, because the smooth values make the high Chebyshev coefficients
    tiny *before* they meet the large entries of the conversion (the
    composed matrix would cost 1e-12).
    """
    n = _COEFFICIENTS
    angles = np.pi * np.outer(np.arange(n), np.arange(n) + 0.5) / n
    to_chebyshev = 2.0 / n * np.cos(angles)
    to_chebyshev[0] *= 0.5
    to_power = np.zeros((n, n))
    to_power[0, 0] = to_power[1, 1] = 1.0
    for j in range(1, n - 1):
        to_power[1:, j + 1] = 2.0 * to_power[:-1, j]
        to_power[:, j + 1] -= to_power[:, j - 1]
    return (values @ to_chebyshev.T) @ to_power.T


def _horner(coefficients, t):
    """Build time: the polynomials of the rows of ``coefficients`` at ``t`` (NumPy)."""
    total = np.zeros(np.shape(t))
    for k in range(coefficients.shape[-1] - 1, -1, -1):
        total = total * t + coefficients[..., k]
    return total


def _build_tables():
    """The coefficient tables of :func:`gw_half_integer_pair_fast` and of :func:`inverse_at`.

    Returns ``(forward, inverse, log_lower, inverse_scale)``: ``forward``
    holds, for each of the ``_PIECES`` pieces of :data:`FAST_RANGE`, the
    monomial coefficients in ``t`` of ``F_{1/2}`` and then of ``F_{3/2}``
    (divided by ``exp(-s²/2)`` from piece ``_FIRST_GAUSSIAN_PIECE`` on), each
    the degree-12 interpolant at the piece's Chebyshev points of
    :func:`_quadrature_pair`; ``inverse`` the coefficients of ``s`` as a
    function of ``log F_{3/2}``, on :data:`INVERSE_PIECES` equal pieces from
    ``log_lower = log F_{3/2}(10.5)`` to ``log F_{3/2}(-5.5)``, interpolating
    the inverse of the forward table (Newton, to rounding) at their Chebyshev
    points; ``inverse_scale`` is pieces per unit of ``log F_{3/2}``.  All flat
    float64 arrays, read-only.
    """
    nodes = _chebyshev_nodes()
    pieces = np.arange(_PIECES)
    centres = _FAST_LOWER + (pieces + 0.5) * _PIECE_WIDTH
    scaled = pieces >= _FIRST_GAUSSIAN_PIECE
    points = centres[:, None] + nodes[None, :] / _PIECE_SCALE
    f_half, f_three_halves = _quadrature_pair(points, np.broadcast_to(scaled[:, None], points.shape))
    forward = np.stack([_interpolate(f_half), _interpolate(f_three_halves)], axis=1)

    def log_pair(s):
        """``(log F_{3/2}(s), F_{1/2}/F_{3/2})`` from the forward table (NumPy)."""
        piece = np.clip(((s - _FAST_LOWER) * _PIECE_SCALE / 2.0).astype(np.int64), 0, _PIECES - 1)
        t = (s - (_FAST_LOWER + (piece + 0.5) * _PIECE_WIDTH)) * _PIECE_SCALE
        half = _horner(forward[piece, 0], t)
        three_halves = _horner(forward[piece, 1], t)
        gaussian = np.where(piece >= _FIRST_GAUSSIAN_PIECE, -0.5 * s * s, 0.0)
        return np.log(three_halves) + gaussian, half / three_halves

    ends = np.array([_FAST_UPPER, _FAST_LOWER])
    log_lower, log_upper = _quadrature_pair(ends, ends > 0.0)[1]
    log_lower, log_upper = math.log(log_lower) - 0.5 * _FAST_UPPER**2, math.log(log_upper)
    width = (log_upper - log_lower) / INVERSE_PIECES
    levels = log_lower + (np.arange(INVERSE_PIECES)[:, None] + 0.5 + 0.5 * nodes[None, :]) * width
    # Newton on log F_{3/2}(s) = level (dlog F_{3/2}/ds = -1.5 F_{1/2}/F_{3/2}),
    # from linear interpolation in a table of the forward function.
    grid = np.linspace(_FAST_LOWER, _FAST_UPPER, 1601)
    grid_levels = log_pair(grid)[0]
    s = np.interp(levels, grid_levels[::-1], grid[::-1])
    for _ in range(8):
        level, ratio = log_pair(s)
        s = np.clip(s + (level - levels) / (1.5 * ratio), _FAST_LOWER, _FAST_UPPER)
    inverse = _interpolate(s)
    tables = (np.ascontiguousarray(forward).ravel(), np.ascontiguousarray(inverse).ravel())
    for table in tables:
        table.setflags(write=False)
    return tables[0], tables[1], log_lower, 1.0 / width


# Compiled into the kernels as constants (numba freezes global arrays).
_FORWARD, _INVERSE, _LOG_LOWER, _INVERSE_SCALE = _build_tables()

@jit(fastmath=False)
def _estrin(coefficients, base, t):
    """``c[base] + c[base+1] t + ... + c[base+12] t^12`` by Estrin's scheme.

    A dependency chain of four multiply-adds instead of Horner's twelve: the
    Newton iteration waits for each evaluation.
    """
    c = coefficients
    t2 = t * t
    t4 = t2 * t2
    t8 = t4 * t4
    q0 = (c[base] + c[base + 1] * t) + (c[base + 2] + c[base + 3] * t) * t2
    q1 = (c[base + 4] + c[base + 5] * t) + (c[base + 6] + c[base + 7] * t) * t2
    q2 = (c[base + 8] + c[base + 9] * t) + (c[base + 10] + c[base + 11] * t) * t2
    return (q0 + q1 * t4) + (q2 + c[base + 12] * t4) * t8


@jit(fastmath=False)
def _gaussian(s):
    """``exp(-s²/2)`` with ``s²`` split exactly (the rounding of ``s * s`` would cost ``s²/2`` ulps).

    ``s = high + low`` with ``high`` rounded to float32, so ``high²`` is an
    exact double and ``exp(-high²/2)`` is ``exp`` of an exact argument; the
    small rest ``b = low (2 high + low) / 2`` (below 7e-6 on
    :data:`FAST_RANGE`) enters as ``exp(-b) = 1 - b (1 - b/2)``, the
    neglected ``b³/6`` below 1e-16.
    """
    high = np.float64(np.float32(s))
    low = s - high
    rest = 0.5 * low * (2.0 * high + low)
    return math.exp(-0.5 * (high * high)) * (1.0 - rest * (1.0 - 0.5 * rest))


@jit(fastmath=False)
def fast_pair(s):
    """The polynomials of :func:`gw_half_integer_pair_fast` at ``s`` in :data:`FAST_RANGE` (not checked).

    Scalars only (no array argument), so that it is inlined into its
    callers without the reference counting an array would bring.
    """
    piece = int((s - _FAST_LOWER) * (0.5 * _PIECE_SCALE))
    if piece >= _PIECES:
        # s within rounding of the upper end.
        piece = _PIECES - 1
    t = (s - (_FAST_LOWER + (piece + 0.5) * _PIECE_WIDTH)) * _PIECE_SCALE
    base = 2 * _COEFFICIENTS * piece
    f_half = _estrin(_FORWARD, base, t)
    f_three_halves = _estrin(_FORWARD, base + _COEFFICIENTS, t)
    if piece >= _FIRST_GAUSSIAN_PIECE:
        gaussian = _gaussian(s)
        f_half *= gaussian
        f_three_halves *= gaussian
    return f_half, f_three_halves


@jit(fastmath=False)
def gw_half_integer_pair_fast(s, addresses):
    """``(F_{1/2}(s), F_{3/2}(s))``: an approximation, relative error below 5e-15 on :data:`FAST_RANGE`.

    On ``s`` in [-5.5, 10.5) the piecewise polynomials of the module notes
    ("The fast pair"; measured relative error below 2.6e-15 against 40-digit
    ``mpmath``, about 30 ns); elsewhere, and for NaN and ±inf,
    :func:`gw_half_integer_pair` itself.  It differs from
    :func:`gw_half_integer_pair` by up to 3e-12 near ``s = 2.8``, by the
    exact pair's own cancellation error.

    Parameters
    ----------
    s : float
        Normalised separation ``d / sigma_a`` [-].
    addresses : numpy.ndarray
        :func:`polind.kernels.special.special_addresses` (used outside
        :data:`FAST_RANGE`).

    Returns
    -------
    tuple of float
        ``F_{1/2}(s)`` and ``F_{3/2}(s)``.
    """
    if _FAST_LOWER <= s and s < _FAST_UPPER:
        return fast_pair(s)
    return gw_half_integer_pair(s, addresses)


@jit(inline="always", fastmath=False)
def inverse_position(value):
    """Where ``F_{3/2} = value`` falls in the pieces of the inverse polynomials.

    ``0 .. INVERSE_PIECES`` for ``s`` inside :data:`FAST_RANGE` (0 at its
    upper end, :data:`INVERSE_PIECES` at its lower end); outside that
    interval, or NaN, ``value`` is beyond the polynomials.
    """
    return (math.log(value) - _LOG_LOWER) * _INVERSE_SCALE


@jit(inline="always", fastmath=False)
def inverse_at(position):
    """``s`` from the inverse polynomials at a ``position`` in [0, :data:`INVERSE_PIECES`] (not checked).

    With :func:`inverse_position`, the inverse of ``F_{3/2}`` on
    :data:`FAST_RANGE`: error in ``s`` below 2e-12.
    """
    piece = int(position)
    if piece >= INVERSE_PIECES:
        piece = INVERSE_PIECES - 1
    return _estrin(_INVERSE, _COEFFICIENTS * piece, 2.0 * (position - piece) - 1.0)


@jit
def tail_moments(heights, counts, d):
    """Sums over the summits above ``d`` of ``counts * delta^p``, ``p = 0, 1/2, 1, 3/2``.

    ``heights`` is sorted ascending, so the summits in contact are a tail;
    summing it from its lowest member adds the small terms first.  The sums
    may be reassociated (fast-math ``reassoc``): LLVM then sums in vector
    lanes, three times faster for a measured map's 1,014 summits, which the
    separation solver sums at every change of the load; the result moves by
    rounding only (a few ulp of each sum).  The one
    sum behind every total of a direct surface
    (:class:`polind.contact.surface.DirectSurface`) and of its load in the
    separation solver (:func:`polind.kernels.separation.direct_load_and_slope`).

    Returns
    -------
    tuple of float
        The count ``sum c_i``, ``sum c_i delta_i^(1/2)``, ``sum c_i delta_i``
        and ``sum c_i delta_i^(3/2)``, ``delta_i = h_i - d``.
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
