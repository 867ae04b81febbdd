"""The solver of :func:`identify`: bounded nonlinear least squares from several starts.

``scipy.optimize.least_squares`` (trust-region-reflective) on the
optimiser's variables of :mod:`polind.identification.parameters`, from each
starting point of :mod:`polind.identification.starts`; the fit with the
smallest sum of squares in sample is kept.  The Jacobian is taken by forward
differences of a fixed step in these variables.  Where one simulation of the
data takes long enough for threads to pay (:data:`~polind.identification.threads.THREADED_SIMULATION`),
the starts run side by side on threads, and each start's Jacobian columns
too (the numba kernels release the GIL).  Neither changes a result: each
start's fit is the same computation on any thread.  A trial point whose
parameters the model rejects (a load its surface cannot carry, say) or where
its force is not finite costs a large constant residual, so the solver backs
off instead of stopping.

A free value whose Jacobian column is zero at a start (a unit change of its
variable, a factor e of a log-scaled parameter, moves the force by less than
:data:`STILL_COLUMN` of the measured force's norm) cannot move the residual
there: it is fixed at that start and not iterated on, and the result reports
it as not identifiable.

A start stops when an iteration lowers the sum of squares by less than
:data:`NOISE_SHARE` of the noise variance ``tau s^2`` (``s^2 = RSS / (n - p)``,
``tau`` the residuals' :func:`~polind.identification.credibility.autocorrelation_time`
at the point reached: :ref:`guide-identification-method`): what is left to
gain is below what the data can tell apart, and on a long record the default
``tolerance`` alone would iterate on it.  The solver's ``ftol`` is at least
``NOISE_SHARE / (n - p)``, but SciPy applies it only to a step its model of
the sum of squares predicted well, and a friction model's residual has kinks
(an element that sticks or slips one sample earlier), so the rule is also
checked after each accepted iteration.

A start also stops when an accepted step ``d`` is too small for the data to
see, ``|J d|^2 < STEP_SHARE tau s^2`` (:data:`STEP_SHARE`; ``J`` the Jacobian
it was taken from), and gained less than ``tau s^2``.  On a smooth sum of squares the two
rules end a fit together (near the minimum a step gains ``|J d|^2``); on a
rough one (a spring's solve passing from stick to slip a sample earlier) the
trust region shrinks below the data's resolution while jumps still lower the
sum of squares now and then: this rule ends the start there.

Both rules are judged when the solver asks for the Jacobian at the accepted
point; a start they stop does not take it (the fit kept takes it afterwards,
for its standard errors: the same computation at the same point).

The threads, and the single BLAS thread of the solver's matrix products:
:mod:`polind.identification.threads`.
"""

from __future__ import annotations

import math
import threading
import time
import warnings
from dataclasses import dataclass, replace

import numpy as np

from polind.errors import InputError, ValidityWarning
from polind.identification.credibility import autocorrelation_time
from polind.identification.data import MeasuredData, holdout_split, measured_data
from polind.identification.memory import fit_bytes_per_sample
from polind.identification.parameters import build_free, model_at, param_value, parse_fit
from polind.identification.results import FitResult, fit_result
from polind.identification.starts import (DEFAULT_SPREAD_STARTS, check_extra_starts,
                                          check_starts, starting_points)
from polind.identification.threads import (one_blas_thread, simulation_seconds, start_threads,
                                           worker_count)
from polind.resources import check_memory
from polind.validation import check_number

__all__ = ["NOISE_SHARE", "STEP_SHARE", "STILL_COLUMN", "identify"]

#: A Jacobian column whose norm is at most this share of the measured force's norm is
#: zero: its free value cannot move the residual (it is fixed at its start).
STILL_COLUMN = 1e-8
#: A start stops when an iteration lowers the sum of squares by less than this share of
#: the noise variance ``tau RSS / (n - p)`` (module docstring): a free value moves then by
#: about a tenth of its standard error at most.
NOISE_SHARE = 1e-2
#: The solver's message of a start stopped by :data:`NOISE_SHARE` in the callback.
NOISE_STOP = ("an iteration lowered the sum of squares by less than a hundredth of the noise "
              "variance")
#: A start stops when an accepted step ``d`` moves the linearised force by ``|J d|^2``
#: below this share of the noise variance ``tau RSS / (n - p)`` (and gained less than
#: one): the free values moved by less than a tenth of a standard error.
STEP_SHARE = 1e-2
#: The solver's message of a start stopped by the step rule (module docstring).
STEP_STOP = ("an iteration's step moved the force by less than a tenth of the noise (a tenth "
             "of a standard error)")


@dataclass(frozen=True)
class _Settings:
    """The solver's options, the same for every start."""

    max_evaluations: int | None
    tolerance: float
    diff_step: float
    x_scale: object
    workers: int | None


class _Counter:
    """The simulations of a whole identification (every start), and the caller's callback."""

    def __init__(self, callback):
        self.callback = callback
        self.evaluations = 0
        self.lock = threading.Lock()

    def count(self, residual) -> None:
        with self.lock:
            self.evaluations += 1
            if self.callback is not None:
                rms = math.inf if residual is None else float(np.sqrt(np.mean(residual ** 2)))
                self.callback(self.evaluations, rms)


@dataclass
class _LocalFit:
    """The solution of one start."""

    label: str
    u: np.ndarray
    rss: float
    jac: np.ndarray | None   # at u, a zero column for each fixed variable; None: not taken
    residual: np.ndarray     # at u
    iterations: int
    success: bool
    message: str
    fixed: np.ndarray        # bool per variable: fixed at the start (zero column there)


class _Problem:
    """The least-squares problem of one model on the fitted samples, solved from any start."""

    def __init__(self, start, frees, measured: MeasuredData, settings: _Settings,
                 counter: _Counter, column_threads: int | None = None):
        self.start, self.frees, self.measured = start, frees, measured
        self.settings, self.counter = settings, counter
        parts = [free.internal_bounds() for free in frees]
        self.low = np.concatenate([low for low, _ in parts]) if parts else np.empty(0)
        self.high = np.concatenate([high for _, high in parts]) if parts else np.empty(0)
        # What a trial point the model rejects (e.g. a load its surface cannot carry) or
        # where it blows up costs: far more than any sensible fit, so the solver backs off.
        self.penalty = 10.0 * measured.scale
        self.still = STILL_COLUMN * float(np.linalg.norm(measured.force))
        self.threads = None
        self.pool = None
        if column_threads is not None:
            self._threads_for(min(column_threads, max(self.low.size, 1)))
        elif settings.workers is not None:
            self._threads_for(worker_count(settings.workers, self.low.size, math.inf))

    def _threads_for(self, count):
        self.threads = count
        if count > 1:
            from concurrent.futures import ThreadPoolExecutor
            self.pool = ThreadPoolExecutor(max_workers=count, thread_name_prefix="polind-fit")

    def close(self):
        if self.pool is not None:
            self.pool.shutdown()

    def evaluate(self, u):
        """The residual at u, or None where the parameters make no valid model."""
        try:
            force = self.measured.simulate(model_at(self.start, self.frees, u))
        except InputError:
            residual = None
        else:
            residual = force - self.measured.force
            if not np.all(np.isfinite(residual)):
                residual = None
        self.counter.count(residual)
        return residual

    def jacobian(self, u, base, columns) -> np.ndarray:
        """Forward differences with a fixed step in the variables (backward at an upper
        bound or where the forward point is invalid) of the given columns, on threads."""
        step = self.settings.diff_step

        def column(j):
            forward = step if u[j] + step <= self.high[j] else -step
            for trial in (forward, -forward):
                moved = u.copy()
                moved[j] += trial
                residual = self.evaluate(moved)
                if residual is not None:
                    return (residual - base) / trial
            return np.zeros(base.size)

        columns = list(columns)
        out = []
        if self.threads is None and columns:
            # The first column, timed, decides how many threads the others get.
            clock = time.perf_counter()
            out.append(column(columns.pop(0)))
            self._threads_for(worker_count(None, self.low.size, time.perf_counter() - clock))
        out += self.pool.map(column, columns) if self.pool is not None else map(column, columns)
        return np.column_stack(out) if out else np.zeros((base.size, 0))

    def solve(self, label: str, u0: np.ndarray) -> _LocalFit | None:
        """The fit from ``u0`` (None if the model rejects that start).

        The values whose Jacobian column is zero at ``u0`` are fixed there.  Where
        the solution has given one of them a column again (GMS's Stribeck velocity
        once a start with ``Fs = Fc`` has moved them apart), the fit goes on from
        the solution with it free (once).  ``jac`` is None where a stop rule ended
        the fit before taking it (:meth:`complete`)."""
        base = self.evaluate(u0)
        if base is None:
            return None
        first = self.jacobian(u0, base, range(u0.size))
        fixed = np.linalg.norm(first, axis=0) <= self.still
        if fixed.all():
            return _LocalFit(label, u0, float(base @ base), first, base, 0, True,
                             "no free value moves the force", fixed)
        u, residual, jac, iterations, success, message = self._solve_active(
            u0, base, np.flatnonzero(~fixed), first[:, ~fixed])
        if fixed.any() and not fixed.all():
            still = np.flatnonzero(fixed)
            revived = np.linalg.norm(self.jacobian(u, residual, still), axis=0) > self.still
            if revived.any():
                fixed[still[revived]] = False
                u, residual, jac, more, success, message = self._solve_active(
                    u, residual, np.flatnonzero(~fixed), None)
                iterations += more
        full = None
        if jac is not None:
            full = np.zeros((base.size, u0.size))
            full[:, ~fixed] = jac
        return _LocalFit(label, u, float(residual @ residual), full, residual, iterations,
                         success, message, fixed)

    def complete(self, local: _LocalFit) -> _LocalFit:
        """``local`` with its Jacobian at its solution (taken now if a stop rule skipped it)."""
        if local.jac is not None:
            return local
        active = np.flatnonzero(~local.fixed)
        full = np.zeros((local.residual.size, local.u.size))
        full[:, active] = self.jacobian(local.u, local.residual, active)
        return replace(local, jac=full)

    def cost_tolerance(self, varied: int) -> float:
        """The solver's ``ftol`` with ``varied`` values varied: the ``tolerance``, or a
        change of the sum of squares by :data:`NOISE_SHARE` of the noise variance
        (``ftol`` is relative to the sum of squares, ``(n - p)`` noise variances)."""
        return max(self.settings.tolerance,
                   NOISE_SHARE / max(self.measured.size - varied, 1))

    def _solve_active(self, u0, base, active, first):
        """``least_squares`` over the variables ``active`` from ``u0`` (residual ``base``;
        ``first``: the Jacobian's active columns there, or None).  Returns ``(u, residual,
        jac, iterations, success, message)``."""
        from scipy.optimize import least_squares

        # The solver's variables are 1 + u (u = u0 at the start): its first trust radius is
        # |x0|, and x0 stays away from 0 where scipy's relative steps would vanish.
        x0 = u0[active] + 1.0
        last = {"x": x0.copy(), "residual": base}
        pending = {"jac": first}                 # the Jacobian at x0, if computed already

        def unpack(x):
            u = u0.copy()
            u[active] = x - 1.0
            return u

        def residuals(x):
            if np.array_equal(last["x"], x):
                return last["residual"]
            residual = self.evaluate(unpack(x))
            if residual is None:
                residual = np.full(self.measured.size, self.penalty)
            last["x"], last["residual"] = x.copy(), residual
            return residual

        accepted = {"rss": float(base @ base), "x": x0, "jac": first}   # the last accepted point
        stop = {}

        def jacobian(x):
            known = pending.pop("jac", None)
            if known is not None and np.array_equal(x, x0):
                return known
            residual = residuals(x)
            if accepted["jac"] is not None and not np.array_equal(x, x0):
                # x was just accepted (SciPy asks for the Jacobian there once, next): the
                # stop rules are judged first, and a start they end does not take it.
                stop["message"] = self._stop_rule(accepted, x, residual, active.size)
                if stop["message"] is not None:
                    stop["skipped"] = True
                    return accepted["jac"]       # not used: the callback ends the fit
            jac = self.jacobian(unpack(x), residual, active)
            accepted.update(rss=float(residual @ residual), x=x.copy(), jac=jac)
            return jac

        def end(intermediate_result):
            """Stop (StopIteration) where a stop rule ended the fit (SciPy passes the
            iteration's result to a parameter of this name)."""
            if stop.get("message") is not None:
                raise StopIteration

        settings = self.settings
        solution = least_squares(residuals, x0, jac=jacobian,
                                 bounds=(self.low[active] + 1.0, self.high[active] + 1.0),
                                 method="trf", x_scale=settings.x_scale,
                                 ftol=self.cost_tolerance(active.size),
                                 xtol=settings.tolerance,
                                 gtol=settings.tolerance, max_nfev=settings.max_evaluations,
                                 callback=end)
        stopped = solution.status == -2             # by a stop rule: at the noise floor
        jac = None if stop.get("skipped") else solution.jac
        return (unpack(solution.x), solution.fun, jac, int(solution.njev or 0),
                stopped or solution.status > 0,
                stop["message"] if stopped else str(solution.message))

    def _stop_rule(self, accepted, x, residual, varied: int) -> str | None:
        """The message of the stop rule (module docstring) that ends a fit at ``x``
        (``residual``), accepted after ``accepted`` (``rss``, ``x``, ``jac``); else None."""
        rss = float(residual @ residual)
        decrease = accepted["rss"] - rss
        dof = max(self.measured.size - varied, 1)
        noise = rss / dof * min(autocorrelation_time(residual), dof)
        if 0.0 < decrease < NOISE_SHARE * noise:
            return NOISE_STOP
        moved = accepted["jac"] @ (x - accepted["x"])
        if 0.0 < decrease < noise and float(moved @ moved) < STEP_SHARE * noise:
            return STEP_STOP
        return None


def _fit_from_starts(start, keys, bounds, frees, measured, settings, counter, *, starts,
                     spread, extra_starts, special_cases, pool=None, threads=1,
                     jacobian=True) -> list[_LocalFit]:
    """The local fits from every starting point (:mod:`polind.identification.starts`).

    With ``jacobian`` the fit with the smallest sum of squares (the first of
    equals) has its Jacobian at its solution (:meth:`_Problem.complete`); the
    others may not.

    With a ``pool`` of ``threads`` threads the starts run side by side on it,
    and each start's Jacobian columns on as many threads again (a start left alone at
    the end keeps every core busy; while several run, the system shares the
    cores among their threads); the fits come back in the order of the starts.
    The starting points are made here, on the calling thread: the fit of a
    special case (which runs its own starts on the same pool) happens when its
    start is reached, while the starts before it run.
    """
    def fit_special_case(case):
        return _special_case_fit(case, bounds, measured, settings, counter, pool, threads)

    problem = _Problem(start, frees, measured, settings, counter,
                       column_threads=None if pool is None else threads)
    fits = []
    pending = []
    try:
        for label, u0 in starting_points(
                start, keys, frees, measured, starts=starts, spread=spread,
                extra_starts=extra_starts,
                fit_special_case=fit_special_case if special_cases else None):
            if pool is None:
                fits.append(problem.solve(label, u0))
            else:
                pending.append(pool.submit(problem.solve, label, u0))
        fits += [future.result() for future in pending]
        fits = [local for local in fits if local is not None]
        if fits and jacobian:
            best = min(range(len(fits)), key=lambda index: fits[index].rss)
            fits[best] = problem.complete(fits[best])
    finally:
        for future in pending:
            future.cancel()
        problem.close()
    return fits


def _special_case_fit(case, bounds, measured, settings, counter, pool=None, threads=1):
    """The fitted contained model of a special case, or None where it cannot be fitted.

    Its free keys are ``case.free``; it keeps the containing fit's bounds of
    the keys of the same name that hold its start; it starts from its own
    values and structured starts (no spread points, no special case of its own).
    """
    params = case.model.params
    carried = {}
    for key, (low, high) in bounds.items():
        if key in case.free:
            value = np.atleast_1d(np.asarray(param_value(params, key), dtype=np.float64))
            if np.all((value >= low) & (value <= high)):
                carried[key] = [low, high]
    try:
        start, keys, given = parse_fit(case.model, free=list(case.free), bounds=carried)
        frees = build_free(start, keys, given, measured, [])
        if not np.all(np.isfinite(measured.simulate(start))):
            return None
    except InputError:
        return None
    fits = _fit_from_starts(start, keys, given, frees, measured, settings, counter,
                            starts=None, spread=0, extra_starts=None, special_cases=False,
                            pool=pool, threads=threads, jacobian=False)
    if not fits:
        return None
    best = min(fits, key=lambda local: local.rss)
    return model_at(start, frees, best.u)


def identify(model, data, *, free=None, bounds=None, holdout=None, starts=None,
             extra_starts=None, max_evaluations=None, tolerance=1e-8, diff_step=1e-6,
             x_scale=1.0, callback=None, workers=None) -> FitResult:
    """Identify free parameters of a friction model from measured force.

    Bounded nonlinear least squares on ``F_model(t; p) - F_measured``
    (``scipy.optimize.least_squares``, trust-region-reflective, Jacobian by
    forward differences), started from the model's current values.  The
    simulation starts from rest (all internal states zero) at the first
    sample, so the record should start with the contact at rest or
    its first sliding stroke will take a transient to forget the start.

    Parameters
    ----------
    model : FrictionModel or dict
        The starting point: a model, or a model document ``{"model": {...},
        "fit": {"free": [...], "bounds": {...}}}`` as read from a model file
        (:func:`polind.io.read_model_file`).
    data : mapping of str to array_like, or a pandas DataFrame
        ``t`` [s] strictly increasing, exactly one of ``x`` [m] and ``v``
        [m/s], ``F`` [N] the measured friction force (positive when it resists
        positive motion), optionally ``normal_load`` [N] (a positive load at
        every sample).  A model that ignores a normal load (one without
        ``reference_load``, except pol-ind) is fitted without the column,
        with a warning.  A data frame (anything with ``columns`` that is not
        a mapping; pandas is not imported) may hold other columns too: they
        are not used and the warnings name them.  A mapping must hold the
        data columns only.
    free : list of str, optional
        Keys to identify, dotted for nested keys (``"surface.height_std"``,
        ``"compliance.stiffness"``); a list-valued key (``stiffness``) is free
        as a whole vector.  Default: the document's ``[fit] free``; without
        one (a bare model, or no ``free`` in ``[fit]``), the model's own
        ``fit_defaults`` (:class:`polind.FrictionModel`).
    bounds : dict, optional
        Per free key ``[low, high]`` in the parameter's unit (one pair for all
        entries of a list key).  Default: the document's ``[fit.bounds]``; a
        free key without bounds gets the default bounds derived from the
        data by its unit (:func:`~polind.identification.default_bounds`), never an unbounded range.
    holdout : float, optional
        A fraction ``F`` in (0, 1): fit the first ``round((1 - F) n)`` of the
        ``n`` samples (the earliest: ``t`` increases) and report the RMS error
        on the rest as ``holdout_rms_error``.  The held-out prediction
        continues the fitted part: the fitted model is simulated over the
        whole record from rest, one run, and its tail is scored (not a run
        restarted from rest at the split).  The default bounds come from the
        fitted part only.
    starts : int, optional
        The number of starting points (``polind fit --starts N``): the
        model's values first, then the ``extra_starts``, the fitted special
        case, the structured starts, and Latin-hypercube points in the
        bounds to make up ``N``.  ``starts=1`` fits from the model's values
        only.  Default: all of the model's own starts and 2 spread points
        (:ref:`guide-fit-starts`).  The result's
        ``start_label`` names the start of the fit kept and ``starts`` what
        each reached.
    extra_starts : mapping of str to FrictionModel, optional
        More starting models, labelled (tried after the model's values);
        only their free keys are used.  :func:`polind.compare` passes the
        fitted models of the other rows that this model contains.
    max_evaluations : int, optional
        Most solver function evaluations per start (``max_nfev``; default
        ``100 * number of variables``).
    tolerance : float
        ``ftol`` and ``xtol`` of the solver (relative change of the cost and
        of the variables); ``ftol`` is at least ``NOISE_SHARE / (n - p)``
        (:data:`polind.identification.NOISE_SHARE`): an iteration
        that lowers the sum of squares of ``n`` samples with ``p`` free values
        by less than a hundredth of the noise variance ``RSS / (n - p)`` ends
        the fit.
    diff_step : float
        Step of the forward-difference Jacobian in the optimiser's variables:
        a log-scaled parameter moves by ``diff_step`` relatively, a linear one
        by ``diff_step`` times its scale.
    x_scale : float or "jac"
        The solver's variable scaling (``least_squares``'s ``x_scale``); the
        default 1 trusts the parametrisation above (one unit of each variable
        is a factor e, or one scale, of its parameter).
    callback : callable, optional
        Called as ``callback(evaluations, rms_error)`` after each simulation
        (e.g. to drive a progress bar; calls are serialised, but may come
        from worker threads); ``rms_error`` is ``inf`` at a trial point
        whose parameters the model rejects (such points cost the solver a
        large constant residual, so it backs off).
    workers : int, optional
        Threads that run the fit's starts side by side, and each start's
        finite-difference Jacobian columns (the numba kernels release the
        GIL).  Default: the number of cores when
        one simulation of the data takes more than 5 ms (a long record,
        Pol-Ind under a varying load); one thread for quicker ones, where the
        threads' overhead and the BLAS's own threads eat the gain.  The
        result does not depend on it.

    Returns
    -------
    FitResult
        Its ``warnings`` (:ref:`guide-fit-warnings`) are also issued as
        ``UserWarning``: a parameter at a bound or not identifiable, a force
        level beyond the data, residuals with structure, a held-out error
        far above the in-sample one, ...

    Raises
    ------
    InputError
        Bad data (too few samples, fewer than free values + 1, no motion, a
        constant force, NaN, non-increasing ``t``), a bad ``holdout`` or
        ``starts``, or a
        bad ``[fit]`` (unknown or non-numeric free key, a free key without a
        starting value, bounds for a key that is not free, low >= high,
        bounds that exclude the starting value), naming the key or column;
        a fit whose estimated memory (``fit_bytes_per_sample`` times the
        samples) passes the limit of :mod:`polind.resources`.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import identify
    >>> true = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                          "coulomb_force": 1.0}})
    >>> t = np.linspace(0.0, 2.0, 201)
    >>> x = 1e-4 * np.sin(np.pi * t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    >>> start = true.with_params(stiffness=3e4, coulomb_force=2.0)
    >>> fit = identify(start, data, free=["stiffness", "coulomb_force"])
    >>> round(fit.values["stiffness"]), round(fit.values["coulomb_force"], 6)
    (100000, 1.0)
    >>> fit.warnings
    ()
    >>> fit.start_label in [label for label, rms in fit.starts]
    True
    """
    max_evaluations = None if max_evaluations is None else check_number(
        "identify", "max_evaluations", max_evaluations, "positive", integer=True)
    tolerance = check_number("identify", "tolerance", tolerance, "positive")
    if tolerance < 1e-15:
        raise InputError(f"The 'tolerance' parameter of identify must be at least 1e-15 (above "
                         f"machine precision). Got {tolerance!r} instead.")
    diff_step = check_number("identify", "diff_step", diff_step, "positive")
    if diff_step >= 1.0:
        raise InputError(f"The 'diff_step' parameter of identify must be below 1 (a relative "
                         f"step). Got {diff_step!r} instead.")
    starts = check_starts(starts)
    start, keys, given_bounds = parse_fit(model, free=free, bounds=bounds)
    notes = []
    record = measured_data(data, model=start, notes=notes)
    fitted_samples = holdout_split(holdout, record.size)
    measured = record if fitted_samples is None else record.head(fitted_samples)
    frees = build_free(start, keys, given_bounds, measured, notes)
    n_variables = sum(f.size for f in frees)
    check_memory(record.size * fit_bytes_per_sample(start, keys),
                 f"Fitting {n_variables} free values to {record.size:.3g} samples of data")
    if measured.size <= n_variables:
        raise InputError(f"Identification of {n_variables} parameter values needs more samples "
                         f"than that. Got {measured.size} samples of 't'"
                         + ("." if fitted_samples is None else " in the fitted part."))
    settings = _Settings(max_evaluations, tolerance, diff_step, x_scale, workers)
    counter = _Counter(callback)
    with one_blas_thread():
        seconds = simulation_seconds(start, measured, retime=starts != 1 and workers is None)
        threads = start_threads(workers, starts, seconds)
        pool = None
        if threads > 1:
            from concurrent.futures import ThreadPoolExecutor
            pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="polind-fit")
        try:
            with warnings.catch_warnings():
                # A trial model's validity is no news (a fit tries hundreds): the fitted model's
                # own warning, if it has one, is given once below.
                warnings.simplefilter("ignore", ValidityWarning)
                fits = _fit_from_starts(start, keys, given_bounds, frees, measured, settings,
                                        counter, starts=starts, spread=DEFAULT_SPREAD_STARTS,
                                        extra_starts=check_extra_starts(extra_starts, start),
                                        special_cases=True, pool=pool, threads=threads)
        finally:
            if pool is not None:
                pool.shutdown(cancel_futures=True)
        best = min(fits, key=lambda local: local.rss)        # the first of equals: the earliest
        fitted = model_at(start, frees, best.u)
        force = measured.simulate(fitted)
        tried = [(local.label, math.sqrt(local.rss / measured.size)) for local in fits]
        if n_variables == 0:
            result = fit_result(start, start, frees, np.zeros(0), given_bounds, force, measured, 0,
                                counter.evaluations, True, "nothing to identify", notes=notes,
                                record=None if fitted_samples is None else record,
                                start_label=best.label, starts=tried)
        else:
            result = fit_result(fitted, start, frees, best.u, given_bounds, force, measured,
                                best.iterations, counter.evaluations, best.success, best.message,
                                jac=best.jac, notes=notes,
                                record=None if fitted_samples is None else record,
                                fixed=best.fixed, start_label=best.label, starts=tried)
    for note in result.warnings:
        warnings.warn(note, UserWarning, stacklevel=2)
    return result
