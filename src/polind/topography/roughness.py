"""Standard roughness figures of a height map (ISO 25178-2), by SurfaceTopography where it has them.

:func:`standard_roughness` gives what a profilometer's software reports
(:ref:`guide-measured-surfaces-roughness`), over the valid points of a
levelled map ``h`` with mean ``hbar``:

- ``Sq``: the rms height, SurfaceTopography's ``Sq``;
- ``Sa = mean |h - hbar|``, ``Ssk = mean (h - hbar)^3 / Sq^3`` and
  ``Sku = mean (h - hbar)^4 / Sq^4``: the ISO 25178-2 definitions, computed
  here from the same points (SurfaceTopography computes no Sa, Ssk or Sku);
- ``Sdq``: the rms gradient ``<h_x^2 + h_y^2>^(1/2)``,
  SurfaceTopography's ``rms_gradient`` (two-point differences
  ``(h[i+1, j] - h[i, j]) / dx``; next to a missing point SurfaceTopography
  leaves out the differences its linear interpolation cannot evaluate, a
  few more than the ones that reach the point);
- ``rms_curvature``: the rms of the mean curvature ``(h_xx + h_yy) / 2``,
  SurfaceTopography's ``rms_curvature_from_area`` (three-point differences).

:func:`power_spectrum` is SurfaceTopography's radially averaged areal power
spectral density (``power_spectrum_from_area``, Hann window); a map with
missing points is first filled by SurfaceTopography's harmonic
interpolation, since a Fourier transform needs every point.
"""

from __future__ import annotations

import numpy as np

from polind.topography.heightmap import HeightMap, surface_topography

__all__ = ["ROUGHNESS_KEYS", "power_spectrum", "standard_roughness"]

#: The keys of :func:`standard_roughness`, in this order.
ROUGHNESS_KEYS = ("Sa", "Sq", "Ssk", "Sku", "Sdq", "rms_curvature")


def standard_roughness(height_map: HeightMap) -> dict:
    """``{Sa, Sq, Ssk, Sku, Sdq, rms_curvature}`` of a (levelled) height map.

    Parameters
    ----------
    height_map : HeightMap
        Heights [m], ``NaN`` where missing; normally levelled (the figures
        are of the map as given, about its mean).

    Returns
    -------
    dict
        ``Sa`` and ``Sq`` [m], ``Ssk`` and ``Sku`` [-], ``Sdq`` [-]
        (m/m), ``rms_curvature`` [1/m]; plain floats.

    Examples
    --------
    >>> x = np.arange(400) * 1e-7                              # 10 periods of 4 um
    >>> h = 2e-8 * np.sin(2 * np.pi * x / 4e-6)[:, None] * np.ones(30)
    >>> r = standard_roughness(HeightMap.from_array(h, (1e-7, 1e-7)))
    >>> round(r["Sq"] / (2e-8 / 2**0.5), 6), round(r["Sa"] / (2 * 2e-8 / np.pi), 2)
    (1.0, 1.0)
    >>> abs(r["Ssk"]) < 1e-9, round(r["Sku"], 6)               # a sine: 0 and 3/2
    (True, 1.5)
    """
    topography = surface_topography(height_map)
    valid = height_map.heights[~np.isnan(height_map.heights)]
    deviation = valid - valid.mean()
    sq = float(topography.Sq())
    # The moments of the deviation in units of Sq: no power of a height is formed, so
    # heights near the largest double give the same figures (sq**4 would overflow).
    scaled = deviation / sq if sq > 0.0 else np.zeros_like(deviation)
    return {
        "Sa": float(np.mean(np.abs(deviation))),
        "Sq": sq,
        "Ssk": float(np.mean(scaled**3)),
        "Sku": float(np.mean(scaled**4)),
        "Sdq": float(topography.rms_gradient()),
        "rms_curvature": float(topography.rms_curvature_from_area()),
    }


def power_spectrum(height_map: HeightMap) -> tuple[np.ndarray, np.ndarray, bool]:
    """The radially averaged areal power spectral density of a height map.

    Parameters
    ----------
    height_map : HeightMap
        Heights [m], ``NaN`` where missing.

    Returns
    -------
    q : numpy.ndarray
        Wavevectors ``|q|`` [1/m] (``2 pi / wavelength``), log-spaced bins.
    C : numpy.ndarray
        ``C_iso(q)`` [m^4], SurfaceTopography's ``power_spectrum_from_area``
        (Hann window); empty bins left out.
    filled : bool
        Whether missing points were filled (harmonic interpolation) first.
    """
    topography = surface_topography(height_map)
    filled = bool(topography.has_undefined_data)
    if filled:
        topography = topography.interpolate_undefined_data("harmonic")
    q, C = topography.power_spectrum_from_area()
    keep = ~(np.ma.getmaskarray(q) | np.ma.getmaskarray(C))
    q = np.ma.filled(q, np.nan)[keep]
    C = np.ma.filled(C, np.nan)[keep]
    keep = np.isfinite(q) & np.isfinite(C) & (q > 0.0) & (C > 0.0)
    return q[keep], C[keep], filled
