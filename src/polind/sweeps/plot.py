"""The figure of a sweep's results: each metric against the swept parameters.

:func:`plot_results` draws a line over one swept parameter and a map over
the first two (the cells of a grid, or one dot per run of a sample), from
a results table (:func:`polind.sweeps.read_results`) and the sweep that made
it, whose axes say which scale to draw.  matplotlib is imported on first use.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from io import BytesIO

import numpy as np

from polind.io import atomic_write_bytes
from polind.sweeps.design import Axis, Sweep, load_sweep
from polind.sweeps.results import read_results

__all__ = ["plot_results"]


def _numeric_positions(axis: Axis, values: list):
    """Plot coordinates of an axis's values, its tick labels (words), and whether it is log."""
    if axis.kind in ("str", "path"):
        labels = list(dict.fromkeys(axis.values or values))
        return [labels.index(value) for value in values], labels, False
    numbers = [float(value) for value in values]
    positive = bool(numbers) and min(numbers) > 0.0
    log = positive and (axis.log or max(numbers) / min(numbers) >= 100.0)
    return numbers, None, log


def _edges(centres, log):
    centres = np.asarray(centres, dtype=np.float64)
    if centres.size == 1:
        return np.array([centres[0] / 1.5, centres[0] * 1.5]) if log else \
            np.array([centres[0] - 0.5, centres[0] + 0.5])
    work = np.log(centres) if log else centres
    middle = 0.5 * (work[1:] + work[:-1])
    edges = np.concatenate(([2.0 * work[0] - middle[0]], middle, [2.0 * work[-1] - middle[-1]]))
    return np.exp(edges) if log else edges


def plot_results(results, spec, path, *, metrics=None, title=None, dpi=100) -> None:
    """Draw each metric against the swept parameters: a line over one, a map over two.

    Parameters
    ----------
    results : str, os.PathLike or dict
        The results table (a file, or columns as :func:`~polind.sweeps.read_results`
        gives).
    spec : Sweep or str
        The sweep that made them (its axes say which scale to draw).
    path : str or os.PathLike
        The PNG to write (atomically).
    metrics : sequence of str, optional
        Default: every metric of the sweep.

    Notes
    -----
    With one swept parameter each metric is a line against it.  With two or
    more, a map over the first two: on a grid the cells of the runs whose
    other parameters are at their first value, otherwise one dot per run.
    Grey cells: the metric is undefined there (NaN: no stick-slip, a failed
    run, ...).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plan = spec if isinstance(spec, Sweep) else load_sweep(spec)
    table = read_results(results) if not isinstance(results, Mapping) else results
    names = list(metrics) if metrics is not None else [metric.name for metric in plan.metrics]
    units = {metric.name: metric.unit for metric in plan.metrics}
    rows = len(table["run"])
    failed = sum(status != "ok" for status in table["status"])
    shown = np.ones(rows, dtype=bool)
    note = ""
    x_axis = plan.axes[0]
    y_axis = plan.axes[1] if len(plan.axes) > 1 else None
    if len(plan.axes) > 2 and plan.method == "grid":
        fixed = []
        for axis in plan.axes[2:]:
            first = axis.grid()[0]
            shown &= np.array([value == first for value in table[axis.key]], dtype=bool)
            fixed.append(f"{axis.key} = {first:g}" if isinstance(first, float)
                         else f"{axis.key} = {first}")
        note = "at " + ", ".join(fixed)
    columns = 2 if len(names) == 4 else min(3, len(names))
    lines = math.ceil(len(names) / columns)
    figure, panels = plt.subplots(lines, columns, figsize=(4.6 * columns, 3.7 * lines),
                                  squeeze=False, layout="constrained")
    x_all, x_labels, x_log = _numeric_positions(x_axis, table[x_axis.key])
    x = np.asarray(x_all, dtype=np.float64)[shown]
    if y_axis is not None:
        y_all, y_labels, y_log = _numeric_positions(y_axis, table[y_axis.key])
        y = np.asarray(y_all, dtype=np.float64)[shown]
    for panel, metric in zip(panels.flat, names):
        values = np.asarray(table[metric], dtype=np.float64)[shown]
        label = f"{metric} [{units.get(metric, '')}]"
        if y_axis is None:
            order = np.argsort(x, kind="stable")
            panel.plot(x[order], values[order], marker="o", markersize=3, linewidth=1.2)
            panel.set_ylabel(label)
            panel.set_title(metric, fontsize=10)
        else:
            colours = plt.get_cmap("viridis").with_extremes(bad="0.85")
            if plan.method == "grid":
                x_centres = np.unique(x)
                y_centres = np.unique(y)
                grid = np.full((y_centres.size, x_centres.size), np.nan)
                grid[np.searchsorted(y_centres, y), np.searchsorted(x_centres, x)] = values
                image = panel.pcolormesh(_edges(x_centres, x_log), _edges(y_centres, y_log),
                                         np.ma.masked_invalid(grid), cmap=colours,
                                         shading="flat")
            else:
                panel.scatter(x[np.isnan(values)], y[np.isnan(values)], s=14, color="0.7",
                              marker="x", linewidths=0.8)
                image = panel.scatter(x, y, c=values, s=18, cmap=colours, plotnonfinite=False)
            figure.colorbar(image, ax=panel, label=label)
            panel.set_title(metric, fontsize=10)
            panel.set_ylabel(y_axis.key)
            if y_log:
                panel.set_yscale("log")
            if y_labels is not None:
                panel.set_yticks(range(len(y_labels)), [os.path.basename(v) for v in y_labels])
        panel.set_xlabel(x_axis.key)
        if x_log:
            panel.set_xscale("log")
        if x_labels is not None:
            panel.set_xticks(range(len(x_labels)), [os.path.basename(v) for v in x_labels])
    for panel in list(panels.flat)[len(names):]:
        panel.set_visible(False)
    heading = title or f"{plan.name}: {rows} of {plan.runs} runs"
    extras = [part for part in (note, f"{failed} failed" if failed else "",
                                "grey: undefined" if y_axis is not None else "") if part]
    figure.suptitle(heading + (f" ({'; '.join(extras)})" if extras else ""), fontsize=10)
    buffer = BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    plt.close(figure)
    atomic_write_bytes(path, buffer.getvalue())
