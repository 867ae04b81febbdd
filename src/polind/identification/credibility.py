"""Whether a fit's result is credible: the warnings on the fit as a whole.

The user guide, :ref:`guide-fit-warnings`.  Besides the warnings on single
parameters (:mod:`polind.identification.results`), every fit is checked for
four signs that its result should not be trusted:

* **an error above the record's noise**: the RMS error of the fitted samples
  above :data:`NOISE_RATIO` times the record's own noise, estimated from its
  high-frequency part (:func:`noise_level`).  A model that describes the
  contact, at the minimum of the sum of squares, leaves the noise, so its
  RMS error is the noise's standard deviation (times ``sqrt((n - p) / n)``);
  one well above it missed a pattern of the force: the model, or the search
  that stopped in a wrong basin.
* **a force level beyond the data**: the model's sliding level (the
  ``coulomb_force`` of its characteristic scales: ``Fc``, ``sum W`` of
  Maxwell-slip, ``mu_k N`` of Pol-Ind) above :data:`SLIDING_LEVEL` times the
  largest measured ``|F|``, or its break-away level (``Fs``, ``sum W``,
  ``mu_s N``) above :data:`BREAKAWAY_LEVEL` times it.  Steady sliding shows
  the sliding level in every record that slides, so a sliding level above
  every measured force is one the data did not choose; a break-away level
  is reached only in the limit of slow steady sliding, and a dynamic
  break-away falls short of it, hence the wider margin.  Under a measured
  normal load the levels are taken at its largest value.  A level that no
  free value moves (its keys fixed by the user: ``Fc`` and ``Fs`` of the
  second stage of a two-stage fit) was not chosen by this fit and is not
  warned about.
* **residuals with structure**: a Wald–Wolfowitz runs test on the signs of
  the residuals of the fitted samples.  With ``n+`` positive and ``n-``
  negative residuals (``n`` in all) and ``R`` runs of one sign,
  ``mu = 2 n+ n- / n + 1`` and ``sigma^2 = (mu - 1)(mu - 2) / (n - 1)``;
  the fit warns when ``z = (R - mu) / sigma < RUNS_Z`` *and* the residuals'
  autocorrelation time ``tau`` (below) is at least :data:`STRUCTURE_TIME`
  samples: the residuals change sign less often than independent noise
  would (significantly), and stay alike long enough to matter (the standard
  errors, which take them for independent, are too small by ``sqrt(tau)``,
  at least ``sqrt(2)``).  The size of the pattern is judged by ``tau``, which
  weighs each residual by its square, not by the share of the runs lost: a
  wrong fit errs most near the reversals and leaves noise elsewhere, so
  its residuals keep most of the noise's runs (a LuGre fit in a wrong basin
  at 1.7 times the noise keeps 88 % of them) while ``tau`` is 10 or more.
  Residuals below ``1e-6`` of the force's RMS are not tested: such a fit is
  exact to the precision that matters.
* **a held-out error far above the in-sample one**: ``holdout_rms_error``
  above :data:`HOLDOUT_RATIO` times ``rms_error``: the model learned the
  fitted part rather than the contact.

The residuals of a friction model on a measured record are rarely
independent: what the model misses is a pattern of the force, so a residual
is much like its neighbours.  :func:`autocorrelation_time` measures how many
samples they stay alike (the integrated autocorrelation time ``tau``): the
record then holds about ``n / tau`` independent residuals.  The solver's stop
rules judge a gain in the sum of squares against ``tau`` noise variances
(:mod:`polind.identification.solver`), and the structure warning states ``tau``
with what it means for the standard errors, which are those of independent
residuals.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import signal, special

from polind.errors import ValidityWarning

__all__ = ["SLIDING_LEVEL", "BREAKAWAY_LEVEL", "RUNS_Z", "STRUCTURE_TIME", "HOLDOUT_RATIO",
           "NOISE_RATIO", "NOISE_ORDER", "NOISE_CLIP", "CORRELATION_WINDOW", "runs_test",
           "autocorrelation_time", "noise_level", "credibility_warnings"]

#: The sliding level may exceed the largest measured ``|F|`` by this factor without a warning.
SLIDING_LEVEL = 1.05
#: The break-away level may exceed the largest measured ``|F|`` by this factor and not warn.
BREAKAWAY_LEVEL = 1.5
#: The runs test's z-score below which (together with STRUCTURE_TIME) the residuals have structure.
RUNS_Z = -3.0
#: ... and the autocorrelation time [samples] from which they have.
STRUCTURE_TIME = 2.0
#: The held-out RMS error may exceed the in-sample one by this factor without a warning.
HOLDOUT_RATIO = 1.5
#: The RMS error may exceed the record's noise (:func:`noise_level`) by this factor and not warn.
NOISE_RATIO = 1.3
#: :func:`noise_level` takes divided differences over ``NOISE_ORDER + 1`` samples.
NOISE_ORDER = 3
#: :func:`noise_level` keeps the differences within this many standard deviations.
NOISE_CLIP = 3.0
# Residuals smaller than this share of the force's RMS are not tested for structure, and
# the noise estimate is at least this share of it.
_NUMERICAL = 1e-6
# The consistency factor of the median absolute deviation of a normal variable.
_MAD = 1.0 / special.ndtri(0.75)
#: :func:`autocorrelation_time` sums the autocorrelations up to the first lag ``M`` with
#: ``M >= CORRELATION_WINDOW * tau(M)`` (Sokal's automatic window).
CORRELATION_WINDOW = 5.0


def runs_test(residual) -> tuple[int, float, float]:
    """``(runs, expected, z)`` of the Wald–Wolfowitz runs test on the signs of ``residual``.

    Zero residuals are left out.  With residuals of one sign only, ``expected``
    is 1 and ``z`` is ``-inf`` when there are more than two of them (no
    change of sign at all), else 0.
    """
    signs = np.sign(np.asarray(residual, dtype=np.float64))
    signs = signs[signs != 0.0]
    n = signs.size
    if n == 0:
        return 0, 0.0, 0.0
    runs = 1 + int(np.count_nonzero(signs[1:] != signs[:-1]))
    positive = int(np.count_nonzero(signs > 0.0))
    negative = n - positive
    if positive == 0 or negative == 0:
        return runs, 1.0, -math.inf if n > 2 else 0.0
    expected = 2.0 * positive * negative / n + 1.0
    variance = (expected - 1.0) * (expected - 2.0) / (n - 1.0)
    z = (runs - expected) / math.sqrt(variance) if variance > 0.0 else 0.0
    return runs, expected, z


def autocorrelation_time(residual) -> float:
    """The integrated autocorrelation time ``tau`` of ``residual``, in samples (at least 1).

    ``tau = 1 + 2 (rho_1 + ... + rho_M)``, with ``rho_k`` the autocorrelation
    of the residuals (less their mean) at lag ``k``, summed up to the first lag
    ``M >= c tau(M)``, ``c =`` :data:`CORRELATION_WINDOW` (A. D. Sokal, *Monte
    Carlo methods in statistical mechanics*, 1997, section 3): far enough to
    take in the correlation, not so far that the noise of the estimated
    ``rho_k`` at long lags swamps it.  Independent residuals give about 1, a
    first-order autoregression of coefficient ``a`` gives ``(1 + a) / (1 - a)``.
    ``n`` residuals hold about ``n / tau`` independent ones; ``tau`` is at most
    ``n`` (all of them one), and 1 for fewer than two residuals or residuals
    all equal.
    """
    values = np.asarray(residual, dtype=np.float64)
    values = values - values.mean() if values.size else values
    if values.size < 2 or not np.any(values):
        return 1.0
    covariance = signal.correlate(values, values, mode="full", method="fft")[values.size - 1:]
    # 1 + 2 (rho_1 + ... + rho_M) for every M: the first M with M >= c tau(M) is the window.
    times = 2.0 * np.cumsum(covariance / covariance[0]) - 1.0
    windowed = np.flatnonzero(np.arange(times.size) >= CORRELATION_WINDOW * times)
    tau = times[windowed[0]] if windowed.size else times[-1]
    return float(min(max(tau, 1.0), values.size))


def noise_level(t, force) -> float:
    """The standard deviation [N] of the noise of a record, from its high-frequency part.

    The difference-based estimator: over every ``k + 1`` consecutive samples
    (``k =`` :data:`NOISE_ORDER`) the combination ``d_i = sum_j w_ij F_(i+j)``
    with ``w_i`` the weights of the ``k``-th divided difference at the times
    ``t_i .. t_(i+k)``, scaled to ``sum_j w_ij^2 = 1``.  The weights cancel
    every polynomial of degree below ``k`` in ``t``, at any spacing of the
    samples (a non-uniform ``t`` column as well as a uniform one), so a
    smooth force leaves only about ``h^k |F^(k)|`` (``h`` the time step); on
    white noise of variance ``s^2`` every ``d_i`` has variance ``s^2``,
    whatever the spacing.  With a uniform step the weights are the binomial
    coefficients ``(-1)^j C(k, j) / sqrt(C(2k, k))``.

    The scale of the ``d_i`` is robust: a first guess from their median
    absolute deviation (``1.4826`` times it: the standard deviation of a
    normal variable), then, three times over, the RMS of the ``d_i`` within
    :data:`NOISE_CLIP` guesses of their median, divided by the square root
    of the share of a normal variance left within that clip (0.973 for 3
    standard deviations).  A sharp change of the force (a friction reversal,
    the break-away of a stick-slip, a Maxwell-slip element that starts to
    slip) spoils the ``k + 1`` differences across it; they fall outside the
    clip and leave the estimate unbiased, and the clipped RMS keeps nearly
    the efficiency of a plain standard deviation (the median absolute
    deviation alone has 37 % of it).

    Assumptions, and what breaks them:

    * the noise is independent from sample to sample (white) and about
      normal.  A record filtered below its sampling rate (oversampled: its
      noise stays alike over several samples) has less noise at high
      frequency than in all: the estimate is too low, and a fit warns
      although its model is right.  Decimate such a record to its filter's
      bandwidth first.
    * the force changes little over ``k + 1`` samples compared with the
      noise, but at a few places.  A record sampled coarsely (a few samples
      per presliding rise, everywhere) gives an estimate too high, and a
      fit too far from the data may then pass without a warning.

    A record without noise (a simulation) gives the size of its ``k``-th
    differences; the estimate is at least ``1e-6`` times the force's RMS (a
    fit that close is exact to the precision that matters).  A record of at
    most ``k`` samples gives NaN.

    Parameters
    ----------
    t : array_like
        Sample times [s], strictly increasing.
    force : array_like
        The measured force [N] at ``t``.

    Returns
    -------
    float
        The noise's standard deviation [N] (a fit's ``FitResult.noise_estimate``).

    Examples
    --------
    >>> import numpy as np
    >>> from polind.identification import noise_level
    >>> t = np.linspace(0.0, 1.0, 2001)
    >>> force = np.sign(np.sin(8.0 * t)) + 0.01 * np.random.default_rng(0).standard_normal(t.size)
    >>> round(noise_level(t, force), 3)
    0.01
    """
    t = np.asarray(t, dtype=np.float64)
    force = np.asarray(force, dtype=np.float64)
    k = NOISE_ORDER
    count = force.size - k
    if count < 1:
        return math.nan
    # Times in units of the median step: the products of k differences stay near 1.
    steps = (t - t[0]) / float(np.median(np.diff(t)))
    weights = np.ones((k + 1, count))
    for j in range(k + 1):
        for other in range(k + 1):
            if other != j:
                weights[j] /= steps[j:j + count] - steps[other:other + count]
    weights /= np.sqrt(np.sum(weights ** 2, axis=0))
    differences = sum(weights[j] * force[j:j + count] for j in range(k + 1))
    differences = differences - np.median(differences)
    size = np.abs(differences)
    scale = _MAD * float(np.median(size))
    if scale == 0.0:
        # Most differences exactly 0 (a quantised or constant stretch): the plain RMS.
        scale = float(np.sqrt(np.mean(differences ** 2)))
    # The variance of a normal variable within +-c standard deviations, as a share of it.
    share = 1.0 - 2.0 * NOISE_CLIP * math.exp(-0.5 * NOISE_CLIP ** 2) / math.sqrt(2.0 * math.pi) \
        / math.erf(NOISE_CLIP / math.sqrt(2.0))
    for _ in range(3):
        kept = differences[size <= NOISE_CLIP * scale]
        if kept.size == 0:
            break
        scale = math.sqrt(float(np.mean(kept ** 2)) / share)
    return max(scale, _NUMERICAL * float(np.sqrt(np.mean(force ** 2))))


def _levels(model, data) -> tuple[float, float] | None:
    """The model's sliding and break-away levels [N] at the data's largest load, or None."""
    scales = model.characteristic_scales()
    if scales is None:
        return None
    factor = 1.0
    if data.normal_load is not None and model.constant_load > 0.0:
        factor = float(np.max(data.normal_load)) / model.constant_load
    return factor * scales["coulomb_force"], factor * scales["static_force"]


def _chosen(levels, data, neighbours) -> tuple[bool, bool]:
    """Whether the fit chose the sliding and the break-away level: whether a free value moves
    it (``neighbours()``: the model with each free value moved a little, None where that
    makes no model; None: every level is chosen)."""
    if neighbours is None:
        return True, True
    chosen = [False, False]
    with warnings.catch_warnings():
        # A neighbour's validity is no news (the fitted model's own warning is given once).
        warnings.simplefilter("ignore", ValidityWarning)
        for other in neighbours():
            moved = None if other is None else _levels(other, data)
            for index in range(2):
                chosen[index] |= moved is None or moved[index] != levels[index]
    return chosen[0], chosen[1]


def credibility_warnings(model, data, residual, held_out=None, *, noise=None, neighbours=None,
                         starts=1) -> list[str]:
    """The warnings of the module docstring for a fitted ``model``.

    ``data`` the fitted samples (:class:`~polind.identification.MeasuredData`),
    ``residual`` the fitted model's force minus the measured one on them,
    ``held_out`` the RMS error on the held-out samples (None without),
    ``noise`` the record's noise (default: :func:`noise_level` of ``data``),
    ``neighbours`` a callable that returns the model with each free value
    moved a little (``fit_result`` of :mod:`polind.identification.results` passes it: a
    force level that none of them moves was fixed by the user and is not
    warned about; None: every level counts as fitted), ``starts`` the number
    of starts the fit tried (the warning on the noise suggests twice as many).
    """
    notes = []
    rms = float(np.sqrt(np.mean(residual ** 2)))
    exact = rms <= _NUMERICAL * float(np.sqrt(np.mean(data.force ** 2)))
    noise = noise_level(data.t, data.force) if noise is None else noise
    if not exact and rms > NOISE_RATIO * noise:
        more = max(8, 2 * int(starts))
        notes.append(f"The fit is {rms / noise:.3g} times the record's noise: the model or the "
                     f"search may be wrong; try --starts {more} (starts={more} in Python). The "
                     f"RMS error of the fitted {model.type} model is {rms:.4g} N, the noise "
                     f"estimated from the record's high-frequency part {noise:.4g} N (warned "
                     f"above {NOISE_RATIO:g} times).")
    largest = data.scale
    levels = _levels(model, data)
    if levels is not None:
        high = [level > factor * largest
                for level, factor in zip(levels, (SLIDING_LEVEL, BREAKAWAY_LEVEL))]
        chosen = _chosen(levels, data, neighbours) if any(high) else (False, False)
        for name, level, factor, warned in (("sliding", levels[0], SLIDING_LEVEL,
                                             high[0] and chosen[0]),
                                            ("break-away", levels[1], BREAKAWAY_LEVEL,
                                             high[1] and chosen[1])):
            if warned:
                notes.append(f"The {name} force level of the fitted {model.type} model, "
                             f"{level:.4g} N, is {level / largest:.3g} times the largest "
                             f"measured |F| ({largest:.4g} N; warned above {factor:g} times): "
                             "the data did not choose it. Bound the force levels, or fit "
                             "data that reach them.")
    if not exact:
        runs, expected, z = runs_test(residual)
        tau = autocorrelation_time(residual) if z < RUNS_Z else 1.0
        if z < RUNS_Z and tau >= STRUCTURE_TIME:
            notes.append(f"The residuals of the fitted {model.type} model have structure: "
                         f"their signs change {runs - 1} times where independent noise "
                         f"would change about {expected - 1:.0f} times (runs test z = "
                         f"{z:.3g}; warned below {RUNS_Z:g}), and they stay alike over about "
                         f"{tau:.3g} samples (their autocorrelation time; warned from "
                         f"{STRUCTURE_TIME:g}): the model misses a pattern of the force, or "
                         "the record's noise is itself correlated. The standard errors, which "
                         "take the residuals for independent, are too small by about the "
                         "square root of that time.")
    if held_out is not None and held_out > HOLDOUT_RATIO * rms:
        ratio = held_out / rms if rms > 0.0 else math.inf
        notes.append(f"The held-out RMS error of the fitted {model.type} model, "
                     f"{held_out:.4g} N, is {ratio:.3g} times the in-sample one "
                     f"({rms:.4g} N; warned above {HOLDOUT_RATIO:g} times): it does not "
                     "predict what it was not fitted to.")
    return notes
