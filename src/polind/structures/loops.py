"""The figures of a hysteresis loop: :func:`polind.hysteresis_loop`
(:ref:`guide-structures-loops`).

What a joint experiment reports of a periodic record of force against
displacement: the energy dissipated per cycle, the secant stiffness and the
equivalent viscous damping ratio of its last closed loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from polind.errors import InputError
from polind.validation import check_samples

__all__ = ["HysteresisLoop", "hysteresis_loop"]


@dataclass(frozen=True)
class HysteresisLoop:
    """The last closed loop of a record and its figures (:func:`polind.hysteresis_loop`).

    Attributes
    ----------
    u : ndarray
        The displacement samples of the loop [m]: ``u_record[start:stop + 1]``.
    F : ndarray
        The force samples of the loop [N]: ``F_record[start:stop + 1]``.
    start, stop : int
        The record's indices of the loop's first and last samples (one cycle apart).
    energy : float
        The energy dissipated per cycle ``D = closed integral of F du`` [J]
        (trapezoidal on the samples, closed by the chord from the last sample
        back to the first), positive when the force resists the motion.
    secant_stiffness : float
        ``(F_max - F_min) / (u_max - u_min)`` over the loop [N/m].
    damping_ratio : float
        The equivalent viscous damping ratio ``D / (4 pi E_s)`` with
        ``E_s = (F_max - F_min)(u_max - u_min) / 8``; NaN for a loop whose
        force never changes (``E_s = 0``).
    """

    u: np.ndarray
    F: np.ndarray
    start: int
    stop: int
    energy: float
    secant_stiffness: float
    damping_ratio: float

    @property
    def strain_energy(self) -> float:
        """``E_s = (F_max - F_min)(u_max - u_min) / 8`` [J], the loop's secant strain energy."""
        return float(np.ptp(self.F) * np.ptp(self.u) / 8.0)

    def __repr__(self):
        return (f"HysteresisLoop(samples {self.start}..{self.stop}, energy {self.energy:.6g} J, "
                f"secant_stiffness {self.secant_stiffness:.6g} N/m, "
                f"damping_ratio {self.damping_ratio:.6g})")


def _record(values, name):
    return check_samples("hysteresis_loop", name, values)


def _peaks(u, middle, band) -> list:
    """The maxima of the excursions of ``u`` above ``middle + band`` that lie inside the record.

    An excursion begins where ``u`` reaches ``middle + band`` and ends where it
    next falls to ``middle - band``; its maximum is the first sample of its
    largest ``u``.
    """
    above = np.flatnonzero(u >= middle + band)
    below = np.flatnonzero(u <= middle - band)
    peaks = []
    first = 0
    while first < above.size:
        fall = np.searchsorted(below, above[first])
        end = below[fall] if fall < below.size else u.shape[0]
        last = int(np.searchsorted(above, end)) - 1
        begin, finish = int(above[first]), int(above[last])
        # inside: below middle + band before and after, so the maximum is a reversal
        if begin > 0 and finish < u.shape[0] - 1:
            peaks.append(begin + int(np.argmax(u[begin:finish + 1])))
        first = last + 1
    return peaks


def last_cycle(u) -> tuple:
    """``(start, stop)``: the record indices of the last full cycle of ``u``.

    The rule: with ``m`` the middle of the record's range of ``u`` and ``q`` a
    quarter of the range, an excursion is a stretch of the record during
    which ``u`` rises to ``m + q`` or above, ended by a fall to ``m - q`` or
    below (the band keeps noise from splitting one excursion in two or
    starting a false one).  Its maximum is a peak when the excursion lies
    inside the record (``u`` is below ``m + q`` before it and after it): a
    reversal of the motion, not a sample where the record was cut.  Troughs
    are the same for ``-u``.  A full cycle runs from one peak to the next, or
    from one trough to the next; the last cycle is the one of the last two
    peaks or of the last two troughs, whichever ends later (peaks on a tie).
    For a record sampled periodically with ``N`` samples per period, its
    ends are exactly ``N`` samples apart.

    Raises
    ------
    InputError
        If ``u`` never changes or holds neither two peaks nor two troughs.
    """
    low, high = float(np.min(u)), float(np.max(u))
    if not high > low:
        raise InputError(f"The record holds no closed loop: 'u' never changes (every sample is "
                         f"{low!r}).")
    middle, band = 0.5 * (low + high), 0.25 * (high - low)
    cycles = [tuple(extrema[-2:]) for extrema in (_peaks(u, middle, band),
                                                   _peaks(-u, -middle, band))
              if len(extrema) >= 2]
    if not cycles:
        raise InputError(f"The record holds no closed loop: 'u' must pass two maxima or two "
                         f"minima of a full cycle (each an excursion beyond {middle + band:.6g} "
                         f"or {middle - band:.6g} that returns, with one to the other side "
                         f"between them); it has fewer in {u.shape[0]} samples.")
    return max(cycles, key=lambda cycle: cycle[1])


def hysteresis_loop(u, F) -> HysteresisLoop:
    """The last closed loop of a periodic record of force against displacement, and its figures.

    Parameters
    ----------
    u : array_like
        The displacement at each sample [m] (a contact's relative
        displacement, or any coordinate), 1-D.
    F : array_like
        The force at each sample [N], as long as ``u``.

    Returns
    -------
    HysteresisLoop
        The loop (the last full cycle of ``u``: between its last two maxima,
        or its last two minima, whichever pair ends later; an extremum counts
        when ``u`` goes from the middle quarter of its range beyond the outer
        quarter and back) with its energy per cycle ``D`` (trapezoidal on
        the samples, closed by the chord back to the first sample), its secant
        stiffness and its equivalent viscous damping ratio
        ``D / (4 pi E_s)``, ``E_s = (F_max - F_min)(u_max - u_min) / 8``.

    Raises
    ------
    InputError
        For ``u`` or ``F`` not 1-D finite arrays of one length, or a record
        without a full cycle of ``u``.

    Examples
    --------
    A spring of 1e5 N/m beside a viscous damper of 50 N s/m, at 2 Hz: the
    damping ratio is ``c omega / (2 sqrt(k^2 + (c omega)^2))``.

    >>> import numpy as np, polind
    >>> t = np.arange(801) / 400.0                    # two periods of 0.5 s
    >>> u = 1e-3 * np.sin(4 * np.pi * t)
    >>> F = 1e5 * u + 50.0 * 1e-3 * 4 * np.pi * np.cos(4 * np.pi * t)
    >>> loop = polind.hysteresis_loop(u, F)
    >>> loop.stop - loop.start, round(loop.damping_ratio, 5)
    (200, 0.00314)
    """
    u, F = _record(u, "u"), _record(F, "F")
    if F.shape != u.shape:
        raise InputError(f"The 'F' of hysteresis_loop must have one value per sample of 'u' "
                         f"({u.shape[0]}). Got {F.shape[0]} instead.")
    start, stop = last_cycle(u)
    loop_u, loop_f = u[start:stop + 1].copy(), F[start:stop + 1].copy()
    closed_u, closed_f = np.append(loop_u, loop_u[0]), np.append(loop_f, loop_f[0])
    energy = float(np.sum(0.5 * (closed_f[1:] + closed_f[:-1]) * np.diff(closed_u)))
    force_range, span = float(np.ptp(loop_f)), float(np.ptp(loop_u))
    strain = force_range * span / 8.0
    ratio = energy / (4.0 * math.pi * strain) if strain > 0.0 else math.nan
    return HysteresisLoop(u=loop_u, F=loop_f, start=start, stop=stop, energy=energy,
                          secant_stiffness=force_range / span, damping_ratio=ratio)
