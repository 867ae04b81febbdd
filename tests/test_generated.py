"""Every model's runners come from the one template (polind.kernels.template).

The runner modules under polind/kernels/generated are written by
polind.kernels.generate from the template; they must be exactly what it
writes, every model of polind's own must use one, and no kernel module may
carry a runner of its own beside them.
"""

from __future__ import annotations

import ast
import importlib

import numpy as np
import pytest

import polind
from polind.kernels import generate
from polind.models.registry import MODEL_TYPES


@pytest.mark.parametrize("name", sorted(generate.MODELS))
def test_generated_runner_module_is_in_sync_with_the_template(name):
    path = generate.GENERATED / f"{name}.py"
    assert path.read_text(encoding="utf-8") == generate.render(name), (
        f"{path.name} is stale: run `python -m polind.kernels.generate`")


def test_no_generated_module_without_an_entry():
    files = {path.stem for path in generate.GENERATED.glob("*.py")} - {"__init__"}
    assert files == set(generate.MODELS)


@pytest.mark.parametrize("model_type", sorted(MODEL_TYPES))
def test_every_model_of_polind_runs_on_generated_runners(model_type):
    kernel = MODEL_TYPES[model_type].example().step_kernel()
    assert kernel.runners.__name__.startswith("polind.kernels.generated.")


def test_no_kernel_module_defines_a_runner_of_its_own():
    # A runner of the template (path, motion, integrate, body, mounted_*) specialised
    # to one model by hand would be named after the model: lugre_path, gms_body, ...
    runner_names = {node.name for node in ast.parse(generate.template_body()).body
                    if isinstance(node, ast.FunctionDef)}
    runner_names -= {"trial"}     # maxwell_slip_trial: the elements' own trial (Leuven's solve)
    prefixes = {names["step"].removesuffix("_step") for _, names in generate.MODELS.values()}
    by_hand = {f"{prefix}_{runner}" for prefix in prefixes for runner in runner_names}
    for path in generate.KERNELS.glob("*.py"):
        names = {node.name for node in ast.parse(path.read_text()).body
                 if isinstance(node, ast.FunctionDef)}
        assert not names & by_hand, f"{path.name} defines runners by hand: {names & by_hand}"
    assert "lugre_path" in by_hand and "maxwell_slip_body" in by_hand


def test_a_users_functions_get_the_template_compiled_for_them():
    from polind.kernels import single

    own = generate.runners_for(single.dahl_step, single.dahl_force, single.dahl_tangent)
    assert own is importlib.import_module("polind.kernels.generated.dahl")

    from numba import njit

    @njit
    def step(scalars, table, state, h, dx, w, v, load):
        state[0] = min(max(state[0] + scalars[0] * dx, -1.0), 1.0)
        return state[0]

    @njit
    def force(scalars, table, state, v, load):
        return state[0]

    @njit
    def tangent(scalars, table, state, h):
        return scalars[0] * h

    runners = generate.runners_for(step, force, tangent)
    assert runners is generate.runners_for(step, force, tangent)    # compiled once
    scalars, table, state = np.array([10.0]), np.zeros((1, 1)), np.zeros(1)
    dx = np.array([0.0, 0.05, 0.05, 0.2, -0.1])
    out = np.empty(5)
    out[0] = force(scalars, table, state, dx[0], 0.0)    # sample 0: the caller's (Python's)
    runners.path(scalars, table, state, np.ones(5), dx, dx, dx, np.zeros(0), 0.0, 0, 5, out)
    np.testing.assert_allclose(out, [0.0, 0.5, 1.0, 1.0, 0.0], atol=1e-15)
    assert polind.StepFunctions(step, force, tangent).runner_module() is runners
