"""The contact rows of ``polind bench``: Pol-Ind's separation solve and a measured surface.

:func:`run_separation` times the separation solve on a directly summed
surface of a million sampled asperities; :func:`run_topography` times a
height map from file to summits, and a Pol-Ind model built on it.  Both are
about Pol-Ind's contact mechanics (:ref:`guide-pol-ind-separation`), so
``polind bench`` runs them when a model with contact mechanics is benchmarked.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

import numpy as np

from polind.models import PolInd


# --- the separation solve -----------------------------------------------------------------

@dataclass
class SeparationRow:
    asperities: int
    build_seconds: float     # sampling and sorting the heights (once per surface)
    solve_seconds: float     # one cold separation solve at the default load
    evaluations: int
    relative_residual: float


def run_separation(asperities=1_000_000, normal_load=100.0, seed=0):
    """Time the iterative method (:ref:`guide-pol-ind-separation`) on a directly summed surface.

    The surface of the default Pol-Ind parameters with ``asperities`` seeded
    Gaussian summits; the solve is timed cold (first solve on the surface),
    best of three fresh surfaces.
    """
    from polind.contact import DirectSurface, effective_moduli, solve_separation

    surface_params = PolInd.example_parameters()["surface"]
    e_star, g_star = effective_moduli(210e9, 0.3, 210e9, 0.3)
    density = asperities / surface_params["nominal_area"]
    build = solve = np.inf
    for _ in range(3):
        start = time.perf_counter()
        surface = DirectSurface.from_seed(density, surface_params["nominal_area"],
                                          surface_params["height_std"],
                                          surface_params["asperity_radius"], e_star, g_star,
                                          seed=seed)
        middle = time.perf_counter()
        separation, evaluations = solve_separation(surface, normal_load, full_output=True)
        end = time.perf_counter()
        build = min(build, middle - start)
        solve = min(solve, end - middle)
    residual = abs(surface.normal_load(separation) - normal_load) / normal_load
    return SeparationRow(asperities, build, solve, int(evaluations), float(residual))


# --- a measured surface --------------------------------------------------------------------

@dataclass
class TopographyRow:
    size: int                # points along each side of the map
    summits: int
    analyse_seconds: float   # read (.npy), levelled, summits and curvatures
    model_seconds: float     # Pol-Ind on the map: surface built, separation, element table
    elements: int            # elements of that table (summits in contact)


#: Pixel size of the benchmark's height maps [m].
MAP_PIXEL = 0.5e-6


def random_height_map(size, missing=0.0, seed=0):
    """A tilted Gaussian random surface of ``size`` x ``size`` points [m].

    Gaussian autocorrelation of 8 pixels, rms 0.5 µm, tilt 1e-3 and -2e-3 at
    a pixel of :data:`MAP_PIXEL`; a fraction ``missing`` of the points
    blanked (NaN) at random.  NumPy alone, in single precision where it can.
    """
    rng = np.random.default_rng(seed)
    q = 2.0 * np.pi * np.fft.fftfreq(size)
    q_half = 2.0 * np.pi * np.fft.rfftfreq(size)
    filter_ = np.exp(-(q[:, None] ** 2 + q_half[None, :] ** 2) * 8.0).astype(np.float32)
    spectrum = np.fft.rfft2(rng.standard_normal((size, size), dtype=np.float32)) * filter_
    heights = np.fft.irfft2(spectrum, s=(size, size)).astype(np.float64)
    heights *= 0.5e-6 / heights.std()
    index = np.arange(size, dtype=np.float64) * MAP_PIXEL
    heights += 1e-3 * index[:, None] - 2e-3 * index[None, :]
    if missing > 0:
        heights[rng.random((size, size)) < missing] = np.nan
    return heights


def run_topography(size=4096, normal_load=1.0):
    """Time a ``size`` x ``size`` height map from file to summits, and a Pol-Ind model on it.

    The map (a NumPy Gaussian random surface, pixel 0.5 µm) is written as
    ``.npy`` to a temporary directory; the analysis (reading, levelling,
    summits, curvatures) is timed once, cold, as ``polind topography`` runs
    it; then a Pol-Ind model with ``[model.surface] topography`` on the same
    file is built at ``normal_load`` (the map read and analysed again, the
    direct surface sorted, the separation solved, the element table built).
    """
    import tempfile

    from polind.topography import load_measured_surface

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "map.npy")
        np.save(path, random_height_map(size))
        start = time.perf_counter()
        measured = load_measured_surface(path, pixel_size=(MAP_PIXEL, MAP_PIXEL))
        middle = time.perf_counter()
        params = PolInd.example_parameters()
        params.update(normal_load=normal_load, discretisation={},
                      surface={"topography": path, "pixel_size": [MAP_PIXEL, MAP_PIXEL]})
        elements = len(PolInd(**params).element_table())
        end = time.perf_counter()
    return TopographyRow(size, measured.summits, middle - start, end - middle, elements)
