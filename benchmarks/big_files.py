"""Big motion files at disk speed: `polind simulate` on a 1e7-sample motion (issue 14, item 5).

    python benchmarks/big_files.py [--samples N] [--keep DIR] [--parquet] [--no-cli]

1. Writes a motion file of N samples (default 1e7, columns ``t,x``, every
   number with 17 significant digits: 417 MB at 1e7) and a 4-element
   Maxwell-slip model file into a temporary directory (or ``--keep DIR``).
   The files are made with NumPy alone, so the same input serves any version
   of polind.
2. Runs ``polind simulate MODEL -i MOTION -o OUT`` as a subprocess (after a
   small warm-up run, so that numba's cache is filled) and reports its wall
   time and peak resident memory (``os.wait4``'s ``ru_maxrss``): the row of
   ``polind bench --big-files``, whose pieces (the motion, the model, the
   measured subprocess) this script shares.  With
   ``--parquet`` the same run with ``.parquet`` input and output too.
3. Times the reading, the computing and the writing inside one process.
   The machine's other load shows in wall times: the CPU seconds of each
   subprocess are reported beside them.
4. Measures ``polind.simulate`` itself: the bytes it allocates per sample
   beyond its inputs (tracemalloc's peak, which NumPy's arrays report to), for
   a displacement motion, a velocity motion, and a displacement motion with a
   normal-load signal, each in a fresh process.

Targets (issue 14): the CLI run in at most 8 s and 1 GB peak at 1e7 samples,
``simulate`` at most 40 bytes per sample.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from polind.bench.big_files import (BIG_FILE_MODEL as MODEL_TOML,
                                    BIG_FILE_TARGET_PEAK_BYTES as TARGET_PEAK_BYTES,
                                    BIG_FILE_TARGET_SECONDS as TARGET_SECONDS,
                                    big_motion as motion, polind_command, run_measured,
                                    write_big_motion_csv as write_motion_csv)

# The same model scaling with a normal-load signal (for the normal_load case of simulate).
MODEL_WITH_LOAD = {"model": {"type": "maxwell-slip", "stiffness": [1e5, 5e4, 2e4, 1e4],
                             "breakaway_force": [0.2, 0.3, 0.25, 0.25],
                             "viscous_coefficient": 0.0, "reference_load": 10.0}}

TARGET_BYTES_PER_SAMPLE = 40.0


def write_motion_parquet(path, t, x):
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table({"t": t, "x": x}), path)


def cli_case(folder, model_path, motion_path, output_path):
    command = polind_command() + ["simulate", str(model_path), "-i", str(motion_path),
                                  "-o", str(output_path)]
    seconds, cpu, peak, status, stderr = run_measured(command)
    if status != 0:
        raise SystemExit(f"{' '.join(command)} exited {status}: {stderr.strip()}")
    return {"seconds": seconds, "cpu_seconds": cpu, "peak_bytes": peak,
            "input_bytes": os.path.getsize(motion_path),
            "output_bytes": os.path.getsize(output_path)}


def in_process_breakdown(model_path, motion_path, output_path):
    """Seconds of reading, simulating and writing (one process, after a warm-up)."""
    import polind
    from polind import io

    model = polind.load_model(model_path)
    polind.simulate(model, np.linspace(0.0, 1.0, 10), x=np.zeros(10))     # numba warm-up
    started = time.perf_counter()
    samples = io.read_motion_csv(motion_path)
    read = time.perf_counter()
    result = polind.simulate(model, samples["t"], x=samples["x"])
    computed = time.perf_counter()
    io.write_csv_atomic(output_path, {"t": result.t, "x": result.x, "v": result.v,
                                      "F": result.force})
    written = time.perf_counter()
    return {"read": read - started, "simulate": computed - read, "write": written - computed}


_BYTES_PER_SAMPLE = """
import json, sys, tracemalloc, warnings
import numpy as np
import polind
case, samples = sys.argv[1], int(sys.argv[2])
model = polind.model_from_dict(json.loads(sys.argv[3]))
k = np.arange(samples, dtype=np.float64)
t = k * 1e-5
motion = 1e-5 * np.sin(2.0 * np.pi * 5.0 * t)
load = 10.0 + np.cos(t) if case == "x+normal_load" else None
keyword = "v" if case == "v" else "x"
small = {keyword: motion[:10]}
polind.simulate(model, t[:10], normal_load=None if load is None else load[:10], **small)
tracemalloc.start()
before = tracemalloc.get_traced_memory()[0]
result = polind.simulate(model, t, normal_load=load, **{keyword: motion})
peak = tracemalloc.get_traced_memory()[1]
print(json.dumps({"bytes_per_sample": (peak - before) / samples}))
"""


def bytes_per_sample(samples):
    rows = {}
    for case in ("x", "v", "x+normal_load"):
        output = subprocess.run([sys.executable, "-c", _BYTES_PER_SAMPLE, case, str(samples),
                                 json.dumps(MODEL_WITH_LOAD)],
                                check=True, capture_output=True, text=True).stdout
        rows[case] = json.loads(output.strip().splitlines()[-1])["bytes_per_sample"]
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=float, default=1e7, help="samples (default 1e7)")
    parser.add_argument("--keep", help="write the files into this directory and keep them")
    parser.add_argument("--parquet", action="store_true", help="also run .parquet in and out")
    parser.add_argument("--no-cli", action="store_true", help="only simulate's bytes per sample")
    parser.add_argument("--json", help="also write the numbers as JSON to this file")
    args = parser.parse_args(argv)
    samples = int(args.samples)
    report = {"samples": samples}
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(args.keep or scratch)
        folder.mkdir(parents=True, exist_ok=True)
        if not args.no_cli:
            model_path = folder / "maxwell_slip.toml"
            model_path.write_text(MODEL_TOML)
            t, x = motion(samples)
            motion_path = folder / "motion.csv"
            if not motion_path.exists() or args.keep is None:
                write_motion_csv(motion_path, t, x)
            small = folder / "small.csv"
            write_motion_csv(small, t[:100], x[:100])
            cli_case(folder, model_path, small, folder / "small_out.csv")       # warm-up
            report["cli_csv"] = cli_case(folder, model_path, motion_path, folder / "out.csv")
            print(f"polind simulate, CSV in and out, {samples:.3g} samples: "
                  f"{report['cli_csv']['seconds']:.2f} s ("
                  f"{report['cli_csv']['cpu_seconds']:.2f} s of CPU), peak "
                  f"{report['cli_csv']['peak_bytes'] / 1e6:.0f} MB (input "
                  f"{report['cli_csv']['input_bytes'] / 1e6:.0f} MB, output "
                  f"{report['cli_csv']['output_bytes'] / 1e6:.0f} MB); target "
                  f"{TARGET_SECONDS:g} s, {TARGET_PEAK_BYTES / 1e6:.0f} MB", flush=True)
            if args.parquet:
                parquet_path = folder / "motion.parquet"
                write_motion_parquet(parquet_path, t, x)
                report["cli_parquet"] = cli_case(folder, model_path, parquet_path,
                                                 folder / "out.parquet")
                print(f"polind simulate, Parquet in and out: "
                      f"{report['cli_parquet']['seconds']:.2f} s ("
                      f"{report['cli_parquet']['cpu_seconds']:.2f} s of CPU), peak "
                      f"{report['cli_parquet']['peak_bytes'] / 1e6:.0f} MB", flush=True)
            del t, x
            report["in_process_seconds"] = in_process_breakdown(model_path, motion_path,
                                                                folder / "out2.csv")
            print("in one process: " + ", ".join(
                f"{stage} {seconds:.2f} s"
                for stage, seconds in report["in_process_seconds"].items()), flush=True)
        report["simulate_bytes_per_sample"] = bytes_per_sample(samples)
        print("polind.simulate, bytes per sample beyond its inputs: " + ", ".join(
            f"{case} {value:.1f}" for case, value in report["simulate_bytes_per_sample"].items())
              + f"; target {TARGET_BYTES_PER_SAMPLE:g}", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
