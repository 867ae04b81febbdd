"""The memoryless models of MODELS.md 1: Coulomb and Stribeck.

They have no state: the force at sample k is a function of the velocity
reported at that sample, ``F[k] = f(v[k])`` (INTERFACE.md), with
``sgn(0) = 0`` so a body at rest carries no friction force.
"""

from __future__ import annotations

import numpy as np

from polind.models.base import FrictionModel, register
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS


def stribeck_curve(v, coulomb_force, static_force, stribeck_velocity, stribeck_exponent=2.0,
                   stribeck_shape="exponential"):
    """g(v) [N] of MODELS.md 0 for an array of velocities [m/s] (NumPy version)."""
    ratio = np.abs(np.asarray(v, dtype=np.float64) / stribeck_velocity) ** stribeck_exponent
    decay = 1.0 / (1.0 + ratio) if stribeck_shape == "rational" else np.exp(-ratio)
    return coulomb_force + (static_force - coulomb_force) * decay


@register
class Coulomb(FrictionModel):
    """Coulomb friction ``F = Fc sgn(v)``.

    Parameters
    ----------
    coulomb_force : float
        Fc [N], positive.

    Examples
    --------
    >>> import numpy as np, polind
    >>> model = polind.model_from_dict({"model": {"type": "coulomb", "coulomb_force": 2.0}})
    >>> polind.simulate(model, np.array([0.0, 1.0, 2.0]), v=np.array([-1.0, 0.0, 3.0])).force
    array([-2.,  0.,  2.])
    """

    type = "coulomb"
    parameters = (Param("coulomb_force", unit="N"),)

    def _advance(self, path, state, normal_load):
        return self._params["coulomb_force"] * np.sign(path.sample_velocity)


@register
class Stribeck(FrictionModel):
    """Static Stribeck friction ``F = g(v) sgn(v) + sigma2 v`` (MODELS.md 1).

    Parameters
    ----------
    coulomb_force, static_force : float
        Fc and Fs [N], positive (``Fs < Fc`` is velocity strengthening).
    stribeck_velocity : float
        vs [m/s].
    stribeck_exponent : float, default 2
        delta.
    stribeck_shape : {"exponential", "rational"}
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    """

    type = "stribeck"
    parameters = STRIBECK_PARAMS + (VISCOUS,)

    def _advance(self, path, state, normal_load):
        p = self._params
        v = path.sample_velocity
        g = stribeck_curve(v, p["coulomb_force"], p["static_force"], p["stribeck_velocity"],
                           p["stribeck_exponent"], p["stribeck_shape"])
        return g * np.sign(v) + p["viscous_coefficient"] * v
