"""Models shipped by another package: the entry-point group ``polind.models``.

Each test makes a real installed distribution in a temporary folder (a
package and its ``*.dist-info`` with ``entry_points.txt``), puts the folder on
``PYTHONPATH`` and runs the command line in a fresh process, as a user who
has ``pip install``-ed the package would.  No mock of ``importlib.metadata``.
"""

from __future__ import annotations

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import polind

#: The plugin's module: a smoothed Coulomb law ``F = Fc tanh(v / v0)`` (memoryless).
PLUGIN_SOURCE = '''
import math

import numpy as np
from numba import njit

import polind


@njit(cache=True)
def smooth_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
                normal_load):
    return scalars[0] * math.tanh(step_velocity / scalars[1])


@njit(cache=True)
def smooth_force(scalars, table, state, sample_velocity, normal_load):
    return scalars[0] * math.tanh(sample_velocity / scalars[1])


@njit(cache=True)
def smooth_tangent(scalars, table, state, step):
    return 0.0


class SmoothCoulomb(polind.FrictionModel):
    """Coulomb friction smoothed over a velocity v0."""

    type = "smooth-coulomb"
    title = "Smoothed Coulomb"
    parameters = (polind.Param("coulomb_force", unit="N", description="Fc"),
                  polind.Param("smoothing_velocity", unit="m/s", description="v0"))

    def step_functions(self):
        return polind.StepFunctions(smooth_step, smooth_force, smooth_tangent)

    def kernel_arrays(self, state):
        p = self.params
        return np.array([p["coulomb_force"], p["smoothing_velocity"]]), np.zeros((1, 0))

    def force_scale(self):
        return self.params["coulomb_force"]
'''

ROOT = Path(__file__).resolve().parents[1]


def install(site: Path, package: str, source: str, entry_points: dict) -> None:
    """A distribution ``package`` 0.1 in ``site``: its module and its dist-info."""
    (site / f"{package}.py").write_text(source)
    info = site / f"{package}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\nVersion: 0.1\n")
    lines = "".join(f"{name} = {value}\n" for name, value in entry_points.items())
    (info / "entry_points.txt").write_text(f"[polind.models]\n{lines}")


def polind_command(site: Path, *args, cwd: Path):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(ROOT / "src"),
                                         env.get("PYTHONPATH", "")])
    env["NUMBA_CACHE_DIR"] = str(site / "numba-cache")
    return subprocess.run([sys.executable, "-m", "polind", *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


def read_columns(path: Path) -> dict:
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {key: np.array([float(row[key]) for row in rows]) for key in rows[0]}


@pytest.fixture
def site(tmp_path):
    folder = tmp_path / "site"
    folder.mkdir()
    return folder


def test_a_plugin_model_runs_in_simulate_fit_and_sweep(site, tmp_path):
    install(site, "polind_smooth", PLUGIN_SOURCE, {"smooth-coulomb": "polind_smooth:SmoothCoulomb"})
    (tmp_path / "model.toml").write_text('[model]\ntype = "smooth-coulomb"\n'
                                         'coulomb_force = 2.0\nsmoothing_velocity = 1e-3\n'
                                         '[fit]\nfree = ["coulomb_force"]\n')
    t = np.linspace(0.0, 1.0, 401)
    x = 1e-3 * np.sin(2 * np.pi * t)
    with open(tmp_path / "motion.csv", "w") as handle:
        handle.write("t,x\n" + "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(t, x)))

    done = polind_command(site, "simulate", "model.toml", "-i", "motion.csv", "-o", "out.csv",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = read_columns(tmp_path / "out.csv")
    step_velocity = np.diff(x) / np.diff(t)
    np.testing.assert_allclose(out["F"][1:], 2.0 * np.tanh(step_velocity / 1e-3), rtol=1e-12)

    # fit: data made with Fc = 3 N, the model starts at 2 N
    with open(tmp_path / "data.csv", "w") as handle:
        handle.write("t,x,F\n" + "".join(
            f"{float(a)!r},{float(b)!r},{float(f)!r}\n" for a, b, f in zip(t, x, 1.5 * out["F"])))
    done = polind_command(site, "fit", "model.toml", "--data", "data.csv", "-o", "fitted.toml",
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    text = (tmp_path / "fitted.toml").read_text()
    assert 'type = "smooth-coulomb"' in text
    value = float(text.split("coulomb_force = ")[1].split("\n")[0])
    assert value == pytest.approx(3.0, rel=1e-6)

    (tmp_path / "sweep.toml").write_text(
        '[sweep]\nmodel = "model.toml"\nmotion = "motion.csv"\nmetrics = ["max_force"]\n'
        '[sweep.parameters]\n"model.coulomb_force" = { values = [1.0, 4.0] }\n')
    done = polind_command(site, "sweep", "sweep.toml", "-o", "results.csv", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    results = list(csv.DictReader(open(tmp_path / "results.csv", newline="")))
    maxima = sorted(float(row["max_force"]) for row in results)
    peak = math.tanh(np.max(np.abs(step_velocity)) / 1e-3)
    assert maxima == pytest.approx([1.0 * peak, 4.0 * peak], rel=1e-6)


def test_a_plugin_that_fails_to_import_is_one_line_naming_its_package(site, tmp_path):
    install(site, "polind_broken", "raise ImportError('no module named fortran_core')\n",
            {"smooth-coulomb": "polind_broken:SmoothCoulomb"})
    (tmp_path / "model.toml").write_text('[model]\ntype = "smooth-coulomb"\n'
                                         'coulomb_force = 2.0\nsmoothing_velocity = 1e-3\n')
    (tmp_path / "motion.csv").write_text("t,x\n0,0\n1,1e-3\n")
    done = polind_command(site, "simulate", "model.toml", "-i", "motion.csv", "-o", "out.csv",
                          cwd=tmp_path)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "polind_broken" in lines[0] and "fortran_core" in lines[0]
    assert not (tmp_path / "out.csv").exists()


def test_a_plugin_declaring_a_type_polind_has_is_refused_naming_its_package(site, tmp_path):
    install(site, "polind_clash", PLUGIN_SOURCE,
            {"lugre": "polind_clash:SmoothCoulomb",
             "smooth-coulomb": "polind_clash:SmoothCoulomb"})
    (tmp_path / "model.toml").write_text('[model]\ntype = "smooth-coulomb"\n'
                                         'coulomb_force = 2.0\nsmoothing_velocity = 1e-3\n')
    (tmp_path / "motion.csv").write_text("t,x\n0,0\n1,1e-3\n")
    done = polind_command(site, "simulate", "model.toml", "-i", "motion.csv", "-o", "out.csv",
                          cwd=tmp_path)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "polind_clash" in lines[0] and "'lugre'" in lines[0]


def test_the_registry_is_read_only_and_unregister_removes_a_type():
    with pytest.raises(TypeError):
        polind.MODEL_TYPES["mine"] = object          # only register_model changes it
    with pytest.raises(polind.InputError, match="not registered"):
        polind.unregister_model("no-such-model")
