"""One conformance test parametrised over every model type (INTERFACE.md).

Like scikit-learn's ``parametrize_with_checks``: every model type runs the
same checks of the ``simulate`` contract, its state and its parameters.
"""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

import polind
from conftest import MODEL_TYPES, REPRESENTATIVE, lib, representative, run, wobbly_motion

SPLIT_REL = 1e-10

#: Every model type of INTERFACE.md runs the conformance checks.
CONFORMANCE_SETS = {name: {"type": name, **cls.example_parameters()}
                    for name, cls in polind.MODEL_TYPES.items()}


def force_scale(inner):
    """A natural force scale of a parameter set [N]."""
    if inner["type"] == "pol-ind":
        return inner["static_coefficient"] * inner["normal_load"]
    return max(float(np.sum(inner.get(key, 0.0)))
               for key in ("coulomb_force", "static_force", "breakaway_force", "slip_force"))


def assert_split_equal(got, want, what):
    got, want = np.asarray(got), np.asarray(want)
    scale = max(float(np.max(np.abs(want))), 1e-300)
    err = np.abs(got - want)
    tol = SPLIT_REL * np.maximum(np.abs(want), scale)
    assert np.all(err <= tol), (
        f"{what}: worst |diff| {err.max():.3e} at {int(np.argmax(err / tol))}")


def motions():
    t, x, v = wobbly_motion(n=1201, duration=1.2, amplitude=4e-4)
    return t, x, v


# --- the checks -----------------------------------------------------------

def check_result_shape(inner):
    t, x, v = motions()
    for kwargs in ({"x": x}, {"v": v}):
        res = run(inner, t, **kwargs)
        for name in ("t", "x", "v", "force"):
            arr = getattr(res, name)
            assert isinstance(arr, np.ndarray) and arr.dtype == np.float64, name
            assert arr.shape == t.shape, name
        assert np.all(np.isfinite(res.force))
        np.testing.assert_array_equal(res.t, t)
    res = run(inner, t, x=x)
    np.testing.assert_array_equal(res.x, x)
    step_v = np.diff(x) / np.diff(t)
    np.testing.assert_allclose(res.v, np.concatenate([step_v[:1], step_v]), rtol=1e-13)
    res = run(inner, t, v=v)
    np.testing.assert_array_equal(res.v, v)
    trapezoid = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
    np.testing.assert_allclose(res.x, trapezoid, rtol=1e-12, atol=1e-12 * np.abs(trapezoid).max())


def chunked(inner, t, splits, **drive):
    """Run split at the sample indices ``splits``; each chunk starts with the
    previous chunk's last sample repeated."""
    (name, values), = drive.items()
    bounds = [0] + list(splits) + [len(t) - 1]
    forces, xs, vs = [], [], []
    state = None
    for a, b in zip(bounds[:-1], bounds[1:]):
        res = run(inner, t[a:b + 1], state=state, **{name: values[a:b + 1]})
        if state is not None:
            assert res.force[0] == pytest.approx(forces[-1][-1], rel=SPLIT_REL,
                                                 abs=SPLIT_REL * force_scale(inner)), \
                f"F[0] of the continuation at sample {a} is not the previous last force"
            res_force = res.force[1:]
            res_x, res_v = res.x[1:], res.v[1:]
        else:
            res_force, res_x, res_v = res.force, res.x, res.v
        forces.append(res_force)
        xs.append(res_x)
        vs.append(res_v)
        state = res.final_state
    return np.concatenate(forces), np.concatenate(xs), np.concatenate(vs)


def check_split_run_equals_one_run(inner):
    t, x, v = motions()
    splits = [1, 2, 97, 500, 501, 777, len(t) - 2]
    for name, values in (("x", x), ("v", v)):
        whole = run(inner, t, **{name: values})
        force, xs, vs = chunked(inner, t, splits, **{name: values})
        assert_split_equal(force, whole.force, f"{name}-driven force")
        assert_split_equal(xs, whole.x, f"{name}-driven x")
        assert_split_equal(vs, whole.v, f"{name}-driven v")


def check_deterministic(inner):
    t, x, v = motions()
    a, b = run(inner, t, x=x), run(inner, t, x=x)
    np.testing.assert_array_equal(a.force, b.force)
    a, b = run(inner, t, v=v), run(inner, t, v=v)
    np.testing.assert_array_equal(a.force, b.force)


def check_saved_state_continues(inner):
    t, x, v = motions()
    cut = 613
    for name, values in (("x", x), ("v", v)):
        whole = run(inner, t, **{name: values})
        first = run(inner, t[:cut + 1], **{name: values[:cut + 1]})
        saved = json.loads(json.dumps(first.final_state.to_dict()))
        state = polind.State.from_dict(saved)
        assert json.loads(json.dumps(state.to_dict())) == saved
        second = run(inner, t[cut:], state=state, **{name: values[cut:]})
        direct = run(inner, t[cut:], state=first.final_state, **{name: values[cut:]})
        np.testing.assert_array_equal(second.force, direct.force)
        assert_split_equal(second.force, whole.force[cut:], f"{name}-driven from a saved state")


def _snapshot(model):
    """Deep copies of the model's attributes (arrays included)."""
    attrs = getattr(model, "__dict__", {})
    slots = [s for cls in type(model).__mro__ for s in getattr(cls, "__slots__", ())]
    out = {k: copy.deepcopy(v) for k, v in attrs.items()}
    for s in slots:
        if hasattr(model, s):
            out[s] = copy.deepcopy(getattr(model, s))
    return out


def _same(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(p, q) for p, q in zip(a, b))
    try:
        return bool(a == b)
    except Exception:  # objects without a usable ==: compare their attributes
        return _same(_snapshot(a), _snapshot(b))


def check_simulate_does_not_mutate_model(inner):
    """``simulate`` leaves the model's parameters alone (``to_dict`` and every
    attribute, arrays included). A private lazy cache of derived quantities
    may appear (STYLE.md: derived quantities happen in ``simulate``), but a
    used model must then give exactly what a fresh one gives."""
    t, x, v = motions()
    model = lib(inner)
    before_dict = copy.deepcopy(model.to_dict())
    before = _snapshot(model)
    extra = {}
    if inner["type"] == "pol-ind":
        extra = {"normal_load": inner["normal_load"] * (1.0 + 0.5 * np.sin(2 * np.pi * t))}
        polind.simulate(model, t, x=x, **extra)
    polind.simulate(model, t, x=x)
    res = polind.simulate(model, t[:300], v=v[:300])
    polind.simulate(model, t[299:], v=v[299:], state=res.final_state)
    assert model.to_dict() == before_dict
    after = _snapshot(model)
    for key in before:
        assert key in after, f"simulate removed model attribute {key!r}"
        assert _same(before[key], after[key]), f"simulate changed model attribute {key!r}"
    added = set(after) - set(before)
    assert all(key.startswith("_") for key in added), f"simulate added attributes {added}"
    fresh = lib(inner)
    np.testing.assert_array_equal(polind.simulate(model, t, v=v).force,
                                  polind.simulate(fresh, t, v=v).force)
    if extra:
        np.testing.assert_array_equal(polind.simulate(model, t, x=x, **extra).force,
                                      polind.simulate(lib(inner), t, x=x, **extra).force)


def check_model_dict_round_trip(inner):
    model = lib(inner)
    d = model.to_dict()
    assert set(d) == {"model"} and d["model"]["type"] == inner["type"]
    json.dumps(d)
    again = polind.model_from_dict(copy.deepcopy(d))
    assert again.to_dict() == d
    assert_given_values_come_back(inner, d["model"])
    t, x, _ = motions()
    np.testing.assert_array_equal(polind.simulate(again, t, x=x).force,
                                  polind.simulate(model, t, x=x).force)


def assert_given_values_come_back(given, returned, where="model"):
    for key, value in given.items():
        assert key in returned, f"{where}.{key} missing from to_dict()"
        if isinstance(value, dict):
            assert_given_values_come_back(value, returned[key], f"{where}.{key}")
        elif isinstance(value, str):
            assert returned[key] == value, f"{where}.{key}"
        else:
            assert returned[key] == pytest.approx(value, rel=1e-15), f"{where}.{key}"


def check_bad_motion_raises(inner):
    t, x, v = motions()
    model = lib(inner)
    bad_t = t.copy()
    bad_t[10] = bad_t[9]                                 # not strictly increasing
    dec_t = t[::-1].copy()
    nan_x = x.copy()
    nan_x[5] = np.nan
    nan_v = v.copy()
    nan_v[7] = np.nan
    inf_t = t.copy()
    inf_t[-1] = np.inf
    cases = [      # (what, arguments, names the message must quote)
        ("repeated time", dict(t=bad_t, x=x), ["'t'"]),
        ("decreasing time", dict(t=dec_t, x=x), ["'t'"]),
        ("infinite time", dict(t=inf_t, x=x), ["'t'"]),
        ("NaN in x", dict(t=t, x=nan_x), ["'x'"]),
        ("NaN in v", dict(t=t, v=nan_v), ["'v'"]),
        ("both x and v", dict(t=t, x=x, v=v), ["'x'", "'v'"]),
        ("neither x nor v", dict(t=t), ["'x'", "'v'"]),
        ("length mismatch", dict(t=t, x=x[:-1]), ["'x'"]),
        ("length mismatch v", dict(t=t[:-3], v=v), ["'v'"]),
        ("a single sample", dict(t=t[:1], x=x[:1]), ["'t'"]),
    ]
    assert issubclass(polind.InputError, ValueError)
    for what, kwargs, names in cases:
        t_arg = kwargs.pop("t")
        with pytest.raises(polind.InputError) as info:
            polind.simulate(model, t_arg, **kwargs)
        message = str(info.value)
        assert "\n" not in message, what
        for name in names:
            assert name in message, f"{what}: {message!r} does not name {name}"


CHECKS = [
    check_result_shape,
    check_split_run_equals_one_run,
    check_deterministic,
    check_saved_state_continues,
    check_simulate_does_not_mutate_model,
    check_model_dict_round_trip,
    check_bad_motion_raises,
]


@pytest.mark.parametrize("check", CHECKS, ids=lambda c: c.__name__)
@pytest.mark.parametrize("model_type", list(CONFORMANCE_SETS))
def test_conformance(model_type, check):
    check(copy.deepcopy(CONFORMANCE_SETS[model_type]))


def test_conformance_covers_every_model_type():
    assert set(CONFORMANCE_SETS) == set(polind.MODEL_TYPES)


# --- parameter validation (INTERFACE.md: errors that name the key) ----------

OPTIONAL = {"viscous_coefficient", "stribeck_exponent", "stribeck_shape", "exponent"}
OPTIONAL_BY_TYPE = {"dahl": {"exponent"}, "leuven": OPTIONAL - {"exponent"}}


def optional_keys(model_type):
    return OPTIONAL_BY_TYPE.get(model_type, OPTIONAL - {"exponent"})


def raises_naming(inner, *keys):
    with pytest.raises(polind.InputError) as info:
        polind.model_from_dict({"model": inner})
    message = str(info.value)
    assert any(k in message for k in keys), f"message {message!r} names none of {keys}"


@pytest.mark.parametrize("model_type", MODEL_TYPES)
def test_parameter_validation(model_type):
    base = representative(model_type)
    # unknown key
    raises_naming(dict(base, surplus_parameter=1.0), "surplus_parameter")
    for key, value in base.items():
        if key == "type":
            continue
        # missing required key; optional keys may be left out
        without = {k: v for k, v in base.items() if k != key}
        if key in optional_keys(model_type):
            polind.model_from_dict({"model": without})
        else:
            raises_naming(without, key)
        # wrong type
        raises_naming(dict(base, **{key: {"a": 1}}), key)
        if key == "stribeck_shape":
            raises_naming(dict(base, **{key: "parabolic"}), key)
            continue
        raises_naming(dict(base, **{key: "abc"}), key)
        # non-finite
        for bad in (math.nan, math.inf):
            if isinstance(value, list):
                broken = list(value)
                broken[-1] = bad
            else:
                broken = bad
            raises_naming(dict(base, **{key: broken}), key)
    if "stiffness" in base:
        stiffness = base["stiffness"]
        negative = [-abs(a) for a in stiffness] if isinstance(stiffness, list) else -stiffness
        raises_naming(dict(base, stiffness=negative), "stiffness")
    if "bristle_stiffness" in base:
        raises_naming(dict(base, bristle_stiffness=-1e5), "bristle_stiffness")
    lists = [k for k, v in base.items() if isinstance(v, list)]
    for key in lists:
        raises_naming(dict(base, **{key: []}), key)
        raises_naming(dict(base, **{key: base[key] + [base[key][-1]]}), *lists)


def test_unknown_type_and_missing_type():
    with pytest.raises(polind.InputError) as info:
        polind.model_from_dict({"model": {"type": "friction-of-the-future"}})
    assert "type" in str(info.value)
    with pytest.raises(polind.InputError) as info:
        polind.model_from_dict({"model": {"coulomb_force": 1.0}})
    assert "type" in str(info.value)


def test_gms_weights_must_sum_to_one():
    base = representative("gms")
    raises_naming(dict(base, weight=[0.2, 0.3, 0.25, 0.26]), "weight")
    raises_naming(dict(base, weight=[0.2, 0.3, 0.25, 0.25 + 1e-7]), "weight")
    polind.model_from_dict({"model": dict(base, weight=[1 / 3, 1 / 3, 1 / 3],
                                          stiffness=[1e5, 5e4, 2e4])})
    polind.model_from_dict({"model": dict(base, weight=[0.1] * 10, stiffness=[1e4] * 10)})


def test_leuven_breakaway_forces_must_sum_to_static_force():
    base = representative("leuven")
    raises_naming(dict(base, breakaway_force=[0.3, 0.45, 0.375, 0.5]),
                  "breakaway_force", "static_force")


@pytest.mark.parametrize("model_type", [m for m in MODEL_TYPES
                                        if optional_keys(m) & set(REPRESENTATIVE[m])])
def test_defaults_equal_explicit_values(model_type):
    """Optional keys left out take their documented defaults."""
    base = representative(model_type)
    explicit = {"viscous_coefficient": 0.0, "stribeck_exponent": 2.0,
                "stribeck_shape": "exponential", "exponent": 1.0}
    keys = optional_keys(model_type) & set(base)
    bare = {k: v for k, v in base.items() if k not in keys}
    full = dict(base, **{k: explicit[k] for k in keys})
    t, x, v = motions()
    np.testing.assert_array_equal(run(bare, t, x=x).force, run(full, t, x=x).force)


def test_every_type_of_the_formats_page_is_registered_and_conformance_tested():
    assert set(REPRESENTATIVE) >= {"coulomb", "stribeck", "dahl", "lugre", "maxwell-slip",
                                   "gms", "leuven"}
    assert set(CONFORMANCE_SETS) == set(REPRESENTATIVE) | {"pol-ind"}


#: The default Pol-Ind parameter set as the formats page states it (a steel pair under 100 N).
POL_IND_DEFAULT = {
    "type": "pol-ind",
    "normal_load": 100.0,
    "static_coefficient": 0.15,
    "kinetic_coefficient": 0.10,
    "stribeck_velocity": 1e-3,
    "stribeck_exponent": 2.0,
    "attraction": 1e4,
    "viscous_coefficient": 0.0,
    "surface": {"asperity_density": 1e10, "nominal_area": 1e-4,
                "asperity_radius": 50e-6, "height_std": 0.5e-6},
    "materials": {"youngs_modulus": [210e9, 210e9], "poisson_ratio": [0.3, 0.3]},
    "discretisation": {"summation": "statistical", "elements": 64},
}


def test_the_pol_ind_example_is_the_documented_default_set():
    """``PolInd.example()`` is the set the formats page and ``polind demo`` promise."""
    assert polind.models.PolInd.example() == polind.model_from_dict({"model": POL_IND_DEFAULT})


@pytest.mark.parametrize("model_type", sorted(CONFORMANCE_SETS))
def test_every_model_owns_its_documentation_facts(model_type):
    """Title, purpose, guide section and a description of every key, asked of the class."""
    cls = polind.MODEL_TYPES[model_type]
    assert cls.title and cls.purpose and cls.guide.startswith("guide-")

    def walk(entries, prefix=""):
        for entry in entries:
            assert entry.description, f"{model_type}: '{prefix}{entry.key}' has no description"
            if hasattr(entry, "entries"):
                walk(entry.entries, f"{prefix}{entry.key}.")
    walk(cls.parameters)


@pytest.mark.parametrize("model_type", [name for name, cls in polind.MODEL_TYPES.items()
                                        if cls.has_elements and not cls.has_contact])
def test_an_example_of_n_elements_has_n_elements(model_type):
    model = polind.MODEL_TYPES[model_type].example(elements=5)
    assert len(model.params["stiffness"]) == 5


OUT_OF_RANGE = [   # (model type, key, value): outside the domains of MODELS.md 0-6
    ("coulomb", "coulomb_force", 0.0),
    ("coulomb", "coulomb_force", -1.0),
    ("stribeck", "stribeck_velocity", 0.0),
    ("stribeck", "stribeck_velocity", -1e-3),
    ("stribeck", "stribeck_exponent", 0.0),          # delta > 0
    ("stribeck", "static_force", -1.0),
    ("dahl", "exponent", -0.5),                      # alpha >= 0
    ("dahl", "stiffness", 0.0),
    ("lugre", "stribeck_exponent", -2.0),
    ("lugre", "coulomb_force", -1.0),
    ("maxwell-slip", "breakaway_force", [0.2, -0.3, 0.25, 0.25]),
    ("gms", "weight", [1.2, -0.2, 0.0, 0.0]),        # alpha_i > 0
    ("gms", "attraction", -50.0),
    ("leuven", "stiffness", [1e5, 0.0, 2e4, 1e4]),
]


@pytest.mark.parametrize("model_type, key, value", OUT_OF_RANGE,
                         ids=[f"{m}-{k}-{v}" for m, k, v in OUT_OF_RANGE])
def test_out_of_range_values_name_the_key(model_type, key, value):
    raises_naming(dict(representative(model_type), **{key: value}), key)


@pytest.mark.parametrize("model_type", sorted(CONFORMANCE_SETS))
def test_a_model_declares_the_files_it_reads(model_type):
    """The keys a model reads files from are its declarations of kind "path" (asked of the
    model: io and the command line hold no list of them)."""
    cls = polind.MODEL_TYPES[model_type]
    expected = {"pol-ind": {"surface.topography", "discretisation.heights_file"}}
    assert set(cls.file_keys()) == expected.get(model_type, set())
    table = {"surface": {"topography": "map.x3p"}, "discretisation": {"heights_file": ""}}
    assert [value for _, _, value in cls.files_in(table)] == \
        (["map.x3p"] if cls.file_keys() else [])


@pytest.mark.parametrize("model_type", sorted(REPRESENTATIVE))
def test_every_model_equals_its_plain_reference(model_type):
    """Each registered model (those of contact mechanics have their own tests) runs as its
    plain-Python stepper of tests/oracles.py does: a new model needs its oracle."""
    import oracles

    assert model_type in oracles.STEPPERS, f"no plain reference for '{model_type}' in oracles.py"
    rtol = oracles.AGREEMENT.get(model_type, 1e-7)
    if rtol is None:
        pytest.skip(f"{model_type} is compared by convergence in its own tests")
    t, x, _ = motions()
    got = run(REPRESENTATIVE[model_type], t, x=x).force
    want = oracles.simulate(REPRESENTATIVE[model_type], t, x=x).force
    scale = float(np.max(np.abs(want)))
    np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * scale)
