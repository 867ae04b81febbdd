"""The memoryless models (the user guide, :ref:`guide-static-models`): Coulomb and Stribeck.

They have no state: the force at sample k is a function of the velocity
reported at that sample, ``F[k] = f(v[k])`` (:ref:`guide-simulate-path`), with
``sgn(0) = 0`` so a body at rest carries no friction force.
"""

from __future__ import annotations

import numpy as np

from polind.models.base import FrictionModel, StepFunctions, register, scales
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS


def stribeck_curve(v, coulomb_force, static_force, stribeck_velocity, stribeck_exponent=2.0,
                   stribeck_shape="exponential"):
    """g(v) [N] (:ref:`guide-stribeck-curve`) for an array of velocities [m/s] (NumPy version)."""
    ratio = np.abs(np.asarray(v, dtype=np.float64) / stribeck_velocity) ** stribeck_exponent
    decay = 1.0 / (1.0 + ratio) if stribeck_shape == "rational" else np.exp(-ratio)
    return coulomb_force + (static_force - coulomb_force) * decay


def _memoryless_functions(self):
    # Kernels load numba: imported on first use so `import polind` stays fast.
    from polind.kernels import static
    return StepFunctions(static.memoryless_step, static.memoryless_force,
                         static.memoryless_tangent, runners="memoryless")


def _memoryless_scalars(coulomb, static, velocity, exponent, shape, viscous):
    from polind.kernels.stribeck import SHAPE_CODES
    return np.array([viscous, coulomb, static, velocity, exponent, SHAPE_CODES[shape]],
                    dtype=np.float64)


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
    title = "Coulomb"
    form = "`F = Fc sgn(v)`"
    purpose = "the simplest compensation term; no presliding, no memory"
    guide = "guide-static-models"
    #: When to use it (the guide's 'Which one to use').
    advice = ('The simplest compensation term: a constant force against the motion.  No '
              'presliding, no memory; the force jumps at zero velocity.')

    @classmethod
    def example_parameters(cls, elements=None):
        """Fc = 1 N."""
        return {"coulomb_force": 1.0}

    parameters = (Param("coulomb_force", unit="N",
          description=("Coulomb (kinetic) friction level :math:`F_c`: the force of steady "
                       "sliding well above the Stribeck velocity."), symbol="F_c"),)
    phenomena = frozenset({"non_drifting"})
    fit_defaults = ("coulomb_force",)

    def characteristic_scales(self):
        return scales(self._params["coulomb_force"], self._params["coulomb_force"])

    def kernel_arrays(self, state):
        force = self._params["coulomb_force"]
        # Coulomb is the Stribeck curve with Fs = Fc: g is then constant.
        return _memoryless_scalars(force, force, 1.0, 1.0, "exponential", 0.0), np.zeros((1, 0))

    def force_scale(self):
        return self._params["coulomb_force"]

    def rest_capacity(self):
        return self._params["coulomb_force"]

    step_functions = _memoryless_functions


@register
class Stribeck(FrictionModel):
    """Static Stribeck friction ``F = g(v) sgn(v) + sigma2 v`` (:ref:`guide-static-models`).

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
    title = "Stribeck"
    form = "`F = g(v) sgn(v) + sigma2 v`"
    purpose = "steady-state friction maps (Stribeck dip) in velocity control"
    guide = "guide-static-models"
    #: When to use it (the guide's 'Which one to use').
    advice = ('Steady-state friction maps in velocity control: the Stribeck dip and a viscous '
              'term, no state.  Good for sliding, wrong near reversals.')

    @classmethod
    def example_parameters(cls, elements=None):
        """The levels of the LuGre set of 1995: Fc = 1 N, Fs = 1.5 N, vs = 1 mm/s,
        sigma2 = 0.4 N s/m."""
        return {"coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
                "stribeck_exponent": 2.0, "viscous_coefficient": 0.4,
                "stribeck_shape": "exponential"}

    parameters = STRIBECK_PARAMS + (VISCOUS,)
    phenomena = frozenset({"non_drifting"})
    fit_defaults = ("coulomb_force", "static_force", "stribeck_velocity")

    def characteristic_scales(self):
        p = self._params
        return scales(p["static_force"], p["coulomb_force"], p["viscous_coefficient"], curve=p)

    def kernel_arrays(self, state):
        p = self._params
        return _memoryless_scalars(p["coulomb_force"], p["static_force"], p["stribeck_velocity"],
                                   p["stribeck_exponent"], p["stribeck_shape"],
                                   p["viscous_coefficient"]), np.zeros((1, 0))

    def force_scale(self):
        return max(self._params["coulomb_force"], self._params["static_force"])

    def rest_capacity(self):
        # g(0) = Fs: the set-valued friction at rest spans [-Fs, Fs].
        return self._params["static_force"]

    step_functions = _memoryless_functions

    # --- starting models from measured data ---------------------------------------------

    def structured_starts(self, path, force, free):
        """The curve estimated from the record's samples as steady points
        (:meth:`from_steady_points`: the force at each sample against its velocity)."""
        from polind.errors import InputError

        try:
            fitted = type(self).from_steady_points(
                path.sample_velocity, force, stribeck_shape=self._params["stribeck_shape"])
        except InputError:
            return {}
        return {"the steady points (Stribeck.from_steady_points)": fitted}

    @classmethod
    def from_steady_points(cls, v, F, *, stribeck_shape="exponential",
                           model=None) -> "Stribeck":
        """A starting Stribeck model estimated from steady-state ``(v, F)`` points.

        ``Fc`` is the median ``|F|`` of the fastest fifth of the points, ``Fs``
        the largest ``|F|`` of the slowest fifth, ``vs`` the speed where
        ``|F|`` is nearest to halfway between them, ``delta = 2`` and
        ``sigma2 = 0`` (a start for :func:`polind.identify_stribeck`, which
        refines it with :func:`polind.identify`).  The force is taken in the
        direction of the motion, ``F sgn(v)``; points at rest are left out.

        Parameters
        ----------
        v : array_like
            Sliding velocities [m/s] of the steady-state points (either sign).
        F : array_like
            The steady friction force at each [N].
        stribeck_shape : {"exponential", "rational"}
            The shape of the estimated curve.
        model : Stribeck, optional
            A Stribeck model to start from instead: it is returned as it is
            (the points are not used).

        Returns
        -------
        Stribeck

        Raises
        ------
        InputError
            Points that do not pair up, velocities that are all 0, or a
            ``model`` that is not a Stribeck model.

        Examples
        --------
        >>> import numpy as np
        >>> from polind.models import Stribeck
        >>> v = np.geomspace(1e-5, 1e-1, 30)
        >>> F = 1.0 + 0.5 * np.exp(-(v / 1e-3) ** 2)
        >>> start = Stribeck.from_steady_points(v, F)
        >>> [round(start.params[k], 4) for k in ("coulomb_force", "static_force")]
        [1.0, 1.5]
        >>> round(start.params["stribeck_velocity"], 7)   # the point nearest to halfway
        0.0008532
        """
        from polind.errors import InputError, describe

        if model is not None:
            if not isinstance(model, cls):
                raise InputError(f"The 'model' of {cls.__name__}.from_steady_points must be a "
                                 f"{cls.type} model. Got {describe(model)} instead.")
            return model
        v = np.asarray(v, dtype=np.float64)
        force = np.asarray(F, dtype=np.float64)
        if v.ndim != 1 or force.shape != v.shape:
            raise InputError(f"The steady-state points need one force 'F' per velocity 'v' "
                             f"(1-D arrays of one length). Got {describe(F)} for "
                             f"{describe(v)} instead.")
        speed, level = np.abs(v), force * np.sign(v)
        moving = speed > 0.0
        if not moving.any():
            raise InputError("The 'v' samples are all 0: steady-state points need motion.")
        speed, level = speed[moving], level[moving]
        order = np.argsort(speed)
        fifth = max(1, order.size // 5)
        coulomb = float(np.median(level[order[-fifth:]]))
        static = float(np.max(level[order[:fifth]]))
        coulomb = coulomb if coulomb > 0.0 else float(np.abs(level).mean()) or 1.0
        static = static if static > 0.0 else coulomb
        halfway = np.argmin(np.abs(level - 0.5 * (coulomb + static)))
        velocity = float(speed[halfway]) if static != coulomb else float(np.median(speed))
        return cls(coulomb_force=coulomb, static_force=static, stribeck_velocity=velocity,
                   stribeck_exponent=2.0, stribeck_shape=stribeck_shape)
