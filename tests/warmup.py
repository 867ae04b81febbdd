"""The kernels most tests need, compiled once between the workers of a parallel run.

With pytest-xdist every worker is a process of its own: a kernel two workers
need before either has cached it is compiled by both (on the development
machine about a third of each worker's compilation, over 100 s each).  Before a
run of the whole suite (:func:`wanted`), each worker calls :func:`share`: the
workers take the jobs below one at a time (whoever creates a job's claim file
first runs it), so each kernel is compiled once, into numba's cache; then each
waits until every job is done, and the tests load what they need.  With a
warm cache a job only loads its kernels.  A job that fails is left to the tests
that use the same code, which report it: warming up never fails a run.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

#: The smallest run worth warming up for: the whole suite, not a few files.
WHOLE_SUITE = 1000


def wanted(items: int) -> bool:
    """Whether a worker with ``items`` collected tests of a parallel run should warm up."""
    return items >= WHOLE_SUITE and "PYTEST_XDIST_TESTRUNUID" in os.environ


def _path():
    t = np.linspace(0.0, 0.05, 51)
    return t, 2e-6 * np.sin(2 * np.pi * 20 * t)


def _runs(model, load=None):
    """A motion by positions and by velocities, a system, a Stepper and a Body."""
    import polind

    t, x = _path()
    polind.simulate(model, t, x=x)
    polind.simulate(model, t, v=np.gradient(x, t))
    if load is not None:
        polind.simulate(model, t, x=x, normal_load=load * (1.0 - 0.1 * t))
    scale = float(model.force_scale())
    system = polind.System(mass=1.0, duration=0.02, time_step=1e-3,
                           spring_stiffness=100.0 * scale, drive_velocity=1e-3)
    polind.simulate_system(model, system)
    stepper = polind.Stepper(model)
    stepper.advance(1e-3, x=1e-7)
    body = polind.Body(model, time_step=1e-3)
    body.step(0.5 * scale)


def _mounted(model):
    import polind

    table = model.to_dict()["model"]
    table["compliance"] = {"stiffness": 100.0 * float(model.force_scale()) / 1e-6}
    mounted = polind.model_from_dict({"model": table})
    t, x = _path()
    polind.simulate(mounted, t, x=x)
    polind.simulate_system(mounted, polind.System(mass=1.0, duration=0.02, time_step=1e-3,
                                                  offset=0.1))


def _pol_ind(**changes):
    import polind
    from polind.models.pol_ind import default_table

    table = default_table()
    for key, value in changes.items():
        outer, inner = key.split(".")
        table[outer][inner] = value
    return polind.model_from_dict({"model": table})


def _all_pol_ind():
    _runs(_pol_ind(), load=100.0)
    _runs(_pol_ind(**{"discretisation.summation": "direct"}), load=100.0)
    _runs(_pol_ind(**{"materials.hardness": 2e9}), load=100.0)
    _mounted(_pol_ind())


def _family(classes):
    for cls in classes:
        _runs(cls.example())
        _mounted(cls.example())


def jobs() -> list:
    """``[(name, function)]``: one job per kernel family (the models that share compiled
    runners), so that no two workers compile the same kernel; the longest first."""
    from polind.models import MODEL_TYPES

    families = {}
    for name, cls in MODEL_TYPES.items():
        if not cls.has_contact:
            runners = cls.example().step_functions().runners or name
            families.setdefault(runners, []).append(cls)
    return [("pol-ind", _all_pol_ind)] + [
        (runners, lambda classes=classes: _family(classes))
        for runners, classes in families.items()]


def share(folder: Path, timeout: float = 1800.0) -> None:
    """Run the jobs no other worker has claimed, then wait until all of them are done."""
    import warnings

    folder.mkdir(parents=True, exist_ok=True)
    todo = jobs()
    for index, (_, job) in enumerate(todo):
        try:
            os.close(os.open(folder / f"{index}.claimed", os.O_CREAT | os.O_EXCL | os.O_WRONLY))
        except FileExistsError:
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                job()
        except Exception:       # noqa: BLE001 - the tests of the same code report it
            pass
        finally:
            (folder / f"{index}.done").touch()
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if all((folder / f"{index}.done").exists() for index in range(len(todo))):
            return
        time.sleep(0.2)
