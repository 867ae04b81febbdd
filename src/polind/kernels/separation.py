"""The separation under a normal load, inside numba kernels.

Kernel versions of the Greenwood–Williamson load integrals and of the
safeguarded Newton iteration of :mod:`polind.contact.separation`, so that a
model kernel can re-solve the separation ``d`` for a new normal load at
every sample without returning to Python:

- :func:`gw_half_integer_pair`: ``(F_{1/2}(s), F_{3/2}(s))`` with
  ``F_m(s) = ∫_s^∞ (t - s)^m phi(t) dt``, the same branches, formulas and
  Taylor cut-off as :func:`polind.contact.greenwood.half_integer_pair`
  (modified Bessel functions of order ±1/4, ±3/4 from SciPy, through
  :mod:`polind.kernels.special`);
- :func:`gw_half_integer_pair_fast`: the same pair from piecewise
  polynomials on :data:`FAST_RANGE` (an approximation, relative error below
  5e-15 there; see "The fast pair" below), :func:`gw_half_integer_pair`
  outside it;
- :func:`statistical_load_and_slope` and :func:`direct_load_and_slope`:
  ``(N(d), dN/dd)`` of the statistical (Gaussian, with the fast pair) and
  the direct (summed summits) surface;
- :func:`newton_separation`: Newton on ``log N(d) = log N_app`` kept in a
  bracket, bisection when a step leaves it, stopping at
  ``|N(d) - N_app| <= 1e-10 N_app`` (statistical surface: ``0.9e-10``, see
  :data:`STATISTICAL_STOP`), returning the best ``d`` seen if the bracket
  shrinks to adjacent doubles; :func:`statistical_start` is the start for a
  statistical surface (the inverse of ``F_{3/2}``, accurate enough that the
  first evaluation meets the tolerance), :func:`predicted_start` the warm
  start of a direct surface from the previous solution and
  :func:`direct_lower_bound` the lower end of a direct surface's bracket.

The mathematics is in the user guide: :ref:`guide-pol-ind-summation` and
:ref:`guide-pol-ind-separation`.

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

Because the Newton iteration balances the fast ``N(d)``, it stops for a
statistical surface at ``0.9e-10 N_app`` (:data:`STATISTICAL_STOP`): the
1e-11 left covers both the approximation and the exact formulas' own error,
so ``|N(d) - N_app| <= 1e-10 N_app`` holds with either.  A second table,
``s`` as piecewise polynomials of ``log F_{3/2}`` (65 pieces of degree 12,
built from the first by Newton at import; error in ``s`` below 2e-12), is
:func:`statistical_start`: from it the first evaluation meets the
tolerance, so a changed load costs one ``log``, two polynomial pieces and
one ``exp``, about 50 ns.  A direct evaluation is a sum over the summits
above ``d``.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.kernels.special import IVE, KVE, ive, kve

__all__ = [
    "STATISTICAL",
    "DIRECT",
    "RELATIVE_TOLERANCE",
    "STATISTICAL_STOP",
    "MAX_ITERATIONS",
    "FAST_RANGE",
    "gw_half_integer_pair",
    "gw_half_integer_pair_fast",
    "tail_moments",
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
    "newton_separation_counted",
    "newton_separation_series",
]

#: Surface kinds of the ``kind`` argument.
STATISTICAL, DIRECT = 0, 1

#: Required accuracy of the load balance, ``|N(d) - N_app| <= tol N_app``.
RELATIVE_TOLERANCE = 1e-10

#: Where the iteration stops for a statistical surface, relative to ``N_app``:
#: its ``N(d)`` is the fast pair's, within 5e-15 of the true value and
#: within 3e-12 of the exact Bessel formulas', so stopping 1e-11 short of
#: :data:`RELATIVE_TOLERANCE` keeps the balance to 1e-10 by either measure.
STATISTICAL_STOP = 0.9 * RELATIVE_TOLERANCE

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
    """``(F_{1/2}(s), F_{3/2}(s))`` of the standard normal density (:ref:`guide-pol-ind-summation`).

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
_INVERSE_PIECES = 65
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
    """The coefficient tables of :func:`gw_half_integer_pair_fast` and :func:`statistical_start`.

    Returns ``(forward, inverse, log_lower, inverse_scale)``: ``forward``
    holds, for each of the ``_PIECES`` pieces of :data:`FAST_RANGE`, the
    monomial coefficients in ``t`` of ``F_{1/2}`` and then of ``F_{3/2}``
    (divided by ``exp(-s²/2)`` from piece ``_FIRST_GAUSSIAN_PIECE`` on), each
    the degree-12 interpolant at the piece's Chebyshev points of
    :func:`_quadrature_pair`; ``inverse`` the coefficients of ``s`` as a
    function of ``log F_{3/2}``, on ``_INVERSE_PIECES`` equal pieces from
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
    width = (log_upper - log_lower) / _INVERSE_PIECES
    levels = log_lower + (np.arange(_INVERSE_PIECES)[:, None] + 0.5 + 0.5 * nodes[None, :]) * width
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
# The summit arrays a statistical surface passes to newton_separation_counted.
_NO_SUMMITS = np.empty(0)


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
def _fast_pair(s):
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
        return _fast_pair(s)
    return gw_half_integer_pair(s, addresses)


@jit(fastmath=False)
def statistical_start(load, load_scale, height_std):
    """Where :func:`newton_separation` starts on a statistical surface, from the inverse of its load.

    ``sigma_a s`` with ``F_{3/2}(s) = load / load_scale``, ``s`` from the
    piecewise polynomials of ``log F_{3/2}`` (module notes;
    error in ``s`` below 2e-12, so the load there is within 3e-11 of
    ``load`` and the first evaluation meets :data:`STATISTICAL_STOP`).  A
    load beyond the ends of :data:`FAST_RANGE` gives the nearer end.

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
    position = _inverse_position(load, load_scale)
    if not position > 0.0:
        # Beyond s = 10.5 (or NaN).
        position = 0.0
    if position > _INVERSE_PIECES:
        position = _INVERSE_PIECES
    return _inverse_separation(position, height_std)


@jit(inline="always", fastmath=False)
def _inverse_position(load, load_scale):
    """Where ``load`` falls in the pieces of the inverse polynomials (0 .. _INVERSE_PIECES inside)."""
    return (math.log(load / load_scale) - _LOG_LOWER) * _INVERSE_SCALE


@jit(inline="always", fastmath=False)
def _inverse_separation(position, height_std):
    """``sigma_a s`` from the inverse polynomials at a ``position`` in [0, _INVERSE_PIECES]."""
    piece = int(position)
    if piece >= _INVERSE_PIECES:
        piece = _INVERSE_PIECES - 1
    return height_std * _estrin(_INVERSE, _COEFFICIENTS * piece, 2.0 * (position - piece) - 1.0)


@jit(fastmath=False)
def statistical_load_and_slope(d, load_scale, height_std, addresses):
    """``(N(d), dN/dd)`` of the Gaussian surface summed statistically (:ref:`guide-pol-ind-summation`).

    ``N = load_scale F_{3/2}(d/sigma_a)``, ``dN/dd = -(3/2) load_scale
    F_{1/2}(d/sigma_a) / sigma_a``, the formulas of
    :meth:`polind.contact.surface.StatisticalSurface.load_and_slope` with
    the fast pair (:func:`gw_half_integer_pair_fast`): within 5e-15 of
    the true values, within 3e-12 of the exact Bessel pair's.

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
    """``(N(d), dN/dd)`` of a finite set of summits, a plain sum (approach I, :ref:`guide-pol-ind-summation`).

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
    # The fast statistical N(d) stops short of the tolerance (STATISTICAL_STOP).
    tolerance = (STATISTICAL_STOP if kind == STATISTICAL else RELATIVE_TOLERANCE) * load
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
        value, slope = surface_load_and_slope(d, kind, load_scale, height_std, heights, counts, hertz,
                                              addresses)
        error = abs(value - load)
        if error < best_error:
            best_d = d
            best_error = error
            best_value = value
            best_slope = slope
        if error <= tolerance:
            return d, value, slope, iteration
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
    return best_d, best_value, best_slope, iteration


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
        f_half, f_three_halves = _fast_pair(s)
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
    d, value, slope, evaluations = newton_separation_counted(load, d, lo, hi, STATISTICAL, load_scale,
                                                             height_std, _NO_SUMMITS, _NO_SUMMITS, 0.0,
                                                             addresses)
    return d, value, slope, 1 + evaluations


@jit(fastmath=False)
def statistical_separation_only(load, lo, hi, load_scale, height_std, kve_address, ive_address):
    """The separation of :func:`statistical_separation_at` alone, without its check inside the bracket.

    For a load whose start (:func:`statistical_start`) lies strictly inside
    ``[lo, hi]`` and inside :data:`FAST_RANGE` (not at an end it was clamped
    to) this returns the start itself, which
    :func:`statistical_separation_at` returns as well after one evaluation
    of ``N(d)`` that confirms the balance: the inverse polynomials put it
    within 2e-12 of the true ``s``, within 3e-11 of the load (measured at
    12,000 points over :data:`FAST_RANGE` and at 2,000 loads over a
    surface's load range, in the tests), so that evaluation always passes
    there.  Skipping it cuts the separation of a model kernel's load update
    from about 50 ns to 10-17 ns (the evaluation waits for the start, and
    ``exp`` waits for it).  A start on or beyond an end of the bracket (a
    load the polynomials do not cover, or NaN) goes to
    :func:`statistical_separation_at`, with its Newton fallback.  What a
    model kernel needs is ``d``; ``N(d)`` and ``dN/dd`` serve only the warm
    start of a direct surface.
    """
    position = _inverse_position(load, load_scale)
    if 0.0 < position and position < _INVERSE_PIECES:
        # statistical_start, not clamped: s inside FAST_RANGE.
        d = _inverse_separation(position, height_std)
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
