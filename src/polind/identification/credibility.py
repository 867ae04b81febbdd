"""Whether a fit's result is credible: the warnings on the fit as a whole.

The user guide, :ref:`guide-fit-warnings`.  Besides the warnings on single
parameters (:mod:`polind.identification.results`), every fit is checked for
three signs that its result should not be trusted:

* **a force level beyond the data**: the model's sliding level (the
  ``coulomb_force`` of its characteristic scales: ``Fc``, ``sum W`` of
  Maxwell-slip, ``mu_k N`` of Pol-Ind) above :data:`SLIDING_LEVEL` times the
  largest measured ``|F|``, or its break-away level (``Fs``, ``sum W``,
  ``mu_s N``) above :data:`BREAKAWAY_LEVEL` times it.  Steady sliding shows
  the sliding level in every record that slides, so a sliding level above
  every measured force is one the data did not choose; a break-away level
  is reached only in the limit of slow steady sliding, and a dynamic
  break-away falls short of it, hence the wider margin.  Under a measured
  normal load the levels are taken at its largest value.
* **residuals with structure**: a Wald–Wolfowitz runs test on the signs of
  the residuals of the fitted samples.  With ``n+`` positive and ``n-``
  negative residuals (``n`` in all) and ``R`` runs of one sign,
  ``mu = 2 n+ n- / n + 1`` and ``sigma^2 = (mu - 1)(mu - 2) / (n - 1)``;
  the fit warns when ``z = (R - mu) / sigma < RUNS_Z`` *and* ``R <
  RUNS_SHARE * mu``: the residuals change sign far less often than
  independent noise would, so the model misses a pattern of the force (the
  second condition keeps a long record's small, significant but harmless
  correlations quiet).  Residuals below ``1e-6`` of the force's RMS are not
  tested: such a fit is exact to the precision that matters.
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

import numpy as np
from scipy import signal

__all__ = ["SLIDING_LEVEL", "BREAKAWAY_LEVEL", "RUNS_Z", "RUNS_SHARE", "HOLDOUT_RATIO",
           "CORRELATION_WINDOW", "runs_test", "autocorrelation_time", "credibility_warnings"]

#: The sliding level may exceed the largest measured ``|F|`` by this factor without a warning.
SLIDING_LEVEL = 1.05
#: The break-away level may exceed the largest measured ``|F|`` by this factor and not warn.
BREAKAWAY_LEVEL = 1.5
#: The runs test's z-score below which (together with RUNS_SHARE) the residuals have structure.
RUNS_Z = -3.0
#: ... and the share of the expected number of runs below which they have.
RUNS_SHARE = 0.5
#: The held-out RMS error may exceed the in-sample one by this factor without a warning.
HOLDOUT_RATIO = 1.5
# Residuals smaller than this share of the force's RMS are not tested for structure.
_NUMERICAL = 1e-6
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


def _levels(model, data) -> tuple[float, float] | None:
    """The model's sliding and break-away levels [N] at the data's largest load, or None."""
    scales = model.characteristic_scales()
    if scales is None:
        return None
    factor = 1.0
    if data.normal_load is not None and model.constant_load > 0.0:
        factor = float(np.max(data.normal_load)) / model.constant_load
    return factor * scales["coulomb_force"], factor * scales["static_force"]


def credibility_warnings(model, data, residual, held_out=None) -> list[str]:
    """The warnings of the module docstring for a fitted ``model``.

    ``data`` the fitted samples (:class:`~polind.identification.MeasuredData`),
    ``residual`` the fitted model's force minus the measured one on them,
    ``held_out`` the RMS error on the held-out samples (None without).
    """
    notes = []
    largest = data.scale
    levels = _levels(model, data)
    if levels is not None:
        for name, level, factor in (("sliding", levels[0], SLIDING_LEVEL),
                                    ("break-away", levels[1], BREAKAWAY_LEVEL)):
            if level > factor * largest:
                notes.append(f"The {name} force level of the fitted {model.type} model, "
                             f"{level:.4g} N, is {level / largest:.3g} times the largest "
                             f"measured |F| ({largest:.4g} N; warned above {factor:g} times): "
                             "the data did not choose it. Bound the force levels, or fit "
                             "data that reach them.")
    rms = float(np.sqrt(np.mean(residual ** 2)))
    if rms > _NUMERICAL * float(np.sqrt(np.mean(data.force ** 2))):
        runs, expected, z = runs_test(residual)
        if z < RUNS_Z and runs < RUNS_SHARE * expected:
            notes.append(f"The residuals of the fitted {model.type} model have structure: "
                         f"their signs change {runs - 1} times where independent noise "
                         f"would change about {expected - 1:.0f} times (runs test z = "
                         f"{z:.3g}; warned below {RUNS_Z:g} with fewer than "
                         f"{RUNS_SHARE:g} of the expected runs): the model misses a pattern "
                         f"of the force. They stay alike over about "
                         f"{autocorrelation_time(residual):.3g} samples (their autocorrelation "
                         "time), and the standard errors, which take them for independent, "
                         "are too small by about its square root.")
    if held_out is not None and held_out > HOLDOUT_RATIO * rms:
        ratio = held_out / rms if rms > 0.0 else math.inf
        notes.append(f"The held-out RMS error of the fitted {model.type} model, "
                     f"{held_out:.4g} N, is {ratio:.3g} times the in-sample one "
                     f"({rms:.4g} N; warned above {HOLDOUT_RATIO:g} times): it does not "
                     "predict what it was not fitted to.")
    return notes
