"""The regression corpus of ``tests/test_corpus.py``: today's results, to hold the code to.

A script, not a test module: it builds every case from polind's public API and
writes the results the code importable as ``polind`` gives into
``corpus.npz`` (the arrays) and ``corpus.json`` (what they are and where they
came from) beside this file.  ``tests/test_corpus.py`` imports the same case
builders from here and checks that the current code gives the same results.

Freeze a commit from a pristine checkout of it, not from a working tree that
others are editing, with numba's cache of that checkout in a folder of its own
(``$BASE`` and ``$CACHE``: any new folders)::

    git worktree add "$BASE" HEAD
    PYTHONPATH="$BASE/src" NUMBA_CACHE_DIR="$CACHE" python tests/corpus/generate.py
    git worktree remove "$BASE"

It takes about four minutes of numba compilation from an empty cache.

A case is a model variant (:data:`VARIANTS`: every built-in model plain, behind
a series spring, and scaled by a varying normal load; Pol-Ind statistical,
direct on a file of summit heights, on a measured height map, elastic-plastic)
run through one driver (:data:`DRIVERS`: ``simulate`` by position and by
velocity, ``Stepper``, ``Body``, ``BodyBatch``, ``simulate_system``,
``Body.compiled`` in a numba loop, ``control.friction_system``,
``control.body_system`` and ``identify``).  Every input is built here with
the four operations and ``np.interp`` only (no ``sin``, no ``exp``: their last
bits differ between libraries), and random numbers come from NumPy's seeded
generator, so that the inputs are the same bits on any machine; the models' own
arithmetic is what the corpus records.  Each model sees motions, forces and
loads sized by its own force, presliding length and speed (:class:`Scale`,
written out here rather than asked of the model, so that the inputs cannot move
with the code under test).

Importing this file runs nothing (pytest's ``--doctest-modules`` imports it; it
has no doctests); only ``python tests/corpus/generate.py`` writes the corpus.
"""

from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
CORPUS = HERE / "corpus.npz"
METADATA = HERE / "corpus.json"

#: Samples of every run: enough for presliding, sliding, reversals and a dwell; few
#: enough that numba's compilation, not the runs, is what the test takes.
SAMPLES = 161

#: Field names are ``case::field`` in ``corpus.npz`` (a case id holds ``/``).
SEPARATOR = "::"

#: The tolerance classes (``tests/test_corpus.py`` says why each is what it is).
PRESCRIBED, BODY, IDENTIFY = "prescribed", "body", "identify"


# ---------------------------------------------------------------------------
# Scales and inputs
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Scale:
    """The sizes a variant's inputs are made to.

    Attributes
    ----------
    force : float
        About the break-away force [N]: applied forces reach 1.3 of it.
    length : float
        About the presliding range [m]: motions travel several, with small
        reversals inside one.
    speed : float
        About the Stribeck velocity [m/s]: motions run from a twentieth of it
        to three times it.
    """

    force: float
    length: float
    speed: float


CLASSICAL = Scale(force=1.5, length=2e-5, speed=1e-3)
POL_IND = Scale(force=15.0, length=1e-7, speed=1e-3)
SUMMITS = Scale(force=0.75, length=7e-8, speed=1e-3)     # the heights file at 5 N (55 in contact)
SEEDED = Scale(force=0.6, length=7e-8, speed=1e-3)      # 40,000 sampled summits at 4 N (58)
MAPPED = Scale(force=0.015, length=1e-8, speed=1e-3)     # the x3p map at 0.1 N

# The velocity of a prescribed motion (in units of Scale.speed) at fractions of its
# duration, linear in between: a slow start, sliding up to 2 and 3 times the
# Stribeck velocity, small reversals that stay in presliding, a dwell at rest (v = 0
# for several samples) and a reversal from fast sliding.
_MOTION = np.array([
    (0.00, 0.0), (0.05, 0.05), (0.15, 1.0), (0.25, 2.0), (0.30, 0.0), (0.35, -0.3),
    (0.40, 0.0), (0.45, 0.15), (0.50, 0.0), (0.55, 0.0), (0.65, -3.0), (0.72, -0.5),
    (0.77, 0.0), (0.82, 1.0), (0.87, 0.0), (0.92, -0.2), (1.00, 0.0)])
# The duration of the motion above in units of length / speed.  Its widest excursion
# is 0.254 speed x duration: 7.5 presliding lengths, with the small reversals inside
# half of one.
_MOTION_SPAN = 8.0 / 0.27

# The applied force of a body (in units of Scale.force) at fractions of the run:
# stuck while it rises, sliding beyond break-away, slowing, pushed back the other way
# and left with a small force it may or may not stick under.
_PUSH = np.array([(0.00, 0.0), (0.15, 1.3), (0.30, 1.3), (0.40, 0.5), (0.55, -1.3),
                  (0.70, -1.3), (0.80, 0.2), (1.00, 0.2)])

# A normal load's relative change: about the reference load for the load-scaled
# classical models (any positive load), at most the model's own load for Pol-Ind (its
# element table is laid out for the largest load, and a Stepper or a Body refuses more).
_LOAD_ABOUT = np.array([(0.0, 1.0), (0.2, 1.4), (0.5, 0.6), (0.8, 1.2), (1.0, 1.0)])
_LOAD_BELOW = np.array([(0.0, 1.0), (0.3, 0.6), (0.6, 0.9), (0.8, 0.7), (1.0, 1.0)])


def _profile(table, points):
    """``table`` (fraction, value) at ``points`` fractions, linear in between."""
    return np.interp(points, table[:, 0], table[:, 1])


def motion(scale: Scale, samples: int = SAMPLES) -> dict:
    """The prescribed motion of a variant: ``t`` [s], ``x`` [m], ``v`` [m/s], uniform steps.

    ``x`` is the trapezoidal integral of ``v``, so ``simulate(x=x)`` and
    ``simulate(v=v)`` follow the same path.
    """
    duration = _MOTION_SPAN * scale.length / scale.speed
    dt = duration / (samples - 1)
    t = dt * np.arange(samples, dtype=np.float64)
    v = scale.speed * _profile(_MOTION, np.arange(samples) / (samples - 1))
    x = np.concatenate(([0.0], np.cumsum(0.5 * dt * (v[1:] + v[:-1]))))
    return {"t": t, "x": x, "v": v, "dt": dt}


def body_setup(scale: Scale, samples: int = SAMPLES) -> dict:
    """A body's mass [kg], time step [s] and applied forces [N] (one per step).

    The run lasts the time the body takes to travel 20 presliding lengths at the
    variant's speed; the mass lets 0.4 of the force bring it to that speed in a
    quarter of the run.
    """
    steps = samples - 1
    duration = 20.0 * scale.length / scale.speed
    mass = 0.1 * scale.force * duration / scale.speed
    forces = scale.force * _profile(_PUSH, np.arange(steps) / steps)
    return {"mass": mass, "time_step": duration / steps, "steps": steps, "forces": forces}


def load_signal(variant: "Variant", samples: int) -> np.ndarray | None:
    """The normal load [N] at each of ``samples`` uniform samples, or None at constant load."""
    if not variant.varying_load:
        return None
    table = _LOAD_BELOW if variant.family == "pol-ind" else _LOAD_ABOUT
    return variant.load * _profile(table, np.arange(samples) / (samples - 1))


# ---------------------------------------------------------------------------
# The model variants
# ---------------------------------------------------------------------------

#: The series compliance k_s [N/m] of the "-compliance" variants: about the
#: contact's own presliding stiffness, so that spring and contact share the motion.
CLASSICAL_COMPLIANCE = 1e5
POL_IND_COMPLIANCE = 2e8
#: N0 [N] of the classical "-load" variants (their force levels belong to it).
REFERENCE_LOAD = 2.0

#: The summit heights of the direct variants, written into a CSV at run time.
HEIGHTS_SEED, HEIGHTS_COUNT, HEIGHTS_STD = 2, 500, 0.3e-6


@dataclass(frozen=True)
class Variant:
    """One model of the corpus.

    Attributes
    ----------
    name : str
        The case id's first part.
    family : str
        The model ``type``.
    scale : Scale
        The sizes of its inputs.
    surface : str
        Pol-Ind only: ``"statistical"``, ``"direct"`` (heights file), ``"seeded"``
        (direct summation of a seeded sample), ``"mapped"`` or ``"plastic"``.
    compliance : float or None
        k_s [N/m] of a series spring.
    varying_load : bool
        Whether the drivers that take a normal load get :func:`load_signal`.
    load : float
        The model's own normal load (Pol-Ind) or reference load [N].
    drivers : tuple of str
        The drivers it runs through.
    """

    name: str
    family: str
    scale: Scale
    surface: str = ""
    compliance: float | None = None
    varying_load: bool = False
    load: float = 0.0
    drivers: tuple = ()


def _classical_document(variant: Variant) -> dict:
    from polind.models import MODEL_TYPES

    table = {"type": variant.family, **MODEL_TYPES[variant.family].example_parameters()}
    if variant.varying_load:
        table["reference_load"] = variant.load
    return table


def _heights_file(workdir: Path) -> Path:
    """The summit heights of the direct variants as the CSV a heights_file is (``h`` [m])."""
    path = Path(workdir) / "summit_heights.csv"
    if not path.exists():
        heights = np.random.default_rng(HEIGHTS_SEED).normal(0.0, HEIGHTS_STD, HEIGHTS_COUNT)
        path.write_text("h\n" + "\n".join(repr(float(h)) for h in heights) + "\n")
    return path


def _pol_ind_document(variant: Variant, workdir: Path) -> dict:
    from polind import datasets
    from polind.models import PolInd

    table = {"type": "pol-ind", **copy.deepcopy(PolInd.example_parameters())}
    table["normal_load"] = variant.load
    if variant.surface == "direct":
        table["surface"] = {"asperity_radius": table["surface"]["asperity_radius"]}
        table["discretisation"] = {"summation": "direct",
                                   "heights_file": str(_heights_file(workdir))}
    elif variant.surface == "seeded":
        # The default A0 holds a million summits to sample: a patch of 40,000 instead.
        table["surface"]["nominal_area"] = 4e-6
        table["discretisation"] = {"summation": "direct", "seed": 3}
    elif variant.surface == "mapped":
        table["surface"] = {"topography": str(datasets.height_map_path("x3p-2.x3p"))}
        table["discretisation"] = {}            # direct summation is implied by a map
    elif variant.surface == "plastic":
        table["materials"]["hardness"] = 2e9
        table["discretisation"]["elements"] = 32
    return table


def document(variant: Variant, workdir: Path) -> dict:
    """The ``{"model": {...}}`` document of a variant (its files written into ``workdir``)."""
    if variant.family == "pol-ind":
        table = _pol_ind_document(variant, workdir)
    else:
        table = _classical_document(variant)
    if variant.compliance is not None:
        table["compliance"] = {"stiffness": variant.compliance}
    return {"model": table}


def portable(document_: dict, workdir: Path) -> dict:
    """A variant's document with its file names as ``$WORKDIR/...`` and ``$DATASETS/...``.

    What ``corpus.json`` keeps of each model: its keys and values as the corpus
    was made with, none of the folders of that machine.
    """
    from polind import datasets

    roots = ((str(Path(workdir)), "$WORKDIR"), (str(datasets.data_folder()), "$DATASETS"))

    def strip(value):
        if isinstance(value, dict):
            return {key: strip(item) for key, item in value.items()}
        if isinstance(value, str):
            for root, name in roots:
                if value.startswith(root + "/"):
                    return name + value[len(root):]
        return value

    return strip(document_)


def build_model(variant: Variant, workdir: Path):
    """The variant's model, through ``polind.model_from_dict``."""
    import polind

    return polind.model_from_dict(document(variant, workdir))


# The drivers of every variant, and the ones a few variants run through besides.
_EVERY = ("simulate_x", "simulate_v", "stepper_x", "body", "simulate_system")
_MORE = ("stepper_v", "body_batch", "compiled", "friction_system_x", "friction_system_v",
         "body_system")


def _variants() -> dict:
    """Every variant by name: each classical model three ways, Pol-Ind on each surface."""
    out = []
    more = {"coulomb", "lugre", "maxwell-slip-compliance", "gms-load", "leuven-compliance"}
    for family in ("coulomb", "stribeck", "dahl", "lugre", "maxwell-slip", "gms", "leuven"):
        for suffix, extra in (("", {}), ("-compliance", {"compliance": CLASSICAL_COMPLIANCE}),
                              ("-load", {"varying_load": True, "load": REFERENCE_LOAD})):
            name = family + suffix
            drivers = _EVERY + (_MORE if name in more else ())
            out.append(Variant(name, family, CLASSICAL, drivers=drivers, **extra))
    # Behind a spring and scaled by a load at once (the two mounts together).
    out.append(Variant("lugre-compliance-load", "lugre", CLASSICAL,
                       compliance=CLASSICAL_COMPLIANCE, varying_load=True, load=REFERENCE_LOAD,
                       drivers=_EVERY + ("friction_system_x", "body_system")))
    pol = dict(family="pol-ind")
    out += [
        Variant("pol-ind", scale=POL_IND, surface="statistical", load=100.0,
                drivers=_EVERY + _MORE, **pol),
        Variant("pol-ind-compliance", scale=POL_IND, surface="statistical", load=100.0,
                compliance=POL_IND_COMPLIANCE, drivers=_EVERY + _MORE, **pol),
        Variant("pol-ind-load", scale=POL_IND, surface="statistical", load=100.0,
                varying_load=True, drivers=_EVERY + ("friction_system_x", "body_system"), **pol),
        Variant("pol-ind-direct", scale=SUMMITS, surface="direct", load=5.0,
                drivers=_EVERY + ("body_batch", "compiled"), **pol),
        Variant("pol-ind-direct-load", scale=SUMMITS, surface="direct", load=5.0,
                varying_load=True, drivers=_EVERY, **pol),
        Variant("pol-ind-seeded", scale=SEEDED, surface="seeded", load=4.0,
                drivers=_EVERY, **pol),
        Variant("pol-ind-mapped", scale=MAPPED, surface="mapped", load=0.1,
                drivers=_EVERY + ("friction_system_x",), **pol),
        Variant("pol-ind-mapped-load", scale=MAPPED, surface="mapped", load=0.1,
                varying_load=True, drivers=_EVERY, **pol),
        Variant("pol-ind-plastic", scale=POL_IND, surface="plastic", load=100.0,
                drivers=_EVERY + ("body_batch", "compiled", "body_system"), **pol),
        Variant("pol-ind-plastic-load", scale=POL_IND, surface="plastic", load=100.0,
                varying_load=True, drivers=_EVERY + ("friction_system_x",), **pol),
        Variant("pol-ind-plastic-compliance", scale=POL_IND, surface="plastic", load=100.0,
                compliance=POL_IND_COMPLIANCE, drivers=_EVERY, **pol),
    ]
    return {variant.name: variant for variant in out}


VARIANTS = _variants()


# ---------------------------------------------------------------------------
# The drivers
# ---------------------------------------------------------------------------

def _state_fields(state) -> dict:
    """A State as arrays: its four scalars, then each variable."""
    out = {"state.scalars": np.array([state.time, state.position, state.velocity, state.force])}
    for key, value in state.variables.items():
        out[f"state.{key}"] = np.asarray(value, dtype=np.float64).ravel().copy()
    return out


def run_simulate(model, variant, by):
    import polind

    path = motion(variant.scale)
    load = load_signal(variant, SAMPLES)
    kwargs = {} if load is None else {"normal_load": load}
    res = polind.simulate(model, path["t"], **{by: path[by]}, **kwargs)
    return {"x": res.x, "v": res.v, "force": res.force, **_state_fields(res.final_state)}


def run_stepper(model, variant, by):
    import polind

    path = motion(variant.scale)
    t, x, v = path["t"], path["x"], path["v"]
    load = load_signal(variant, SAMPLES)
    # By position, simulate reports the first step's velocity at sample 0; give it.
    first = (x[1] - x[0]) / (t[1] - t[0]) if by == "x" else v[0]
    stepper = polind.Stepper(model, velocity=float(first))
    force = [stepper.force]
    for k in range(1, SAMPLES):
        kwargs = {by: float(path[by][k])}
        if load is not None:
            kwargs["normal_load"] = float(load[k])
        force.append(stepper.advance(float(t[k]), **kwargs))
    return {"force": np.array(force), **_state_fields(stepper.state)}


def run_body(model, variant):
    import polind

    setup = body_setup(variant.scale)
    load = load_signal(variant, SAMPLES)
    body = polind.Body(model, mass=setup["mass"], time_step=setup["time_step"])
    rows = [(body.position, body.velocity, body.friction)]
    for k, applied in enumerate(setup["forces"]):
        if load is None:
            rows.append(body.step(float(applied)))
        else:
            rows.append(body.step(float(applied), normal_load=float(load[k + 1])))
    x, v, force = np.array(rows).T
    return {"x": x, "v": v, "force": force, **_state_fields(body.state)}


#: Per body of a batch: its mass, starting position and share of the applied force.
_BATCH = np.array([(1.0, 0.0, 1.0), (0.5, 0.5, 0.7), (2.0, -1.0, -1.2)])


def run_body_batch(model, variant):
    import polind

    setup = body_setup(variant.scale)
    masses = setup["mass"] * _BATCH[:, 0]
    positions = variant.scale.length * _BATCH[:, 1]
    batch = polind.BodyBatch(model, len(_BATCH), mass=masses, time_step=setup["time_step"],
                             position=positions)
    xs, vs, fs = [batch.position], [batch.velocity], [batch.friction]
    for applied in setup["forces"]:
        x, v, force = batch.step(applied * _BATCH[:, 2])
        xs.append(x)
        vs.append(v)
        fs.append(force)
    return {"x": np.array(xs), "v": np.array(vs), "force": np.array(fs)}


def _pushed(step, arguments, forces, out):
    """A user's own compiled loop: one body step per applied force, (x, v, F) kept."""
    for k in range(forces.shape[0]):
        x, v, friction = step(*arguments, forces[k])
        out[k, 0] = x
        out[k, 1] = v
        out[k, 2] = friction


_compiled_loop = None


def run_compiled(model, variant):
    global _compiled_loop
    import polind
    from numba import njit

    if _compiled_loop is None:
        _compiled_loop = njit(_pushed)
    setup = body_setup(variant.scale)
    body = polind.Body(model, mass=setup["mass"], time_step=setup["time_step"])
    first = (body.position, body.velocity, body.friction)
    step, arguments = body.compiled()
    out = np.empty((setup["steps"], 3))
    _compiled_loop(step, arguments, setup["forces"], out)
    rows = np.vstack((first, out))
    # The body advanced with the loop: its state is the one after the last step.
    return {"x": rows[:, 0], "v": rows[:, 1], "force": rows[:, 2], **_state_fields(body.state)}


def run_simulate_system(model, variant):
    import polind

    setup = body_setup(variant.scale)
    scale = variant.scale
    duration = setup["time_step"] * setup["steps"]
    # A drive spring that reaches the break-away force in a quarter of the run at half
    # the variant's speed (stick-slip in the models with a Stribeck dip), and a small
    # oscillating force beside it.
    system = polind.System(mass=setup["mass"], duration=duration, time_step=setup["time_step"],
                           spring_stiffness=scale.force / (0.5 * scale.speed * 0.25 * duration),
                           drive_velocity=0.5 * scale.speed, offset=0.0,
                           amplitude=0.1 * scale.force, frequency=3.0 / duration)
    res = polind.simulate_system(model, system)
    return {"x": res.x, "v": res.v, "force": res.force, "applied": res.applied,
            **_state_fields(res.final_state)}


def run_friction_system(model, variant, by):
    import control
    from polind.control import friction_system, initial_state

    path = motion(variant.scale)
    load = load_signal(variant, SAMPLES)
    system = friction_system(model, dt=path["dt"], input=by, normal_load=load is not None)
    T = path["dt"] * np.arange(SAMPLES)
    U = path[by] if load is None else np.vstack((path[by], load))
    velocity = (path["x"][1] - path["x"][0]) / path["dt"] if by == "x" else path["v"][0]
    X0 = initial_state(model, velocity=float(velocity))
    resp = control.input_output_response(system, T, U, X0)
    return {"force": np.asarray(resp.outputs, dtype=np.float64).ravel(),
            "states": np.asarray(resp.states, dtype=np.float64)[:, -1].copy()}


def run_body_system(model, variant):
    import control
    from polind.control import body_system

    setup = body_setup(variant.scale)
    load = load_signal(variant, SAMPLES)
    system = body_system(model, mass=setup["mass"], dt=setup["time_step"],
                         normal_load=load is not None)
    T = setup["time_step"] * np.arange(SAMPLES)
    # u[k] drives the step from sample k to k + 1; the last one drives nothing seen.
    forces = np.append(setup["forces"], setup["forces"][-1])
    U = forces if load is None else np.vstack((forces, np.append(load[1:], load[-1])))
    resp = control.input_output_response(system, T, U, system.initial_state)
    x, v, force = np.asarray(resp.outputs, dtype=np.float64)
    return {"x": x.copy(), "v": v.copy(), "force": force.copy()}


DRIVERS = {
    "simulate_x": (PRESCRIBED, lambda m, var: run_simulate(m, var, "x")),
    "simulate_v": (PRESCRIBED, lambda m, var: run_simulate(m, var, "v")),
    "stepper_x": (PRESCRIBED, lambda m, var: run_stepper(m, var, "x")),
    "stepper_v": (PRESCRIBED, lambda m, var: run_stepper(m, var, "v")),
    "friction_system_x": (PRESCRIBED, lambda m, var: run_friction_system(m, var, "x")),
    "friction_system_v": (PRESCRIBED, lambda m, var: run_friction_system(m, var, "v")),
    "body": (BODY, run_body),
    "body_batch": (BODY, run_body_batch),
    "compiled": (BODY, run_compiled),
    "simulate_system": (BODY, run_simulate_system),
    "body_system": (BODY, run_body_system),
}


# ---------------------------------------------------------------------------
# Identification
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Fit:
    """An identification case: the variant whose model made the data, and the fit.

    Attributes
    ----------
    variant : str
        The model that gives the record (its ``simulate_x`` of the variant's motion).
    start : dict
        The starting values (changed keys of the model; dotted for nested ones).
    free : tuple of str
        The keys identified.
    evaluations : int
        The fit's budget (``max_evaluations``), a bound on its time.  Each fit
        below ends before it, in 5 to 8 iterations, by the solver's noise test
        (an iteration that gains less than a hundredth of the noise variance).
    """

    variant: str
    start: dict
    free: tuple
    evaluations: int


FITS = {
    "dahl": Fit("dahl", {"stiffness": 3e4, "coulomb_force": 2.0},
                ("stiffness", "coulomb_force"), 12),
    "gms-compliance": Fit("gms-compliance", {"coulomb_force": 1.4, "compliance.stiffness": 3e5},
                          ("coulomb_force", "attraction", "compliance.stiffness"), 12),
    "lugre-load": Fit("lugre-load", {"static_force": 1.2, "stribeck_velocity": 3e-3},
                      ("coulomb_force", "static_force", "stribeck_velocity"), 12),
    "pol-ind": Fit("pol-ind", {"static_coefficient": 0.2, "kinetic_coefficient": 0.08},
                   ("static_coefficient", "kinetic_coefficient"), 8),
}


def _with_start(variant, start, workdir):
    """The variant's document with the fit's starting values put in."""
    doc = document(variant, workdir)
    for key, value in start.items():
        table = doc["model"]
        *outer, last = key.split(".")
        for part in outer:
            table = table[part]
        table[last] = value
    return doc


def fit_record(name: str, workdir: Path) -> dict:
    """The record a fit is made to: the true model's ``simulate_x`` force, with a noise.

    At generation time only: the test fits the stored record, so that the fit's
    inputs are the corpus's bits whatever the current code simulates.
    """
    import polind

    fit = FITS[name]
    variant = VARIANTS[fit.variant]
    path = motion(variant.scale)
    load = load_signal(variant, SAMPLES)
    kwargs = {} if load is None else {"normal_load": load}
    force = polind.simulate(build_model(variant, workdir), path["t"], x=path["x"],
                            **kwargs).force
    # Measurement noise of 1 % of the force, from a seeded generator (the same bits on
    # any machine), so that the fit's residual is not zero.
    noise = np.random.default_rng(5).standard_normal(force.shape[0])
    return force + 0.01 * variant.scale.force * noise


def run_identify(name: str, workdir: Path, measured: np.ndarray) -> dict:
    """``polind.identify`` of the fit ``name`` to the force ``measured``."""
    import polind

    fit = FITS[name]
    variant = VARIANTS[fit.variant]
    path = motion(variant.scale)
    data = {"t": path["t"], "x": path["x"], "F": measured}
    load = load_signal(variant, SAMPLES)
    if load is not None:
        data["normal_load"] = load
    start = polind.model_from_dict(_with_start(variant, fit.start, workdir))
    # One start (the model's values): the Latin-hypercube spread starts are seeded, but
    # a budget of a few evaluations is about the path, not about which start wins.  One
    # worker: the result does not depend on it, and the choice then does not depend on
    # how fast this machine runs a simulation.
    result = polind.identify(start, data, free=list(fit.free), starts=1,
                             max_evaluations=fit.evaluations, workers=1)
    values = np.concatenate([np.atleast_1d(np.asarray(result.values[key], dtype=np.float64))
                             for key in fit.free])
    return {"measured": np.asarray(measured, dtype=np.float64), "values": values,
            "rms_error": np.array([result.rms_error]), "force": result.force,
            "counts": np.array([result.iterations, result.evaluations], dtype=np.float64)}


# ---------------------------------------------------------------------------
# The cases
# ---------------------------------------------------------------------------

def case_ids() -> list:
    """Every case, ``variant/driver`` (fits: ``variant/identify``), in a fixed order."""
    ids = [f"{name}/{driver}" for name, variant in VARIANTS.items() for driver in variant.drivers]
    return ids + [f"{name}/identify" for name in FITS]


def kind_of(case: str) -> str:
    """The tolerance class of a case: :data:`PRESCRIBED`, :data:`BODY` or :data:`IDENTIFY`."""
    driver = case.split("/")[1]
    return IDENTIFY if driver == "identify" else DRIVERS[driver][0]


def run_case(case: str, workdir: Path, stored: dict | None = None) -> dict:
    """The fields of one case, computed by the ``polind`` that is imported.

    Parameters
    ----------
    case : str
        A :func:`case_ids` entry.
    workdir : path-like
        A folder for the files a model reads (the heights file).
    stored : dict, optional
        The corpus's fields of the case: an identification fits their
        ``measured`` force (without them, the one :func:`fit_record` makes).
    """
    name, driver = case.split("/")
    workdir = Path(workdir)
    with warnings.catch_warnings():
        # Validity and fit warnings are not what the corpus holds (a measured map under
        # Hertz warns of its peak pressure, a short fit of its budget).
        warnings.simplefilter("ignore")
        if driver == "identify":
            measured = fit_record(name, workdir) if stored is None else stored["measured"]
            return run_identify(name, workdir, measured)
        variant = VARIANTS[name]
        return DRIVERS[driver][1](build_model(variant, workdir), variant)


def split_fields(corpus) -> dict:
    """``{case: {field: array}}`` of a loaded ``corpus.npz``."""
    out = {}
    for key in corpus.files:
        case, field = key.split(SEPARATOR)
        out.setdefault(case, {})[field] = corpus[key]
    return out


def _provenance() -> dict:
    """The commit and the versions the corpus was made with."""
    import control
    import numba
    import scipy

    import polind

    source = Path(polind.__file__).resolve().parent

    def git(*args):
        try:
            done = subprocess.run(["git", *args], cwd=source, capture_output=True, text=True,
                                  timeout=30)
        except OSError:
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    return {"commit": git("rev-parse", "HEAD"),
            "source_modified": bool(git("status", "--porcelain", "--", ".")),
            "python": sys.version.split()[0], "numpy": np.__version__,
            "numba": numba.__version__, "scipy": scipy.__version__,
            "control": control.__version__, "polind": polind.__version__}


def main(argv=None) -> None:
    import tempfile
    import time

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", default=str(HERE),
                        help="folder for corpus.npz and corpus.json (default: beside this file)")
    args = parser.parse_args(argv)
    output = Path(args.output)
    import polind

    # The code being frozen: a pristine checkout's, as PYTHONPATH put it first.
    print(f"polind from {Path(polind.__file__).resolve().parent}", flush=True)
    arrays, cases = {}, {}
    with tempfile.TemporaryDirectory() as workdir:
        models = {name: portable(document(variant, Path(workdir)), Path(workdir))
                  for name, variant in VARIANTS.items()}
        for case in case_ids():
            began = time.perf_counter()
            fields = run_case(case, Path(workdir))
            cases[case] = {"kind": kind_of(case), "fields": sorted(fields)}
            for field, value in fields.items():
                arrays[f"{case}{SEPARATOR}{field}"] = np.asarray(value, dtype=np.float64)
            print(f"{time.perf_counter() - began:7.2f} s  {case}", flush=True)
    metadata = {"about": ("Results of polind's public API for tests/test_corpus.py, made by "
                          "tests/corpus/generate.py; identify's 'values' are its free keys in "
                          "the order of 'free', list keys flattened, 'counts' its iterations "
                          "and evaluations."),
                "provenance": _provenance(), "samples": SAMPLES, "models": models,
                "fits": {name: {"variant": fit.variant, "start": fit.start,
                                "free": list(fit.free), "max_evaluations": fit.evaluations}
                         for name, fit in FITS.items()},
                "cases": cases}
    output.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(output / CORPUS.name, **arrays)
    (output / METADATA.name).write_text(json.dumps(metadata, indent=1) + "\n")
    print(f"{len(cases)} cases -> {output / CORPUS.name}")


if __name__ == "__main__":
    main()
