"""Rough surfaces pressed by a rigid flat: statistical and direct summation.

Two surfaces with one interface, both functions of the separation ``d`` [m]
between the flat and the mean summit height:

- :class:`StatisticalSurface`: the continuous Gaussian summit-height
  distribution of Greenwood and Williamson, totals in closed form through
  the integrals ``F_m`` of :mod:`polind.contact.greenwood`;
- :class:`DirectSurface`: a finite set of summit heights (approach I of the
  paper), every total a plain sum over the summits above ``d``, either
  drawn from the Gaussian with a seeded generator or read from a file of
  measured heights.

Each offers ``normal_load(d)``, its slope ``normal_load_slope(d)`` (= dN/dd,
negative), ``contacts(d)`` and ``real_area(d)``, vectorised over ``d``, and
the scalar ``load_and_slope(d)`` that the separation solver
(:mod:`polind.contact.separation`) iterates on.  With a
:class:`~polind.contact.plasticity.Plasticity` (``plasticity=``, or
:meth:`~polind.contact.plasticity.ElasticPlasticSums.with_plasticity`) the
asperities are elastic-plastic and these totals are those of
:mod:`polind.contact.plasticity` (:ref:`guide-pol-ind-plasticity`); the
``hertz_*`` methods are always the Hertzian ones.

See the user guide: :ref:`guide-pol-ind-surface` and
:ref:`guide-pol-ind-summation`.
"""

from __future__ import annotations

import csv
import math
import os
from functools import cached_property

import numpy as np
from numba import njit

from polind.contact._checks import positive_number
from polind.contact.greenwood import VALID_RANGE, gw_integral, half_integer_pair
from polind.errors import InputError, describe
from polind.contact.plasticity import ElasticPlasticSums, direct_totals, statistical_totals
from polind.contact.heights import read_summit_heights, sorted_heights, summit_groups
from polind.kernels.greenwood import tail_moments
from polind.resources import check_memory

__all__ = [
    "StatisticalSurface",
    "DirectSurface",
    "read_summit_heights",
    "BYTES_PER_ASPERITY",
    "MAX_SAMPLED_ASPERITIES",
]

#: Largest seeded sample :meth:`DirectSurface.from_seed` draws (memory: 8
#: bytes per summit, twice while sorting); beyond it use statistical summation.
MAX_SAMPLED_ASPERITIES = 50_000_000
#: What direct summation holds per summit at its peak [bytes]: heights, counts, weights,
#: their sorted tail sums and the separation solve (40 measured at 4e6 summits).
BYTES_PER_ASPERITY = 48


class StatisticalSurface(ElasticPlasticSums):
    """Gaussian summit heights summed statistically (Greenwood–Williamson).

    ``N(d) = (4/3) eta A0 E* sqrt(R) sigma^(3/2) F_{3/2}(d/sigma)``,
    ``dN/dd = -2 eta A0 E* sqrt(R) sigma^(1/2) F_{1/2}(d/sigma)``,
    ``n(d) = eta A0 F_0(d/sigma)``, ``A(d) = pi eta A0 R sigma F_1(d/sigma)``.

    Parameters
    ----------
    asperity_density : float
        Summits per unit nominal area ``eta`` [1/m^2].
    nominal_area : float
        Nominal contact area ``A0`` [m^2].
    asperity_radius : float
        Summit radius ``R`` [m].
    height_std : float
        Standard deviation of the summit heights ``sigma_a`` [m].
    E_star, G_star : float
        Effective normal and tangential moduli [Pa]
        (:func:`polind.contact.materials.effective_moduli`).
    plasticity : polind.contact.plasticity.Plasticity, optional
        The rough body's hardness: elastic-plastic asperities
        (:ref:`guide-pol-ind-plasticity`); default Hertzian.

    Notes
    -----
    The separation is only evaluated for ``d / sigma_a`` in
    :data:`polind.contact.greenwood.VALID_RANGE` = [-5, 10]; see
    :func:`polind.contact.separation.solve_separation`.

    Examples
    --------
    >>> surface = StatisticalSurface(1e10, 1e-4, 50e-6, 0.5e-6, 1.15e11, 2.4e10)
    >>> round(float(surface.contacts(0.0)))       # half the 1e6 summits
    500000
    """

    kind = "statistical"

    def __init__(self, asperity_density, nominal_area, asperity_radius, height_std, E_star, G_star,
                 plasticity=None):
        self.asperity_density = positive_number(asperity_density, "surface.asperity_density")
        self.nominal_area = positive_number(nominal_area, "surface.nominal_area")
        self.asperity_radius = positive_number(asperity_radius, "surface.asperity_radius")
        self.height_std = positive_number(height_std, "surface.height_std")
        self.E_star = positive_number(E_star, "E_star")
        self.G_star = positive_number(G_star, "G_star")
        self.plasticity = plasticity

    @property
    def asperity_count(self) -> float:
        """Expected number of summits on the nominal area, ``eta A0``."""
        return self.asperity_density * self.nominal_area

    @property
    def _load_scale(self) -> float:
        """``(4/3) eta A0 E* sqrt(R) sigma^(3/2)`` [N]: ``N = scale F_{3/2}``."""
        return (
            (4.0 / 3.0)
            * self.asperity_count
            * self.E_star
            * math.sqrt(self.asperity_radius)
            * self.height_std**1.5
        )

    def hertz_load(self, d):
        """Normal load ``N(d)`` [N] of Hertzian asperities at separation ``d`` [m] (vectorised)."""
        return self._load_scale * gw_integral(1.5, np.asarray(d, dtype=float) / self.height_std)

    def hertz_load_slope(self, d):
        """``dN/dd`` [N/m] of Hertzian asperities at separation ``d`` [m] (negative; vectorised)."""
        # d/dd [scale F_{3/2}(d/sigma)] = -(3/2) scale F_{1/2} / sigma.
        return -1.5 * self._load_scale / self.height_std * gw_integral(
            0.5, np.asarray(d, dtype=float) / self.height_std
        )

    def contacts(self, d):
        """Expected number of asperities in contact ``n(d)`` (vectorised)."""
        return self.asperity_count * gw_integral(0, np.asarray(d, dtype=float) / self.height_std)

    def hertz_area(self, d):
        """Real contact area ``A(d)`` [m^2] of Hertzian asperities (vectorised)."""
        return (
            math.pi
            * self.asperity_count
            * self.asperity_radius
            * self.height_std
            * gw_integral(1, np.asarray(d, dtype=float) / self.height_std)
        )

    def plastic_totals(self, d) -> dict:
        """The elastic-plastic totals at ``d`` (:func:`polind.contact.plasticity.statistical_totals`)."""
        return statistical_totals(self, d)

    def hertz_load_and_slope(self, d: float) -> tuple[float, float]:
        """``(N(d), dN/dd)`` of Hertzian asperities for one separation ``d`` [m] (one Python call)."""
        f_half, f_three_halves = half_integer_pair(d / self.height_std)
        scale = self._load_scale
        return scale * f_three_halves, -1.5 * scale / self.height_std * f_half

    @property
    def separation_range(self) -> tuple[float, float]:
        """Separations the solver may return [m]: ``sigma_a`` times [-5, 10]."""
        return VALID_RANGE[0] * self.height_std, VALID_RANGE[1] * self.height_std

    @cached_property
    def load_range(self) -> tuple[float, float]:
        """Smallest and largest normal load [N] with a separation in :attr:`separation_range`."""
        low, high = self.separation_range
        return float(self.normal_load(high)), float(self.normal_load(low))

    def __repr__(self) -> str:
        return (
            f"StatisticalSurface(asperity_density={self.asperity_density!r}, "
            f"nominal_area={self.nominal_area!r}, asperity_radius={self.asperity_radius!r}, "
            f"height_std={self.height_std!r}, E_star={self.E_star!r}, G_star={self.G_star!r})"
        )


@njit(cache=True)
def _tail_moments_many(heights, counts, separations, out):
    """:func:`~polind.kernels.greenwood.tail_moments` at every separation; ``out`` is (n, 4)."""
    for k in range(separations.size):
        number, root_sum, linear_sum, load_sum = tail_moments(heights, counts, separations[k])
        out[k, 0] = number
        out[k, 1] = root_sum
        out[k, 2] = linear_sum
        out[k, 3] = load_sum


class DirectSurface(ElasticPlasticSums):
    """A finite set of summits, every total a plain sum (approach I).

    ``N(d) = sum_{h_i > d} c_i (4/3) E* sqrt(R_i) (h_i - d)^(3/2)``,
    ``n(d) = sum_{h_i > d} c_i``, ``A(d) = sum_{h_i > d} c_i pi R_i (h_i - d)``
    (the Hertz contact of the user guide's single asperity), with ``c_i``
    the number of summits the entry ``i`` stands for (1 for a sample; any
    positive weight, e.g. the asperity counts of an element table or the
    ``A0 / A_map`` of a measured map, is accepted) and ``R_i`` its radius.

    Parameters
    ----------
    heights : array_like
        Summit heights ``h_i`` [m], measured from the reference plane of the
        separation (for a sample or a map: the mean summit height).
    asperity_radius : float
        Summit radius ``R`` [m]; with ``radii``, the reference radius the
        kernels scale by (a measured map uses ``1 / mean(kappa)``).
    E_star, G_star : float
        Effective normal and tangential moduli [Pa].
    counts : array_like, optional
        Summits at each height (default: one each).
    radii : array_like, optional
        Each summit's own radius ``R_i`` [m] (default: ``asperity_radius``
        for all).
    plasticity : polind.contact.plasticity.Plasticity, optional
        The rough body's hardness: elastic-plastic asperities, each summit
        with its own critical interference (:ref:`guide-pol-ind-plasticity`;
        beyond yield the Hertz weights below no longer hold, and the sums
        run over :attr:`plastic_summits`); default Hertzian.

    Attributes
    ----------
    heights : numpy.ndarray
        The distinct summit heights [m], ascending.
    counts : numpy.ndarray
        The number of summits ``c_i`` at each height (floats).
    weights : numpy.ndarray
        The Hertz weights ``w_i = c_i sqrt(R_i / R)`` of the summits at each
        height (see the Notes); ``counts`` itself when every radius is ``R``.

    Notes
    -----
    In Hertz and Mindlin contact the radius enters the load
    ``P = (4/3) E* sqrt(R) delta^(3/2)`` and the tangential stiffness
    ``k = 8 G* sqrt(R delta)`` only through ``sqrt(R)``, so ``c_i`` summits
    of radius ``R_i`` carry exactly the load, stiffness and break-away force
    of ``w_i = c_i sqrt(R_i / R)`` summits of the reference radius ``R``.
    ``weights`` holds these ``w_i``; every kernel (separation, element
    table, the Pol-Ind step) sums with them and one scalar radius, so
    per-summit radii cost nothing in the hot loops.  Only the count of
    contacts (``c_i``) and the real area (``c_i R_i``) need the radii
    themselves.

    The constructor sorts the heights once and merges equal heights (adding
    their counts, weights and areas, which are all additive, so summits of
    different radii at one height merge exactly); sums over the summits in
    contact then run over the sorted tail above ``d`` only, in a numba
    kernel.  Use :meth:`from_seed`, :meth:`from_csv` or
    :meth:`from_topography` to build one from model parameters.

    Examples
    --------
    >>> surface = DirectSurface([1e-6, 2e-6, 2e-6], 50e-6, 1.15e11, 2.4e10)
    >>> surface.heights.tolist(), surface.counts.tolist()
    ([1e-06, 2e-06], [1.0, 2.0])
    >>> float(surface.contacts(1.5e-6))
    2.0
    >>> four = DirectSurface([1e-6], 25e-6, 1.15e11, 2.4e10, radii=[100e-6])
    >>> float(four.weights[0])                  # sqrt(100 / 25): twice the load of R = 25 um
    2.0
    """

    kind = "direct"

    def __init__(self, heights, asperity_radius, E_star, G_star, counts=None, radii=None,
                 plasticity=None):
        self.asperity_radius = positive_number(asperity_radius, "surface.asperity_radius")
        self.E_star = positive_number(E_star, "E_star")
        self.G_star = positive_number(G_star, "G_star")
        self.heights, self.counts, self.weights, self._area_weights = sorted_heights(
            heights, counts, radii, self.asperity_radius)
        # The summits as given (validated above), for plastic_summits; only with radii.
        self._given = None if radii is None else (
            np.asarray(heights, dtype=float).ravel(),
            np.ones(np.size(heights)) if counts is None else np.asarray(counts, dtype=float).ravel(),
            np.asarray(radii, dtype=float).ravel())
        self.plasticity = plasticity
        #: Lowest separation the surface may be pressed to [m] (``-inf``: any
        #: load is carried; a measured map sets its lowest summit).
        self.lowest_separation = -math.inf
        #: The file of a measured map (:meth:`from_topography`), else None.
        self.source = None
        #: The Greenwood–Williamson surface of a measured map (``[model.surface]``
        #: keys, ``nominal_area`` the model's ``A0``), else None.
        self.greenwood_williamson = None

    @classmethod
    def from_seed(cls, asperity_density, nominal_area, height_std, asperity_radius, E_star, G_star, seed=0):
        """Draw ``round(eta A0)`` Gaussian summit heights with a seeded generator.

        Parameters
        ----------
        asperity_density : float
            ``eta`` [1/m^2].
        nominal_area : float
            ``A0`` [m^2].
        height_std : float
            ``sigma_a`` [m].
        asperity_radius : float
            ``R`` [m].
        E_star, G_star : float
            Effective moduli [Pa].
        seed : int, optional
            Seed of ``numpy.random.default_rng`` (default 0).

        Returns
        -------
        DirectSurface
        """
        asperity_density = positive_number(asperity_density, "surface.asperity_density")
        nominal_area = positive_number(nominal_area, "surface.nominal_area")
        height_std = positive_number(height_std, "surface.height_std")
        count = round(asperity_density * nominal_area)
        if not 1 <= count <= MAX_SAMPLED_ASPERITIES:
            raise InputError(
                "The asperity count 'surface.asperity_density' x 'surface.nominal_area' of "
                f"pol-ind must round to 1..{MAX_SAMPLED_ASPERITIES} for direct summation. "
                f"Got {asperity_density * nominal_area:.6g}; use summation = \"statistical\" "
                "for larger surfaces."
            )
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
            raise InputError(
                f"The 'discretisation.seed' of pol-ind must be a non-negative integer. "
                f"Got {describe(seed)}."
            )
        check_memory(count * BYTES_PER_ASPERITY,
                     f"Direct summation over {count:.3g} sampled summits ('surface.asperity_"
                     f"density' x 'surface.nominal_area' of pol-ind)")
        rng = np.random.default_rng(int(seed))
        heights = height_std * rng.standard_normal(count)
        return cls(heights, asperity_radius, E_star, G_star)

    @classmethod
    def from_csv(cls, path, asperity_radius, E_star, G_star):
        """Read measured summit heights (column ``h``, metres) from a CSV file.

        See :func:`read_summit_heights` for the format.

        Returns
        -------
        DirectSurface
        """
        return cls(read_summit_heights(path), asperity_radius, E_star, G_star)

    @classmethod
    def from_topography(cls, measured, E_star, G_star, nominal_area=None):
        """The summits of a measured height map, each with its own radius.

        Parameters
        ----------
        measured : polind.topography.MeasuredSurface
            The analysed map (:func:`polind.topography.load_measured_surface`).
        E_star, G_star : float
            Effective moduli [Pa].
        nominal_area : float, optional
            The nominal contact area ``A0`` [m^2] the model stands for;
            default the map's own area ``A_map = valid_points dx dy``.
            **Choice** (:ref:`guide-measured-surfaces`): each measured
            summit stands for ``A0 / A_map`` summits, so the surface keeps
            the map's summit density, height and radius distributions.

        Returns
        -------
        DirectSurface
            Heights measured from the mean summit height (the reference
            plane of the Greenwood–Williamson equivalent, so that the two
            surfaces' separations compare), reference radius
            ``1 / mean(kappa)``, and :attr:`lowest_separation` at the lowest
            summit: a load that would bring the flat below every measured
            summit is more than the map can carry (the valleys between the
            summits, which the map does not resolve as summits, would touch).
        """
        heights = np.asarray(measured.summit_heights, dtype=float)
        area = float(measured.nominal_area)
        scale = 1.0 if nominal_area is None else positive_number(nominal_area, "surface.nominal_area") / area
        surface = cls(heights - heights.mean(), measured.summit_radius_mean, E_star, G_star,
                      counts=np.full(heights.size, scale), radii=measured.summit_radii)
        surface.lowest_separation = float(surface.heights[0])
        surface.source = measured.source
        surface.greenwood_williamson = {
            **{key: float(value) for key, value in measured.greenwood_williamson().items()},
            "nominal_area": area if nominal_area is None else float(nominal_area)}
        return surface

    @property
    def asperity_count(self) -> float:
        """Number of summits (sum of the counts)."""
        return float(self.counts.sum())

    @cached_property
    def has_radii(self) -> bool:
        """Whether the summits have radii of their own (weights differ from counts)."""
        return self.weights is not self.counts

    def _moments(self, d, weights) -> np.ndarray:
        """Tail sums of ``weights * delta^p``, ``p = 0, 1/2, 1, 3/2``; shape ``d.shape + (4,)``.

        The load and its slope sum with the Hertz weights, the count with the
        counts, the area with the area weights (one array when the summits
        share one radius).
        """
        separations = np.asarray(d, dtype=float)
        flat = np.ascontiguousarray(separations.ravel())
        out = np.empty((flat.size, 4))
        _tail_moments_many(self.heights, weights, flat, out)
        return out.reshape(separations.shape + (4,))

    def _hertz_scale(self) -> float:
        """``(4/3) E* sqrt(R)`` [N/m^(3/2)]: ``P = scale w delta^(3/2)``."""
        return (4.0 / 3.0) * self.E_star * math.sqrt(self.asperity_radius)

    def hertz_load(self, d):
        """Normal load ``N(d)`` [N] of Hertzian asperities at separation ``d`` [m] (vectorised)."""
        return self._hertz_scale() * self._moments(d, self.weights)[..., 3]

    def hertz_load_slope(self, d):
        """``dN/dd`` [N/m] of Hertzian asperities at separation ``d`` [m] (negative; vectorised)."""
        return -1.5 * self._hertz_scale() * self._moments(d, self.weights)[..., 1]

    def contacts(self, d):
        """Number of asperities in contact ``n(d)`` (vectorised)."""
        return self._moments(d, self.counts)[..., 0]

    def hertz_area(self, d):
        """Real contact area ``A(d)`` [m^2] of Hertzian asperities (vectorised)."""
        return math.pi * self.asperity_radius * self._moments(d, self._area_weights)[..., 2]

    @cached_property
    def plastic_summits(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(heights, counts, radii)`` of the summits, merged only at equal height and radius.

        What the elastic-plastic sums run on
        (:func:`polind.contact.heights.summit_groups`); for summits of one
        radius, ``heights`` and ``counts`` with ``R`` for every radius.
        """
        if self._given is None:
            return self.heights, self.counts, np.full(self.heights.size, self.asperity_radius)
        heights, counts, _, radii = summit_groups(*self._given, self.asperity_radius)
        return heights, counts, radii

    @cached_property
    def plastic_weights(self) -> np.ndarray:
        """The Hertz weights ``c_i sqrt(R_i / R)`` of :attr:`plastic_summits`."""
        if self._given is None:
            return self.weights
        return summit_groups(*self._given, self.asperity_radius)[2]

    def plastic_totals(self, d) -> dict:
        """The elastic-plastic totals at ``d`` (:func:`polind.contact.plasticity.direct_totals`)."""
        return direct_totals(self, d)

    def hertz_load_and_slope(self, d: float) -> tuple[float, float]:
        """``(N(d), dN/dd)`` of Hertzian asperities for one separation ``d`` [m] (one Python call)."""
        _, root_sum, _, load_sum = tail_moments(self.heights, self.weights, float(d))
        scale = self._hertz_scale()
        return scale * load_sum, -1.5 * scale * root_sum

    @property
    def separation_range(self) -> tuple[float, float]:
        """Separations the solver may return [m]: below the highest summit.

        Below the lowest summit every summit is in contact and ``N(d)`` keeps
        growing as ``(h - d)^(3/2)``: any positive load has a separation,
        unless :attr:`lowest_separation` (a measured map) stops it there.
        """
        return self.lowest_separation, float(self.heights[-1])

    @property
    def smallest_load(self) -> float:
        """The smallest load [N] a separation in double precision lets a summit carry.

        ``N`` one unit in the last place below the highest summit (the
        closest separation to it a double holds): the highest summit(s) at an
        interference of that one unit.  A smaller load would need a smaller
        interference than any double below the summit's height gives, so at
        every separation the solver could return no summit would be in
        contact: the load would rest on no asperity and the element table
        would be empty (no break-away force for ``mu_s N``).  It is some
        ``1e-24`` N for summits at micrometres; 0 for a highest summit at 0.
        :func:`polind.contact.separation.solve_separation` refuses loads
        below it.
        """
        highest = float(self.heights[-1])
        return float(self.normal_load(np.nextafter(highest, -math.inf)))

    @property
    def load_range(self) -> tuple[float, float]:
        """Loads [N] the surface can carry: from :attr:`smallest_load` up to ``N(lowest_separation)``.

        In real numbers every positive load has a separation; in doubles a
        load below :attr:`smallest_load` leaves no summit in contact.  The
        largest is unbounded, unless :attr:`lowest_separation` (a measured
        map) stops the flat at the lowest summit.
        """
        smallest = self.smallest_load
        if math.isfinite(self.lowest_separation):
            return smallest, float(self.normal_load(self.lowest_separation))
        return smallest, math.inf

    @cached_property
    def height_statistics(self) -> tuple[float, float]:
        """Count-weighted mean and standard deviation of the summit heights [m]."""
        weights = self.counts / self.counts.sum()
        mean = float(weights @ self.heights)
        std = float(math.sqrt(max(weights @ (self.heights - mean) ** 2, 0.0)))
        return mean, std

    def __repr__(self) -> str:
        radii = ", own radii" if self.has_radii else ""
        return (
            f"DirectSurface(<{self.heights.size} heights, {self.asperity_count:.6g} summits{radii}>, "
            f"asperity_radius={self.asperity_radius!r}, E_star={self.E_star!r}, "
            f"G_star={self.G_star!r})"
        )
