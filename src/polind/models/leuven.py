"""The modified Leuven model (the user guide, :ref:`guide-leuven`), a Maxwell-slip hysteresis force."""

from __future__ import annotations

import math

import numpy as np

from polind.models.base import FrictionModel, StepFunctions, element_scales, register, scales
from polind.errors import InputError
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS, same_length, sums_to
from polind.models.maxwell_slip import example_elements


@register
class Leuven(FrictionModel):
    """Leuven: ``dz/dt = v (1 - sgn(Fh/s)|Fh/s|^n)``, ``F = Fh(z) + sigma1 dz/dt + sigma2 v``.

    ``Fh(z)`` is a Maxwell-slip structure driven by ``z`` (a choice of polind's,
    :ref:`guide-leuven`), which gives it non-local memory.  The state equation is
    integrated by backward Euler with a safeguarded Newton solve per step:
    unconditionally stable, but *approximate*, first order in the step (the
    error is tested against a fine-step reference in the test suite).  In
    presliding (``|Fh| << s(v)``) ``z`` follows ``x`` and ``Fh`` is the
    Maxwell-slip force of the displacement, exactly.  The ``sigma1 dz/dt``
    term of the output is the step's ``dz/dt`` (the increment over ``h``,
    which the implicit equation makes equal to the state equation at the
    step's end); at the first sample of a fresh run no step has been taken
    and it is 0, so ``F[0] = sigma2 v[0]``.

    With ``static_force < coulomb_force`` (velocity strengthening) the model
    cannot reach the Stribeck curve: ``sum W_i = Fs`` bounds ``|Fh|`` below
    ``g(v)``, so ``dz/dt`` never vanishes and steady sliding gives
    ``Fs + sigma1 v (1 - (Fs/g(v))^n) + sigma2 v``.  That follows from
    the model's equations as written; polind keeps it rather than change the model.

    Parameters
    ----------
    stiffness : list of float
        k_i [N/m] of the hysteresis elements.
    breakaway_force : list of float
        W_i [N], summing to ``static_force`` within 1e-9.
    exponent : float
        n > 0 of the state equation.
    bristle_damping : float
        sigma1 [N s/m], non-negative.
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    coulomb_force, static_force, stribeck_velocity, stribeck_exponent, stribeck_shape
        The Stribeck curve s(v) = sgn(v) g(v) (:ref:`guide-stribeck-curve`).
    """

    type = "leuven"
    title = "Leuven (modified)"
    form = "modified Leuven model, Maxwell-slip hysteresis force"
    purpose = "a LuGre-like model with non-local memory"
    guide = "guide-leuven"
    #: When to use it (the guide's 'Which one to use').
    advice = ('A LuGre-like state equation whose hysteresis force is a Maxwell-slip structure, '
              'giving it non-local memory.')
    has_elements = True

    @classmethod
    def example_parameters(cls, elements=None):
        """The elements of ``example_elements()``, break-away
        forces summing to Fs = 1.5 N, n = 2, sigma1 = 100 N s/m with the four default
        elements (10 N s/m with ``elements``), and the Stribeck levels of the LuGre set of
        1995."""
        stiffness, breakaway = example_elements(elements)
        if elements is None:
            breakaway = [0.3, 0.45, 0.375, 0.375]
        else:
            breakaway = [w * 1.5 / math.fsum(breakaway) for w in breakaway]
        return {"stiffness": stiffness, "breakaway_force": breakaway, "exponent": 2.0,
                "bristle_damping": 100.0 if elements is None else 10.0,
                "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
                "stribeck_exponent": 2.0, "viscous_coefficient": 0.4,
                "stribeck_shape": "exponential"}

    parameters = (
        Param("stiffness", kind="list", unit="N/m",
          description="Stiffnesses :math:`k_i` of the hysteresis elements.", symbol="k_i"),
        Param("breakaway_force", kind="list", unit="N",
          description=("Break-away forces :math:`W_i` of the hysteresis elements, summing to "
                       "``static_force`` within :math:`10^{-9}`."), symbol="W_i"),
        Param("exponent",
          description="Exponent :math:`n` of the state equation.", symbol="n"),
        Param("bristle_damping", bound="nonnegative", unit="N s/m",
          description=(r"Bristle damping :math:`\sigma_1`: the force :math:`\sigma_1 \dot z` "
                       r"of the bristle's deflection rate."), symbol=r"\sigma_1"),
        VISCOUS,
    ) + STRIBECK_PARAMS
    phenomena = frozenset({"frictional_lag"})
    fit_defaults = ("stiffness", "coulomb_force", "static_force", "stribeck_velocity")

    def characteristic_scales(self):
        p = self._params
        presliding, slope = element_scales(p["stiffness"], p["breakaway_force"])
        return scales(p["static_force"], p["coulomb_force"], p["viscous_coefficient"], curve=p,
                      presliding_range=presliding, presliding_stiffness=slope,
                      relaxation_length=presliding)

    @classmethod
    def check_free_keys(cls, keys):
        if {"breakaway_force", "static_force"} <= set(keys):
            raise InputError("The free keys 'breakaway_force' and 'static_force' of leuven "
                             "cannot both be free: the break-away forces must sum to the static "
                             "force; free one of them.")

    @classmethod
    def couple_fit(cls, params, keys, start):
        # The break-away forces sum to Fs (user guide, "Leuven"): move the other with the free one.
        if "breakaway_force" in keys:
            params["static_force"] = math.fsum(params["breakaway_force"])
        elif "static_force" in keys:
            ratio = params["static_force"] / start["static_force"]
            params["breakaway_force"] = [w * ratio for w in start["breakaway_force"]]

    @classmethod
    def _check(cls, params):
        same_length(cls.type, params, ("stiffness", "breakaway_force"))
        sums_to(cls.type, params, "breakaway_force", params["static_force"],
                "static_force")

    def initial_variables(self, normal_load=None):
        return {"element_force": np.zeros(len(self._params["stiffness"])),
                "deflection": np.zeros(1), "deflection_rate": np.zeros(1)}

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import single
        return StepFunctions(single.leuven_step, single.leuven_force, single.leuven_tangent,
                             runners="leuven")

    def kernel_arrays(self, state):
        from polind.kernels.stribeck import SHAPE_CODES
        p = self._params
        scalars = np.array([p["viscous_coefficient"], p["exponent"], p["bristle_damping"],
                            p["coulomb_force"], p["static_force"], p["stribeck_velocity"],
                            p["stribeck_exponent"], SHAPE_CODES[p["stribeck_shape"]],
                            float(np.sum(self._array("breakaway_force")))], dtype=np.float64)
        return scalars, np.vstack([self._array("stiffness"), self._array("breakaway_force")])

    def force_scale(self):
        return max(self._params["coulomb_force"], self._params["static_force"])
