"""Elastic-plastic asperities: Kogut–Etsion with Chang–Etsion–Bogy yield inception.

The user guide, :ref:`guide-pol-ind-plasticity`.

Hertz's law (:mod:`polind.contact.asperity`) holds until a summit yields.
With the hardness ``H`` [Pa] of the rough body (body 1) a summit of radius
``R`` yields at the critical interference ``w_c = (pi K H / (2 E*))^2 R``,
``K = 0.454 + 0.41 nu1`` (Chang, Etsion and Bogy 1987), where it carries
``P_c = (2/3) pi K H R w_c`` on the area ``A_c = pi R w_c``; beyond, the
finite-element fits of Kogut and Etsion (2002) give ``P / P_c`` and
``A / A_c`` as powers of ``w = delta / w_c`` on three more ranges
(:func:`polind.kernels.plastic.kogut_etsion`).

:class:`Plasticity` carries ``H`` and ``nu1``; the surfaces of
:mod:`polind.contact.surface` take one (``plasticity=``) and then sum the
elastic-plastic law instead of Hertz's.  The sums themselves are the
compiled ones of :mod:`polind.kernels.plastic`: this module gives them to
the surfaces (:func:`statistical_totals`, :func:`direct_totals`) and offers
the single-asperity law on arrays (:func:`elastic_plastic_load`,
:func:`elastic_plastic_area`).
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from polind.contact._checks import poisson_ratio, positive_number
from polind.kernels import plastic as _kernels

__all__ = [
    "Plasticity",
    "yield_coefficient",
    "elastic_plastic_load",
    "elastic_plastic_area",
    "plasticity_index",
    "statistical_totals",
    "direct_totals",
    "HARDNESS_PER_YIELD_STRENGTH",
    "ElasticPlasticSums",
    "plastic_kernel_arguments",
    "plastic_properties",
]

#: ``H = 2.8 Y``: the hardness of a body of yield strength ``Y`` (Tabor).
HARDNESS_PER_YIELD_STRENGTH = 2.8


def yield_coefficient(poisson: float) -> float:
    """``K = 0.454 + 0.41 nu1``: the maximum contact pressure at yield inception over ``H``.

    Parameters
    ----------
    poisson : float
        Poisson's ratio ``nu1`` of the rough body [-].

    Returns
    -------
    float
        ``K`` [-].

    Examples
    --------
    >>> round(yield_coefficient(0.3), 3)
    0.577
    """
    return 0.454 + 0.41 * poisson


@dataclass(frozen=True)
class Plasticity:
    """The hardness of the rough body, which makes its asperities elastic-plastic.

    Attributes
    ----------
    hardness : float
        ``H`` [Pa] of the rough body (body 1).
    poisson_ratio : float
        ``nu1`` [-] of the rough body (it sets ``K``).

    Examples
    --------
    >>> plasticity = Plasticity(2e9, 0.3)
    >>> E_star, R = 115.4e9, 10e-6
    >>> w_c = plasticity.critical_interference(R, E_star)
    >>> round(float(w_c) * 1e9, 3)                # nm: steel summits yield early
    2.467
    """

    hardness: float
    poisson_ratio: float

    def __post_init__(self):
        object.__setattr__(self, "hardness", positive_number(self.hardness, "materials.hardness"))
        object.__setattr__(self, "poisson_ratio",
                           poisson_ratio(self.poisson_ratio, "materials.poisson_ratio[0]"))

    @property
    def yield_coefficient(self) -> float:
        """``K = 0.454 + 0.41 nu1`` [-]."""
        return yield_coefficient(self.poisson_ratio)

    def critical_factor(self, E_star: float) -> float:
        """``c = (pi K H / (2 E*))^2`` [-]: a summit of radius ``R`` yields at ``w_c = c R``."""
        return (math.pi * self.yield_coefficient * self.hardness / (2.0 * E_star)) ** 2

    def plastic_scale(self, E_star: float) -> float:
        """``p = (2/3) pi K H c`` [Pa]: the load at yield is ``P_c = p R^2``."""
        return 2.0 / 3.0 * math.pi * self.yield_coefficient * self.hardness * self.critical_factor(E_star)

    def critical_interference(self, R, E_star: float):
        """``w_c = c R`` [m] of summits of radius ``R`` [m]."""
        return self.critical_factor(E_star) * np.asarray(R, dtype=float)


def _ratios(interference, R, E_star, plasticity):
    """``(P / P_c, A / A_c, w_c)`` of :func:`polind.kernels.plastic.kogut_etsion` on arrays."""
    delta, radius = np.broadcast_arrays(np.asarray(interference, dtype=float),
                                        np.asarray(R, dtype=float))
    w_c = plasticity.critical_interference(radius, E_star)
    w = np.ascontiguousarray((delta / w_c).ravel())
    load, area = np.empty_like(w), np.empty_like(w)
    _kernels.kogut_etsion_ratios(w, plasticity.yield_coefficient, load, area)
    return load.reshape(delta.shape), area.reshape(delta.shape), w_c


def elastic_plastic_load(interference, R, E_star: float, plasticity: Plasticity):
    """Normal load ``P`` [N] of one elastic-plastic asperity (Kogut–Etsion).

    Parameters
    ----------
    interference : float or array_like
        ``delta`` [m]; non-positive values give 0.
    R : float or array_like
        Summit radius [m] (broadcasts with ``interference``).
    E_star : float
        Effective modulus [Pa].
    plasticity : Plasticity
        The rough body's hardness and Poisson ratio.

    Returns
    -------
    numpy.ndarray
        ``P = P_c (P / P_c)(delta / w_c)``; Hertz's load within yield.
    """
    load, _, w_c = _ratios(interference, R, E_star, plasticity)
    return load * 2.0 / 3.0 * math.pi * plasticity.yield_coefficient * plasticity.hardness \
        * np.asarray(R, dtype=float) * w_c


def elastic_plastic_area(interference, R, E_star: float, plasticity: Plasticity):
    """Contact area ``A`` [m^2] of one elastic-plastic asperity (Kogut–Etsion).

    Same parameters as :func:`elastic_plastic_load`; ``A = A_c (A / A_c)``,
    ``A_c = pi R w_c``, Hertz's ``pi R delta`` within yield.  The contact
    radius of the element law is ``a = sqrt(A / pi)``.
    """
    _, area, w_c = _ratios(interference, R, E_star, plasticity)
    return area * math.pi * np.asarray(R, dtype=float) * w_c


def plasticity_index(E_star: float, hardness: float, height_std: float, radius: float) -> float:
    """Greenwood and Williamson's plasticity index ``psi = (E* / H) sqrt(sigma_a / R)`` [-].

    Below about 0.6 the contact is mostly elastic, above 1 mostly plastic.

    Examples
    --------
    >>> round(plasticity_index(115.4e9, 2e9, 0.5e-6, 50e-6), 2)
    5.77
    """
    return E_star / hardness * math.sqrt(height_std / radius)


def statistical_totals(surface, d) -> dict:
    """The elastic-plastic totals of a statistical surface at separations ``d`` [m] (vectorised).

    ``normal_load``, ``slope`` (dN/dd), ``real_area``, ``plastic_load`` and
    ``plastic_contacts`` (the asperities beyond yield, ``eta A0 F_0(s + omega)``):
    the elastic (Hertz) totals of the surface plus the excess integrals of
    :func:`polind.kernels.plastic.statistical_excess` (:ref:`guide-pol-ind-plasticity`).
    """
    plasticity = surface.plasticity
    sigma, R, E_star = surface.height_std, surface.asperity_radius, surface.E_star
    factor = plasticity.critical_factor(E_star)
    omega = factor * R / sigma
    count = surface.asperity_count
    separations = np.asarray(d, dtype=float)
    s = np.ascontiguousarray(separations.ravel() / sigma)
    out = np.empty((s.size, 4))
    _kernels.statistical_excess_many(s, omega, plasticity.yield_coefficient, out)
    out = out.reshape(separations.shape + (4,))
    critical_load = count * plasticity.plastic_scale(E_star) * R * R
    critical_area = count * math.pi * factor * R * R
    return {
        "normal_load": surface.hertz_load(separations) + critical_load * out[..., 0],
        "slope": surface.hertz_load_slope(separations) + critical_load / sigma * out[..., 1],
        "real_area": surface.hertz_area(separations) + critical_area * out[..., 2],
        "plastic_load": critical_load * out[..., 3],
        "plastic_contacts": count * 0.5 * special.erfc((s.reshape(separations.shape) + omega)
                                                       / math.sqrt(2.0)),
    }


def direct_totals(surface, d) -> dict:
    """The elastic-plastic totals of a direct surface at separations ``d`` [m] (vectorised).

    The keys of :func:`statistical_totals`: the surface's elastic sums plus the
    excess of its summits beyond yield, each with its own radius
    (:func:`polind.kernels.plastic.direct_excess`).
    """
    plasticity = surface.plasticity
    heights, counts, radii = surface.plastic_summits
    E_star = surface.E_star
    factor = plasticity.critical_factor(E_star)
    scale = plasticity.plastic_scale(E_star)
    separations = np.asarray(d, dtype=float)
    flat = np.ascontiguousarray(separations.ravel())
    out = np.empty((flat.size, 5))
    _kernels.direct_excess_many(heights, counts, radii, flat, factor, plasticity.yield_coefficient,
                                float(radii.min()), out)
    out = out.reshape(separations.shape + (5,))
    return {
        "normal_load": surface.hertz_load(separations) + scale * out[..., 0],
        "slope": surface.hertz_load_slope(separations) - scale / factor * out[..., 1],
        "real_area": surface.hertz_area(separations) + math.pi * factor * out[..., 2],
        "plastic_load": scale * out[..., 4],
        "plastic_contacts": out[..., 3],
    }


class ElasticPlasticSums:
    """The totals a surface offers, Hertzian or elastic-plastic (a base of the surfaces).

    A surface supplies its Hertz totals (``hertz_load``, ``hertz_load_slope``,
    ``hertz_area``, ``hertz_load_and_slope``) and ``plastic_totals(d)`` (the
    dict of :func:`statistical_totals` or :func:`direct_totals`); with
    :attr:`plasticity` ``None`` the totals below are the Hertz ones, computed
    by exactly the elastic code.
    """

    #: The rough body's :class:`Plasticity`, or ``None``: Hertzian asperities.
    plasticity = None

    def with_plasticity(self, plasticity):
        """The same summits with elastic-plastic asperities (``None``: Hertzian); shares the arrays."""
        surface = copy.copy(self)
        surface.plasticity = plasticity
        # Loads computed for the other law are not this surface's.
        surface.__dict__.pop("load_range", None)
        return surface

    @property
    def yields(self) -> bool:
        """Whether an asperity can pass yield at a separation the solver may return.

        ``False`` without a hardness, and for a statistical surface whose
        critical interference lies beyond where its excess integral ends at
        the lowest separation (``w_c > 13.9 sigma_a`` or so: ``H -> inf``),
        where every total is exactly the Hertzian one: such a model runs the
        Hertzian step (:ref:`guide-pol-ind-plasticity`).
        """
        if self.plasticity is None:
            return False
        if self.kind != "statistical":
            return True
        omega = self.plasticity.critical_factor(self.E_star) * self.asperity_radius / self.height_std
        return omega < _kernels.excess_end(self.separation_range[0] / self.height_std)

    def normal_load(self, d):
        """Total normal load ``N(d)`` [N] at separation ``d`` [m] (vectorised)."""
        if self.plasticity is None:
            return self.hertz_load(d)
        return self.plastic_totals(d)["normal_load"]

    def normal_load_slope(self, d):
        """``dN/dd`` [N/m] at separation ``d`` [m] (vectorised; the direct sum's, between jumps)."""
        if self.plasticity is None:
            return self.hertz_load_slope(d)
        return self.plastic_totals(d)["slope"]

    def real_area(self, d):
        """Real contact area ``A(d)`` [m^2] (vectorised)."""
        if self.plasticity is None:
            return self.hertz_area(d)
        return self.plastic_totals(d)["real_area"]

    def plastic_load(self, d):
        """Load [N] carried by the asperities beyond yield (0 for Hertzian asperities; vectorised)."""
        if self.plasticity is None:
            return np.zeros_like(np.asarray(d, dtype=float))
        return self.plastic_totals(d)["plastic_load"]

    def plastic_contacts(self, d):
        """Asperities beyond yield, ``delta > w_c`` (0 for Hertzian asperities; vectorised)."""
        if self.plasticity is None:
            return np.zeros_like(np.asarray(d, dtype=float))
        return self.plastic_totals(d)["plastic_contacts"]

    def load_and_slope(self, d: float) -> tuple[float, float]:
        """``(N(d), dN/dd)`` for one separation ``d`` [m] (one Python call)."""
        if self.plasticity is None:
            return self.hertz_load_and_slope(d)
        totals = self.plastic_totals(float(d))
        return float(totals["normal_load"]), float(totals["slope"])


def plastic_kernel_arguments(surface) -> tuple:
    """An elastic-plastic surface as the arguments of :mod:`polind.kernels.plastic_separation`.

    ``(vector, heights, weights, counts, radii)``: the surface vector of
    :data:`~polind.kernels.plastic_separation.SIZE` floats and, for a direct
    surface, its :attr:`~polind.contact.surface.DirectSurface.plastic_summits`
    with their Hertz weights (empty arrays for a statistical surface).  The
    scales are the surfaces' own, so the kernels' loads are those of
    :meth:`ElasticPlasticSums.load_and_slope` (to the bit for a direct surface;
    within the fast pair's 3e-12 for a statistical one).
    """
    from polind.kernels import plastic_separation as slots
    from polind.kernels.separation import DIRECT, STATISTICAL
    from polind.kernels.special import special_addresses

    plasticity = surface.plasticity
    E_star, R = surface.E_star, surface.asperity_radius
    vector = np.zeros(slots.SIZE)
    vector[slots.CRITICAL_FACTOR] = plasticity.critical_factor(E_star)
    vector[slots.PLASTIC_SCALE] = plasticity.plastic_scale(E_star)
    vector[slots.YIELD_COEFFICIENT] = plasticity.yield_coefficient
    vector[slots.ADDRESSES:slots.ADDRESSES + 2] = special_addresses()
    if surface.kind == "statistical":
        vector[slots.KIND] = STATISTICAL
        vector[slots.LOAD_SCALE] = surface._load_scale
        vector[slots.HEIGHT_STD] = surface.height_std
        vector[slots.EXCESS_SCALE] = surface.asperity_count * vector[slots.PLASTIC_SCALE] * R * R
        vector[slots.OMEGA] = vector[slots.CRITICAL_FACTOR] * R / surface.height_std
        return (vector, _NO_SUMMITS, _NO_SUMMITS, _NO_SUMMITS, _NO_SUMMITS)
    heights, counts, radii = surface.plastic_summits
    vector[slots.KIND] = DIRECT
    vector[slots.HERTZ] = surface._hertz_scale()
    vector[slots.SMALLEST_RADIUS] = float(radii.min())
    vector[slots.JUMP_WIDTH] = slots.JUMP_FRACTION * surface.height_statistics[1]
    return (vector, heights, surface.plastic_weights, counts, radii)


_NO_SUMMITS = np.empty(0)


def plastic_properties(plasticity, heights, weights, counts, radii, separation, R, E_star, G_star,
                       mu_s, out_k, out_W):
    """``k_j = n_j 8 G* a(delta_j)`` and ``W_j = n_j mu_s P(delta_j)`` into ``out_k``, ``out_W``.

    :func:`polind.kernels.plastic.plastic_element_properties` with the
    constants of ``plasticity``; ``radii`` ``None`` means ``R`` for every element.
    """
    if radii is None:
        radii = np.full(np.shape(heights), float(R))
    _kernels.plastic_element_properties(
        heights, np.ascontiguousarray(weights, dtype=float), np.ascontiguousarray(counts, dtype=float),
        np.ascontiguousarray(radii, dtype=float), float(separation), float(R), float(E_star),
        float(G_star), float(mu_s), plasticity.critical_factor(E_star),
        plasticity.plastic_scale(E_star), plasticity.yield_coefficient, out_k, out_W)
