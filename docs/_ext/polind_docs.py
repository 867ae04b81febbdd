"""Sphinx extension of polind's documentation: tables made from the code, offline MathJax.

Directives (each reads polind's own declarations at build time, so the pages
cannot drift from what polind reads and writes):

``.. polind-model-keys::``
    One section per registered model type (``polind.MODEL_TYPES``), labelled
    ``formats-model-<type>``, with a table of every key of its ``[model]``
    table and of its nested tables: key, what it is, unit, default, range.
    Built from the ``Param`` and ``Table`` declarations of the model classes.
    A declared key without a description here is a build warning (and so a
    failure of ``tests/test_docs.py``): a new key must be explained.
``.. polind-system-keys::``
    The keys of a ``[system]`` file (``polind.dynamics.FILE_KEYS`` and the
    file reader's schema).
``.. polind-structure-keys::``
    The keys of a structure file (the declarations of
    ``polind.structures.files``: ``STRUCTURE_KEYS``, ``CONTACT_KEYS``,
    ``RUN_KEYS``, ``FORCE_KEYS``).
``.. polind-sweep-keys::`` and ``.. polind-sweep-metrics::``
    The keys of a ``[sweep]`` table and the metrics of ``polind.sweeps.METRICS``.
``.. polind-columns:: motion|data``
    The columns of a motion file and of a measured-data file.
``.. polind-default-bounds::``
    The default bounds of a free parameter by unit
    (``polind.identification.DEFAULT_RANGES``).
``.. polind-model-types::``
    The registered model types with their classes.
``.. polind-data-licence:: FILE`` and ``.. polind-data-file:: FILE``
    The text of a licence file, or any file, of the data polind installs
    (``polind.datasets.data_folder() / FILE``), as a literal block (option
    ``:language:``, default ``text``).

Besides: the API pages of the public names (``write_api_pages``, called from
``conf.py`` before the sources are read, so autosummary sees them), the
gallery's command line (:func:`gallery_argv`) and image scraper
(:class:`PngScraper`), and the copy of MathJax into the build.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import math
import shutil
from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import directives
from docutils.statemachine import StringList
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import nested_parse_with_titles

logger = logging.getLogger(__name__)

RANGES = {
    "positive": "> 0",
    "nonnegative": "≥ 0",
    "any": "any finite number",
    "poisson": "−1 < ν ≤ 0.5",
    "fraction": "0 < value ≤ 1",
    "iwan_exponent": "−1 < χ ≤ 0",
}


def parse_number(value) -> str:
    if isinstance(value, float):
        text = repr(value)
        if text.endswith(".0") and abs(value) < 1e6:
            text = text[:-2]
        return text
    return repr(value) if not isinstance(value, str) else f'"{value}"'


def _default_text(entry, required, table_kind=False) -> str:
    default = entry.default
    if default is required:
        return "required"
    if default is None:
        return "optional table" if table_kind else "optional"
    if table_kind:
        return "optional table"
    if isinstance(default, (list, tuple)):
        return "[" + ", ".join(parse_number(v) for v in default) + "]"
    return parse_number(default)


def _range_text(param) -> str:
    if param.kind == "bool":
        return "``true`` or ``false``"
    if param.kind in ("str", "path"):
        if param.choices:
            return " or ".join(f'``"{choice}"``' for choice in param.choices)
        return "a file name" if param.kind == "path" else "a non-empty string"
    bound = RANGES.get(param.bound, param.bound)
    if param.kind == "int":
        return f"integer, {bound}"
    if param.kind == "list":
        return f"non-empty list, each {bound}"
    if param.kind == "pair":
        return f"two numbers, each {bound}"
    return bound


def _cell(text: str) -> list[str]:
    return [line for line in str(text).splitlines()] or [""]


def list_table(header, rows, widths=None, label=None, css="") -> list[str]:
    """The lines of a ``list-table`` directive (classes ``polind-keys`` and ``css``)."""
    lines = []
    if label:
        lines += [f".. _{label}:", ""]
    lines += [".. list-table::", "   :header-rows: 1",
              "   :class: polind-keys" + (f" {css}" if css else "")]
    if widths:
        lines.append("   :widths: " + " ".join(str(w) for w in widths))
    lines.append("")
    for row in [header] + rows:
        first = True
        for cell in row:
            cell_lines = _cell(cell)
            prefix = "   * - " if first else "     - "
            lines.append(prefix + cell_lines[0])
            lines.extend("       " + extra for extra in cell_lines[1:])
            first = False
    lines.append("")
    return lines


def model_key_rows(model_type, cls, warn=None):
    """``(dotted key, rows)`` of a model's declared keys, nested tables flattened."""
    from polind.models.params import REQUIRED, Table

    rows = []

    def walk(entries, prefix):
        for entry in entries:
            key = prefix + entry.key
            description = entry.description
            if not description and warn is not None:
                warn(f"the key '{key}' of the {model_type} model has no description (its "
                     f"declaration's 'description')")
            symbol = getattr(entry, "symbol", "")
            what = description if not symbol or f":math:`{symbol}`" in description \
                else f":math:`{symbol}` — {description}"
            if isinstance(entry, Table):
                rows.append((key, [f"``[model.{key}]``", what, "", _default_text(
                    entry, REQUIRED, table_kind=True), "table"]))
                walk(entry.entries, key + ".")
            else:
                shown = key.rpartition(".")[2]
                where = f"``{shown}``" if "." not in key else \
                    f"``{shown}`` (in ``[model.{key.rpartition('.')[0]}]``)"
                default = _default_text(entry, REQUIRED)
                if "." in key and default == "required":
                    default = "required in its table"
                rows.append((key, [where, what, entry.unit or "—", default,
                                   _range_text(entry)]))

    walk(cls.parameters, "")
    return rows


def _ordered_types():
    """The registered types in registration order (polind's own first, in the guide's order)."""
    from polind.models.registry import load_plugins

    return list(load_plugins())


def _parse(directive, lines):
    """Parse generated reST lines (with section titles) into nodes."""
    node = nodes.section() if any(line.startswith("---") or line.startswith("~~~")
                                  for line in lines) else nodes.container()
    node.document = directive.state.document
    content = StringList(lines, source=f"<{directive.name}>")
    nested_parse_with_titles(directive.state, content, node)
    return node.children


class ModelKeys(SphinxDirective):
    """One section per registered model type with the table of its keys."""

    has_content = False

    def run(self):
        from polind.models import MODEL_TYPES

        lines = []
        source, line = self.get_source_info()

        def warn(message):
            logger.warning(message, location=(source, line))

        for model_type in _ordered_types():
            cls = MODEL_TYPES[model_type]
            title = f"``{model_type}``: {cls.title or cls.__name__}"
            guide = cls.guide
            lines += [f".. _formats-model-{model_type}:", "", title, "~" * (len(title) + 4), ""]
            intro = f'``type = "{model_type}"``, the class :class:`{cls.__module__}.' \
                    f'{cls.__name__}`' if cls.__module__.startswith("polind.models") is False \
                else f'``type = "{model_type}"``'
            if guide:
                intro += f"; the equations are in :ref:`{guide}`"
            lines += [intro + ".", ""]
            rows = [row for _, row in model_key_rows(model_type, cls, warn)]
            lines += list_table(["key", "what it is", "unit", "default", "range"], rows,
                                widths=[22, 48, 8, 10, 12], css=f"polind-model-{model_type}")
        return _parse(self, lines)


class SystemKeys(SphinxDirective):
    """The keys of a [system] file, from the reader's schema and FILE_KEYS."""

    UNITS = {"mass": "kg", "duration": "s", "time_step": "s",
             "spring_drive.stiffness": "N/m", "spring_drive.velocity": "m/s",
             "force.offset": "N", "force.rate": "N/s", "force.amplitude": "N",
             "force.frequency": "Hz"}
    WHAT = {"mass": r"Mass :math:`m` of the body.",
            "duration": "Length of the run.",
            "time_step": "Output sample spacing and integration step; at most the duration.",
            "spring_drive.stiffness": r"Stiffness :math:`k_d` of the drive spring.",
            "spring_drive.velocity": r"Velocity :math:`v_d` at which the spring's far end "
                                     r"is pulled.",
            "force.offset": r"Constant part of the applied force :math:`F_a(t)`.",
            "force.rate": "Slope of the applied force's ramp.",
            "force.amplitude": "Amplitude of the applied force's sine.",
            "force.frequency": "Frequency of the applied force's sine."}

    def run(self):
        import dataclasses

        from polind import dynamics

        defaults = {item.name: item.default for item in dataclasses.fields(dynamics.System)}
        declarations = getattr(dynamics, "_KEYS", {})
        rows = []
        source, line = self.get_source_info()
        for key, field_name in dynamics.FILE_KEYS.items():
            table, _, name = key.rpartition(".")
            where = "system" + ("." + table if table else "")
            declared = declarations.get(key)
            default = defaults.get(field_name, dataclasses.MISSING)
            required = declared.required if declared is not None \
                else default is dataclasses.MISSING
            default_text = "required" if required else parse_number(float(default))
            bound = RANGES.get(getattr(declared, "bound", "any"), "")
            what = self.WHAT.get(key)
            if what is None:
                logger.warning(f"the [system] key '{key}' has no description in "
                               f"docs/_ext/polind_docs.py", location=(source, line))
                what = ""
            rows.append([f"``{name}`` in ``[{where}]``", what, self.UNITS.get(key, "—"),
                         default_text, bound, f"``{field_name}``"])
        lines = list_table(["key", "what it is", "unit", "default", "range",
                            ":class:`~polind.System` field"], rows,
                           widths=[24, 40, 8, 10, 10, 16])
        return _parse(self, lines)


class StructureKeys(SphinxDirective):
    """The keys of a structure file, from the declarations of polind.structures.files."""

    WHAT = {
        ("structure", "mass"): (
            "kg", "required",
            "The mass matrix :math:`M`, :math:`n \\times n` (a list of rows): symmetric, "
            "positive definite. A number for one coordinate. Its size is :math:`n`."),
        ("structure", "stiffness"): (
            "N/m", "zeros", "The stiffness matrix :math:`K`, :math:`n \\times n`."),
        ("structure", "damping"): (
            "N s/m", "zeros", "The damping matrix :math:`C`, :math:`n \\times n`."),
        ("structure", "contacts"): (
            "—", "required",
            "The contacts, an array of tables ``[[structure.contacts]]``, at least one; "
            "named ``structure.contacts[0]``, ``structure.contacts[1]``, ... in messages."),
        ("structure", "run"): (
            "—", "optional table",
            "The run of ``polind structure`` (and of ``run.simulate(structure)``): "
            "``[structure.run]``, below."),
        ("structure.contacts", "model"): (
            "—", "required",
            "The contact's friction model: a model file (relative to the structure file) "
            "or an inline ``[structure.contacts.model]`` table with the keys of a "
            "``[model]`` table (:ref:`formats-model-files`; its own file keys relative to "
            "the structure file). Every contact of one structure shares one model "
            "family."),
        ("structure.contacts", "dofs"): (
            "—", "required",
            "``[i, j]``: the contact on :math:`u = q_i - q_j` (:math:`-F` on "
            ":math:`q_i`, :math:`+F` on :math:`q_j`); ``[i]``: on :math:`u = q_i`, "
            "against the ground. Coordinates from 0 to :math:`n - 1`."),
        ("structure.run", "kind"): (
            "—", '``"time"``',
            'The kind of run: ``"time"`` (the keys below), ``"frequency_response"`` or '
            '``"backbone"`` (harmonic balance: their keys follow, in the same '
            "``[structure.run]`` table). A key of another kind is refused."),
        ("structure.run", "duration"): ("s", "required", "Length of the run, positive."),
        ("structure.run", "time_step"): (
            "s", "required",
            "Output sample spacing and integration step, positive, at most the duration."),
        ("structure.run", "initial_position"): (
            "m", "zeros", ":math:`q` at :math:`t = 0`: :math:`n` numbers."),
        ("structure.run", "initial_velocity"): (
            "m/s", "zeros", ":math:`\\dot q` at :math:`t = 0`: :math:`n` numbers."),
        ("structure.run", "method"): (
            "—", '``"bdf2"``', '``"bdf2"`` (second order) or ``"euler"`` (backward Euler).'),
        ("structure.run", "force"): (
            "—", "optional table",
            "The applied forces ``[structure.run.force]``: "
            ":math:`f_i(t) = \\text{offset}_i + \\text{amplitude}_i \\sin(2\\pi\\, "
            "\\text{frequency}\\; t)`, the step that ends at :math:`t_k` taking "
            ":math:`f(t_k)`. Without it the structure moves from its initial state alone."),
        ("structure.run.force", "offset"): (
            "N", "zeros", "Constant part of each coordinate's force: :math:`n` numbers."),
        ("structure.run.force", "amplitude"): (
            "N", "zeros",
            "Amplitude of each coordinate's sine: :math:`n` numbers (0 for a coordinate "
            "not driven). Needs ``frequency``."),
        ("structure.run.force", "frequency"): (
            "Hz", "required with ``amplitude``",
            "Frequency of the sine, one for every coordinate, non-negative."),
    }

    #: The keys of the harmonic-balance kinds (polind.structures.frequency_files), by kind.
    HARMONIC_WHAT = {
        ("frequency_response", "omega_range"): (
            "rad/s", "required",
            "``[first, last]``: the fundamental frequencies the curve runs between "
            "(downwards if the first is larger), positive and different; the continuation "
            "follows the curve through its turning points (:func:`polind.frequency_response`)."),
        ("frequency_response", "force"): (
            "N", "required",
            "Each coordinate's force amplitude, :math:`f_i(t) = \\text{force}_i \\cos "
            "\\omega t`: :math:`n` numbers (a number for one coordinate), not all zero."),
        ("frequency_response", "harmonics"): (
            "—", "7", "The harmonics :math:`H` balanced, a positive integer."),
        ("frequency_response", "samples"): (
            "—", "128 (:math:`H \\le 16`)",
            "Samples per period of the contacts' forces (alternating frequency–time), "
            "an integer of at least :math:`4H + 1`; by default the larger of 128 and "
            ":math:`8H` rounded up to a power of two."),
        ("frequency_response", "max_points"): (
            "—", "2000",
            "The most points of the curve, a positive integer. A curve that needs more "
            "stops there: the points found are written and the command exits with "
            "status 2."),
        ("backbone", "amplitudes"): (
            "m kg^0.5", "required",
            "The modal amplitudes :math:`a` (the first harmonic's "
            ":math:`\\sqrt{Q^T M Q}`), a list of positive numbers, solved in increasing "
            "order (:func:`polind.backbone`)."),
        ("backbone", "mode"): (
            "—", "0",
            "Which linear mode (contacts stuck), by increasing frequency: 0 to "
            ":math:`n - 1`."),
        ("backbone", "harmonics"): (
            "—", "7", "The harmonics :math:`H` balanced, a positive integer."),
        ("backbone", "samples"): (
            "—", "128 (:math:`H \\le 16`)",
            "Samples per period, an integer of at least :math:`4H + 1`."),
    }

    def run(self):
        from polind.structures import files, frequency_files

        source, line = self.get_source_info()
        rows = []

        def described(table, key, what):
            if what is None:
                logger.warning(f"the structure file key '{table}.{key}' has no "
                               f"description in docs/_ext/polind_docs.py",
                               location=(source, line))
                return ("", "", "")
            return what

        for table, keys in (("structure", files.STRUCTURE_KEYS),
                            ("structure.contacts", files.CONTACT_KEYS),
                            ("structure.run", files.RUN_KEYS),
                            ("structure.run.force", files.FORCE_KEYS)):
            where = "[[structure.contacts]]" if table == "structure.contacts" \
                else f"[{table}]"
            for key in keys:
                unit, default, what = described(table, key, self.WHAT.get((table, key)))
                label = f"``{key}`` in ``{where}``"
                if table.startswith("structure.run") and key != "kind":
                    label += ', kind ``"time"``'
                rows.append([label, what, unit, default])
        for kind, keys in frequency_files.HARMONIC_KINDS.items():
            for key in keys:
                if key == "kind":
                    continue
                unit, default, what = described(f"structure.run ({kind})", key,
                                                self.HARMONIC_WHAT.get((kind, key)))
                rows.append([f"``{key}`` in ``[structure.run]``, kind ``\"{kind}\"``", what,
                             unit, default])
        return _parse(self, list_table(["key", "what it is", "unit", "default"], rows,
                                       widths=[26, 52, 8, 14]))


class SweepKeys(SphinxDirective):
    """The keys of a [sweep] table."""

    WHAT = {
        "model": "The model file (relative to the sweep file). Required.",
        "system": "A ``[system]`` file: every run is that one-degree-of-freedom system. "
                  "Exactly one of ``system`` and ``motion``.",
        "motion": "A motion file (``t`` and ``x`` or ``v``, optionally ``normal_load``): "
                  "every run is that prescribed motion.",
        "metrics": "The metrics to keep, a non-empty list of names (table below).",
        "method": '``"grid"`` (default), ``"latin-hypercube"`` or ``"random"``.',
        "samples": "The number of runs of a Latin-hypercube or random design (required for "
                   "them).",
        "seed": "The seed of a Latin-hypercube or random design (default 0): the same file "
                "gives the same runs.",
        "parameters": "The table ``[sweep.parameters]`` of the keys to vary (below).",
    }

    def run(self):
        from polind.sweeps import SWEEP_KEYS

        source, line = self.get_source_info()
        rows = []
        for key in SWEEP_KEYS:
            what = self.WHAT.get(key)
            if what is None:
                logger.warning(f"the [sweep] key '{key}' has no description in "
                               f"docs/_ext/polind_docs.py", location=(source, line))
                what = ""
            rows.append([f"``{key}``", what])
        return _parse(self, list_table(["key", "what it is"], rows, widths=[20, 80]))


class SweepMetrics(SphinxDirective):
    """The metrics a sweep can keep (polind.sweeps.METRICS)."""

    def run(self):
        from polind.sweeps import METRICS, NEEDS

        rows = []
        for name, metric in METRICS.items():
            needs = NEEDS.get(metric.needs, "") or "—"
            rows.append([f"``{name}``", metric.unit or "—", needs,
                         metric.definition.replace("*", r"\*")])
        return _parse(self, list_table(["metric", "unit", "needs", "definition"], rows,
                                       widths=[18, 8, 20, 54]))


class Columns(SphinxDirective):
    """The columns of a motion file or a measured-data file."""

    required_arguments = 1
    WHAT = {"t": ("s", "Sample times, strictly increasing and finite."),
            "x": ("m", "Position (displacement) at each sample; the path is linear between "
                       "samples."),
            "v": ("m/s", "Velocity at each sample; the position is its trapezoidal "
                         "integral."),
            "F": ("N", "Measured friction force, positive when it resists positive motion."),
            "normal_load": ("N", "Normal load at each sample (models that use a load; "
                                 "ignored, with a warning, by the others).")}

    def run(self):
        from polind import io

        spec = {"motion": io.MOTION_COLUMNS, "data": io.MEASUREMENT_COLUMNS}[self.arguments[0]]
        rows = []
        for group, text in (("require", "required"), ("one_of", "exactly one of x and v"),
                            ("optional", "optional")):
            for column in spec[group]:
                unit, what = self.WHAT[column]
                rows.append([f"``{column}``", unit, text, what])
        return _parse(self, list_table(["column", "unit", "", "what it is"], rows,
                                       widths=[14, 8, 22, 56]))


class DefaultBounds(SphinxDirective):
    """The default bounds of a free parameter, by its unit."""

    def run(self):
        from polind.identification import DEFAULT_RANGES, UNSCALED_RANGE

        rows = []
        for unit, rule in DEFAULT_RANGES.items():
            rows.append([unit, f"[{rule.low:g}, {rule.high:g}] × scale",
                         rule.words.replace("|", r"\|")])
        rows.append(["any other", f"[{UNSCALED_RANGE[0]:g}, {UNSCALED_RANGE[1]:g}] × the "
                                  f"start", "a decade either side of the starting value"])
        return _parse(self, list_table(["unit", "default bounds", "scale"], rows,
                                       widths=[12, 30, 58]))


class ModelTypes(SphinxDirective):
    """The registered model types and their classes."""

    def run(self):
        from polind.models import MODEL_TYPES

        rows = []
        for model_type in _ordered_types():
            cls = MODEL_TYPES[model_type]
            guide = cls.guide
            rows.append([f"``{model_type}``", cls.title or cls.__name__,
                         f":ref:`keys <formats-model-{model_type}>`",
                         f":ref:`{guide}`" if guide else "—"])
        return _parse(self, list_table(["``type``", "model", "keys", "equations"], rows))


class ModelAdvice(SphinxDirective):
    """A definition list: each registered type with when to use it (``cls.advice``)."""

    def run(self):
        from polind.models import MODEL_TYPES

        lines = []
        for model_type in _ordered_types():
            cls = MODEL_TYPES[model_type]
            text = cls.advice or (cls.purpose[:1].upper() + cls.purpose[1:] + ".")
            lines += [f"``{model_type}``", f"    {text}"]
        return _parse(self, lines + [""])


class DefaultModel(SphinxDirective):
    """The default Pol-Ind model file, as TOML (from ``PolInd.example_parameters()``)."""

    def run(self):
        import tomli_w

        from polind.models import PolInd

        text = tomli_w.dumps({"model": {"type": PolInd.type, **PolInd.example_parameters()}})
        block = nodes.literal_block(text, text)
        block["language"] = "toml"
        return [block]


# --- API pages -------------------------------------------------------------------------------

# Headings of the top-level API page; a name of ``polind.__all__`` that is in none of them
# goes under "More" (so a new public name is documented as soon as it is exported).
API_GROUPS = (
    ("Models and files", ("load_model", "model_from_dict", "save_model", "MODEL_TYPES",
                          "FrictionModel", "register_model", "Param", "Table", "State")),
    ("Prescribed motion", ("simulate", "SimulationResult")),
    ("Your own loop", ("Stepper", "Body", "BodyBatch", "StepKernel", "StepFunctions")),
    ("One-degree-of-freedom systems", ("System", "SystemResult", "load_system",
                                       "simulate_system")),
    ("Identification", ("identify", "FitResult", "identify_maxwell_slip", "identify_gms",
                        "identify_stribeck", "compare", "Comparison")),
    ("Structures", ("Structure", "StructureResult", "simulate_structure", "load_structure",
                    "hysteresis_loop", "HysteresisLoop")),
    ("The frequency domain", ("harmonic_balance", "HarmonicBalanceResult",
                              "frequency_response", "FrequencyResponse", "ContinuationError",
                              "backbone", "Backbone")),
    ("Sweeps", ("sweep", "SweepSummary")),
    ("Errors", ("InputError",)),
)

SUBPACKAGES = (
    ("polind.contact", "Contact mechanics of the Pol-Ind model"),
    ("polind.topography", "Measured surfaces"),
    ("polind.control", "python-control systems"),
    ("polind.fmu", "FMUs for Modelica tools and Simulink"),
    ("polind.structures", "Structures with friction contacts"),
    ("polind.sweeps", "Parameter sweeps"),
    ("polind.datasets", "Measured data shipped with polind"),
)

# Modules documented whole (every public function, class and documented constant), for
# the functions the user guide and the docstrings name in them.
MODULES = (
    ("Files, systems and resources", ("polind.io", "polind.dynamics", "polind.resources",
                                      "polind.validation")),
    ("Running a model", ("polind.simulation",)),
    ("Models and their parameters", ("polind.models", "polind.models.params",
                                     "polind.models.registry", "polind.models.state",
                                     "polind.models.kernel", "polind.models.checks",
                                     "polind.models.pol_ind", "polind.models.pol_ind_fit",
                                     "polind.models.pol_ind_tables")),
    ("Identification and comparison", ("polind.identification",)),
    ("Harmonic balance, module by module", ("polind.structures.harmonic",
                                            "polind.structures.continuation",
                                            "polind.structures.modes")),
    ("The demo", ("polind.phenomena", "polind.demo", "polind.report")),
    ("The phenomena, module by module", ("polind.phenomena.common", "polind.phenomena.steady",
                                         "polind.phenomena.presliding", "polind.phenomena.lag",
                                         "polind.phenomena.drift",
                                         "polind.phenomena.stickslip_runs",
                                         "polind.phenomena.breakaway_ramps")),
    ("The report, module by module", ("polind.report.captions", "polind.report.figures",
                                      "polind.report.summary", "polind.report.page",
                                      "polind.report.writer")),
    ("Contact mechanics, module by module", ("polind.contact.materials",
                                             "polind.contact.asperity",
                                             "polind.contact.greenwood",
                                             "polind.contact.plasticity",
                                             "polind.contact.surface",
                                             "polind.contact.heights",
                                             "polind.contact.separation",
                                             "polind.contact.elements",
                                             "polind.contact.validity",
                                             "polind.contact.ball",
                                             "polind.contact.microslip")),
    ("Measured surfaces, module by module", ("polind.topography.heightmap",
                                             "polind.topography.summits",
                                             "polind.topography.outliers",
                                             "polind.topography.roughness",
                                             "polind.topography.analysis",
                                             "polind.topography_figure")),
    ("Sweeps, module by module", ("polind.sweeps.design", "polind.sweeps.metrics",
                                  "polind.sweeps.runs", "polind.sweeps.results",
                                  "polind.sweeps.engine", "polind.sweeps.cluster",
                                  "polind.sweeps.plot")),
    ("Compiled kernels", ("polind.kernels.contract", "polind.kernels.template",
                          "polind.kernels.generate", "polind.kernels.mount",
                          "polind.kernels.series", "polind.kernels.dynamics",
                          "polind.kernels.structure", "polind.kernels.periodic",
                          "polind.kernels.buffer",
                          "polind.kernels.elements", "polind.kernels.greenwood",
                          "polind.kernels.separation", "polind.kernels.plastic",
                          "polind.kernels.plastic_separation", "polind.kernels.pol_ind",
                          "polind.kernels.pol_ind_plastic", "polind.kernels.pol_ind_fixed",
                          "polind.kernels.special", "polind.kernels.fastexp",
                          "polind.kernels.select", "polind.kernels.interpreted",
                          "polind.kernels.cache")),
)

# Packages of MODULES documented as one module (the names their own modules define are
# theirs, as when they were one file): see _imported_public.
WHOLE_PACKAGES = ("polind.identification", "polind.io")


class DataLicence(SphinxDirective):
    """A file of the shipped data (:mod:`polind.datasets`), as a literal block.

    Read from the polind being documented, so the page shows the file installed
    beside the data, wherever the documentation sources are copied.  The option
    ``:language:`` (default ``text``) highlights it (``toml`` for a data
    description).
    """

    required_arguments = 1
    option_spec = {"language": directives.unchanged}

    def run(self):
        from polind import datasets

        path = datasets.data_folder() / self.arguments[0]
        if not path.is_file():
            raise self.error(f"{self.name}: no file {path}")
        self.env.note_dependency(str(path))
        text = path.read_text(encoding="utf-8").rstrip()
        block = nodes.literal_block(text, text)
        block["language"] = self.options.get("language", "text")
        return [block]


def _autosummary(names, module):
    lines = [f".. currentmodule:: {module}", "", ".. autosummary::", "   :toctree: generated/",
             "   :nosignatures:", ""]
    lines += [f"   {name}" for name in names]
    return lines + [""]


def write_api_pages(docs: Path) -> None:
    """Write ``api/polind.rst`` and one page per public subpackage (generated, not in git)."""
    import inspect

    import polind

    api = docs / "api"
    api.mkdir(exist_ok=True)
    public = list(polind.__all__)
    lines = [".. This page is generated by docs/_ext/polind_docs.py from polind.__all__.", "",
             "``polind``", "==========", "", ".. automodule:: polind", "   :no-members:", ""]
    placed = set()
    for heading, names in API_GROUPS:
        present = [name for name in names if name in public]
        if not present:
            continue
        placed.update(present)
        lines += [heading, "-" * len(heading), ""] + _autosummary(present, "polind")
    rest = [name for name in public if name not in placed]
    if rest:
        lines += ["More", "----", ""] + _autosummary(rest, "polind")
    _write_if_changed(api / "polind.rst", lines)
    for module_name, title in SUBPACKAGES:
        module = importlib.import_module(module_name)
        heading = f"``{module_name}``: {title}"
        page = [f".. This page is generated by docs/_ext/polind_docs.py from "
                f"{module_name}.__all__.", "", heading, "=" * len(heading), "",
                f".. automodule:: {module_name}", "   :no-members:", ""]
        # A class polind exports too (polind.SweepSummary) is listed by its page under
        # polind: a second page would describe it again under its defining module's
        # name (the canonical name of both), a duplicate that Sphinx reports or not
        # depending on how its parallel reading splits the pages.
        shared = [name for name in module.__all__
                  if name in public and inspect.isclass(getattr(module, name))
                  and getattr(polind, name) is getattr(module, name)]
        page += _autosummary([name for name in module.__all__ if name not in shared],
                             module_name)
        if shared:
            page += ["Exported by :mod:`polind` too, and documented there:", ""]
            page += _autosummary(shared, "polind")
        _write_if_changed(api / (module_name.replace(".", "_") + ".rst"), page)
    index = [".. This page is generated by docs/_ext/polind_docs.py (MODULES).", "",
             ".. _api-modules:", "", "More modules", "============", "",
             "Modules documented whole, for the functions, classes and constants that the "
             "user guide and the docstrings name in them.", ""]
    for heading, names in MODULES:
        index += [heading, "-" * len(heading), "", ".. toctree::", "   :maxdepth: 1", ""]
        index += [f"   {name.replace('.', '_')}" for name in names] + [""]
        for name in names:
            module = importlib.import_module(name)
            title = f"``{name}``"
            page = [".. This page is generated by docs/_ext/polind_docs.py (MODULES).", "",
                    title, "=" * len(title), "", f".. automodule:: {name}", "   :members:",
                    "   :ignore-module-all:", ""]
            page += _imported_public(module)
            _write_if_changed(api / (name.replace(".", "_") + ".rst"), page + [""])
    _write_if_changed(api / "modules.rst", index)


def _imported_public(module) -> list[str]:
    """Directives for the names of a module's ``__all__`` that it imports from elsewhere.

    ``automodule`` with ``:ignore-module-all:`` documents what the module defines
    (functions, classes, constants with a ``#:`` comment); a name it re-exports is
    documented here too, under the module's name, so a reference to it resolves.  A
    package of ``WHOLE_PACKAGES`` is documented as one module: a function one of its own
    modules defines is documented here whether or not ``polind`` exports it too (a class
    that ``polind`` exports is not: both pages would register its defining module's name
    as its canonical one), and a constant with the ``#:`` comment it has where it is
    defined.
    """
    import inspect

    import polind

    package = module.__name__ + "." if module.__name__ in WHOLE_PACKAGES else None
    lines = []
    for name in getattr(module, "__all__", ()):
        value = getattr(module, name, None)
        if value is None:
            continue
        if not (inspect.isclass(value) or callable(value)):
            comment = _package_constant_comment(module, name, value) if package else None
            if comment:
                lines += [f".. autodata:: {module.__name__}.{name}", ""]
                lines += [f"   {line}" if line else "" for line in comment] + [""]
            continue
        home = getattr(value, "__module__", module.__name__)
        if home == module.__name__:
            continue
        own = package is not None and home.startswith(package) and not inspect.isclass(value)
        if not own and name in polind.__all__ and getattr(polind, name) is value:
            continue          # documented as polind.<name>
        if inspect.isclass(value):
            lines += [f".. autoclass:: {module.__name__}.{name}", "   :members:", ""]
        else:
            lines += [f".. autofunction:: {module.__name__}.{name}", ""]
    return lines


def _package_constant_comment(package, name, value) -> list[str] | None:
    """The ``#:`` comment of a constant of ``package`` where one of its modules defines it."""
    import pkgutil

    from sphinx.pycode import ModuleAnalyzer

    for info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        if getattr(module, name, None) is not value:
            continue
        comment = ModuleAnalyzer.for_module(module.__name__).find_attr_docs().get(("", name))
        if comment:
            return list(comment)
    return None


def _write_if_changed(path: Path, lines) -> None:
    text = "\n".join(lines) + "\n"
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


# --- the gallery --------------------------------------------------------------------------

class GalleryArgv:
    """The command line of an example: its output directory, made empty first.

    ``examples/tribometer_fit.py`` takes ``--out DIR``; the others take the
    directory as their first argument.
    """

    def __init__(self, root: Path):
        self.root = Path(root)

    def directory(self, src_file) -> Path:
        return self.root / Path(src_file).stem

    def __call__(self, gallery_conf, script_vars):
        out = self.directory(script_vars["src_file"])
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir(parents=True)
        if Path(script_vars["src_file"]).stem == "tribometer_fit":
            return ["--out", str(out)]
        return [str(out)]

    def __repr__(self):
        return "GalleryArgv()"


class PngScraper:
    """Show the PNG files an example wrote to its output directory, in the order written."""

    def __init__(self, argv: GalleryArgv):
        self.argv = argv
        self.shown = {}

    def __call__(self, block, block_vars, gallery_conf, **kwargs):
        from sphinx_gallery.scrapers import figure_rst

        src_file = block_vars["src_file"]
        out = self.argv.directory(src_file)
        shown = self.shown.setdefault(str(src_file), set())
        new = sorted((p for p in out.glob("*.png") if p.name not in shown),
                     key=lambda p: p.stat().st_mtime)
        paths = []
        for png, image_path in zip(new, block_vars["image_path_iterator"]):
            shutil.copyfile(png, image_path)
            shown.add(png.name)
            paths.append(image_path)
        return figure_rst(paths, gallery_conf["src_dir"])

    def __repr__(self):
        return "PngScraper()"


# --- MathJax from the build ------------------------------------------------------------------

def _mathjax_source() -> Path | None:
    try:
        distribution = importlib.metadata.distribution("sphinx-mathjax-offline")
    except importlib.metadata.PackageNotFoundError:
        return None
    path = Path(distribution.locate_file("sphinx-mathjax-offline/static/mathjax"))
    return path if path.is_dir() else None


def copy_mathjax(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    source = _mathjax_source()
    target = Path(app.outdir) / "_static" / "mathjax"
    if source is None:
        logger.warning("sphinx-mathjax-offline is not installed: equations need the network "
                       "(pip install -e '.[docs]')")
        return
    if not (target / "tex-chtml.js").exists():
        shutil.copytree(source, target, dirs_exist_ok=True)


def numpydoc_template_once():
    """Have numpydoc compile its docstring template once per build, not once per docstring.

    numpydoc's ``docscrape_sphinx.get_doc_object`` makes a Jinja environment
    and compiles ``numpydoc_docstring.rst`` for every docstring it renders:
    profiled, a sixth of this site's build.  numpydoc's own ``setup`` takes
    that function as an argument (``get_doc_object_``) and keeps it in
    ``numpydoc.numpydoc.get_doc_object``; this puts there the same function
    with the template compiled the first time (from the same loader: the
    builder's template path, then numpydoc's templates).  The rendered pages
    are unchanged.
    """
    import os

    from numpydoc import docscrape, docscrape_sphinx
    from numpydoc import numpydoc as extension

    templates = {}

    def get_doc_object(obj, what=None, doc=None, config=None, builder=None):
        key = id(builder)
        if key not in templates:
            directory = os.path.join(os.path.dirname(docscrape_sphinx.__file__), "templates")
            if builder is not None:
                loader = docscrape_sphinx.BuiltinTemplateLoader()
                loader.init(builder, dirs=[directory])
            else:
                loader = docscrape_sphinx.FileSystemLoader([directory])
            environment = docscrape_sphinx.SandboxedEnvironment(loader=loader)
            templates[key] = environment.get_template("numpydoc_docstring.rst")
        config = dict(config or {}, template=templates[key])
        return docscrape.get_doc_object(obj, what=what, doc=doc, config=config,
                                        class_doc=docscrape_sphinx.SphinxClassDoc,
                                        func_doc=docscrape_sphinx.SphinxFunctionDoc,
                                        obj_doc=docscrape_sphinx.SphinxObjDoc)

    extension.get_doc_object = get_doc_object


def setup(app):
    numpydoc_template_once()
    app.add_directive("polind-model-keys", ModelKeys)
    app.add_directive("polind-system-keys", SystemKeys)
    app.add_directive("polind-structure-keys", StructureKeys)
    app.add_directive("polind-sweep-keys", SweepKeys)
    app.add_directive("polind-sweep-metrics", SweepMetrics)
    app.add_directive("polind-columns", Columns)
    app.add_directive("polind-default-bounds", DefaultBounds)
    app.add_directive("polind-model-types", ModelTypes)
    app.add_directive("polind-model-advice", ModelAdvice)
    app.add_directive("polind-default-model", DefaultModel)
    app.add_directive("polind-data-licence", DataLicence)
    app.add_directive("polind-data-file", DataLicence)
    app.connect("build-finished", copy_mathjax)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
