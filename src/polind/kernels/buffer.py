"""One float64 buffer with all that a Stepper or a Body sample needs, for one cheap call.

A call from Python into numba unboxes each argument: an array costs some
20-50 ns (numba wraps it in a reference-counted record for the call), a float
about 20 ns, and a tuple of results about 45 ns to box (measured, one call
after another).  A body's step needs a dozen arrays and numbers (the model's
``scalars``, ``table``, ``state``, a scratch array, the mount, the clock, the
body's history, its mass, ...), a stepper's three arrays and five numbers.
Here they all live in one buffer: a header of numbers (``HEADER`` slots,
below) at its start, then the model's arrays, and the Python side's arrays
are views into it.  The
runners that take a buffer (``stepper_position``, ``stepper_velocity``,
``body_buffer`` of :mod:`polind.kernels.template`) cross the boundary with
one array and a few floats, and take the arrays out of it inside numba.

The arrays taken out (:func:`vector`, :func:`matrix`) are numba's C-contiguous
float64 arrays, the types the model's functions are compiled for, so the
same compiled code runs as when the arrays are passed one by one (the
results are the same to the bit).  They are views *without* a reference
count (as :func:`numba.carray` gives): the buffer itself, an argument of
the call, keeps the memory alive while the call runs, and the calls they
are passed to skip the atomic reference counting of every array argument
(measured in a numba loop: a LuGre body step 0.53 µs against 0.65 µs with
counted views of the same buffer).  They must not outlive the call:
no runner returns or stores one.

Each array starts at the offset within a 4096-byte page that
:func:`polind.models.kernel.page_placed` gives it (the table at 0, the state
and the scratch at 2048, the scalars at 3072), for the reasons given there.
"""

from __future__ import annotations

import math

import numpy as np
from numba import carray, types
from numba.extending import intrinsic

from polind.kernels import jit
from polind.kernels.dynamics import body_advance_with, clock_step
from polind.kernels.mount import N_MOUNT

# --- the header: slots of the buffer's first HEADER floats -------------------------------
# Where the model's arrays are (a start index into the buffer and a size).
SCALARS = 0
SCALARS_SIZE = 1
TABLE = 2
TABLE_ROWS = 3
TABLE_COLUMNS = 4
STATE = 5
STATE_SIZE = 6
SCRATCH = 7
SCRATCH_SIZE = 8
# A Stepper's current sample.
TIME = 9
POSITION = 10
VELOCITY = 11
FORCE = 12
# A Body's numbers (polind.kernels.dynamics.body_advance_with's arguments) ...
MEMORYLESS = 13        # 1.0 for a memoryless model
REST_CAPACITY = 14
FORCE_SCALE = 15
METHOD = 16            # polind.kernels.dynamics.BDF2 or EULER
MASS = 17
LAST_LOAD = 18         # the normal load the model was last brought to [N]
# ... and its arrays: [t_0, n, h], [x_n, v_n, v_{n-1}, w_n, history, friction], the mount.
CLOCK = 19
CLOCK_SIZE = 3
BODY = CLOCK + CLOCK_SIZE
BODY_SIZE = 6
MOUNT = BODY + BODY_SIZE
HEADER = MOUNT + N_MOUNT

#: Page offsets [bytes] of the arrays (polind.models.kernel.page_placed's).
_TABLE_OFFSET, _STATE_OFFSET, _SCALARS_OFFSET = 0, 2048, 3072
_PAGE = 512    # floats in a 4096-byte page


class RefusedSample(Exception):
    """A sample the compiled step of a Stepper or a Body refuses, changing nothing.

    Raised instead of computing it (a time not after the current one, a
    non-finite motion or applied force, a time step lost in the absolute
    time); the Python side catches it and raises the
    :class:`polind.InputError` that names what was wrong.  An exception
    costs nothing on a sample that is taken, where checking a returned NaN
    in Python would.
    """


@intrinsic
def _address(typingctx, array, index):
    """A pointer to ``array[index]`` (no bounds check)."""
    signature = types.CPointer(array.dtype)(array, index)

    def codegen(context, builder, signature, arguments):
        values = context.make_array(signature.args[0])(context, builder, arguments[0])
        return builder.gep(values.data, [arguments[1]])

    return signature, codegen


@jit(inline="always")
def vector(buffer, start, size):
    """``buffer[start:start + size]`` as a view without a reference count (the module notes)."""
    return carray(_address(buffer, start), size)


@jit(inline="always")
def matrix(buffer, start, rows, columns):
    """``buffer[start:start + rows * columns]`` as a C-ordered (rows, columns) view, likewise."""
    return carray(_address(buffer, start), (rows, columns))


@jit(inline="always")
def model_arrays(buffer):
    """The model's ``(scalars, table, state, scratch)`` in ``buffer``."""
    scalars = vector(buffer, int(buffer[SCALARS]), int(buffer[SCALARS_SIZE]))
    table = matrix(buffer, int(buffer[TABLE]), int(buffer[TABLE_ROWS]),
                   int(buffer[TABLE_COLUMNS]))
    state = vector(buffer, int(buffer[STATE]), int(buffer[STATE_SIZE]))
    scratch = vector(buffer, int(buffer[SCRATCH]), int(buffer[SCRATCH_SIZE]))
    return scalars, table, state, scratch


@jit(inline="always")
def stepper_sample(step_function, buffer, t, motion, by_velocity, normal_load):
    """One sample of :class:`polind.Stepper` from its buffer: the force at ``t`` [N].

    ``motion`` is the position at ``t`` (linear path from the current
    sample) or, ``by_velocity``, the velocity there (trapezoidal position):
    :meth:`polind.Stepper.advance`'s rules, with its arithmetic, so a runner
    inlining this is compiled without fast-math (IEEE operations in the
    order written, as Python computes them).  The current sample is the
    header's ``TIME`` .. ``FORCE``; ``step_function`` is the model's step.
    A time not after the current one, or a motion without a finite step
    velocity or position, raises :class:`RefusedSample` and changes nothing.
    """
    position = buffer[POSITION]
    step = t - buffer[TIME]
    if not 0.0 < step < math.inf:
        raise RefusedSample
    if by_velocity:
        step_velocity = 0.5 * (buffer[VELOCITY] + motion)
        displacement = step_velocity * step
        new_position = position + displacement
        if new_position - new_position != 0.0:         # inf or nan
            raise RefusedSample
        sample_velocity = motion
    else:
        displacement = motion - position
        step_velocity = displacement / step
        if step_velocity - step_velocity != 0.0:       # inf or nan
            raise RefusedSample
        sample_velocity = step_velocity
        new_position = motion
    scalars, table, state, _ = model_arrays(buffer)
    force = step_function(scalars, table, state, step, displacement, step_velocity,
                          sample_velocity, normal_load)
    buffer[TIME] = t
    buffer[POSITION] = new_position
    buffer[VELOCITY] = sample_velocity
    buffer[FORCE] = force
    return force


@jit(inline="always")
def body_sample(stepper, force_function, buffer, normal_load, applied_force):
    """One step of :class:`polind.Body` from its buffer: ``(x, v, F)`` at its end.

    :func:`polind.kernels.dynamics.body_advance_with` of ``stepper`` (a
    runner's ``body_step`` or ``mounted_body_step``) on the arrays and
    numbers of the buffer.  A load other than the one the model was last
    brought to (the header's ``LAST_LOAD``) brings it there first, on its
    real state, with the model's ``force_function``, as ``Body.step`` did
    from Python.  A non-finite ``applied_force`` or a lost step
    (:func:`polind.kernels.dynamics.clock_step`) raises
    :class:`RefusedSample` and changes nothing.
    """
    clock = vector(buffer, CLOCK, CLOCK_SIZE)
    step = clock_step(clock)
    if step != step or not -math.inf < applied_force < math.inf:
        raise RefusedSample
    scalars, table, state, scratch = model_arrays(buffer)
    body = vector(buffer, BODY, BODY_SIZE)
    if normal_load != buffer[LAST_LOAD]:
        force_function(scalars, table, state, body[1], normal_load)
        buffer[LAST_LOAD] = normal_load
    return body_advance_with(stepper, buffer[MEMORYLESS] != 0.0, buffer[REST_CAPACITY],
                             buffer[FORCE_SCALE], vector(buffer, MOUNT, N_MOUNT), scalars,
                             table, state, scratch, int(buffer[METHOD]), buffer[MASS], clock,
                             body, normal_load, applied_force)


# --- the Python side ---------------------------------------------------------------------

#: NumPy's real scalar types: numba takes ``float()`` of one for a runner's float argument
#: (``PyNumber_Float``), the number polind.validation.check_number takes, so
#: :class:`polind.Stepper` and :class:`polind.Body` pass one as it is.
NUMPY_REALS = frozenset(kind for kind in np.sctypeDict.values()
                        if issubclass(kind, (np.integer, np.floating))
                        and not issubclass(kind, np.timedelta64))


def _placed(cursor, base, offset):
    """The first index at or after ``cursor`` whose address lies ``offset`` bytes into a page."""
    within = (base + offset // 8) % _PAGE
    return cursor + (within - cursor) % _PAGE


def step_buffer(scalars, table, state, scratch_size):
    """A buffer holding ``scalars``, ``table``, ``state`` and a scratch array (zeros).

    Returns ``(buffer, (scalars, table, state, scratch))``: the buffer, its
    header's array slots filled (the other slots 0), and the four arrays as
    views into it, with the values given.
    """
    table = np.atleast_2d(table)
    parts = ((table.size, _TABLE_OFFSET), (state.size, _STATE_OFFSET),
             (scalars.size, _SCALARS_OFFSET), (scratch_size, _STATE_OFFSET))
    size = HEADER + sum(part for part, _ in parts) + (len(parts) + 1) * _PAGE
    buffer = np.zeros(size)
    base = (-(buffer.ctypes.data // 8)) % _PAGE     # the index where a page starts
    cursor = HEADER
    starts = []
    for part, offset in parts:
        start = _placed(cursor, base, offset)
        starts.append(start)
        cursor = start + part
    table_start, state_start, scalars_start, scratch_start = starts
    buffer[[SCALARS, SCALARS_SIZE, TABLE, TABLE_ROWS, TABLE_COLUMNS, STATE, STATE_SIZE,
            SCRATCH, SCRATCH_SIZE]] = (scalars_start, scalars.size, table_start,
                                       table.shape[0], table.shape[1], state_start,
                                       state.size, scratch_start, scratch_size)
    views = (buffer[scalars_start:scalars_start + scalars.size],
             buffer[table_start:table_start + table.size].reshape(table.shape),
             buffer[state_start:state_start + state.size],
             buffer[scratch_start:scratch_start + scratch_size])
    views[0][:] = scalars
    views[1][...] = table
    views[2][:] = state
    return buffer, views


def copied(buffer):
    """A copy of a step buffer (its arrays placed anew) and its views, as :func:`step_buffer`."""
    scalars, table, state, scratch = views_of(buffer)
    twin, views = step_buffer(scalars, table, state, scratch.size)
    views[3][:] = scratch
    twin[TIME:HEADER] = buffer[TIME:HEADER]
    return twin, views


def views_of(buffer):
    """The ``(scalars, table, state, scratch)`` views of a step buffer (from its header)."""
    def at(start, size):
        start = int(buffer[start])
        return buffer[start:start + int(buffer[size])]

    rows, columns = int(buffer[TABLE_ROWS]), int(buffer[TABLE_COLUMNS])
    table_start = int(buffer[TABLE])
    return (at(SCALARS, SCALARS_SIZE),
            buffer[table_start:table_start + rows * columns].reshape(rows, columns),
            at(STATE, STATE_SIZE), at(SCRATCH, SCRATCH_SIZE))


_ENTRIES = {}


def buffer_entry(function, floats):
    """The compiled wrapper of a runner ``function(buffer, *floats)`` (one per process).

    ``polind.kernels.compiled_entry`` for the types every caller
    passes (a C-contiguous float64 buffer and ``floats`` floats), looked up
    once: a Stepper or a Body built afterwards pays nothing for it.
    """
    from polind.kernels import compiled_entry

    key = (function, floats)
    entry = _ENTRIES.get(key)
    if entry is None:
        entry = compiled_entry(function, np.zeros(HEADER), *([0.0] * floats))
        _ENTRIES[key] = entry
    return entry
