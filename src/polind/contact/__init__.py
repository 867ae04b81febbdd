"""Contact mechanics of the Pol-Ind model (the user guide, :ref:`guide-pol-ind`).

Greenwood–Williamson surfaces (statistical and direct summation), the
single-asperity laws of Hertz, Cattaneo–Mindlin and Masing (Mindlin's law also
as microslip sub-elements), the elastic-plastic law of Kogut and Etsion, the
validity figures, the separation solver (the paper's iterative method) and the
modified Maxwell-slip element table built from them.
"""

from polind.contact.asperity import (
    contact_radius,
    hertz_load,
    masing_force,
    mindlin_force,
    mindlin_slip_displacement,
    slip_capacity,
    tangential_stiffness,
)
from polind.contact.builder import PLASTIC_KEYS, Contact, build_contact, build_surface, plasticity_of
from polind.contact.elements import ElementTable, element_properties, element_table
from polind.contact.greenwood import VALID_RANGE, gw_integral
from polind.contact.materials import effective_moduli, shear_modulus
from polind.contact.microslip import mindlin_loop_energy, microslip_table
from polind.contact.plasticity import (Plasticity, elastic_plastic_area, elastic_plastic_load,
                                       plasticity_index, yield_coefficient)
from polind.contact.separation import solve_separation, solve_separation_series
from polind.contact.surface import DirectSurface, StatisticalSurface, read_summit_heights

__all__ = [
    "Contact",
    "DirectSurface",
    "ElementTable",
    "PLASTIC_KEYS",
    "Plasticity",
    "StatisticalSurface",
    "VALID_RANGE",
    "build_contact",
    "build_surface",
    "contact_radius",
    "effective_moduli",
    "elastic_plastic_area",
    "elastic_plastic_load",
    "element_properties",
    "element_table",
    "gw_integral",
    "hertz_load",
    "masing_force",
    "microslip_table",
    "mindlin_force",
    "mindlin_loop_energy",
    "mindlin_slip_displacement",
    "plasticity_index",
    "plasticity_of",
    "read_summit_heights",
    "shear_modulus",
    "slip_capacity",
    "solve_separation",
    "solve_separation_series",
    "tangential_stiffness",
    "yield_coefficient",
]
