"""numba's on-disk cache of the kernels cannot go stale (polind.kernels.cache).

A copy of the package is run in fresh processes with its own cache folder:
after a helper in one kernel file changes, a cached kernel of another file
that inlines it must give the new result, not the one compiled before.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "polind"

# The Stribeck model's runners (kernels/generated/memoryless.py) inline the curve of
# kernels/stribeck.py.
PROBE = ("import numpy as np, polind\n"
         "from polind.models import Stribeck\n"
         "t = np.linspace(0.0, 1.0, 11)\n"
         "print(repr(float(polind.simulate(Stribeck.example(), t, x=1e-3 * t).force[-1])))\n"
         "from numba.core.dispatcher import Dispatcher\n"
         "from polind.kernels.generated import memoryless\n"
         "print(sum(sum(d.stats.cache_hits.values()) for d in vars(memoryless).values()\n"
         "          if isinstance(d, Dispatcher)))\n")


def run(folder: Path, cache: Path):
    env = dict(os.environ, PYTHONPATH=str(folder), NUMBA_CACHE_DIR=str(cache))
    done = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    force, hits = done.stdout.split("\n")[:2]
    return float(force), hits


@pytest.fixture
def package_copy(tmp_path):
    target = tmp_path / "src" / "polind"
    shutil.copytree(SOURCE, target, ignore=shutil.ignore_patterns("__pycache__"))
    return tmp_path / "src"


def test_a_changed_helper_in_another_file_recompiles_its_cached_caller(package_copy, tmp_path):
    cache = tmp_path / "numba-cache"
    first, _ = run(package_copy, cache)
    again, hits = run(package_copy, cache)
    assert again == first and int(hits) > 0          # the second process loaded the cache
    curve = package_copy / "polind" / "kernels" / "stribeck.py"
    text = curve.read_text()
    changed = text.replace("return coulomb_force + (static_force - coulomb_force) * decay",
                           "return 1.0001 * (coulomb_force + (static_force - coulomb_force) * decay)")
    assert changed != text
    curve.write_text(changed)
    after, _ = run(package_copy, cache)
    viscous = 0.4 * 1e-3                             # sigma2 v, outside the curve
    assert after == pytest.approx(1.0001 * (first - viscous) + viscous, rel=1e-12)
    assert any(path.name.startswith("polind-") for path in cache.rglob("*") if path.is_dir())


def test_the_stamp_covers_every_kernel_source():
    from polind.kernels import cache

    stamp = cache.sources_stamp(cache.KERNELS_DIR / "static.py")
    assert stamp == cache.sources_stamp(cache.KERNELS_DIR / "static.py")
    assert {path.name for path in cache._kernel_files()} >= {"static.py", "stribeck.py",
                                                              "elements.py", "cache.py"}


# A LuGre contact behind a series spring (the mounted runners, the path every rig needs).
MOUNTED = ("import numpy as np, polind\n"
           "from polind.models import LuGre\n"
           "model = LuGre.example().with_params(compliance={'stiffness': 1e5})\n"
           "t = np.linspace(0.0, 1.0, 101)\n"
           "print(repr(float(polind.simulate(model, t, x=1e-4 * t).force[-1])))\n"
           "from polind.kernels.generated import lugre\n"
           "print(sum(lugre.mounted_path.stats.cache_hits.values()),\n"
           "      sum(lugre.mounted_path.stats.cache_misses.values()))\n"
           "print(len(lugre.spring_trial.signatures))\n")


def test_the_mounted_path_is_cached_after_its_first_process(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    outputs = []
    for _ in range(2):
        done = subprocess.run([sys.executable, "-c", MOUNTED], env=env, capture_output=True,
                              text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        outputs.append(done.stdout.split("\n")[:3])
    (first, cold, trials), (second, warm, _) = outputs
    assert first == second
    assert cold == "0 1"        # compiled in the first process
    assert warm == "1 0"        # loaded from the cache in the second
    # The spring's trial compiled once: the solver's first call (keep false) and its
    # later ones pass `keep` of one type (a literal False would be a second type).
    assert trials == "1"


SAME_RUN = ("import numpy as np, polind\n"
            "from polind.models import MODEL_TYPES\n"
            "t = np.cumsum(np.random.default_rng(7).uniform(1e-4, 2e-4, 3001))\n"
            "x = 3e-5 * np.sin(2 * np.pi * 30 * t)\n"
            "for name in ('lugre',):\n"
            "    force = polind.simulate(MODEL_TYPES[name].example(), t, x=x).force\n"
            "    print(force.tobytes().hex())\n")


def test_a_run_is_the_same_to_the_bit_from_a_cold_and_from_a_warm_cache(tmp_path):
    # With the compiler free to fuse multiply-adds, a kernel loaded from the cache rounded
    # one last place differently from the same kernel compiled in the process (LuGre's
    # blocks, 404 of 3001 forces): a result depended on whether the cache was warm.
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    runs = []
    for _ in range(2):
        done = subprocess.run([sys.executable, "-c", SAME_RUN], env=env, capture_output=True,
                              text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        runs.append(done.stdout.split())
    cold, warm = runs
    assert len(cold) == 1 and cold == warm
