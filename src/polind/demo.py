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

import os
import time

from polind import phenomena
from polind.errors import InputError
from polind.phenomena import PHENOMENA

__all__ = ["EXPERIMENTS", "demo_models", "run_demo", "DemoSummary"]

#: The experiment of each phenomenon (the keys of metrics.json).
EXPERIMENTS = {
    "stribeck": phenomena.stribeck_effect,
    "presliding_memory": phenomena.presliding_memory,
    "frictional_lag": phenomena.frictional_lag,
    "non_drifting": phenomena.non_drifting,
    "stick_slip": phenomena.stick_slip,
    "breakaway": phenomena.breakaway,
}

def demo_models(subject=None) -> dict:
    """The models of the demo, ``{label: (model, description)}``, the subject first.

    Parameters
    ----------
    subject : polind.FrictionModel, optional
        The model the demo is about; default the default Pol-Ind parameter set
        (``PolInd.example()``).  The models beside it are its
        ``peers()`` (for Pol-Ind: LuGre of 1995, a
        phenomenological GMS and its Maxwell-slip limit).
    """
    from polind.models import PolInd

    if subject is None:
        subject = PolInd.example()
    described = (f"The {subject.title or subject.type} model of the report (the user guide, "
                 f"'{subject.title or subject.type}').")
    if subject == PolInd.example():
        described = ("The default Pol-Ind parameter set (the formats page, 'Model files'): GMS "
                     "elements built from Greenwood-Williamson asperity statistics and "
                     "Hertz/elastic-slip asperity mechanics (the user guide, 'The Pol-Ind "
                     "model').")
    return {subject.title or subject.type: (subject, described), **subject.peers()}


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


def _workers(workers, models: int) -> int:
    """The number of processes :func:`run_demo` uses (checked)."""
    if workers is None:
        return max(1, min(models, os.cpu_count() or 1))
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError(f"The 'workers' of run_demo must be a whole number of processes, at "
                         f"least 1. Got {workers!r} instead.")
    return min(workers, models)


def _experiments(label, friction_model, advance=None) -> dict:
    """Every phenomenon's experiment on one model: ``{phenomenon: result}``."""
    results = {}
    for phenomenon in PHENOMENA:
        try:        # a run the model's scales make too big is refused naming its experiment
            results[phenomenon] = EXPERIMENTS[phenomenon](friction_model)
        except InputError as error:
            raise InputError(f"The {phenomenon} experiment on {label}: {error}") from None
        if advance is not None:
            advance(f"{phenomenon}: {label}")
    return results


def _experiments_apart(label, friction_model, limit) -> tuple:
    """:func:`_experiments` in a process of its own: ``(results, warnings)``.

    ``limit`` is the memory limit of the process that started this one; the
    warnings are returned as ``(message, category)`` pairs, for that process
    to give as its own.
    """
    import warnings

    from polind.resources import set_memory_limit

    set_memory_limit(limit)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        results = _experiments(label, friction_model)
    return results, [(str(w.message), w.category) for w in caught]


def _experiments_in_processes(models: dict, workers: int, advance) -> dict:
    """:func:`_experiments` of every model, one model a task, in ``workers`` new processes.

    Processes are started fresh (``spawn``: the same on every platform); each
    gets this process's memory limit, and its warnings are given here, once
    each.  A model's kernels are compiled (or loaded from the cache) in the
    process that runs it.  A failed experiment ends the demo with its own
    error (the first model's, in the models' order) once the others have
    stopped.
    """
    import multiprocessing
    import warnings
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from polind.resources import given_memory_limit

    context = multiprocessing.get_context("spawn")
    limit = given_memory_limit()
    by_model = {}
    failed = False
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        tasks = {pool.submit(_experiments_apart, label, friction_model, limit): label
                 for label, friction_model in models.items()}
        for task in as_completed(tasks):
            if task.cancelled() or task.exception() is not None:
                failed = True
                for other in tasks:        # the ones not started yet
                    other.cancel()
                continue
            label = tasks[task]
            by_model[label], caught = task.result()
            for message, category in dict.fromkeys(caught):
                warnings.warn(message, category, stacklevel=2)
            for phenomenon in PHENOMENA:
                advance(f"{phenomenon}: {label}")
    if failed:
        for task in tasks:
            if not task.cancelled() and task.exception() is not None:
                raise task.exception()
    return by_model


def run_demo(out_dir="polind-report", progress=None, *, model=None, workers=None) -> DemoSummary:
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
    workers : int, optional
        Processes the models' experiments run in, one model's six at a time
        in each (default: as many as there are models and CPU cores, at most).
        With one, every experiment runs in this process.  The results do not
        depend on it: each model's experiments are the same calls either way.
        On a first run most of the time is the compilation of each model's
        kernels (:ref:`guide-first-run`), which the processes share out; a
        progress bar then advances by a model's six experiments at once.

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
    described = demo_models(model)
    models = {label: entry[0] for label, entry in described.items()}
    subject = next(iter(models))
    total = len(models) * len(PHENOMENA) + 1
    advance = _progress_hooks(progress, total)
    workers = _workers(workers, len(models))
    if workers == 1:
        by_model = {label: _experiments(label, friction_model, advance)
                    for label, friction_model in models.items()}
    else:
        by_model = _experiments_in_processes(models, workers, advance)
    results = {phenomenon: {label: by_model[label][phenomenon] for label in models}
               for phenomenon in PHENOMENA}
    info = {label: {"description": description, "parameters": m.to_dict()["model"]}
            for label, (m, description) in described.items()}
    written = report.write_report(results, out_dir, models=info, subject=subject)
    advance("report")
    table = report.summary_table(results)
    return DemoSummary(out_dir=written["out_dir"], files=written["files"],
                       metrics=written["metrics"], results=results, table=table,
                       passed={p: written["metrics"][p]["passed"] for p in PHENOMENA},
                       seconds=time.perf_counter() - started)
