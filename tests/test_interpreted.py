"""Kernels run by Python (polind.kernels.interpreted): the compiled kernels' results, to the bit.

A model built at one load solves its separation with the Python run of the
statistical Newton kernel, and asks the Greenwood–Williamson pair a few
values with the Python run of the pair; a run's first force is the Python
run of the model's force: no compilation for any of them.  These
tests compare every bit with the compiled kernels (the reference) and check
that such a build compiles neither.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from polind.contact import separation as contact_separation
from polind.contact.surface import StatisticalSurface
from polind.kernels import greenwood as gw_kernels
from polind.kernels import separation as kernels
from polind.kernels.interpreted import call_once, interpreted
from polind.kernels.special import special_addresses
from polind.models import MODEL_TYPES

SURFACE = StatisticalSurface(1e10, 1e-4, 50e-6, 0.5e-6, 1.15e11, 2.4e10)
ARGUMENTS = contact_separation._kernel_surface(SURFACE)
SMALLEST, LARGEST = SURFACE.load_range
LO, HI = SURFACE.separation_range


def in_a_fresh_process(code, cache_dir):
    """The JSON ``code`` prints last, run in a new interpreter with an empty numba cache."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, env={**os.environ, "NUMBA_CACHE_DIR": str(cache_dir)})
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def bits(values):
    """The float64 bits of each value (so that NaN equals NaN and -0.0 differs from 0.0)."""
    return [np.float64(value).view(np.int64).item() for value in values]


@settings(max_examples=300, deadline=None)
@given(log_load=st.floats(math.log(SMALLEST), math.log(LARGEST)),
       where=st.one_of(st.none(), st.floats(0.0, 1.0)))
def test_the_interpreted_statistical_newton_is_the_compiled_one_to_the_bit(log_load, where):
    load = math.exp(log_load)
    # From the solver's own start (one evaluation) or anywhere in the bracket (Newton
    # steps and bisections): the iterations, stops and results of the compiled kernel.
    start = (contact_separation._initial_guess(SURFACE, load, LO, HI) if where is None
             else LO + where * (HI - LO))
    compiled = kernels.statistical_newton_counted(load, start, LO, HI, *ARGUMENTS)
    python = interpreted(kernels.statistical_newton_counted)(load, start, LO, HI, *ARGUMENTS)
    assert bits(python) == bits(compiled)
    assert abs(python[1] - load) <= kernels.RELATIVE_TOLERANCE * load


@settings(max_examples=300, deadline=None)
@given(s=st.one_of(st.floats(-12.0, 12.0), st.floats(-1e-7, 1e-7),
                   st.sampled_from([0.0, -0.0, math.inf, -math.inf, math.nan, 5.5, 10.5])))
def test_the_interpreted_pair_is_the_compiled_one_to_the_bit(s):
    # Through SciPy's Bessel ufuncs in Python and their C functions' addresses in numba,
    # the Taylor series about 0 and the special values.
    addresses = special_addresses().astype(np.float64)
    compiled = gw_kernels.gw_half_integer_pair(s, addresses)
    python = interpreted(gw_kernels.gw_half_integer_pair)(s, addresses)
    assert bits(python) == bits(compiled)
    fast = interpreted(gw_kernels.gw_half_integer_pair_fast)(s, addresses)
    assert bits(fast) == bits(gw_kernels.gw_half_integer_pair_fast(s, addresses))


def test_a_kernel_compiled_with_fastmath_is_refused():
    # tail_moments sums with reassociation: Python would add in another order.
    with pytest.raises(ValueError, match="tail_moments is compiled with fastmath"):
        interpreted(gw_kernels.tail_moments)


def test_a_model_built_at_one_load_compiles_no_separation_kernel(tmp_path):
    code = (
        "import json\n"
        "from polind.models import MODEL_TYPES\n"
        "from polind.kernels import greenwood, separation\n"
        "model = MODEL_TYPES['pol-ind'].example()\n"
        "contact = model.contact()\n"
        "surface = contact.surface\n"
        "print(json.dumps([contact.separation, float(surface.normal_load(contact.separation)),\n"
        "                  contact.normal_load,\n"
        "                  len(separation.statistical_newton_counted.signatures),\n"
        "                  len(greenwood.gw_half_integer_pair.signatures)]))\n")
    separation, load, normal_load, newton, pair = in_a_fresh_process(code, tmp_path)
    assert abs(load - normal_load) <= kernels.RELATIVE_TOLERANCE * normal_load
    assert math.isfinite(separation)
    assert (newton, pair) == (0, 0)


def _moved_kernel(model_type, fixed_load):
    """A model's kernel after a back-and-forth motion (stuck and slipping elements, bristles bent)."""
    model = MODEL_TYPES[model_type].example()
    kernel = model.step_kernel(model.initial_state(), fixed_load=fixed_load)
    step = 1e-4
    for k in range(300):
        velocity = 2e-3 * math.sin(2.0 * math.pi * k / 150.0)
        kernel.step(kernel.scalars, kernel.table, kernel.state, step, velocity * step, velocity,
                    velocity, kernel.normal_load)
    return kernel


@pytest.mark.parametrize("fixed_load", [False, True], ids=["own-step", "fixed-load"])
@pytest.mark.parametrize("model_type", sorted(MODEL_TYPES))
def test_the_first_sample_force_is_the_compiled_force_to_the_bit(model_type, fixed_load):
    # A run's first force is call_once's: by Python where the model's force is compiled
    # without fastmath (every model's but Pol-Ind's at a varying load), else compiled.
    kernel = _moved_kernel(model_type, fixed_load)
    for velocity in (0.0, 1e-5, -3e-3, 0.2, -40.0, 1e300):   # 1e300: overflows inside
        arguments = (kernel.scalars, kernel.table, kernel.state, velocity, kernel.normal_load)
        compiled = kernel.force(*arguments)
        assert bits([call_once(kernel.force, *arguments)]) == bits([compiled])
        if not kernel.force.targetoptions.get("fastmath"):
            assert bits([interpreted(kernel.force)(*arguments)]) == bits([compiled])


def test_call_once_falls_back_to_the_compiled_kernel_where_python_stops():
    from polind.kernels import jit

    @jit(fastmath=False)
    def ratio(a, b):
        return a / b

    # Python raises ZeroDivisionError; numba (error_model "numpy") gives inf.
    assert call_once(ratio, 1.0, 0.0) == math.inf
    assert call_once(ratio, 1.0, 4.0) == 0.25


def test_a_run_compiles_no_force_kernel_with_or_without_a_spring(tmp_path):
    # The first sample's force is Python's (call_once), and a constant-load run behind a
    # spring starts with the spring's force and has no load change to bring the model to.
    code = (
        "import json\n"
        "import numpy as np\n"
        "import polind\n"
        "from polind.kernels import single\n"
        "from polind.models import MODEL_TYPES\n"
        "t = np.linspace(0.0, 0.2, 400)\n"
        "x = 2e-5 * np.sin(2 * np.pi * 5 * t)\n"
        "model = MODEL_TYPES['lugre'].example()\n"
        "plain = polind.simulate(model, t, x).force\n"
        "sprung = polind.simulate(model.with_params(compliance={'stiffness': 1e5}), t, x).force\n"
        "print(json.dumps([float(plain[0]), float(plain[-1]), float(sprung[-1]),\n"
        "                  len(single.lugre_force.signatures)]))\n")
    first, last, sprung_last, compiled = in_a_fresh_process(code, tmp_path)
    assert math.isfinite(first) and last != 0.0 and sprung_last != 0.0   # real runs
    assert compiled == 0
