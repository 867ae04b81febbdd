"""The LuGre model (the user guide, :ref:`guide-lugre`), with the exact exponential state update."""

from __future__ import annotations

import math
import numpy as np

from polind.models.base import FrictionModel, SpecialCase, StepFunctions, register, scales
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS
from polind.models.static import Stribeck

#: The keys LuGre shares with the Stribeck curve it follows in steady sliding.
_CURVE_KEYS = ("coulomb_force", "static_force", "stribeck_velocity", "stribeck_exponent",
               "viscous_coefficient")
#: A bristle stiff enough that the bristle settles within a step: sigma0 times a short step
#: displacement (the 1st percentile of the moving samples') is this many times the largest
#: level of g.
_SETTLING = 50.0


@register
class LuGre(FrictionModel):
    """LuGre: ``dz/dt = v - sigma0 |v| z / g(v)``, ``F = sigma0 z + sigma1 dz/dt + sigma2 v``.

    At constant velocity over a step the state equation is linear in ``z``;
    each step uses its exact solution, so the update is stable for any
    ``sigma0`` and step.  The output's ``dz/dt`` is the state equation
    evaluated at the sample (state after the step, the sample's velocity).
    LuGre drifts under an oscillating force below break-away (Dupont et al.
    2002); that is the model's own behaviour and polind keeps it.

    Parameters
    ----------
    bristle_stiffness : float
        sigma0 [N/m].
    bristle_damping : float
        sigma1 [N s/m], non-negative.
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    coulomb_force, static_force, stribeck_velocity, stribeck_exponent, stribeck_shape
        The Stribeck curve g(v) (:ref:`guide-stribeck-curve`).

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "lugre",
    ...     "bristle_stiffness": 1e5, "bristle_damping": 316.2, "viscous_coefficient": 0.4,
    ...     "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3}})
    >>> t = np.linspace(0.0, 1.0, 1001)
    >>> round(float(polind.simulate(model, t, v=np.full_like(t, 0.01)).force[-1]), 6)
    1.004
    """

    type = "lugre"
    title = "LuGre"
    form = "bristle model with a Stribeck curve"
    purpose = ("the standard dynamic model for servo compensation; stick-slip and frictional lag "
               "(drifts under small oscillating forces, as it must)")
    guide = "guide-lugre"
    #: When to use it (the guide's 'Which one to use').
    advice = ('The standard dynamic model for servo compensation: one bristle state, a Stribeck '
              'curve, stick-slip and frictional lag.  It drifts under small oscillating forces '
              '(a property of the model, kept in polind) and has no non-local memory.')

    @classmethod
    def example_parameters(cls, elements=None):
        """The parameters of Canudas de Wit, Olsson, Astrom and Lischinsky (1995).

        sigma0 = 1e5 N/m, sigma1 = sqrt(1e5) N s/m, sigma2 = 0.4 N s/m,
        Fc = 1 N, Fs = 1.5 N, vs = 1 mm/s, delta = 2.
        """
        return {"bristle_stiffness": 1e5, "bristle_damping": math.sqrt(1e5),
                "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
                "stribeck_exponent": 2.0, "viscous_coefficient": 0.4,
                "stribeck_shape": "exponential"}

    parameters = (
        Param("bristle_stiffness", unit="N/m",
          description=(r"Bristle stiffness :math:`\sigma_0`: the presliding stiffness."), symbol=r"\sigma_0"),
        Param("bristle_damping", bound="nonnegative", unit="N s/m",
          description=(r"Bristle damping :math:`\sigma_1`: the force :math:`\sigma_1 \dot z` "
                       r"of the bristle's deflection rate."), symbol=r"\sigma_1"),
        VISCOUS,
    ) + STRIBECK_PARAMS
    phenomena = frozenset({"frictional_lag"})
    fit_defaults = ("bristle_stiffness", "coulomb_force", "static_force", "stribeck_velocity")

    @classmethod
    def contains(cls):
        """Stribeck: in steady sliding LuGre's force is the Stribeck curve's."""
        return Stribeck

    def special_case(self, free, path):
        """The Stribeck model of this model's curve; its free keys are LuGre's curve keys
        that are free.

        A fitted Stribeck model lifts to LuGre with its curve, no bristle
        damping and a bristle stiff enough to settle within a step (sigma0
        times a short step displacement -- the 1st percentile of the moving
        samples' -- 50 times the larger of Fs and Fc): at every moving sample
        after the first (but the shortest steps) the force is the Stribeck
        model's.  (At rest Stribeck gives 0, LuGre holds its bristle.)
        """
        contained = tuple(key for key in _CURVE_KEYS if key in free)
        if not contained:
            return None
        p = self._params
        start = Stribeck(**{key: p[key] for key in _CURVE_KEYS + ("stribeck_shape",)})
        moving = np.abs(path.displacement[1:])
        moving = moving[moving > 0.0]
        step = float(np.percentile(moving, 1.0)) if moving.size else 1.0

        def lift(fitted):
            q = fitted.params
            level = max(q["coulomb_force"], q["static_force"])
            return self.with_params(**{key: q[key] for key in _CURVE_KEYS},
                                    bristle_stiffness=_SETTLING * level / step,
                                    bristle_damping=0.0)

        return SpecialCase(Stribeck, start, contained, lift,
                           "stribeck (lugre in steady sliding)")

    def characteristic_scales(self):
        p = self._params
        return scales(p["static_force"], p["coulomb_force"], p["viscous_coefficient"], curve=p,
                      presliding_range=p["static_force"] / p["bristle_stiffness"],
                      presliding_stiffness=p["bristle_stiffness"],
                      bristle_stiffness=p["bristle_stiffness"])

    def initial_variables(self, normal_load=None):
        return {"deflection": np.zeros(1)}

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import single
        return StepFunctions(single.lugre_step, single.lugre_force, single.lugre_tangent,
                             runners="lugre")

    def kernel_arrays(self, state):
        from polind.kernels.stribeck import SHAPE_CODES
        p = self._params
        scalars = np.array([p["viscous_coefficient"], p["bristle_stiffness"],
                            p["bristle_damping"], p["coulomb_force"], p["static_force"],
                            p["stribeck_velocity"], p["stribeck_exponent"],
                            SHAPE_CODES[p["stribeck_shape"]]], dtype=np.float64)
        return scalars, np.zeros((1, 0))

    def force_scale(self):
        return max(self._params["coulomb_force"], self._params["static_force"])
