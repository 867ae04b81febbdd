"""The engines of a sweep, and :func:`sweep`, which runs one.

Each run is a pure function of its parameter values
(:func:`polind.sweeps.runs.run_one`), so a run's row does not depend on
where it ran: local worker threads (the numba kernels release the GIL), or
the workers of an existing Dask distributed cluster
(:mod:`polind.sweeps.cluster`).  :func:`sweep` checks
the sweep and its output, computes the runs missing from the results table
(:class:`polind.sweeps.results.Results`) on one engine, writes their rows as
they finish, and returns a :class:`SweepSummary`; Ctrl-C stops it with every
finished row kept (:class:`SweepInterrupted`), and so do SIGTERM and SIGHUP
(the signals a terminal, ``kill`` or a batch system send) while it runs: the
same rows kept, the lock removed, the same exception (unless the signal was
ignored when the sweep started, as under ``nohup``).

Every run checks the files it reads against the digests of the table's
record (:mod:`polind.sweeps.runs`); a run that finds one changed stops the
sweep with an :class:`~polind.errors.InputError` naming the file, the rows
finished before the change kept: the rows of a table never mix two versions
of an input, and the record still holds the digest they were computed with.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import signal
import threading
import time
from dataclasses import dataclass, field

from polind.dynamics import BYTES_PER_SAMPLE
from polind.errors import InputError, describe
from polind.io import STDOUT, check_output_path
from polind.resources import check_memory
from polind.sweeps.cluster import run_dask
from polind.sweeps.design import Sweep, is_number, is_whole, load_sweep
from polind.sweeps.results import Results
from polind.sweeps.runs import CHANGED, RunPlan, run_one

__all__ = ["MAX_RUNS", "SweepInterrupted", "SweepSummary", "sweep"]

#: A sweep with more runs than this is refused unless the caller confirms
#: (``max_runs=None`` in Python, ``--yes`` on the command line).
MAX_RUNS = 10_000

#: What a prescribed-motion run holds per sample (t, x, v, F and the step arrays) [bytes].
_MOTION_BYTES_PER_SAMPLE = 64


# --- the engines ----------------------------------------------------------------------------

def _run_local(plan: RunPlan, todo, workers: int, record, keep) -> None:
    """Every run of ``todo`` (index, values) on ``workers`` threads, each row to ``record``.

    At most two runs per thread wait in the queue.  On any exception here
    (Ctrl-C, a ``record`` that raises) the queued runs are dropped, the
    running ones stop at their next progress report, the rows of the runs
    that finished all the same go to ``keep``, and the exception goes on.
    """
    from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

    stop = threading.Event()
    queue = iter(todo)
    unrecorded = set()
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="polind-sweep")
    try:
        while True:
            for index, values in itertools.islice(queue, 2 * workers - len(unrecorded)):
                unrecorded.add(pool.submit(run_one, plan, index, values, stop))
            if not unrecorded:
                return
            finished, _ = wait(unrecorded, return_when=FIRST_COMPLETED)
            for future in sorted(finished, key=lambda f: f.result()["run"]):
                unrecorded.discard(future)
                record(future.result())
    finally:
        stop.set()
        for future in unrecorded:
            future.cancel()
        pool.shutdown(wait=True)
        for future in unrecorded:
            if not future.cancelled() and future.exception() is None:
                keep(future.result())


# --- the sweep ------------------------------------------------------------------------------

@dataclass
class SweepSummary:
    """What :func:`sweep` did.

    Attributes
    ----------
    path : str
        The results table.
    runs : int
        Runs of the design.
    computed : int
        Runs computed now (the others were already in the table).
    failed : int
        Of those, runs whose status is an error.
    lost : int
        Dask tasks that failed outside their run (not recorded: run again).
    seconds : float
        Wall time of this call [s].
    table : dict
        Every row of the table now, sorted by run: column name to list.
    """

    path: str
    runs: int
    computed: int
    failed: int
    lost: int
    seconds: float
    table: dict = field(repr=False)

    @property
    def existing(self) -> int:
        """Runs found in the table before this call."""
        return len(self.table["run"]) - self.computed


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a sweep; every finished row is in its table.

    ``computed`` runs were added by the interrupted call, ``runs`` the whole
    design, ``done`` the rows the table holds now.
    """

    def __init__(self, path, runs, computed, done):
        super().__init__(f"{path}: interrupted with {done} of {runs} runs written")
        self.path, self.runs, self.computed, self.done = path, runs, computed, done


def _check_output(path, plan: Sweep):
    name = os.fspath(path)
    if name == STDOUT or not name.lower().endswith((".parquet", ".csv")):
        raise InputError(f"{name}: a sweep's results go to a file whose name ends in .parquet "
                         f"or .csv (so that a second run can find its rows)")
    check_output_path(name, plan.inputs)
    if os.path.exists(name) and not os.path.isfile(name):
        raise InputError(f"{name}: not a regular file; expected a .parquet or .csv file")


def _default_workers() -> int:
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def sweep(spec, output, *, workers=None, scheduler=None, max_runs=MAX_RUNS,
          progress=None) -> SweepSummary:
    """Run a sweep; rows go to ``output`` as runs finish; only missing runs are computed.

    Parameters
    ----------
    spec : Sweep, str or os.PathLike
        A :class:`~polind.sweeps.Sweep` or a sweep file (:func:`~polind.sweeps.load_sweep`).
    output : str or os.PathLike
        The results table, ``.parquet`` or ``.csv``.  If it exists, it must
        hold rows of this sweep (else InputError); their runs are not run again.
    workers : int, optional
        Local worker threads; default the number of cores.
    scheduler : str or distributed.Client, optional
        Run on an existing Dask cluster (its address, ``tcp://HOST:PORT``)
        instead of local threads.  Its workers need polind installed.
    max_runs : int or None
        Refuse a design with more runs (None: no limit).
    progress : callable, optional
        ``progress(done, total, failed)`` after each run (``total``: the runs
        this call computes).  An exception it raises stops the sweep as
        Ctrl-C does.

    Returns
    -------
    SweepSummary

    Raises
    ------
    InputError
        A bad sweep, an output of another sweep, too many runs.
    SweepInterrupted
        Ctrl-C (a KeyboardInterrupt): finished rows are in the table.
    """
    started = time.perf_counter()
    if not isinstance(spec, (Sweep, str, os.PathLike)):
        raise InputError(f"The 'spec' of sweep must be a polind.sweeps.Sweep or a sweep file. "
                         f"Got {describe(spec)} instead.")
    if not isinstance(output, (str, os.PathLike)):
        raise InputError(f"The 'output' of sweep must be a file name ending in .parquet or "
                         f".csv. Got {describe(output)} instead.")
    _check_options(workers, scheduler, max_runs)
    plan = spec if isinstance(spec, Sweep) else load_sweep(spec)
    name = os.fspath(output)
    _check_output(name, plan)
    runs = plan.runs
    if max_runs is not None and runs > max_runs:
        raise InputError(f"{plan.name}: the sweep has {_count(runs)} runs, more than the limit "
                         f"of {_count(max_runs)}; check the counts of [sweep.parameters] and "
                         f"sweep.samples, or confirm with --yes (max_runs=None in Python)")
    check_memory(min(runs, 1e300) * (len(plan.axes) + 2) * 64.0,
                 f"{plan.name}: the design ({_count(runs)} runs)")
    design = plan.design()
    with _signals_interrupt(), Results(name, plan, design) as results:
        todo = [(index, values) for index, values in enumerate(design)
                if index not in results.rows]
        if todo:
            results.check_writable()
        threads = _default_workers() if workers is None else int(workers)
        if scheduler is None and todo:
            _check_run_memory(plan, todo, min(threads, len(todo)))
        counts = {"done": 0, "failed": 0, "lost": 0}

        def keep(row):
            if row.get(CHANGED) is not None:
                return                  # read another version of a file: not a result
            results.add(row)
            counts["done"] += 1
            counts["failed"] += row["status"] != "ok"

        def record(row):
            if row.get(CHANGED) is not None:
                raise _changed(row[CHANGED], name)
            keep(row)
            if progress is not None:
                progress(counts["done"], len(todo), counts["failed"])

        def lost(future):
            counts["lost"] += 1

        if progress is not None:
            progress(0, len(todo), 0)
        # The digests the runs check their files against: the table's record.
        shared = plan.plan(results.record["files"]) if todo else None
        try:
            if todo and scheduler is not None:
                run_dask(shared, todo, scheduler, record, keep, lost)
            elif todo:
                _run_local(shared, todo, min(threads, len(todo)), record, keep)
        except KeyboardInterrupt:
            results.flush()
            raise SweepInterrupted(name, runs, counts["done"], len(results.rows)) from None
        return SweepSummary(path=name, runs=runs, computed=counts["done"],
                            failed=counts["failed"], lost=counts["lost"],
                            seconds=time.perf_counter() - started, table=results.table())


def _changed(file, output) -> InputError:
    """The refusal of a sweep whose input ``file`` changed while it ran."""
    return InputError(f"{file}: changed while the sweep ran (its contents are not those "
                      f"recorded when it started); the rows of one table never mix two "
                      f"versions of an input: {output} keeps the rows computed before the "
                      f"change, so put the file back and run the same command again to "
                      f"compute the rest, or give another --output for the new file")


@contextlib.contextmanager
def _signals_interrupt():
    """SIGTERM and SIGHUP raise KeyboardInterrupt for the block, as SIGINT does.

    So that a sweep they stop ends as Ctrl-C ends it: finished rows written,
    lock removed.  Only the main thread can set handlers; elsewhere, and for
    a signal ignored when the block starts (``nohup``), nothing changes.  The
    previous handlers are put back at the end.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(number, frame):
        raise KeyboardInterrupt

    previous = {}
    for signal_name in ("SIGTERM", "SIGHUP"):
        number = getattr(signal, signal_name, None)
        if number is None or signal.getsignal(number) is signal.SIG_IGN:
            continue
        previous[number] = signal.signal(number, interrupt)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, signal.SIG_DFL if handler is None else handler)


def _count(number) -> str:
    """A count for a message: ``12,345``, or ``about 1e+400`` for a huge one."""
    if number < 10 ** 15:
        return f"{int(number):,}"
    return f"about 1e+{int(int(number).bit_length() * 0.30103)}"


def _check_options(workers, scheduler, max_runs):
    """The options of :func:`sweep`: InputError naming the one that is wrong."""
    if workers is not None and scheduler is not None:
        raise InputError("give 'workers' (local threads) or 'scheduler' (a Dask cluster), "
                         "not both")
    if workers is not None and not (is_whole(workers) and not isinstance(workers, float)
                                    and workers >= 1):
        raise InputError(f"The number of 'workers' must be a positive integer. Got "
                         f"{describe(workers)} instead.")
    if max_runs is not None and not (is_number(max_runs) and max_runs >= 0):
        raise InputError(f"The 'max_runs' of sweep must be a non-negative number of runs, or "
                         f"None for no limit. Got {describe(max_runs)} instead.")
    if scheduler is not None and not isinstance(scheduler, (str, os.PathLike)) \
            and not _is_dask_client(scheduler):
        raise InputError(f"The 'scheduler' of sweep must be the address of a Dask scheduler "
                         f"(tcp://HOST:PORT) or a distributed.Client. Got "
                         f"{describe(scheduler)} instead.")


def _is_dask_client(value) -> bool:
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - a dependency of polind
        return False
    return isinstance(value, Client)


def _check_run_memory(plan: Sweep, todo, threads):
    """Refuse before starting when the runs at a time would pass the memory limit."""
    if plan.system is not None:
        samples = 0.0
        positions = {key: j for j, key in enumerate(plan.keys)}
        for _, values in todo:
            duration = values[positions["system.duration"]] if "system.duration" in positions \
                else plan.system["duration"]
            step = values[positions["system.time_step"]] if "system.time_step" in positions \
                else plan.system["time_step"]
            if duration > 0.0 and step > 0.0:
                samples = max(samples, duration / step)
        need = samples * BYTES_PER_SAMPLE
    else:
        samples = float(len(plan.motion["t"]))
        need = samples * _MOTION_BYTES_PER_SAMPLE
    check_memory(threads * need, f"{plan.name}: {threads} runs at a time of up to "
                                 f"{samples:.3g} samples each")
