"""``polind precompile`` (issue 38): every built-in model through every driver, into numba's cache.

A process compiles the kernels it needs the first time it needs them and
keeps them in numba's on-disk cache (:mod:`polind.kernels.cache`); every
later process loads them.  ``polind precompile`` pays that once, after an
install: it runs each model of :data:`VARIANTS` (every built-in type's
example, and Pol-Ind's kernel variants) through each driver of
:data:`DRIVERS` on a tiny input, which compiles exactly the signatures a
run of any size uses (numba compiles for the arguments' types, never their
sizes).  A driver is a function of a model that runs it the ways a user
does (:func:`_setups`): as it is and behind a series spring
(``[model.compliance]``), at its own normal load and at a varying one
(Pol-Ind through its contact mechanics, the other models with a
``reference_load``), each run twice, since a process compiles a model's
``force`` only at its second run (:func:`polind.kernels.interpreted.call_once`:
the second run of a fit or a sweep).  Adding a driver is one entry of
:data:`DRIVERS`: a name and a function of the model.

The tasks run in the calling process until one compiles something; then
the rest is shared out (:func:`run_precompile`) in groups of
:func:`families`, split by the runner modules their variants compile
(:data:`polind.kernels.generate.MODELS`; Coulomb and Stribeck share theirs,
Pol-Ind's variants its fixed-load one), each group run in one process, so
no two processes compile the same runner.  The helpers of
:mod:`polind.kernels` that every runner calls may still be compiled in two
processes at once, and numba saves a function's signatures in one index
file that it reads, extends and replaces: two processes saving different
signatures of one function at once could lose one, or pair an index entry
with the other's data file.  So every process saves to the cache under one
file lock (:func:`_lock_cache_saves`): the compilations run side by side,
only the milliseconds of each save in turn.  The other processes are
spawned (fresh interpreters), so a script that calls :func:`run_precompile`
with several ``jobs`` needs the usual ``if __name__ == "__main__":`` guard.
"""

from __future__ import annotations

import functools
import os
import time
import warnings
from dataclasses import dataclass, field

from polind.errors import InputError

__all__ = ["DRIVERS", "VARIANTS", "TaskRow", "Variant", "cache_location", "driver_names",
           "families", "format_rows", "model_types", "run_precompile", "run_task", "tasks",
           "variant_model"]

#: The samples of every driver's tiny input.
SAMPLES = 64
#: The series spring [N/m] of the runs behind one.
COMPLIANCE_STIFFNESS = 1e5
#: The ``reference_load`` [N] of the classical models' varying-load runs.
REFERENCE_LOAD = 10.0


@dataclass(frozen=True)
class Variant:
    """A model ``precompile`` runs: its type's ``example_parameters()`` with ``changes``.

    ``runners`` are the runner modules its runs compile (keys of
    :data:`polind.kernels.generate.MODELS`): variants that share one are
    compiled in one process (:func:`families`).
    """

    model_type: str
    runners: tuple
    changes: dict = field(default_factory=dict)
    #: Runner modules of ``runners`` another group compiles: not grouped by (:func:`families`).
    shared: tuple = ()
    #: The seconds its drivers took to compile on a 2-core machine (a fresh precompile,
    #: measured): :func:`families` starts the longest groups first.
    cost: float = 1.0

    @property
    def grouped_by(self) -> set:
        """The runner modules :func:`families` keeps in one process: ``runners`` but ``shared``."""
        return set(self.runners) - set(self.shared)


#: Every model ``precompile`` runs, by name: each built-in type's example, and Pol-Ind's
#: kernel variants (statistical at a varying load, at its fixed load, elastic-plastic).
VARIANTS = {
    "coulomb": Variant("coulomb", ("memoryless",), cost=24),
    "stribeck": Variant("stribeck", ("memoryless",), cost=1),
    "dahl": Variant("dahl", ("dahl",), cost=22),
    "lugre": Variant("lugre", ("lugre",), cost=32),
    "maxwell-slip": Variant("maxwell-slip", ("maxwell_slip",), cost=29),
    "gms": Variant("gms", ("gms",), cost=42),
    "leuven": Variant("leuven", ("leuven",), cost=35),
    "pol-ind": Variant("pol-ind", ("pol_ind", "pol_ind_fixed_load"), cost=68),
    # Its fixed-load runs use the fixed-load runners Pol-Ind's own variant compiles, but it
    # is a group of its own (``shared``): one group of both took some 125 s in one process
    # while the other took the rest (185 s), against about 155 s each apart (the few
    # fixed-load runners the two may then compile side by side cost less than that).
    "pol-ind elastic-plastic": Variant("pol-ind", ("pol_ind_plastic", "pol_ind_fixed_load"), {
        "materials": {"youngs_modulus": [210e9, 210e9], "poisson_ratio": [0.3, 0.3],
                      "hardness": 2e9}}, shared=("pol_ind_fixed_load",), cost=58),
    # Steps as Maxwell-slip: its runs compile nothing of their own (one group with it).
    "iwan4": Variant("iwan4", ("maxwell_slip",), cost=1),
}


# --- the tiny inputs ------------------------------------------------------------------------

@functools.lru_cache(maxsize=None)
def _motion():
    """``(t, x, v, relative load)``: a presliding sine, SAMPLES samples over 10 ms.

    The load is at most the model's own (a Pol-Ind state's element table is built for it).
    """
    import numpy as np

    t = np.linspace(0.0, 1e-2, SAMPLES)
    phase = 2.0 * np.pi * 200.0 * t
    x = 2e-6 * np.sin(phase)
    v = 2e-6 * 2.0 * np.pi * 200.0 * np.cos(phase)
    return t, x, v, 0.9 + 0.1 * np.sin(phase)


def _setups(model):
    """``[(model, loads or None), ...]``: each way a driver runs ``model``.

    As it is and behind a series spring, each at its own load and at a
    varying one: Pol-Ind's own, any other model's with a ``reference_load``
    (which mounts it with its load scaling wherever a load may be given, in
    Stepper, Body and BodyBatch even without one).  A driver that takes no
    load (BodyBatch, simulate_system) runs those models at their own.
    """
    sprung = {"compliance": {"stiffness": COMPLIANCE_STIFFNESS}}
    if model.takes_normal_load:
        loaded, level = model, model.constant_load
    else:
        loaded, level = model.with_params(reference_load=REFERENCE_LOAD), REFERENCE_LOAD
    loads = level * _motion()[3]
    return [(model, None), (model.with_params(**sprung), None),
            (loaded, loads), (loaded.with_params(**sprung), loads)]


# --- the drivers ----------------------------------------------------------------------------
# Each runs every setup twice: a process compiles a model's force at its second run.

def _simulate_x(model):
    from polind.simulation import simulate

    t, x, _, _ = _motion()
    for setup, loads in _setups(model):
        for _ in range(2):
            simulate(setup, t, x=x, normal_load=loads)


def _simulate_v(model):
    from polind.simulation import simulate

    t, _, v, _ = _motion()
    for setup, loads in _setups(model):
        for _ in range(2):
            simulate(setup, t, v=v, normal_load=loads)


def _path(model):
    """The plain path runner (:meth:`polind.models.kernel.StepKernel.run`, unmounted): what
    the element fits run (:func:`polind.identify_maxwell_slip`, the structured starts of a
    Maxwell-slip or GMS fit, the demo's), and ``polind bench``."""
    from polind.simulation import make_path

    t, x, _, _ = _motion()
    for _ in range(2):
        model._advance(make_path(t, x=x), model.initial_state(), None)


def _stepper(model):
    from polind.stepper import Stepper

    t, x, v, _ = _motion()
    half = SAMPLES // 2                          # positions, then velocities
    for setup, loads in _setups(model):
        for _ in range(2):
            stepper = Stepper(setup)
            for k in range(1, SAMPLES):
                load = None if loads is None else float(loads[k])
                if k < half:
                    stepper.advance(float(t[k]), x=float(x[k]), normal_load=load)
                else:
                    stepper.advance(float(t[k]), v=float(v[k]), normal_load=load)


def _applied_force(model):
    """A force that slides every built-in model's body a little: twice its force level."""
    return 2.0 * float(model.force_scale()) + 1.0


def _body(model):
    from polind.stepper import Body

    _, _, _, relative = _motion()
    force = _applied_force(model)
    for setup, loads in _setups(model):
        for _ in range(2):
            body = Body(setup, mass=1e-3, time_step=1e-4)
            for k in range(1, SAMPLES):
                load = None if loads is None else float(loads[k])
                body.step(force * relative[k], normal_load=load)
            step, arguments = body.compiled()    # the runner a user's own loop calls
            step(*arguments, force)


def _body_batch(model):
    import numpy as np

    from polind.batch import BodyBatch

    force = _applied_force(model)
    for setup, _ in _setups(model):
        for _ in range(2):
            batch = BodyBatch(setup, 3, mass=1e-3, time_step=1e-4)
            forces = np.array([0.0, force, -force])
            for _ in range(SAMPLES):
                batch.step(forces)


def _simulate_system(model):
    from polind.dynamics import System, simulate_system

    system = System(mass=1e-3, duration=SAMPLES * 1e-4, time_step=1e-4,
                    spring_stiffness=1e4, drive_velocity=1e-3)
    for setup, _ in _setups(model):
        for _ in range(2):
            simulate_system(setup, system)
            simulate_system(setup, system, method="euler")


def _structure(model):
    """A structure of two coordinates: the model as a joint, and to the ground (at its own load)."""
    import numpy as np

    from polind.structures import Structure, simulate_structure

    t = np.arange(SAMPLES) * 1e-4
    force = np.zeros((SAMPLES, 2))
    force[:, 0] = _applied_force(model)
    for setup, _ in _setups(model)[:2]:
        structure = Structure(mass=np.diag([1e-3, 2e-3]))
        structure.add_contact(setup, dofs=(0, 1))
        structure.add_contact(setup, dofs=(1,))
        simulate_structure(structure, t, force=force)


def _period(model):
    """A contact's periodic steady state (the hook of harmonic balance), spring or not."""
    from polind.structures import contact_period

    _, x, _, _ = _motion()
    for setup, _ in _setups(model)[:2]:
        contact_period(setup, x[:32], 1e-3, cycles=3, tolerance=1e300)


#: Every driver ``precompile`` runs each model through: ``{name: function(model)}``.
DRIVERS = {
    "simulate-x": _simulate_x,
    "simulate-v": _simulate_v,
    "path": _path,
    "Stepper": _stepper,
    "Body": _body,
    "BodyBatch": _body_batch,
    "simulate_system": _simulate_system,
    "simulate_structure": _structure,
    "contact_period": _period,
}


# --- the tasks ------------------------------------------------------------------------------

def _chosen(names, known, option, what):
    """``names`` (default: every one of ``known``) in the order of ``known``, checked."""
    if not names:
        return list(known)
    unknown = [name for name in names if name not in known]
    if unknown:
        raise InputError(f"The option '{option}' names {', '.join(map(repr, unknown))}, not "
                         f"{what}; expected some of: {', '.join(known)}.")
    return [name for name in known if name in names]


def model_types(names=None):
    """The built-in model types to compile: ``names`` (checked), default every one.

    Raises
    ------
    InputError
        For a name that is not a built-in model type, naming it (a model
        registered from outside polind compiles its runners in every process:
        no cache keeps them, :func:`polind.kernels.generate.runners_for`).
    """
    known = list(dict.fromkeys(variant.model_type for variant in VARIANTS.values()))
    return _chosen(names, known, "--models", "a built-in model type")


def driver_names(names=None):
    """The drivers to run (keys of :data:`DRIVERS`): ``names`` (checked), default every one."""
    return _chosen(names, list(DRIVERS), "--drivers", "a driver")


def tasks(types=None, drivers=None):
    """``[(variant, driver), ...]``: each variant of ``types`` through each of ``drivers``.

    Both default to every one (:func:`model_types`, :func:`driver_names`).
    """
    types, drivers = model_types(types), driver_names(drivers)
    return [(name, driver) for name, variant in VARIANTS.items() if variant.model_type in types
            for driver in drivers]


def families(work):
    """``work`` (:func:`tasks`) split into groups whose variants share no runner module.

    Variants that share one (Coulomb and Stribeck, Maxwell-slip and iwan4) are
    one group, but for the modules a variant leaves to another
    (``Variant.shared``); the groups whose variants took longest to compile
    come first (``Variant.cost``: the longest compilations start first, so
    that the processes end together).
    """
    groups = []     # [(runner modules, tasks)]
    for name, driver in work:
        runners = VARIANTS[name].grouped_by
        joined = [group for group in groups if group[0] & runners]
        for group in joined:
            groups.remove(group)
            runners |= group[0]
        merged = [task for group in joined for task in group[1]] + [(name, driver)]
        groups.append((runners, merged))
    groups.sort(key=lambda group: sum(VARIANTS[name].cost for name in
                                      {name for name, _ in group[1]}), reverse=True)
    return [sorted(group, key=work.index) for _, group in groups]


@functools.lru_cache(maxsize=None)
def variant_model(name):
    """The model of the variant ``name`` (:data:`VARIANTS`), built once per process."""
    from polind.models.registry import MODEL_TYPES

    variant = VARIANTS[name]
    cls = MODEL_TYPES[variant.model_type]
    return cls(**{**cls.example_parameters(), **variant.changes})


@dataclass
class TaskRow:
    """One task done: a variant through a driver, in one process."""

    variant: str        # the model ("lugre", "pol-ind elastic-plastic")
    driver: str         # a key of DRIVERS
    seconds: float      # wall time of the task in its process
    cpu_seconds: float  # processor time of the task in its process
    compiled: int       # kernel signatures numba compiled (not in the cache)
    loaded: int         # kernel signatures numba loaded from the cache


def _dispatchers():
    """Every numba dispatcher of the polind modules imported in this process."""
    import sys

    from numba.core.dispatcher import Dispatcher

    found = {}
    for name, module in list(sys.modules.items()):
        if name.startswith("polind.") and module is not None:
            for value in list(vars(module).values()):
                if isinstance(value, Dispatcher):
                    found[id(value)] = value
    return list(found.values())


def _counts():
    """``(compiled, loaded)``: cache misses and hits of every polind dispatcher so far."""
    compiled = loaded = 0
    for dispatcher in _dispatchers():
        compiled += sum(dispatcher.stats.cache_misses.values())
        loaded += sum(dispatcher.stats.cache_hits.values())
    return compiled, loaded


def run_task(variant, driver) -> TaskRow:
    """Run ``DRIVERS[driver]`` on the model of ``variant``, timed, counting what numba did."""
    before = _counts()
    started, cpu = time.perf_counter(), time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")          # validity figures, ignored loads: not ours
        DRIVERS[driver](variant_model(variant))
    seconds, cpu = time.perf_counter() - started, time.process_time() - cpu
    after = _counts()
    return TaskRow(variant, driver, seconds, cpu, after[0] - before[0], after[1] - before[1])


# --- the processes --------------------------------------------------------------------------

def _lock_cache_saves(lock_path):
    """Make every save to numba's cache in this process hold an exclusive lock on ``lock_path``.

    See the module notes: a function's index file is read, extended and
    replaced; two processes doing that at once could lose an entry.  Returns
    a function that undoes it (numba's own saves again).
    """
    try:
        import fcntl
    except ImportError:         # not POSIX: the families alone keep the processes apart
        return lambda: None
    from numba.core import caching

    save = caching.IndexDataCacheFile.save

    def locked_save(self, key, data):
        with open(lock_path, "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                save(self, key, data)
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    caching.IndexDataCacheFile.save = locked_save

    def undo():
        caching.IndexDataCacheFile.save = save
    return undo


def _worker(groups, results, lock_path):
    """A spawned worker: the groups it takes from ``groups`` until a None, each row put on
    ``results``; then ``("exit", None)``, or ``("error", exception)`` at the first failure."""
    _lock_cache_saves(lock_path)
    try:
        while (group := groups.get()) is not None:
            for variant, driver in group:
                results.put(("row", run_task(variant, driver)))
    except BaseException as error:      # noqa: BLE001 - the parent raises it
        try:
            results.put(("error", error))
        except Exception:               # noqa: BLE001 - an exception that does not pickle
            results.put(("error", RuntimeError(f"{type(error).__name__}: {error}")))
        return
    results.put(("exit", None))


class _Workers:
    """Spawned processes sharing a queue of groups with this one (:func:`run_precompile`)."""

    def __init__(self, groups, count, finished):
        import multiprocessing
        import tempfile
        import threading

        context = multiprocessing.get_context("spawn")    # fresh interpreters, no forked numba
        self._scratch = tempfile.TemporaryDirectory(prefix="polind-precompile-")
        lock_path = os.path.join(self._scratch.name, "cache.lock")
        self._undo = _lock_cache_saves(lock_path)           # this process saves under it too
        self._groups, self._results = context.Queue(), context.Queue()
        for group in groups:
            self._groups.put(group)
        for _ in range(count):
            self._groups.put(None)
        self._errors = []
        self._finished = finished
        self._processes = [context.Process(target=_worker, daemon=True,
                                           args=(self._groups, self._results, lock_path))
                           for _ in range(count)]
        for process in self._processes:
            process.start()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        """The workers' rows as they come (a thread of this process), until a None."""
        while (message := self._results.get()) is not None:
            kind, value = message
            if kind == "row":
                self._finished(value)
            elif kind == "error":
                self._errors.append(value)

    def take(self):
        """The next group no process has begun, or None (a worker's None is put back)."""
        import queue

        if self._errors:
            raise self._errors[0]
        try:
            group = self._groups.get(timeout=0.5)
        except queue.Empty:
            return None
        if group is None:
            self._groups.put(None)
        return group

    def finish(self):
        """Wait for every worker to end; raise the first failure."""
        for process in self._processes:
            while process.is_alive() and not self._errors:
                process.join(timeout=0.2)
        if not self._errors:
            for process in self._processes:
                process.join()
        self._results.put(None)
        self._reader.join()
        if self._errors:
            raise self._errors[0]
        for process in self._processes:
            if process.exitcode != 0:
                raise RuntimeError(f"a precompile process ended with exit status "
                                   f"{process.exitcode}")

    def close(self):
        """Stop what still runs (after a failure), restore numba's saves, remove the lock."""
        for process in self._processes:
            if process.is_alive():
                process.terminate()
            process.join()
        self._undo()
        self._scratch.cleanup()


def run_precompile(types=None, drivers=None, jobs=1, progress=None):
    """Compile each variant of ``types`` through each of ``drivers`` into numba's cache.

    The tasks run in this process.  With ``jobs`` above 1, as soon as a task
    has compiled something (the cache did not hold it), the groups of
    :func:`families` not yet begun are shared out: ``jobs - 1`` spawned
    processes and this one each take the next group as they finish one.  A
    cache that holds everything spawns nothing: loading it is quicker than
    starting interpreters.

    Parameters
    ----------
    types : list of str, optional
        Built-in model types (:func:`model_types`; default every one).
    drivers : list of str, optional
        Keys of :data:`DRIVERS` (default every one).
    jobs : int
        The most processes compiling at once, this one included.
    progress : callable, optional
        Called with each :class:`TaskRow` as it finishes (from a thread of
        this process for the tasks of the others).

    Returns
    -------
    list of TaskRow
        In the order of :func:`tasks`.
    """
    import threading

    work = tasks(types, drivers)
    rows = {}
    lock = threading.Lock()

    def finished(row):
        with lock:
            rows[row.variant, row.driver] = row
            if progress is not None:
                progress(row)

    waiting = families(work)
    workers = None
    try:
        while True:
            if workers is None:
                group = waiting.pop(0) if waiting else None
            else:
                group = workers.take()
            if group is None:
                break
            for variant, driver in group:
                row = run_task(variant, driver)
                finished(row)
                if row.compiled and workers is None and waiting and jobs > 1:
                    workers = _Workers(waiting, min(jobs - 1, len(waiting)), finished)
                    waiting = []
        if workers is not None:
            workers.finish()
    finally:
        if workers is not None:
            workers.close()
    return [rows[task] for task in work]


# --- where the cache is ---------------------------------------------------------------------

def cache_location():
    """The folder numba keeps polind's runners in, checked writable (numba's own test).

    Raises
    ------
    InputError
        If no folder numba would use for them can be written, naming them.
    """
    from polind.kernels import cache
    from polind.kernels.generate import GENERATED

    source = str(GENERATED / "lugre.py")
    locator = cache.KernelCacheLocator.from_function(run_task, source)
    if locator is None:
        from numba.core import config

        where = (f"NUMBA_CACHE_DIR ({config.CACHE_DIR})" if config.CACHE_DIR else
                 f"neither {GENERATED / '__pycache__'} nor numba's user-wide cache folder")
        raise InputError(f"numba's cache cannot be written: {where}; expected a writable "
                         f"directory (set NUMBA_CACHE_DIR to one).")
    return locator.get_cache_path()


def format_rows(rows):
    """The table ``polind precompile`` prints: per variant, its drivers, the kernel
    signatures compiled and loaded, and the seconds its tasks took in their process."""
    by_variant = {}
    for row in rows:
        by_variant.setdefault(row.variant, []).append(row)
    lines = [f"{'model':<26}{'drivers':>8}{'compiled':>10}{'loaded':>8}{'seconds':>9}"]
    for variant, own in by_variant.items():
        lines.append(f"{variant:<26}{len(own):>8}{sum(r.compiled for r in own):>10}"
                     f"{sum(r.loaded for r in own):>8}{sum(r.seconds for r in own):>9.1f}")
    return "\n".join(lines)
