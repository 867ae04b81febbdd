# The commands of the README: `make demo`, `make test` and `make docs`.
# Each creates .venv if needed, installs the project into it and precompiles its kernels.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin

.PHONY: demo test bench docs clean

# The packages are installed by uv (from PyPI, into the venv): it fetches and unpacks
# them side by side, in about a quarter of pip's time on a fresh machine (32 s against
# 2 min for the test extras, measured on the same machine).  --compile-bytecode writes
# their .pyc files once, as pip does and uv does not by default: where Python may not
# write them itself (PYTHONDONTWRITEBYTECODE, set in many containers) every process
# would compile numba's, NumPy's and SciPy's sources again (`import numba` 0.9 s
# instead of 0.3 s; a warm `polind simulate` 1.8 s instead of 0.7 s).
INSTALL := $(BIN)/python -m uv pip install --quiet --compile-bytecode --python $(BIN)/python

# After every install, `polind precompile` compiles each built-in model's kernels for every
# driver into numba's on-disk cache, in as many processes as there are cores, so that the
# demo, the tests and every later process load them instead of compiling them.  It runs
# when the install runs (a fresh .venv, a changed pyproject.toml); a kernel edited since is
# compiled by the first process that needs it, or by running `.venv/bin/polind precompile`.
PRECOMPILE := $(BIN)/polind precompile

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet "uv>=0.5"

$(VENV)/.installed-run: pyproject.toml | $(BIN)/python
	$(INSTALL) -e .
	$(PRECOMPILE)
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(BIN)/python
	$(INSTALL) -e ".[test]"
	$(PRECOMPILE)
	touch $@ $(VENV)/.installed-run

$(VENV)/.installed-docs: pyproject.toml | $(BIN)/python
	$(INSTALL) -e ".[docs]"
	$(PRECOMPILE)
	touch $@ $(VENV)/.installed-run

demo: $(VENV)/.installed-run
	$(BIN)/polind demo

test: $(VENV)/.installed-test
	$(BIN)/python -m pytest

# The documentation site, into docs/_build/html (open docs/_build/html/index.html; it
# needs no network).  The examples of examples/ run during the build (a minute or two).
docs: $(VENV)/.installed-docs
	$(BIN)/python -m sphinx -b html -j auto -n --keep-going docs docs/_build/html

bench: $(VENV)/.installed-run
	$(BIN)/polind bench

clean:
	rm -rf $(VENV) polind-report .pytest_cache docs/_build docs/api/generated docs/api/polind*.rst \
		docs/api/modules.rst docs/auto_examples docs/sg_execution_times.rst
