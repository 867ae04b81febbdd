"""The Generalized Maxwell-slip model (MODELS.md 5)."""

from __future__ import annotations

import numpy as np

from polind.models.base import FrictionModel, register
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS, same_length, sums_to


@register
class GMS(FrictionModel):
    """GMS: Maxwell-slip elements whose slip obeys a rate-state law.

    Element ``i`` (stiffness ``k_i``, weight ``alpha_i``) sticks with
    ``dF_i/dt = k_i v`` until ``|F_i| >= alpha_i g(v)`` with ``F_i v > 0``, then
    slips with ``dF_i/dt = sgn(v) C (1 - F_i/(alpha_i s(v)))`` until ``v``
    changes sign.  Each step is integrated exactly at the step's constant
    velocity (see :mod:`polind.kernels.elements`).  A step with ``v = 0``
    leaves every element as it is.

    Parameters
    ----------
    stiffness : list of float
        k_i [N/m].
    weight : list of float
        alpha_i > 0, summing to 1 within 1e-9.
    attraction : float
        C [N/s], how fast a slipping element approaches the Stribeck curve.
    coulomb_force, static_force, stribeck_velocity, stribeck_exponent, stribeck_shape
        The Stribeck curve g(v) (MODELS.md 0).
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    """

    type = "gms"
    parameters = (
        Param("stiffness", kind="list", unit="N/m"),
        Param("weight", kind="list"),
        Param("attraction", unit="N/s"),
    ) + STRIBECK_PARAMS + (VISCOUS,)

    @classmethod
    def _check(cls, params):
        same_length(cls.type, params, ("stiffness", "weight"))
        sums_to(cls.type, params, "weight", 1.0, "1")

    def initial_variables(self, normal_load=None):
        n = len(self._params["stiffness"])
        return {"element_force": np.zeros(n), "slip_direction": np.zeros(n)}

    def _advance(self, path, state, normal_load):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels.elements import gms_run
        from polind.kernels.stribeck import SHAPE_CODES
        p = self._params
        out = np.empty(path.t.shape[0])
        gms_run(path.step, path.displacement, path.step_velocity, self._array("stiffness"),
                self._array("weight"), p["attraction"], p["coulomb_force"], p["static_force"],
                p["stribeck_velocity"], p["stribeck_exponent"], SHAPE_CODES[p["stribeck_shape"]],
                state.variables["element_force"], state.variables["slip_direction"], out)
        return out + p["viscous_coefficient"] * path.sample_velocity
