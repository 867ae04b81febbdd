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

An error inside the FMU (a non-finite input, a communication step that is not
a whole multiple of ``time_step``, a model that refuses a step) is never a
silent early end: the slave logs one message with status ``fmi2Error`` that
names the input, its value and the communication step, then raises.
PythonFMU's binary has no other way to fail a call: a ``False`` from
``do_step`` becomes ``fmi2Discard`` with ``fmi2Terminated`` set, which a
master (FMPy's ``simulate_fmu``) takes for a normal end, while an exception
makes the call return ``fmi2Fatal`` (PythonFMU 0.7.0; it forwards the log
messages only to a master that turned debug logging on).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from polind.errors import InputError

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
        time, step = float(current_time), float(step_size)
        try:
            if self.kind == "x":
                self.time = time
                self._settle()
                self.settled = False
            else:
                self._advance_body(step)
        except Exception as error:  # noqa: BLE001 - reported to the master (module notes)
            self._fail(f"{_what(error)}, in the communication step from t = {time!r} s "
                       f"of {step!r} s.")
        self.time = time + step
        return True

    def _fail(self, message):
        """Log ``message`` to the master with status fmi2Error, then raise it (module notes)."""
        message = "polind: " + " ".join(message.split())
        self.log(message, Fmi2Status.error)
        raise InputError(message) from None

    # --- input x: a Stepper ----------------------------------------------------------------

    def _set_x(self, value):
        value = float(value)
        if not math.isfinite(value):
            self._fail(f"The input 'x' of the FMU must be a finite position [m]. Got {value!r} "
                       f"instead, at the communication point t = {self.time!r} s.")
        if value != self.x or self.stepper is None:
            self.settled = False
        self.x = value

    def _stepper_force(self):
        try:
            self._settle()
        except Exception as error:  # noqa: BLE001 - reported to the master (module notes)
            self._fail(f"{_what(error)}, for the output 'F' at the communication point "
                       f"t = {self.time!r} s.")
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
        value = float(value)
        if not 0.0 < value < math.inf:
            self._fail(f"The parameter '{name}' of the FMU must be a positive finite number. "
                       f"Got {value!r} instead.")
        setattr(self, name, value)
        self.body = None

    def _body(self):
        if self.body is None:
            from polind.stepper import Body

            self.body = Body(self.model, mass=self.mass, time_step=self.time_step)
        return self.body

    def _advance_body(self, step_size):
        steps = round(step_size / self.time_step) if math.isfinite(step_size) else 0
        if steps < 1 or abs(steps * self.time_step - step_size) > 1e-9 * step_size:
            raise InputError(f"The communication step of the FMU must be a whole multiple of "
                             f"its time_step {self.time_step!r} s. Got {step_size!r} s instead")
        applied = float(self.force)
        if not math.isfinite(applied):
            raise InputError(f"The input 'force' of the FMU must be a finite force [N]. Got "
                             f"{applied!r} instead")
        body = self._body()
        for _ in range(steps):
            body.step(applied)


def _what(error) -> str:
    """An error's message without its final full stop (an unexpected one with its type)."""
    text = str(error) if isinstance(error, InputError) else f"{type(error).__name__}: {error}"
    return text.rstrip(".")
