"""How a fit uses the machine's cores: its threads, and one BLAS thread.

The starts of :func:`polind.identify` run side by side on threads, and each
start's Jacobian columns too, where one simulation of the data takes long
enough for threads to pay (:data:`THREADED_SIMULATION`); the numba kernels
release the interpreter's lock.  The solver's own matrix products are small
(a Jacobian of a few columns) and run on one BLAS thread
(:func:`one_blas_thread`, ``threadpoolctl``): a BLAS thread spinning between
them takes a core from the simulations (about an eighth of the processor
time of Pol-Ind's fit on a measured map, on two cores), and the result does
not depend on the number of threads the machine's BLAS would use (with two,
the same fit ended elsewhere: its sums of products were added in another
order).
"""

from __future__ import annotations

import math
import os
import time

import numpy as np
from threadpoolctl import threadpool_limits

from polind.errors import InputError
from polind.validation import describe

__all__ = ["THREADED_SIMULATION", "worker_count", "simulation_seconds", "start_threads",
           "one_blas_thread"]

#: A simulation of the data shorter than this [s] runs the fit on one thread by
#: default: the threads' overhead and their contention for the interpreter's lock eat
#: the gain.
THREADED_SIMULATION = 5e-3


def worker_count(workers, columns: int, seconds: float) -> int:
    """Threads for ``columns`` tasks side by side (``seconds``: one simulation of the data).

    The tasks are a Jacobian's columns or a fit's starts; by default one
    thread a core, none beside the caller's for quick simulations.
    """
    if workers is None:
        if seconds < THREADED_SIMULATION:
            return 1
        return max(1, min(os.cpu_count() or 1, columns))
    if isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1:
        raise InputError(f"The number of 'workers' must be a positive integer. Got "
                         f"{describe(workers)} instead.")
    return int(min(workers, max(columns, 1)))


def simulation_seconds(start, measured, retime: bool) -> float:
    """The time of one simulation of the data [s]; InputError where the start's force is not finite.

    The first simulation may include compiling the model's kernels: with
    ``retime``, one that looks long enough for threads
    (:data:`THREADED_SIMULATION`) is timed again.
    """
    seconds = math.inf
    for _ in range(2 if retime else 1):
        clock = time.perf_counter()
        force = measured.simulate(start)
        seconds = time.perf_counter() - clock
        if not np.all(np.isfinite(force)):
            raise InputError(f"The starting {start.type} model gives a non-finite force on "
                             "these data; check its parameters.")
        if seconds < THREADED_SIMULATION:
            break
    return seconds


def start_threads(workers, starts, seconds) -> int:
    """The threads the starts run on side by side; 1 for none (one start, or quick simulations).

    ``workers`` threads when given, else one per core when a simulation takes
    at least :data:`THREADED_SIMULATION`.  A fit from one start
    (``starts=1``) threads only its Jacobian's columns (the solver's problem).
    """
    if starts == 1:
        return 1
    tasks = (os.cpu_count() or 1) if workers is None else workers
    return worker_count(workers, tasks, seconds)


def one_blas_thread():
    """A context in which the BLAS (NumPy's and SciPy's) uses one thread, as before after it."""
    return threadpool_limits(limits=1, user_api="blas")
