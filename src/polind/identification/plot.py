"""The figure of a fit: measured against fitted force (``polind fit --plot``)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from polind.errors import InputError
from polind.identification.data import measured_data
from polind.identification.results import FitResult
from polind.models import FrictionModel
from polind.validation import describe

__all__ = ["plot_fit"]


def _labelled(results) -> list[tuple[str, FrictionModel, FitResult | None]]:
    """``(label, model, its FitResult or None)`` of each item."""
    if isinstance(results, (FitResult, FrictionModel)):
        results = [results]
    items = results.items() if isinstance(results, Mapping) else [(None, r) for r in results]
    out = []
    for label, item in items:
        model = item.model if isinstance(item, FitResult) else item
        if not isinstance(model, FrictionModel):
            raise InputError(f"plot_fit takes FitResults or models. Got {describe(item)} instead.")
        out.append((label or model.type, model, item if isinstance(item, FitResult) else None))
    return out


def _legend(label: str, result: FitResult | None, measured, force) -> str:
    """The curve's label: a fit's own RMS numbers (as printed), else the RMS over the data."""
    if result is None:
        rms = float(np.sqrt(np.mean((force - measured.force) ** 2)))
        return f"{label} (RMS {rms:.3g} N)"
    if result.holdout_rms_error is None:
        return f"{label} (RMS {result.rms_error:.3g} N)"
    return (f"{label} (RMS {result.rms_error:.3g} N in sample, "
            f"{result.holdout_rms_error:.3g} N held out)")


def _held_out_start(result: FitResult | None, samples: int) -> int | None:
    """The first held-out sample of a fit with a hold-out on these very samples, else None."""
    if result is None or result.holdout_rms_error is None or result.force.shape[0] != samples:
        return None
    return result.fitted_samples


def plot_fit(data, results, path, *, window=None, title=None, dpi=120):
    """Write a PNG of measured against fitted force (``polind fit --plot FILE``).

    Three panels: force over the whole record, force over a time window (a
    few strokes, to see the shape), and force against position.  Each model
    is simulated again on ``data``, so results fitted on a decimated record
    can be drawn against the full one.  A curve is labelled with its fit's
    RMS errors as the fit printed them (in sample, and held out with a
    hold-out; for a bare model, the RMS error over ``data``); the held-out
    part of a fit with a hold-out on these samples is shaded on the time
    panels.

    Parameters
    ----------
    data : mapping of str to array_like
        As :func:`identify`; a ``normal_load`` column goes to the models that
        take one (pol-ind) only.
    results : FitResult, FrictionModel, a sequence of them, or a mapping label -> one
        The fitted models (labelled by model type unless a mapping is given).
    path : str, os.PathLike or None
        The PNG to write (atomically); None returns its bytes instead, to be
        written with a command's other outputs (:func:`polind.io.write_together`).
    window : (float, float), optional
        Start and end [s] of the middle panel; default a tenth of the record
        around its middle.
    title : str, optional
    dpi : int

    Returns
    -------
    bytes or None
        The PNG when ``path`` is None.
    """
    from io import BytesIO

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from polind import io

    measured = measured_data(data)
    labelled = _labelled(results)
    position = measured.path().x
    t = measured.t
    if window is None:
        middle, half = 0.5 * (t[0] + t[-1]), 0.05 * (t[-1] - t[0])
        window = (middle - half, middle + half)
    inside = (t >= window[0]) & (t <= window[1])
    if inside.sum() < 2:
        inside[:] = True

    figure = Figure(figsize=(11, 11), layout="constrained")
    FigureCanvasAgg(figure)
    over_time, zoomed, against_x = figure.subplots(3, 1, height_ratios=(1, 1, 1.4))
    for axes, mask in ((over_time, slice(None)), (zoomed, inside)):
        axes.plot(t[mask], measured.force[mask], color="black", lw=1.6, label="measured")
    against_x.plot(position * 1e3, measured.force, color="black", lw=0.8, label="measured")
    shaded = set()
    for label, model, result in labelled:
        force = measured.simulate(model)
        text = _legend(label, result, measured, force)
        over_time.plot(t, force, lw=1.0, label=text)
        zoomed.plot(t[inside], force[inside], lw=1.2, label=text)
        against_x.plot(position * 1e3, force, lw=0.8, alpha=0.7, label=text)
        split = _held_out_start(result, t.shape[0])
        if split is not None and split not in shaded:
            shaded.add(split)
            for axes in (over_time, zoomed):
                axes.axvspan(t[split], t[-1], color="0.5", alpha=0.15, lw=0,
                             label="held out (not fitted)")
    zoomed.set_xlim(t[inside][0], t[inside][-1])
    over_time.set(xlabel="time t [s]", ylabel="friction force F [N]",
                  title=title or "Measured and fitted friction force")
    zoomed.set(xlabel="time t [s]", ylabel="friction force F [N]",
               title=f"window {window[0]:.4g} s to {window[1]:.4g} s")
    against_x.set(xlabel="position x [mm]", ylabel="friction force F [N]",
                  title="force against position")
    for axes in (over_time, zoomed, against_x):
        axes.grid(alpha=0.3)
    over_time.legend(loc="best", fontsize=8)
    zoomed.legend(loc="best", fontsize=8)
    against_x.legend(loc="best", fontsize=8)
    buffer = BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png")
    if path is None:
        return buffer.getvalue()
    io.atomic_write_bytes(path, buffer.getvalue())      # the output rules of every command
    return None
