"""The results in polind.__all__ have a short repr: one line, never their arrays."""

from __future__ import annotations

import numpy as np

import polind
from conftest import lib, representative


def short(text):
    assert "\n" not in text and len(text) < 400, text
    assert "array(" not in text
    return text


def test_system_result_repr():
    model = lib(representative("lugre"))
    system = polind.System(mass=1.0, duration=20.0, time_step=1e-4, spring_stiffness=2.0,
                           drive_velocity=0.1)
    text = short(repr(polind.simulate_system(model, system)))
    assert text.startswith("SystemResult(200001 samples, t 0 .. 20 s")
    assert "applied " in text and "final_state lugre at t = 20 s" in text


def test_fit_result_and_comparison_reprs():
    t = np.linspace(0.0, 1.0, 2001)
    x = 2e-5 * np.sin(2.0 * np.pi * t)
    truth = lib(representative("maxwell-slip"))
    data = {"t": t, "x": x, "F": polind.simulate(truth, t, x=x).force}
    fit = polind.identify(truth.with_params(stiffness=[2e5, 1e5, 4e4, 2e4]), data)
    text = short(repr(fit))
    assert text.startswith("FitResult(maxwell-slip, free ") and "rms_error " in text
    comparison = polind.compare({"MS": truth, "Dahl": lib(representative("dahl"))}, data)
    text = short(repr(comparison))
    assert text.startswith("Comparison(2 models on 2001 samples: MS rms ")
