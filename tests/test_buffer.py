"""The step buffer of Stepper and Body (polind.kernels.buffer).

Its views from Python and its arrays taken out inside numba are the same
memory; each array starts at its offset within a page; a copy is
independent; a refused sample changes nothing in it.
"""

from __future__ import annotations

import numpy as np
import pytest

from polind.kernels import buffer as sb
from polind.kernels import jit
from polind.models import LuGre, PolInd


def _kernel(model):
    return model.step_kernel(model.initial_state(), varying_load=True)


@jit(cache=False)
def _taken_out(step_buffer):
    """The arrays as the runners take them out, each doubled in place, and their sums."""
    scalars, table, state, scratch = sb.model_arrays(step_buffer)
    sums = np.zeros(4)
    for i in range(scalars.shape[0]):
        sums[0] += scalars[i]
        scalars[i] *= 2.0
    for i in range(table.shape[0]):
        for j in range(table.shape[1]):
            sums[1] += table[i, j]
            table[i, j] *= 2.0
    for i in range(state.shape[0]):
        sums[2] += state[i]
        state[i] *= 2.0
    for i in range(scratch.shape[0]):
        sums[3] += scratch[i]
        scratch[i] *= 2.0
    return sums


@pytest.mark.parametrize("model", [LuGre.example(), PolInd.example()], ids=["lugre", "pol-ind"])
def test_the_views_and_the_arrays_numba_takes_out_are_the_same_memory(model):
    kernel = _kernel(model)
    buffer, views = sb.step_buffer(kernel.scalars, kernel.table, kernel.state, 7)
    scalars, table, state, scratch = views
    np.testing.assert_array_equal(scalars, kernel.scalars)
    np.testing.assert_array_equal(table, kernel.table)
    np.testing.assert_array_equal(state, kernel.state)
    assert scratch.shape == (7,) and not scratch.any()
    scratch[:] = np.arange(7.0)
    for view in views:
        assert view.base is buffer and view.flags.c_contiguous
    # Each array at the offset in its page that polind.models.kernel.page_placed gives it.
    for view, offset in zip(views, (3072, 0, 2048, 2048)):
        assert view.size == 0 or view.ctypes.data % 4096 == offset
    ends = sorted((view.ctypes.data, view.ctypes.data + view.nbytes) for view in views
                  if view.size)
    assert all(end <= start for (_, end), (start, _) in zip(ends, ends[1:]))   # no overlap
    assert ends[0][0] >= buffer.ctypes.data + 8 * sb.HEADER
    assert ends[-1][1] <= buffer.ctypes.data + buffer.nbytes
    originals = [view.copy() for view in views]
    sums = _taken_out(buffer)
    np.testing.assert_allclose(sums, [view.sum() for view in originals], rtol=1e-14)
    for view, original in zip(views, originals):
        np.testing.assert_array_equal(view, 2.0 * original)
    np.testing.assert_array_equal(sb.views_of(buffer)[1], table)


def test_a_copied_buffer_is_independent_and_keeps_the_header():
    kernel = _kernel(PolInd.example())
    buffer, views = sb.step_buffer(kernel.scalars, kernel.table, kernel.state, 5)
    views[3][:] = 1.5
    buffer[sb.TIME:sb.HEADER] = np.arange(sb.HEADER - sb.TIME)
    twin, twin_views = sb.copied(buffer)
    np.testing.assert_array_equal(twin[sb.TIME:sb.HEADER], buffer[sb.TIME:sb.HEADER])
    for view, other in zip(views, twin_views):
        np.testing.assert_array_equal(other, view)
        assert not np.shares_memory(other, buffer)
    twin_views[2][:] = -1.0
    assert not (views[2] == -1.0).any()
    assert twin_views[1].ctypes.data % 4096 == 0


def test_a_refused_sample_raises_and_leaves_the_buffer_as_it_was():
    from polind.stepper import Body, Stepper

    stepper = Stepper(LuGre.example())
    stepper.advance(1e-3, x=1e-6)
    before = stepper._buffer.copy()
    runner = stepper.kernel.runners.stepper_position
    for t, x in [(1e-3, 2e-6), (float("nan"), 2e-6), (2e-3, float("inf"))]:
        with pytest.raises(sb.RefusedSample):
            runner(stepper._buffer, t, x, 0.0)
        np.testing.assert_array_equal(stepper._buffer, before)
    body = Body(LuGre.example())
    before = body._buffer.copy()
    with pytest.raises(sb.RefusedSample):
        body._kernel.runners.body_buffer(body._buffer, 0.0, float("nan"))
    np.testing.assert_array_equal(body._buffer, before)
