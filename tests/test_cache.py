"""numba's on-disk cache of the kernels cannot go stale (polind.kernels.cache).

A copy of the package is run in fresh processes with its own cache folder:
after a helper in one kernel file changes, a cached kernel of another file
that inlines it must give the new result, not the one compiled before.  One cold
and one warm process of the installed package (a module fixture) check what is
cached and that a run is the same from either.
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


# One cold process (an empty numba cache) and one warm process (the cache the cold one
# left) run the checks below, each with its own kernels:
# - the scipy-calling kernels (a function pointer as a global would stop numba caching;
#   the run-time addresses do not), with every NumbaWarning an error;
# - a LuGre contact behind a series spring (the mounted runners, the path every rig needs);
# - a plain LuGre run, printed to the bit.
SHARED = ("import warnings\n"
          "from numba.core.errors import NumbaWarning\n"
          "warnings.simplefilter('error', NumbaWarning)\n"
          "import numpy as np\n"
          "from polind.kernels.greenwood import gw_half_integer_pair, gw_half_integer_pair_fast\n"
          "from polind.kernels.separation import STATISTICAL, newton_separation\n"
          "from polind.kernels.special import kve, special_addresses\n"
          "addresses = special_addresses()\n"
          "sigma = 0.5e-6\n"
          "d, value, slope = newton_separation(100.0, 0.0, -5 * sigma, 10 * sigma, STATISTICAL,\n"
          "                                    3.8e5, sigma, np.empty(0), np.empty(0), 0.0,\n"
          "                                    addresses)\n"
          "assert abs(value - 100.0) <= 1e-8, value\n"
          "gw_half_integer_pair(0.3, addresses)\n"
          "gw_half_integer_pair_fast(0.3, addresses)\n"
          "kve(0.25, 1.0, addresses)\n"
          "for function in (newton_separation, gw_half_integer_pair, gw_half_integer_pair_fast,\n"
          "                 kve):\n"
          "    print('scipy', function.__name__, sum(function.stats.cache_hits.values()),\n"
          "          sum(function.stats.cache_misses.values()))\n"
          # the mounted LuGre
          "import polind\n"
          "from polind.models import LuGre\n"
          "model = LuGre.example().with_params(compliance={'stiffness': 1e5})\n"
          "t = np.linspace(0.0, 1.0, 101)\n"
          "print('mounted_force', repr(float(polind.simulate(model, t, x=1e-4 * t).force[-1])))\n"
          "from polind.kernels.generated import lugre\n"
          "print('mounted_stats', sum(lugre.mounted_path.stats.cache_hits.values()),\n"
          "      sum(lugre.mounted_path.stats.cache_misses.values()))\n"
          "print('mounted_trials', len(lugre.spring_trial.signatures))\n"
          # the same run to the bit
          "from polind.models import MODEL_TYPES\n"
          "t = np.cumsum(np.random.default_rng(7).uniform(1e-4, 2e-4, 3001))\n"
          "x = 3e-5 * np.sin(2 * np.pi * 30 * t)\n"
          "for name in ('lugre',):\n"
          "    force = polind.simulate(MODEL_TYPES[name].example(), t, x=x).force\n"
          "    print('same_run', force.tobytes().hex())\n")


@pytest.fixture(scope="module")
def cold_and_warm(tmp_path_factory):
    """SHARED run twice with one new numba cache: ``([cold, warm], cache folder)``, each
    process as ``(stderr, {tag: [its lines' fields]})``."""
    cache = tmp_path_factory.mktemp("shared") / "cache"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    runs = []
    for _ in range(2):
        done = subprocess.run([sys.executable, "-c", SHARED], env=env, capture_output=True,
                              text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        lines = {}
        for line in done.stdout.splitlines():
            tag, *fields = line.split()
            lines.setdefault(tag, []).append(fields)
        runs.append((done.stderr, lines))
    return runs, cache


def test_the_mounted_path_is_cached_after_its_first_process(cold_and_warm):
    runs, _ = cold_and_warm
    (_, one), (_, two) = runs
    first, second = one["mounted_force"], two["mounted_force"]
    cold, warm = (" ".join(lines["mounted_stats"][0]) for lines in (one, two))
    assert len(first) == 1 and first == second
    assert cold == "0 1"        # compiled in the first process
    assert warm == "1 0"        # loaded from the cache in the second
    # The spring's trial compiled once: the solver's first call (keep false) and its
    # later ones pass `keep` of one type (a literal False would be a second type).
    assert one["mounted_trials"] == [["1"]]


def test_a_run_is_the_same_to_the_bit_from_a_cold_and_from_a_warm_cache(cold_and_warm):
    # With the compiler free to fuse multiply-adds, a kernel loaded from the cache rounded
    # one last place differently from the same kernel compiled in the process (LuGre's
    # blocks, 404 of 3001 forces): a result depended on whether the cache was warm.
    runs, _ = cold_and_warm
    cold, warm = ([fields[0] for fields in lines["same_run"]] for _, lines in runs)
    assert len(cold) == 1 and cold == warm


def test_kernels_calling_scipy_are_cached(cold_and_warm):
    """A function pointer as a global would stop numba caching; the run-time addresses do not."""
    runs, cache = cold_and_warm
    stats = []
    for stderr, lines in runs:
        assert "NumbaWarning" not in stderr and "cannot cache" not in stderr.lower()
        stats.append({fields[0]: tuple(map(int, fields[1:])) for fields in lines["scipy"]})
    first, second = stats
    # (the fast pair's coefficient tables are global arrays, frozen into the cached code)
    for name in ("newton_separation", "gw_half_integer_pair", "gw_half_integer_pair_fast", "kve"):
        assert first[name] == (0, 1)            # compiled and saved
        assert second[name] == (1, 0)           # loaded from the cache
    files = [path.name for path in cache.rglob("*")]
    for stem in ("special.kve", "greenwood.gw_half_integer_pair-", "greenwood.gw_half_integer_pair_fast",
                 "separation.newton_separation-"):
        for suffix in (".nbi", ".nbc"):
            found = any(name.startswith(stem) and name.endswith(suffix) for name in files)
            assert found, (stem, suffix, files)
