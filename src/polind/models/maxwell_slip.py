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


#: The four elements of the representative Maxwell-slip family models (N/m; N, summing to 1).
EXAMPLE_STIFFNESS = (1e5, 5e4, 2e4, 1e4)
EXAMPLE_BREAKAWAY = (0.2, 0.3, 0.25, 0.25)


def example_elements(count=None, seed=0) -> tuple:
    """``(stiffness [N/m], breakaway_force [N])`` lists of representative elements.

    Without ``count``: four elements, k = 1e5, 5e4, 2e4, 1e4 N/m and W = 0.2,
    0.3, 0.25, 0.25 N.  With ``count``: that many, stiffnesses log-uniform in
    [1e5, 1e7] N/m and slip distances log-uniform in [0.1, 10] um, drawn with
    ``seed`` (the element sets ``polind bench`` times).
    """
    if count is None:
        return list(EXAMPLE_STIFFNESS), list(EXAMPLE_BREAKAWAY)
    rng = np.random.default_rng(seed)
    stiffness = 10.0 ** rng.uniform(5.0, 7.0, count)
    slip = 10.0 ** rng.uniform(-7.0, -5.0, count)
    return stiffness.tolist(), (stiffness * slip).tolist()


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
    title = "Maxwell-slip"
    form = "elastic–perfectly-plastic elements in parallel"
    purpose = "presliding hysteresis with exact non-local memory"
    guide = "guide-maxwell-slip"
    #: When to use it (the guide's 'Which one to use').
    advice = ('Presliding hysteresis with exact non-local memory from elastic–perfectly-plastic '
              'elements in parallel; rate independent, so no Stribeck effect and no lag.')
    has_elements = True

    @classmethod
    def example_parameters(cls, elements=None):
        """The elements of ``example_elements()``, sigma2 = 0.4 N s/m."""
        stiffness, breakaway = example_elements(elements)
        return {"stiffness": stiffness, "breakaway_force": breakaway,
                "viscous_coefficient": 0.4}

    parameters = (
        Param("stiffness", kind="list", unit="N/m",
          description="Element stiffnesses :math:`k_i`, one per element.", symbol="k_i"),
        Param("breakaway_force", kind="list", unit="N",
          description=(r"Element break-away forces :math:`W_i`, one per element; the largest "
                       r"friction force is :math:`\sum_i W_i`."), symbol="W_i"),
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
