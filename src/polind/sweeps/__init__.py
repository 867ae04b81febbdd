"""Many runs of one friction model over a grid or a sample of its parameters.

The user guide, :ref:`guide-sweeps`; the sweep file, :ref:`formats-sweep`.  The
metrics measure the phenomena (:ref:`guide-phenomena`) on the one-degree-of-freedom
systems (:ref:`guide-systems`).

A sweep file names a model file, a one-degree-of-freedom system or a
prescribed motion, the metrics to keep (:data:`METRICS`) and the
parameters to vary: dotted keys into ``[model]`` and ``[system]``, each a
list of values or a range (linear or logarithmic).  The design is a grid
(every combination, in the order of the keys, the last varying fastest), a
Latin hypercube (:class:`scipy.stats.qmc.LatinHypercube`) or a uniform random
sample, seeded.  Each run is a pure function of its parameter values, so a
run's row does not depend on where it ran: local worker threads (the numba
kernels release the GIL), or the workers of an existing Dask distributed
cluster.

The results table (Parquet or CSV) has one row per run: ``run`` (the run's
index in the design), the parameter values, the metrics, ``status`` (``"ok"``
or the run's one-line error) and ``seconds``.  Rows are written as runs
finish; a sweep started again on the same output computes only the runs that
are missing, and refuses an output made by another sweep.

The modules, one idea each:

- :mod:`polind.sweeps.design`: the sweep (:class:`Sweep`), its parameters and
  its design, and the sweep file (:func:`load_sweep`);
- :mod:`polind.sweeps.metrics`: the metrics (:data:`METRICS`,
  :func:`register_metric`, :data:`NEEDS`);
- :mod:`polind.sweeps.runs`: one run, a pure function of its parameter values;
- :mod:`polind.sweeps.results`: the results table, resumed and read back
  (:func:`read_results`);
- :mod:`polind.sweeps.engine`: the local and Dask engines and :func:`sweep`,
  which runs a sweep on one;
- :mod:`polind.sweeps.cluster`: the runs on a Dask cluster, its address
  checked before a client connects;
- :mod:`polind.sweeps.plot`: the figure (:func:`plot_results`).

``polind.sweep`` is the function :func:`sweep`; this package is ``polind.sweeps``.

Examples
--------
>>> import polind, tempfile, pathlib
>>> from polind.dynamics import System
>>> model = {"model": {"type": "coulomb", "coulomb_force": 1.0}}
>>> system = System(mass=1.0, duration=1.0, time_step=0.01, spring_stiffness=10.0,
...                 drive_velocity=0.1)
>>> plan = Sweep(model, system=system, metrics=["mean_force", "max_force"],
...              parameters={"model.coulomb_force": {"values": [0.5, 1.0]}})
>>> out = pathlib.Path(tempfile.mkdtemp()) / "results.csv"
>>> summary = polind.sweep(plan, out, workers=1)
>>> summary.table["model.coulomb_force"], summary.table["status"]
([0.5, 1.0], ['ok', 'ok'])
"""

from polind.sweeps.design import SWEEP_KEYS, Sweep, load_sweep
from polind.sweeps.engine import MAX_RUNS, SweepInterrupted, SweepSummary, sweep
from polind.sweeps.metrics import METRICS, NEEDS, Metric, RunOutput, register_metric
from polind.sweeps.plot import plot_results
from polind.sweeps.results import read_results

__all__ = ["METRICS", "MAX_RUNS", "Metric", "NEEDS", "RunOutput", "SWEEP_KEYS", "Sweep",
           "SweepInterrupted", "SweepSummary", "load_sweep", "plot_results", "read_results",
           "register_metric", "sweep"]
