"""The Dahl model (the user guide, :ref:`guide-dahl`), integrated exactly in the distance."""

from __future__ import annotations

import numpy as np

from polind.models.base import FrictionModel, StepFunctions, register, scales
from polind.models.params import Param


@register
class Dahl(FrictionModel):
    """Dahl: ``dF/dt = sigma0 v |1 - F sgn(v)/Fc|^alpha sgn(1 - F sgn(v)/Fc)``.

    The equation depends on the path only through the travelled distance, and
    in the normalised deficit ``u = 1 - F sgn(v)/Fc`` it is separable, so each
    step is updated by its exact solution (exponential for ``alpha = 1``,
    algebraic otherwise): the result does not depend on the sampling of a
    piecewise-linear path.

    Parameters
    ----------
    stiffness : float
        sigma0 [N/m], the initial slope.
    coulomb_force : float
        Fc [N].
    exponent : float, default 1
        alpha >= 0.
    """

    type = "dahl"
    title = "Dahl"
    form = "rate-independent first-order hysteresis"
    purpose = "presliding stiffness with a smooth approach to Coulomb friction"
    guide = "guide-dahl"
    #: When to use it (the guide's 'Which one to use').
    advice = ('A smooth, rate-independent approach to Coulomb friction after each reversal: the '
              'first presliding model, one state, two parameters.')

    @classmethod
    def example_parameters(cls, elements=None):
        """sigma0 = 1e5 N/m, Fc = 1 N, alpha = 1."""
        return {"stiffness": 1e5, "coulomb_force": 1.0, "exponent": 1.0}

    parameters = (
        Param("stiffness", unit="N/m",
          description=(r"Dahl stiffness :math:`\sigma_0`: the slope of the force against "
                       r"displacement after a reversal."), symbol=r"\sigma_0"),
        Param("coulomb_force", unit="N",
          description=("Coulomb (kinetic) friction level :math:`F_c`: the force of steady "
                       "sliding well above the Stribeck velocity."), symbol="F_c"),
        Param("exponent", bound="nonnegative", default=1.0,
          description=(r"Dahl exponent :math:`\alpha`: the shape of the approach to "
                       r":math:`F_c` (1 gives the exponential)."), symbol=r"\alpha"),
    )
    fit_defaults = ("stiffness", "coulomb_force")

    def characteristic_scales(self):
        p = self._params
        return scales(p["coulomb_force"], p["coulomb_force"],
                      presliding_range=p["coulomb_force"] / p["stiffness"],
                      presliding_stiffness=p["stiffness"])

    def initial_variables(self, normal_load=None):
        return {"friction": np.zeros(1)}

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import single
        return StepFunctions(single.dahl_step, single.dahl_force, single.dahl_tangent,
                             runners="dahl")

    def kernel_arrays(self, state):
        p = self._params
        return np.array([p["stiffness"], p["coulomb_force"], p["exponent"]]), np.zeros((1, 0))

    def force_scale(self):
        return self._params["coulomb_force"]
