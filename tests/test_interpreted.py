"""Kernels run by Python (polind.kernels.interpreted): the compiled kernels' results, to the bit.

A model built at one load solves its separation with the Python run of the
statistical Newton kernel, and asks the Greenwood–Williamson pair a few
values with the Python run of the pair: no compilation for either.  These
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
from polind.kernels.interpreted import interpreted
from polind.kernels.special import special_addresses

SURFACE = StatisticalSurface(1e10, 1e-4, 50e-6, 0.5e-6, 1.15e11, 2.4e10)
ARGUMENTS = contact_separation._kernel_surface(SURFACE)
SMALLEST, LARGEST = SURFACE.load_range
LO, HI = SURFACE.separation_range


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
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, env={**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)})
    assert done.returncode == 0, done.stderr
    separation, load, normal_load, newton, pair = json.loads(done.stdout.splitlines()[-1])
    assert abs(load - normal_load) <= kernels.RELATIVE_TOLERANCE * normal_load
    assert math.isfinite(separation)
    assert (newton, pair) == (0, 0)
