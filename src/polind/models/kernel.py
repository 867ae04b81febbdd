"""A model as compiled code steps it: its numba functions and its flat arrays.

:class:`StepFunctions` is what a model supplies; :class:`StepKernel` is the
model made ready for a run (:meth:`polind.FrictionModel.step_kernel`), with
the run loops of ``polind.kernels`` it dispatches to.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StepFunctions:
    """A model's numba functions of the stepping contract (:mod:`polind.kernels.contract`).

    ``step``, ``force`` and ``tangent`` are ``@njit`` functions with the
    signatures documented there.  Every loop that runs them (a path, a
    motion, a body, each behind a series spring) is a *runner* of the one
    template :mod:`polind.kernels.template`.  polind's own models name
    their runner module in ``runners`` (generated under
    ``polind.kernels.generated``, kept in numba's on-disk cache); a model
    of your own leaves it None and gets the template compiled for its
    functions once per process.
    """

    step: object
    force: object
    tangent: object
    runners: str | None = None

    def runner_module(self):
        """The runners of these functions (:func:`polind.kernels.generate.runners_for`)."""
        from polind.kernels.generate import runners_for
        return runners_for(self.step, self.force, self.tangent, self.runners)


#: Where a kernel's arrays start within a 4096-byte page (:func:`page_placed`): the
#: table (read in the element loops), the state (written there) half a page away,
#: the scalars (written per sample by a varying load) between.
TABLE_OFFSET, STATE_OFFSET, SCALARS_OFFSET = 0, 2048, 3072


def page_placed(values, offset=0):
    """A C-contiguous float64 copy of ``values`` starting ``offset`` bytes into a 4096-byte page.

    Two things about where an array starts cost an element loop time, both
    measured on the 1024-element Maxwell-slip benchmark.  An array that
    straddles cache lines at a varying offset (NumPy aligns to 16 bytes) ran
    up to 1.5 times slower.  A load whose address agrees with that of an
    earlier store in its low 12 bits waits for it (4K aliasing): with the
    element forces 64 bytes past the element table within a page,
    ``simulate`` took 47 ms instead of 25-27 ms.  Placing each array at a
    fixed ``offset`` (a multiple of 64) within a page settles both, so a
    kernel's arrays are placed with :data:`TABLE_OFFSET`,
    :data:`STATE_OFFSET` and :data:`SCALARS_OFFSET`.
    """
    values = np.asarray(values, dtype=np.float64)
    buffer = np.empty(values.size + 1024)
    start = (-(buffer.ctypes.data // 8)) % 512 + offset // 8
    placed = buffer[start:start + values.size].reshape(values.shape)
    placed[...] = values
    return placed


@dataclass
class StepKernel:
    """A model ready to be stepped by compiled code: its functions and flat arrays.

    The three arrays are what the model's numba functions take: ``scalars``
    (float64, 1-D), ``table`` (float64, 2-D, one column per element) and
    ``state`` (float64, 1-D, advanced in place).  From a user's own
    ``@njit`` loop::

        kernel = model.step_kernel()
        force = kernel.step(kernel.scalars, kernel.table, kernel.state,
                            h, dx, dx / h, dx / h, kernel.normal_load)

    Attributes
    ----------
    step, force, tangent : numba functions
        See :mod:`polind.kernels.contract`.
    runners : module
        The model's runners (:mod:`polind.kernels.template`): ``path``,
        ``motion_samples`` (and the model's ``model_blocks`` and
        ``model_block``), ``integrate``, ``body``, ``body_step`` and the
        ``mounted_`` ones.
    scalars, table, state : ndarray
        The model's parameters and its state, laid out for its functions.
    normal_load : float
        The model's own constant normal load [N] (0 for models without one).
    force_scale : float
        A typical friction force [N] (the solvers' tolerances scale with it).
    rest_capacity : float or None
        For a memoryless model, the largest force it holds at rest (``g(0)``,
        its friction is set-valued there); None for models with state (and
        for a memoryless contact behind a series spring: the spring is state).
    mount : ndarray or None
        What sits around the contact (:mod:`polind.kernels.mount`): a series
        spring, a normal-load scaling; None when nothing does.  A mounted
        model runs through :mod:`polind.kernels.series`, and ``step`` is then
        the bare contact's.
    """

    step: object
    force: object
    tangent: object
    runners: object
    scalars: np.ndarray
    table: np.ndarray
    state: np.ndarray
    normal_load: float
    force_scale: float
    rest_capacity: float | None
    mount: np.ndarray | None = None

    def __post_init__(self):
        # A trial's state and, behind a series spring, the spring's own solve.
        self.scratch = np.empty(2 * self.state.shape[0])

    def first_force(self, sample_velocity, normal_load=None):
        """The force at the state without moving (the first sample of a run) [N].

        Behind a series spring it is the spring's force (0 at rest); else the
        model's ``force`` at ``sample_velocity``, scaled by the load.
        """
        from polind.kernels.mount import first_force

        load = self.normal_load if normal_load is None else normal_load
        return first_force(self.force, self.mount, self.scalars, self.table, self.state,
                           sample_velocity, load)

    def run(self, step, displacement, step_velocity, sample_velocity, loads, lo, hi, first,
            out_force):
        """Run the path arrays (indexed by the sample a step ends at) over ``lo .. hi - 1``.

        With ``first``, sample ``lo`` starts the run: its force is
        :meth:`first_force`'s, in Python, and the compiled path takes the
        samples after it (as it does after a chunk that continues a run).
        """
        from polind.kernels.contract import sample_load

        loads = NO_LOADS if loads is None else loads
        if first:
            out_force[lo] = self.first_force(sample_velocity[lo],
                                             sample_load.py_func(loads, self.normal_load, lo))
        if self.mount is not None:
            self.runners.mounted_path(self.mount, self.scalars, self.table, self.state,
                                      self.scratch, step, displacement, step_velocity,
                                      sample_velocity, loads, self.normal_load, lo, hi,
                                      out_force)
        else:
            self.runners.path(self.scalars, self.table, self.state, step, displacement,
                              step_velocity, sample_velocity, loads, self.normal_load, lo, hi,
                              out_force)

    def run_motion(self, source_t, source_motion, t, motion, by_velocity, start_position,
                   start_velocity, continuing, position, velocity, loads, lo, hi, first,
                   out_force):
        """The loop of :func:`polind.simulate` over samples ``lo .. hi - 1``: ``(code, index)``.

        Copies ``source_t`` and ``source_motion`` into ``t`` and ``motion`` (they
        may be the same arrays) as it checks and runs them.  With ``first``,
        sample ``lo`` starts the run
        (:func:`polind.kernels.contract.first_motion_sample`); the runners'
        ``model_block`` takes the rest where the model has blocks and they take
        the motion (``model_blocks``), and their ``motion_samples`` where not,
        or from the last good sample before a block that met a bad one.  Not
        for a mounted model (a series spring or a load scaling), which runs
        from step arrays (:meth:`run`).
        """
        from polind.kernels.contract import VALID, first_motion_sample

        loads = NO_LOADS if loads is None else loads
        if first:
            code, index = first_motion_sample(self.force, self.scalars, self.table, self.state,
                                              source_t, source_motion, t, motion, by_velocity,
                                              start_position, start_velocity, continuing,
                                              position, velocity, loads, self.normal_load, lo,
                                              hi, out_force)
            if code != VALID:
                return code, index
        runners = self.runners
        if runners.model_blocks(self.scalars, by_velocity):
            stop = runners.model_block(self.scalars, self.table, self.state, source_t,
                                       source_motion, t, motion, velocity, out_force, lo + 1, hi)
            if stop == hi:
                return VALID, -1
            lo = -stop - 1          # the last good sample, before the bad block
        return runners.motion_samples(self.scalars, self.table, self.state, source_t,
                                      source_motion, t, motion, by_velocity, position, velocity,
                                      loads, self.normal_load, lo, hi, out_force)

    def integrate_system(self, *args):
        """The runners' ``integrate`` (``polind.kernels.dynamics.integrate_system_with``).

        ``args`` are its arguments without the final ``mount`` (added here).
        """
        if self.mount is not None:
            self.runners.mounted_integrate(args + (self.mount,))
        else:
            self.runners.integrate(args + (RIGID,))

    def advance_body(self, *args):
        """The runners' ``body`` (``polind.kernels.dynamics.advance_body_with``).

        ``args`` are its arguments without the final ``mount`` (added here);
        its ``scratch`` is the kernel's ``scratch`` array.
        """
        if self.mount is not None:
            self.runners.mounted_body(args + (self.mount,))
        else:
            self.runners.body(args + (RIGID,))


NO_LOADS = np.zeros(0)
# The mount of a model with nothing around its contact (polind.kernels.mount slots:
# an infinitely stiff spring, no reference load).
RIGID = np.array([math.inf] + [0.0] * 8)
