"""The report's numbers: the ``metrics.json`` document and the summary table.

:func:`metrics_document` makes the ``metrics.json`` document
(:ref:`formats-results`): per phenomenon, whether it appears in the subject
model, whether every model behaves as the user guide says, and per model
its metrics.  :func:`summary_table` prints model x phenomenon as text;
:func:`headline` is the one number of each cell (the HTML summary of
:mod:`polind.report.page` shows it too).
"""

from __future__ import annotations

from polind.phenomena import PHENOMENA
from polind.report.captions import DESCRIPTIONS, FIGURES

__all__ = ["metrics_document", "headline", "summary_table"]


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

def headline(result) -> str:
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
    cells = {phenomenon: {label: ("yes " if result.passed else "no  ") + headline(result)
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
