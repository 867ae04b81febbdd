"""polind's models and bodies as python-control systems (:ref:`guide-python-control`).

* :func:`friction_system`: a friction model alone, input the motion
  (``"x"`` or ``"v"``), output the friction force; its response equals
  :func:`polind.simulate`'s (``polind.control.friction``).
* :func:`body_system`: a mass and its contact as one system, input the
  applied force, outputs ``x``, ``v``, ``F``, stepped by the implicit step
  of :class:`polind.Body`; a loop closed around it equals the same loop
  around a ``Body`` (``polind.control.body``).
* :func:`linearize`: the stuck body's small-signal two-state model, from
  the contact's presliding stiffness and damping
  (``polind.control.linear``).

python-control is an optional dependency: ``pip install polind[control]``.
``import polind`` never imports this package.
"""

from __future__ import annotations

try:
    import control  # noqa: F401  (python-control: the optional extra)
except ImportError as error:    # the optional extra is not installed
    raise ImportError("polind.control needs python-control: "
                      "pip install polind[control]") from error

from polind.control.body import BODY_STATES, body_state_names, body_system
from polind.control.friction import (CARRIED_STATES, MOUNT_STATES, friction_system,
                                     initial_state, state_names)
from polind.control.linear import contact_stiffness, linearize

__all__ = ["friction_system", "initial_state", "state_names", "body_system",
           "body_state_names", "linearize", "contact_stiffness", "CARRIED_STATES",
           "MOUNT_STATES", "BODY_STATES"]
