"""`polind bench` takes its cases from the model registry: a model registered here is timed.

The model lives only in this test module (a user's model, as in
tests/test_extension.py): registered, it appears in ``cases()``, ``run_case``
times its kernel and, having no NumPy loop in the benchmark's references,
leaves the NumPy column and the ratio empty ("—"); ``polind bench --model``
accepts its type.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numba import njit

import polind
from polind.bench import harness
from polind.bench.references import NUMPY_REFERENCES, numpy_reference
from polind.cli import main
from polind.models import MODEL_TYPES


@njit
def relax_step(scalars, table, state, step, displacement, step_velocity, sample_velocity,
               normal_load):
    # dF/ds = (k / Fc) (sgn(v) Fc - F) along the travelled distance: Dahl, exact per step.
    target = scalars[1] if step_velocity > 0.0 else -scalars[1] if step_velocity < 0.0 \
        else state[0]
    state[0] = target + (state[0] - target) * math.exp(-scalars[0] / scalars[1]
                                                       * abs(displacement))
    return state[0]


@njit
def relax_force(scalars, table, state, sample_velocity, normal_load):
    return state[0]


@njit
def relax_tangent(scalars, table, state, step):
    return scalars[0] * step


class Relax(polind.FrictionModel):
    """A Dahl model of the user's own, which the benchmark has no NumPy loop for."""

    type = "bench-test-relax"
    title = "Relaxation (a test's own)"
    parameters = (polind.Param("stiffness", unit="N/m"), polind.Param("coulomb_force", unit="N"))

    @classmethod
    def example_parameters(cls, elements=None):
        return {"stiffness": 1e5, "coulomb_force": 1.0}

    def initial_variables(self, normal_load=None):
        return {"friction": np.zeros(1)}

    def step_functions(self):
        return polind.StepFunctions(relax_step, relax_force, relax_tangent)

    def kernel_arrays(self, state):
        p = self.params
        return np.array([p["stiffness"], p["coulomb_force"]]), np.zeros((1, 0))


@pytest.fixture
def registered():
    polind.register_model(Relax)
    yield Relax
    polind.unregister_model(Relax.type)


def test_every_registered_model_is_a_case(registered):
    cases = harness.cases()
    assert {model_type for model_type, _ in cases} == set(MODEL_TYPES)
    assert (Relax.type, 1) in cases and [n for t, n in cases if t == Relax.type] == [1]
    assert [n for t, n in cases if t == "gms"] == list(harness.ELEMENT_COUNTS)
    assert harness.cases([Relax.type]) == [(Relax.type, 1)]
    assert numpy_reference(Relax.example()) is None and Relax.type not in NUMPY_REFERENCES


def test_a_model_without_a_numpy_loop_is_timed_with_the_numpy_column_empty(registered):
    row = harness.run_case(Relax.type, 1, kernel_seconds=0.01, numpy_seconds=0.02, repeats=1)
    assert row.model == Relax.type and row.elements == 1 and row.steps >= 20_000
    assert row.kernel_rate > 0
    assert row.numpy_rate is None and row.max_difference is None and row.ratio is None
    line = harness.format_table([row]).splitlines()[-1]
    assert line.startswith(Relax.type) and line.count(harness.MISSING) == 3


def test_bench_accepts_any_registered_type(registered, monkeypatch, capsys):
    timed = []

    def run_case(model_type, n):
        timed.append((model_type, n))
        return harness.BenchRow(model_type, n, 100, 1e8)

    monkeypatch.setattr(harness, "run_case", run_case)
    with pytest.raises(SystemExit) as done:
        main(["bench", "--model", Relax.type])
    assert done.value.code == 0
    out = capsys.readouterr().out
    assert timed == [(Relax.type, 1)]
    last = out.splitlines()[-1].split()
    assert last == [Relax.type, "1", "100", "1.000e+08", "—", "—", "—"]
    assert "separation" not in out            # no contact mechanics: no contact rows


def test_every_ratio_row_has_a_target_and_the_numpy_scalar_rows_are_there():
    """The ratio rows, listed without measuring any: each named once, with a target; the rows
    of issue 38 hold NumPy-scalar calls of Stepper.advance and Body.step to 1.2 float calls."""
    from polind.bench import ratios

    specs = ratios.ratio_specs()
    names = [spec.name for spec in specs]
    assert len(names) == len(set(names))
    for spec in specs:
        assert spec.target > 0 and isinstance(spec.at_most, bool) and callable(spec.measure)
        assert len(spec.name) <= 58                 # the width of format_ratios' name column
    by_name = {spec.name: spec for spec in specs}
    for label in ("LuGre", "Pol-Ind (64)"):
        for name in (f"Stepper.advance np.float64 / float arguments: {label}",
                     f"Body.step np.float64 / float argument: {label}"):
            assert by_name[name].target == 1.2 and by_name[name].at_most
    assert names.index("Stepper.advance / bare numba call: LuGre") == 0   # the order kept
    # a structure step with one 64-element joint: at most 3 simulate_system steps (issue 38)
    structure = by_name["structure / simulate_system step: 64-element MS joint"]
    assert structure.target == 3.0 and structure.at_most
    # the frequency domain (issue 39): harmonic balance at least 10 times the time
    # integration's speed, and its 200-point curve within 30 s
    speed = by_name["time integration / harmonic balance: 200-point curve"]
    assert speed.target == 10.0 and not speed.at_most
    seconds = by_name["harmonic balance, 200-point curve: seconds (absolute)"]
    assert seconds.target == 30.0 and seconds.at_most


def test_the_frequency_rows_time_a_curve_that_agrees_with_the_time_integration():
    """The harmonic-balance timing measures a real curve: its first harmonic is the time
    integration's steady state (the detail reports it), at a reduced size here."""
    from polind.bench import frequency

    hb_seconds, td_seconds, count, detail = frequency.frequency_response_timing(points=40,
                                                                               probes=1)
    assert hb_seconds > 0 and td_seconds > 0 and 20 <= count <= 60
    agreement = float(detail.rsplit(" ", 1)[-1])
    assert agreement < 1e-3


def test_run_ratios_runs_the_rows_asked_for(monkeypatch):
    from polind.bench import ratios

    measured = []

    def spec(name, value, target, at_most):
        return ratios.RatioSpec(name, target, at_most,
                                lambda: measured.append(name) or (value, "detail"))

    monkeypatch.setattr(ratios, "ratio_specs", lambda: [
        spec("Stepper.advance np.float64 / float arguments: LuGre", 1.1, 1.2, True),
        spec("bare loop / simulate: LuGre", 0.5, 1.0, False)])
    shown = []
    rows = ratios.run_ratios(progress=shown.append, only=["np.float64"])
    assert measured == ["Stepper.advance np.float64 / float arguments: LuGre"]
    assert shown == rows and [(r.value, r.target, r.met) for r in rows] == [(1.1, 1.2, True)]
    line = ratios.format_ratios(rows).splitlines()[-1]
    assert "<= 1.2" in line and "met" in line
    assert [r.met for r in ratios.run_ratios()] == [True, False]
