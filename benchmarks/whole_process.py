"""What the user waits for: whole `polind` processes, cold and warm (issue 25, item 4).

    python benchmarks/whole_process.py [--json results.json] [--quick] [--warm-runs N]
                                       [--cold-runs N] [--timeout SECONDS]

The same rows as ``polind bench --processes`` (:mod:`polind.bench.processes`):
each case is one ``polind`` process timed from outside, first with
``NUMBA_CACHE_DIR`` an empty temporary directory (every kernel compiled;
best of ``--cold-runs``, each with a new empty directory), then best of
``--warm-runs`` with the first one's directory (every kernel loaded).
The cases: ``simulate`` of each registered model along a 2000-sample motion,
LuGre and the default Pol-Ind model with a ``[model.compliance]``, Pol-Ind on
the shipped height map with a compliance, ``fit`` of LuGre and of that map
model to synthetic records, and ``demo``; ``--quick`` runs only ``simulate``
of LuGre without and with a compliance.  Then the target rows: cold over
warm, the cost of a compliance, Pol-Ind over LuGre, the map fit's seconds.
A run that takes longer than ``--timeout`` is stopped and shown as "> T".
All files are temporary.  Run it on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict

from polind.bench import processes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", help="also write the rows as JSON to this file")
    parser.add_argument("--quick", action="store_true",
                        help="only simulate of LuGre without and with a compliance")
    parser.add_argument("--warm-runs", type=int, default=2, help="warm runs per case (best)")
    parser.add_argument("--cold-runs", type=int, default=2,
                        help="cold runs per case, each with an empty cache (best)")
    parser.add_argument("--timeout", type=float, default=processes.DEFAULT_TIMEOUT,
                        help="seconds a process may take (default %(default)g)")
    args = parser.parse_args(argv)
    print(processes.format_processes([]), flush=True)
    rows = processes.run_processes(
        quick=args.quick, warm_runs=args.warm_runs, cold_runs=args.cold_runs,
        timeout=args.timeout,
        progress=lambda row: print(processes.format_processes([row]).splitlines()[-1],
                                   flush=True))
    targets = processes.target_rows(rows)
    print("\n" + processes.format_targets(targets), flush=True)
    note = processes.bytecode_note()
    if note:
        print(note, flush=True)
    if args.json:
        with open(args.json, "w") as handle:
            json.dump({"processes": [asdict(r) | {"cold_over_warm": r.cold_over_warm}
                                     for r in rows],
                       "targets": [asdict(r) | {"met": r.met} for r in targets]},
                      handle, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
