"""From a height map to asperity summits and their radii (:ref:`guide-measured-surfaces`).

The steps, each a function on a grid ``h[i, j]`` at ``x = i dx``, ``y = j dy``
with ``NaN`` for a missing point (missing points stay missing throughout):

1. :func:`mean_plane` / :func:`level`: subtract the least-squares plane
   ``a + b x + c y`` fitted over the valid points; or, for a scanning-probe
   map whose scan lines carry their own offsets and tilts,
   :func:`level_lines` (SurfaceTopography's line-by-line alignment, then the
   plane).
2. :func:`low_pass` (optional): the areal Gaussian filter of ISO 16610-61
   with 50 % transmission at the wavelength ``short_cutoff``.
3. :func:`find_summits`: a summit is an interior point, none of whose 8
   neighbours is missing, strictly higher than each of its 8 neighbours.
4. :func:`summit_curvatures`: ``kappa = -(h_xx + h_yy) / 2`` by central
   differences; the summit radius is ``R = 1 / kappa``.

Everything is vectorised NumPy (whole-array passes, no Python loop over
points): a 4096 x 4096 map is levelled and reduced to summits in about a
second.
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError
from polind.validation import check_number

__all__ = ["mean_plane", "level", "level_lines", "level_map", "check_levelling", "LEVELLINGS",
           "low_pass",
           "find_summits", "summit_candidates", "summit_curvatures", "ISO_GAUSSIAN_ALPHA"]

#: The ways of levelling a map (:func:`level_map`): the plane, or line by line.
LEVELLINGS = ("plane", "lines")

#: ``alpha = sqrt(ln 2 / pi)`` of the ISO 16610-61 Gaussian weighting function.
ISO_GAUSSIAN_ALPHA = math.sqrt(math.log(2.0) / math.pi)

# The 8 neighbours (di, dj) of a grid point.
_NEIGHBOURS = tuple((di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0))


def mean_plane(heights, pixel_size, source="height map"):
    """The least-squares plane ``a + b x + c y`` through the valid points.

    Minimises ``sum (h[i, j] - a - b x_i - c y_j)^2`` over the points that
    are not ``NaN`` (``x_i = i dx``, ``y_j = j dy``) by the 3 x 3 normal
    equations, assembled from row and column sums in index coordinates
    centred on the grid (so that they are well conditioned).

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m], ``NaN`` where missing.
    pixel_size : pair of float
        ``(dx, dy)`` [m].
    source : str
        Named in the error message.

    Returns
    -------
    tuple of float
        ``(a, b, c)``: ``a`` [m] (the plane at ``i = j = 0``), slopes ``b``
        and ``c`` [m/m].

    Raises
    ------
    polind.InputError
        If the valid points lie on one line (fewer than 3, or all in one
        row, column or diagonal): the plane is not determined.

    Examples
    --------
    >>> i, j = np.meshgrid(np.arange(4.0), np.arange(5.0), indexing="ij")
    >>> h = 1e-6 + 2e-3 * (i * 1e-6) - 5e-4 * (j * 2e-6)
    >>> np.allclose(mean_plane(h, (1e-6, 2e-6)), (1e-6, 2e-3, -5e-4), rtol=1e-12, atol=0)
    True
    """
    h = np.asarray(heights, dtype=np.float64)
    nx, ny = h.shape
    valid = ~np.isnan(h)
    filled = np.where(valid, h, 0.0)
    # Centred, scaled index coordinates u, v in [-1/2, 1/2]: all sums are O(n).
    u = (np.arange(nx) - 0.5 * (nx - 1)) / max(nx - 1, 1)
    v = (np.arange(ny) - 0.5 * (ny - 1)) / max(ny - 1, 1)
    per_row = valid.sum(axis=1, dtype=np.float64)
    per_column = valid.sum(axis=0, dtype=np.float64)
    count = per_row.sum()
    if valid.all():
        su_v = float(u.sum() * v.sum())
    else:
        su_v = float(u @ (valid @ v))
    matrix = np.array([
        [count, u @ per_row, v @ per_column],
        [u @ per_row, (u * u) @ per_row, su_v],
        [v @ per_column, su_v, (v * v) @ per_column],
    ])
    rhs = np.array([filled.sum(), u @ filled.sum(axis=1), filled.sum(axis=0) @ v])
    # Equilibrate before judging the rank: the diagonal can span many decades.
    scale = 1.0 / np.sqrt(np.maximum(np.diag(matrix), np.finfo(float).tiny))
    scaled = matrix * scale[:, None] * scale[None, :]
    if count < 3 or np.linalg.cond(scaled) > 1e12:
        raise InputError(f"{source}: the {int(count)} valid point(s) lie on one line, so the "
                         f"mean plane is not determined; expected valid points spread over "
                         f"the map.")
    a0, bu, cv = scale * np.linalg.solve(scaled, rhs * scale)
    dx, dy = pixel_size
    # Back to x = i dx, y = j dy: u = (i - (nx-1)/2) / (nx-1).
    b = bu / (max(nx - 1, 1) * dx)
    c = cv / (max(ny - 1, 1) * dy)
    a = a0 - b * 0.5 * (nx - 1) * dx - c * 0.5 * (ny - 1) * dy
    return float(a), float(b), float(c)


def level(heights, pixel_size, source="height map"):
    """``h`` minus its least-squares plane (:func:`mean_plane`); ``NaN`` stays ``NaN``.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m], ``NaN`` where missing.
    pixel_size : pair of float
        ``(dx, dy)`` [m].

    Returns
    -------
    numpy.ndarray
        The levelled heights [m] (a new array): their mean over the valid
        points is zero and they have no mean slope.

    Examples
    --------
    >>> h = np.array([[1.0, 2.0, 3.0], [2.0, np.nan, 4.0], [3.0, 4.0, 5.0]]) * 1e-9
    >>> out = level(h, (1e-6, 1e-6))
    >>> bool(np.isnan(out[1, 1])), float(np.nanmax(np.abs(out))) < 1e-15 * 5e-9
    (True, True)
    """
    a, b, c = mean_plane(heights, pixel_size, source)
    h = np.asarray(heights, dtype=np.float64)
    dx, dy = pixel_size
    levelled = h - a
    levelled -= (b * dx) * np.arange(h.shape[0], dtype=np.float64)[:, None]
    levelled -= (c * dy) * np.arange(h.shape[1], dtype=np.float64)[None, :]
    return levelled


def level_lines(heights, pixel_size, source="height map"):
    """Line-by-line levelling of a scanning-probe map, then :func:`level`.

    An AFM or STM builds its map one scan line at a time (along ``x``, the
    first index, the fast scan direction), and each line can carry its own
    offset and tilt from drift and the feedback loop: steps between lines
    that no plane removes.  SurfaceTopography's ``scan_line_align``
    (``direction="x"``, ``degree=1``, ``mode="median"``) subtracts from each
    line ``h[:, j]`` its own least-squares straight line over its valid
    points and then shifts the lines so that the medians of neighbouring
    lines agree; :func:`level` then removes what plane is left.  Any real
    height variation across the lines (along ``y``) is removed with the
    artefacts, so use it only on maps built line by line, never on an
    optical (areal) measurement.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m], ``NaN`` where missing; a scan line is ``h[:, j]``.
    pixel_size : pair of float
        ``(dx, dy)`` [m].
    source : str
        Named in error messages.

    Returns
    -------
    numpy.ndarray
        The levelled heights [m] (a new array), ``NaN`` where missing.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> rough = 1e-9 * rng.standard_normal((64, 32))             # the surface
    >>> x = np.arange(64.0)[:, None] / 64
    >>> lines = 5e-9 * rng.standard_normal(32) + 3e-9 * rng.standard_normal(32) * x
    >>> scanned = rough + lines                                   # each line's offset and tilt
    >>> by_lines, by_plane = level_lines(scanned, (1e-8, 1e-8)), level(scanned, (1e-8, 1e-8))
    >>> [round(float(np.std(h) / np.std(rough)), 1) for h in (by_lines, by_plane)]
    [1.0, 4.9]
    """
    from polind.topography.heightmap import HeightMap, surface_topography

    h = np.asarray(heights, dtype=np.float64)
    # A line with no valid point would make every offset after it NaN: align the others.
    lines = np.flatnonzero((~np.isnan(h)).any(axis=0))
    topography = surface_topography(HeightMap(h[:, lines], tuple(pixel_size), source))
    aligned = topography.scan_line_align(direction="x", mode="median", degree=1).heights()
    levelled = np.full(h.shape, np.nan)
    levelled[:, lines] = np.ma.filled(np.ma.asarray(aligned, dtype=np.float64), np.nan)
    levelled[np.isnan(h)] = np.nan
    return level(levelled, pixel_size, source)


def level_map(heights, pixel_size, levelling="plane", source="height map"):
    """:func:`level` (``levelling="plane"``) or :func:`level_lines` (``"lines"``).

    Raises
    ------
    polind.InputError
        If ``levelling`` is neither.
    """
    if check_levelling(levelling) == "lines":
        return level_lines(heights, pixel_size, source)
    return level(heights, pixel_size, source)


def check_levelling(levelling) -> str:
    """``levelling`` if it is one of :data:`LEVELLINGS`, else an InputError naming them."""
    if levelling not in LEVELLINGS:
        raise InputError(f"The 'levelling' parameter of topography must be one of "
                         f"{', '.join(repr(name) for name in LEVELLINGS)}. Got {levelling!r} "
                         f"instead.")
    return levelling


def low_pass(heights, pixel_size, short_cutoff):
    """The ISO 16610-61 areal Gaussian low-pass filter (short-wavelength cut-off).

    The weighting function is
    ``s(x, y) = exp(-pi (x^2 + y^2) / (alpha lc)^2) / (alpha lc)^2`` with
    ``alpha = sqrt(ln 2 / pi)``: its transmission
    ``exp(-pi (alpha lc / lambda)^2)`` is 50 % at the wavelength
    ``lambda = lc`` (``short_cutoff``).  It is a Gaussian of standard
    deviation ``alpha lc / sqrt(2 pi)``, applied separably.  Missing points
    and the outside of the map carry no weight: the filtered height is
    ``(s * h) / (s * w)`` with ``w`` = 1 on valid points and 0 elsewhere
    (normalised convolution), so the map keeps its size, no missing point
    takes part, and missing points stay missing.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m], ``NaN`` where missing.
    pixel_size : pair of float
        ``(dx, dy)`` [m].
    short_cutoff : float
        The cut-off wavelength ``lc`` [m], positive.

    Returns
    -------
    numpy.ndarray
        The filtered heights [m] (a new array), ``NaN`` where missing.

    Examples
    --------
    >>> x = np.arange(400) * 1e-7                       # 40 um, a 4 um wave
    >>> h = np.sin(2 * np.pi * x / 4e-6)[:, None] * np.ones(5)
    >>> out = low_pass(h, (1e-7, 1e-7), short_cutoff=4e-6)
    >>> round(float(np.abs(out[100:300, 2]).max()), 3)  # 50 % transmission
    0.5
    """
    from scipy import ndimage

    cutoff = check_number("topography", "short_cutoff", short_cutoff, "positive")
    h = np.asarray(heights, dtype=np.float64)
    valid = ~np.isnan(h)
    width = ISO_GAUSSIAN_ALPHA * cutoff / math.sqrt(2.0 * math.pi)
    sigma = (width / pixel_size[0], width / pixel_size[1])
    smoothed = ndimage.gaussian_filter(np.where(valid, h, 0.0), sigma, mode="constant", cval=0.0)
    weight = ndimage.gaussian_filter(valid.astype(np.float64), sigma, mode="constant", cval=0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        smoothed /= weight
    smoothed[~valid] = np.nan
    return smoothed


def find_summits(heights, tolerance=0.0):
    """The summits of a height map: indices ``(i, j)`` in row-major order.

    A summit is an interior point (not on the border), none of whose 8
    neighbours is missing, that is higher than each of its 8 neighbours by
    more than ``tolerance``.  A plateau of equal heights therefore has no
    summit, and a point next to a missing point is never one.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]``, ``NaN`` where missing.
    tolerance : float, optional
        Differences of height up to this [m] count as equal (the round-off
        of levelling, :func:`polind.topography.analyse`); default 0: strictly higher.

    Returns
    -------
    i, j : numpy.ndarray
        Integer index arrays of the summits.

    Examples
    --------
    >>> h = np.zeros((5, 5)); h[2, 2] = 1.0; h[1, 3] = 0.5
    >>> i, j = find_summits(h)
    >>> i.tolist(), j.tolist()
    ([2], [2])
    """
    h = np.asarray(heights, dtype=np.float64)
    nx, ny = h.shape
    if nx < 3 or ny < 3:
        empty = np.empty(0, dtype=np.intp)
        return empty, empty
    centre = h[1:-1, 1:-1]

    def neighbour(di, dj):
        return h[1 + di:nx - 1 + di, 1 + dj:ny - 1 + dj]

    # A comparison with NaN is False: a missing neighbour or centre excludes the point.
    if tolerance > 0.0:
        centre = centre - tolerance
    first, *others = _NEIGHBOURS
    summit = centre > neighbour(*first)
    for di, dj in others:
        np.logical_and(summit, centre > neighbour(di, dj), out=summit)
    i, j = np.nonzero(summit)
    return i + 1, j + 1


def summit_candidates(heights) -> int:
    """The number of points that could be summits: interior, valid, with 8 valid neighbours.

    A white-noise map (independent heights) has a summit at one in nine of
    them, each point of a 3 x 3 block being equally likely to be its highest
    (:ref:`guide-measured-surfaces-validity`).

    Examples
    --------
    >>> h = np.zeros((5, 6)); h[1, 1] = np.nan
    >>> summit_candidates(h)                # 3 x 4 interior points, 4 of them next to the hole
    8
    """
    valid = ~np.isnan(np.asarray(heights, dtype=np.float64))
    nx, ny = valid.shape
    if nx < 3 or ny < 3:
        return 0
    eligible = valid[1:-1, 1:-1].copy()
    for di, dj in _NEIGHBOURS:
        eligible &= valid[1 + di:nx - 1 + di, 1 + dj:ny - 1 + dj]
    return int(np.count_nonzero(eligible))


def summit_curvatures(heights, pixel_size, i, j):
    """Mean curvature ``kappa = -(h_xx + h_yy) / 2`` [1/m] at the points ``(i, j)``.

    Central differences:
    ``h_xx = (h[i+1, j] - 2 h[i, j] + h[i-1, j]) / dx^2`` and
    ``h_yy = (h[i, j+1] - 2 h[i, j] + h[i, j-1]) / dy^2``.  At a summit of
    :func:`find_summits` both differences are negative, so ``kappa > 0``
    and the summit radius ``R = 1 / kappa`` is positive and finite.  The
    differences are exact for a paraboloid: a cap
    ``h = H - x^2 / (2 R) - y^2 / (2 R)`` gives ``kappa = 1 / R``.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m].
    pixel_size : pair of float
        ``(dx, dy)`` [m].
    i, j : numpy.ndarray
        Interior indices (from :func:`find_summits`).

    Returns
    -------
    numpy.ndarray
        ``kappa`` [1/m] at each point.

    Examples
    --------
    >>> x = (np.arange(7) - 3) * 1e-6
    >>> cap = 1e-6 - (x[:, None] ** 2 + x[None, :] ** 2) / (2 * 50e-6)
    >>> kappa = summit_curvatures(cap, (1e-6, 1e-6), np.array([3]), np.array([3]))
    >>> round(float(1.0 / kappa[0]) / 50e-6, 12)
    1.0
    """
    h = np.asarray(heights, dtype=np.float64)
    dx, dy = pixel_size
    centre = h[i, j]
    h_xx = (h[i + 1, j] - 2.0 * centre + h[i - 1, j]) / (dx * dx)
    h_yy = (h[i, j + 1] - 2.0 * centre + h[i, j - 1]) / (dy * dy)
    return -0.5 * (h_xx + h_yy)
