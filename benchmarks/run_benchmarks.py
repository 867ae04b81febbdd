"""Run polind's kernel benchmark and save the table (the same as `polind bench`).

    python benchmarks/run_benchmarks.py [--json results.json] [MODEL ...]

Reports element-steps per second of each model's numba kernel and of a plain
NumPy loop doing the same work in the same run, and their ratio.  Run it on
an otherwise idle machine; numba compiles (or loads its cache) before timing.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict

from polind import bench


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", help="model types (default: all benchmarked)")
    parser.add_argument("--json", help="also write the rows as JSON to this file")
    args = parser.parse_args(argv)
    rows = []
    for model_type, n in bench.cases(args.models or None):
        rows.append(bench.run_case(model_type, n))
        print(bench.format_table(rows[-1:]).splitlines()[-1], flush=True)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump([asdict(r) | {"ratio": r.ratio} for r in rows], handle, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
