"""The contact tables of the Pol-Ind model and the cache of the surfaces built from them.

The ``[model.surface]``, ``[model.materials]`` and ``[model.discretisation]``
tables of a ``pol-ind`` model file declared as data (the file-format tables
of the documentation are generated from them; :ref:`formats-model-files`), and
:func:`surface_of`, the surface of a parameter set from the cache of recently
built ones, and :func:`plastic_arrays`, the elastic-plastic kernel arrays of a
contact.  Part of :mod:`polind.models.pol_ind`, which owns the model.
"""

from __future__ import annotations

import json
import os
import threading
from collections import OrderedDict

import numpy as np

from polind.models.params import Param, Table

__all__ = ["SURFACE_TABLE", "MATERIALS_TABLE", "DISCRETISATION_TABLE", "SAMPLED_SURFACE_KEYS",
           "MAPPED_SURFACE_KEYS", "MAP_KEYS", "plastic_arrays", "surface_of"]

# The keys a file of measured summit heights replaces: required without one,
# refused with one (PolInd._check).
SAMPLED_SURFACE_KEYS = ("asperity_density", "nominal_area", "height_std")
# The keys a measured height map replaces (it gives every summit's height and radius).
MAPPED_SURFACE_KEYS = ("asperity_density", "asperity_radius", "height_std")
# The keys that only go with a height map.
MAP_KEYS = ("pixel_size", "short_cutoff", "remove_outliers", "levelling", "channel")
SURFACE_TABLE = Table("surface", (
    Param("asperity_density", unit="1/m^2", default=None,
          description=(r"Summit density :math:`\eta`, summits per unit nominal area. Required "
                       r"unless the summits come from a file."), symbol=r"\eta"),
    Param("nominal_area", unit="m^2", default=None,
          description=("Nominal (apparent) contact area :math:`A_0`. Required unless the "
                       "summits come from a file; with a measured ``topography``, optional "
                       "(default: the map's own area)."), symbol="A_0"),
    Param("asperity_radius", unit="m", default=None,
          description=("Summit radius :math:`R`, the same for every summit of a Gaussian "
                       "surface."), symbol="R"),
    Param("height_std", unit="m", default=None,
          description=(r"Standard deviation :math:`\sigma_a` of the summit heights. Required "
                       r"unless the summits come from a file."), symbol=r"\sigma_a"),
    Param("topography", kind="path", default=None,
          description=("A measured height map (any format SurfaceTopography reads, or a "
                       "``.npy`` / ``.csv`` grid), relative to the model file: the summits, "
                       "their heights and radii come from it "
                       "(:ref:`guide-measured-surfaces`).")),
    Param("pixel_size", kind="pair", unit="m", default=None, fittable=False,
          description=(r"Grid spacings :math:`[\Delta x, \Delta y]` of a ``.npy`` or ``.csv`` "
                       r"height map (other formats carry their own).")),
    Param("short_cutoff", unit="m", default=None, fittable=False,
          description=("Optional Gaussian low-pass (ISO 16610-61) of the height map before "
                       "the summits are found: the wavelength passed at 50 %; at least twice "
                       "the smaller pixel spacing.")),
    Param("remove_outliers", kind="bool", default=None, fittable=False,
          description=("Mark the map's outliers (spikes) missing; default ``false``: counted "
                       "and warned about (:ref:`guide-measured-surfaces-conditioning`).")),
    Param("levelling", kind="str", default=None, choices=("plane", "lines"), fittable=False,
          description=('The map\'s levelling: ``"plane"`` (default) or ``"lines"``, line by '
                       'line for AFM/STM maps (:ref:`guide-measured-surfaces-conditioning`).')),
    Param("channel", kind="str", default=None, fittable=False,
          description="The height channel of a map file with several, by name."),
    Param("ball_radius", unit="m", default=None, fittable=False,
          description=("Ball on flat: the ball's radius; the nominal area is its Hertz contact "
                       "at the normal load, and follows a varying load "
                       "(:ref:`guide-measured-surfaces-ball`)."),
          symbol="R_b"),
    Param("bulk_compliance", kind="bool", default=None, fittable=False,
          description=("Ball on flat only: the smooth ball's Mindlin compliance "
                       ":math:`1 / (8 G^* a)`, :math:`a` its Hertz contact radius at the "
                       "normal load, in series with the asperities (with a "
                       "``[model.compliance]`` too); default ``true``, ``false`` leaves it out "
                       "(:ref:`guide-pol-ind-bulk`).")),
), description="The rough surface (:ref:`guide-pol-ind-surface`).")
MATERIALS_TABLE = Table("materials", (
    Param("youngs_modulus", kind="pair", unit="Pa",
          description="Young's moduli :math:`[E_1, E_2]` of the two bodies."),
    Param("poisson_ratio", kind="pair", bound="poisson",
          description=r"Poisson's ratios :math:`[\nu_1, \nu_2]` of the two bodies."),
    Param("hardness", unit="Pa", default=None,
          description=("Hardness :math:`H` of the rough body (body 1). Optional: with it the "
                       "asperities are elastic-plastic (Kogut–Etsion), without it Hertzian "
                       "(:ref:`guide-pol-ind-plasticity`)."), symbol="H"),
    Param("yield_strength", unit="Pa", default=None,
          description=("Yield strength :math:`Y` of the rough body, instead of ``hardness``: "
                       ":math:`H = 2.8\\,Y`. Giving both is an error."), symbol="Y"),
), description=("The two bodies' elastic constants and the rough body's hardness "
                "(:ref:`guide-pol-ind-surface`, :ref:`guide-pol-ind-plasticity`)."))
DISCRETISATION_TABLE = Table("discretisation", (
    # Default: "direct" with a surface.topography, else "statistical" (PolInd._check).
    Param("summation", kind="str", default=None, choices=("statistical", "direct"),
          description=('``"statistical"`` (height bins of the Gaussian) or ``"direct"`` (one '
                       'element per summit).')),
    Param("elements", kind="int", default=64,
          description="Statistical summation: the number of height bins (elements)."),
    Param("seed", kind="int", bound="nonnegative", default=0,
          description=("Direct summation: the seed of the random summit heights drawn from "
                       "the Gaussian.")),
    Param("heights_file", kind="path", default=None,
          description=("Direct summation: a CSV file of measured summit heights (column "
                       "``h``, m), relative to the model file; replaces "
                       "``asperity_density``, ``nominal_area`` and ``height_std``.")),
    Param("tangential", kind="str", default=None, choices=("elastic-slip", "mindlin"),
          fittable=False,
          description=('The asperities\' tangential law: ``"elastic-slip"`` (default; one '
                       'element each) or ``"mindlin"`` (Cattaneo–Mindlin microslip: '
                       '``microslip_elements`` sub-elements each, at a constant normal load; '
                       ':ref:`guide-pol-ind-microslip`).')),
    Param("microslip_elements", kind="int", default=None, fittable=False,
          description=('With ``tangential = "mindlin"``: sub-elements per element, an '
                       'integer from 2 to 1024 (default 32).')),
), default={},
          description="How the surface becomes elements (:ref:`guide-pol-ind-elements`).")


# Surfaces built from the same surface, materials and discretisation tables are
# the same (sampled summits are seeded; a heights file is keyed with its size and
# modification time): a fit that moves only friction keys builds one, not one per
# evaluation (a sampled direct surface takes 0.16 s).
_SURFACES: "OrderedDict[str, object]" = OrderedDict()
_SURFACES_KEPT = 8
_SURFACES_LOCK = threading.Lock()


def surface_of(params):
    """The surface of a parameter set, from the cache of recently built ones.

    The cache holds the Hertzian surfaces; a hardness (or yield strength) is
    applied to the cached one (:meth:`~polind.contact.plasticity.ElasticPlasticSums.with_plasticity`,
    which shares its summits), so a fit that moves the hardness builds no
    surface either.
    """
    from polind.contact import PLASTIC_KEYS, plasticity_of

    materials = params.get("materials") or {}
    hertzian = {key: value for key, value in materials.items() if key not in PLASTIC_KEYS}
    surface = _hertzian_surface_of({**params, "materials": hertzian})
    plasticity = plasticity_of(materials, materials["poisson_ratio"][0])
    return surface if plasticity is None else surface.with_plasticity(plasticity)


def _hertzian_surface_of(params):
    """The cached surface of a parameter set without a hardness."""
    from polind.contact import build_surface
    from polind.models.pol_ind import PolInd

    parts = {key: params.get(key) for key in ("surface", "materials", "discretisation")}
    if (params.get("surface") or {}).get("ball_radius") is not None:
        parts["normal_load"] = params["normal_load"]      # its nominal area follows the load
    for _, name, path in PolInd.files_in(params):
        if path:
            try:
                status = os.stat(path)
            except OSError:
                return build_surface(params)        # its own error message
            parts[f"{name}_status"] = [os.path.abspath(path), status.st_size, status.st_mtime_ns]
    key = json.dumps(parts, sort_keys=True, default=str)
    with _SURFACES_LOCK:       # sweeps build models on several threads
        surface = _SURFACES.get(key)
        if surface is not None:
            _SURFACES.move_to_end(key)
            return surface
    surface = build_surface(params)
    with _SURFACES_LOCK:
        _SURFACES[key] = surface
        while len(_SURFACES) > _SURFACES_KEPT:
            _SURFACES.popitem(last=False)
    return surface


def plastic_arrays(scalars, table, contact):
    """The kernel arrays of :mod:`polind.kernels.pol_ind_plastic` from the Hertzian step's.

    The surface vector of :mod:`polind.kernels.plastic_separation` after the
    scalars, the elements' asperity counts and radii after the table's rows.
    """
    from polind.contact.plasticity import plastic_kernel_arguments
    from polind.kernels import pol_ind_plastic as slots

    vector = plastic_kernel_arguments(contact.surface)[0]
    elements = contact.elements
    plastic_scalars = np.zeros(slots.N_PLASTIC_SCALARS)
    plastic_scalars[:scalars.shape[0]] = scalars
    plastic_scalars[slots.PLASTIC_SURFACE:] = vector
    plastic_table = np.zeros((slots.N_PLASTIC_ROWS, table.shape[1]))
    plastic_table[:table.shape[0]] = table
    plastic_table[slots.ELEMENT_ASPERITIES] = elements.asperities
    plastic_table[slots.ELEMENT_RADIUS] = elements.radii
    return plastic_scalars, plastic_table
