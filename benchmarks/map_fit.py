"""The fit issue 21 (item 4) and issue 25 hold to 30 s: Pol-Ind on a measured map with a compliance.

    python benchmarks/map_fit.py [--free KEY,KEY,...] [--starts N] [--workers N]
                                 [--model-out FILE] [--json results.json]

The shipped tribometer record through its shipped data description (40,800
samples, the measured normal load sample by sample), fitted on its first half
(``--holdout 0.5``) as ``polind fit MODEL --data DESCRIPTION --holdout 0.5``
does (:func:`polind.identify` with the same arguments).  The starting model:
Pol-Ind with the shipped height map ``x3p-2.x3p`` as its surface at the
record's median load, behind a series spring of ``F_90 / (0.4 stroke)``
(``F_90`` the 90th percentile of ``|F|``; the rig's presliding spans about
0.4 of the stroke), ``mu_s = 1.05 F_90 / N``, ``mu_k = F_90 / N``,
``attraction = 10``, ``stribeck_velocity = 1e-4``; free (default)
``static_coefficient``, ``kinetic_coefficient``, ``attraction`` and
``compliance.stiffness`` (bounds ``[1e3, 1e7]`` N/m), the keys of
``examples/tribometer_fit.py`` that a map leaves free (it gives the summit
heights, so there is no ``surface.height_std``).

Prints the wall time of the fit (the model read and the first simulation
included, the kernels loaded from numba's cache: run it once before timing),
the simulations, each start's RMS error, the fitted values with their
standard errors, the RMS errors in sample and held out.  ``--model-out``
writes the starting model file (to time ``polind fit`` on it as one
process).  Run it on an otherwise idle machine; on a shared one compare the
simulation counts, which do not depend on the load.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from polind import datasets, identification, io
from polind.models import read_model_document
from polind.models.pol_ind import default_table

DEFAULT_FREE = ("static_coefficient", "kinetic_coefficient", "attraction",
                "compliance.stiffness")
MAP = "x3p-2.x3p"


def start_document(free) -> dict:
    """The starting model document (``[model]`` and ``[fit]``) of the module docstring."""
    record = datasets.tribometer()
    force_level = float(np.percentile(np.abs(record["F"]), 90))
    stroke = float(np.ptp(record["x"]))
    load = float(np.median(record["normal_load"]))
    table = default_table()
    table.update(normal_load=load, static_coefficient=1.05 * force_level / load,
                 kinetic_coefficient=force_level / load, stribeck_velocity=1e-4,
                 attraction=10.0)
    table["surface"] = {"topography": str(datasets.height_map_path(MAP))}
    table["discretisation"] = {}
    table["compliance"] = {"stiffness": force_level / (0.4 * stroke)}
    fit = {"free": list(free)}
    if "compliance.stiffness" in free:
        fit["bounds"] = {"compliance.stiffness": [1e3, 1e7]}
    return {"model": table, "fit": fit}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--free", default=",".join(DEFAULT_FREE),
                        help="the free keys, comma-separated (default %(default)s)")
    parser.add_argument("--starts", type=int, default=None, help="polind fit --starts")
    parser.add_argument("--workers", type=int, default=None,
                        help="threads of the Jacobian (default: identify's)")
    parser.add_argument("--model-out", help="also write the starting model file here")
    parser.add_argument("--json", help="also write the results as JSON to this file")
    args = parser.parse_args(argv)
    document = start_document([key for key in args.free.split(",") if key])
    if args.model_out:
        io.write_model_file(args.model_out, document)
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        # Read back from a file, as polind fit reads its model.
        path = Path(folder) / "map-fit.toml"
        io.write_model_file(path, document)
        model, free, bounds = identification.parse_fit(read_model_document(path))
    data = io.read_record(datasets.tribometer_description_path(), **io.MEASUREMENT_COLUMNS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = identification.identify(model, data, free=free, bounds=bounds, holdout=0.5,
                                         starts=args.starts, workers=args.workers)
    seconds = time.perf_counter() - started
    print(f"Pol-Ind on {MAP} + compliance, tribometer record, hold-out 0.5: "
          f"{seconds:.1f} s, {result.evaluations} simulations of {result.fitted_samples} "
          f"samples")
    for label, rms in result.starts:
        print(f"  start {label}: rms {rms:.7g} N")
    print(result.summary())
    print(f"warnings: {len(result.warnings)}")
    for note in result.warnings:
        print(f"  {note}")
    if args.json:
        io.atomic_write_text(args.json, json.dumps({
            "seconds": seconds, "simulations": result.evaluations,
            "rms_error": result.rms_error, "holdout_rms_error": result.holdout_rms_error,
            "values": result.values, "standard_errors": result.standard_errors,
            "start": result.start_label, "starts": result.starts}, indent=2, default=float))
    return result


if __name__ == "__main__":
    sys.exit(main() and 0)
