"""The kernels' numerical building blocks, against NumPy and closed forms."""

import numpy as np
import pytest

from polind.kernels.fastexp import decay_exp_array
from polind.kernels.stribeck import EXPONENTIAL, RATIONAL
from polind.models.static import stribeck_curve
from polind.bench import harness
from polind.bench.references import numpy_reference


def test_decay_exp_matches_numpy_within_its_documented_error():
    rng = np.random.default_rng(1)
    x = np.concatenate([-rng.exponential(3.0, 200_000), -rng.uniform(0, 708, 200_000),
                        [0.0, -1e-300, -0.5 * np.log(2), -np.log(2), -700.0, -708.0]])
    got = decay_exp_array(x, np.empty_like(x))
    want = np.exp(x)
    assert np.max(np.abs(got - want)) < 2e-16
    assert np.max(np.abs(got - want) / want / (1.0 + np.abs(x))) < 2e-16
    small = x > -5.0
    assert np.max(np.abs(got - want)[small] / want[small]) < 1e-15


def test_decay_exp_underflows_to_zero():
    x = np.array([-708.5, -1e4, -np.inf])
    assert np.all(decay_exp_array(x, np.empty_like(x)) == 0.0)


def test_stribeck_shape_codes_match_the_curve_definitions():
    v = np.array([-1e-2, -1e-3, 0.0, 5e-4, 1e-3, 3e-3])
    fc, fs, vs, delta = 1.0, 1.5, 1e-3, 2.0
    exponential = fc + (fs - fc) * np.exp(-np.abs(v / vs) ** delta)
    rational = fc + (fs - fc) / (1.0 + np.abs(v / vs) ** delta)
    np.testing.assert_allclose(stribeck_curve(v, fc, fs, vs, delta, "exponential"), exponential,
                               rtol=1e-15)
    np.testing.assert_allclose(stribeck_curve(v, fc, fs, vs, delta, "rational"), rational,
                               rtol=1e-15)
    assert (EXPONENTIAL, RATIONAL) == (0, 1)


@pytest.mark.parametrize("model_type, n", [("maxwell-slip", 1), ("maxwell-slip", 64),
                                           ("gms", 1), ("gms", 64), ("pol-ind", 16),
                                           ("leuven", 1), ("leuven", 16), ("lugre", 1),
                                           ("dahl", 1), ("stribeck", 1)])
def test_kernels_agree_with_the_plain_numpy_loops_of_the_benchmark(model_type, n):
    # The benchmark's ratio is only meaningful if both sides do the same work.
    model = harness.bench_model(model_type, n)
    path = harness.bench_path(4000 if model_type != "leuven" else 400)
    kernel = model._advance(path, model.initial_state(), None)
    reference = numpy_reference(model)(path)
    scale = np.max(np.abs(reference))
    assert scale > 0
    assert np.max(np.abs(kernel - reference)) <= 1e-11 * scale


def test_compiled_entry_is_the_dispatchers_compiled_function():
    """``compiled_entry`` (what Stepper calls) computes what the dispatcher computes, or is it."""
    import numba

    from polind.kernels import compiled_entry

    @numba.njit
    def scaled_sum(values, factor):
        values[0] += factor
        return values.sum() * factor

    values = np.arange(4.0)
    entry = compiled_entry(scaled_sum, values, 2.0)
    assert entry is not scaled_sum
    assert values.tolist() == [0.0, 1.0, 2.0, 3.0]          # compiled, not called
    twin = values.copy()
    assert entry(values, 3.0) == scaled_sum(twin, 3.0)
    assert values.tolist() == twin.tolist()                  # same effect on the array

    def plain(values, factor):
        return 0.0

    assert compiled_entry(plain, values, 2.0) is plain       # not a dispatcher
    assert compiled_entry(scaled_sum, "text", 2.0) is scaled_sum   # a signature numba refuses


@pytest.mark.parametrize("model_type, n", [("maxwell-slip", 1024), ("gms", 7), ("lugre", 1)])
def test_kernel_arrays_are_placed_in_their_pages(model_type, n):
    from polind.models.kernel import SCALARS_OFFSET, STATE_OFFSET, TABLE_OFFSET, page_placed

    kernel = harness.bench_model(model_type, n).step_kernel()
    for values, offset in ((kernel.scalars, SCALARS_OFFSET), (kernel.table, TABLE_OFFSET),
                           (kernel.state, STATE_OFFSET)):
        assert values.size == 0 or values.ctypes.data % 4096 == offset   # (LuGre has no table)
        assert values.dtype == np.float64 and values.flags.c_contiguous
    raw = np.arange(15.0).reshape(3, 5)[:, ::2]          # not contiguous
    placed = page_placed(raw, 192)
    assert placed.ctypes.data % 4096 == 192 and placed.flags.c_contiguous
    np.testing.assert_array_equal(placed, raw)
