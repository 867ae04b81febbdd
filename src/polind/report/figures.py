"""The report's figures: one PNG per phenomenon, and the stick-slip reference run.

:func:`render_figures` draws every file of
:data:`~polind.report.captions.FIGURES` from the results of
:mod:`polind.phenomena`: ``stribeck.png``, ``presliding_memory.png``,
``frictional_lag.png``, ``non_drifting.png``, ``stick_slip.png``,
``stick_slip_reference.png`` (the run chosen by :func:`reference_label`)
and ``breakaway.png``.  matplotlib is imported inside the plotting
functions, with the Agg backend, so ``import polind`` stays fast (it does
not load matplotlib).
"""

from __future__ import annotations

import io as _bytes_io

import numpy as np

from polind.report.captions import TITLES

__all__ = ["SET_UP_1995", "is_1995_set_up", "reference_label", "render_figures"]

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")
_MARKERS = ("o", "s", "^", "D", "v", "P")


# --- matplotlib, lazily ------------------------------------------------------------------

def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _png(fig) -> bytes:
    """The figure as PNG bytes (no software tag in the metadata), then closed."""
    plt = _pyplot()
    buffer = _bytes_io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, metadata={"Software": None})
    plt.close(fig)
    return buffer.getvalue()


def _grid(count, width=11.0, height=3.6):
    plt = _pyplot()
    columns = 2 if count > 1 else 1
    rows = (count + columns - 1) // columns
    fig, axes = plt.subplots(rows, columns, figsize=(width, height * rows), squeeze=False)
    flat = axes.ravel()
    for extra in flat[count:]:
        extra.set_visible(False)
    return fig, flat[:count]


def _annotate(ax, text, y=0.95, va="top"):
    """A small text box in the upper left corner of an axes."""
    ax.text(0.03, y, text, transform=ax.transAxes, fontsize=8, va=va,
            bbox={"facecolor": "white", "edgecolor": "0.8", "alpha": 0.85})


def _finish_panel(ax, label, result, xlabel, ylabel, legend="upper right", legend_size=8,
                  detail=None):
    """Labels, a title saying whether the phenomenon appears, legend and grid.

    ``detail`` is a second title line (the panel's numbers: above the axes,
    where it covers no curve); ``legend=None`` leaves the legend to the
    figure (:func:`_finish_figure`).
    """
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    title = f"{label}: {'appears' if result.passed else 'does not appear'}"
    ax.set_title(title if detail is None else f"{title}\n{detail}", fontsize=10)
    if legend is not None:
        ax.legend(fontsize=legend_size, loc=legend)
    ax.grid(True, which="both", alpha=0.3)


def _finish_figure(fig, title, legend=None):
    """The title, and ``legend`` (matplotlib handles with labels) as one row below the panels."""
    fig.suptitle(title)
    if legend:
        fig.legend(handles=legend, loc="lower center", ncol=len(legend), fontsize=8,
                   frameon=False)
        # The legend's height in figure units, kept free below the panels.
        bottom = 0.35 / fig.get_size_inches()[1]
        fig.tight_layout(rect=(0.0, bottom, 1.0, 1.0))
    else:
        fig.tight_layout()
    return fig


def _key(label, **style):
    """A legend entry for a figure's legend (a line or marker that is not in any axes)."""
    from matplotlib.lines import Line2D

    return Line2D([], [], label=label, **style)


# --- one figure per phenomenon ---------------------------------------------------------------

def _figure_stribeck(results):
    fig, axes = _grid(len(results))
    for ax, (label, result), colour in zip(axes, results.items(), _COLOURS):
        d = result.data
        ax.semilogx(d["curve_velocity"], d["curve_force"], "-", color="0.3", lw=1,
                    label="analytic g(v) + sigma2 v")
        ax.semilogx(d["velocity"], d["force"], "o", color=colour, ms=4,
                    label="simulated, steady")
        m = result.metrics
        _annotate(ax, f"dip {m['dip']:.1%}\nmax deviation {m['max_relative_deviation']:.1e}",
                  y=0.05, va="bottom")
        _finish_panel(ax, label, result, "sliding velocity v [m/s]",
                      "steady friction force F [N]")
    return _finish_figure(fig, TITLES["stribeck"])


def _fraction(value) -> str:
    """A fraction for a title: ``0``, a percentage from 0.1 %, else ``1.2e-05``."""
    if value == 0.0:
        return "0"
    return f"{100.0 * value:.2g}%" if value >= 1e-3 else f"{value:.1e}"


_CLOSES = {"marker": "o", "mfc": "none", "mec": "k", "ms": 10, "ls": "none"}
_STAYS_OPEN = {"marker": "s", "mfc": "none", "mec": "k", "ms": 8, "mew": 1.5, "ls": "none"}


def _figure_presliding_memory(results):
    fig, axes = _grid(len(results), height=4.0)
    for ax, (label, result), colour in zip(axes, results.items(), _COLOURS):
        d = result.data
        scale, unit = _length_unit(float(np.max(np.abs(d["x"]))))
        x, force = d["x"] / scale, d["force"]
        ax.plot(x, force, "-", color=colour, lw=1.2)
        corners = d["corners"]
        ax.plot(x[corners], force[corners], "k.", ms=6)
        closes = result.metrics["loops_close"]
        for (close, reversal, _), closed in zip(d["closures"], closes):
            k, start = corners[close], corners[reversal]
            if closed:
                ax.plot(x[k], force[k], **_CLOSES)
            else:
                # Where the path came back to the loop's starting displacement, and the
                # gap to the force it had there.
                ax.plot([x[k], x[start]], [force[k], force[start]], ":", color="k", lw=1.2)
                ax.plot(x[k], force[k], **_STAYS_OPEN)
        for x_ref, f_ref in d["reference_branches"]:
            ax.plot(x_ref / scale, f_ref, "--", color="0.4", lw=1)
        detail = (f"{sum(closes)} of {len(closes)} inner loops close; largest gap "
                  f"{_fraction(result.metrics['closure_mismatch'])} of a loop's span")
        _finish_panel(ax, label, result, f"displacement x [{unit}]", "friction force F [N]",
                      legend=None, detail=detail)
    legend = [_key("force along the path", color="0.3", lw=1.2),
              _key("reversal points", color="k", marker=".", ms=6, ls="none"),
              _key("a loop closes on its reversal point", **_CLOSES),
              _key("a loop returns, but does not close (gap dotted)", **_STAYS_OPEN),
              _key("branch without the inner loops", color="0.4", ls="--", lw=1)]
    return _finish_figure(fig, TITLES["presliding_memory"], legend=legend)


def _figure_frictional_lag(results):
    plt = _pyplot()
    fig, axes = _grid(len(results), height=4.0)
    for ax, (label, result) in zip(axes, results.items()):
        d = result.data
        frequencies = result.metrics["frequency"]
        colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(frequencies)))
        areas = result.metrics["loop_area"]
        for number, ((v, force), frequency, colour, area) in enumerate(
                zip(d["loops"], frequencies, colours, areas)):
            ax.plot(v * 1e3, force, "-", color=colour, lw=1.2, label=f"f = {frequency:g} Hz")
            if area != 0.0:
                # spread over -45 to +45 degrees of phase around the v0 crossings
                _direction_arrows(ax, v * 1e3, force, colour,
                                  0.25 * (number / max(len(frequencies) - 1, 1) - 0.5))
        ax.plot(d["curve_velocity"] * 1e3, d["curve_force"], "k--", lw=1, label="steady curve")
        _finish_panel(ax, label, result, "velocity v [mm/s]", "friction force F [N]",
                      legend_size=7)
    return _finish_figure(fig, TITLES["frictional_lag"] + ": v(t) = v0 + va sin(2 pi f t)")


def _direction_arrows(ax, x, y, colour, phase):
    """Two arrowheads on a loop (one per branch) pointing the way it is travelled.

    The loop is one period sampled evenly from ``v = v0`` rising; the arrows
    sit ``phase`` (a fraction of the period) after its start and half a
    period later, so that the arrows of several loops are spread along
    them instead of stacked.
    """
    n = x.shape[0] - 1
    ahead = max(1, n // 40)
    for fraction in (phase, phase + 0.5):
        k = int(round(fraction * n)) % n
        end = min(k + ahead, n)
        ax.annotate("", xy=(x[end], y[end]), xytext=(x[k], y[k]),
                    arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.2,
                                "mutation_scale": 13, "shrinkA": 0, "shrinkB": 0})


def _figure_non_drifting(results):
    fig, axes = _grid(len(results), height=3.8)
    for ax, (label, result), colour in zip(axes, results.items(), _COLOURS):
        d = result.data
        scale, unit = _length_unit(max(np.max(np.abs(d["x"])), 1e-300))
        ax.plot(d["t"], d["x"] / scale, "-", color=colour, lw=0.8)
        cycles = np.arange(d["cycle_mean_position"].shape[0]) + 0.5
        ax.plot(cycles, d["cycle_mean_position"] / scale, "ko", ms=4)
        m = result.metrics
        detail = (f"drift {m['steady_advance'] * 1e6:.3g} µm per cycle" if m["drifts"] else
                  f"advance per cycle: first {m['first_advance']:.2e} m, "
                  f"last {m['last_advance']:.1e} m")
        _finish_panel(ax, label, result, "time t [s]", f"position x [{unit}]", legend=None,
                      detail=detail)
    legend = [_key("position x(t)", color="0.3", lw=0.8),
              _key("mean position of each 1 s cycle", color="k", marker="o", ms=4, ls="none")]
    return _finish_figure(fig, TITLES["non_drifting"] + ": F_a = 0.5 Fc + 0.4 Fc sin(2 pi t)",
                          legend=legend)


def _length_unit(extent):
    for scale, unit in ((1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm")):
        if extent >= scale:
            return scale, unit
    return 1e-12, "pm"


_RUN_TITLES = {"reference": "from rest", "low": "started sliding, low v_d",
               "high": "started sliding, high v_d"}
#: The spring-driven body of Canudas de Wit et al. (1995): mass [kg], k_d [N/m], v_d [m/s].
SET_UP_1995 = (1.0, 2.0, 0.1)


def is_1995_set_up(metrics) -> bool:
    """Whether a stick-slip run is the set-up of Canudas de Wit et al. (1995).

    Parameters
    ----------
    metrics : dict
        The metrics of one run of :func:`polind.phenomena.stick_slip`
        (``result.metrics["reference"]``, ...), with its ``mass``,
        ``spring_stiffness`` and ``drive_velocity``.

    Returns
    -------
    bool
        The run's body and spring are
        :data:`~polind.report.figures.SET_UP_1995` (m = 1 kg, k_d = 2 N/m,
        v_d = 0.1 m/s).
    """
    body = (metrics["mass"], metrics["spring_stiffness"], metrics["drive_velocity"])
    return body == SET_UP_1995


def _run_title(label, run, metrics) -> str:
    """The three title lines of a stick-slip panel: the run, its body and spring, the verdict.

    "1995 set-up" only where the run is that set-up (m = 1 kg, k_d = 2 N/m,
    v_d = 0.1 m/s); the reference runs of other models are it scaled to
    their force level.
    """
    which = _RUN_TITLES[run] + (" (the 1995 set-up)" if is_1995_set_up(metrics) else "")
    verdict = ("sticks and slips" if metrics["sticks_and_slips"] else
               "slides steadily" if metrics["slides_steadily"] else "neither")
    period = f", period {metrics['period']:.3g} s" if metrics["sticks_and_slips"] else ""
    return (f"{label}, {which}\nm = {metrics['mass']:g} kg, k_d = "
            f"{metrics['spring_stiffness']:g} N/m, v_d = {metrics['drive_velocity']:g} m/s\n"
            f"{verdict}{period}")


def _figure_stick_slip(results):
    plt = _pyplot()
    runs = ("reference", "low", "high")
    fig, axes = plt.subplots(len(results), len(runs), figsize=(13.0, 2.9 * len(results)),
                             squeeze=False)
    for row, ((label, result), colour) in enumerate(zip(results.items(), _COLOURS)):
        # One force scale per model, so a steady run looks as flat as it is.
        top = max(float(np.max(result.data[run]["spring_force"])) for run in runs)
        for col, run in enumerate(runs):
            ax = axes[row, col]
            d = result.data[run]
            m = result.metrics[run]
            ax.plot(d["t"], d["spring_force"], "-", color=colour, lw=1)
            ax.set_title(_run_title(label, run, m), fontsize=8.5)
            ax.set_xlabel("time t [s]")
            ax.set_ylabel("spring force [N]")
            ax.set_ylim(0.0, 1.1 * top)
            ax.grid(True, alpha=0.3)
    return _finish_figure(fig, TITLES["stick_slip"] + " (spring-driven body)")


def _figure_stick_slip_reference(result, label):
    plt = _pyplot()
    d = result.data["reference"]
    m = result.metrics["reference"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9.0, 6.0), sharex=True)
    top.plot(d["t"], d["spring_force"], "-", label="spring force k_d (v_d t - x)")
    top.plot(d["t"], d["friction"], "-", lw=0.8, label="friction force F")
    top.set_ylabel("force [N]")
    top.legend(fontsize=8, loc="lower right")
    top.grid(True, alpha=0.3)
    bottom.plot(d["t"], d["v"], "-", color="C2")
    bottom.axhline(m["drive_velocity"], color="0.4", ls="--", lw=1, label="drive velocity v_d")
    bottom.set_xlabel("time t [s]")
    bottom.set_ylabel("velocity v [m/s]")
    # Head room above the velocity peaks for the legend, so that it covers none of them.
    bottom.set_ylim(top=1.35 * max(float(np.max(d["v"])), m["drive_velocity"]))
    bottom.legend(fontsize=8, loc="upper right")
    bottom.grid(True, alpha=0.3)
    period = f"period {m['period']:.3g} s" if m["period"] else "no period"
    return _finish_figure(fig, f"{label}: stick-slip reference case (m = {m['mass']:g} kg, "
                          f"k_d = {m['spring_stiffness']:g} N/m, "
                          f"v_d = {m['drive_velocity']:g} m/s), {period}")


def _figure_breakaway(results, subject):
    plt = _pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, 4.4))
    for (label, result), colour, marker in zip(results.items(), _COLOURS, _MARKERS):
        m = result.metrics
        # The subject's markers are large and open, drawn on top: a model that breaks away
        # where it does (GMS) shows inside them instead of hiding them.
        style = ({"marker": "o", "ms": 11, "mfc": "none", "mew": 1.8, "zorder": 4}
                 if label == subject else {"marker": marker, "ms": 5, "zorder": 3})
        left.semilogx(m["rate"], m["breakaway_ratio"], "-", color=colour, lw=1,
                      label=f"{label} (Fs = {m['static_force']:g} N)", **style)
    left.axhline(1.0, color="0.4", ls="--", lw=1)
    left.set_xlabel("force rate [N/s]")
    left.set_ylabel("break-away force / Fs [-]")
    left.set_title("applied force at break-away", fontsize=10)
    left.legend(fontsize=8)
    left.grid(True, which="both", alpha=0.3)
    result = results[subject]
    fs = result.metrics["static_force"]
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(result.metrics["rate"])))
    for run, rate, colour in zip(result.data["runs"], result.metrics["rate"], colours):
        right.semilogy(run["applied"] / fs, np.maximum(run["v"], 1e-12), "-", color=colour,
                       lw=1, label=f"{rate:.3g} N/s")
    right.axhline(result.settings["threshold_velocity"], color="0.4", ls="--", lw=1,
                  label="break-away threshold")
    right.set_xlim(0.0, 1.5)
    right.set_ylim(1e-9, None)
    right.set_xlabel("applied force / Fs [-]")
    right.set_ylabel("velocity v [m/s]")
    right.set_title(f"{subject}: velocity during the ramp", fontsize=10)
    right.legend(fontsize=8, loc="lower right")
    right.grid(True, which="both", alpha=0.3)
    return _finish_figure(fig, TITLES["breakaway"])


def render_figures(results, subject) -> dict:
    """``{file name: PNG bytes}`` for every figure of :data:`~polind.report.captions.FIGURES`."""
    figures = {
        "stribeck.png": _figure_stribeck(results["stribeck"]),
        "presliding_memory.png": _figure_presliding_memory(results["presliding_memory"]),
        "frictional_lag.png": _figure_frictional_lag(results["frictional_lag"]),
        "non_drifting.png": _figure_non_drifting(results["non_drifting"]),
        "stick_slip.png": _figure_stick_slip(results["stick_slip"]),
        "breakaway.png": _figure_breakaway(results["breakaway"], subject),
    }
    reference = reference_label(results["stick_slip"])
    figures["stick_slip_reference.png"] = _figure_stick_slip_reference(
        results["stick_slip"][reference], reference)
    return {name: _png(fig) for name, fig in figures.items()}


def reference_label(stick_slip_results):
    """The model whose stick-slip reference run gets its own figure.

    Chosen by the data, never by the model's type: the first model whose
    reference run is the published 1995 set-up
    (:func:`~polind.report.figures.is_1995_set_up`; in ``polind demo``
    LuGre with the 1995 parameters), else the first model.

    Parameters
    ----------
    stick_slip_results : dict
        ``{model label: PhenomenonResult}`` of :func:`polind.phenomena.stick_slip`.

    Returns
    -------
    str
        The label.
    """
    for label, result in stick_slip_results.items():
        if is_1995_set_up(result.metrics["reference"]):
            return label
    return next(iter(stick_slip_results))
