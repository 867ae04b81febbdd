"""Start-up: nothing heavy is imported before it is needed (issue 14).

`polind --help` imports neither NumPy nor numba, SciPy, matplotlib, pyarrow
or Dask; a small `polind simulate` imports numba (its kernels) but none of
the others' modules it does not use.  Each check runs in a fresh interpreter,
where ``sys.modules`` says what an import really costs.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import polind

#: Packages too slow to import for a command that does not use them.
HEAVY = ("numba", "scipy", "matplotlib", "pyarrow", "dask", "distributed", "SurfaceTopography")


def imported_after(code: str) -> list[str]:
    """The top-level packages (and polind modules) in ``sys.modules`` after running ``code``."""
    script = (f"import sys\n{code}\n"
              "import json\n"
              "print(json.dumps(sorted({name if name.startswith('polind') else "
              "name.split('.')[0] for name in sys.modules})))\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("code", ["import polind", "import polind.cli",
                                  "from polind.cli import _run\n_run(['--help'])",
                                  "from polind.cli import _run\n_run(['simulate', '--help'])"])
def test_import_and_help_import_nothing_heavy(code):
    modules = imported_after(code)
    assert [name for name in (*HEAVY, "numpy") if name in modules] == []


def test_a_small_simulate_imports_only_what_it_uses(tmp_path):
    model = tmp_path / "model.toml"
    model.write_text('[model]\ntype = "maxwell-slip"\nstiffness = [1e5, 5e4, 2e4, 1e4]\n'
                     'breakaway_force = [0.2, 0.3, 0.25, 0.25]\n')
    motion = tmp_path / "motion.csv"
    motion.write_text("t,x\n0,0\n0.5,1e-6\n1,2e-6\n")
    out = tmp_path / "out.csv"
    modules = imported_after(f"from polind.cli import _run\n"
                             f"assert _run(['simulate', {str(model)!r}, '-i', {str(motion)!r}, "
                             f"'-o', {str(out)!r}]) == 0")
    assert out.exists()
    # numba loads scipy.linalg for its own registry; nothing else of SciPy is needed.
    unused = ("matplotlib", "pyarrow", "dask", "distributed", "SurfaceTopography",
              "polind.contact", "polind.topography", "polind.identification", "polind.report",
              "polind.phenomena", "polind.sweeps", "polind.dynamics")
    assert [name for name in unused if name in modules] == []
    assert "numba" in modules                     # the check above looked at a real run


def test_scipy_special_and_optimize_wait_for_their_use(tmp_path):
    code = ("import sys\nimport polind, polind.cli, polind.simulation\n"
            "print(sorted(m for m in sys.modules if m.startswith(('scipy.special', "
            "'scipy.optimize', 'scipy.integrate'))))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=True)
    assert done.stdout.strip() == "[]"


def test_every_export_resolves_and_simulate_is_the_function():
    import importlib

    module = importlib.import_module("polind.simulation")
    assert callable(polind.simulate) and polind.simulate is module.simulate
    for name in polind.__all__:
        assert getattr(polind, name) is not None, name
    assert set(polind.__all__) <= set(dir(polind))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        polind.nothing     # noqa: B018


def test_simulate_is_the_function_whichever_import_comes_first():
    code = ("import polind.dynamics, polind.simulation\nimport polind\n"
            "print(polind.simulate.__module__, type(polind.simulate).__name__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, check=True)
    assert done.stdout.split() == ["polind.simulation", "function"]
