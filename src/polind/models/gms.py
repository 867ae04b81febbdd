"""The Generalized Maxwell-slip model (the user guide, :ref:`guide-gms`)."""

from __future__ import annotations

import math
import numpy as np

from polind.models.base import (FrictionModel, SpecialCase, StepFunctions, element_scales,
                                register, scales)
from polind.models.params import Param, STRIBECK_PARAMS, VISCOUS, same_length, sums_to
from polind.models.maxwell_slip import MaxwellSlip, example_elements


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
        The Stribeck curve g(v) (:ref:`guide-stribeck-curve`).
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    """

    type = "gms"
    title = "Generalized Maxwell-slip (GMS)"
    form = "Maxwell-slip elements with a rate-state slip law"
    purpose = "presliding memory *and* sliding dynamics (Stribeck, lag) in one model"
    guide = "guide-gms"
    #: When to use it (the guide's 'Which one to use').
    advice = ('Maxwell-slip elements whose slip obeys a rate-state law: presliding memory *and* '
              'the sliding dynamics (Stribeck dip, frictional lag) in one model.  A good '
              'default for identification from measured data.')
    has_elements = True

    @classmethod
    def example_parameters(cls, elements=None):
        """The elements of ``example_elements()`` (weights
        their shares of the break-away force), C = 50 N/s with the four default elements
        (1e4 N/s with ``elements``), and the Stribeck levels of the LuGre set of 1995."""
        stiffness, breakaway = example_elements(elements)
        total = math.fsum(breakaway)
        return {"stiffness": stiffness, "weight": [w / total for w in breakaway],
                "attraction": 50.0 if elements is None else 1e4,
                "coulomb_force": 1.0, "static_force": 1.5, "stribeck_velocity": 1e-3,
                "stribeck_exponent": 2.0, "viscous_coefficient": 0.4,
                "stribeck_shape": "exponential"}

    parameters = (
        Param("stiffness", kind="list", unit="N/m",
          description="Element stiffnesses :math:`k_i`, one per element.", symbol="k_i"),
        Param("weight", kind="list",
          description=(r"Element weights :math:`\alpha_i`, each element's share of the "
                       r"Stribeck curve; positive, summing to 1 within :math:`10^{-9}`."), symbol=r"\alpha_i"),
        Param("attraction", unit="N/s",
          description=("Attraction parameter :math:`C`: how fast a slipping element's force "
                       "approaches its share of the Stribeck curve."), symbol="C"),
    ) + STRIBECK_PARAMS + (VISCOUS,)
    phenomena = frozenset({"presliding_memory", "frictional_lag", "non_drifting"})
    # The weights are free by default: with them GMS contains Maxwell-slip (Fs = Fc).
    fit_defaults = ("stiffness", "weight", "attraction", "coulomb_force", "static_force",
                    "stribeck_velocity")
    simplex_keys = ("weight",)

    def characteristic_scales(self):
        return gms_scales(self._params)

    @classmethod
    def _check(cls, params):
        same_length(cls.type, params, ("stiffness", "weight"))
        sums_to(cls.type, params, "weight", 1.0, "1")

    def initial_variables(self, normal_load=None):
        n = len(self._params["stiffness"])
        return {"element_force": np.zeros(n), "slip_direction": np.zeros(n)}

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import elements
        return StepFunctions(elements.gms_step, elements.gms_force, elements.gms_tangent,
                             runners="gms")

    def kernel_arrays(self, state):
        return gms_arrays(self._params)

    def force_scale(self):
        return max(self._params["coulomb_force"], self._params["static_force"])

    # --- starting models from measured data ---------------------------------------------

    def structured_starts(self, path, force, free):
        """The NNLS element set of the record with this model's element count and its
        attraction, Stribeck velocity and ratio Fs / Fc (:meth:`from_presliding`)."""
        from polind.errors import InputError

        try:
            fitted = type(self).from_presliding(path, force, model=self,
                                                elements=len(self._params["stiffness"]))
        except InputError:
            return {}
        return {"the NNLS element set (GMS.from_presliding)": fitted}

    @classmethod
    def contains(cls):
        """Maxwell-slip: GMS with ``Fs = Fc`` is Maxwell-slip with ``W_i = alpha_i Fc``."""
        return MaxwellSlip

    def special_case(self, free, path):
        """Maxwell-slip with this model's elements, ``W_i = alpha_i Fc``.

        Its free keys: ``stiffness`` if free here, ``breakaway_force`` if the
        weights and a force level are, ``viscous_coefficient`` if free here.
        A fitted Maxwell-slip model lifts to ``k_i``, ``alpha_i = W_i / sum W``,
        ``Fs = Fc = sum W`` and its sigma2: with ``Fs = Fc`` a GMS element
        holds ``alpha_i Fc`` while it slips, whatever ``C``, so the two
        models' forces are equal.
        """
        keys = set(free)
        contained = [key for key, needs in (
            ("stiffness", {"stiffness"}), ("breakaway_force", {"weight"}),
            ("viscous_coefficient", {"viscous_coefficient"})) if needs <= keys]
        if "breakaway_force" in contained and not keys & {"coulomb_force", "static_force"}:
            contained.remove("breakaway_force")
        if not contained:
            return None
        p = self._params
        start = MaxwellSlip(stiffness=list(p["stiffness"]),
                            breakaway_force=[a * p["coulomb_force"] for a in p["weight"]],
                            viscous_coefficient=p["viscous_coefficient"])

        def lift(fitted):
            q = fitted.params
            total = math.fsum(q["breakaway_force"])
            weight = [w / total for w in q["breakaway_force"]]
            weight[-1] = 1.0 - math.fsum(weight[:-1])
            return self.with_params(stiffness=list(q["stiffness"]), weight=weight,
                                    coulomb_force=total, static_force=total,
                                    viscous_coefficient=q["viscous_coefficient"])

        return SpecialCase(MaxwellSlip, start, tuple(contained), lift,
                           "maxwell-slip (gms with Fs = Fc)")

    @classmethod
    def from_presliding(cls, path, F, slip_distances=None, n=24, *, model=None,
                        elements=None) -> "GMS":
        """A GMS starting model: the element set of a presliding record.

        GMS with ``Fs = Fc`` and a large attraction ``C`` is the Maxwell-slip
        model with ``W_i = alpha_i Fc`` (:ref:`guide-gms`), so the element set
        of :meth:`MaxwellSlip.from_presliding <polind.models.MaxwellSlip.from_presliding>`
        gives ``alpha_i = W_i / sum W`` and ``k_i``; the Coulomb force is
        ``sum W`` (the sliding force of the record).
        :func:`polind.identify_gms` checks a data record and calls this.

        Parameters
        ----------
        path, F, slip_distances, n
            As :meth:`MaxwellSlip.from_presliding
            <polind.models.MaxwellSlip.from_presliding>`: the motion [m, m/s]
            cut into steps, the force [N], the grid of slip distances [m].
        model : GMS, optional
            A GMS model whose ``attraction`` [N/s], Stribeck velocity [m/s],
            exponent, shape and ``viscous_coefficient`` [N s/m] are kept,
            and whose ratio ``static_force / coulomb_force`` is applied.
            Without it: ``Fs = Fc = sum W``, ``stribeck_velocity`` the
            median speed of the moving samples, and ``C = 10 v max_i k_i``
            with ``v`` that speed (a slip relaxation length
            ``alpha_i g / C`` well below every slip distance, i.e. close to
            Maxwell-slip).
        elements : int, optional
            The number of elements, as :meth:`MaxwellSlip.from_presliding
            <polind.models.MaxwellSlip.from_presliding>` (default: as NNLS
            finds them).

        Returns
        -------
        GMS

        Raises
        ------
        InputError
            As :meth:`MaxwellSlip.from_presliding
            <polind.models.MaxwellSlip.from_presliding>`, or a ``model``
            that is not a GMS model.

        Examples
        --------
        >>> import numpy as np, polind
        >>> from polind.models import GMS
        >>> from polind.simulation import make_path
        >>> slip = polind.model_from_dict({"model": {"type": "maxwell-slip",
        ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 3.0]}})
        >>> t = np.linspace(0.0, 1.0, 401)
        >>> x = 4e-5 * np.sin(2 * np.pi * t) * (1 - t)
        >>> F = polind.simulate(slip, t, x=x).force
        >>> start = GMS.from_presliding(make_path(t, x=x), F,
        ...                             slip_distances=[1e-6, 5e-6, 3e-5])
        >>> round(start.params["coulomb_force"], 9), np.round(start.params["weight"], 9).tolist()
        (4.0, [0.25, 0.75])
        """
        from polind.errors import InputError, describe

        slip = MaxwellSlip.from_presliding(path, F, slip_distances, n, elements=elements)
        stiffness = np.asarray(slip.params["stiffness"])
        breakaway = np.asarray(slip.params["breakaway_force"])
        total = float(breakaway.sum())
        weight = breakaway / total
        weight[-1] = 1.0 - weight[:-1].sum()
        elements = {"stiffness": stiffness.tolist(), "weight": weight.tolist()}
        if model is not None:
            if not isinstance(model, cls):
                raise InputError(f"The 'model' of {cls.__name__}.from_presliding must be a "
                                 f"{cls.type} model. Got {describe(model)} instead.")
            p = model.params
            ratio = p["static_force"] / p["coulomb_force"]
            return model.with_params(**elements, coulomb_force=total, static_force=total * ratio)
        speed = np.abs(path.sample_velocity)
        typical = float(np.median(speed[speed > 0.0]))
        return cls(**elements, attraction=10.0 * typical * float(stiffness.max()),
                   coulomb_force=total, static_force=total, stribeck_velocity=typical)


def gms_scales(params):
    """The characteristic scales of a GMS parameter set (GMS and Pol-Ind at its load)."""
    capacity = np.asarray(params["weight"], dtype=np.float64) * params["static_force"]
    presliding, slope = element_scales(params["stiffness"], capacity)
    return scales(params["static_force"], params["coulomb_force"],
                  params["viscous_coefficient"], curve=params, presliding_range=presliding,
                  presliding_stiffness=slope,
                  relaxation_rate=params["attraction"] * float(np.sum(capacity))
                  / float(np.max(capacity)))


def gms_arrays(params):
    """``(scalars, table)`` of the GMS step for a parameter set (GMS and Pol-Ind at its load)."""
    from polind.kernels import elements as slots
    from polind.kernels.stribeck import SHAPE_CODES

    scalars = np.zeros(slots.N_GMS_SCALARS)
    scalars[slots.VISCOUS] = params["viscous_coefficient"]
    scalars[slots.ATTRACTION] = params["attraction"]
    scalars[slots.COULOMB] = params["coulomb_force"]
    scalars[slots.STATIC] = params["static_force"]
    scalars[slots.STRIBECK_VELOCITY] = params["stribeck_velocity"]
    scalars[slots.STRIBECK_EXPONENT] = params["stribeck_exponent"]
    scalars[slots.STRIBECK_SHAPE] = SHAPE_CODES[params["stribeck_shape"]]
    stiffness = np.asarray(params["stiffness"], dtype=np.float64)
    weight = np.asarray(params["weight"], dtype=np.float64)
    # An element without load (alpha = 0) never carries force: 1/alpha = inf.
    inverse = np.divide(1.0, weight, where=weight > 0.0, out=np.full_like(weight, np.inf))
    return scalars, np.vstack([stiffness, weight, inverse])
