"""Rough surfaces pressed by a rigid flat: statistical and direct summation (MODELS.md 7.1, 7.3).

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
(:mod:`polind.contact.separation`) iterates on.
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
from polind.kernels.separation import tail_moments

__all__ = [
    "StatisticalSurface",
    "DirectSurface",
    "read_summit_heights",
    "MAX_SAMPLED_ASPERITIES",
]

#: Largest seeded sample :meth:`DirectSurface.from_seed` draws (memory: 8
#: bytes per summit, twice while sorting); beyond it use statistical summation.
MAX_SAMPLED_ASPERITIES = 50_000_000


class StatisticalSurface:
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

    def __init__(self, asperity_density, nominal_area, asperity_radius, height_std, E_star, G_star):
        self.asperity_density = positive_number(asperity_density, "surface.asperity_density")
        self.nominal_area = positive_number(nominal_area, "surface.nominal_area")
        self.asperity_radius = positive_number(asperity_radius, "surface.asperity_radius")
        self.height_std = positive_number(height_std, "surface.height_std")
        self.E_star = positive_number(E_star, "E_star")
        self.G_star = positive_number(G_star, "G_star")

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

    def normal_load(self, d):
        """Total normal load ``N(d)`` [N] at separation ``d`` [m] (vectorised)."""
        return self._load_scale * gw_integral(1.5, np.asarray(d, dtype=float) / self.height_std)

    def normal_load_slope(self, d):
        """``dN/dd`` [N/m] at separation ``d`` [m] (negative; vectorised)."""
        # d/dd [scale F_{3/2}(d/sigma)] = -(3/2) scale F_{1/2} / sigma.
        return -1.5 * self._load_scale / self.height_std * gw_integral(
            0.5, np.asarray(d, dtype=float) / self.height_std
        )

    def contacts(self, d):
        """Expected number of asperities in contact ``n(d)`` (vectorised)."""
        return self.asperity_count * gw_integral(0, np.asarray(d, dtype=float) / self.height_std)

    def real_area(self, d):
        """Real contact area ``A(d)`` [m^2] (vectorised)."""
        return (
            math.pi
            * self.asperity_count
            * self.asperity_radius
            * self.height_std
            * gw_integral(1, np.asarray(d, dtype=float) / self.height_std)
        )

    def load_and_slope(self, d: float) -> tuple[float, float]:
        """``(N(d), dN/dd)`` for one separation ``d`` [m] (one Python call)."""
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
    """:func:`~polind.kernels.separation.tail_moments` at every separation; ``out`` is (n, 4)."""
    for k in range(separations.size):
        number, root_sum, linear_sum, load_sum = tail_moments(heights, counts, separations[k])
        out[k, 0] = number
        out[k, 1] = root_sum
        out[k, 2] = linear_sum
        out[k, 3] = load_sum


class DirectSurface:
    """A finite set of summit heights, every total a plain sum (approach I).

    ``N(d) = sum_{h_i > d} c_i P(h_i - d)``, ``n(d) = sum_{h_i > d} c_i``,
    ``A(d) = sum_{h_i > d} c_i pi R (h_i - d)``, with the Hertz load ``P`` of
    MODELS.md 7.2 and ``c_i`` the number of summits at height ``h_i`` (1 for
    a sample; any positive weight, e.g. the asperity counts of an element
    table, is accepted).

    Parameters
    ----------
    heights : array_like
        Summit heights ``h_i`` [m], measured from the reference plane of the
        separation (for a sample: the mean summit height).
    asperity_radius : float
        Summit radius ``R`` [m].
    E_star, G_star : float
        Effective normal and tangential moduli [Pa].
    counts : array_like, optional
        Summits at each height (default: one each).

    Notes
    -----
    The constructor sorts the heights once and merges equal heights (adding
    their counts); sums over the summits in contact then run over the
    sorted tail above ``d`` only, in a numba kernel.  Use
    :meth:`from_seed` or :meth:`from_csv` to build one from model parameters.

    Examples
    --------
    >>> surface = DirectSurface([1e-6, 2e-6, 2e-6], 50e-6, 1.15e11, 2.4e10)
    >>> surface.heights.tolist(), surface.counts.tolist()
    ([1e-06, 2e-06], [1.0, 2.0])
    >>> float(surface.contacts(1.5e-6))
    2.0
    """

    kind = "direct"

    def __init__(self, heights, asperity_radius, E_star, G_star, counts=None):
        self.asperity_radius = positive_number(asperity_radius, "surface.asperity_radius")
        self.E_star = positive_number(E_star, "E_star")
        self.G_star = positive_number(G_star, "G_star")
        self.heights, self.counts = _sorted_heights(heights, counts)

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

    @property
    def asperity_count(self) -> float:
        """Number of summits (sum of the counts)."""
        return float(self.counts.sum())

    def _moments(self, d) -> np.ndarray:
        """Tail sums of ``delta^p``, ``p = 0, 1/2, 1, 3/2``; shape ``d.shape + (4,)``."""
        separations = np.asarray(d, dtype=float)
        flat = np.ascontiguousarray(separations.ravel())
        out = np.empty((flat.size, 4))
        _tail_moments_many(self.heights, self.counts, flat, out)
        return out.reshape(separations.shape + (4,))

    def _hertz_scale(self) -> float:
        """``(4/3) E* sqrt(R)`` [N/m^(3/2)]: ``P = scale delta^(3/2)``."""
        return (4.0 / 3.0) * self.E_star * math.sqrt(self.asperity_radius)

    def normal_load(self, d):
        """Total normal load ``N(d)`` [N] at separation ``d`` [m] (vectorised)."""
        return self._hertz_scale() * self._moments(d)[..., 3]

    def normal_load_slope(self, d):
        """``dN/dd`` [N/m] at separation ``d`` [m] (negative; vectorised)."""
        return -1.5 * self._hertz_scale() * self._moments(d)[..., 1]

    def contacts(self, d):
        """Number of asperities in contact ``n(d)`` (vectorised)."""
        return self._moments(d)[..., 0]

    def real_area(self, d):
        """Real contact area ``A(d)`` [m^2] (vectorised)."""
        return math.pi * self.asperity_radius * self._moments(d)[..., 2]

    def load_and_slope(self, d: float) -> tuple[float, float]:
        """``(N(d), dN/dd)`` for one separation ``d`` [m] (one Python call)."""
        _, root_sum, _, load_sum = tail_moments(self.heights, self.counts, float(d))
        scale = self._hertz_scale()
        return scale * load_sum, -1.5 * scale * root_sum

    @property
    def separation_range(self) -> tuple[float, float]:
        """Separations the solver may return [m]: anything below the highest summit.

        Below the lowest summit every summit is in contact and ``N(d)`` keeps
        growing as ``(h - d)^(3/2)``: any positive load has a separation.
        """
        return -math.inf, float(self.heights[-1])

    @property
    def load_range(self) -> tuple[float, float]:
        """Loads [N] the surface can carry: every positive load."""
        return 0.0, math.inf

    @cached_property
    def height_statistics(self) -> tuple[float, float]:
        """Count-weighted mean and standard deviation of the summit heights [m]."""
        weights = self.counts / self.counts.sum()
        mean = float(weights @ self.heights)
        std = float(math.sqrt(max(weights @ (self.heights - mean) ** 2, 0.0)))
        return mean, std

    def __repr__(self) -> str:
        return (
            f"DirectSurface(<{self.heights.size} heights, {self.asperity_count:.6g} summits>, "
            f"asperity_radius={self.asperity_radius!r}, E_star={self.E_star!r}, "
            f"G_star={self.G_star!r})"
        )


def _sorted_heights(heights, counts) -> tuple[np.ndarray, np.ndarray]:
    """Validate, sort ascending and merge equal heights; returns (heights, counts)."""
    values = np.asarray(heights, dtype=float)
    if values.ndim != 1 or values.size == 0:
        raise InputError(
            f"The summit 'heights' of pol-ind must be a non-empty 1-D list of numbers. "
            f"Got shape {values.shape}."
        )
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError(
            f"The summit 'heights' of pol-ind must be finite. Got {values[bad[0]]!r} at index {bad[0]}."
        )
    if counts is None:
        weights = np.ones_like(values)
    else:
        weights = np.asarray(counts, dtype=float)
        if weights.shape != values.shape:
            raise InputError(
                f"The asperity 'counts' of pol-ind must match the heights, shape {values.shape}. "
                f"Got shape {weights.shape}."
            )
        bad = np.flatnonzero(~(np.isfinite(weights) & (weights > 0.0)))
        if bad.size:
            raise InputError(
                f"The asperity 'counts' of pol-ind must be positive and finite. "
                f"Got {weights[bad[0]]!r} at index {bad[0]}."
            )
    if counts is None:
        # All weights are 1: a plain sort is about twice as fast as argsort.
        values = np.sort(values)
    else:
        order = np.argsort(values)
        values = values[order]
        weights = weights[order]
    # Equal heights become one summit group: same interference, same forces.
    starts = np.flatnonzero(np.concatenate(([True], values[1:] != values[:-1])))
    if starts.size != values.size:
        weights = np.add.reduceat(weights, starts)
        values = values[starts]
    return np.ascontiguousarray(values), np.ascontiguousarray(weights)


def read_summit_heights(path) -> np.ndarray:
    """Read measured summit heights from a CSV file.

    The file has a header row naming a column ``h`` (other columns are
    ignored) and one summit per row, heights in metres measured from the
    reference plane of the separation.  Blank lines are skipped.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    numpy.ndarray
        The heights [m], in file order.

    Raises
    ------
    polind.InputError
        If the file cannot be read, has no ``h`` column or no rows, or a row
        holds something other than one finite number in that column; the
        message names the file and the line.
    """
    name = os.fspath(path)
    what = f"The heights file '{name}' of pol-ind"
    try:
        with open(name, newline="", encoding="utf-8-sig") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError) as error:
        raise InputError(f"{what} cannot be read: {error}.") from None
    lines = [(number, row) for number, row in enumerate(rows, start=1) if any(f.strip() for f in row)]
    if not lines:
        raise InputError(f"{what} is empty; expected a header 'h' and one summit height per row.")
    header_line, header = lines[0]
    names = [field.strip() for field in header]
    if "h" not in names:
        raise InputError(
            f"{what} must have a header naming a column 'h' (summit heights in metres). "
            f"Got header {describe(names)} on line {header_line}."
        )
    column = names.index("h")
    heights = np.empty(len(lines) - 1)
    for index, (line, row) in enumerate(lines[1:]):
        text = row[column].strip() if column < len(row) else ""
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or len(row) != len(header):
            raise InputError(
                f"{what} has a bad row {index + 1} (line {line}): {describe(','.join(row))}; "
                f"expected {len(header)} field(s) with a finite summit height in metres in column 'h'."
            )
        heights[index] = value
    if heights.size == 0:
        raise InputError(f"{what} has no data rows; expected one summit height per row.")
    return heights
