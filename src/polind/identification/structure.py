"""Structured fits: starting models from the structure of a model, not from a start.

* :func:`identify_maxwell_slip` and :func:`identify_gms` -- the element set
  of a Maxwell-slip structure (:ref:`guide-maxwell-slip`, :ref:`guide-gms`)
  from a presliding record by non-negative least squares, a good starting
  point for :func:`identify`.
* :func:`identify_stribeck` -- the static Stribeck curve
  (:ref:`guide-stribeck-curve`) from steady-state ``(v, F)`` points.
"""

from __future__ import annotations

import numpy as np

from polind.errors import InputError
from polind.identification.data import MeasuredData, measured_data
from polind.identification.results import FitResult
from polind.identification.solver import identify
from polind.models import FrictionModel, model_from_dict
from polind.resources import check_memory
from polind.simulate import as_samples, simulate
from polind.validation import describe

__all__ = ["identify_maxwell_slip", "identify_gms", "identify_stribeck"]

# The element fit per sample (480 bytes at 24 slip distances): the data and a path, and
# per slip distance the unit element's response, its stacked and scaled copies.
_ELEMENT_FIT_BYTES = 96.0
_ELEMENT_FIT_BYTES_PER_COLUMN = 24.0


def _slip_grid(path, slip_distances, n):
    if slip_distances is None:
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1):
            raise InputError(f"The number of slip distances 'n' must be a positive integer. "
                             f"Got {describe(n)} instead.")
        span = float(np.ptp(path.x))
        return np.geomspace(span * 1e-3, span, int(n))
    grid = as_samples("slip_distances", slip_distances, positive=True)
    if grid.size == 0:
        raise InputError("The 'slip_distances' must hold at least one distance [m]. Got none.")
    return np.unique(grid)


def _element_responses(data: MeasuredData, grid):
    """A[k, i] = z_i(x_k) / D_i: the clipped deflection of a unit element of slip distance D_i."""
    columns = []
    for distance in grid:
        unit = model_from_dict({"model": {"type": "maxwell-slip", "stiffness": [1.0],
                                          "breakaway_force": [float(distance)]}})
        columns.append(simulate(unit, data.t, **data.motion()).force / distance)
    return np.column_stack(columns)


def identify_maxwell_slip(data, slip_distances=None, n=24, *, viscous=False):
    """A Maxwell-slip element set from a presliding record, by non-negative least squares.

    With the slip distances ``D_i`` fixed on a grid, the force is linear in
    the break-away forces: ``F = sum_i W_i z_i(x) / D_i (+ sigma2 v)``, where
    ``z_i`` is the deflection of element ``i``, clipped to ``[-D_i, D_i]``
    along the path (it depends on the path and ``D_i`` only).
    ``scipy.optimize.nnls`` finds ``W_i >= 0``; elements with ``W_i = 0`` are
    dropped, and ``k_i = W_i / D_i``.  The elements start unloaded at the
    first sample.  Noiseless data from a Maxwell-slip model whose slip
    distances are on the grid are recovered exactly.

    Parameters
    ----------
    data : mapping of str to array_like
        ``t`` [s], one of ``x`` [m] / ``v`` [m/s], ``F`` [N].
    slip_distances : array_like, optional
        The grid of slip distances [m]; default ``n`` distances spaced
        logarithmically from 1e-3 to 1 times the displacement range of the data.
    n : int
        Number of grid points when ``slip_distances`` is not given.
    viscous : bool
        Also fit ``viscous_coefficient`` (sigma2 >= 0, a column ``v``).

    Returns
    -------
    FrictionModel
        A ``maxwell-slip`` model (elements ordered by slip distance).

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import identify_maxwell_slip
    >>> true = polind.model_from_dict({"model": {"type": "maxwell-slip",
    ...     "stiffness": [1e6, 1e5], "breakaway_force": [1.0, 2.0]}})
    >>> t = np.linspace(0.0, 1.0, 401)
    >>> x = 4e-5 * np.sin(2 * np.pi * t) * (1 - t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    >>> fit = identify_maxwell_slip(data, slip_distances=[1e-6, 5e-6, 2e-5])
    >>> np.round(fit.params["breakaway_force"], 9).tolist()
    [1.0, 2.0]
    """
    from scipy.optimize import nnls

    measured = measured_data(data, normal_load_ok=False)
    path = measured.path()
    grid = _slip_grid(path, slip_distances, n)
    columns = grid.size + bool(viscous)
    check_memory(measured.size * (_ELEMENT_FIT_BYTES + _ELEMENT_FIT_BYTES_PER_COLUMN * columns),
                 f"The element fit of {grid.size} slip distances to {measured.size:.3g} "
                 f"samples of data")
    design = _element_responses(measured, grid)
    if viscous:
        design = np.column_stack([design, path.sample_velocity])
    # Columns of very different size (the viscous one) are scaled to unit norm for NNLS.
    norms = np.linalg.norm(design, axis=0)
    norms[norms == 0.0] = 1.0
    coefficients, _ = nnls(design / norms, measured.force, maxiter=50 * design.shape[1])
    coefficients = coefficients / norms
    weights = coefficients[:grid.size]
    active = weights > 1e-12 * max(weights.max(initial=0.0), 1e-300)
    if not active.any():
        raise InputError("The 'F' samples show no presliding force that a Maxwell-slip element "
                         "set with non-negative break-away forces can carry.")
    params = {"stiffness": (weights[active] / grid[active]).tolist(),
              "breakaway_force": weights[active].tolist()}
    if viscous:
        params["viscous_coefficient"] = float(coefficients[-1])
    return model_from_dict({"model": {"type": "maxwell-slip", **params}})


def identify_gms(data, slip_distances=None, n=24, *, model=None):
    """A GMS starting model: element stiffnesses and weights from :func:`identify_maxwell_slip`.

    GMS with ``Fs = Fc`` and a large attraction ``C`` is the Maxwell-slip
    model with ``W_i = alpha_i Fc`` (:ref:`guide-gms`), so the NNLS element set
    gives ``alpha_i = W_i / sum W`` and ``k_i``; the Coulomb force is
    ``sum W`` (the sliding force of the record).

    Parameters
    ----------
    data, slip_distances, n
        As :func:`identify_maxwell_slip`.
    model : FrictionModel, optional
        A ``gms`` model whose ``attraction``, Stribeck velocity, exponent,
        shape and ``viscous_coefficient`` are kept, and whose ratio
        ``static_force / coulomb_force`` is applied.  Without it:
        ``Fs = Fc = sum W``, ``stribeck_velocity`` the median speed of the
        moving samples, and ``C = 10 v max_i k_i`` with ``v`` that speed (a
        slip relaxation length ``alpha_i g / C`` well below every slip
        distance, i.e. close to Maxwell-slip).

    Returns
    -------
    FrictionModel
        A ``gms`` model.
    """
    slip = identify_maxwell_slip(data, slip_distances, n)
    stiffness = np.asarray(slip.params["stiffness"])
    breakaway = np.asarray(slip.params["breakaway_force"])
    total = float(breakaway.sum())
    weight = breakaway / total
    weight[-1] = 1.0 - weight[:-1].sum()
    elements = {"stiffness": stiffness.tolist(), "weight": weight.tolist()}
    if model is not None:
        if not isinstance(model, FrictionModel) or model.type != "gms":
            raise InputError(f"The 'model' of identify_gms must be a gms model. Got "
                             f"{describe(model)} instead.")
        p = model.params
        ratio = p["static_force"] / p["coulomb_force"]
        return model.with_params(**elements, coulomb_force=total, static_force=total * ratio)
    measured = measured_data(data, normal_load_ok=False)
    speed = np.abs(measured.path().sample_velocity)
    typical = float(np.median(speed[speed > 0.0]))
    return model_from_dict({"model": {"type": "gms", **elements,
                                      "attraction": 10.0 * typical * float(stiffness.max()),
                                      "coulomb_force": total, "static_force": total,
                                      "stribeck_velocity": typical}})


def identify_stribeck(v, F, *, model=None, free=None, bounds=None, stribeck_shape="exponential",
                      **options) -> FitResult:
    """The Stribeck curve ``F = g(v) sgn(v) + sigma2 v`` from steady-state points.

    Parameters
    ----------
    v : array_like
        Sliding velocities [m/s] of the steady-state points (either sign).
    F : array_like
        The steady friction force at each [N].
    model : FrictionModel, optional
        A ``stribeck`` model to start from.  Default: estimates from the
        points -- ``Fc`` the median ``|F|`` of the fastest fifth, ``Fs`` the
        largest ``|F|`` of the slowest fifth, ``vs`` the speed where ``|F|``
        is nearest to halfway between them, ``delta = 2``, ``sigma2 = 0``.
    free : list of str, optional
        Default ``coulomb_force, static_force, stribeck_velocity,
        stribeck_exponent``; add ``viscous_coefficient`` to fit sigma2.
    bounds : dict, optional
        As :func:`identify`.
    stribeck_shape : {"exponential", "rational"}
        The shape of the default starting model.
    **options
        Passed to :func:`identify` (``max_evaluations``, ``tolerance``, ...).

    Returns
    -------
    FitResult
        Its ``model`` is a ``stribeck`` model.

    Examples
    --------
    >>> import numpy as np
    >>> from polind.identification import identify_stribeck
    >>> v = np.geomspace(1e-5, 1e-1, 30)
    >>> F = 1.0 + 0.5 * np.exp(-(v / 1e-3) ** 2)
    >>> fit = identify_stribeck(v, F)
    >>> [round(fit.values[k], 6) for k in ("coulomb_force", "static_force", "stribeck_velocity")]
    [1.0, 1.5, 0.001]
    """
    v = as_samples("v", v)
    force = as_samples("F", F, v.shape[0])
    if model is None:
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
        model = model_from_dict({"model": {"type": "stribeck", "coulomb_force": coulomb,
                                           "static_force": static, "stribeck_velocity": velocity,
                                           "stribeck_exponent": 2.0,
                                           "stribeck_shape": stribeck_shape}})
    elif not isinstance(model, FrictionModel) or model.type != "stribeck":
        raise InputError(f"The 'model' of identify_stribeck must be a stribeck model. Got "
                         f"{describe(model)} instead.")
    if free is None:
        free = ["coulomb_force", "static_force", "stribeck_velocity", "stribeck_exponent"]
    # A memoryless model's force at sample k depends on v[k] only: the points form a "path".
    points = {"t": np.arange(v.shape[0], dtype=np.float64), "v": v, "F": force}
    return identify(model, points, free=free, bounds=bounds, **options)
