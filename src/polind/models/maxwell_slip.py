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
                             elements.maxwell_slip_tangent, runners="maxwell_slip")

    def kernel_arrays(self, state):
        table = np.vstack([self._array("stiffness"), self._array("breakaway_force")])
        return np.array([self._params["viscous_coefficient"]]), table

    def force_scale(self):
        return float(np.sum(self._params["breakaway_force"]))

    # --- starting models from measured data ---------------------------------------------

    def structured_starts(self, path, force, free):
        """The NNLS element set of the record (:meth:`from_presliding`), with as many
        elements as this model (and sigma2 when ``viscous_coefficient`` is free)."""
        from polind.errors import InputError

        try:
            fitted = type(self).from_presliding(
                path, force, elements=len(self._params["stiffness"]),
                viscous="viscous_coefficient" in free)
        except InputError:
            return {}
        return {"the NNLS element set (MaxwellSlip.from_presliding)": fitted}

    @classmethod
    def from_presliding(cls, path, F, slip_distances=None, n=24, *,
                        viscous=False, elements=None) -> "MaxwellSlip":
        """An element set fitted to a presliding record by non-negative least squares.

        With the slip distances ``D_i`` fixed on a grid, the force is linear
        in the break-away forces: ``F = sum_i W_i z_i(x) / D_i (+ sigma2 v)``,
        where ``z_i`` is the deflection of element ``i``, clipped to
        ``[-D_i, D_i]`` along the path (it depends on the path and ``D_i``
        only).  ``scipy.optimize.nnls`` finds ``W_i >= 0``; elements with
        ``W_i = 0`` are dropped, and ``k_i = W_i / D_i``.  The elements start
        unloaded at the first sample.  Noiseless data from a Maxwell-slip
        model whose slip distances are on the grid are recovered exactly.
        :func:`polind.identify_maxwell_slip` checks a data record and calls
        this.

        Parameters
        ----------
        path : polind.models.Path
            The measured motion cut into steps, as
            ``polind.simulation.make_path(t, x=x)`` (or ``v=v``) gives it:
            positions ``x`` [m], step displacements [m] and sample
            velocities [m/s] at the sample times ``t`` [s].
        F : array_like
            The measured friction force at each sample [N].
        slip_distances : array_like, optional
            The grid of slip distances [m], positive; default ``n`` distances
            spaced logarithmically from 1e-3 to 1 times the displacement
            range ``max x - min x`` of the path.
        n : int
            Number of grid points when ``slip_distances`` is not given.
        viscous : bool
            Also fit ``viscous_coefficient`` (sigma2 >= 0 [N s/m], a column
            of the sample velocities).
        elements : int, optional
            The number of elements of the result (a starting point for a
            model of that many elements): the NNLS set's elements neighbouring
            in slip distance are merged (break-away forces summed, slip
            distance their force-weighted geometric mean) or the strongest is
            split in two (half its force each, at slip distances a grid
            step apart) until there are that many.  Default: as NNLS finds them.

        Returns
        -------
        MaxwellSlip
            Its elements ordered by slip distance.

        Raises
        ------
        InputError
            A bad ``n`` or ``slip_distances``, a force that does not match
            the path, a fit whose estimated memory passes the limit of
            :mod:`polind.resources`, or a force that no element set with
            non-negative break-away forces carries.

        Examples
        --------
        >>> import numpy as np, polind
        >>> from polind.models import MaxwellSlip
        >>> from polind.simulation import make_path
        >>> true = MaxwellSlip(stiffness=[1e6, 1e5], breakaway_force=[1.0, 2.0])
        >>> t = np.linspace(0.0, 1.0, 401)
        >>> x = 4e-5 * np.sin(2 * np.pi * t) * (1 - t)
        >>> F = polind.simulate(true, t, x=x).force
        >>> fit = MaxwellSlip.from_presliding(make_path(t, x=x), F,
        ...                                   slip_distances=[1e-6, 5e-6, 2e-5])
        >>> np.round(fit.params["breakaway_force"], 9).tolist()
        [1.0, 2.0]
        """
        from scipy.optimize import nnls

        from polind.errors import InputError, describe
        from polind.resources import check_memory

        samples = path.t.shape[0]
        force = np.asarray(F, dtype=np.float64)
        if force.shape != (samples,):
            raise InputError(f"The force 'F' must have one value per sample of the path "
                             f"({samples}). Got {describe(F)} instead.")
        if slip_distances is None:
            if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1):
                raise InputError(f"The number of slip distances 'n' must be a positive "
                                 f"integer. Got {describe(n)} instead.")
            span = float(np.ptp(path.x))
            if not span > 0.0:
                raise InputError("The path never moves: a grid of slip distances needs a "
                                 "displacement range; give 'slip_distances'.")
            grid = np.geomspace(span * 1e-3, span, int(n))
        else:
            grid = np.unique(np.asarray(slip_distances, dtype=np.float64))
            if grid.size == 0 or not np.all(np.isfinite(grid) & (grid > 0.0)):
                raise InputError(f"The 'slip_distances' must be at least one positive distance "
                                 f"[m]. Got {describe(slip_distances)} instead.")
        columns = grid.size + bool(viscous)
        check_memory(samples * (_ELEMENT_FIT_BYTES + _ELEMENT_FIT_BYTES_PER_COLUMN * columns),
                     f"The element fit of {grid.size} slip distances to {samples:.3g} "
                     f"samples of data")
        # A[k, i] = z_i(x_k) / D_i: the clipped deflection of a unit element of slip distance D_i.
        responses = []
        for distance in grid:
            unit = cls(stiffness=[1.0], breakaway_force=[float(distance)])
            responses.append(unit._advance(path, unit.initial_state(), None) / distance)
        design = np.column_stack(responses)
        if viscous:
            design = np.column_stack([design, path.sample_velocity])
        # Columns of very different size (the viscous one) are scaled to unit norm for NNLS.
        norms = np.linalg.norm(design, axis=0)
        norms[norms == 0.0] = 1.0
        coefficients, _ = nnls(design / norms, force, maxiter=50 * design.shape[1])
        coefficients = coefficients / norms
        weights = coefficients[:grid.size]
        active = weights > 1e-12 * max(weights.max(initial=0.0), 1e-300)
        if not active.any():
            raise InputError("The 'F' samples show no presliding force that a Maxwell-slip "
                             "element set with non-negative break-away forces can carry.")
        distances, weights = grid[active], weights[active]
        if elements is not None:
            if isinstance(elements, bool) or not isinstance(elements, (int, np.integer)) \
                    or elements < 1:
                raise InputError(f"The number of 'elements' must be a positive integer. Got "
                                 f"{describe(elements)} instead.")
            step = float(grid[1] / grid[0]) if grid.size > 1 else 2.0
            distances, weights = _resized(distances, weights, int(elements), step)
        params = {"stiffness": (weights / distances).tolist(),
                  "breakaway_force": weights.tolist()}
        if viscous:
            params["viscous_coefficient"] = float(coefficients[-1])
        return cls(**params)


def _resized(distances, weights, count, step):
    """An element set (slip distances, break-away forces) brought to ``count`` elements.

    Merges the neighbours (in slip distance) whose merge moves the least force
    across the least log-distance; splits the strongest element in two a grid
    ``step`` (a ratio) apart.
    """
    distances, weights = list(map(float, distances)), list(map(float, weights))
    while len(distances) > count:
        costs = [min(weights[i], weights[i + 1]) * math.log(distances[i + 1] / distances[i])
                 for i in range(len(distances) - 1)]
        i = int(np.argmin(costs))
        total = weights[i] + weights[i + 1]
        merged = math.exp((weights[i] * math.log(distances[i])
                           + weights[i + 1] * math.log(distances[i + 1])) / total)
        distances[i:i + 2], weights[i:i + 2] = [merged], [total]
    while len(distances) < count:
        i = int(np.argmax(weights))
        half, ratio = 0.5 * weights[i], math.sqrt(step)
        distances[i:i + 1] = [distances[i] / ratio, distances[i] * ratio]
        weights[i:i + 1] = [half, half]
    return np.array(distances), np.array(weights)


# The element fit per sample (480 bytes at 24 slip distances): the data and a path, and
# per slip distance the unit element's response, its stacked and scaled copies.
_ELEMENT_FIT_BYTES = 96.0
_ELEMENT_FIT_BYTES_PER_COLUMN = 24.0
