"""The report page, ``report.html``: self-contained, one section per phenomenon.

:func:`render_html` writes the page: a summary table, each model's
parameters as a complete model file (:func:`polind.io.model_file_text`),
then per phenomenon what to see, its figures embedded as base64 data URIs,
its metrics and the settings of its runs.  The page opens offline: no
external CSS, script or link.
"""

from __future__ import annotations

import base64
import html

import numpy as np

from polind.io import model_file_text
from polind.phenomena import PHENOMENA
from polind.report.captions import DESCRIPTIONS, FIGURES, TITLES
from polind.report.summary import headline

__all__ = ["render_html"]


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
                         f"{html.escape(headline(result))}</td>")
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
        f"<h1>{html.escape(title)}: the friction phenomena of the {html.escape(subject)} "
        f"model</h1>",
        "<p>The six friction phenomena of the user guide ('Friction phenomena'), each run on "
        f"the {html.escape(subject)} model"
        + (" beside the classical models it is compared with. " if len(models) > 1 else ". ")
        + "Every experiment is sized by the "
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
