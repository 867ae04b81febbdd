"""Where the asperity physics of a loaded contact stands: the validity figures.

The user guide, :ref:`guide-pol-ind-validity`.

Hertz's law holds only until an asperity yields, and a metal summit of a few
micrometres radius yields at nanometres of interference.  Every loaded
contact (:class:`polind.contact.Contact`) reports, elastic or not:

- ``plasticity_index``: Greenwood and Williamson's
  ``psi = (E* / H) sqrt(sigma_a / R)`` (``None`` without a hardness); on a
  direct surface ``sigma_a`` is the standard deviation of its summit
  heights and ``R`` its reference radius (a measured map: those of its
  Greenwood–Williamson equivalent);
- ``plastic_contact_share`` and ``plastic_load_share``: the share of the
  asperities in contact that are beyond yield (``delta > w_c``) and the share
  of the load they carry (0 without a hardness);
- ``mean_real_pressure``: ``N / A_real`` [Pa];
- ``peak_asperity_pressure``: the Hertz peak pressure
  ``p0 = (2 E* / pi) sqrt(delta / R)`` of the highest element (statistical:
  its bin's interference; direct: the highest summit with its own radius),
  or, beyond yield with a hardness, its Kogut–Etsion mean pressure ``P / A``;
- ``unmatched_load``: the applied load the separation could not match [N],
  nonzero only where a direct sum's load jumps across it.

A contact without a hardness whose peak pressure exceeds
:data:`PEAK_PRESSURE_LIMIT` gets a warning (:func:`validity_warning`) that
names the figures and the way out.
"""

from __future__ import annotations

import math

from polind.contact.plasticity import plasticity_index
from polind.kernels.plastic import kogut_etsion

__all__ = ["PEAK_PRESSURE_LIMIT", "VALIDITY_KEYS", "peak_pressure", "validity_figures", "validity_warning"]

#: Peak asperity pressure [Pa] above which an elastic (Hertzian) contact warns.
PEAK_PRESSURE_LIMIT = 10e9

#: The keys of :func:`validity_figures`, in the order ``polind surface`` prints them.
VALIDITY_KEYS = ("plasticity_index", "plastic_contact_share", "plastic_load_share",
                 "mean_real_pressure", "peak_asperity_pressure", "unmatched_load")


def _roughness(surface) -> tuple[float, float]:
    """``(sigma_a, R)`` of the surface's Greenwood–Williamson description."""
    if surface.kind == "statistical":
        return surface.height_std, surface.asperity_radius
    return surface.height_statistics[1], surface.asperity_radius


def _highest_element(table) -> tuple[float, float]:
    """Interference [m] and radius [m] of the highest element in contact, or ``(0, R)``."""
    touching = [j for j in range(len(table)) if table.interference[j] > 0.0]
    if not touching:
        return 0.0, table.asperity_radius
    top = max(touching, key=lambda j: table.heights[j])
    if table.radii is not None:
        radius = float(table.radii[top])
    elif table.weights is not None:
        # The radius an elastic element's Hertz weight stands for: R (w_j / n_j)^2.
        radius = table.asperity_radius * float(table.weights[top] / table.asperities[top]) ** 2
    else:
        radius = table.asperity_radius
    return float(table.interference[top]), radius


def peak_pressure(table) -> float:
    """``peak_asperity_pressure`` [Pa] of an element table (the module notes)."""
    delta, radius = _highest_element(table)
    plasticity = table.plasticity
    if plasticity is not None:
        w = delta / (plasticity.critical_factor(table.E_star) * radius)
        if w > 1.0:
            load_ratio, area_ratio, _ = kogut_etsion(w, plasticity.yield_coefficient)
            # P / A = (P_c / A_c) (P / P_c) / (A / A_c), P_c / A_c = (2/3) K H.
            return 2.0 / 3.0 * plasticity.yield_coefficient * plasticity.hardness * load_ratio / area_ratio
    return 2.0 * table.E_star / math.pi * math.sqrt(delta / radius)


def validity_figures(contact) -> dict:
    """The validity figures of a loaded contact (the module notes), plain floats.

    Parameters
    ----------
    contact : polind.contact.Contact
        The loaded contact.

    Returns
    -------
    dict
        The keys of :data:`VALIDITY_KEYS`; ``plasticity_index`` is ``None``
        without a hardness.
    """
    surface = contact.surface
    d = contact.separation
    plasticity = surface.plasticity
    contacts = float(surface.contacts(d))
    if plasticity is None:
        index, contact_share, load_share = None, 0.0, 0.0
    else:
        sigma, radius = _roughness(surface)
        index = plasticity_index(surface.E_star, plasticity.hardness, sigma, radius)
        contact_share = float(surface.plastic_contacts(d)) / contacts if contacts > 0.0 else 0.0
        carried = float(surface.normal_load(d))
        load_share = float(surface.plastic_load(d)) / carried if carried > 0.0 else 0.0
    area = contact.real_area
    return {
        "plasticity_index": index,
        "plastic_contact_share": contact_share,
        "plastic_load_share": load_share,
        "mean_real_pressure": contact.normal_load / area if area > 0.0 else math.inf,
        "peak_asperity_pressure": peak_pressure(contact.elements),
        "unmatched_load": float(contact.unmatched_load),
    }


def validity_warning(contact, figures=None) -> str | None:
    """The warning of an elastic contact beyond the validity of Hertz, or ``None``.

    A contact without a hardness whose ``peak_asperity_pressure`` exceeds
    :data:`PEAK_PRESSURE_LIMIT` (10 GPa): metal asperities would have yielded
    long before.  A contact with a hardness never warns about elasticity.
    """
    if contact.surface.plasticity is not None:
        return None
    figures = validity_figures(contact) if figures is None else figures
    peak = figures["peak_asperity_pressure"]
    if not peak > PEAK_PRESSURE_LIMIT:
        return None
    return (f"The pol-ind contact at {contact.normal_load:.6g} N is beyond the validity of elastic "
            f"(Hertz) asperities: peak_asperity_pressure {peak / 1e9:.3g} GPa (above "
            f"{PEAK_PRESSURE_LIMIT / 1e9:g} GPa), mean_real_pressure "
            f"{figures['mean_real_pressure'] / 1e9:.3g} GPa over {contact.contacts:.4g} asperities "
            f"in contact; metal asperities yield at a few GPa. Give the rough body's "
            f"'materials.hardness' (or 'materials.yield_strength') to make the asperities "
            f"elastic-plastic (Kogut-Etsion).")
