"""``polind demo``: the six phenomena on the default Pol-Ind model and its classical peers.

:func:`run_demo` runs every experiment of :mod:`polind.phenomena` on four
models and writes the report of :mod:`polind.report`:

* **Pol-Ind**: the default parameter set (:ref:`formats-model-files`; a steel pair under
  100 N: ``mu_s N = 15 N``, ``mu_k N = 10 N``, vs = 1 mm/s, C = 1e4 N/s,
  64 statistical elements), or a model given by the caller.
* **LuGre** with the parameters of Canudas de Wit et al. (1995):
  sigma0 = 1e5 N/m, sigma1 = sqrt(1e5) N s/m, sigma2 = 0.4 N s/m, Fc = 1 N,
  Fs = 1.5 N, vs = 1 mm/s.  Its forces are fifteen times smaller than
  Pol-Ind's; every experiment scales with the model's own levels.
* **GMS** as an engineer would set it up without the asperity mechanics:
  eight elements of equal weight whose slip distances are log-spaced over
  Pol-Ind's presliding range (from 1/30 of its largest element slip
  distance to that distance, ``k_i = alpha_i Fs / D_i``), with Pol-Ind's Stribeck curve and
  attraction (Fs = mu_s N, Fc = mu_k N, vs, C, sigma2).  Same levels, a
  different (phenomenological) element set: the comparison shows what the
  surface-derived table changes.  (A GMS with Pol-Ind's own table *is*
  Pol-Ind at a constant load, :ref:`guide-pol-ind-law`.)
* **Maxwell-slip** with the same elements: ``k_j`` from the table and
  ``W_j = mu_s N alpha_j`` (the table's break-away forces, summing to
  ``mu_s N``), no viscous term: the rate-independent limit (C -> inf,
  Fs = Fc) of the same contact.

See the user guide: :ref:`guide-demo`.
"""

from __future__ import annotations

import math
import os
import time

from polind import phenomena
from polind.errors import InputError
from polind.phenomena import PHENOMENA

__all__ = ["LUGRE_1995", "EXPERIMENTS", "demo_models", "run_demo", "DemoSummary"]

#: The LuGre parameters of Canudas de Wit, Olsson, Astrom and Lischinsky (1995)
#: (:ref:`guide-lugre`).
LUGRE_1995 = {
    "type": "lugre",
    "bristle_stiffness": 1e5,
    "bristle_damping": math.sqrt(1e5),
    "viscous_coefficient": 0.4,
    "coulomb_force": 1.0,
    "static_force": 1.5,
    "stribeck_velocity": 1e-3,
    "stribeck_exponent": 2.0,
}

#: The experiment of each phenomenon (the keys of metrics.json).
EXPERIMENTS = {
    "stribeck": phenomena.stribeck_effect,
    "presliding_memory": phenomena.presliding_memory,
    "frictional_lag": phenomena.frictional_lag,
    "non_drifting": phenomena.non_drifting,
    "stick_slip": phenomena.stick_slip,
    "breakaway": phenomena.breakaway,
}

_DESCRIPTIONS = {
    "Pol-Ind": "The default Pol-Ind parameter set (the formats page, 'Model files'): GMS "
               "elements built from Greenwood-Williamson asperity statistics and "
               "Hertz/elastic-slip asperity mechanics (the user guide, 'The Pol-Ind model').",
    "LuGre": "The LuGre model (the user guide, 'LuGre') with the parameters of Canudas de "
             "Wit et al. (1995).",
    "GMS": "GMS (the user guide, 'Generalized Maxwell-slip (GMS)') with eight equal-weight "
           "elements whose slip distances are log-spaced from 1/30 of Pol-Ind's largest slip "
           "distance to it, and Pol-Ind's Stribeck curve and attraction: the same levels with "
           "a phenomenological element set.",
    "Maxwell-slip": "Maxwell-slip (the user guide, 'Maxwell-slip') with Pol-Ind's element "
                    "stiffnesses and W_j = mu_s N alpha_j (summing to mu_s N): the "
                    "rate-independent limit of the same contact.",
}


def demo_models(pol_ind=None) -> dict:
    """The four models of the demo, ``{label: model}``, Pol-Ind first.

    Parameters
    ----------
    pol_ind : polind.FrictionModel, optional
        A Pol-Ind model; default the default parameter set
        (:func:`polind.models.pol_ind.default_table`).
        GMS and Maxwell-slip are built from its element table and levels.
    """
    import polind
    from polind.models.pol_ind import default_table

    if pol_ind is None:
        pol_ind = polind.model_from_dict({"model": default_table()})
    equivalent = pol_ind.gms_parameters()       # the GMS Pol-Ind is at its load (7.6)
    stiffness = [float(k) for k in equivalent["stiffness"]]
    weight = [float(a) for a in equivalent["weight"]]
    static = equivalent["static_force"]
    slips = [static * a / k for a, k in zip(weight, stiffness) if k > 0.0]
    count = 8
    shortest = max(slips) / 30.0
    ratio = (max(slips) / shortest) ** (1.0 / (count - 1))
    gms_slip = [shortest * ratio ** i for i in range(count)]
    gms = {key: equivalent[key] for key in (
        "attraction", "coulomb_force", "static_force", "stribeck_velocity",
        "stribeck_exponent", "stribeck_shape", "viscous_coefficient")}
    gms.update(type="gms", stiffness=[static / count / d for d in gms_slip],
               weight=[1.0 / count] * count)
    maxwell_slip = {"type": "maxwell-slip", "stiffness": stiffness,
                    "breakaway_force": [static * a for a in weight]}
    return {
        "Pol-Ind": pol_ind,
        "LuGre": polind.model_from_dict({"model": dict(LUGRE_1995)}),
        "GMS": polind.model_from_dict({"model": gms}),
        "Maxwell-slip": polind.model_from_dict({"model": maxwell_slip}),
    }


class DemoSummary(dict):
    """What :func:`run_demo` returns: a dict with ``out_dir``, ``files``, ``metrics``,
    ``results``, ``table`` (the summary as text), ``passed`` (phenomenon -> bool, in
    Pol-Ind) and ``seconds``; ``str()`` of it is the table."""

    def __str__(self):
        return self["table"]


def _progress_hooks(progress, total):
    """``(advance(description), close())`` for a tqdm-like bar or a callable.

    A bar (anything with ``update``) gets ``total`` if it has none and one
    ``update()`` per experiment; a callable is called as
    ``progress(done, total, description)``.
    """
    if progress is None:
        return lambda description: None
    if hasattr(progress, "update"):
        if getattr(progress, "total", None) in (None, 0):
            progress.total = total
            if hasattr(progress, "refresh"):
                progress.refresh()
        done = [0]

        def advance(description):
            done[0] += 1
            if hasattr(progress, "set_description_str"):
                progress.set_description_str(description)
            progress.update(1)
        return advance
    done = [0]

    def call(description):
        done[0] += 1
        progress(done[0], total, description)
    return call


def run_demo(out_dir="polind-report", progress=None, *, model=None) -> DemoSummary:
    """Run the six phenomena on Pol-Ind, LuGre, GMS and Maxwell-slip; write the report.

    Parameters
    ----------
    out_dir : str or os.PathLike
        Directory for ``report.html``, ``metrics.json`` and the PNGs
        (created if needed; files in it are replaced atomically).
    progress : tqdm-like or callable, optional
        A progress bar (``update(1)`` per experiment, its ``total`` set if
        missing) or a function ``progress(done, total, description)``.
    model : polind.FrictionModel, optional
        The Pol-Ind model to run (default: the default parameter set,
        :ref:`formats-model-files`).

    Returns
    -------
    DemoSummary
        ``table`` is the model x phenomenon summary as text (``print`` it).

    Examples
    --------
    >>> summary = run_demo("polind-report")            # doctest: +SKIP
    >>> print(summary["table"])                        # doctest: +SKIP
    """
    from polind import report

    started = time.perf_counter()
    if os.path.isdir(out_dir):
        report.check_targets(out_dir)      # before the experiments, not after them
    models = demo_models(model)
    total = len(models) * len(PHENOMENA) + 1
    advance = _progress_hooks(progress, total)
    results = {phenomenon: {} for phenomenon in PHENOMENA}
    for phenomenon in PHENOMENA:
        for label, friction_model in models.items():
            try:        # a run the model's scales make too big is refused naming its experiment
                results[phenomenon][label] = EXPERIMENTS[phenomenon](friction_model)
            except InputError as error:
                raise InputError(f"The {phenomenon} experiment on {label}: {error}") from None
            advance(f"{phenomenon}: {label}")
    info = {label: {"description": _DESCRIPTIONS[label], "parameters": m.to_dict()["model"]}
            for label, m in models.items()}
    written = report.write_report(results, out_dir, models=info, subject="Pol-Ind")
    advance("report")
    table = report.summary_table(results)
    return DemoSummary(out_dir=written["out_dir"], files=written["files"],
                       metrics=written["metrics"], results=results, table=table,
                       passed={p: written["metrics"][p]["passed"] for p in PHENOMENA},
                       seconds=time.perf_counter() - started)
