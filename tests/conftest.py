"""Shared parameter sets, motions and helpers for the model tests.

The parameter sets are model dictionaries in the INTERFACE.md schema (the
inner ``[model]`` table, with ``type``); :func:`lib` wraps one for
``polind.model_from_dict`` and :mod:`oracles` reads the same dictionaries.
"""

from __future__ import annotations

import copy
import os
import signal
import sys

import numpy as np

# A shell without job control starts a background command with SIGINT ignored, and a
# child process inherits that: the tests that interrupt a `polind` process with SIGINT
# (Ctrl-C) would see it ignored.  The suite's processes take Python's own handler.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# the test modules import ``oracles`` and these helpers as plain modules
sys.path.insert(0, os.path.dirname(__file__))

# ---------------------------------------------------------------------------
# Representative parameter sets (one per model type)
# ---------------------------------------------------------------------------

#: The LuGre parameters of Canudas de Wit et al. 1995 (MODELS.md 3).
LUGRE_1995 = {
    "type": "lugre",
    "bristle_stiffness": 1e5,
    "bristle_damping": float(np.sqrt(1e5)),
    "viscous_coefficient": 0.4,
    "coulomb_force": 1.0,
    "static_force": 1.5,
    "stribeck_velocity": 1e-3,
    "stribeck_exponent": 2.0,
    "stribeck_shape": "exponential",
}

STIFFNESS = [1e5, 5e4, 2e4, 1e4]                 # N/m
BREAKAWAY = [0.2, 0.3, 0.25, 0.25]               # N, sum 1.0
WEIGHT = [0.2, 0.3, 0.25, 0.25]

def _registered_examples() -> dict:
    """Each registered model's own representative set (``FrictionModel.example_parameters``),
    as a model dictionary; models built from contact mechanics (Pol-Ind) are tested with
    their own sets, being slower to build."""
    from polind.models import MODEL_TYPES as registered

    return {name: {"type": name, **cls.example_parameters()}
            for name, cls in registered.items() if not cls.has_contact}


#: The representative parameter set of every model type, from the models themselves.
REPRESENTATIVE = _registered_examples()

MODEL_TYPES = list(REPRESENTATIVE)


def representative(model_type: str, **changes) -> dict:
    """A deep copy of the representative parameter set, with ``changes``."""
    out = copy.deepcopy(REPRESENTATIVE[model_type])
    out.update(changes)
    return out


# ---------------------------------------------------------------------------
# The library under test
# ---------------------------------------------------------------------------

def lib(inner: dict):
    """``polind.model_from_dict`` of an inner model dict."""
    import polind

    return polind.model_from_dict({"model": copy.deepcopy(inner)})


def run(inner: dict, t, x=None, v=None, state=None):
    """``polind.simulate`` of an inner model dict."""
    import polind

    kwargs = {"x": x} if x is not None else {"v": v}
    if state is not None:
        kwargs["state"] = state
    return polind.simulate(lib(inner), np.asarray(t, dtype=float), **kwargs)


def element_forces(state) -> np.ndarray:
    """The ``element_force`` list of a state's dictionary (INTERFACE contract)."""
    return np.asarray(state.to_dict()["element_force"], dtype=float)


def run_collecting_states(inner: dict, t, x, at):
    """Run in chunks ending at the sample indices ``at`` (sorted, > 0) and
    return ``(forces, {index: final_state})``; chunks repeat the boundary
    sample as INTERFACE.md prescribes for continuing a run."""
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    bounds = [0] + sorted(set(int(i) for i in at if 0 < i < len(t) - 1)) + [len(t) - 1]
    forces = [None] * len(t)
    states = {}
    state = None
    for a, b in zip(bounds[:-1], bounds[1:]):
        res = run(inner, t[a:b + 1], x=x[a:b + 1], state=state)
        for j, f in enumerate(res.force):
            forces[a + j] = f
        state = res.final_state
        states[b] = state
    return np.asarray(forces, dtype=float), states


# ---------------------------------------------------------------------------
# Motions
# ---------------------------------------------------------------------------

def polyline(vertices, samples_per_leg=50, speed=1e-4, t0=0.0):
    """A piecewise-linear path through ``vertices`` traversed at a constant
    ``speed`` [m/s], every vertex a sample; returns ``(t, x)``.

    ``samples_per_leg`` may be an int or a list (one per leg)."""
    vertices = [float(a) for a in vertices]
    legs = len(vertices) - 1
    if np.isscalar(samples_per_leg):
        samples_per_leg = [int(samples_per_leg)] * legs
    xs = [np.array([vertices[0]])]
    for i in range(legs):
        seg = np.linspace(vertices[i], vertices[i + 1], samples_per_leg[i] + 1)[1:]
        xs.append(seg)
    x = np.concatenate(xs)
    t = t0 + np.concatenate([[0.0], np.cumsum(np.abs(np.diff(x)) / speed)])
    return t, x


def wobbly_motion(n=2001, duration=2.0, amplitude=1e-3, seed=None):
    """A smooth motion with reversals, presliding and sliding; ``(t, x, v)``."""
    t = np.linspace(0.0, duration, n)
    w1, w2 = 2 * np.pi / duration, 2 * np.pi * 3.3 / duration
    x = amplitude * (np.sin(w1 * t) + 0.2 * np.sin(w2 * t + 0.3))
    v = amplitude * (w1 * np.cos(w1 * t) + 0.2 * w2 * np.cos(w2 * t + 0.3))
    return t, x, v


def random_walk(n, step_scale, seed, dt_range=(5e-4, 2e-3), dwell=0.0):
    """A random piecewise-linear displacement with uneven time steps; a
    fraction ``dwell`` of the steps stand still (``v = 0`` exactly)."""
    rng = np.random.default_rng(seed)
    dt = rng.uniform(*dt_range, size=n - 1)
    t = np.concatenate([[0.0], np.cumsum(dt)])
    # persistent direction with occasional reversals: presliding and sliding
    direction = np.sign(np.cumsum(rng.normal(size=n - 1)) + 1e-300)
    dx = direction * rng.uniform(0.0, 1.0, size=n - 1) * step_scale
    dx[rng.uniform(size=n - 1) < dwell] = 0.0
    x = np.concatenate([[0.0], np.cumsum(dx)])
    return t, x


def spoil_sample(t, x, where, what):
    """Copies of ``t`` and ``x`` with one bad sample at ``where``, and the message it must give.

    ``what``: "x nan", "x inf", "t nan", "t inf", "t repeated" or "overflow"
    (finite positions whose step velocity is not). The message is a regular
    expression for ``pytest.raises(match=...)``.
    """
    t, x = np.array(t, dtype=float), np.array(x, dtype=float)
    if what in ("x nan", "x inf", "t nan", "t inf"):
        name, value = what.split()
        (x if name == "x" else t)[where] = float(value)
        return t, x, f"'{name}' samples must be finite. Got {value} at index {where}"
    if what == "t repeated":
        t[where] = t[where - 1]
        return t, x, fr"'t' samples must be strictly increasing. Got t\[{where}\]"
    if what == "overflow":
        x[where], x[where - 1] = 1e308, -1e308
        return t, x, "overflow"
    raise ValueError(f"unknown spoiling {what!r}")


# ---------------------------------------------------------------------------
# Assertions
# ---------------------------------------------------------------------------

def assert_close(got, expected, rel, scale, what=""):
    """``|got - expected| <= rel * max(|expected|, scale)`` element-wise, with a
    message that names the worst sample."""
    got = np.asarray(got, dtype=float)
    expected = np.asarray(expected, dtype=float)
    assert got.shape == expected.shape, (got.shape, expected.shape)
    tol = rel * np.maximum(np.abs(expected), scale)
    err = np.abs(got - expected)
    bad = ~(err <= tol)
    if np.any(bad):
        i = int(np.argmax(np.where(bad, err / tol, -np.inf)))
        raise AssertionError(
            f"{what}: {int(bad.sum())} of {bad.size} samples differ; worst at "
            f"index {i}: got {got.flat[i]!r}, expected {expected.flat[i]!r}, "
            f"|diff| = {err.flat[i]:.3e} > tol {tol.flat[i]:.3e}")

