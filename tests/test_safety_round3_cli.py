"""Nothing lost, round three (issue 44): signals, plugins, read-only caches, finiteness.

* Every signal a terminal sends (SIGINT, SIGTERM, SIGHUP) ends ``polind
  simulate`` at any moment with status 130, no output and no temporary file
  (a signal whose exception a library swallows too), or, once the output is
  complete, with the whole output and status 0 (cause: signals at start-up).
* A plugin that fails (a step that does not give a number, a ``sys.exit`` on
  import) is exit 2 with one line naming the plugin.
* A declaration ``register_model`` cannot use is refused there, naming the class
  and the entry.
* No writable numba cache: the kernels are cached in a temporary folder, with a
  note.
* Every run's forces pass one finiteness check, whoever wrote the model.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import polind
from polind.errors import InputError

ROOT = Path(__file__).resolve().parents[1]

LUGRE = """[model]
type = "lugre"
bristle_stiffness = 1e5
bristle_damping = 316.0
viscous_coefficient = 0.4
coulomb_force = 1.0
static_force = 1.5
stribeck_velocity = 1e-3
"""


def polind_process(*args, cwd, env=None):
    """``python -m polind ARGS`` started (not waited for)."""
    return subprocess.Popen([sys.executable, "-m", "polind", *map(str, args)], cwd=cwd,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


# --- signals ----------------------------------------------------------------------------------

def _interrupted_run(inputs: Path, folder: Path, delay: float, number: int):
    """Run simulate into ``folder``, send ``number`` after ``delay`` s: (status, stderr, sent).

    ``sent`` is the wall-clock time of the signal [ns] (None: the run had ended).
    """
    folder.mkdir()
    process = polind_process("simulate", inputs / "model.toml", "-i", inputs / "motion.csv",
                             "-o", folder / "out.csv", cwd=folder)
    time.sleep(delay)
    sent = time.time_ns() if process.poll() is None else None
    process.send_signal(number)
    _, stderr = process.communicate(timeout=120)
    return process.returncode, stderr, sent


def test_a_signal_at_any_moment_ends_simulate_with_130_and_nothing_left(tmp_path):
    inputs = tmp_path / "inputs"
    inputs.mkdir()
    (inputs / "model.toml").write_text(LUGRE)
    # Over 1 MiB: pyarrow reads it (and imports pandas, in code that swallows exceptions).
    t = np.linspace(0.0, 2.0, 60_000)
    np.savetxt(inputs / "motion.csv", np.column_stack([t, 1e-3 * np.sin(2 * np.pi * t)]),
               delimiter=",", header="t,x", comments="", fmt="%.17g")
    clock = time.monotonic()
    whole = polind_process("simulate", inputs / "model.toml", "-i", inputs / "motion.csv",
                           "-o", tmp_path / "whole.csv", cwd=tmp_path)
    whole.communicate(timeout=120)
    duration = time.monotonic() - clock
    assert whole.returncode == 0
    expected = (tmp_path / "whole.csv").read_bytes()

    numbers = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]
    moments = np.linspace(0.1, duration, 20)
    with ThreadPoolExecutor(2) as pool:
        runs = list(pool.map(lambda k: _interrupted_run(inputs, tmp_path / f"run{k}",
                                                        float(moments[k]), numbers[k % 3]),
                             range(len(moments))))
    for k, (status, stderr, sent) in enumerate(runs):
        folder = tmp_path / f"run{k}"
        left = sorted(path.name for path in folder.iterdir())
        what = f"{numbers[k % 3].name} at {moments[k]:.2f} s: status {status}, {left}, {stderr!r}"
        assert "Traceback" not in stderr, what
        if status == 130:
            assert left == [], what
            assert stderr.strip().splitlines()[-1].startswith("polind: error: interrupted"), what
        else:
            # Only a run whose output was complete before the signal may end with it.
            assert status == 0 and left == ["out.csv"], what
            out = folder / "out.csv"
            assert out.read_bytes() == expected, what
            assert sent is None or out.stat().st_mtime_ns <= sent, what
    assert sum(status == 130 for status, _, _ in runs) >= 10
