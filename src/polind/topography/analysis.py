"""A measured surface reduced to its summits, and its Greenwood–Williamson equivalent.

:func:`analyse` conditions a :class:`~polind.topography.heightmap.HeightMap`
(levelling by plane or line by line, the outliers of
:mod:`polind.topography.outliers` found and, on request, marked missing),
runs the steps of :mod:`polind.topography.summits` (the optional low-pass,
summits, curvatures) and returns a :class:`MeasuredSurface`: the summit
heights and radii that direct summation sums over
(:ref:`guide-measured-surfaces`), and the statistics of the map:

- summit density ``eta = summits / (valid_points dx dy)``;
- the equivalent Greenwood–Williamson surface: this ``eta``,
  ``R = 1 / mean(kappa)`` and ``sigma_a`` = the standard deviation of the
  summit heights;
- the map's nominal (projected) area ``A_map = valid_points dx dy``, so that
  ``eta A_map`` is the number of summits;
- the standard roughness of :mod:`polind.topography.roughness`, a cut-off
  study (:func:`cutoff_study`: summits and ``1 / mean(kappa)`` against the
  low-pass cut-off), the plasticity index given a hardness, and warnings
  (outliers left in, summits near the white-noise rate).
"""

from __future__ import annotations

import functools
import math
import os
import warnings
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.validation import check_number
from polind.topography.heightmap import (LARGEST_HEIGHT, SMALLEST_HEIGHT, HeightMap,
                                         check_pixel_size, read_height_map)
from polind.topography.outliers import OUTLIER_THRESHOLD, find_outliers
from polind.topography.roughness import standard_roughness
from polind.topography.summits import (check_levelling, find_summits, level_map, low_pass,
                                       summit_candidates, summit_curvatures)

__all__ = ["MeasuredSurface", "analyse", "check_cutoff", "cutoff_study", "default_cutoffs",
           "load_measured_surface", "WHITE_NOISE_RATE", "NEAR_WHITE_NOISE"]

#: Summits per candidate point of a white-noise map (8-neighbour rule: 1 in 9).
WHITE_NOISE_RATE = 1.0 / 9.0
#: A summit density at least this share of the white-noise rate warns: the summits are
#: then at the pixel scale (a Gaussian surface gets there at a correlation length of
#: about 1.5 pixels), set by the sampling or the noise rather than by the asperities.
NEAR_WHITE_NOISE = 0.5
#: Most filtered rows of the default cut-off study.
STUDY_ROWS = 7

# Heights closer than this many times the largest height of the map (as measured) are
# equal to within the round-off of levelling (a few operations of relative error eps).
_ROUND_OFF = 64 * float(np.finfo(np.float64).eps)


@dataclass(frozen=True)
class MeasuredSurface:
    """A levelled height map and its summits (built by :func:`analyse`).

    Attributes
    ----------
    height_map : HeightMap
        The levelled (and, with a cut-off, low-passed) map the summits were
        found on: heights [m] above its mean plane, ``NaN`` where missing.
    summit_index : tuple of numpy.ndarray
        ``(i, j)``, the grid indices of the summits.
    summit_heights : numpy.ndarray
        Summit heights [m] above the mean plane of the map.
    summit_curvatures : numpy.ndarray
        Summit mean curvatures ``kappa`` [1/m], positive.
    short_cutoff : float or None
        The low-pass cut-off wavelength [m] applied, if any.
    levelled_map : HeightMap or None
        The conditioned map before the low-pass (levelled, outliers missing
        if removed); ``None``: the same as ``height_map`` (no cut-off).
    outlier_index : tuple of numpy.ndarray
        ``(i, j)``, the grid indices of the outliers found
        (:mod:`polind.topography.outliers`), removed or not.
    outliers_removed : bool
        Whether the outliers were marked missing.
    levelling : {"plane", "lines"}
        How the map was levelled.
    """

    height_map: HeightMap
    summit_index: tuple[np.ndarray, np.ndarray]
    summit_heights: np.ndarray
    summit_curvatures: np.ndarray
    short_cutoff: float | None = None
    levelled_map: HeightMap | None = None
    outlier_index: tuple[np.ndarray, np.ndarray] = (np.empty(0, dtype=np.intp),
                                                    np.empty(0, dtype=np.intp))
    outliers_removed: bool = False
    levelling: str = "plane"

    # --- the map ---------------------------------------------------------------------------

    @property
    def heights(self) -> np.ndarray:
        """The analysed heights ``h[i, j]`` [m], ``NaN`` where missing."""
        return self.height_map.heights

    @property
    def pixel_size(self) -> tuple[float, float]:
        """``(dx, dy)`` [m]."""
        return self.height_map.pixel_size

    @property
    def source(self) -> str:
        """What the map came from (a file name)."""
        return self.height_map.source

    @property
    def channel(self) -> str | None:
        """The channel of the file the heights were read from (``None`` for a grid)."""
        return self.height_map.channel

    @property
    def grid(self) -> tuple[int, int]:
        """``(nx, ny)``: points along ``x`` and ``y``."""
        return self.height_map.grid

    @property
    def valid_points(self) -> int:
        """Points of the map that are not missing."""
        return self.height_map.valid_points

    @property
    def nominal_area(self) -> float:
        """The projected area of the valid points, ``valid_points dx dy`` [m^2]."""
        return self.valid_points * self.pixel_size[0] * self.pixel_size[1]

    @property
    def rms_height(self) -> float:
        """Root mean square of the analysed heights over the valid points [m]."""
        return float(np.sqrt(np.nanmean(np.square(self.heights))))

    @property
    def outliers(self) -> int:
        """Number of outliers found (removed or not)."""
        return int(self.outlier_index[0].size)

    @functools.cached_property
    def roughness(self) -> dict:
        """``{Sa, Sq, Ssk, Sku, Sdq, rms_curvature}`` of the analysed map.

        :func:`polind.topography.roughness.standard_roughness` of
        ``height_map`` (levelled, outliers missing if removed, low-passed
        with a cut-off): ``Sq``, ``Sdq`` (SurfaceTopography's
        ``rms_gradient``) and ``rms_curvature`` computed by
        SurfaceTopography.
        """
        return standard_roughness(self.height_map)

    # --- the summits -----------------------------------------------------------------------

    @property
    def summits(self) -> int:
        """Number of summits."""
        return int(self.summit_heights.size)

    @property
    def summit_radii(self) -> np.ndarray:
        """Summit radii ``R_i = 1 / kappa_i`` [m]."""
        return 1.0 / self.summit_curvatures

    @property
    def summit_density(self) -> float:
        """``eta = summits / (valid_points dx dy)`` [1/m^2]."""
        return self.summits / self.nominal_area

    @property
    def summit_radius_mean(self) -> float:
        """``1 / mean(kappa)`` [m]: the radius of the Greenwood–Williamson equivalent."""
        return float(1.0 / np.mean(self.summit_curvatures))

    @property
    def summit_radius_median(self) -> float:
        """The median of the summit radii [m]."""
        return float(np.median(self.summit_radii))

    @property
    def summit_height_mean(self) -> float:
        """Mean summit height above the mean plane of the map [m]."""
        return float(np.mean(self.summit_heights))

    @property
    def summit_height_std(self) -> float:
        """Standard deviation of the summit heights [m] (population form, ``ddof = 0``)."""
        return float(np.std(self.summit_heights))

    @functools.cached_property
    def summit_candidates(self) -> int:
        """Points that could be summits: interior, valid, with 8 valid neighbours."""
        return summit_candidates(self.heights)

    @property
    def white_noise_share(self) -> float:
        """``summits / summit_candidates`` over the white-noise rate 1/9 (1: white noise)."""
        return self.summits / max(self.summit_candidates, 1) / WHITE_NOISE_RATE

    @functools.cached_property
    def cutoff_study(self) -> list:
        """The cut-off study (the ``--json`` table): :func:`~polind.topography.analysis.cutoff_study`.

        Over :func:`~polind.topography.analysis.default_cutoffs`.
        """
        return cutoff_study(self)

    def plasticity_index(self, effective_modulus, hardness) -> float:
        """``psi = (E* / H) sqrt(sigma_a / R)`` of the Greenwood–Williamson equivalent.

        Greenwood and Williamson (1966), with ``sigma_a`` the standard
        deviation of the summit heights and ``R = 1 / mean(kappa)``: below
        0.6 the contact is mostly elastic, above 1 mostly plastic.

        Parameters
        ----------
        effective_modulus : float
            ``E*`` [Pa].
        hardness : float
            ``H`` [Pa] of the softer body.

        Returns
        -------
        float
        """
        E_star = check_number("topography", "effective_modulus", effective_modulus, "positive")
        H = check_number("topography", "hardness", hardness, "positive")
        return float(E_star / H * math.sqrt(self.summit_height_std / self.summit_radius_mean))

    @property
    def warnings(self) -> tuple:
        """What the user should know about the map, as sentences (empty when all is well).

        Outliers found and left in; a summit density of at least
        :data:`~polind.topography.analysis.NEAR_WHITE_NOISE` of the white-noise rate.
        """
        notes = []
        if self.outliers and not self.outliers_removed:
            notes.append(
                f"{self.source}: {self.outliers} point(s) lie more than {OUTLIER_THRESHOLD:g} "
                f"robust standard deviations from the median height (outliers, spikes) and are "
                f"left in: they inflate the rms height, the slopes and the summits; "
                f"--remove-outliers ([model.surface] remove_outliers = true) marks them missing, "
                f"unless they are real (deep valleys).")
        share = self.white_noise_share
        if share >= NEAR_WHITE_NOISE:
            cutoff = "" if self.short_cutoff is None else \
                f" at the cut-off {self.short_cutoff:.3g} m"
            notes.append(
                f"{self.source}: {self.summits} summits are {100 * share:.0f} % of the white-noise "
                f"rate (1 in 9 of the points that can be summits){cutoff}: the summits are at the "
                f"pixel scale, set by noise or sampling rather than by the asperities; choose a "
                f"short_cutoff of a few pixels (see the cut-off study).")
        return tuple(notes)

    def greenwood_williamson(self) -> dict:
        """The statistical surface equivalent to the map, as ``[model.surface]`` keys.

        ``{asperity_density: eta, asperity_radius: 1 / mean(kappa),
        height_std: std(summit heights)}``, SI units.
        """
        return {"asperity_density": self.summit_density,
                "asperity_radius": self.summit_radius_mean,
                "height_std": self.summit_height_std}

    def summary(self, effective_modulus=None, hardness=None) -> dict:
        """The keys of ``polind topography --json`` (plain floats, ints, lists).

        ``grid``, ``pixel_size``, ``valid_points``, ``rms_height``,
        ``summits``, ``summit_density``, ``summit_radius_mean``,
        ``summit_radius_median``, ``summit_height_std``,
        ``greenwood_williamson``, ``roughness`` (:attr:`roughness`),
        ``channel``, ``outliers`` and ``cutoff_study`` (:attr:`cutoff_study`);
        also ``nominal_area`` (m^2), ``summit_height_mean`` (m, above the
        mean plane), ``short_cutoff`` (m, or None), ``levelling``,
        ``outliers_removed`` and ``warnings`` (:attr:`warnings`).  With both
        ``effective_modulus`` ``E*`` [Pa] and ``hardness`` ``H`` [Pa]:
        ``plasticity_index`` (:meth:`plasticity_index`).
        Every number is finite: a map whose statistics pass double precision is an
        InputError naming the key.  The hardness and modulus are checked
        first, before the statistics (the cut-off study low-passes the map
        several times) are computed.
        """
        if effective_modulus is not None or hardness is not None:
            if effective_modulus is None or hardness is None:
                missing = "effective_modulus" if effective_modulus is None else "hardness"
                raise InputError(f"The plasticity index of topography needs both a hardness and "
                                 f"an effective modulus; expected the '{missing}' too.")
            check_number("topography", "effective_modulus", effective_modulus, "positive")
            check_number("topography", "hardness", hardness, "positive")
        summary = {
            "grid": list(self.grid),
            "pixel_size": [float(size) for size in self.pixel_size],
            "valid_points": self.valid_points,
            "nominal_area": float(self.nominal_area),
            "rms_height": self.rms_height,
            "short_cutoff": None if self.short_cutoff is None else float(self.short_cutoff),
            "summits": self.summits,
            "summit_density": float(self.summit_density),
            "summit_radius_mean": self.summit_radius_mean,
            "summit_radius_median": self.summit_radius_median,
            "summit_height_mean": self.summit_height_mean,
            "summit_height_std": self.summit_height_std,
            "greenwood_williamson": {key: float(value) for key, value
                                     in self.greenwood_williamson().items()},
            "roughness": dict(self.roughness),
            "channel": self.channel,
            "levelling": self.levelling,
            "outliers": self.outliers,
            "outliers_removed": self.outliers_removed,
            "cutoff_study": [dict(row) for row in self.cutoff_study],
            "warnings": list(self.warnings),
        }
        bad = _first_non_finite(summary)
        if bad is not None:
            key, value = bad
            raise InputError(f"{self.source}: its {key} is {value} (beyond double "
                             f"precision); expected heights and pixel sizes of a physical "
                             f"size.")
        bad = _first_underflow(summary)
        if bad is not None:
            key, value = bad
            raise InputError(f"{self.source}: its {key} is {value!r} (below double precision: "
                             f"a map with summits has a positive one); expected heights and "
                             f"pixel sizes of a physical size.")
        if effective_modulus is not None:
            summary["plasticity_index"] = self.plasticity_index(effective_modulus, hardness)
        return summary


#: Keys of :meth:`MeasuredSurface.summary` positive for every map with a summit: one that
#: is 0 or subnormal has underflowed (heights tiny against the pixel size, or the reverse).
_POSITIVE_KEYS = ("nominal_area", "rms_height", "summit_density", "summit_radius_mean",
                  "summit_radius_median", "roughness.Sa", "roughness.Sq", "roughness.Sku",
                  "roughness.Sdq", "roughness.rms_curvature",
                  "greenwood_williamson.asperity_density", "greenwood_williamson.asperity_radius")
_TINY = float(np.finfo(np.float64).tiny)


def _first_underflow(summary):
    """``(key, number)`` of the first of :data:`_POSITIVE_KEYS` below the smallest normal double."""
    for key in _POSITIVE_KEYS:
        value = summary
        for part in key.split("."):
            value = value[part]
        if not value >= _TINY:
            return key, value
    return None


def _first_non_finite(value, where=""):
    """``(key path, number)`` of the first float in ``value`` (nested dicts and lists) that is not finite."""
    if isinstance(value, dict):
        items = ((f"{where}.{key}" if where else str(key), item) for key, item in value.items())
    elif isinstance(value, (list, tuple)):
        items = ((f"{where}[{index}]", item) for index, item in enumerate(value))
    else:
        return (where, value) if isinstance(value, float) and not np.isfinite(value) else None
    for path, item in items:
        found = _first_non_finite(item, path)
        if found is not None:
            return found
    return None


def analyse(height_map: HeightMap, short_cutoff=None, *, remove_outliers=False,
            levelling="plane", warn=True) -> MeasuredSurface:
    """Condition a height map, optionally low-pass it, and find its summits and radii.

    The steps (:ref:`guide-measured-surfaces-conditioning`):

    1. the outliers are found (:func:`~polind.topography.outliers.find_outliers`)
       and, with ``remove_outliers``, marked missing;
    2. the map is levelled (:func:`~polind.topography.summits.level_map`; with
       the outliers removed, fitted without them);
    3. with ``short_cutoff``, the ISO 16610-61 low-pass
       (:func:`~polind.topography.summits.low_pass`);
    4. summits and their curvatures.

    Parameters
    ----------
    height_map : HeightMap
        Heights [m] on a regular grid, ``NaN`` where missing.
    short_cutoff : float, optional
        Cut-off wavelength [m] of the ISO 16610-61 Gaussian low-pass applied
        after levelling; at least twice the smaller pixel spacing (the
        shortest wavelength on the grid).
    remove_outliers : bool, optional
        Mark the outliers missing (default: only count them).
    levelling : {"plane", "lines"}, optional
        ``"plane"``: the least-squares plane; ``"lines"``: line by line, for
        scanning-probe maps (:func:`~polind.topography.summits.level_lines`).
    warn : bool, optional
        Issue :attr:`MeasuredSurface.warnings` as ``UserWarning`` (default).

    Returns
    -------
    MeasuredSurface

    Raises
    ------
    polind.InputError
        If the cut-off is not a number of at least twice the smaller pixel
        spacing, the levelling is unknown, the mean plane is not determined,
        the map has no summit, or its largest height is below
        :data:`~polind.topography.heightmap.SMALLEST_HEIGHT` (1e-100 m) in
        size; the message names the map's source.

    Notes
    -----
    The heights analysed: the largest of them from 1e-100 to 1e100 m in
    size (:data:`~polind.topography.heightmap.SMALLEST_HEIGHT`,
    :data:`~polind.topography.heightmap.LARGEST_HEIGHT`).  That is far wider
    than any measured surface (picometres to millimetres), and as wide as
    double precision lets the analysis square and sum heights.  A map
    scaled by 1e-300 is refused, not analysed: its squares underflow to 0,
    which would report an rms height of 0 beside a dozen summits.  Heights
    that small are not in metres, and the message says what range is
    accepted.  A flat map is "no summit" at any scale.  Where the pixel size
    pushes a statistic below double precision all the same (tiny heights on
    huge pixels), :meth:`MeasuredSurface.summary` refuses it by name.

    Examples
    --------
    >>> x = (np.arange(9) - 4) * 1e-6
    >>> cap = np.maximum(0.0, 1e-7 - (x[:, None] ** 2 + x[None, :] ** 2) / (2 * 20e-6))
    >>> surface = analyse(HeightMap.from_array(cap, (1e-6, 1e-6)))
    >>> surface.summits, round(surface.summit_radius_mean / 20e-6, 12), surface.outliers
    (1, 1.0, 0)
    """
    dx, dy = height_map.pixel_size
    if short_cutoff is not None:
        short_cutoff = check_cutoff(short_cutoff, (dx, dy), height_map.source)
        nx, ny = height_map.grid
        extent = max(nx * dx, ny * dy)
        if short_cutoff > extent:
            raise InputError(f"{height_map.source}: the short_cutoff {short_cutoff!r} m is longer "
                             f"than the map ({extent:.6g} m across), which it would flatten; "
                             f"expected a cut-off shorter than the map.")
    check_levelling(levelling)
    if not isinstance(remove_outliers, (bool, np.bool_)):
        raise InputError(f"The 'remove_outliers' parameter of topography must be true or false. "
                         f"Got {remove_outliers!r} instead.")
    heights = level_map(height_map.heights, (dx, dy), levelling, height_map.source)
    outliers = find_outliers(height_map.heights, (dx, dy), levelling, source=height_map.source,
                             levelled=heights)
    if remove_outliers and outliers.any():        # levelled again, without them
        heights = level_map(np.where(outliers, np.nan, height_map.heights), (dx, dy), levelling,
                            height_map.source)
    levelled = HeightMap(heights, (float(dx), float(dy)), height_map.source, height_map.channel)
    analysed = levelled
    if short_cutoff is not None:
        analysed = HeightMap(low_pass(levelled.heights, (dx, dy), short_cutoff),
                             levelled.pixel_size, levelled.source, levelled.channel)
    heights = analysed.heights
    # Levelling leaves round-off of the size of the heights it subtracted the plane from
    # (a tilted plane is flat to within it): a summit must stand out of it.
    largest = float(np.nanmax(np.abs(height_map.heights)))
    i, j = find_summits(heights, tolerance=_ROUND_OFF * largest)
    if i.size == 0:
        raise InputError(f"{height_map.source}: the map has no summit (no interior point with "
                         f"8 valid neighbours stands above all of them by more than the "
                         f"round-off of levelling); expected a rough surface.")
    if largest < SMALLEST_HEIGHT:
        raise InputError(f"{height_map.source}: the largest height is {largest:.3g} m in size; "
                         f"expected heights in metres of a physical size, the largest from "
                         f"{SMALLEST_HEIGHT:g} to {LARGEST_HEIGHT:g} m (the squares of smaller "
                         f"heights fall below double precision: the rms height and the slopes "
                         f"would come out 0).")
    surface = MeasuredSurface(
        height_map=analysed,
        summit_index=(i, j),
        summit_heights=heights[i, j],
        summit_curvatures=summit_curvatures(heights, (dx, dy), i, j),
        short_cutoff=short_cutoff,
        levelled_map=None if short_cutoff is None else levelled,
        outlier_index=tuple(np.nonzero(outliers)),
        outliers_removed=bool(remove_outliers),
        levelling=levelling,
    )
    if warn:
        for note in surface.warnings:
            warnings.warn(note, UserWarning, stacklevel=2)
    return surface


def check_cutoff(short_cutoff, pixel_size, source="height map") -> float:
    """A ``short_cutoff`` [m] checked against the grid: at least ``2 min(dx, dy)``.

    Twice the smaller pixel spacing is the shortest wavelength on the grid
    (the Nyquist wavelength): a low-pass at a shorter one would do nothing.

    Raises
    ------
    polind.InputError
        Naming the parameter (``--short-cutoff``, ``[model.surface]
        short_cutoff``), the map and the smallest cut-off it allows.
    """
    cutoff = check_number("topography", "short_cutoff", short_cutoff, "positive")
    shortest = 2.0 * min(pixel_size)
    if cutoff < shortest * (1.0 - 1e-12):
        raise InputError(f"{source}: the 'short_cutoff' must be at least twice the smaller "
                         f"pixel spacing, {shortest:.6g} m (the shortest wavelength on the grid; "
                         f"a shorter cut-off filters nothing). Got {cutoff!r} instead.")
    return cutoff


def default_cutoffs(pixel_size, grid) -> list:
    """The cut-offs of the default :func:`cutoff_study` [m].

    ``2 min(dx, dy)`` (the shortest allowed), doubling, at most
    :data:`STUDY_ROWS` values and none longer than an eighth of the map's
    shorter side (beyond it the map holds too few wavelengths for summits).

    Examples
    --------
    >>> [round(lc * 1e6, 3) for lc in default_cutoffs((1e-6, 2e-6), (100, 40))]
    [2.0, 4.0, 8.0]
    """
    shortest = 2.0 * min(pixel_size)
    longest = min(n * size for n, size in zip(grid, pixel_size)) / 8.0
    return [shortest * 2.0**k for k in range(STUDY_ROWS) if shortest * 2.0**k <= longest]


def cutoff_study(surface: MeasuredSurface, cutoffs=None) -> list:
    """Summits and ``1 / mean(kappa)`` of a map against the low-pass cut-off.

    The conditioned map of ``surface`` (levelled, outliers as analysed,
    before any low-pass) is low-passed at each cut-off and its summits
    found again: how many there are, and their Greenwood–Williamson radius,
    depend on the shortest wavelength kept, and a study shows where they
    settle or keep changing (:ref:`guide-measured-surfaces-cutoff`).

    Parameters
    ----------
    surface : MeasuredSurface
    cutoffs : sequence of float, optional
        Cut-off wavelengths [m], each at least ``2 min(dx, dy)``; default
        :func:`~polind.topography.analysis.default_cutoffs`.

    Returns
    -------
    list of dict
        One row per cut-off, the unfiltered map first (``short_cutoff``
        None): ``short_cutoff`` [m], ``summits`` and ``summit_radius_mean``
        [m] (``None`` without a summit).
    """
    levelled = surface.levelled_map or surface.height_map
    if cutoffs is None:
        cutoffs = default_cutoffs(levelled.pixel_size, levelled.grid)
    rows = []
    for cutoff in [None, *cutoffs]:
        heights = levelled.heights
        if cutoff is not None:
            cutoff = check_cutoff(cutoff, levelled.pixel_size, levelled.source)
            heights = low_pass(heights, levelled.pixel_size, cutoff)
        i, j = find_summits(heights)
        kappa = summit_curvatures(heights, levelled.pixel_size, i, j)
        rows.append({"short_cutoff": cutoff, "summits": int(i.size),
                     "summit_radius_mean": float(1.0 / np.mean(kappa)) if i.size else None})
    return rows


def load_measured_surface(path, pixel_size=None, short_cutoff=None, *, remove_outliers=False,
                          levelling="plane", channel=None) -> MeasuredSurface:
    """:func:`~polind.topography.heightmap.read_height_map` then :func:`analyse`.

    Parameters
    ----------
    path : str or os.PathLike
        A height map SurfaceTopography reads, or a ``.npy`` / ``.csv`` grid.
    pixel_size : pair of float, optional
        ``(dx, dy)`` [m], for a ``.npy`` / ``.csv`` grid.
    short_cutoff : float, optional
        Low-pass cut-off wavelength [m].
    remove_outliers : bool, optional
        Mark the outliers missing.
    levelling : {"plane", "lines"}, optional
        How to level the map.
    channel : str, optional
        The channel of a file with several.

    Returns
    -------
    MeasuredSurface
    """
    # Checked before a long read: the options alone, and the cut-off against a given pixel size.
    if short_cutoff is not None:
        check_number("topography", "short_cutoff", short_cutoff, "positive")
        if pixel_size is not None:
            check_cutoff(short_cutoff, check_pixel_size(pixel_size), os.fspath(path))
    check_levelling(levelling)
    if not isinstance(remove_outliers, (bool, np.bool_)):
        raise InputError(f"The 'remove_outliers' parameter of topography must be true or false. "
                         f"Got {remove_outliers!r} instead.")
    return analyse(read_height_map(path, pixel_size, channel), short_cutoff,
                   remove_outliers=remove_outliers, levelling=levelling)
