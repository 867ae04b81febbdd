"""A measured surface reduced to its summits, and its Greenwood–Williamson equivalent.

:func:`analyse` runs the steps of :mod:`polind.topography.summits` on a
:class:`~polind.topography.heightmap.HeightMap` (levelling, the optional
low-pass, summits, curvatures) and returns a :class:`MeasuredSurface`: the
summit heights and radii that direct summation sums over
(:ref:`guide-measured-surfaces`), and the statistics of the map:

- summit density ``eta = summits / (valid_points dx dy)``;
- the equivalent Greenwood–Williamson surface: this ``eta``,
  ``R = 1 / mean(kappa)`` and ``sigma_a`` = the standard deviation of the
  summit heights;
- the map's nominal (projected) area ``A_map = valid_points dx dy``, so that
  ``eta A_map`` is the number of summits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.validation import check_number
from polind.topography.heightmap import HeightMap, read_height_map
from polind.topography.summits import find_summits, level, low_pass, summit_curvatures

__all__ = ["MeasuredSurface", "analyse", "load_measured_surface"]

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
    """

    height_map: HeightMap
    summit_index: tuple[np.ndarray, np.ndarray]
    summit_heights: np.ndarray
    summit_curvatures: np.ndarray
    short_cutoff: float | None = None

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

    def greenwood_williamson(self) -> dict:
        """The statistical surface equivalent to the map, as ``[model.surface]`` keys.

        ``{asperity_density: eta, asperity_radius: 1 / mean(kappa),
        height_std: std(summit heights)}``, SI units.
        """
        return {"asperity_density": self.summit_density,
                "asperity_radius": self.summit_radius_mean,
                "height_std": self.summit_height_std}

    def summary(self) -> dict:
        """The keys of ``polind topography --json`` (plain floats and ints).

        ``grid``, ``pixel_size``, ``valid_points``, ``rms_height``,
        ``summits``, ``summit_density``, ``summit_radius_mean``,
        ``summit_radius_median``, ``summit_height_std``,
        ``greenwood_williamson``; also ``nominal_area`` (m^2),
        ``summit_height_mean`` (m, above the mean plane) and
        ``short_cutoff`` (m, or None).  Every number is finite: a map whose
        statistics pass double precision is an InputError naming the key.
        """
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
        }
        for key, value in [*summary.items(), *summary["greenwood_williamson"].items()]:
            if isinstance(value, float) and not np.isfinite(value):
                raise InputError(f"{self.source}: its {key} is {value} (beyond double "
                                 f"precision); expected heights and pixel sizes of a physical "
                                 f"size.")
        return summary


def analyse(height_map: HeightMap, short_cutoff=None) -> MeasuredSurface:
    """Level a height map, optionally low-pass it, and find its summits and radii.

    Parameters
    ----------
    height_map : HeightMap
        Heights [m] on a regular grid, ``NaN`` where missing.
    short_cutoff : float, optional
        Cut-off wavelength [m] of the ISO 16610-61 Gaussian low-pass applied
        after levelling (:func:`~polind.topography.summits.low_pass`).

    Returns
    -------
    MeasuredSurface

    Raises
    ------
    polind.InputError
        If the mean plane is not determined or the map has no summit; the
        message names the map's source.

    Examples
    --------
    >>> x = (np.arange(9) - 4) * 1e-6
    >>> cap = np.maximum(0.0, 1e-7 - (x[:, None] ** 2 + x[None, :] ** 2) / (2 * 20e-6))
    >>> surface = analyse(HeightMap.from_array(cap, (1e-6, 1e-6)))
    >>> surface.summits, round(surface.summit_radius_mean / 20e-6, 12)
    (1, 1.0)
    """
    dx, dy = height_map.pixel_size
    heights = level(height_map.heights, (dx, dy), height_map.source)
    if short_cutoff is not None:
        cutoff = check_number("topography", "short_cutoff", short_cutoff, "positive")
        nx, ny = height_map.grid
        extent = max(nx * dx, ny * dy)
        if cutoff > extent:
            raise InputError(f"{height_map.source}: the short_cutoff {cutoff!r} m is longer than "
                             f"the map ({extent:.6g} m across), which it would flatten; "
                             f"expected a cut-off shorter than the map.")
        heights = low_pass(heights, (dx, dy), cutoff)
        short_cutoff = cutoff
    # Levelling leaves round-off of the size of the heights it subtracted the plane from
    # (a tilted plane is flat to within it): a summit must stand out of it.
    largest = float(np.nanmax(np.abs(height_map.heights)))
    i, j = find_summits(heights, tolerance=_ROUND_OFF * largest)
    if i.size == 0:
        raise InputError(f"{height_map.source}: the map has no summit (no interior point with "
                         f"8 valid neighbours stands above all of them by more than the "
                         f"round-off of levelling); expected a rough surface.")
    return MeasuredSurface(
        height_map=HeightMap(heights, (float(dx), float(dy)), height_map.source),
        summit_index=(i, j),
        summit_heights=heights[i, j],
        summit_curvatures=summit_curvatures(heights, (dx, dy), i, j),
        short_cutoff=short_cutoff,
    )


def load_measured_surface(path, pixel_size=None, short_cutoff=None) -> MeasuredSurface:
    """:func:`~polind.topography.heightmap.read_height_map` then :func:`analyse`.

    Parameters
    ----------
    path : str or os.PathLike
        A height map SurfaceTopography reads, or a ``.npy`` / ``.csv`` grid.
    pixel_size : pair of float, optional
        ``(dx, dy)`` [m], for a ``.npy`` / ``.csv`` grid.
    short_cutoff : float, optional
        Low-pass cut-off wavelength [m].

    Returns
    -------
    MeasuredSurface
    """
    if short_cutoff is not None:  # checked before a long read
        check_number("topography", "short_cutoff", short_cutoff, "positive")
    return analyse(read_height_map(path, pixel_size), short_cutoff)
