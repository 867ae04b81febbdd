"""Measured surfaces: height maps, summits and summit radii (:ref:`guide-measured-surfaces`).

A profilometer, interferometer or AFM height map becomes the set of asperity
summits that the Pol-Ind model's direct summation sums over, each with its
own height and radius, and the Greenwood–Williamson surface equivalent to it::

    from polind.topography import load_measured_surface
    surface = load_measured_surface("scan.x3p")            # SurfaceTopography reads it
    surface.summit_heights, surface.summit_radii           # [m], [m]
    surface.greenwood_williamson()                         # {asperity_density, ...}
    surface.summary()                                      # polind topography --json

- :mod:`~polind.topography.heightmap`: reading (SurfaceTopography's
  formats with units converted to metres, the height channel named and
  choosable; ``.npy`` / ``.csv`` grids with a pixel size); missing points
  stay missing;
- :mod:`~polind.topography.summits`: levelling (plane, or line by line for
  scanning-probe maps), the ISO 16610-61 Gaussian low-pass, summits (strict
  8-neighbour maxima), curvatures;
- :mod:`~polind.topography.outliers`: outliers (spikes) by a robust rule;
- :mod:`~polind.topography.roughness`: Sa, Sq, Ssk, Sku, Sdq, the rms
  curvature and the power spectral density (SurfaceTopography's where it
  has them);
- :mod:`~polind.topography.analysis`: :class:`MeasuredSurface`, the result,
  and the cut-off study.

The package reads and analyses maps and depends on nothing in
:mod:`polind.contact`: the contact mechanics builds its surfaces from a
:class:`MeasuredSurface` (:meth:`polind.contact.surface.DirectSurface.from_topography`),
and the figure of ``polind topography --plot``, which draws both, is
:mod:`polind.topography_figure`.

SurfaceTopography is imported only when needed.
"""

from polind.topography.analysis import (MeasuredSurface, analyse, cutoff_study,
                                        load_measured_surface)
from polind.topography.heightmap import HeightMap, read_height_map
from polind.topography.outliers import find_outliers
from polind.topography.roughness import power_spectrum, standard_roughness
from polind.topography.summits import (find_summits, level, level_lines, low_pass, mean_plane,
                                       summit_curvatures)

__all__ = [
    "HeightMap",
    "MeasuredSurface",
    "analyse",
    "cutoff_study",
    "find_outliers",
    "find_summits",
    "level",
    "level_lines",
    "load_measured_surface",
    "low_pass",
    "mean_plane",
    "power_spectrum",
    "read_height_map",
    "standard_roughness",
    "summit_curvatures",
]
