"""Figures, ``metrics.json`` and the self-contained HTML report of ``polind demo``.

Input: the results of :mod:`polind.phenomena` for several models, as
``{phenomenon: {model label: PhenomenonResult}}`` (every phenomenon of
:ref:`guide-phenomena` run on every model).  Output, in one directory
(``polind demo``, :ref:`guide-demo`; :ref:`formats-results`):

* one PNG per figure (``stribeck.png``, ``presliding_memory.png``,
  ``frictional_lag.png``, ``non_drifting.png``, ``stick_slip.png``,
  ``stick_slip_reference.png``, ``breakaway.png``);
* ``metrics.json``: one object per phenomenon, under the keys ``stribeck``,
  ``presliding_memory``, ``frictional_lag``, ``non_drifting``,
  ``stick_slip``, ``breakaway``, each with ``passed`` (the phenomenon appears
  in the subject model, Pol-Ind), ``as_expected`` (every model behaves as
  the user guide says, :ref:`guide-choosing-table`) and per model the numbers its figure shows;
* ``report.html``: a page that opens offline -- the figures embedded as
  base64 data URIs, no external CSS, script or link -- with, per
  phenomenon, what to see, the metrics and the parameter values used.

Every file is written atomically (:func:`polind.io.atomic_write_bytes`).
matplotlib is imported inside the plotting functions, with the Agg backend,
so ``import polind`` stays fast (it does not load matplotlib).
"""

from __future__ import annotations

import base64
import html
import io as _bytes_io
import json
import os

import numpy as np

from polind.io import atomic_write_bytes, atomic_write_text, check_output_path, model_file_text
from polind.phenomena import MEMORY_TOLERANCE, PHENOMENA

__all__ = ["TITLES", "DESCRIPTIONS", "FIGURES", "write_report", "metrics_document",
           "summary_table", "render_html"]

TITLES = {
    "stribeck": "Stribeck effect",
    "presliding_memory": "Presliding hysteresis with non-local memory",
    "frictional_lag": "Sliding hysteresis (frictional lag)",
    "non_drifting": "Non-drifting under an oscillating force below break-away",
    "stick_slip": "Stick-slip",
    "breakaway": "Break-away force versus force rate",
}

#: One sentence per phenomenon: what the figure shows and what to look for.
DESCRIPTIONS = {
    "stribeck": "Each model slides at constant velocities from 1e-3 vs to 1e3 vs until its "
                "force is steady (markers); the line is the analytic steady curve "
                "g(v) + sigma2 v. Look for the dip from the static level Fs at low velocity "
                "down to the Coulomb level Fc, and for the markers sitting on the line. "
                "Maxwell-slip is rate independent: its steady force is flat.",
    "presliding_memory": "The displacement goes to +A (virgin curve), back to -A, then through "
                         "loops nested inside that major loop, all within the presliding "
                         "range. Where a loop comes back to the reversal point it started "
                         "from, an open circle marks a loop that closes there (its force "
                         f"equals the force the path had at that point, within "
                         f"{MEMORY_TOLERANCE:g} of the loop's span) and a square one that "
                         "does not, the gap dotted. "
                         "With non-local memory (the Maxwell-slip family) every loop closes, "
                         "is wiped out, and the path continues on the branch it would have "
                         "followed without the loop (dashed). LuGre's loops do not close.",
    "frictional_lag": "The velocity oscillates as v0 + va sin(2 pi f t), always positive; each "
                      "loop is the force over one period at one frequency, the dashed line "
                      "the steady curve. Look for loops that circulate clockwise in this "
                      "plane, as the arrows show (the force is higher while the velocity "
                      "rises than while it falls), shrink onto the steady curve as f falls "
                      "and open up as f rises. Maxwell-slip has no loop.",
    "non_drifting": "A body pushed by 0.5 Fc + 0.4 Fc sin(2 pi t), always below break-away. "
                    "The curve is its position, the dots the mean position of each cycle. "
                    "The Maxwell-slip family shakes down: the cycle means stop moving. LuGre "
                    "creeps forward by the same step every cycle (Dupont et al. 2002).",
    "stick_slip": "A body pulled through a spring at a constant drive velocity; the curves are "
                  "the spring force. Left: from rest, the set-up of Canudas de Wit et al. "
                  "(1995), m = 1 kg, k_d = 2 N/m, v_d = 0.1 m/s, scaled to each model's "
                  "force level (m and k_d times Fc / 1 N, v_d = 100 vs): LuGre with the "
                  "1995 parameters runs it as published, the other models a heavier body on a "
                  "stiffer spring (each panel's title gives m and k_d). Middle and right: "
                  "the body starts in steady sliding with a stiffer spring; at the low drive "
                  "velocity (on the falling branch of the Stribeck curve) sliding is unstable "
                  "and grows into a periodic stick-slip cycle, at the high one it stays "
                  "steady. Maxwell-slip, with no velocity weakening, never stick-slips.",
    "breakaway": "The applied force rises at a constant rate from zero; the body has broken "
                 "away when its velocity reaches the threshold (vs). Left: the applied force at "
                 "break-away over Fs, per rate. Right: the velocity of the subject model's body "
                 "against the applied force for each rate. Look for break-away at Fs for slow "
                 "ramps, and for how it moves with the rate.",
}

#: PNG files of each phenomenon (the first is the phenomenon's main figure).
FIGURES = {
    "stribeck": ("stribeck.png",),
    "presliding_memory": ("presliding_memory.png",),
    "frictional_lag": ("frictional_lag.png",),
    "non_drifting": ("non_drifting.png",),
    "stick_slip": ("stick_slip.png", "stick_slip_reference.png"),
    "breakaway": ("breakaway.png",),
}

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


def _run_title(label, run, metrics) -> str:
    """The three title lines of a stick-slip panel: the run, its body and spring, the verdict.

    "1995 set-up" only where the run is that set-up (m = 1 kg, k_d = 2 N/m,
    v_d = 0.1 m/s); the reference runs of other models are it scaled to
    their force level.
    """
    body = (metrics["mass"], metrics["spring_stiffness"], metrics["drive_velocity"])
    which = _RUN_TITLES[run] + (" (the 1995 set-up)" if body == SET_UP_1995 else "")
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
    """``{file name: PNG bytes}`` for every figure of :data:`FIGURES`."""
    figures = {
        "stribeck.png": _figure_stribeck(results["stribeck"]),
        "presliding_memory.png": _figure_presliding_memory(results["presliding_memory"]),
        "frictional_lag.png": _figure_frictional_lag(results["frictional_lag"]),
        "non_drifting.png": _figure_non_drifting(results["non_drifting"]),
        "stick_slip.png": _figure_stick_slip(results["stick_slip"]),
        "breakaway.png": _figure_breakaway(results["breakaway"], subject),
    }
    reference = _reference_label(results["stick_slip"])
    figures["stick_slip_reference.png"] = _figure_stick_slip_reference(
        results["stick_slip"][reference], reference)
    return {name: _png(fig) for name, fig in figures.items()}


def _reference_label(stick_slip_results):
    """The model whose stick-slip reference run gets its own figure: LuGre (the 1995 case)."""
    for label, result in stick_slip_results.items():
        if result.model_type == "lugre":
            return label
    return next(iter(stick_slip_results))


# --- metrics.json -------------------------------------------------------------------------

def metrics_document(results, subject) -> dict:
    """The ``metrics.json`` document: the six phenomena, each with ``passed`` and per model.

    ``passed`` is whether the phenomenon appears in the subject model (the
    default Pol-Ind model of ``polind demo``); ``as_expected`` whether every
    model behaves as the user guide says (the phenomenon appears exactly in the
    models credited with it; :ref:`guide-choosing-table`).
    """
    document = {}
    for phenomenon in PHENOMENA:
        per_model = results[phenomenon]
        document[phenomenon] = {
            "passed": bool(per_model[subject].passed),
            "as_expected": all(result.as_expected for result in per_model.values()),
            "subject": subject,
            "description": DESCRIPTIONS[phenomenon],
            "figures": list(FIGURES[phenomenon]),
            "models": {label: dict(result.to_dict(), model_type=result.model_type)
                       for label, result in per_model.items()},
        }
    return document


# --- the summary table ----------------------------------------------------------------------

def _headline(result) -> str:
    """The one number that sums up a result, for the summary table."""
    m = result.metrics
    if result.phenomenon == "stribeck":
        return f"dip {m['dip']:.0%}"
    if result.phenomenon == "presliding_memory":
        gap = m["closure_mismatch"]
        return f"gap {gap:.0e}" if gap >= 1e-15 else "gap 0"
    if result.phenomenon == "frictional_lag":
        area = m["relative_area"][-1]
        return f"area {area:.0e}" if area else "area 0"
    if result.phenomenon == "non_drifting":
        return f"{m['last_advance'] * 1e6:+.2g} µm/cyc"
    if result.phenomenon == "stick_slip":
        period = m["low"]["period"]
        return f"T {period:.2g} s" if m["low"]["sticks_and_slips"] else "no cycle"
    return f"{m['breakaway_ratio'][0]:.3f} Fs"


def summary_table(results) -> str:
    """Model x phenomenon as text: ``yes``/``no`` (the phenomenon appears) and its metric.

    A ``!`` marks a result that contradicts the user guide (a phenomenon that
    appears where it should not, or is missing where it should be;
    :ref:`guide-choosing-table`).
    """
    labels = list(next(iter(results.values())))
    cells = {phenomenon: {label: ("yes " if result.passed else "no  ") + _headline(result)
                          + ("" if result.as_expected else " !")
                          for label, result in results[phenomenon].items()}
             for phenomenon in PHENOMENA}
    widths = [max(len(label), *(len(cells[p][label]) for p in PHENOMENA)) for label in labels]
    first = max(len(p) for p in PHENOMENA)
    lines = ["phenomenon".ljust(first) + "  " + "  ".join(
        label.ljust(width) for label, width in zip(labels, widths))]
    lines.append("-" * len(lines[0]))
    for phenomenon in PHENOMENA:
        lines.append(phenomenon.ljust(first) + "  " + "  ".join(
            cells[phenomenon][label].ljust(width) for label, width in zip(labels, widths)))
    lines.append("yes/no: the phenomenon appears; ! where that contradicts the user guide "
                 "('Which model shows which phenomenon')")
    return "\n".join(line.rstrip() for line in lines)


# --- report.html ----------------------------------------------------------------------------

_STYLE = """
body { font-family: sans-serif; max-width: 1200px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ccc; }
img { max-width: 100%; height: auto; border: 1px solid #ddd; margin: 0.5em 0; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; }
.yes { color: #1a7f37; font-weight: bold; } .no { color: #555; font-weight: bold; }
.unexpected { background: #fde2e2; }
.note { color: #444; font-size: 0.92em; }
code, pre { font-family: monospace; font-size: 0.9em; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; }
pre.model-file { max-height: 24em; overflow-y: auto; }
"""


def _format(value) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        if len(value) > 8:
            return f"{len(value)} values, {_format(value[0])} ... {_format(value[-1])}"
        return ", ".join(_format(item) for item in value)
    if value is None:
        return "-"
    return html.escape(str(value))


#: Units of the metrics (the last part of a metric's name), shown in the tables.
_UNITS = {
    "force_at_lowest_velocity": "N", "minimum_force": "N", "force_at_highest_velocity": "N",
    "velocity_at_minimum": "m/s", "velocity": "m/s", "force": "N", "major_loop_span": "N",
    "amplitude": "m", "frequency": "Hz", "loop_area": "N m/s", "advance_per_cycle": "m",
    "first_advance": "m", "last_advance": "m", "steady_advance": "m",
    "cycle_mean_position": "m", "drive_velocity": "m/s", "spring_stiffness": "N/m",
    "mass": "kg", "period": "s", "spring_force_amplitude": "N", "spring_force_range": "N",
    "rate": "N/s", "breakaway_force": "N", "breakaway_displacement": "m", "static_force": "N",
}


def _unit(key) -> str:
    unit = _UNITS.get(key.rsplit(".", 1)[-1])
    return f" [{unit}]" if unit else ""


def _metrics_rows(result) -> list:
    """(name, value) rows of a result's metrics, nested runs flattened with a dot."""
    rows = []
    for key, value in result.to_dict().items():
        if key in ("passed", "expected", "as_expected", "note", "settings"):
            continue
        if isinstance(value, dict):
            rows.extend((f"{key}.{sub}", item) for sub, item in value.items())
        else:
            rows.append((key, value))
    return rows


def _result_table(per_model) -> str:
    labels = list(per_model)
    rows_by_label = {label: dict(_metrics_rows(result)) for label, result in per_model.items()}
    keys = []
    for label in labels:
        keys.extend(key for key in rows_by_label[label] if key not in keys)
    head = "".join(f"<th>{html.escape(label)}</th>" for label in labels)
    out = [f"<table><tr><th>metric</th>{head}</tr>"]
    verdict = "".join(
        f"<td class=\"{'' if r.as_expected else 'unexpected'}\">"
        f"<span class=\"{'yes' if r.passed else 'no'}\">{'appears' if r.passed else 'does not appear'}"
        f"</span> (expected: {'yes' if r.expected else 'no'})</td>" for r in per_model.values())
    out.append(f"<tr><th>phenomenon</th>{verdict}</tr>")
    for key in keys:
        cells = "".join(f"<td>{_format(rows_by_label[label].get(key))}</td>" for label in labels)
        out.append(f"<tr><td><code>{html.escape(key)}</code>{_unit(key)}</td>{cells}</tr>")
    notes = "".join(f"<td class=\"note\">{html.escape(r.note)}</td>" for r in per_model.values())
    out.append(f"<tr><th>reading</th>{notes}</tr></table>")
    return "\n".join(out)


def _settings_list(per_model) -> str:
    items = []
    for label, result in per_model.items():
        text = "; ".join(f"{html.escape(str(key))} = {_format(value)}"
                         for key, value in _plain_settings(result.settings).items())
        items.append(f"<li><b>{html.escape(label)}</b>: {text}</li>")
    return "<ul class=\"note\">" + "".join(items) + "</ul>"


def _plain_settings(settings):
    return {key: (float(value) if isinstance(value, np.floating) else value)
            for key, value in settings.items()}


def _summary_html(results, subject) -> str:
    labels = list(next(iter(results.values())))
    head = "".join(f"<th>{html.escape(label)}</th>" for label in labels)
    rows = [f"<table><tr><th>phenomenon</th>{head}</tr>"]
    for phenomenon in PHENOMENA:
        cells = []
        for label in labels:
            result = results[phenomenon][label]
            css = "" if result.as_expected else " class=\"unexpected\""
            word = "yes" if result.passed else "no"
            cells.append(f"<td{css}><span class=\"{word}\">{word}</span> "
                         f"{html.escape(_headline(result))}</td>")
        rows.append(f"<tr><td><a href=\"#{phenomenon}\">{TITLES[phenomenon]}</a></td>"
                    + "".join(cells) + "</tr>")
    rows.append("</table>")
    return "\n".join(rows)


def render_html(results, images, models, subject, *, title="polind demo") -> str:
    """The report page: summary, models and their parameters, one section per phenomenon.

    Parameters
    ----------
    results : dict
        ``{phenomenon: {label: PhenomenonResult}}``.
    images : dict
        ``{file name: PNG bytes}``, embedded as base64 data URIs.
    models : dict
        ``{label: {"description": str, "parameters": dict}}`` shown in the
        parameter section, ``parameters`` the ``[model]`` table: each is
        shown as the model file it makes (:func:`polind.io.model_file_text`).
    subject : str
        The label of the model whose result is each phenomenon's ``passed``.
    """
    parts = [
        "<!DOCTYPE html>",
        "<html lang=\"en\"><head><meta charset=\"utf-8\">",
        f"<title>{html.escape(title)}</title>",
        f"<style>{_STYLE}</style></head><body>",
        f"<h1>{html.escape(title)}: the friction phenomena of the Pol-Ind model</h1>",
        "<p>The six friction phenomena of the user guide ('Friction phenomena'), each run on "
        "the default Pol-Ind model "
        "beside the classical models it is compared with. Every experiment is sized by the "
        "model's own scales (its static and Coulomb forces, Stribeck velocity, presliding "
        "range and lag time). <b>yes</b> means the phenomenon appears in that model's run; a "
        "red cell marks a result that contradicts what the user guide ('Which model shows "
        "which phenomenon') says the model does "
        "(LuGre is expected to drift and to lack non-local memory; Maxwell-slip, being "
        "rate independent, to show neither a Stribeck effect, frictional lag nor "
        "stick-slip).</p>",
        "<h2 id=\"summary\">Summary</h2>",
        _summary_html(results, subject),
        "<h2 id=\"models\">Models and parameters</h2>",
        "<p class=\"note\">Each block is a complete model file: save it as a <code>.toml</code> "
        "file and read it with <code>polind.load_model</code> or give it to the command "
        "line (<code>polind simulate MODEL ...</code>).</p>",
    ]
    for label, info in models.items():
        parts.append(f"<h3>{html.escape(label)}</h3>")
        if info.get("description"):
            parts.append(f"<p class=\"note\">{html.escape(info['description'])}</p>")
        parts.append("<pre class=\"model-file\">"
                     + html.escape(model_file_text({"model": info.get("parameters", {})}))
                     + "</pre>")
    for phenomenon in PHENOMENA:
        per_model = results[phenomenon]
        verdict = "appears" if per_model[subject].passed else "does not appear"
        parts.append(f"<h2 id=\"{phenomenon}\">{TITLES[phenomenon]}</h2>")
        parts.append(f"<p>{html.escape(DESCRIPTIONS[phenomenon])}</p>")
        parts.append(f"<p>In {html.escape(subject)} the phenomenon <b>{verdict}</b>.</p>")
        for name in FIGURES[phenomenon]:
            encoded = base64.b64encode(images[name]).decode("ascii")
            parts.append(f"<img alt=\"{html.escape(TITLES[phenomenon])} ({name})\" "
                         f"src=\"data:image/png;base64,{encoded}\">")
        parts.append(_result_table(per_model))
        parts.append("<p class=\"note\">Settings used:</p>")
        parts.append(_settings_list(per_model))
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


# --- writing it all -------------------------------------------------------------------------

def file_names() -> list:
    """The names of the files a report writes: every figure, ``metrics.json``, ``report.html``."""
    return [name for names in FIGURES.values() for name in names] + ["metrics.json",
                                                                     "report.html"]


def check_targets(out_dir) -> None:
    """InputError if any file of a report cannot be written into ``out_dir`` (a directory in the way...)."""
    for name in file_names():
        check_output_path(os.path.join(out_dir, name))


def write_report(results, out_dir, *, models=None, subject=None, title="polind demo") -> dict:
    """Write the PNGs, ``metrics.json`` and ``report.html`` into ``out_dir`` (created if needed).

    Parameters
    ----------
    results : dict
        ``{phenomenon: {model label: PhenomenonResult}}`` with every key of
        :data:`polind.phenomena.PHENOMENA` and the same labels throughout.
    out_dir : str or os.PathLike
    models : dict, optional
        ``{label: {"description": str, "parameters": dict}}`` for the page.
    subject : str, optional
        The label whose result sets each phenomenon's ``passed``; default
        the first label.

    Returns
    -------
    dict
        ``{"out_dir", "files": [names], "metrics": metrics document}``.
    """
    missing = [phenomenon for phenomenon in PHENOMENA if phenomenon not in results]
    if missing:
        raise ValueError(f"write_report needs every phenomenon; missing: {', '.join(missing)}")
    subject = subject or next(iter(results["stribeck"]))
    os.makedirs(out_dir, exist_ok=True)
    images = render_figures(results, subject)
    metrics = metrics_document(results, subject)
    page = render_html(results, images, models or {}, subject, title=title)
    # Everything is rendered; check every target before the first write, so that
    # a report is written whole or not at all.
    check_targets(out_dir)
    for name, data in images.items():
        atomic_write_bytes(os.path.join(out_dir, name), data)
    atomic_write_text(os.path.join(out_dir, "metrics.json"),
                      json.dumps(metrics, indent=2, allow_nan=False) + "\n")
    atomic_write_text(os.path.join(out_dir, "report.html"), page)
    return {"out_dir": os.fspath(out_dir),
            "files": sorted(images) + ["metrics.json", "report.html"], "metrics": metrics}
