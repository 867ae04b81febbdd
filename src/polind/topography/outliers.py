"""Outliers (spikes) of a height map: found by a robust rule, reported, removed on request.

An optical profiler or an AFM leaves a few points far from the surface: a
lost fringe, a dust grain, a tip jump, the dark edge of an unmeasured
region.  Each one drags the least-squares plane, multiplies the rms height
and the rms slope, and makes a summit (or kills the summits around it).
:ref:`guide-measured-surfaces-conditioning` gives the rule:

- levelled heights ``r`` (the map minus its plane, or line by line);
- their median ``m`` and robust standard deviation
  ``s = 1.4826 median(|r - m|)`` (the median absolute deviation, scaled to
  the standard deviation of a Gaussian; unlike the rms it is not inflated
  by the outliers themselves);
- an outlier is a valid point with ``|r - m| > k s``, ``k =``
  :data:`OUTLIER_THRESHOLD` ``= 8``: a Gaussian surface has no such point in
  10^14 (P = 1.2e-15), the spikes this is for lie tens to hundreds of ``s``
  away.  A surface with genuinely heavy tails (the deep valleys of a
  plateau-honed liner) can have real points there: they are reported, and
  removing them is the user's decision;
- the levelling is redone without the outliers found and the rule applied
  again to the points left, until no new one is found (a spike tilts the
  plane; at most :data:`ROUNDS` rounds).

:func:`find_outliers` returns the mask; :func:`polind.topography.analyse`
reports their number and, with ``remove_outliers``, marks them missing, as
the instrument's own missing points are.
"""

from __future__ import annotations

import numpy as np

from polind.topography.summits import level_map

__all__ = ["OUTLIER_THRESHOLD", "MAD_TO_STD", "ROUNDS", "find_outliers", "robust_scale"]

#: ``k``: an outlier lies more than ``k`` robust standard deviations from the median height.
OUTLIER_THRESHOLD = 8.0
#: ``1 / Phi^-1(3/4)``: the median absolute deviation of a Gaussian times this is its sigma.
MAD_TO_STD = 1.482602218505602
#: Most rounds of levelling without the outliers and looking again.
ROUNDS = 5


def robust_scale(values) -> tuple[float, float]:
    """``(median, 1.4826 median |x - median|)`` of the finite values.

    The robust centre and standard deviation of :func:`find_outliers`.  If
    more than half the values are equal (a median absolute deviation of
    zero), the root mean square about the median stands in for the scale.

    Examples
    --------
    >>> x = np.array([0.0, 1.0, -1.0, 2.0, -2.0, np.nan, 1000.0])
    >>> [round(value, 4) for value in robust_scale(x)]
    [0.5, 2.2239]
    """
    finite = np.asarray(values, dtype=np.float64)
    finite = finite[np.isfinite(finite)]
    if finite.size == 0:
        return 0.0, 0.0
    centre = float(np.median(finite))
    deviations = np.abs(finite - centre)
    scale = MAD_TO_STD * float(np.median(deviations))
    if scale == 0.0:
        scale = float(np.sqrt(np.mean(deviations**2)))
    return centre, scale


def find_outliers(heights, pixel_size, levelling="plane", threshold=OUTLIER_THRESHOLD,
                  source="height map", levelled=None):
    """The outliers of a height map by the robust rule of this module.

    Parameters
    ----------
    heights : numpy.ndarray
        ``h[i, j]`` [m] as measured (before levelling), ``NaN`` where missing.
    pixel_size : pair of float
        ``(dx, dy)`` [m].
    levelling : {"plane", "lines"}, optional
        How the map is levelled before the heights are judged
        (:func:`~polind.topography.summits.level_map`).
    threshold : float, optional
        ``k``, in robust standard deviations.
    source : str, optional
        Named in error messages.
    levelled : numpy.ndarray, optional
        ``heights`` levelled by ``levelling`` already (the first round's), to
        save levelling it again.

    Returns
    -------
    numpy.ndarray of bool
        ``True`` at the outliers (never at a missing point).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> h = 1e-7 * rng.standard_normal((40, 50))
    >>> h[3, 4], h[20, 30] = -7e-5, 3e-6                 # two spikes
    >>> np.argwhere(find_outliers(h, (1e-6, 1e-6))).tolist()
    [[3, 4], [20, 30]]
    """
    h = np.asarray(heights, dtype=np.float64)
    outliers = np.zeros(h.shape, dtype=bool)
    for round_ in range(ROUNDS):
        if round_ or levelled is None:
            levelled = level_map(np.where(outliers, np.nan, h), pixel_size, levelling, source)
        centre, scale = robust_scale(levelled)
        with np.errstate(invalid="ignore"):
            new = np.abs(levelled - centre) > threshold * scale
        if scale == 0.0 or not new.any():
            break
        outliers |= new
    return outliers
