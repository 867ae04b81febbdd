"""The solver of :func:`identify`: bounded nonlinear least squares on the simulated force.

``scipy.optimize.least_squares`` (trust-region-reflective) on the
optimiser's variables of :mod:`polind.identification.parameters`.  The
Jacobian is taken by forward differences of a fixed step in these
variables, its columns simulated side by side on threads (the numba kernels
release the GIL).  A trial point whose parameters the model rejects (a load
its surface cannot carry, say) or where its force is not finite costs a
large constant residual, so the solver backs off instead of stopping.
"""

from __future__ import annotations

import math
import os
import threading
import time
import warnings

import numpy as np

from polind.errors import InputError
from polind.identification.data import holdout_split, measured_data
from polind.identification.memory import fit_bytes_per_sample
from polind.identification.parameters import build_free, model_at, parse_fit
from polind.identification.results import FitResult, fit_result
from polind.resources import check_memory
from polind.validation import check_number, describe

__all__ = ["identify"]

#: A simulation of the data shorter than this [s] runs the Jacobian on one thread by
#: default: the threads' overhead, and their contention with the BLAS's own threads
#: (which spin between the solver's matrix products), eat the gain.
_THREADED_SIMULATION = 5e-3


def _worker_count(workers, columns: int, seconds: float) -> int:
    """Threads for the Jacobian's columns (``seconds``: one simulation of the data)."""
    if workers is None:
        if seconds < _THREADED_SIMULATION:
            return 1
        return max(1, min(os.cpu_count() or 1, columns))
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise InputError(f"The number of 'workers' must be a positive integer. Got "
                         f"{describe(workers)} instead.")
    return int(min(workers, max(columns, 1)))


def identify(model, data, *, free=None, bounds=None, holdout=None, max_evaluations=None,
             tolerance=1e-8, diff_step=1e-6, x_scale=1.0, callback=None,
             workers=None) -> FitResult:
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
    max_evaluations : int, optional
        Most solver function evaluations (``max_nfev``; default
        ``100 * number of variables``).
    tolerance : float
        ``ftol`` and ``xtol`` of the solver (relative change of the cost and
        of the variables).
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
        Threads that simulate the columns of the finite-difference Jacobian
        side by side (the numba kernels release the GIL).  Default: the
        number of cores, at most one per column, when one simulation of the
        data takes more than 5 ms (a long record, Pol-Ind under a varying
        load); one thread for quicker ones, where the threads' overhead and
        the BLAS's own threads eat the gain.  The result does not depend on
        it.

    Returns
    -------
    FitResult
        Its ``warnings`` are also issued as ``UserWarning``.

    Raises
    ------
    InputError
        Bad data (too few samples, fewer than free values + 1, no motion, a
        constant force, NaN, non-increasing ``t``), a bad ``holdout``, or a
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
    """
    from scipy.optimize import least_squares

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
    low, high = (np.concatenate(parts) if parts else np.empty(0)
                 for parts in zip(*(f.internal_bounds() for f in frees)))

    # The solver's variables are 1 + u (u = 0 at the start): its first trust radius is
    # |x0| (one unit per variable: a factor e for a log-scaled parameter), and x0 stays
    # away from 0 where scipy's relative steps would vanish.
    low, high = low + 1.0, high + 1.0
    evaluations = 0
    counting = threading.Lock()
    last = {}
    threads = pool = None        # the Jacobian's worker threads, while the solver runs
    # What a trial point the model rejects (e.g. a load its surface cannot carry) or
    # where it blows up costs: far more than any sensible fit, so the solver backs off.
    penalty = 10.0 * measured.scale

    def evaluate(x):
        """The residual at x, or None where the parameters make no valid model."""
        nonlocal evaluations
        try:
            force = measured.simulate(model_at(start, frees, x - 1.0))
        except InputError:
            residual = None
        else:
            residual = force - measured.force
            if not np.all(np.isfinite(residual)):
                residual = None
        with counting:
            evaluations += 1
            if callback is not None:
                rms = math.inf if residual is None else float(np.sqrt(np.mean(residual ** 2)))
                callback(evaluations, rms)
        return residual

    def residuals(x):
        if np.array_equal(last.get("x"), x):        # the start, simulated once below
            return last["residual"]
        residual = evaluate(x)
        if residual is None:
            residual = np.full(measured.size, penalty)
        last["x"], last["residual"] = x.copy(), residual
        return residual

    def jacobian(x):
        """Forward differences with a fixed step in the solver's variables (backward at an
        upper bound or where the forward point is invalid); the residual at x is the one
        the solver has just evaluated.  Columns are independent simulations: on threads."""
        base = last["residual"] if np.array_equal(last.get("x"), x) else residuals(x)

        def column(j):
            forward = diff_step if x[j] + diff_step <= high[j] else -diff_step
            for step in (forward, -forward):
                moved = x.copy()
                moved[j] += step
                residual = evaluate(moved)
                if residual is not None:
                    return (residual - base) / step
            return np.zeros(base.size)

        nonlocal pool
        columns, rest = [], range(x.size)
        if threads is None:
            # The first column, timed, decides how many threads the others get.
            clock = time.perf_counter()
            columns.append(column(0))
            threads_for(_worker_count(workers, x.size, time.perf_counter() - clock))
            rest = range(1, x.size)
        columns += pool.map(column, rest) if pool is not None else map(column, rest)
        return np.column_stack(columns)

    def threads_for(count):
        nonlocal threads, pool
        threads = count
        if count > 1:
            from concurrent.futures import ThreadPoolExecutor
            pool = ThreadPoolExecutor(max_workers=count, thread_name_prefix="polind-fit")

    first = measured.simulate(start)
    if not np.all(np.isfinite(first)):
        raise InputError(f"The starting {start.type} model gives a non-finite force on these "
                         "data; check its parameters.")
    last["x"], last["residual"] = np.ones(n_variables), first - measured.force
    holdout_record = None if fitted_samples is None else record
    if n_variables == 0:
        result = fit_result(start, start, frees, np.zeros(0), given_bounds, first, measured, 0, 1,
                            True, "nothing to identify", notes=notes, record=holdout_record)
    else:
        if workers is not None:
            threads_for(_worker_count(workers, n_variables, math.inf))
        try:
            solution = least_squares(residuals, np.ones(n_variables), jac=jacobian,
                                     bounds=(low, high), method="trf", x_scale=x_scale,
                                     ftol=tolerance, xtol=tolerance, gtol=tolerance,
                                     max_nfev=max_evaluations)
        finally:
            if pool is not None:
                pool.shutdown()
        solution.x = solution.x - 1.0
        fitted = model_at(start, frees, solution.x)
        force = measured.simulate(fitted)
        result = fit_result(fitted, start, frees, solution.x, given_bounds, force, measured,
                            solution.njev or 0, evaluations, solution.status > 0, solution.message,
                            jac=solution.jac, notes=notes, record=holdout_record)
    for note in result.warnings:
        warnings.warn(note, UserWarning, stacklevel=2)
    return result
