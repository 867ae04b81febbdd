"""The performance benchmark behind ``polind bench`` and ``benchmarks/``, one module per idea.

* :mod:`polind.bench.harness`: the cases (every registered model, at every
  element count if it has elements), their timing in element-steps per second
  against the model's NumPy loop, and the table;
* :mod:`polind.bench.references`: the reference loops the benchmark measures
  against, plain NumPy and bare numba, written from the user guide's
  equations (no model uses them);
* :mod:`polind.bench.ratios`: the ratio rows, two timings taken in the same run;
* :mod:`polind.bench.surfaces`: Pol-Ind's separation solve and a measured
  height map from file to model;
* :mod:`polind.bench.big_files`: ``polind simulate`` end to end along a
  1e7-sample CSV;
* :mod:`polind.bench.processes`: whole ``polind`` processes, cold (an empty
  numba cache) and warm, and the ratios the user waits for.
* :mod:`polind.bench.precompile`: ``polind precompile``, every built-in model
  through every driver on a tiny input, so that numba's cache holds every
  kernel before the first real run.
"""
