"""Writing a report: the PNGs, ``metrics.json`` and ``report.html`` into one directory.

:func:`write_report` renders everything first (:mod:`polind.report.figures`,
:mod:`polind.report.summary`, :mod:`polind.report.page`), checks every
target (:func:`check_targets`), then writes each file atomically
(:func:`polind.io.atomic_write_bytes`): a report is written whole or not at
all.
"""

from __future__ import annotations

import json
import os

from polind.io import atomic_write_bytes, atomic_write_text, check_output_path
from polind.phenomena import PHENOMENA
from polind.report.captions import FIGURES
from polind.report.figures import render_figures
from polind.report.page import render_html
from polind.report.summary import metrics_document

__all__ = ["file_names", "check_targets", "write_report"]


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
        :data:`polind.phenomena.PHENOMENA <polind.phenomena.common.PHENOMENA>`
        and the same labels throughout.
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
