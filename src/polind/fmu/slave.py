"""The FMU's slave class: a polind model behind the FMI 2.0 co-simulation interface.

:func:`polind.fmu.build_fmu` puts a two-line script into the FMU whose class
subclasses :class:`FrictionSlave`; PythonFMU's binary runs it inside the
Python where the FMU is simulated, which must have polind (and PythonFMU)
installed.  The model and the settings are the FMU's resource
``polind_fmu.json`` (:data:`CONFIG`).

Two kinds (the user guide, :ref:`guide-fmu`):

``"x"`` (:class:`polind.Stepper`)
    Input ``x`` [m], output ``F`` [N].  At each communication point ``t_k``
    the output is the force that ``Stepper.advance(t_k, x=x_k)`` returns for
    the ``x_k`` set at that point (direct feedthrough: set ``x``, then read
    ``F``); at the start time, the force of a ``Stepper`` started at
    ``x_0``.  ``doStep`` takes the step to the current point if ``F`` was
    not read, and moves on.
``"force"`` (:class:`polind.Body`)
    Input ``force`` [N], outputs ``x`` [m], ``v`` [m/s] and ``F`` [N]; fixed
    parameters ``mass`` [kg] and ``time_step`` [s].  ``doStep`` holds the
    force over the communication step, ``n`` Body steps of ``time_step``
    (the communication step must be a whole multiple of it); the outputs are
    the body after them.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

__all__ = ["FrictionSlave", "CONFIG", "KINDS"]

#: The FMU resource with the model and the settings.
CONFIG = "polind_fmu.json"

#: The FMU kinds, by input.
KINDS = ("x", "force")


class FrictionSlave(Fmi2Slave):
    """A polind model as an FMI 2.0 co-simulation slave (the module notes)."""

    author = "polind"
    description = "A polind friction model (needs a Python with polind where it runs)."

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        from polind.models import model_from_dict

        config = json.loads((Path(self.resources) / CONFIG).read_text(encoding="utf-8"))
        self.model = model_from_dict(config["model"])
        self.kind = config["input"]
        self.mass = float(config["mass"])
        self.time_step = float(config["time_step"])
        self.time = 0.0
        self.stepper = None
        self.previous = None
        self.body = None
        self.x = 0.0
        self.force = 0.0
        self.friction = 0.0
        self.settled = False
        output = dict(causality=Fmi2Causality.output)
        if self.kind == "x":
            self.register_variable(Real("x", causality=Fmi2Causality.input, start=0.0,
                                        description="position [m]", setter=self._set_x))
            self.register_variable(Real("F", description="friction force [N]",
                                        getter=self._stepper_force, **output))
        else:
            fixed = dict(causality=Fmi2Causality.parameter,
                         variability=Fmi2Variability.fixed)
            self.register_variable(Real("mass", start=self.mass, description="mass [kg]",
                                        setter=lambda value: self._set("mass", value),
                                        **fixed))
            self.register_variable(Real("time_step", start=self.time_step,
                                        description="the Body's time step [s]",
                                        setter=lambda value: self._set("time_step", value),
                                        **fixed))
            self.register_variable(Real("force", causality=Fmi2Causality.input, start=0.0,
                                        description="applied force [N], held over a step"))
            self.register_variable(Real("x", description="position [m]",
                                        getter=lambda: self._body().position, **output))
            self.register_variable(Real("v", description="velocity [m/s]",
                                        getter=lambda: self._body().velocity, **output))
            self.register_variable(Real("F", description="friction force [N]",
                                        getter=lambda: self._body().friction, **output))

    # --- FMI -------------------------------------------------------------------------------

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self.time = float(start_time)

    def do_step(self, current_time, step_size):
        try:
            if self.kind == "x":
                self.time = float(current_time)
                self._settle()
                self.settled = False
            else:
                self._advance_body(float(step_size))
            self.time = float(current_time) + float(step_size)
            return True
        except Exception as error:  # noqa: BLE001 - reported to the master, not raised
            self.log(f"polind: {type(error).__name__}: {error}", Fmi2Status.error)
            return False

    # --- input x: a Stepper ----------------------------------------------------------------

    def _set_x(self, value):
        value = float(value)
        if value != self.x or self.stepper is None:
            self.settled = False
        self.x = value

    def _stepper_force(self):
        self._settle()
        return self.force

    def _settle(self):
        """The force at the current point for the ``x`` set there (once per point and ``x``)."""
        if self.settled:
            return
        from polind.stepper import Stepper

        if self.stepper is not None and self.stepper.time == self.time:
            # x was set again at a point already taken: take it again from the point before.
            self.stepper = None if self.previous is None else \
                Stepper(self.model, state=self.previous)
        if self.stepper is None:
            self.stepper = Stepper(self.model, time=self.time, position=self.x)
            self.force = self.stepper.force
        else:
            self.previous = self.stepper.state
            self.force = self.stepper.advance(self.time, x=self.x)
        self.settled = True

    # --- input force: a Body -----------------------------------------------------------------

    def _set(self, name, value):
        # A parameter set before the run starts: the Body is built with it.
        setattr(self, name, float(value))
        self.body = None

    def _body(self):
        if self.body is None:
            from polind.stepper import Body

            self.body = Body(self.model, mass=self.mass, time_step=self.time_step)
        return self.body

    def _advance_body(self, step_size):
        steps = round(step_size / self.time_step)
        if steps < 1 or abs(steps * self.time_step - step_size) > 1e-9 * step_size:
            raise ValueError(f"the communication step {step_size!r} s is not a whole multiple "
                             f"of the FMU's time_step {self.time_step!r} s")
        body = self._body()
        applied = float(self.force)
        if not math.isfinite(applied):
            raise ValueError(f"the input 'force' must be finite, got {applied!r}")
        for _ in range(steps):
            body.step(applied)
