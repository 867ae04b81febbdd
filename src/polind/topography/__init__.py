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
  formats with units converted to metres; ``.npy`` / ``.csv`` grids with a
  pixel size); missing points stay missing;
- :mod:`~polind.topography.summits`: levelling, the ISO 16610-61 Gaussian
  low-pass, summits (strict 8-neighbour maxima), curvatures;
- :mod:`~polind.topography.analysis`: :class:`MeasuredSurface`, the result.

The package reads and analyses maps and depends on nothing in
:mod:`polind.contact`: the contact mechanics builds its surfaces from a
:class:`MeasuredSurface` (:meth:`polind.contact.surface.DirectSurface.from_topography`),
and the figure of ``polind topography --plot``, which draws both, is
:mod:`polind.topography_figure`.

SurfaceTopography is imported only when needed.
"""

from polind.topography.analysis import MeasuredSurface, analyse, load_measured_surface
from polind.topography.heightmap import HeightMap, read_height_map
from polind.topography.summits import find_summits, level, low_pass, mean_plane, summit_curvatures

__all__ = [
    "HeightMap",
    "MeasuredSurface",
    "analyse",
    "find_summits",
    "level",
    "load_measured_surface",
    "low_pass",
    "mean_plane",
    "read_height_map",
    "summit_curvatures",
]
