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


def _labelled(results) -> list[tuple[str, FrictionModel]]:
    if isinstance(results, (FitResult, FrictionModel)):
        results = [results]
    items = results.items() if isinstance(results, Mapping) else [(None, r) for r in results]
    out = []
    for label, item in items:
        model = item.model if isinstance(item, FitResult) else item
        if not isinstance(model, FrictionModel):
            raise InputError(f"plot_fit takes FitResults or models. Got {describe(item)} instead.")
        out.append((label or model.type, model))
    return out


def plot_fit(data, results, path, *, window=None, title=None, dpi=120):
    """Write a PNG of measured against fitted force (``polind fit --plot FILE``).

    Three panels: force over the whole record, force over a time window (a
    few strokes, to see the shape), and force against position.  Each model
    is simulated again on ``data``, so results fitted on a decimated record
    can be drawn against the full one.

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
    for label, model in labelled:
        force = measured.simulate(model)
        rms = float(np.sqrt(np.mean((force - measured.force) ** 2)))
        text = f"{label} (RMS {rms:.3g} N)"
        over_time.plot(t, force, lw=1.0, label=text)
        zoomed.plot(t[inside], force[inside], lw=1.2, label=text)
        against_x.plot(position * 1e3, force, lw=0.8, alpha=0.7, label=text)
    over_time.set(xlabel="time t [s]", ylabel="friction force F [N]",
                  title=title or "Measured and fitted friction force")
    zoomed.set(xlabel="time t [s]", ylabel="friction force F [N]",
               title=f"window {window[0]:.4g} s to {window[1]:.4g} s")
    against_x.set(xlabel="position x [mm]", ylabel="friction force F [N]",
                  title="force against position")
    for axes in (over_time, zoomed, against_x):
        axes.grid(alpha=0.3)
    zoomed.legend(loc="best", fontsize=8)
    against_x.legend(loc="best", fontsize=8)
    buffer = BytesIO()
    figure.savefig(buffer, dpi=dpi, format="png")
    if path is None:
        return buffer.getvalue()
    io.atomic_write_bytes(path, buffer.getvalue())      # the output rules of every command
    return None
