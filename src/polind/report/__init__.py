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

The package holds one module per part of the report:

* :mod:`polind.report.captions`: the title, description and figure files
  of each phenomenon (:data:`~polind.report.captions.TITLES`,
  :data:`~polind.report.captions.DESCRIPTIONS`,
  :data:`~polind.report.captions.FIGURES`);
* :mod:`polind.report.figures`: the PNGs (:func:`render_figures`);
* :mod:`polind.report.summary`: ``metrics.json`` (:func:`metrics_document`)
  and the summary table (:func:`summary_table`);
* :mod:`polind.report.page`: ``report.html`` (:func:`render_html`);
* :mod:`polind.report.writer`: writing them all (:func:`write_report`).

Every public name is importable from :mod:`polind.report` itself.
"""

from polind.report.captions import DESCRIPTIONS, FIGURES, TITLES
from polind.report.figures import SET_UP_1995, is_1995_set_up, reference_label, render_figures
from polind.report.page import render_html
from polind.report.summary import headline, metrics_document, summary_table
from polind.report.writer import check_targets, file_names, write_report

__all__ = [
    "TITLES",
    "DESCRIPTIONS",
    "FIGURES",
    "SET_UP_1995",
    "write_report",
    "check_targets",
    "file_names",
    "render_figures",
    "is_1995_set_up",
    "reference_label",
    "metrics_document",
    "headline",
    "summary_table",
    "render_html",
]
