"""``polind precompile`` (issue 38): every built-in model's kernels compiled once, into the cache.

The command's table of models and drivers is checked against the models
themselves (every built-in type is there, every runner module is compiled,
the processes' groups share none); a bad name or an unwritable cache is one
error line and exit 2; and after a precompile of two models into an empty
cache, in two processes, a fresh process that simulates them compiles nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys

from polind.bench import precompile
from polind.kernels.generate import MODELS

try:
    from test_cli import no_debug, run  # noqa: F401 - no_debug is an autouse fixture
except ImportError:  # tests/ run as a package
    from tests.test_cli import no_debug, run  # noqa: F401


def polind_process(*arguments, cache, timeout=300):
    """``polind ARGUMENTS`` in a fresh process with ``NUMBA_CACHE_DIR=cache``."""
    env = dict(os.environ, NUMBA_CACHE_DIR=os.fspath(cache))
    env.pop("POLIND_DEBUG", None)
    return subprocess.run([sys.executable, "-m", "polind", *map(os.fspath, arguments)],
                          env=env, capture_output=True, text=True, timeout=timeout)


def test_every_built_in_model_and_runner_module_is_compiled():
    from polind.models.registry import MODEL_TYPES

    own = [name for name, cls in MODEL_TYPES.items() if cls.__module__.startswith("polind.")]
    assert precompile.model_types() == own
    compiled = set()
    for name, variant in precompile.VARIANTS.items():
        model = precompile.variant_model(name)
        state = model.initial_state()
        fixed = model.fixed_load_step_functions(state)
        runners = {model.step_functions().runners} | ({fixed.runners} if fixed else set())
        assert runners == set(variant.runners), name       # what families() splits by
        compiled |= runners
    assert compiled == set(MODELS)
    assert precompile.VARIANTS["pol-ind elastic-plastic"].runners[0] == "pol_ind_plastic"
    assert precompile.variant_model("pol-ind elastic-plastic").plastic


def test_the_process_groups_share_no_runner_module_and_cover_every_task():
    work = precompile.tasks()
    assert len(work) == len(precompile.VARIANTS) * len(precompile.DRIVERS)
    groups = precompile.families(work)
    assert sorted(task for group in groups for task in group) == sorted(work)
    modules = [{module for name, _ in group for module in precompile.VARIANTS[name].grouped_by}
               for group in groups]
    for index, own in enumerate(modules):
        for other in modules[index + 1:]:
            assert not own & other
    # Pol-Ind's two variants are two groups, the first two (the longest compilations); a
    # module a variant shares is another group's own.
    assert [{name for name, _ in group} for group in groups[:2]] == [
        {"pol-ind"}, {"pol-ind elastic-plastic"}]
    for variant in precompile.VARIANTS.values():
        for module in variant.shared:
            assert any(module in other.grouped_by for other in precompile.VARIANTS.values())
    assert precompile.tasks(["lugre"], ["Body"]) == [("lugre", "Body")]


def test_an_unknown_model_or_driver_is_one_error_line_naming_it(capsys):
    status, out, err = run(capsys, "precompile", "--models", "lugre,friction-9000")
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith("polind: error: ")
    assert "'friction-9000'" in err and "--models" in err and "lugre" in err
    status, out, err = run(capsys, "precompile", "--drivers", "simulate-y")
    assert status == 2 and err.count("\n") == 1 and "'simulate-y'" in err and "--drivers" in err
    status, _, err = run(capsys, "precompile", "--jobs", "0")
    assert status == 2 and err.count("\n") == 1 and "--jobs" in err


def test_an_unwritable_cache_is_one_error_line(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    done = polind_process("precompile", "--models", "coulomb", cache=blocker / "cache")
    assert done.returncode == 2, done.stderr
    assert done.stdout == "" and done.stderr.count("\n") == 1
    assert done.stderr.startswith("polind: error: ") and "NUMBA_CACHE_DIR" in done.stderr


# A fresh process's kernels: cache misses (compiled) and hits (loaded) of every polind
# dispatcher, after simulating LuGre and Coulomb along positions, plain and behind a spring.
PROBE = """\
import sys, warnings
import numpy as np
import polind
from numba.core.dispatcher import Dispatcher
warnings.simplefilter("ignore")
t = np.linspace(0.0, 0.05, 501)
x = 1e-5 * np.sin(2.0 * np.pi * 40.0 * t)
for name in ("lugre", "coulomb"):
    model = polind.MODEL_TYPES[name].example()
    polind.simulate(model, t, x=x)
    polind.simulate(model.with_params(compliance={"stiffness": 4e4}), t, x=x)
kernels = {id(v): v for m in list(sys.modules.values()) if m and m.__name__.startswith("polind.")
           for v in vars(m).values() if isinstance(v, Dispatcher)}.values()
print(sum(sum(k.stats.cache_misses.values()) for k in kernels),
      sum(sum(k.stats.cache_hits.values()) for k in kernels))
"""


def test_after_a_precompile_a_fresh_simulate_compiles_nothing(tmp_path):
    cache = tmp_path / "cache"
    done = polind_process("precompile", "--models", "lugre,coulomb", "--drivers", "simulate-x",
                          "--jobs", "2", cache=cache)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""                            # piped: no progress bar
    lines = done.stdout.splitlines()
    assert "up to 2 processes" in lines[0] and "lugre" in done.stdout and "coulomb" in done.stdout
    assert lines[-1].startswith("compiled ") and not lines[-1].startswith("compiled 0 ")
    env = dict(os.environ, NUMBA_CACHE_DIR=os.fspath(cache))
    probe = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                           text=True, timeout=300)
    assert probe.returncode == 0, probe.stderr
    misses, hits = map(int, probe.stdout.split())
    assert misses == 0 and hits > 0
    again = polind_process("precompile", "--models", "lugre", "--drivers", "simulate-x",
                           "--quiet", cache=cache)
    assert again.returncode == 0 and again.stdout == "" and again.stderr == ""


def test_the_command_is_listed_with_its_options(capsys):
    status, out, _ = run(capsys, "--help")
    assert status == 0 and "precompile" in out
    status, out, _ = run(capsys, "precompile", "--help")
    assert status == 0
    for option in ("--models", "--drivers", "--jobs", "--quiet"):
        assert option in out
