"""The whole-process rows of ``polind bench --processes`` (issue 25): what the user waits for.

Each case is a whole ``polind`` process, timed from outside
(:func:`subprocess.run` between two :func:`time.perf_counter` readings): the
interpreter starting, polind and its libraries imported, the files read,
numba's kernels compiled or loaded from its cache, the work, the files
written.  A case runs first *cold*, with ``NUMBA_CACHE_DIR`` set to a fresh,
empty directory (polind's cache locator, :mod:`polind.kernels.cache`, keeps
its kernels there then), so every kernel it needs is compiled — best of
``cold_runs`` runs, each with an empty directory of its own; and then
*warm*, best of ``warm_runs`` runs with the first cold run's directory, so
every kernel is loaded.  Best of two for both (the defaults): on a shared
machine other work only ever adds to a process's time, and one cold
process, alone, moved the GMS ratio between 2.7 and 3.5 in one session.
Each row counts the files numba wrote into the empty directory (more than
none: the cold run compiled) and the files the warm runs added or
changed (none: every kernel the case needs is kept on disk, the runners of a
mounted model included; only the runners of a model registered from outside
polind, :func:`polind.kernels.generate.runners_for`, are compiled in every
process, and no case runs one).

A warm process still imports numba, NumPy and SciPy.  It reads them from
their ``.pyc`` files where those exist; where they do not and Python may not
write them (``PYTHONDONTWRITEBYTECODE``, set in many containers, with a
package installer that leaves them out: uv does unless asked), every process
compiles those libraries' sources again, which adds about a second to every
row (``import numba`` 0.9 s instead of 0.3 s on the development machine) and
makes every cold/warm ratio smaller.  :func:`bytecode_note` says so under the
table.

The cases (:func:`case_names`): ``polind simulate`` of each registered
model's ``example()`` along a 2000-sample motion CSV; LuGre and the default
Pol-Ind model with a ``[model.compliance]`` (a series spring); Pol-Ind on
the shipped height map ``x3p-2.x3p`` at 1 N with a compliance; ``polind
fit`` of LuGre to a synthetic record; ``polind fit`` of that map model to a
synthetic record; and ``polind demo``.  The input files are written by a
separate process with its own numba cache (:data:`_PREPARE`), so nothing of
the cases' caches is filled before their cold run, and all files live in a
:class:`tempfile.TemporaryDirectory`.

The target rows (:func:`target_rows`) are ratios of timings of the same run
and one time: cold over warm of ``simulate`` of one model (at most 3; the
cases behind a spring are held to it too, which is more than issue 25 asks:
it sets the spring's targets on warm processes, below) and of
``polind demo`` (at most 4); a model with a compliance over the same model
without, warm (at most 1.5); the default Pol-Ind model with a compliance
over plain LuGre, warm (at most 2); the warm fit of Pol-Ind on the measured
map with a compliance (at most 30 s).
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from polind.bench.big_files import polind_command
from polind.errors import InputError

#: The samples of the motion every ``simulate`` case runs along.
MOTION_SAMPLES = 2000
#: The stiffness [N/m] of the series spring of the cases with a ``[model.compliance]``.
COMPLIANCE_STIFFNESS = 1e5
#: Seconds a process may take before it is stopped and its time reported as "> timeout".
DEFAULT_TIMEOUT = 300.0
#: The cases of ``--quick``.
QUICK_CASES = ("simulate lugre", "simulate lugre + compliance")

#: The targets (issue 25, item 4).
TARGET_SIMULATE_COLD_WARM = 3.0
TARGET_DEMO_COLD_WARM = 4.0
TARGET_COMPLIANCE_COST = 1.5
TARGET_POL_IND_OVER_LUGRE = 2.0
TARGET_MAP_FIT_SECONDS = 30.0

#: What the table shows for a time or ratio not measured.
MISSING = "—"

# Writes the cases' input files into the folder argv[1] (run with its own NUMBA_CACHE_DIR,
# never the cases').  argv[2] is "records" when the fits' synthetic records are wanted.
_PREPARE = """\
import sys, warnings
from pathlib import Path
import numpy as np
import polind
from polind import datasets
from polind.models.pol_ind import default_table
from polind.models.registry import MODEL_TYPES
warnings.simplefilter("ignore")
folder, records = Path(sys.argv[1]), sys.argv[2] == "records"
samples, stiffness = int(sys.argv[3]), float(sys.argv[4])
compliance = f"\\n[model.compliance]\\nstiffness = {stiffness!r}\\n"
for name, cls in MODEL_TYPES.items():
    polind.save_model(cls.example(), folder / f"{name}.toml")
for name in ("lugre", "pol-ind"):
    text = (folder / f"{name}.toml").read_text()
    (folder / f"{name}-compliance.toml").write_text(text + compliance)
table = default_table()
table["normal_load"] = 1.0
table["surface"] = {"topography": str(datasets.height_map_path("x3p-2.x3p"))}
table["discretisation"] = {}
table["compliance"] = {"stiffness": stiffness}
map_model = polind.model_from_dict({"model": table})
polind.save_model(map_model, folder / "pol-ind-map-compliance.toml")
t = np.arange(samples) * 1e-4
x = 2e-5 * np.sin(2.0 * np.pi * 2.0 * t)
np.savetxt(folder / "motion.csv", np.c_[t, x], delimiter=",", header="t,x", comments="",
           fmt="%.17g")
if records:
    t = np.linspace(0.0, 2.0, 1001)
    x = 5e-4 * np.sin(np.pi * t) + 2e-5 * np.sin(2.0 * np.pi * 7.0 * t)
    noise = np.random.default_rng(25)
    fits = (("lugre", polind.load_model(folder / "lugre.toml"),
             ("coulomb_force", "static_force", "stribeck_velocity")),
            ("pol-ind-map", map_model,
             ("static_coefficient", "kinetic_coefficient", "stribeck_velocity")))
    for name, truth, free in fits:
        force = polind.simulate(truth, t, x=x).force
        force = force + 0.01 * np.abs(force).max() * noise.standard_normal(t.size)
        np.savetxt(folder / f"{name}-record.csv", np.c_[t, x, force], delimiter=",",
                   header="t,x,F", comments="", fmt="%.17g")
        start = truth.with_params(**{key: 1.3 * truth.params[key] for key in free})
        polind.save_model(start, folder / f"{name}-start.toml")
        keys = ", ".join(f'"{key}"' for key in free)
        with open(folder / f"{name}-start.toml", "a") as stream:
            stream.write(f"\\n[fit]\\nfree = [{keys}]\\n")
"""


def case_commands(folder):
    """``{case name: polind arguments}`` of every case, its files in ``folder``."""
    from polind.models.registry import MODEL_TYPES

    folder = Path(folder)
    motion = ["-i", str(folder / "motion.csv"), "-o", str(folder / "out.csv")]
    commands = {f"simulate {name}": ["simulate", str(folder / f"{name}.toml"), *motion]
                for name in MODEL_TYPES}
    for name in ("lugre", "pol-ind"):
        commands[f"simulate {name} + compliance"] = [
            "simulate", str(folder / f"{name}-compliance.toml"), *motion]
    commands["simulate pol-ind map + compliance"] = [
        "simulate", str(folder / "pol-ind-map-compliance.toml"), *motion]
    for name, label in (("lugre", "fit lugre"), ("pol-ind-map", "fit pol-ind map + compliance")):
        commands[label] = ["fit", str(folder / f"{name}-start.toml"), "--data",
                           str(folder / f"{name}-record.csv"), "-o",
                           str(folder / f"{name}-fitted.toml")]
    commands["demo"] = ["demo", "--out", str(folder / "demo")]
    return commands


def case_names(quick=False):
    """The cases in the order they run: :data:`QUICK_CASES` with ``quick``, else every one."""
    return list(QUICK_CASES) if quick else list(case_commands("."))


@dataclass
class ProcessRow:
    case: str                    # what the process does ("simulate lugre", "demo", ...)
    cold_seconds: float | None   # wall time with an empty numba cache; None: timed out
    warm_seconds: float | None   # best wall time with that cache filled; None: timed out
    cache_files: int             # files numba wrote into the empty cache directory (cold)
    warm_changes: int            # files the warm runs added to it or changed (0: no compiling)
    timeout: float               # seconds a run was allowed

    @property
    def cold_over_warm(self) -> float | None:
        """Cold over warm seconds, or None if either timed out."""
        if self.cold_seconds is None or self.warm_seconds is None:
            return None
        return self.cold_seconds / self.warm_seconds


@dataclass
class TargetRow:
    name: str               # what is compared with what
    value: float | None     # the measured ratio or seconds; None: a run timed out
    target: float           # an upper bound
    unit: str = ""          # "" for a ratio, "s" for seconds
    detail: str = ""        # the timings it is made of

    @property
    def met(self) -> bool:
        return self.value is not None and self.value <= self.target


def _snapshot(folder):
    """``{path: (size, mtime_ns)}`` of every file under ``folder``."""
    files = {}
    for root, _, names in os.walk(folder):
        for name in names:
            status = os.stat(os.path.join(root, name))
            files[os.path.join(root, name)] = (status.st_size, status.st_mtime_ns)
    return files


def run_process(arguments, cache_dir, timeout=DEFAULT_TIMEOUT):
    """Wall seconds of one ``polind ARGUMENTS`` process with ``NUMBA_CACHE_DIR=cache_dir``.

    Parameters
    ----------
    arguments : list of str
        The arguments after ``polind``.
    cache_dir : path-like
        numba's cache directory for the process.
    timeout : float
        Seconds after which the process is stopped.

    Returns
    -------
    float or None
        The seconds, or None if the process was stopped at ``timeout``.

    Raises
    ------
    InputError
        If the process exits with a status other than 0 (its standard error in the message).
    """
    environment = dict(os.environ, NUMBA_CACHE_DIR=os.fspath(cache_dir))
    command = polind_command() + [str(argument) for argument in arguments]
    started = time.perf_counter()
    try:
        done = subprocess.run(command, env=environment, stdout=subprocess.DEVNULL,
                              stderr=subprocess.PIPE, text=True, errors="replace",
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    seconds = time.perf_counter() - started
    if done.returncode != 0:
        raise InputError(f"polind {' '.join(map(str, arguments[:1]))} exited {done.returncode}: "
                         f"{' '.join(done.stderr.split())[-500:]}")
    return seconds


def run_case(name, arguments, cache_dir, warm_runs=2, timeout=DEFAULT_TIMEOUT, cold_runs=2):
    """One case cold (best of ``cold_runs``, each in an empty cache), then warm (best of ``warm_runs``).

    The first cold run fills ``cache_dir``, which the warm runs then load; each
    further cold run has an empty directory of its own beside it, removed
    afterwards.  Best of several, cold and warm alike: a shared machine only
    ever adds to a process's time.

    Parameters
    ----------
    name : str
        The case's name, for the row.
    arguments : list of str
        The arguments after ``polind``.
    cache_dir : pathlib.Path
        numba's cache directory for the case; it must not exist or be empty.
    warm_runs : int
        The warm runs; the row keeps the best.
    timeout : float
        Seconds each run may take.
    cold_runs : int
        The cold runs; the row keeps the best.

    Returns
    -------
    ProcessRow
    """
    import shutil

    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    if any(cache_dir.iterdir()):
        raise ValueError(f"{cache_dir}: a cold run needs an empty cache directory")
    colds = [run_process(arguments, cache_dir, timeout)]
    filled = _snapshot(cache_dir)
    for index in range(1, cold_runs):
        empty = cache_dir.with_name(f"{cache_dir.name}-cold-{index}")
        empty.mkdir()
        try:
            colds.append(run_process(arguments, empty, timeout))
        finally:
            shutil.rmtree(empty, ignore_errors=True)
    finished_cold = [seconds for seconds in colds if seconds is not None]
    cold = min(finished_cold) if finished_cold else None
    warm = []
    for _ in range(warm_runs):
        warm.append(run_process(arguments, cache_dir, timeout))
    after = _snapshot(cache_dir)
    changes = sum(1 for path, stamp in after.items() if filled.get(path) != stamp)
    finished = [seconds for seconds in warm if seconds is not None]
    return ProcessRow(name, cold, min(finished) if finished else None, len(filled), changes,
                      timeout)


def prepare(folder, names):
    """Write the input files of the cases ``names`` into ``folder`` (in a separate process)."""
    records = any(name.startswith("fit ") for name in names)
    done = subprocess.run(
        [sys.executable, "-c", _PREPARE, os.fspath(folder), "records" if records else "-",
         str(MOTION_SAMPLES), repr(COMPLIANCE_STIFFNESS)],
        env=dict(os.environ, NUMBA_CACHE_DIR=os.fspath(Path(folder) / "prepare-cache")),
        capture_output=True, text=True, errors="replace")
    if done.returncode != 0:
        raise InputError(f"writing the whole-process cases' files failed: "
                         f"{' '.join(done.stderr.split())[-500:]}")


def run_processes(names=None, quick=False, warm_runs=2, timeout=DEFAULT_TIMEOUT,
                  folder=None, progress=None, cold_runs=2):
    """Every case of ``names`` (default :func:`case_names` of ``quick``), cold then warm.

    Parameters
    ----------
    names : list of str, optional
        The cases to run, from :func:`case_names`.
    quick : bool
        Without ``names``: only :data:`QUICK_CASES`.
    warm_runs : int
        Warm runs per case (the best is kept).
    timeout : float
        Seconds each process may take.
    folder : path-like, optional
        Where the temporary directory is made (default: the system's).
    progress : callable, optional
        Called with each :class:`ProcessRow` when it is done.
    cold_runs : int
        Cold runs per case, each with an empty cache (the best is kept).

    Returns
    -------
    list of ProcessRow
    """
    import tempfile

    names = list(names) if names else case_names(quick)
    unknown = sorted(set(names) - set(case_names()))
    if unknown:
        raise InputError(f"unknown whole-process case(s) {', '.join(unknown)}; expected "
                         f"some of: {', '.join(case_names())}")
    rows = []
    with tempfile.TemporaryDirectory(prefix="polind-processes-", dir=folder) as scratch:
        scratch = Path(scratch)
        prepare(scratch, names)
        commands = case_commands(scratch)
        for index, name in enumerate(names):
            rows.append(run_case(name, commands[name], scratch / f"cache-{index}", warm_runs,
                                 timeout, cold_runs))
            if progress is not None:
                progress(rows[-1])
    return rows


def _ratio_row(name, numerator, denominator, target, what):
    """``numerator / denominator`` of two seconds (either None: not measured)."""
    if numerator is None or denominator is None:
        return TargetRow(name, None, target, "", f"{what}: a run timed out")
    return TargetRow(name, numerator / denominator, target, "",
                     f"{numerator:.2f} s / {denominator:.2f} s")


def target_rows(rows):
    """The target rows of issue 25 that ``rows`` hold the timings for.

    Parameters
    ----------
    rows : list of ProcessRow

    Returns
    -------
    list of TargetRow
    """
    by_case = {row.case: row for row in rows}
    targets = []
    for row in rows:
        if row.case.startswith("simulate "):
            targets.append(_ratio_row(f"cold / warm: {row.case}", row.cold_seconds,
                                      row.warm_seconds, TARGET_SIMULATE_COLD_WARM, "cold/warm"))
    if "demo" in by_case:
        demo = by_case["demo"]
        targets.append(_ratio_row("cold / warm: demo", demo.cold_seconds, demo.warm_seconds,
                                  TARGET_DEMO_COLD_WARM, "cold/warm"))
    for name in ("lugre", "pol-ind"):
        plain, sprung = by_case.get(f"simulate {name}"), by_case.get(
            f"simulate {name} + compliance")
        if plain is not None and sprung is not None:
            targets.append(_ratio_row(f"warm: simulate {name} + compliance / without",
                                      sprung.warm_seconds, plain.warm_seconds,
                                      TARGET_COMPLIANCE_COST, "warm"))
    lugre, pol_ind = by_case.get("simulate lugre"), by_case.get("simulate pol-ind + compliance")
    if lugre is not None and pol_ind is not None:
        targets.append(_ratio_row("warm: simulate pol-ind + compliance / lugre",
                                  pol_ind.warm_seconds, lugre.warm_seconds,
                                  TARGET_POL_IND_OVER_LUGRE, "warm"))
    fit = by_case.get("fit pol-ind map + compliance")
    if fit is not None:
        cold = MISSING if fit.cold_seconds is None else f"{fit.cold_seconds:.1f} s"
        targets.append(TargetRow("warm: fit pol-ind map + compliance", fit.warm_seconds,
                                 TARGET_MAP_FIT_SECONDS, "s",
                                 f"cold {cold}" if fit.warm_seconds is not None else
                                 f"> {fit.timeout:g} s (stopped); cold {cold}"))
    return targets


def _seconds(value, timeout, width):
    return f"{'> ' + format(timeout, 'g'):>{width}}" if value is None else f"{value:>{width}.2f}"


def format_processes(rows):
    """The rows as the table ``polind bench --processes`` prints, under its header line."""
    lines = [f"{'whole process':<36}{'cold s':>9}{'warm s':>9}{'cold/warm':>11}"
             f"{'cache files':>13}{'warm writes':>13}"]
    for r in rows:
        ratio = r.cold_over_warm
        lines.append(f"{r.case:<36}{_seconds(r.cold_seconds, r.timeout, 9)}"
                     f"{_seconds(r.warm_seconds, r.timeout, 9)}"
                     f"{MISSING if ratio is None else format(ratio, '.2f'):>11}"
                     f"{r.cache_files:>13}{r.warm_changes:>13}")
    return "\n".join(lines)


def bytecode_note(environment=None) -> str:
    """A line under the table when its processes compile their libraries' sources, else ``""``.

    Parameters
    ----------
    environment : mapping, optional
        The processes' environment; default :data:`os.environ` (what
        :func:`run_process` passes on).

    Returns
    -------
    str
        Empty when numba's installed ``__init__.py`` has its ``.pyc`` or the
        processes may write it (the first, cold, process then does); else the
        note of the module docstring, with the remedy.
    """
    import numba

    environment = os.environ if environment is None else environment
    compiled = os.path.exists(importlib.util.cache_from_source(numba.__file__))
    if compiled or not environment.get("PYTHONDONTWRITEBYTECODE"):
        return ""
    return ("note: numba has no .pyc files and PYTHONDONTWRITEBYTECODE is set, so every "
            "process above compiled numba's, NumPy's and SciPy's sources (about 1 s more "
            "per process, smaller cold/warm ratios); install with `uv pip install "
            "--compile-bytecode` (as `make` does) to time what a user with bytecode waits for")


def format_targets(rows):
    """The target rows as ``polind bench --processes`` prints them, under their header."""
    lines = [f"{'target (same run)':<52}{'measured':>10}{'target':>10}{'':>6}  detail"]
    for r in rows:
        value = MISSING if r.value is None else f"{r.value:.3g}{' s' if r.unit else ''}"
        target = f"<= {r.target:g}{' s' if r.unit else ''}"
        lines.append(f"{r.name:<52}{value:>10}{target:>10}{'met' if r.met else 'NOT':>6}"
                     f"  {r.detail}")
    return "\n".join(lines)
