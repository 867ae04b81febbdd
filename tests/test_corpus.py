"""Nothing changes for users: today's results of the public API, held to the current code.

``tests/corpus/corpus.npz`` holds what a pristine checkout of one commit gave
(``corpus.json`` names it) for every case of ``tests/corpus/generate.py``:
every built-in model, plain, behind a series spring and under a varying normal
load, and Pol-Ind on each of its surfaces, run through ``simulate`` (by position
and by velocity), ``Stepper``, ``Body``, ``BodyBatch``, ``simulate_system``,
``Body.compiled`` in a numba loop, the python-control systems and a short
``identify``.  Each test rebuilds one case with the generator's own builders,
runs it with the code under test and compares every stored field.

Tolerances, by what a faithful refactor of the stepping core may change:

- prescribed motion (``simulate``, ``Stepper``, ``friction_system``): 1e-13 of
  the record's range.  The force at a sample is a few operations on the state
  of the step before; a reordered sum may move it by some ulps of the largest
  force, not more, and nothing feeds a sample's rounding back into the path.
- a body (``Body``, ``BodyBatch``, ``simulate_system``, ``compiled``,
  ``body_system``): 1e-11 of the range of each of ``x``, ``v`` and the force.
  The friction force moves the body, so a last-bit difference is fed back at
  every step, and each step solves an implicit equation to a tolerance whose
  last iterate may round the other way.
- ``identify``: 1e-6 relative on the fitted values and the RMS error, 1e-6 of
  the range on the fitted force, the iteration and evaluation counts exactly.
  The solver differentiates the force by forward differences with a relative
  step of 1e-6, so a change of the force in its last bits moves the Jacobian by
  about 1e-10 relative, and the steps the solver takes, over a few
  iterations, by more; 1e-6 is loose for that and tight against any change of
  the model itself.  A fit that took a different number of iterations took a
  different path, which is a change a user sees.

A range of zero (a constant record) takes the largest magnitude in the
record instead, and an all-zero record the unit: a record that was exactly 0
must stay within the tolerance of 0.  The final states (``state.*`` fields:
what a user saves and continues from; ``states``, a python-control system's
last state) are held at their case's tolerance too: a model's own variable
(element forces, deflections, ...) relative to its largest magnitude, and the
vectors whose entries have different units (the four scalars of a State, a
Body's history, a control system's state) entry by entry, relative to each
entry, so that an entry that was exactly 0 (a body stuck, a flag) stays 0.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

CORPUS_DIR = Path(__file__).resolve().parent / "corpus"


def _generator():
    """``tests/corpus/generate.py`` as a module (a script beside the data, not a package)."""
    name = "polind_corpus_generate"
    spec = importlib.util.spec_from_file_location(name, CORPUS_DIR / "generate.py")
    module = importlib.util.module_from_spec(spec)
    # Registered before it runs: its dataclasses look their module up by name.
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


generate = _generator()
METADATA = json.loads(generate.METADATA.read_text())
CASES = list(METADATA["cases"])

#: Relative tolerance of each kind of case (the module notes say why).
TOLERANCE = {generate.PRESCRIBED: 1e-13, generate.BODY: 1e-11, generate.IDENTIFY: 1e-6}


@pytest.fixture(scope="module")
def corpus():
    with np.load(generate.CORPUS) as stored:
        return generate.split_fields(stored)


#: The fields whose entries have units of their own (compared entry by entry).
MIXED = ("state.scalars", "state.body", "states")
RANGE, MAGNITUDE, ENTRY = "range", "magnitude", "entry"


def _scale(stored: np.ndarray, relative_to: str):
    """What a field's tolerance is relative to (never 0): a number, or one per entry."""
    if relative_to == ENTRY:
        return np.abs(stored)
    finite = stored[np.isfinite(stored)]
    if finite.size == 0:
        return 1.0
    if relative_to == RANGE and finite.max() > finite.min():
        return float(finite.max() - finite.min())
    largest = float(np.abs(finite).max())
    return largest if largest > 0.0 else 1.0


def _compare(case, field, got, stored, tolerance, relative_to=RANGE):
    got = np.asarray(got, dtype=np.float64)
    assert got.shape == stored.shape, (
        f"{case} {field}: shape {got.shape}, the corpus has {stored.shape}")
    same_nan = np.isnan(got) == np.isnan(stored)
    assert same_nan.all(), f"{case} {field}: NaN at other samples than the corpus's"
    bound = np.broadcast_to(tolerance * _scale(stored, relative_to), stored.shape)
    error = np.abs(np.where(np.isnan(stored), 0.0, got - stored))
    bad = ~(error <= bound)
    if bad.any():
        worst = np.unravel_index(int(np.argmax(np.where(bad, error - bound, -np.inf))),
                                 error.shape)
        raise AssertionError(
            f"{case} {field}: {int(bad.sum())} of {error.size} entries differ beyond "
            f"{tolerance:g} relative to the corpus's {relative_to}; worst at "
            f"{tuple(int(i) for i in worst)}: got {float(got[worst])!r}, corpus "
            f"{float(stored[worst])!r}, |difference| {error[worst]:.3g} > {bound[worst]:.3g}")


def test_the_corpus_holds_every_case_of_the_generator(corpus):
    # A case added to (or dropped from) the generator without regenerating the corpus.
    assert CASES == generate.case_ids()
    assert list(METADATA["models"]) == list(generate.VARIANTS)
    assert set(corpus) == set(CASES)
    for case in CASES:
        assert sorted(corpus[case]) == METADATA["cases"][case]["fields"], case
        assert METADATA["cases"][case]["kind"] == generate.kind_of(case), case


@pytest.mark.parametrize("variant", list(METADATA["models"]))
def test_the_models_are_the_corpus_models(variant, tmp_path):
    # The parameter sets come from the models' own examples: one that changed fails here,
    # named, rather than as a different force in every case of the variant.
    model = generate.VARIANTS[variant]
    assert generate.portable(generate.document(model, tmp_path), tmp_path) \
        == METADATA["models"][variant]


@pytest.mark.parametrize("case", CASES)
def test_case(case, corpus, tmp_path):
    stored = corpus[case]
    kind = generate.kind_of(case)
    tolerance = TOLERANCE[kind]
    got = generate.run_case(case, tmp_path, stored)
    assert sorted(got) == sorted(stored), f"{case}: other fields than the corpus's"
    for field in sorted(stored):
        if kind == generate.IDENTIFY:
            if field == "counts":           # iterations and evaluations: the same path
                assert got[field].tolist() == stored[field].tolist(), f"{case} {field}"
            elif field in ("values", "rms_error"):
                np.testing.assert_allclose(got[field], stored[field], rtol=tolerance, atol=0.0,
                                           err_msg=f"{case} {field}")
            else:                           # the fitted force and the record it was fitted to
                _compare(case, field, got[field], stored[field], tolerance)
        elif field in MIXED:
            _compare(case, field, got[field], stored[field], tolerance, ENTRY)
        elif field.startswith("state."):
            _compare(case, field, got[field], stored[field], tolerance, MAGNITUDE)
        else:
            _compare(case, field, got[field], stored[field], tolerance)
