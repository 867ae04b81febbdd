"""The outcome of an identification: :class:`FitResult`, its standard errors and warnings.

The standard errors come from the Jacobian at the solution (the delta
method, :mod:`polind.identification`); the warnings name a parameter at a
bound, one the data do not determine and a solver that stopped early
(:ref:`guide-fit-warnings`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError
from polind.identification.credibility import credibility_warnings, noise_level
from polind.identification.parameters import model_at, split_variables
from polind.identification.starts import GIVEN_START
from polind.models import FrictionModel

__all__ = ["FitResult", "fit_result"]

# A free variable moved by this much tells whether a force level depends on it (the
# optimiser's units: a relative 1e-3 of a log-scaled parameter).
_LEVEL_STEP = 1e-3


@dataclass(frozen=True)
class FitResult:
    """The outcome of an identification.

    Attributes
    ----------
    model : FrictionModel
        The model with the identified values.
    start : FrictionModel
        The starting model (the model's values; the fit kept may have started
        elsewhere: ``start_label``).
    free : tuple of str
        The identified keys (dotted for nested ones).
    bounds : dict
        The bounds given per key, ``[low, high]`` (keys without bounds absent).
    values, standard_errors : dict
        Per free key its identified value and standard error (floats, or
        lists for list keys), in the parameter's unit.  An infinite standard
        error marks a value the data do not determine.
    rms_error : float
        Root-mean-square of ``F_model - F_measured`` over the fitted samples [N].
    iterations : int
        Iterations of the trust-region-reflective solver (its Jacobian
        evaluations, one per iteration).
    evaluations : int
        Model simulations in all, finite-difference ones included.
    success : bool
        Whether the solver met a convergence test (not the evaluation limit).
    message : str
        The solver's reason for stopping.
    force : ndarray
        The fitted model's force at every sample of the data [N] (with a
        hold-out, the fitted part and the prediction of the rest, one run).
    warnings : tuple of str
        What the user should know about the fit (:ref:`guide-fit-warnings`): a
        parameter at a bound, one the data do not determine, a column or
        signal the model does not use, ...; empty when all is well.
    holdout_rms_error : float or None
        RMS of ``F_model - F_measured`` over the held-out samples [N]; None
        without a hold-out.
    fitted_samples : int
        The number of samples fitted (the first ones of the data).
    parameter_count : int
        The number of free values the solver varied (a list key counts its
        entries; the GMS weights, which sum to 1, one fewer; a value that
        could not move the force at its start is fixed and not counted).
    start_label : str
        Where the fit kept started (:ref:`guide-fit-starts`): ``"the model's
        values"``, ``"the fitted maxwell-slip (gms with Fs = Fc)"``, ``"the
        NNLS element set (GMS.from_presliding)"``, ``"Latin hypercube point 1
        of 2"``, ...
    starts : tuple of (str, float)
        Every start tried and the RMS error in sample [N] its fit reached, in
        the order tried.
    noise_estimate : float or None
        The standard deviation of the record's noise [N], estimated from the
        high-frequency part of the fitted samples' force
        (:func:`polind.identification.noise_level`); a fit whose
        ``rms_error`` exceeds it by more than
        :data:`polind.identification.NOISE_RATIO` warns
        (:ref:`guide-fit-warnings`).  NaN for a record too short to tell;
        None on a result made without it.
    """

    model: FrictionModel
    start: FrictionModel
    free: tuple
    bounds: dict
    values: dict
    standard_errors: dict
    rms_error: float
    iterations: int
    evaluations: int
    success: bool
    message: str
    force: np.ndarray = field(repr=False)
    warnings: tuple = ()
    holdout_rms_error: float | None = None
    fitted_samples: int = 0
    parameter_count: int = 0
    start_label: str = GIVEN_START
    starts: tuple = ()
    noise_estimate: float | None = None

    def __repr__(self):
        held_out = ("" if self.holdout_rms_error is None
                    else f", holdout_rms_error {self.holdout_rms_error:.4g} N")
        return (f"FitResult({self.model.type}, free {', '.join(self.free) or 'nothing'} "
                f"({self.parameter_count} values), rms_error {self.rms_error:.4g} N"
                f"{held_out} on {self.fitted_samples} samples, "
                f"{'converged' if self.success else 'not converged'} after "
                f"{self.iterations} iterations, {len(self.warnings)} warnings)")

    @property
    def aic(self) -> float:
        """Akaike's information criterion of the fitted part (lower is better).

        ``n ln(RSS / n) + 2 k``: minus twice the Gaussian log-likelihood of the
        ``n`` fitted residuals at the maximum-likelihood variance ``RSS / n``,
        without the constant ``n (1 + ln 2 pi)`` that every model fitted to
        the same samples shares, plus twice the ``k`` free values
        (``parameter_count``).  Only differences between models fitted
        to the same samples mean anything.
        """
        n = self.fitted_samples
        return n * math.log(self.rms_error ** 2) + 2.0 * self.parameter_count \
            if self.rms_error > 0.0 else -math.inf

    @property
    def bic(self) -> float:
        """The Bayesian (Schwarz) criterion: ``n ln(RSS / n) + k ln n``, as :attr:`aic`."""
        n = self.fitted_samples
        return n * math.log(self.rms_error ** 2) + self.parameter_count * math.log(n) \
            if self.rms_error > 0.0 else -math.inf

    def to_fit_table(self) -> dict:
        """The ``[fit.result]`` table of a fitted model file (:ref:`formats-fit`).

        ``{"rms_error": ..., "holdout_rms_error": ... (with a hold-out),
        "iterations": ..., "start": ..., "starts": [{"start": ...,
        "rms_error": ...}, ...], "warnings": [...], key: {"value": ...,
        "standard_error": ...}, ...}``; a dotted key stays one key
        (``[fit.result."surface.height_std"]`` in TOML).
        """
        table = {"rms_error": float(self.rms_error)}
        if self.holdout_rms_error is not None:
            table["holdout_rms_error"] = float(self.holdout_rms_error)
        table["iterations"] = int(self.iterations)
        table["start"] = self.start_label
        table["starts"] = [{"start": label, "rms_error": float(rms)}
                           for label, rms in self.starts]
        table["warnings"] = list(self.warnings)
        for key in self.free:
            table[key] = {"value": self.values[key], "standard_error": self.standard_errors[key]}
        return table

    def to_document(self) -> dict:
        """The model-file document ``polind fit`` writes.

        ``[model]`` with the identified values, ``[fit]`` with ``free``, the
        given ``bounds`` (if any) and ``result`` (:meth:`to_fit_table`).  Write
        it with :func:`polind.io.write_model_file`; read back with
        :func:`polind.load_model` (the ``[fit]`` table is ignored there) or
        passed again to :func:`identify` to continue from the identified values.
        """
        fit = {"free": list(self.free)}
        if self.bounds:
            fit["bounds"] = {key: list(pair) for key, pair in self.bounds.items()}
        fit["result"] = self.to_fit_table()
        return {"model": self.model.to_dict()["model"], "fit": fit}

    def summary(self) -> str:
        """A few lines for a terminal: the RMS errors and each key's value and standard error."""
        held_out = ("" if self.holdout_rms_error is None
                    else f", holdout_rms_error = {self.holdout_rms_error:.6g} N")
        noise = ("" if self.noise_estimate is None
                 else f" (the record's noise: {self.noise_estimate:.3g} N)")
        lines = [f"{self.model.type}: rms_error = {self.rms_error:.6g} N{noise}{held_out}, "
                 f"iterations = {self.iterations}" + ("" if self.success else
                                                      f" (stopped: {self.message})"),
                 f"  start: {self.start_label} (best of {max(len(self.starts), 1)})"]
        for key in self.free:
            value = np.atleast_1d(self.values[key])
            error = np.atleast_1d(self.standard_errors[key])
            shown = ", ".join(f"{a:.6g} +- {b:.2g}" for a, b in zip(value, error))
            lines.append(f"  {key} = {shown}")
        return "\n".join(lines)


def _standard_errors(frees, u, jac, residual, varied) -> list[np.ndarray]:
    """Physical standard errors from the Jacobian in the optimiser's variables (delta method).

    ``varied`` values were varied (the columns of fixed ones are zero: their errors are
    infinite)."""
    n, p = jac.shape
    variance = float(residual @ residual) / max(n - varied, 1)
    _, singular, vt = np.linalg.svd(jac, full_matrices=False)
    tol = singular.max(initial=0.0) * max(n, p) * np.finfo(float).eps
    kept = singular > tol
    transform = np.zeros((sum(f.start.size for f in frees), p))
    row = col = 0
    for free, part in zip(frees, split_variables(frees, u)):
        block = free.derivative(part)
        transform[row:row + block.shape[0], col:col + block.shape[1]] = block
        row, col = row + block.shape[0], col + block.shape[1]
    mapped = transform @ vt[kept].T / singular[kept]
    errors = np.sqrt(variance * np.sum(mapped ** 2, axis=1))
    if not kept.all():
        undetermined = np.any(np.abs(transform @ vt[~kept].T) > 1e-8 * np.abs(transform).max(),
                              axis=1)
        errors[undetermined] = np.inf
    out, row = [], 0
    for free in frees:
        out.append(errors[row:row + free.start.size])
        row += free.start.size
    return out


def _fit_warnings(model, frees, values, errors, success, message, fixed) -> list[str]:
    """A parameter at a bound, a parameter the data do not determine, a solver stopped early,
    a value fixed at its start because it could not move the force there."""
    notes = []
    if not success:
        notes.append(f"The solver stopped before converging ({message}); the values are its "
                     "last iterate. Allow more evaluations or start closer.")
    for free, value, error, still in zip(frees, values, errors, fixed):
        several = value.size > 1
        for index, (entry, spread) in enumerate(zip(value, error)):
            name = f"{free.key}[{index}]" if several else free.key
            if index < still.size and still[index]:
                notes.append(f"The '{name}' parameter of {model.type} does not move the force "
                             f"at the start of the fit kept ({entry:.6g}; its column of the "
                             "Jacobian is zero there and where the fit ended): it is not "
                             "identifiable from there and was fixed at that value, not "
                             "iterated on.")
                continue
            for side, bound, origin in (("lower", free.low, free.low_origin),
                                        ("upper", free.high, free.high_origin)):
                if (free.mapping == "simplex" or not math.isfinite(bound)
                        or (free.mapping == "log" and bound <= 0.0)):
                    continue
                tolerance = 1e-6 * (abs(bound) if bound != 0.0 else free.scale)
                if abs(entry - bound) <= tolerance:
                    notes.append(f"The '{name}' parameter of {model.type} ended at its {side} "
                                 f"bound {bound:.6g} ({origin}); the data would move it "
                                 "further: widen its [fit.bounds] or fix it.")
            if not math.isfinite(spread) or spread > abs(entry):
                why = ("a standard error that is not finite" if not math.isfinite(spread)
                       else f"a standard error of {spread:.2g}, larger than the value")
                notes.append(f"The '{name}' parameter of {model.type} is not identifiable from "
                             f"these data ({entry:.6g} with {why}); fix it, or fit data that "
                             "excite it.")
    return notes


def fit_result(model, start, frees, u, bounds, force, data, iterations, evaluations, success,
               message, jac=None, notes=(), record=None, fixed=None,
               start_label=GIVEN_START, starts=()) -> FitResult:
    """The :class:`FitResult` of a solution ``u`` of the optimiser's variables.

    ``frees`` as ``build_free`` returns
    them, ``force`` the model's force on ``data`` (the fitted samples),
    ``jac`` the Jacobian of the residuals at ``u`` (None: no standard errors
    and no warnings of the solution), ``notes`` the warnings found before the
    solve; with ``record`` (the whole data of a hold-out split) its tail is
    scored.  ``fixed`` marks the variables fixed at their start (zero
    columns of ``jac``), ``start_label`` and ``starts`` say where the fit
    started and what each start reached.
    """
    residual = force - data.force
    fixed = np.zeros(u.size, dtype=bool) if fixed is None else np.asarray(fixed, dtype=bool)
    varied = int(u.size - np.count_nonzero(fixed))
    values, standard_errors, physical, spreads = {}, {}, [], []
    errors = (_standard_errors(frees, u, jac, residual, varied) if jac is not None
              else [np.full(free.start.size, np.nan) for free in frees])
    for free, part, error in zip(frees, split_variables(frees, u), errors):
        value = free.physical(part)
        values[free.key] = free.output(value)
        standard_errors[free.key] = free.output(error)
        physical.append(value)
        spreads.append(error)
    notes = list(notes)
    if jac is not None:
        notes += _fit_warnings(model, frees, physical, spreads, success, message,
                               split_variables(frees, fixed))
    held_out = None
    if record is not None:
        # The held-out prediction continues the fitted part: one run over the whole record.
        whole = record.simulate(model)
        tail = whole[data.size:] - record.force[data.size:]
        held_out = float(np.sqrt(np.mean(tail ** 2)))
        force = whole
    noise = noise_level(data.t, data.force)

    def neighbours():
        """The model with each free value moved a little (None where it makes no model)."""
        out = []
        for index in range(u.size):
            moved = np.array(u, dtype=np.float64)
            moved[index] += _LEVEL_STEP
            try:
                out.append(model_at(start, frees, moved))
            except InputError:
                out.append(None)
        return out

    notes += credibility_warnings(model, data, residual, held_out, noise=noise,
                                  neighbours=neighbours, starts=max(len(starts), 1))
    return FitResult(model=model, start=start, free=tuple(f.key for f in frees),
                     bounds={key: tuple(pair) for key, pair in bounds.items()}, values=values,
                     standard_errors=standard_errors,
                     rms_error=float(np.sqrt(np.mean(residual ** 2))), iterations=int(iterations),
                     evaluations=int(evaluations), success=bool(success), message=str(message),
                     force=force, warnings=tuple(notes), holdout_rms_error=held_out,
                     fitted_samples=int(data.size), parameter_count=varied,
                     start_label=str(start_label),
                     starts=tuple((str(label), float(rms)) for label, rms in starts),
                     noise_estimate=float(noise))
