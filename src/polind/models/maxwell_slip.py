"""The Maxwell-slip model (the user guide, :ref:`guide-maxwell-slip`): elastic-perfectly-plastic
elements in parallel."""

from __future__ import annotations

import math

import numpy as np

from polind.models.base import FrictionModel, StepFunctions, element_scales, register, scales
from polind.models.params import Param, VISCOUS, same_length


def virgin_curve(x, stiffness, breakaway_force):
    """phi(x) = sgn(x) sum_i k_i min(|x|, D_i), D_i = W_i/k_i [N] (:ref:`guide-maxwell-slip`)."""
    x = np.asarray(x, dtype=np.float64)
    k = np.asarray(stiffness, dtype=np.float64)
    slip = np.asarray(breakaway_force, dtype=np.float64) / k
    return np.sign(x) * np.sum(k * np.minimum(np.abs(x)[..., None], slip), axis=-1)


@register
class MaxwellSlip(FrictionModel):
    """Maxwell-slip: ``z_i <- clip(z_i + dx, -D_i, D_i)``, ``F = sum k_i z_i + sigma2 v``.

    The update is exact: forces at the samples do not depend on how finely a
    piecewise-linear path is sampled, as long as every reversal is a sample.
    The state holds the element forces ``k_i z_i``.

    Parameters
    ----------
    stiffness : list of float
        k_i [N/m], positive.
    breakaway_force : list of float
        W_i [N], positive, same length.
    viscous_coefficient : float, default 0
        sigma2 [N s/m].

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 1.0]}})
    >>> polind.simulate(model, np.array([0.0, 1.0, 2.0]), x=np.array([0.0, 2e-6, 0.0])).force
    array([ 0. ,  1.2, -1. ])
    """

    type = "maxwell-slip"
    parameters = (
        Param("stiffness", kind="list", unit="N/m"),
        Param("breakaway_force", kind="list", unit="N"),
        VISCOUS,
    )
    phenomena = frozenset({"presliding_memory", "non_drifting"})
    fit_defaults = ("stiffness", "breakaway_force")

    def characteristic_scales(self):
        p = self._params
        level = math.fsum(p["breakaway_force"])
        presliding, slope = element_scales(p["stiffness"], p["breakaway_force"])
        return scales(level, level, p["viscous_coefficient"], presliding_range=presliding,
                      presliding_stiffness=slope)

    @classmethod
    def _check(cls, params):
        same_length(cls.type, params, ("stiffness", "breakaway_force"))

    def initial_variables(self, normal_load=None):
        return {"element_force": np.zeros(len(self._params["stiffness"]))}

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import elements
        return StepFunctions(elements.maxwell_slip_step, elements.maxwell_slip_force,
                             elements.maxwell_slip_tangent, elements.maxwell_slip_path,
                             elements.maxwell_slip_integrate, elements.maxwell_slip_body,
                             motion=elements.maxwell_slip_motion)

    def kernel_arrays(self, state):
        table = np.vstack([self._array("stiffness"), self._array("breakaway_force")])
        return np.array([self._params["viscous_coefficient"]]), table

    def force_scale(self):
        return float(np.sum(self._params["breakaway_force"]))
