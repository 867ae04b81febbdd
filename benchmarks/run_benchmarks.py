"""Run polind's kernel benchmark and save the table (the same as `polind bench`).

    python benchmarks/run_benchmarks.py [--json results.json] [--ratios | --no-ratios] [MODEL ...]

Reports element-steps per second of each model's numba kernel and of a plain
NumPy loop doing the same work in the same run, and their ratio.  Then (unless
``--no-ratios`` or model types are named) the ratio rows of
``polind.bench.ratios.run_ratios``: ``Stepper.advance`` against a bare numba call,
``simulate`` end to end against bare numba loops, and the Pol-Ind model under
a varying against a constant normal load, each against its target;
``--ratios`` runs those rows only.  Run it on an otherwise idle machine; numba
compiles (or loads its cache) before timing.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict

from polind.bench import harness, ratios as ratio_rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", help="model types (default: all benchmarked)")
    parser.add_argument("--json", help="also write the rows as JSON to this file")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--ratios", action="store_true", help="run only the ratio rows")
    which.add_argument("--no-ratios", action="store_true", help="skip the ratio rows")
    args = parser.parse_args(argv)
    rows = []
    if not args.ratios:
        print(harness.format_table([]), flush=True)
        for model_type, n in harness.cases(args.models or None):
            rows.append(harness.run_case(model_type, n))
            print(harness.format_table(rows[-1:]).splitlines()[-1], flush=True)
    ratios = []
    if args.ratios or not (args.no_ratios or args.models):
        print("\n" + ratio_rows.format_ratios([]), flush=True)
        ratios = ratio_rows.run_ratios(progress=lambda row: print(
            ratio_rows.format_ratios([row]).splitlines()[-1], flush=True))
    if args.json:
        with open(args.json, "w") as handle:
            json.dump({"rows": [asdict(r) | {"ratio": r.ratio} for r in rows],
                       "ratios": [asdict(r) | {"met": r.met} for r in ratios]},
                      handle, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
