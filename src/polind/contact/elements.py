"""The modified Maxwell-slip element table of a loaded surface (approach II).

Every summit in contact (direct summation) or every height bin of the
Gaussian tail (statistical summation) becomes one elastic-slip element ``j``
carrying ``n_j`` asperities at interference ``delta_j``:
``k_j = n_j 8 G* sqrt(R delta_j)`` and ``W_j = n_j mu_s P(delta_j)``, so that
``sum_j W_j = mu_s N`` (Amontons' law from the asperity mechanics).

Statistical binning (:func:`element_table` with a
:class:`~polind.contact.surface.StatisticalSurface`): in the normalised
variable ``u = sqrt((h - d) / sigma_a)`` an asperity's count, stiffness,
contact area and Hertz load are ``u^0, u^1, u^2, u^3`` times constants, and
the summit density is ``2 u phi(s + u^2)``, smooth in ``u`` (while
``(t - s)^(3/2)`` is not smooth in ``t`` at the contact edge).  The tail
above ``d`` is split into ``ceil(n/2)`` bins of equal probability; each bin
gets the two-point Gauss rule of that density on the bin (its nodes are the
two elements; count and node heights from the bin's first four moments,
which 24-point Gauss–Legendre rules in ``u`` give to rounding; the unbounded
top bin is integrated over 16 panels up to where the density has fallen by
``e^-75``).  A two-point Gauss rule is exact for ``u^0 .. u^3``, so the
table reproduces the asperity count, the total tangential stiffness, the
real area and the normal load of the surface at once (measured against the
closed forms: within 1e-12 relative, the accuracy of ``F_m``, for 2 to 256
elements and ``d/sigma_a`` in [-5, 10]),
and its presliding virgin curve ``sum_j min(k_j u, W_j)`` follows the
continuum one within 0.4 % of ``mu_s N`` at 64 elements.  With an odd
number of elements the lowest bin gets one node, at the interference whose
Hertz load times the bin's count is the bin's load (load and count stay
exact; the stiffness and area totals are then off by 8e-4 and 3e-4 at 63 or
65 elements, so prefer an even number).
Given the applied load, the counts are finally scaled by
``N_app / sum_j n_j P(delta_j)`` (a factor within 1e-10 of 1 after the
separation solve) so that ``sum_j W_j = mu_s N_app`` to rounding.  A direct
table keeps whole summits (``n_j`` = number of summits at that height); its
load is ``N(d)``, within the solver's 1e-10 of ``N_app``.  Summits with radii
of their own (a measured map) get ``k_j = n_j 8 G* sqrt(R_j delta_j)`` and
``W_j = n_j mu_s (4/3) E* sqrt(R_j) delta_j^(3/2)``, which are those of
``w_j = n_j sqrt(R_j / R)`` summits of the reference radius ``R``: the
table keeps these Hertz weights (the field ``weights`` of :class:`ElementTable`) and every
kernel sums with them.

The element heights ``h_j = d + delta_j`` are fixed, so a table built at one
separation can follow a time-varying separation ``d(t)``
(:func:`element_properties`; :ref:`guide-pol-ind-varying-load`): elements whose
summits leave contact carry nothing.  The Pol-Ind model
(:mod:`polind.models.pol_ind`) builds the table at the run's largest load
(the flat at its lowest, so every summit that ever touches has an element),
solves ``d(t)`` on the surface itself (:ref:`guide-pol-ind-separation`) and renormalises the
capacities so that ``sum_j W_j(t) = mu_s N(t)`` exactly.  The bins are
placed for the largest load: far below it few bins remain in contact and
the table's stiffness is coarser (with 64 bins built at 100 N: 0.03 % low at
50 N, 0.15 % at 5 N, 26 % at 1 N, where one bin is left).
:meth:`ElementTable.as_surface` gives the alternative of solving ``d(t)`` on
the table itself.

Elastic-plastic asperities (a surface with a hardness,
:ref:`guide-pol-ind-plasticity`): ``k_j = n_j 8 G* a(delta_j)`` with
``a = sqrt(A / pi)`` and ``W_j = n_j mu_s P(delta_j)`` of the Kogut–Etsion
law; statistical bins are edged at the law's range boundaries and their
two-point rules placed so that count, stiffness, area and load are all
exact; a direct table has one element per summit group of one height and
one radius, each with its own radius (the ``radii`` of :class:`ElementTable`).

See the user guide: :ref:`guide-pol-ind-elements`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import special

from polind.contact._checks import element_count, finite_number, positive_number
from polind.contact.plasticity import elastic_plastic_load, plastic_properties
from polind.kernels.elements import element_properties
from polind.kernels.plastic import RANGE_ENDS

__all__ = ["ElementTable", "element_table", "element_properties", "MAX_ELEMENTS"]


def _hertz_properties(heights, counts, d, R, E_star, G_star, mu_s, out_k, out_W):
    """:func:`element_properties` in NumPy: the same operations in the same order, to the bit.

    The kernel compiled for one table cost a cold process a quarter of a second
    that a run at the table's own load never needs again (the kernels call it
    only when the load changes); IEEE arithmetic and a correctly rounded square
    root give NumPy's results the kernel's bits (a test compares them).
    """
    sqrt_R = math.sqrt(R)
    stiffness_scale = 8.0 * G_star * sqrt_R
    capacity_scale = mu_s * (4.0 / 3.0) * E_star * sqrt_R
    delta = heights - d
    touching = delta > 0.0
    root = np.sqrt(np.where(touching, delta, 0.0))
    out_k[:] = np.where(touching, counts * stiffness_scale * root, 0.0)
    out_W[:] = np.where(touching, counts * capacity_scale * delta * root, 0.0)

#: Most height bins a statistical table may have.
MAX_ELEMENTS = 100_000

_NODES_PER_BIN = 24
_TOP_BIN_PANELS = 16
# The top bin is integrated until phi has fallen by e^-75 (about 3e-33).
_TOP_BIN_DECAY = 75.0
# Kogut–Etsion's area exponents of the second and third ranges (A/A_c = c w^g).
_AREA_EXPONENTS = (1.136, 1.146)
# ... and load exponents (P/P_c = c w^q), both in u = sqrt(w): twice these.
_LOAD_EXPONENTS = (2.0 * 1.425, 2.0 * 1.263)


@dataclass(frozen=True, eq=False)
class ElementTable:
    """Elastic-slip elements of a loaded surface (:ref:`guide-pol-ind-elements`).

    Attributes
    ----------
    heights : numpy.ndarray
        Element heights ``h_j = d + delta_j`` [m], ascending.
    asperities : numpy.ndarray
        Asperities per element ``n_j`` [-] (fractional for bins).
    interference : numpy.ndarray
        ``delta_j`` [m] at ``separation``.
    stiffness : numpy.ndarray
        ``k_j`` [N/m].
    breakaway_force : numpy.ndarray
        ``W_j`` [N].
    separation : float
        The separation the table was built at [m].
    static_coefficient : float
        ``mu_s`` [-].
    asperity_radius, E_star, G_star : float
        ``R`` [m] and the effective moduli [Pa], to re-evaluate the table.
    weights : numpy.ndarray or None
        Hertz weights ``w_j = n_j sqrt(R_j / R)`` of elements whose summits
        have radii ``R_j`` of their own; ``None`` when every radius is ``R``
        (then ``w_j = n_j``).  See :attr:`contact_weights`.
    plasticity : polind.contact.plasticity.Plasticity or None
        The rough body's hardness: elastic-plastic elements
        (:ref:`guide-pol-ind-plasticity`); ``None`` for Hertzian ones.
    radii : numpy.ndarray or None
        Elastic-plastic elements: each element's summit radius ``R_j`` [m]
        (``None`` for Hertzian elements, whose radii the weights carry).
    stiffness_share, capacity_share : numpy.ndarray or None
        Microslip sub-elements (:ref:`guide-pol-ind-microslip`): each row's
        share ``c_i`` of its element's stiffness and ``w_i`` of its capacity
        (``None`` for elastic-slip elements, one row each).
    parent : ElementTable or None
        Microslip sub-elements: the table of the elements they replace
        (:func:`polind.contact.microslip.microslip_table`); ``None`` otherwise.
    """

    heights: np.ndarray
    asperities: np.ndarray
    interference: np.ndarray
    stiffness: np.ndarray
    breakaway_force: np.ndarray
    separation: float
    static_coefficient: float
    asperity_radius: float
    E_star: float
    G_star: float
    weights: np.ndarray | None = None
    plasticity: object = None
    radii: np.ndarray | None = None
    stiffness_share: np.ndarray | None = None
    capacity_share: np.ndarray | None = None
    parent: "ElementTable | None" = None

    @property
    def microslip_elements(self) -> int:
        """Sub-elements per element (1 for elastic-slip elements, :ref:`guide-pol-ind-microslip`)."""
        return 1 if self.parent is None else len(self) // len(self.parent)

    @property
    def slip_displacement(self) -> np.ndarray:
        """Each element's Cattaneo–Mindlin slip displacement ``u*_j = 3 mu_s P_j / (16 G* a_j)`` [m].

        ``1.5 W_j / k_j`` of the elements (of ``parent`` for sub-elements):
        the displacement at which a sphere of that load and contact radius
        slips whole (:ref:`guide-pol-ind-microslip`).
        """
        elements = self if self.parent is None else self.parent
        return 1.5 * elements.breakaway_force / elements.stiffness

    @property
    def contact_weights(self) -> np.ndarray:
        """``w_j``: the counts the kernels scale ``k_j`` and ``W_j`` by (``n_j sqrt(R_j / R)``)."""
        return self.asperities if self.weights is None else self.weights

    def __len__(self) -> int:
        return int(self.heights.size)

    @property
    def weight(self) -> np.ndarray:
        """Each element's share of the load, ``alpha_j = W_j / sum W`` (sums to 1).

        See :ref:`guide-pol-ind-law`.
        """
        return self.breakaway_force / self.breakaway_force.sum()

    @property
    def normal_load(self) -> float:
        """Normal load the elements carry, ``sum_j n_j P(delta_j)`` [N]."""
        return float(self.breakaway_force.sum() / self.static_coefficient)

    def properties_at(self, separation: float) -> tuple[np.ndarray, np.ndarray]:
        """``(k_j, W_j)`` of the same elements at another separation [m].

        Microslip sub-elements get their shares of their element's numbers
        (each follows its element's load, :ref:`guide-pol-ind-microslip`).
        """
        if self.parent is not None:
            stiffness, capacity = self.parent.properties_at(separation)
            m = self.microslip_elements
            return (np.repeat(stiffness, m) * self.stiffness_share,
                    np.repeat(capacity, m) * self.capacity_share)
        out_k = np.empty_like(self.heights)
        out_W = np.empty_like(self.heights)
        if self.plasticity is not None:
            plastic_properties(self.plasticity, self.heights, self.contact_weights, self.asperities,
                               self.radii, float(separation), self.asperity_radius, self.E_star,
                               self.G_star, self.static_coefficient, out_k, out_W)
            return out_k, out_W
        _hertz_properties(
            self.heights,
            self.contact_weights,
            float(separation),
            self.asperity_radius,
            self.E_star,
            self.G_star,
            self.static_coefficient,
            out_k,
            out_W,
        )
        return out_k, out_W

    def virgin_force(self, displacement):
        """Presliding virgin curve ``sum_j min(k_j |u|, W_j) sgn(u)`` [N] (vectorised).

        Parameters
        ----------
        displacement : float or array_like
            Tangential displacement from rest [m].
        """
        u = np.asarray(displacement, dtype=float)
        magnitude = np.minimum(np.abs(u)[..., None] * self.stiffness, self.breakaway_force).sum(axis=-1)
        return np.sign(u) * magnitude

    def as_surface(self):
        """The table as a :class:`~polind.contact.surface.DirectSurface` with counts.

        Solving this surface for a time-varying load gives the separation at
        which the table itself carries ``N(t)`` exactly, so
        ``sum_j W_j(t) = mu_s N(t)`` at every sample without renormalising.
        (The Pol-Ind model solves the continuous surface instead,
        :ref:`guide-pol-ind-separation`, and renormalises.)  Microslip
        sub-elements give their elements' surface.
        """
        from polind.contact.surface import DirectSurface

        if self.parent is not None:
            return self.parent.as_surface()

        if self.plasticity is not None:
            return DirectSurface(self.heights, self.asperity_radius, self.E_star, self.G_star,
                                 counts=self.asperities, radii=self.radii,
                                 plasticity=self.plasticity)
        if self.weights is None:
            return DirectSurface(self.heights, self.asperity_radius, self.E_star, self.G_star,
                                 counts=self.asperities)
        # Each element's radius is the one its Hertz weight stands for: R (w_j / n_j)^2.
        radii = self.asperity_radius * (self.weights / self.asperities) ** 2
        return DirectSurface(self.heights, self.asperity_radius, self.E_star, self.G_star,
                             counts=self.asperities, radii=radii)

    def records(self) -> list[dict]:
        """One dict per element: ``stiffness``, ``breakaway_force``, ``asperities``, ``interference``."""
        return [
            {"stiffness": k, "breakaway_force": w, "asperities": n, "interference": delta}
            for k, w, n, delta in zip(
                self.stiffness.tolist(),
                self.breakaway_force.tolist(),
                self.asperities.tolist(),
                self.interference.tolist(),
            )
        ]


def _upper_quantiles(s: float, fractions: np.ndarray) -> np.ndarray:
    """``t`` with ``Q(t) = Q(s) * fractions`` (upper-tail quantiles), accurately on both tails."""
    tail = 0.5 * special.erfc(s / math.sqrt(2.0))
    upper = tail * fractions
    # Invert whichever of Q and 1 - Q is the small one, to keep its digits.
    lower = special.ndtr(s) + tail * (1.0 - fractions)
    with np.errstate(divide="ignore"):
        return np.where(upper <= 0.5, -special.ndtri(np.minimum(upper, 0.5)), special.ndtri(np.minimum(lower, 1.0)))


def _snapped_edges(edges_u: np.ndarray, kinks) -> np.ndarray:
    """The bin edges with one interior edge given up for each kink, the kinks in their place.

    Each kink (lowest first) replaces the interior edge nearest to it that no
    kink has replaced yet; the edges are then sorted, so the bins keep their
    number and every kink is an edge (as many kinks as there are interior
    edges, for a table of very few bins).
    """
    interior = list(edges_u[1:])
    placed = []
    for kink in kinks:
        if not interior:
            break
        nearest = int(np.argmin(np.abs(np.asarray(interior) - kink)))
        interior.pop(nearest)
        placed.append(kink)
    edges = np.sort(np.concatenate(([edges_u[0]], interior, placed)))
    # An edge on a kink to the bit would leave an empty bin: keep the edges as they were.
    return edges if np.all(np.diff(edges) > 0.0) else edges_u


def _matched_rules(probability, variance, load_moment, load_power, mean, low_weight, low_node,
                   high_node):
    """Two-point rules with the given count, mean and variance whose ``v^q`` moment is ``load_moment``.

    The two-point distributions of mean ``mu`` and variance ``var`` are
    ``v = mu - sqrt(var p_2 / p_1)`` with weight ``p_1`` and
    ``mu + sqrt(var p_1 / p_2)`` with ``p_2 = 1 - p_1``; for ``q > 2`` their
    ``v^q`` moment grows with ``p_1`` (without bound as ``p_1 -> 1``), so bisection on ``p_1`` (both nodes
    non-negative) matches it.  Bins with ``q = 3`` (or no spread) keep the
    Gauss rule given.  Returns ``(low_weight, low_node, high_node)``, nodes
    relative to the mean.
    """
    todo = (load_power != 3.0) & (variance > 0.0)
    if not np.any(todo):
        return low_weight, low_node, high_node
    mu, var, q = mean[todo], variance[todo], load_power[todo]
    target = load_moment[todo] / probability[todo]
    lo = var / (var + mu * mu) * (1.0 + 1e-12)
    hi = np.full_like(lo, 1.0 - 1e-12)

    def excess(p):
        below = np.maximum(mu - np.sqrt(var * (1.0 - p) / p), 0.0)
        return p * below ** q + (1.0 - p) * (mu + np.sqrt(var * p / (1.0 - p))) ** q - target

    for _ in range(200):
        middle = 0.5 * (lo + hi)
        too_high = excess(middle) > 0.0
        lo, hi = np.where(too_high, lo, middle), np.where(too_high, middle, hi)
    p = 0.5 * (lo + hi)
    low_weight, low_node, high_node = low_weight.copy(), low_node.copy(), high_node.copy()
    low_weight[todo] = probability[todo] * p
    low_node[todo] = -np.sqrt(var * (1.0 - p) / p)
    high_node[todo] = np.sqrt(var * p / (1.0 - p))
    return low_weight, low_node, high_node


def _gaussian_elements(s: float, n_elements: int, kinks=()) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature of the Gaussian tail above ``s`` with ``n_elements`` nodes.

    Returns the probability carried by each node (sums to ``F_0(s)``) and
    its ``u = sqrt(delta / sigma)``, ascending.  See the module notes.
    ``kinks``, the ``u`` of the three Kogut–Etsion range boundaries of
    elastic-plastic asperities, become bin edges where they fall on the
    tail, and a bin between the first and the third gets its two-point rule
    in ``v = u^g`` instead of ``u``, ``g`` the area exponent of its range
    (1.136, 1.146): then its count, stiffness (``a ∝ v``) and area (``∝ v^2``)
    are exact and its load (``∝ v^2.51``, ``v^2.20``) is nearly so.
    """
    n_bins = (n_elements + 1) // 2
    # Bin edges in t (equal probability), then in u = sqrt(t - s); edge 0
    # is the contact edge.
    edges_t = _upper_quantiles(s, 1.0 - np.arange(n_bins) / n_bins)
    edges_t[0] = s
    edges_u = np.sqrt(np.maximum(np.maximum.accumulate(edges_t) - s, 0.0))
    top_start_t = max(float(edges_t[-1]), 0.0)
    top_end_u = math.sqrt(math.sqrt(top_start_t**2 + 2.0 * _TOP_BIN_DECAY) - s)
    ranges = tuple(kinks)
    kinks = [kink for kink in kinks if kink < top_end_u]
    if kinks and n_bins > 1:
        edges_u = _snapped_edges(edges_u, kinks)
        top_start_t = max(s + float(edges_u[-1]) ** 2, 0.0)
        top_end_u = math.sqrt(math.sqrt(top_start_t**2 + 2.0 * _TOP_BIN_DECAY) - s)
    top_edges = np.linspace(edges_u[-1], max(top_end_u, edges_u[-1]), _TOP_BIN_PANELS + 1)
    lower = np.concatenate((edges_u[:-1], top_edges[:-1]))
    upper = np.concatenate((edges_u[1:], top_edges[1:]))
    nodes, weights = np.polynomial.legendre.leggauss(_NODES_PER_BIN)
    half = 0.5 * (upper - lower)
    u = (0.5 * (upper + lower))[:, None] + half[:, None] * nodes
    density = (half[:, None] * weights) * 2.0 * u * np.exp(-0.5 * (s + u * u) ** 2) / math.sqrt(2.0 * math.pi)
    # Panels beyond the last finite bin all belong to the top bin.
    bin_of_panel = np.minimum(np.arange(lower.size), n_bins - 1)

    def per_bin(values):
        return np.bincount(bin_of_panel, weights=values.sum(axis=1), minlength=n_bins)

    probability = per_bin(density)
    if ranges:
        # The rule's variable v = u^g per bin (1 within Hertz and fully plastic).
        first = edges_u[np.minimum(np.arange(n_bins), edges_u.size - 1)]
        power = np.where((first >= ranges[0]) & (first < ranges[1]), _AREA_EXPONENTS[0],
                         np.where((first >= ranges[1]) & (first < ranges[2]), _AREA_EXPONENTS[1], 1.0))
        exponent = power[bin_of_panel][:, None]
        u = u ** exponent
    mean = per_bin(density * u) / probability
    # Central moments: the bins are narrow, raw moments would cancel.
    offset = u - mean[bin_of_panel][:, None]
    variance = per_bin(density * offset**2)
    skew = per_bin(density * offset**3)
    # Two-point Gauss rule of each bin: the roots of x^2 - (m3/m2) x - m2/m0.
    spread = np.where(variance > 0.0, variance, 1.0)
    ratio = np.where(variance > 0.0, skew / spread, 0.0)
    root = np.sqrt(ratio * ratio + 4.0 * variance / probability)
    low_node, high_node = 0.5 * (ratio - root), 0.5 * (ratio + root)
    width = np.where(root > 0.0, root, 1.0)
    low_weight = np.where(root > 0.0, probability * high_node / width, 0.5 * probability)
    high_weight = probability - low_weight
    if ranges:
        # In the two middle ranges the load goes as v^q, not v^3: move the nodes
        # along the rules with the bin's count, mean and variance until the load
        # is matched too.
        load_power = np.where(power == _AREA_EXPONENTS[0], _LOAD_EXPONENTS[0] / power,
                              np.where(power == _AREA_EXPONENTS[1], _LOAD_EXPONENTS[1] / power, 3.0))
        load_moment = per_bin(density * u ** load_power[bin_of_panel][:, None])
        low_weight, low_node, high_node = _matched_rules(
            probability, variance / probability, load_moment, load_power, mean, low_weight,
            low_node, high_node)
        high_weight = probability - low_weight
    node_u = np.column_stack((mean + low_node, mean + high_node)).ravel()
    node_probability = np.column_stack((low_weight, high_weight)).ravel()
    if ranges:
        node_u = node_u ** np.repeat(1.0 / power, 2)
    if n_elements % 2:
        # Odd count: the lowest bin gets one node, at the interference whose
        # Hertz load times the bin's count is the bin's load.
        first_load = per_bin(density * u**3)[0]
        node_u = np.concatenate(([(first_load / probability[0]) ** (1.0 / 3.0)], node_u[2:]))
        node_probability = np.concatenate(([probability[0]], node_probability[2:]))
    return node_probability, node_u


def element_table(surface, separation, static_coefficient, n_elements=64, normal_load=None):
    """Build the modified Maxwell-slip elements of a surface at separation ``d``.

    Parameters
    ----------
    surface : StatisticalSurface or DirectSurface
        The rough surface.
    separation : float
        Separation ``d`` [m], usually from
        :func:`~polind.contact.separation.solve_separation`.
    static_coefficient : float
        ``mu_s`` [-], positive.
    n_elements : int, optional
        Statistical surface: number of height bins (default 64).  Ignored
        for a direct surface, which gets one element per summit height in
        contact.
    normal_load : float, optional
        Applied load [N].  Statistical surface: the asperity counts are
        scaled so that the table carries exactly this load (Amontons' law
        exact).  Ignored for a direct surface.

    Returns
    -------
    ElementTable

    Examples
    --------
    >>> from polind.contact.surface import StatisticalSurface
    >>> from polind.contact.separation import solve_separation
    >>> surface = StatisticalSurface(1e10, 1e-4, 50e-6, 0.5e-6, 1.15e11, 2.4e10)
    >>> d = solve_separation(surface, 100.0)
    >>> table = element_table(surface, d, 0.15, 64, normal_load=100.0)
    >>> len(table), round(float(table.breakaway_force.sum()), 12)
    (64, 15.0)
    """
    d = finite_number(separation, "separation")
    mu_s = positive_number(static_coefficient, "static_coefficient")
    plasticity = surface.plasticity
    if plasticity is not None:
        return _plastic_table(surface, d, mu_s, n_elements, normal_load)
    if surface.kind == "statistical":
        n_nodes = element_count(n_elements, "discretisation.elements", MAX_ELEMENTS)
        sigma = surface.height_std
        probability, node_u = _gaussian_elements(d / sigma, n_nodes)
        counts = surface.asperity_count * probability
        heights = d + sigma * node_u**2
        # Re-derived from the stored heights so that the table and
        # element_properties(heights, ..., d) agree to the last bit.
        interference = heights - d
        if normal_load is not None:
            load = positive_number(normal_load, "normal_load")
            hertz = (4.0 / 3.0) * surface.E_star * math.sqrt(surface.asperity_radius)
            counts = counts * (load / float(np.sum(counts * hertz * interference**1.5)))
    else:
        start = int(np.searchsorted(surface.heights, d, side="right"))
        heights = surface.heights[start:].copy()
        asperities = surface.counts[start:].copy()
        counts = surface.weights[start:].copy() if surface.has_radii else asperities
        interference = heights - d
    stiffness = np.empty_like(heights)
    breakaway_force = np.empty_like(heights)
    _hertz_properties(
        heights, counts, d, surface.asperity_radius, surface.E_star, surface.G_star, mu_s, stiffness, breakaway_force
    )
    if surface.kind == "statistical":
        asperities = counts
    return ElementTable(
        heights=heights,
        asperities=asperities,
        interference=interference,
        stiffness=stiffness,
        breakaway_force=breakaway_force,
        separation=d,
        static_coefficient=mu_s,
        asperity_radius=surface.asperity_radius,
        E_star=surface.E_star,
        G_star=surface.G_star,
        weights=None if counts is asperities else counts,
    )


def _plastic_table(surface, d, mu_s, n_elements, normal_load) -> ElementTable:
    """:func:`element_table` of a surface with elastic-plastic asperities (:ref:`guide-pol-ind-plasticity`).

    Statistical: the bins of the Hertzian table with the nearest edges moved
    onto the Kogut–Etsion range boundaries ``u = sqrt(k w_c / sigma_a)``,
    ``k = 1, 6, 110`` (each bin then holds one smooth law), the counts scaled
    to the applied load with the elastic-plastic ``P``.  Direct: one element
    per summit group of one height and radius
    (:attr:`~polind.contact.surface.DirectSurface.plastic_summits`).  Within
    yield every number is the Hertzian table's, to the bit.
    """
    plasticity = surface.plasticity
    R = surface.asperity_radius
    if surface.kind == "statistical":
        n_nodes = element_count(n_elements, "discretisation.elements", MAX_ELEMENTS)
        sigma = surface.height_std
        omega = plasticity.critical_factor(surface.E_star) * R / sigma
        kinks = [math.sqrt(end * omega) for end in RANGE_ENDS]
        probability, node_u = _gaussian_elements(d / sigma, n_nodes, kinks)
        counts = surface.asperity_count * probability
        heights = d + sigma * node_u**2
        interference = heights - d
        if normal_load is not None:
            load = positive_number(normal_load, "normal_load")
            hertz = (4.0 / 3.0) * surface.E_star * math.sqrt(R)
            carried = counts * hertz * interference**1.5
            beyond = interference / (plasticity.critical_factor(surface.E_star) * R) > 1.0
            carried[beyond] = counts[beyond] * elastic_plastic_load(interference[beyond], R, surface.E_star,
                                                                    plasticity)
            counts = counts * (load / float(np.sum(carried)))
        asperities = weights = counts
        radii = np.full(heights.shape, R)
    else:
        summit_heights, summit_counts, summit_radii = surface.plastic_summits
        start = int(np.searchsorted(summit_heights, d, side="right"))
        heights = summit_heights[start:].copy()
        asperities = summit_counts[start:].copy()
        weights = surface.plastic_weights[start:].copy() if surface.has_radii else asperities
        radii = summit_radii[start:].copy()
        interference = heights - d
    stiffness = np.empty_like(heights)
    breakaway_force = np.empty_like(heights)
    plastic_properties(plasticity, heights, weights, asperities, radii, d, R, surface.E_star,
                       surface.G_star, mu_s, stiffness, breakaway_force)
    return ElementTable(heights=heights, asperities=asperities, interference=interference,
                        stiffness=stiffness, breakaway_force=breakaway_force, separation=d,
                        static_coefficient=mu_s, asperity_radius=R, E_star=surface.E_star,
                        G_star=surface.G_star, weights=None if weights is asperities else weights,
                        plasticity=plasticity, radii=radii)
