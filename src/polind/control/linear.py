"""The stuck body's small-signal model: :func:`linearize`, :func:`contact_stiffness`.

The user guide, :ref:`guide-linearize`.

A body held by presliding friction is, for small motions, a mass on the
contact's spring and damper: ``m x'' = u - k x - c x'`` with ``k`` the
stiffness of the elements that stick and ``c`` the rate terms of the force
(a viscous ``sigma2``, LuGre's bristle damping ``sigma1``).  polind asks the
model for both through its stepping contract
(:mod:`polind.kernels.contract`): over a step of length ``h`` the force's
derivative with respect to the step velocity is its ``tangent``,
``dF/dw = k h + c``, so ``c`` is the tangent at ``h = 0`` and ``k`` its
slope in ``h``.  Nothing here knows which model it runs.
"""

from __future__ import annotations

import math

import numpy as np
import control as _ct   # python-control; polind.control says how to install it

from polind.errors import InputError
from polind.stepper import check_model, start_state
from polind.validation import check_number

__all__ = ["linearize", "contact_stiffness"]


def contact_stiffness(model, state=None) -> tuple:
    """``(k, c)``: the contact's presliding stiffness [N/m] and damping [N s/m] at a state.

    Parameters
    ----------
    model : FrictionModel
        Any polind model with presliding (a model of elements or bristles;
        a memoryless model holds a stuck body rigidly and has none, unless
        a series spring sits in front of it).
    state : State, optional
        The model's state (a result's ``final_state``); default: at rest.

    Returns
    -------
    tuple of float
        ``k`` [N/m]: the summed stiffness of what sticks at ``state``
        (elements in stick, LuGre's bristles); ``c`` [N s/m]: the force's
        rate terms.  Behind a series spring ``k_s`` (``[model.compliance]``)
        the two in series: ``k k_s / (k + k_s)``, and ``c (k_s / (k +
        k_s))^2``, the damper seen through the spring at low frequency.

    Notes
    -----
    From the model's ``tangent`` (the stepping contract,
    :ref:`guide-own-models`): ``tangent(h) = k h + c`` over a step of
    length ``h``.  A tangent that is not of that form (its second
    difference over ``h = 0, 1, 2`` s above 1e-9 of its size) is an
    :class:`~polind.InputError`.

    Examples
    --------
    >>> import polind
    >>> from polind.control import contact_stiffness
    >>> model = polind.model_from_dict({"model": {"type": "lugre",
    ...     "bristle_stiffness": 1e5, "bristle_damping": 300.0, "viscous_coefficient": 0.4,
    ...     "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3}})
    >>> k, c = contact_stiffness(model)       # sigma0 and sigma1 + sigma2
    >>> round(k, 6), round(c, 6)
    (100000.0, 300.4)
    """
    check_model(model, "contact_stiffness")
    start = start_state(model, state, "contact_stiffness")
    series = model.series_stiffness
    if model.rest_capacity() is not None:
        # A memoryless contact sticks rigidly: only a spring in front of it gives.
        if series == math.inf:
            raise InputError(f"The {model.type} model holds a stuck body rigidly (its friction "
                             f"is set-valued at rest): it has no presliding stiffness to "
                             f"linearize; expected a model with presliding (elements, "
                             f"bristles) or a [model.compliance] spring.")
        return float(series), 0.0
    kernel = model.step_kernel(start)
    values = [float(kernel.tangent(kernel.scalars, kernel.table, kernel.state.copy(), h))
              for h in (0.0, 1.0, 2.0)]
    damping, stiffness = values[0], values[1] - values[0]
    curvature = values[2] - 2.0 * values[1] + values[0]
    if not all(math.isfinite(value) for value in values) \
            or abs(curvature) > 1e-9 * max(abs(value) for value in values) or stiffness < 0.0 \
            or damping < 0.0:
        raise InputError(f"The tangent of the {model.type} model is not of the form k h + c "
                         f"with k, c >= 0 (at h = 0, 1, 2 s it gives {values}); expected the "
                         f"stepping contract's tangent (the user guide, 'A model of your "
                         f"own').")
    if series < math.inf:
        share = series / (stiffness + series)
        return stiffness * share, damping * share * share
    return stiffness, damping


def linearize(model, mass, state=None, *, name=None):
    """The stuck body's small-signal model: a two-state continuous-time ``StateSpace``.

    Parameters
    ----------
    model : FrictionModel
        Any polind model with presliding (see :func:`contact_stiffness`).
    mass : float
        m [kg], positive.
    state : State, optional
        The model's state the body is stuck at (a result's ``final_state``);
        default: at rest.
    name : str, optional
        The system's name in python-control.

    Returns
    -------
    control.StateSpace
        ``m x'' = u - k x - c x'``, with ``k`` and ``c`` of
        :func:`contact_stiffness`: states ``"x"`` [m] and ``"v"`` [m/s],
        input ``"u"`` [N], the applied force; outputs ``"x"``, ``"v"`` and
        ``"F"`` [N], the friction force ``k x + c v``.  All are deviations
        from the stuck operating point (the body at rest, its friction
        balancing the applied force).  Natural frequency ``sqrt(k / m)``,
        damping ratio ``c / (2 sqrt(k m))``.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.control import linearize
    >>> model = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e6,
    ...                                           "coulomb_force": 1.0}})
    >>> sys = linearize(model, mass=1.0)
    >>> sys.A.tolist()
    [[0.0, 1.0], [-1000000.0, 0.0]]
    >>> wn, zeta, poles = sys.damp()
    >>> round(float(wn[0]), 9)                      # sqrt(k / m) [rad/s]
    1000.0
    """
    mass = check_number("linearize", "mass", mass, "positive")
    check_model(model, "linearize")
    stiffness, damping = contact_stiffness(model, state)
    a = np.array([[0.0, 1.0], [-stiffness / mass, 0.0 - damping / mass]])
    b = np.array([[0.0], [1.0 / mass]])
    c = np.array([[1.0, 0.0], [0.0, 1.0], [stiffness, damping]])
    d = np.zeros((3, 1))
    return _ct.ss(a, b, c, d, states=["x", "v"], inputs=["u"], outputs=["x", "v", "F"],
                  name=name)
