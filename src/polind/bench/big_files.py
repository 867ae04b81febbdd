"""The big-file row of ``polind bench --big-files`` (issue 14): ``polind simulate`` end to end.

A 4-element Maxwell-slip model along a motion CSV of 1e7 samples (423 MB) is
run as the command line runs it, in its own process, and its wall time, CPU
time and peak resident memory are held to targets.  The pieces (the motion,
the model file, the measuring subprocess) serve ``benchmarks/big_files.py``
too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from polind.errors import InputError

#: The big-file case: a 4-element Maxwell-slip model along a motion CSV of 1e7 samples
#: (423 MB), run as the command line runs it.
BIG_FILE_SAMPLES = 10_000_000
BIG_FILE_MODEL = """\
[model]
type = "maxwell-slip"
stiffness = [1e5, 5e4, 2e4, 1e4]
breakaway_force = [0.2, 0.3, 0.25, 0.25]
viscous_coefficient = 0.0
"""
#: Its targets (issue 14): wall time [s] and peak resident memory [bytes].
BIG_FILE_TARGET_SECONDS = 8.0
BIG_FILE_TARGET_PEAK_BYTES = 1e9


def big_motion(samples):
    """``(t, x)``: a sinusoidal displacement (10 µm, 5 Hz) sampled at 100 kHz, jittered in t."""
    k = np.arange(samples, dtype=np.float64)
    t = k * 1e-5 + 1e-7 * np.sin(k)               # strictly increasing, 17 digits each
    return t, 1e-5 * np.sin(2.0 * np.pi * 5.0 * t)


def write_big_motion_csv(path, t, x, rows_per_chunk=100_000):
    """``t,x`` with every number in 17 significant digits, by NumPy and Python alone (so that
    the same file serves any version of polind)."""
    with open(path, "w", encoding="ascii") as stream:
        stream.write("t,x\n")
        for start in range(0, t.shape[0], rows_per_chunk):
            chunk = np.column_stack((t[start:start + rows_per_chunk],
                                     x[start:start + rows_per_chunk]))
            stream.write(("%.17g,%.17g\n" * chunk.shape[0]) % tuple(chunk.ravel().tolist()))


def polind_command():
    """The ``polind`` script beside this Python, else ``python -m polind``."""
    import sys
    from pathlib import Path

    script = Path(sys.executable).with_name("polind")
    return [str(script)] if script.exists() else [sys.executable, "-m", "polind"]


# Runs a command and prints its wall time, CPU time, peak RSS and exit status.  A child's
# peak RSS counts the memory of the process it was forked from (until its exec), so the
# command is started from this small process, not from the benchmark's own.
_MEASURE = """\
import json, os, subprocess, sys, time
started = time.perf_counter()
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL)
_, status, usage = os.wait4(child.pid, 0)
child.returncode = os.waitstatus_to_exitcode(status)
print(json.dumps([time.perf_counter() - started, usage.ru_utime + usage.ru_stime,
                  usage.ru_maxrss * 1024, child.returncode]))
"""


def run_measured(command):
    """``(wall seconds, CPU seconds, peak RSS bytes, exit status, stderr)`` of one subprocess."""
    import json
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", _MEASURE, *command], capture_output=True,
                          text=True, errors="replace")
    if done.returncode != 0:
        return 0.0, 0.0, 0, done.returncode, done.stderr
    seconds, cpu, peak, status = json.loads(done.stdout.strip().splitlines()[-1])
    return seconds, cpu, peak, status, done.stderr


@dataclass
class BigFileRow:
    samples: int
    input_bytes: int
    output_bytes: int
    seconds: float           # wall time of the `polind simulate` process
    cpu_seconds: float       # its user and system CPU time
    peak_bytes: int          # its peak resident memory

    @property
    def met(self) -> bool:
        return (self.seconds <= BIG_FILE_TARGET_SECONDS
                and self.peak_bytes <= BIG_FILE_TARGET_PEAK_BYTES)


def run_big_files(samples=BIG_FILE_SAMPLES, folder=None, progress=None) -> BigFileRow:
    """Time ``polind simulate MODEL -i MOTION.csv -o OUT.csv`` of :data:`BIG_FILE_MODEL`.

    The motion (:func:`big_motion`, ``samples`` rows) is written into a
    temporary directory (in ``folder`` if given; not timed), a run on its
    first 100 rows fills numba's cache, and then the whole run is one
    subprocess: its wall and CPU time and peak resident memory (``os.wait4``)
    are the row.  ``progress(text)`` is told what is being done.  The
    command's failure is an InputError with its message.
    """
    import tempfile
    from pathlib import Path

    from polind.resources import check_memory

    check_memory(16.0 * samples, f"The big-file case's motion ({samples:.3g} samples)")
    try:
        with tempfile.TemporaryDirectory(prefix="polind-bench-", dir=folder) as scratch:
            return _run_big_files(Path(scratch), samples, progress)
    except OSError as error:
        where = folder if folder is not None else tempfile.gettempdir()
        raise InputError(f"{where}: cannot hold the big-file case's files (about "
                         f"{128 * samples / 1e9:.2g} GB): {error.strerror or error}; expected a "
                         f"directory with that much free space (TMPDIR chooses it).") from None


def _run_big_files(scratch, samples, progress):
    model = scratch / "maxwell_slip.toml"
    model.write_text(BIG_FILE_MODEL)
    t, x = big_motion(samples)
    if progress is not None:
        progress(f"writing a motion of {samples:.3g} samples")
    motion = scratch / "motion.csv"
    write_big_motion_csv(motion, t, x)
    small = scratch / "small.csv"
    write_big_motion_csv(small, t[:100], x[:100])
    del t, x
    output = scratch / "out.csv"
    command = polind_command() + ["simulate", str(model), "-i"]
    for path in (small, motion):                          # the first: numba's cache
        if progress is not None and path == motion:
            progress("running polind simulate")
        seconds, cpu, peak, status, stderr = run_measured(command + [str(path), "-o",
                                                                       str(output)])
        if status != 0:
            raise InputError(f"polind simulate of the big-file case exited {status}: "
                             f"{' '.join(stderr.split())}")
    return BigFileRow(samples, motion.stat().st_size, output.stat().st_size, seconds, cpu, peak)


def format_big_files(row: BigFileRow) -> str:
    return (f"polind simulate, 4-element Maxwell-slip, {row.samples:.3g}-sample CSV in and out "
            f"({row.input_bytes / 1e6:.0f} MB in, {row.output_bytes / 1e6:.0f} MB out): "
            f"{row.seconds:.2f} s ({row.cpu_seconds:.2f} s of CPU), peak "
            f"{row.peak_bytes / 1e6:.0f} MB; target {BIG_FILE_TARGET_SECONDS:g} s and "
            f"{BIG_FILE_TARGET_PEAK_BYTES / 1e6:.0f} MB: {'met' if row.met else 'NOT met'}")
