"""The simulate contract's bookkeeping (INTERFACE.md): chunking, continuation checks, overflow."""

import numpy as np
import pytest

import importlib
import sys

import polind
from polind.models.pol_ind import default_table
from conftest import lib, representative

# polind.simulate is the function, polind.simulation its module.
simulate_module = importlib.import_module("polind.simulation")


@pytest.mark.parametrize("model_type", ["maxwell-slip", "gms", "lugre", "leuven", "pol-ind"])
def test_internal_chunks_equal_one_kernel_call_and_report_progress(monkeypatch, model_type):
    model = lib(default_table() if model_type == "pol-ind" else representative(model_type))
    t = np.linspace(0.0, 1.0, 1001)
    x = 3e-6 * np.sin(2 * np.pi * 3 * t) + 1e-4 * t
    load = None if model_type != "pol-ind" else 100.0 + 10.0 * np.sin(2 * np.pi * t)
    whole = polind.simulate(model, t, x=x, normal_load=load)
    assert whole.force.shape == t.shape
    monkeypatch.setattr(simulate_module, "CHUNK", 97)
    calls = []
    chunked = polind.simulate(model, t, x=x, normal_load=load,
                              progress=lambda done, total: calls.append((done, total)))
    np.testing.assert_allclose(chunked.force, whole.force, rtol=1e-10, atol=1e-12)
    assert calls[-1] == (1001, 1001) and len(calls) == 11
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)


def test_continuation_must_start_at_the_states_sample():
    model = lib(representative("dahl"))
    t = np.linspace(0.0, 1.0, 11)
    res = polind.simulate(model, t, x=1e-5 * t)
    with pytest.raises(polind.InputError, match=r"'t'.*state's time"):
        polind.simulate(model, t, x=1e-5 + 1e-5 * t, state=res.final_state)
    with pytest.raises(polind.InputError, match=r"'x'.*state's position"):
        polind.simulate(model, t + 1.0, x=1e-5 * t, state=res.final_state)
    resv = polind.simulate(model, t, v=np.full(11, 1e-5))
    with pytest.raises(polind.InputError, match=r"'v'.*state's velocity"):
        polind.simulate(model, t + 1.0, v=np.full(11, 2e-5), state=resv.final_state)
    # the documented way works
    polind.simulate(model, t + 1.0, x=1e-5 * (t + 1.0), state=res.final_state)


@pytest.mark.parametrize("kwargs, column", [
    ({"t": [0.0, 10.0], "v": [1e308, 1e308]}, "'v'"),
    ({"t": [0.0, 1e-10], "x": [-1e308, 1e308]}, "'x'"),
])
def test_overflowing_motion_is_an_input_error(kwargs, column):
    model = lib(representative("coulomb"))
    with _no_warnings():
        with pytest.raises(polind.InputError, match=column):
            polind.simulate(model, **kwargs)


class _no_warnings:
    def __enter__(self):
        import warnings
        self._catch = warnings.catch_warnings()
        self._catch.__enter__()
        warnings.simplefilter("error")

    def __exit__(self, *exc):
        return self._catch.__exit__(*exc)


@pytest.mark.parametrize("continuing", [False, True])
def test_the_path_is_numpys_diff_divide_and_accumulate_to_the_bit(continuing):
    # INTERFACE.md's rules written with NumPy, against the one-pass compiled cut.
    from polind.models import State
    from polind.simulation import make_path

    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(1e-4, 2e-3, 500))
    x = np.cumsum(rng.normal(0.0, 1e-6, 500))
    v = rng.normal(0.0, 1e-3, 500)
    state = State("coulomb", time=t[0], position=0.3, velocity=-2e-3) if continuing else None
    h = np.diff(t)
    by_x = make_path(t, x=x, state=state)
    np.testing.assert_array_equal(by_x.step[1:], h)
    np.testing.assert_array_equal(by_x.displacement[1:], np.diff(x))
    np.testing.assert_array_equal(by_x.step_velocity[1:], np.diff(x) / h)
    np.testing.assert_array_equal(by_x.sample_velocity[1:], np.diff(x) / h)
    assert by_x.sample_velocity[0] == (-2e-3 if continuing else np.diff(x)[0] / h[0])
    assert by_x.step[0] == by_x.displacement[0] == by_x.step_velocity[0] == 0.0
    by_v = make_path(t, v=v, state=state)
    mean = 0.5 * (v[:-1] + v[1:])
    np.testing.assert_array_equal(by_v.step_velocity[1:], mean)
    np.testing.assert_array_equal(by_v.displacement[1:], mean * h)
    start = 0.3 if continuing else 0.0
    np.testing.assert_array_equal(by_v.x, np.add.accumulate(np.concatenate(([start],
                                                                            mean * h))))
    np.testing.assert_array_equal(by_v.sample_velocity, v)
