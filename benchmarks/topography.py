"""A large height map read, levelled and reduced to summits (issue 11: 10 s at 4096 x 4096).

    python benchmarks/topography.py [--size N] [--keep DIR] [--missing FRACTION] [--x3p]

1. Makes a Gaussian random height map of N x N points (default 4096; rms
   0.5 µm, correlation length 8 pixels, tilted, pixel 0.5 µm) with NumPy
   alone and saves it as ``.npy`` (heights in metres) in a temporary
   directory (or ``--keep DIR``); ``--missing`` blanks that fraction of the
   points (NaN) at random.
2. Times, in this process, each step of ``polind.topography``: reading the
   ``.npy``, levelling, finding the summits and their curvatures (best of 3),
   and the same with the ISO 16610-61 low-pass at a cut-off of 4 pixels.
3. Runs ``polind topography MAP --pixel-size DX DY --json`` as a subprocess
   and reports its wall time (Python start-up and imports included) and CPU
   seconds; with ``--x3p``, the same for the map written as ISO 25178-72 x3p by
   SurfaceTopography (its reader and unit conversion included).
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

from polind.bench.surfaces import MAP_PIXEL as PIXEL
from polind.bench.surfaces import random_height_map as make_map


def best_of(function, repeat=3):
    times, result = [], None
    for _ in range(repeat):
        started = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - started)
    return min(times), result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--keep", type=Path, default=None)
    parser.add_argument("--missing", type=float, default=0.0)
    parser.add_argument("--x3p", action="store_true",
                        help="also write the map as x3p (SurfaceTopography) and time reading it")
    args = parser.parse_args(argv)
    if args.keep is None:
        with tempfile.TemporaryDirectory(prefix="polind-topography-") as folder:
            return run(Path(folder), args)
    args.keep.mkdir(parents=True, exist_ok=True)
    return run(args.keep, args)


def run(folder: Path, args) -> int:
    from polind.topography import analyse, read_height_map
    from polind.topography.summits import find_summits, level, low_pass, summit_curvatures

    path = folder / f"map_{args.size}.npy"
    started = time.perf_counter()
    np.save(path, make_map(args.size, args.missing))
    print(f"made {path} ({args.size} x {args.size}, {path.stat().st_size / 1e6:.0f} MB) in "
          f"{time.perf_counter() - started:.1f} s")

    pixel = (PIXEL, PIXEL)
    read_s, height_map = best_of(lambda: read_height_map(path, pixel))
    level_s, levelled = best_of(lambda: level(height_map.heights, pixel))
    find_s, (i, j) = best_of(lambda: find_summits(levelled))
    curvature_s, _ = best_of(lambda: summit_curvatures(levelled, pixel, i, j))
    total_s, surface = best_of(lambda: analyse(read_height_map(path, pixel)))
    filter_s, _ = best_of(lambda: low_pass(levelled, pixel, 4 * PIXEL), repeat=1)
    filtered_s, filtered = best_of(lambda: analyse(read_height_map(path, pixel),
                                                   short_cutoff=4 * PIXEL), repeat=1)
    print(f"read .npy {read_s:.2f} s, level {level_s:.2f} s, summits {find_s:.2f} s, "
          f"curvatures {curvature_s:.3f} s")
    print(f"read + level + summits (analyse): {total_s:.2f} s, {surface.summits:,} summits")
    print(f"with the low-pass (cut-off 4 pixels): filter alone {filter_s:.2f} s, all "
          f"{filtered_s:.2f} s, {filtered.summits:,} summits")

    polind = os.path.join(os.path.dirname(sys.executable), "polind")
    run_command([polind, "topography", str(path), "--pixel-size", str(PIXEL), str(PIXEL),
                 "--json"], "polind topography MAP.npy --json")
    if args.x3p:
        from SurfaceTopography import Topography

        x3p = path.with_suffix(".x3p")
        size = args.size * PIXEL
        Topography(np.load(path), (size, size), unit="m").to_x3p(str(x3p))
        run_command([polind, "topography", str(x3p), "--json"], "polind topography MAP.x3p --json")
    return 0


def run_command(command, label) -> None:
    """Run a ``polind`` command line; print its wall and CPU time and its summit count."""
    started = time.perf_counter()
    before = os.times()
    completed = subprocess.run(command, capture_output=True, text=True, check=True)
    after = os.times()
    wall = time.perf_counter() - started
    cpu = (after.children_user - before.children_user) + (after.children_system
                                                          - before.children_system)
    summits = json.loads(completed.stdout)["summits"]
    print(f"{label} (subprocess): {wall:.2f} s wall, {cpu:.2f} s CPU, {summits:,} summits")


if __name__ == "__main__":
    sys.exit(main())
