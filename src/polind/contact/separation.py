"""The separation under a given normal load: the iterative method (approach III).

Solves ``N(d) = N_app`` for the separation ``d`` of a
:class:`~polind.contact.surface.StatisticalSurface` or a
:class:`~polind.contact.surface.DirectSurface` with a
safeguarded Newton iteration: the root is kept in a bracket
``[lo, hi]`` with ``N(lo) >= N_app >= N(hi)``; each step is a Newton step on
``log N(d) - log N_app`` (the load spans decades, and ``log N`` is concave
and gently curved where ``N`` itself is exponentially small, so Newton
converges monotonically after its first step), and a step that would leave
the bracket is replaced by bisection.  It stops when
``|N(d) - N_app| <= 1e-10 N_app``.  The start is a table look-up of
``F_{3/2}`` for the Gaussian with the surface's moments: 3 load evaluations
for any load on the default surfaces; a warm start in a series needs 1–2.
The iteration itself runs in the numba kernels of
:mod:`polind.kernels.separation` (which model kernels call per sample), so
this module's separations and a kernel's are the same to the bit; this
module validates the loads and picks the first starting point.
The one case the tolerance cannot be met is a direct surface whose highest
summit alone carries a load so small that its interference is below about
1e-9 of ``|d|``: neighbouring doubles of ``d`` then differ by more than
1e-10 in load, and the best representable ``d`` is returned.

Loads the surface cannot carry are :class:`polind.InputError`:

- not a positive finite number;
- statistical surface: a load that needs ``d/sigma_a < -5`` (nearly every
  summit crushed, far outside the model's small-interference validity) or
  ``d/sigma_a > 10`` (fewer than ``eta A0 * 8e-24`` summits in contact:
  the load is carried by no asperity in any physical sense); this is also
  the range over which the ``F_m`` are verified to 1e-10;
- direct surface from a measured map: a load above ``N`` at its lowest
  summit (every measured summit in contact; the map cannot carry it);
- any direct surface: a load below its
  :attr:`~polind.contact.surface.DirectSurface.smallest_load`, the load of
  its highest summit at an interference of one unit in the last place of
  that summit's height.  In real numbers every positive load has a
  separation below the highest summit (the load tends to 0 as ``d`` tends
  to it); in doubles a smaller load would leave no summit in contact at any
  separation: a contact resting on no asperity, with no element to carry
  ``mu_s N``, which is no contact at all (some ``1e-24`` N for summits at
  micrometres);
- other direct surfaces: nothing more.  A load
  above ``N(lowest summit)`` puts the flat below every summit, all in
  contact, and is accepted, because an element table used as a surface
  (:meth:`polind.contact.elements.ElementTable.as_surface`) must carry the
  load it was built for with the flat below its lowest element.  The
  bracket's lower end is where the highest summit alone would carry the
  load, ``h_max - (N / (c_max (4/3) E* sqrt(R)))^(2/3)``.

A surface with elastic-plastic asperities (a hardness,
:ref:`guide-pol-ind-plasticity`) is solved by the same iteration on its
elastic-plastic load (:mod:`polind.kernels.plastic_separation`), started
from the same guess.  A direct sum of such summits jumps where a summit
crosses a Kogut–Etsion range boundary: a load inside a jump has no
separation, and the iteration stops at the jump (bracket narrower than
``1e-12 sigma_a``), at the best separation it evaluated;
:func:`polind.contact.build_contact` reports the load left over as the
contact's ``unmatched_load``.

See the user guide: :ref:`guide-pol-ind-separation`.
"""

from __future__ import annotations

import math

import numpy as np

from polind.contact.greenwood import three_halves_inverse
from polind.contact.plasticity import plastic_kernel_arguments
from polind.errors import InputError, describe
from polind.kernels import plastic_separation as _plastic
from polind.kernels import separation as _kernels
from polind.kernels.interpreted import interpreted
from polind.kernels.special import special_addresses

__all__ = ["solve_separation", "solve_separation_series", "RELATIVE_TOLERANCE"]

#: Required accuracy of the load balance, ``|N(d) - N_app| <= tol N_app``.
RELATIVE_TOLERANCE = _kernels.RELATIVE_TOLERANCE

# The arrays a statistical surface passes for the direct surface's summits.


def _checked_load(value, where: str = "") -> float:
    """The load as a float if positive and finite, else InputError."""
    numeric = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    number = float(value) if numeric else math.nan
    if not (math.isfinite(number) and number > 0.0):
        raise InputError(
            f"The 'normal_load' of pol-ind must be a positive finite number. "
            f"Got {describe(number if numeric else value)}{where}."
        )
    return number


def _checked_initial(value) -> float:
    """The starting separation as a float if finite, else InputError."""
    numeric = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not (numeric and math.isfinite(float(value))):
        raise InputError(f"The 'initial' separation must be a finite number in metres. Got {describe(value)}.")
    return float(value)


def _check_reachable(surface, load: float, where: str = "") -> None:
    """Raise InputError if no separation in the surface's range carries ``load``."""
    smallest, largest = surface.load_range
    if surface.kind == "direct" and load < smallest:
        raise InputError(
            f"The 'normal_load' of pol-ind is too small for its summits: their highest, at "
            f"{float(surface.heights[-1]):.6g} m, would carry it at an interference below the "
            f"spacing of doubles at that height, so no summit would be in contact and no "
            f"asperity would carry the load. Got {load!r} N{where}; expected at least "
            f"{smallest:.6g} N."
        )
    if surface.kind == "direct" and load > largest:
        raise InputError(
            f"The 'normal_load' of pol-ind is more than the measured surface "
            f"'{surface.source}' can carry: every one of its "
            f"{surface.asperity_count:.6g} summits would be in contact and the flat would reach "
            f"the valleys between them. Got {load!r} N{where}; expected at most {largest:.6g} N "
            f"(a larger 'surface.nominal_area' spreads the load over more summits)."
        )
    if surface.kind == "statistical":
        if load > largest:
            raise InputError(
                f"The 'normal_load' of pol-ind is too large for its statistical surface: it "
                f"needs d/sigma_a below -5, nearly every summit crushed, outside the "
                f"Greenwood–Williamson model. Got {load!r} N{where}; expected at most {largest:.6g} N."
            )
        if load < smallest:
            raise InputError(
                f"The 'normal_load' of pol-ind is too small for its statistical surface: it "
                f"needs d/sigma_a above 10, where no asperity is in contact "
                f"(expected count {surface.contacts(surface.separation_range[1]):.3g}). "
                f"Got {load!r} N{where}; expected at least {smallest:.6g} N."
            )


def _initial_guess(surface, load: float, low: float, high: float) -> float:
    """A starting separation inside the bracket ``(low, high)``.

    The Gaussian surface with the same summit count, mean height and spread
    carries nearly the same load at nearly the same separation, and its
    ``F_{3/2}`` is inverted by table look-up; for the statistical surface
    that is the surface itself.
    """
    if surface.kind == "statistical":
        mean, std, count = 0.0, surface.height_std, surface.asperity_count
    else:
        # Summits of their own radii count by their Hertz weights c_i sqrt(R_i / R).
        (mean, std), count = surface.height_statistics, float(surface.weights.sum())
    if std > 0.0:
        scale = (4.0 / 3.0) * count * surface.E_star * math.sqrt(surface.asperity_radius) * std**1.5
        guess = mean + std * three_halves_inverse(load / scale)
        if low < guess < high:
            return guess
    # Equal heights (or a guess outside the bracket): the lower end, where
    # the highest summits alone carry the load, exact for equal heights.
    return low if math.isfinite(low) else 0.5 * (low + high)


def _kernel_surface(surface) -> tuple:
    """The surface as the kernels' arguments.

    ``(kind, load_scale, height_std, heights, counts, hertz, addresses)``,
    see :mod:`polind.kernels.separation`.  The scales are the surfaces' own
    (``_load_scale``, ``_hertz_scale``) and a direct surface passes its
    Hertz weights ``c_i sqrt(R_i / R)`` as the counts, so the kernels' loads
    are those of ``surface.load_and_slope`` to the bit.
    """
    # The types the model's kernels pass (float64 kind and addresses, writable arrays):
    # one compiled solver serves both.
    addresses = special_addresses().astype(np.float64)
    if surface.kind == "statistical":
        return (_kernels.STATISTICAL, surface._load_scale, surface.height_std, np.empty(0),
                np.empty(0), 0.0, addresses)
    return (_kernels.DIRECT, 0.0, 1.0, _writable(surface.heights), _writable(surface.weights),
            surface._hertz_scale(), addresses)


def _writable(values):
    """``values`` as a writable C-contiguous float64 array (a copy only if it is not one)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return values if values.flags.writeable else values.copy()


def _lower_bound(surface, load: float, arguments: tuple) -> float:
    """A separation at which the surface carries at least ``load``.

    Statistical surface: the end of its range (the load was checked against
    it).  Direct surface: the highest summits alone, carrying the whole
    load, need a larger interference than the real contact, where lower
    summits help, so ``N(d) >= load`` at
    ``d = h_max - (N / (c_max (4/3) E* sqrt(R)))^(2/3)``
    (:func:`polind.kernels.separation.direct_lower_bound`).
    """
    if surface.kind != "direct":
        return surface.separation_range[0]
    _, _, _, heights, counts, hertz, _ = arguments
    return _kernels.direct_lower_bound(load, heights, counts, hertz)


def solve_separation(surface, normal_load, initial=None, *, full_output=False):
    """Separation ``d`` at which the surface carries the normal load (:ref:`guide-pol-ind-separation`).

    Parameters
    ----------
    surface : StatisticalSurface or DirectSurface
        The rough surface.
    normal_load : float
        Applied normal load ``N_app`` [N], positive.
    initial : float, optional
        Starting separation [m] (a warm start); by default a guess from the
        surface's statistics.
    full_output : bool, optional
        Also return the number of load evaluations.

    Returns
    -------
    d : float
        Separation [m] with ``|N(d) - N_app| <= 1e-10 N_app``.
    evaluations : int
        Only with ``full_output``: load evaluations used.

    Raises
    ------
    polind.InputError
        If the load is not positive and finite, or the surface cannot carry
        it (see the module notes for the limits).

    Examples
    --------
    >>> from polind.contact.surface import StatisticalSurface
    >>> surface = StatisticalSurface(1e10, 1e-4, 50e-6, 0.5e-6, 1.15e11, 2.4e10)
    >>> d = solve_separation(surface, 100.0)
    >>> abs(float(surface.normal_load(d)) - 100.0) <= 1e-8
    True
    """
    load = _checked_load(normal_load)
    _check_reachable(surface, load)
    if surface.plasticity is not None:
        vector, heights, weights, counts, radii = plastic_kernel_arguments(surface)
        lo, hi = surface.separation_range
        lo = _plastic.plastic_lower(load, lo, vector, heights, counts, radii)
        start = _initial_guess(surface, load, lo, hi) if initial is None else _checked_initial(initial)
        d, _, _, evaluations = _plastic.plastic_newton(load, start, lo, hi, vector, heights, weights,
                                                       counts, radii)
        return (d, evaluations) if full_output else d
    arguments = _kernel_surface(surface)
    lo, hi = _lower_bound(surface, load, arguments), surface.separation_range[1]
    start = _initial_guess(surface, load, lo, hi) if initial is None else _checked_initial(initial)
    # One kind's solver: newton_separation_counted's results, without compiling the other kind.
    # A statistical surface's is run by Python (its kernels compile without fastmath, so the
    # results are the compiled solver's to the bit): one solve is not worth the 0.9 s its
    # compilation costs a cold process.  The load and the bracket are checked above.
    solver = (interpreted(_kernels.statistical_newton_counted) if surface.kind == "statistical"
              else _kernels.direct_newton_counted)
    d, _, _, evaluations = solver(load, start, lo, hi, *arguments)
    return (float(d), int(evaluations)) if full_output else float(d)


def solve_separation_series(surface, normal_load, initial=None, *, full_output=False):
    """Separation ``d(t)`` for a time-varying normal load ``N(t)``, warm-started.

    Every sample is solved as in :func:`solve_separation`, warm-started from
    the previous sample: the first guess is the Newton step from the previous
    separation, whose load and slope are known (a repeated load reuses the
    previous separation outright).

    Parameters
    ----------
    surface : StatisticalSurface or DirectSurface
        The rough surface.
    normal_load : array_like
        Normal load at every sample [N], 1-D, each positive.
    initial : float, optional
        Starting separation [m] for the first sample.
    full_output : bool, optional
        Also return the load evaluations used at each sample.

    Returns
    -------
    separation : numpy.ndarray
        Separation [m] at every sample.
    evaluations : numpy.ndarray of int
        Only with ``full_output``.

    Raises
    ------
    polind.InputError
        As :func:`solve_separation`; the message gives the sample's index.
    """
    loads = np.asarray(normal_load, dtype=float)
    if loads.ndim != 1:
        raise InputError(
            f"The 'normal_load' series of pol-ind must be 1-D. Got shape {loads.shape}."
        )
    # Check every sample before solving any: the error names the first bad one.
    smallest, largest = surface.load_range
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(loads) & (loads > 0.0) & (loads >= smallest) & (loads <= largest))
    if bad.any():
        index = int(np.flatnonzero(bad)[0])
        where = f" at index {index}"
        _check_reachable(surface, _checked_load(loads[index], where), where)
    separation = np.empty(loads.size)
    evaluations = np.zeros(loads.size, dtype=np.int64)
    if loads.size and surface.plasticity is not None:
        arguments = plastic_kernel_arguments(surface)
        lo, hi = surface.separation_range
        first = float(loads[0])
        if initial is None:
            vector, heights, _, counts, radii = arguments
            start = _initial_guess(surface, first,
                                   _plastic.plastic_lower(first, lo, vector, heights, counts, radii), hi)
        else:
            start = _checked_initial(initial)
        _plastic.plastic_separation_series(np.ascontiguousarray(loads), start, lo, hi, *arguments,
                                           separation, evaluations)
    elif loads.size:
        arguments = _kernel_surface(surface)
        lo, hi = surface.separation_range
        first = float(loads[0])
        if initial is None:
            start = _initial_guess(surface, first, _lower_bound(surface, first, arguments), hi)
        else:
            start = _checked_initial(initial)
        # The kernel warm-starts every later sample from the previous one.
        _kernels.newton_separation_series(np.ascontiguousarray(loads), start, lo, hi, *arguments,
                                          separation, evaluations)
    return (separation, evaluations) if full_output else separation
