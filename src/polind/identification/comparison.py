"""Fit several friction models to one record and rank them (``polind compare``).

The user guide, :ref:`guide-compare`.

An engineer trusts a friction model once it predicts data it was not fitted
to.  :func:`compare` fits every model with :func:`polind.identify` on the
same samples -- the first ``1 - holdout`` of the record -- and tabulates, per
model, the number of free values, the RMS error in sample and on the
held-out rest, and two information criteria that charge for the free
values: the Akaike (AIC) and the Bayesian (BIC) criterion of the fitted
part (:attr:`polind.FitResult.aic`).  :meth:`Comparison.plot` draws measured
and predicted force against time and against position for every model, the
held-out part shaded.

The criteria, with ``n`` fitted samples, ``RSS`` the sum of the squared
residuals over them and ``k`` the free values::

    AIC = n ln(RSS / n) + 2 k          BIC = n ln(RSS / n) + k ln n

``n ln(RSS / n)`` is minus twice the Gaussian log-likelihood of the
residuals at the maximum-likelihood variance ``RSS / n``, less the constant
``n (1 + ln 2 pi)`` that every model fitted to the same samples shares, so
only differences between the rows mean anything (lower is better).  Both
treat the residuals as independent; those of a densely sampled record are
correlated, so the penalties are mild and the hold-out RMS is the better
judge of over-fitting.
"""

from __future__ import annotations

import csv
import io as _text_io
import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from polind.errors import InputError, describe
from polind.identification.data import holdout_split, measured_data
from polind.identification.parameters import parse_fit
from polind.identification.results import FitResult
from polind.identification.solver import identify
from polind.models import FrictionModel

__all__ = ["COLUMNS", "COLOURS", "Comparison", "compare"]

#: The columns of the comparison table (``polind compare --output``), in order.
COLUMNS = ("model", "free_parameters", "rms_in_sample", "rms_held_out", "aic", "bic")
_HEADINGS = ("model", "free", "RMS in sample [N]", "RMS held out [N]", "AIC", "BIC")
#: The figure's colours, the same in every row: measured, predicted on the fitted part,
#: predicted on the held-out part.
COLOURS = {"measured": "black", "fitted": "C0", "held out": "C3"}


@dataclass(frozen=True)
class Comparison:
    """The outcome of :func:`compare`: one fitted model per row.

    Attributes
    ----------
    rows : tuple of dict
        Per model, in the order given, the
        :data:`~polind.identification.COLUMNS`: ``model`` (its label),
        ``free_parameters`` (free values the fit varied), ``rms_in_sample``
        [N], ``rms_held_out`` [N] (None without a hold-out), ``aic``, ``bic``.
    results : dict
        Label -> the :class:`~polind.FitResult` of that model.
    holdout : float or None
        The held-out fraction.
    fitted_samples : int
        How many samples (the first ones) every model was fitted to.
    t, x, force : ndarray
        The whole record: time [s], position [m] (integrated from ``v`` when
        the data give velocity) and measured force [N], for the figure.
    """

    rows: tuple
    results: dict
    holdout: float | None
    fitted_samples: int
    t: np.ndarray = field(repr=False)
    x: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)

    def __repr__(self):
        rows = ", ".join(f"{row['model']} rms {row['rms_in_sample']:.4g} N" for row in self.rows)
        held_out = "" if self.holdout is None else f", holdout {self.holdout:g}"
        return (f"Comparison({len(self.rows)} models on {self.fitted_samples} samples"
                f"{held_out}: {rows})")

    def table(self) -> str:
        """The rows as aligned text for a terminal (a missing value is ``-``)."""
        width = max([len(_HEADINGS[0])] + [len(row["model"]) for row in self.rows])
        lines = [f"{_HEADINGS[0]:<{width}}  {_HEADINGS[1]:>4}  {_HEADINGS[2]:>17}  "
                 f"{_HEADINGS[3]:>16}  {_HEADINGS[4]:>12}  {_HEADINGS[5]:>12}"]
        for row in self.rows:
            held_out = "-" if row["rms_held_out"] is None else f"{row['rms_held_out']:.5g}"
            lines.append(f"{row['model']:<{width}}  {row['free_parameters']:>4d}  "
                         f"{row['rms_in_sample']:>17.5g}  {held_out:>16}  "
                         f"{row['aic']:>12.6g}  {row['bic']:>12.6g}")
        return "\n".join(lines)

    def to_csv(self) -> str:
        """The rows as CSV text: a header of the columns, numbers at full precision.

        The header is :data:`~polind.identification.COLUMNS`; a missing
        held-out RMS (no hold-out) is an empty field.
        """
        text = _text_io.StringIO()
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(COLUMNS)
        for row in self.rows:
            writer.writerow([row["model"], row["free_parameters"]]
                            + ["" if row[key] is None else repr(float(row[key]))
                               for key in COLUMNS[2:]])
        return text.getvalue()

    def to_frame(self):
        """The rows as a pandas ``DataFrame`` indexed by model (pandas imported here)."""
        import pandas

        return pandas.DataFrame([{key: (math.nan if row[key] is None else row[key])
                                  for key in COLUMNS} for row in self.rows]).set_index("model")

    def figure(self, *, title=None):
        """A matplotlib ``Figure``: per model, force against time and against position.

        Three panels a row: the whole record against time, a window around
        the start of the held-out part (the middle of the record without a
        hold-out) against time, and force against position.  The colours
        are the same in every row (:data:`polind.identification.COLOURS`):
        measured black, the prediction on the fitted part blue, on the
        held-out part red; the held-out time span is shaded.
        """
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        t, position = self.t, self.x * 1e3
        split = self.fitted_samples
        held = split < t.shape[0]
        centre = t[split] if held else 0.5 * (t[0] + t[-1])
        half = 0.04 * (t[-1] - t[0])
        window = (t >= centre - half) & (t <= centre + half)
        rows = len(self.rows)
        figure = Figure(figsize=(15, 3.3 * rows + 0.6), layout="constrained")
        FigureCanvasAgg(figure)
        axes = np.atleast_2d(figure.subplots(rows, 3, width_ratios=(1.4, 1.0, 1.0),
                                             squeeze=False))
        fitted, held_out_part = slice(None, split), slice(max(split - 1, 0), None)
        for line, (row, (label, result)) in enumerate(zip(self.rows, self.results.items())):
            predicted = result.force
            whole, zoom, against_x = axes[line]
            for panel, mask in ((whole, slice(None)), (zoom, window)):
                panel.plot(t[mask], self.force[mask], color=COLOURS["measured"], lw=0.9,
                           label="measured")
                shown = np.zeros(t.shape[0], dtype=bool)
                shown[mask] = True
                for part, name in ((fitted, "fitted"), (held_out_part, "held out")):
                    if part is held_out_part and not held:
                        continue
                    inside = np.flatnonzero(shown[part]) + (part.start or 0)
                    if inside.size:
                        panel.plot(t[inside], predicted[inside], color=COLOURS[name], lw=0.9,
                                   label=f"predicted, {name}" if held else "predicted")
                if held:
                    panel.axvspan(t[split], t[-1], color="0.5", alpha=0.15, lw=0,
                                  label="held out (not fitted)")
                panel.set(xlabel="time t [s]", ylabel="friction force F [N]")
            zoom.set_xlim(t[window][0], t[window][-1])
            against_x.plot(position, self.force, color="0.35", lw=0.5, alpha=0.6,
                           label="measured")
            against_x.plot(position[fitted], predicted[fitted], color=COLOURS["fitted"], lw=0.8,
                           label="predicted, fitted" if held else "predicted")
            if held:
                against_x.plot(position[held_out_part], predicted[held_out_part],
                               color=COLOURS["held out"], lw=0.8, alpha=0.8,
                               label="predicted, held out")
            against_x.set(xlabel="position x [mm]", ylabel="friction force F [N]")
            held_out = ("" if row["rms_held_out"] is None
                        else f", {row['rms_held_out']:.3g} N held out")
            whole.set_title(f"{label}: RMS {row['rms_in_sample']:.3g} N in sample{held_out}",
                            loc="left", fontsize=10)
            zoom.set_title("around the start of the held-out part" if held
                           else "a window in the middle", fontsize=9)
            against_x.set_title("force against position", fontsize=9)
            for panel in (whole, zoom, against_x):
                panel.grid(alpha=0.3)
            zoom.legend(loc="best", fontsize=7)
            against_x.legend(loc="best", fontsize=7)
        figure.suptitle(title or "Measured and predicted friction force", fontsize=12)
        return figure

    def plot(self, path, *, title=None, dpi=110):
        """Write :meth:`figure` as a PNG (atomically: all of it or nothing).

        With ``path`` None, return the PNG's bytes instead (to be written
        with a command's other outputs, :func:`polind.io.write_together`).
        """
        from polind import io

        buffer = _text_io.BytesIO()
        self.figure(title=title).savefig(buffer, dpi=dpi, format="png")
        if path is None:
            return buffer.getvalue()
        io.atomic_write_bytes(path, buffer.getvalue())
        return None


def _labelled(models) -> list[tuple[str, object]]:
    """``(label, model)`` pairs: a mapping's keys, else the model types (made unique)."""
    if isinstance(models, (FrictionModel, Mapping)) and not _is_labelled(models):
        models = [models]
    if isinstance(models, Mapping):
        items = [(str(label), model) for label, model in models.items()]
    elif isinstance(models, (list, tuple)):
        items = [(None, model) for model in models]
    else:
        raise InputError(f"The 'models' of compare must be a list of models (or model "
                         f"documents) or a mapping label -> model. Got {describe(models)} "
                         "instead.")
    if not items:
        raise InputError("The 'models' of compare must name at least one model. Got none.")
    out, seen = [], {}
    for label, model in items:
        if label is None:
            kind = model.type if isinstance(model, FrictionModel) else _document_type(model)
            seen[kind] = seen.get(kind, 0) + 1
            label = kind if seen[kind] == 1 else f"{kind} {seen[kind]}"
        out.append((label, model))
    return out


def _is_model(value) -> bool:
    """A model, or a model document (a mapping with a ``model`` table)."""
    return isinstance(value, FrictionModel) or (isinstance(value, Mapping)
                                                and isinstance(value.get("model"), Mapping))


def _is_labelled(models) -> bool:
    """A mapping of labels to models, not one model document ({"model": ..., "fit": ...}).

    A document's values are its tables (``[model]``, ``[fit]``), never models or
    documents; a mapping of labels holds only models or documents.  So a row
    labelled ``model`` (a file ``model.toml``) is still a row.
    """
    return (isinstance(models, Mapping) and bool(models)
            and all(_is_model(value) for value in models.values()))


def _document_type(document) -> str:
    table = document.get("model") if isinstance(document, Mapping) else None
    kind = table.get("type") if isinstance(table, Mapping) else None
    return kind if isinstance(kind, str) else "model"


def compare(models, data, holdout=None, *, progress=None, **options) -> Comparison:
    """Fit each model to the same data and tabulate how well each fits and predicts.

    Every model is fitted by :func:`polind.identify` with its own free keys
    and bounds (a document's ``[fit]`` table, else the model's
    ``fit_defaults`` and the default bounds) on the first ``1 - holdout`` of
    the samples; the held-out rest is predicted by continuing each fitted
    model's run.  A model that contains another row's model as a special
    case (:meth:`polind.FrictionModel.contains`: GMS contains Maxwell-slip,
    LuGre Stribeck) is fitted after it and starts from that row's fit too
    (``extra_starts``), so it never ends worse in sample than that row where
    its free keys and element count can reproduce it.  AIC and BIC are
    those of the fitted part (module docstring): ``n ln(RSS / n) + 2 k`` and
    ``n ln(RSS / n) + k ln n``.

    Parameters
    ----------
    models : sequence or mapping
        Models (:class:`polind.FrictionModel`) or model documents
        (``{"model": {...}, "fit": {...}}``), labelled by model type (``gms``,
        ``gms 2``, ...), or a mapping label -> model or document.
    data : mapping of str to array_like, or a pandas DataFrame
        As :func:`polind.identify`: ``t``, ``x`` or ``v``, ``F``, optionally
        ``normal_load`` (used by the models that use a load).
    holdout : float, optional
        The fraction of the samples, at the end, kept out of every fit.
    progress : callable, optional
        ``progress(done, total, label)`` after each model's fit.
    **options
        Passed to :func:`polind.identify` (``starts``, ``max_evaluations``,
        ``workers``, ...).

    Returns
    -------
    Comparison
        Its ``rows`` are the table; the warnings of each fit are issued
        again as ``UserWarning``, prefixed with the model's label.

    Raises
    ------
    InputError
        A bad model or ``[fit]`` (prefixed with the model's label), bad data
        or a bad ``holdout``.

    Examples
    --------
    >>> import numpy as np, polind
    >>> truth = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                           "coulomb_force": 1.0}})
    >>> t = np.linspace(0.0, 4.0, 801)
    >>> x = 1e-4 * np.sin(np.pi * t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(truth, t, x=x).force}
    >>> coulomb = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 2.0}})
    >>> table = polind.compare([truth.with_params(stiffness=3e4), coulomb], data, holdout=0.25)
    >>> [(row["model"], row["free_parameters"]) for row in table.rows]
    [('dahl', 2), ('coulomb', 1)]
    >>> table.rows[0]["rms_held_out"] < 1e-6 < table.rows[1]["rms_held_out"]
    True
    """
    items = _labelled(models)
    parsed = {}
    for label, model in items:
        try:
            parsed[label] = parse_fit(model)
        except InputError as error:
            raise InputError(f"model '{label}': {error}") from None
    record = measured_data(data)
    fitted_samples = holdout_split(holdout, record.size)
    fitted_path = (record if fitted_samples is None else record.head(fitted_samples)).path()
    documents = dict(items)
    results = {}
    for done, label in enumerate(_fit_order(parsed), start=1):
        start, keys, _ = parsed[label]
        extra = _contained_rows(start, keys, results, fitted_path)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = identify(documents[label], data, holdout=holdout,
                                  extra_starts=extra or None, **options)
            except InputError as error:
                raise InputError(f"model '{label}': {error}") from None
        for warning in caught:
            warnings.warn(f"{label}: {warning.message}", warning.category, stacklevel=2)
        results[label] = result
        if progress is not None:
            progress(done, len(items), label)
    results = {label: results[label] for label, _ in items}
    rows = [_row(label, result) for label, result in results.items()]
    path = record.path()
    return Comparison(rows=tuple(rows), results=results,
                      holdout=None if holdout is None else float(holdout),
                      fitted_samples=record.size if fitted_samples is None else fitted_samples,
                      t=record.t, x=path.x, force=record.force)


def _fit_order(parsed: dict) -> list[str]:
    """The labels in the order to fit them: a model that contains another row's model after it.

    ``parsed``: label -> ``(start, free keys, bounds)`` as :func:`parse_fit` gives them.
    """
    kinds = {label: type(start) for label, (start, _, _) in parsed.items()}

    def waits(label):
        kind = kinds[label].contains()
        return kind is not None and kind is not kinds[label] and any(
            kinds[other] is kind for other in kinds if other != label)

    return ([label for label in kinds if not waits(label)]
            + [label for label in kinds if waits(label)])


def _contained_rows(start, keys, results: dict, path) -> dict:
    """Starts lifted from the fitted rows whose model ``start`` contains as a special case."""
    try:
        case = start.special_case(list(keys), path)
    except InputError:
        return {}
    if case is None or case.kind is type(start):
        return {}
    extra = {}
    for label, result in results.items():
        if type(result.model) is case.kind:
            try:
                extra[f"the fitted '{label}' row"] = case.lift(result.model)
            except InputError:
                continue
    return extra


def _row(label: str, result: FitResult) -> dict:
    return {"model": label, "free_parameters": result.parameter_count,
            "rms_in_sample": result.rms_error, "rms_held_out": result.holdout_rms_error,
            "aic": result.aic, "bic": result.bic}
