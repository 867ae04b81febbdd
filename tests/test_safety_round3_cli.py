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

import math
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import polind
from polind.errors import InputError
from polind.models.registry import PARAM_KINDS
from polind.validation import BOUNDS

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


# --- plugins that misbehave ---------------------------------------------------------------------

PLUGIN = '''
import math
import sys

import numpy as np
from numba import njit

import polind

{prelude}

@njit
def step(scalars, table, state, h, dx, step_velocity, sample_velocity, normal_load):
{step}


@njit
def force(scalars, table, state, sample_velocity, normal_load):
    return 0.0


@njit
def tangent(scalars, table, state, h):
    return 0.0


class Plugged(polind.FrictionModel):
    type = "{name}"
    parameters = (polind.Param("coulomb_force", unit="N"),)

    def step_functions(self):
        return polind.StepFunctions(step, force, tangent)

    def kernel_arrays(self, state):
        return np.array([self.params["coulomb_force"]]), np.zeros((1, 0))
'''

#: A plugin's defect, what its module does, and what the one line must say.
PLUGIN_DEFECTS = {
    "raises": ("", "    raise ValueError('no force')", "returns none instead (it only raises)"),
    "array": ("", "    return scalars", "returns array(float64, 1d, C) instead"),
    "untyped": ("", "    return scalars.no_such_attribute", "does not compile"),
    "exits": ("sys.exit(0)", "    return 1.0", "its import called sys.exit(0)"),
}


@pytest.fixture
def plugged(tmp_path, monkeypatch):
    """Install a plugin module as an entry point ``polind.models`` (no dist: its module names
    it), the files of a run of it; unregister what it registered afterwards."""
    from importlib.metadata import EntryPoint

    from polind.models import registry

    site = tmp_path / "site"
    site.mkdir()
    monkeypatch.syspath_prepend(str(site))
    points = []
    monkeypatch.setattr(registry, "_entry_points", lambda: points)
    (tmp_path / "motion.csv").write_text("t,x\n0,0\n0.001,1e-6\n0.002,3e-6\n")

    def plug(defect):
        prelude, step, _ = PLUGIN_DEFECTS[defect]
        name, module = f"plugged-{defect}", f"polind_plugged_{defect}"
        (site / f"{module}.py").write_text(PLUGIN.format(prelude=prelude, step=step, name=name))
        points.append(EntryPoint(name, f"{module}:Plugged", registry.ENTRY_POINT_GROUP))
        model = tmp_path / f"{defect}.toml"
        model.write_text(f'[model]\ntype = "{name}"\ncoulomb_force = 1.0\n')
        return model, module

    yield plug
    for point in points:
        if point.name in polind.MODEL_TYPES:
            polind.unregister_model(point.name)
        sys.modules.pop(point.value.partition(":")[0], None)


@pytest.mark.parametrize("defect", sorted(PLUGIN_DEFECTS))
def test_a_plugin_that_fails_is_exit_2_in_one_line_naming_it(plugged, tmp_path, capsys, defect):
    from polind.cli import _run

    model, module = plugged(defect)
    out = tmp_path / "out.csv"
    status = _run(["simulate", str(model), "-i", str(tmp_path / "motion.csv"), "-o", str(out)])
    lines = capsys.readouterr().err.strip().splitlines()
    assert status == 2, lines
    assert len(lines) == 1 and lines[0].startswith("polind: error: ")
    assert f"'plugged-{defect}' ({module}:Plugged)" in lines[0]      # the entry point
    assert PLUGIN_DEFECTS[defect][2] in lines[0]
    assert not out.exists()


# --- declarations register_model cannot use ---------------------------------------------------

def _model_class(parameters):
    """A model class declaring ``parameters`` (set after the class statement, as a
    decorator or a metaclass could), never registered."""
    from numba import njit

    @njit
    def zero(*args):
        return 0.0

    class Declared(polind.FrictionModel):
        type = "declared"

        def step_functions(self):
            return polind.StepFunctions(zero, zero, zero)

        def kernel_arrays(self, state):
            return np.zeros(1), np.zeros((1, 0))

    Declared.parameters = parameters
    return Declared


Param = polind.Param

BAD_DECLARATIONS = [
    (("coulomb_force", "stiffness"), "declares 'coulomb_force' as entry 0 of its 'parameters'"),
    ("coulomb_force", "must declare its 'parameters' as a tuple"),
    ((Param("coulomb_force"), Param("coulomb_force")), "'coulomb_force' twice"),
    ((Param(3),), "whose key is 3"),
    ((Param("coulomb_force", default="two"),), "'coulomb_force' with a default its own checks"),
    ((Param("shape", kind="str", choices="ab", default="a"),), "the choices 'ab'"),
    ((polind.Table("surface", entries=("height_std",)),),
     "declares 'height_std' as entry 0 of its 'surface' table's entries"),
]


@pytest.mark.parametrize("parameters, message", BAD_DECLARATIONS)
def test_register_model_refuses_parameters_it_cannot_use_naming_them(parameters, message):
    with pytest.raises(InputError, match="The model class Declared ") as refused:
        polind.register_model(_model_class(parameters))
    assert message in str(refused.value)
    assert "declared" not in polind.MODEL_TYPES


def test_a_class_declaring_strings_can_be_defined_and_is_refused_at_registration():
    functions = _model_class(()).step_functions

    class Strings(polind.FrictionModel):
        type = "strings"
        parameters = ("coulomb_force",)
        step_functions = functions

        def kernel_arrays(self, state):
            return np.zeros(1), np.zeros((1, 0))

    with pytest.raises(InputError, match="The model class Strings declares 'coulomb_force' as "
                                         "entry 0 of its 'parameters'"):
        polind.register_model(Strings)


@settings(max_examples=15, deadline=None, database=None)
@given(field=st.sampled_from(["bound", "kind"]),
       value=st.text(min_size=1, max_size=12).filter(
           lambda text: text not in (*BOUNDS, *PARAM_KINDS)))
def test_an_unknown_bound_or_kind_is_refused_at_registration(field, value):
    declared = _model_class((Param("coulomb_force", **{field: value}),))
    with pytest.raises(InputError) as refused:
        polind.register_model(declared)
    text = str(refused.value)
    assert text.startswith("The model class Declared declares the parameter 'coulomb_force' "
                           f"{'with the bound' if field == 'bound' else 'of kind'} ")
    assert "expected one of: " in text



# --- no writable numba cache --------------------------------------------------------------------

def test_no_writable_numba_cache_falls_back_to_a_temporary_folder_with_a_note(tmp_path,
                                                                              monkeypatch):
    """A read-only install: NUMBA_CACHE_DIR cannot be made (a file is in the way, which
    stops root too), and numba's own folders (the package's tree, the home) cannot be
    written either.  A polind kernel still compiles, caches and runs."""
    import tempfile

    from numba import njit
    from numba.core import caching, config

    from polind.kernels import cache, stribeck

    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setattr(config, "CACHE_DIR", str(blocker / "numba"))
    for name in ("InTreeCacheLocator", "UserWideCacheLocator"):
        monkeypatch.setattr(getattr(caching, name), "from_function",
                            classmethod(lambda cls, py_func, py_file: None))
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temporary))
    cache.temporary_base.cache_clear()
    monkeypatch.setattr(cache, "_NOTED", [])
    try:
        with pytest.warns(UserWarning, match=r"numba's cache folder .*a-file/numba cannot be "
                                             r"written; the compiled kernels are cached in "):
            curve = njit(cache=True)(stribeck.stribeck_curve.py_func)
        assert curve(1e-3, 1.0, 1.5, 1e-3, 2.0, 0) == \
            stribeck.stribeck_curve.py_func(1e-3, 1.0, 1.5, 1e-3, 2.0, 0)
    finally:
        cache.temporary_base.cache_clear()
    folder = temporary / f"polind-numba-cache-{os.getuid()}"
    assert any(path.suffix == ".nbi" for path in folder.rglob("*"))       # cached there
    assert folder.stat().st_mode & 0o777 == 0o700


# --- one finiteness check of every run's forces ------------------------------------------------

def _counting_model():
    """A model whose force turns ``nan``, ``inf`` or ``-inf`` (scalars[2] = 1, 2, 3) from the
    sample scalars[1] on, 1 N before; registered as "turning"."""
    from numba import njit

    @njit
    def step(scalars, table, state, h, dx, step_velocity, sample_velocity, normal_load):
        state[0] += 1.0
        if state[0] < scalars[1]:
            return scalars[0]
        if scalars[2] == 1.0:
            return math.nan
        return math.inf if scalars[2] == 2.0 else -math.inf

    @njit
    def force(scalars, table, state, sample_velocity, normal_load):
        return scalars[0]

    @njit
    def tangent(scalars, table, state, h):
        return 0.0

    class Turning(polind.FrictionModel):
        type = "turning"
        parameters = (Param("coulomb_force", unit="N"), Param("turn", kind="int"),
                      Param("value", kind="int"))

        def initial_variables(self, normal_load=None):
            return {"count": np.zeros(1)}

        def step_functions(self):
            return polind.StepFunctions(step, force, tangent)

        def kernel_arrays(self, state):
            p = self.params
            return np.array([p["coulomb_force"], p["turn"], p["value"]]), np.zeros((1, 0))

    return Turning


@pytest.fixture(scope="module")
def turning():
    polind.register_model(_counting_model())
    yield
    polind.unregister_model("turning")


@settings(max_examples=15, deadline=None, database=None)
@given(turn=st.integers(1, 199), value=st.sampled_from([1, 2, 3]))
def test_a_run_whose_forces_are_not_finite_is_refused_naming_the_sample(turning, turn, value):
    model = polind.model_from_dict({"model": {"type": "turning", "coulomb_force": 1.0,
                                              "turn": turn, "value": value}})
    t = np.linspace(0.0, 0.2, 200)
    with pytest.raises(InputError) as refused:
        polind.simulate(model, t, x=1e-4 * t)
    text = {1: "nan", 2: "inf", 3: "-inf"}[value]
    assert str(refused.value).startswith(
        f"the run's friction force is {text} at t = {t[turn]:.6g} s (sample {turn + 1} of 200): "
        f"the turning model (the model class ")
    finite = polind.model_from_dict({"model": {"type": "turning", "coulomb_force": 1.0,
                                               "turn": 500, "value": value}})
    assert np.all(polind.simulate(finite, t, x=1e-4 * t).force == 1.0)


def test_a_body_whose_friction_is_not_finite_is_refused_too(turning):
    """simulate_system passes the same check as simulate (it returned the NaN before)."""
    model = polind.model_from_dict({"model": {"type": "turning", "coulomb_force": 1.0,
                                              "turn": 20, "value": 1}})
    system = polind.System(mass=1.0, duration=0.1, time_step=1e-3, spring_stiffness=1e3,
                           drive_velocity=1e-3)
    with pytest.raises(InputError, match=r"^the run's friction force is nan at t = .* "
                                         r"the turning model \(the model class "):
        polind.simulate_system(model, system)



def test_a_finished_run_ignores_the_terminals_signals_to_its_exit():
    """The interpreter's finalisation puts back the default handler of every signal a Python
    function handles: a signal in that last window killed a run whose output was complete
    (status -15).  The program ignores them once its status is decided (seen at exit)."""
    script = ("import atexit, runpy, signal, sys\n"
              "atexit.register(lambda: print([signal.getsignal(n) is signal.SIG_IGN for n in "
              "(signal.SIGINT, signal.SIGTERM, signal.SIGHUP)], file=sys.stderr))\n"
              "sys.argv = ['polind', '--version']\n"
              "runpy.run_module('polind', run_name='__main__', alter_sys=True)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stderr.strip().splitlines()[-1] == "[True, True, True]", done.stderr


def test_an_interrupt_where_python_cannot_raise_it_is_not_printed(capsys):
    """A signal during numba's compilation raises Interrupted inside a ctypes callback, where
    Python prints it as 'Exception ignored ... Traceback'; the signal is remembered (it stops
    the run at the next checkpoint), so that print is dropped, and only that one."""
    from types import SimpleNamespace

    import polind.cli as cli

    forwarded = []
    previous, cli._Signals.unraisable = cli._Signals.unraisable, forwarded.append
    try:
        cli._on_unraisable(SimpleNamespace(exc_value=cli.Interrupted(signal.SIGTERM)))
        other = SimpleNamespace(exc_value=ValueError("a real one"))
        cli._on_unraisable(other)
    finally:
        cli._Signals.unraisable = previous
    assert forwarded == [other]
