"""The element models' read-only trial (polind.kernels.contract.no_trial).

The implicit solvers (the body's and the series spring's) ask a model's
``trial`` for the force of a step and its derivative in the step velocity
without writing its state; it must give what the step on a copy of the
state gives (to rounding: the sums may run in another order), a derivative
that is the model's tangent there where the Stribeck curve is flat (at rest,
sliding fast) and the slope of the step's force everywhere, leave every array as it
was (but for a cache the step keeps too: Pol-Ind's decay factors,
``polind.kernels.pol_ind.decay_row``), and decline (``written`` -1) where
Pol-Ind's table is at another load.
Asked to keep its state (``keep``), it writes the state the step leaves into
its ``out`` array: the leading ``written`` entries, bit for bit the step's
(the series spring takes that state instead of stepping again).
"""

from __future__ import annotations

import numpy as np
import pytest

from polind.kernels import generate
from polind.models import GMS, MaxwellSlip, PolInd

STEP = 1e-3
# Step velocities [m/s]: at rest, creeping, sliding both ways.
VELOCITIES = [0.0, 1e-7, -3e-6, 2e-4, -5e-3, 0.3]


def _kernel(model):
    """The model's kernel after a back-and-forth motion (stuck and slipping elements)."""
    kernel = model.step_kernel(model.initial_state())
    scalars, table, state = kernel.scalars, kernel.table, kernel.state
    for k in range(400):
        velocity = 2e-3 * np.sin(2.0 * np.pi * k / 150.0)
        kernel.step(scalars, table, state, STEP, velocity * STEP, velocity, velocity,
                    kernel.normal_load)
    return kernel


def _lasting(model, scalars, table):
    """``scalars`` and ``table`` without the entries a step may use as a cache.

    Pol-Ind keeps its last decay factors in work rows and slots of its
    arrays (``polind.kernels.pol_ind.decay_row``), which its trial fills
    as its step does.
    """
    if not isinstance(model, PolInd):
        return scalars, table
    from polind.kernels import pol_ind

    kept_slots = np.arange(pol_ind.DECAY_KEYS, pol_ind.DECAY_NEWEST + 1)
    kept_rows = np.arange(pol_ind.DECAY, pol_ind.DECAY_INVERSE + 1)
    return np.delete(scalars, kept_slots), np.delete(table, kept_rows, axis=0)


def _step_slope(kernel, velocity, sample_velocity):
    """``dF/dw`` of the step's force by central differences (the rate term held)."""
    def force(w):
        return kernel.step(kernel.scalars.copy(), kernel.table.copy(), kernel.state.copy(), STEP,
                           w * STEP, w, sample_velocity, kernel.normal_load)
    change = 1e-7 * abs(velocity)
    return (force(velocity + change) - force(velocity - change)) / (2.0 * change)


def _trial_of(kernel):
    module, names = generate.MODELS[kernel.runners.__name__.rsplit(".", 1)[1]]
    return getattr(__import__(module, fromlist=["_"]), names["trial"])


@pytest.mark.parametrize("keep", [False, True])
@pytest.mark.parametrize("velocity", VELOCITIES)
@pytest.mark.parametrize("model", [MaxwellSlip.example(elements=40), GMS.example(elements=40),
                                   PolInd.example()], ids=["maxwell-slip", "gms", "pol-ind"])
def test_the_trial_is_the_step_on_a_copy_and_writes_only_out(model, velocity, keep):
    kernel = _kernel(model)
    trial = _trial_of(kernel)
    arrays = (kernel.scalars, kernel.table, kernel.state)
    before = [*_lasting(model, kernel.scalars.copy(), kernel.table.copy()), kernel.state.copy()]
    # `out` is the caller's scratch: the trial may write one state's worth of it, keep or
    # not, and nothing beyond (it is taken only as far as `written` says).
    out = np.full(kernel.state.shape[0] + 8, np.nan)
    sample_velocity = 1.5 * velocity - 1e-4
    force, tangent, written = trial(*arrays, out, keep, STEP, velocity * STEP, velocity,
                                    sample_velocity, kernel.normal_load)
    assert written >= 0 and (keep or written == 0)
    after = [*_lasting(model, kernel.scalars, kernel.table), kernel.state]
    for array, copy in zip(after, before):
        np.testing.assert_array_equal(array, copy)
    assert np.isnan(out[kernel.state.shape[0]:]).all()
    work = kernel.state.copy()
    expected = kernel.step(kernel.scalars, kernel.table, work, STEP, velocity * STEP, velocity,
                           sample_velocity, kernel.normal_load)
    expected_tangent = kernel.tangent(kernel.scalars, kernel.table, work, STEP)
    scale = np.sum(np.abs(kernel.state[:kernel.table.shape[1]])) + 1.0
    assert abs(force - expected) <= 1e-13 * scale
    if velocity == 0.0 or abs(velocity) >= 0.3:
        assert tangent == pytest.approx(expected_tangent, rel=1e-13, abs=1e-300)
    else:
        # Below a few Stribeck velocities g(w) moves the slipping elements too.
        slope = _step_slope(kernel, velocity, sample_velocity)
        assert tangent - kernel.scalars[0] == pytest.approx(slope, rel=1e-3, abs=1e-5)
    np.testing.assert_array_equal(np.where(np.arange(work.shape[0]) < written,
                                           out[:work.shape[0]], work), work)
    assert written > 0 or velocity == 0.0 or not keep


def test_pol_ind_declines_a_trial_at_another_load_and_changes_nothing():
    kernel = _kernel(PolInd.example())
    trial = _trial_of(kernel)
    arrays = (kernel.scalars, kernel.table, kernel.state)
    before = [array.copy() for array in arrays]
    out = np.zeros(kernel.state.shape[0])
    force, tangent, written = trial(*arrays, out, True, STEP, 1e-6, 1e-3, 1e-3,
                                    0.9 * kernel.normal_load)
    assert written == -1 and not out.any()
    for array, copy in zip(arrays, before):
        np.testing.assert_array_equal(array, copy)


def test_pol_ind_brings_stale_weights_up_to_date_as_its_step_would():
    # A moving step at a new load leaves the weight rows stale (pol_ind.TABLE_STALE);
    # the trial at that load must use the weights the step would use.
    from polind.kernels import pol_ind

    kernel = _kernel(PolInd.example())
    scalars, table, state = kernel.scalars, kernel.table, kernel.state
    load = 1.1 * kernel.normal_load
    pol_ind.pol_ind_step(scalars, table, state, STEP, 1e-6, 1e-3, 1e-3, load)
    assert scalars[pol_ind.TABLE_STALE] == 1.0
    copies = scalars.copy(), table.copy(), state.copy()
    expected = pol_ind.settled_step(*copies, STEP, 2e-6, 2e-3, 2e-3, load)
    # `out` is scratch the trial may write (one state), kept or not.
    force, _, written = pol_ind.pol_ind_trial_step(scalars, table, state,
                                                   np.zeros(state.shape[0]), False,
                                                   STEP, 2e-6, 2e-3, 2e-3, load)
    assert written == 0 and scalars[pol_ind.TABLE_STALE] == 0.0
    assert abs(force - expected) <= 1e-13 * (abs(expected) + 1.0)
    np.testing.assert_array_equal(table, copies[1])
