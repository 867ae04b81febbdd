"""Structured fits: starting models from the structure of a model, not from a start.

Each is a wrapper of a model's own constructor: it checks the data as
:func:`identify` does and calls the constructor (and, for the Stribeck curve,
refines its estimate with :func:`identify`).

* :func:`identify_maxwell_slip` and :func:`identify_gms` -- the element set
  of a Maxwell-slip structure (:ref:`guide-maxwell-slip`, :ref:`guide-gms`)
  from a presliding record by non-negative least squares, a good starting
  point for :func:`identify` (:meth:`polind.models.MaxwellSlip.from_presliding`,
  :meth:`polind.models.GMS.from_presliding`).
* :func:`identify_stribeck` -- the static Stribeck curve
  (:ref:`guide-stribeck-curve`) from steady-state ``(v, F)`` points
  (:meth:`polind.models.Stribeck.from_steady_points`, then :func:`identify`).
"""

from __future__ import annotations

import numpy as np

from polind.errors import InputError
from polind.identification.data import measured_data
from polind.identification.results import FitResult
from polind.identification.solver import identify
from polind.models import GMS, MaxwellSlip, Stribeck
from polind.simulation import as_samples

__all__ = ["identify_maxwell_slip", "identify_gms", "identify_stribeck"]


def _slip_distances(slip_distances):
    """The given grid of slip distances, checked as data (None: the constructor's default)."""
    if slip_distances is None:
        return None
    grid = as_samples("slip_distances", slip_distances, positive=True)
    if grid.size == 0:
        raise InputError("The 'slip_distances' must hold at least one distance [m]. Got none.")
    return grid


def identify_maxwell_slip(data, slip_distances=None, n=24, *, viscous=False) -> MaxwellSlip:
    """A Maxwell-slip element set from a presliding record, by non-negative least squares.

    With the slip distances ``D_i`` fixed on a grid, the force is linear in
    the break-away forces: ``F = sum_i W_i z_i(x) / D_i (+ sigma2 v)``, where
    ``z_i`` is the deflection of element ``i``, clipped to ``[-D_i, D_i]``
    along the path (it depends on the path and ``D_i`` only).
    ``scipy.optimize.nnls`` finds ``W_i >= 0``; elements with ``W_i = 0`` are
    dropped, and ``k_i = W_i / D_i``.  The elements start unloaded at the
    first sample.  Noiseless data from a Maxwell-slip model whose slip
    distances are on the grid are recovered exactly.  The data are checked
    as :func:`identify` checks them; the fit is
    :meth:`polind.models.MaxwellSlip.from_presliding`.

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
        Also fit ``viscous_coefficient`` (sigma2 >= 0 [N s/m], a column ``v``).

    Returns
    -------
    FrictionModel
        A ``maxwell-slip`` model (elements ordered by slip distance).

    Raises
    ------
    InputError
        Bad data (as :func:`identify`, and a ``normal_load`` column, which
        the element fit does not use), a bad ``slip_distances`` or ``n``, a
        fit whose estimated memory passes the limit of
        :mod:`polind.resources`, or a force that no element set carries.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.identification import identify_maxwell_slip
    >>> from polind.models import MaxwellSlip
    >>> true = MaxwellSlip(stiffness=[1e6, 1e5], breakaway_force=[1.0, 2.0])
    >>> t = np.linspace(0.0, 1.0, 401)
    >>> x = 4e-5 * np.sin(2 * np.pi * t) * (1 - t)
    >>> data = {"t": t, "x": x, "F": polind.simulate(true, t, x=x).force}
    >>> fit = identify_maxwell_slip(data, slip_distances=[1e-6, 5e-6, 2e-5])
    >>> np.round(fit.params["breakaway_force"], 9).tolist()
    [1.0, 2.0]
    """
    measured = measured_data(data, normal_load_ok=False)
    grid = _slip_distances(slip_distances)
    return MaxwellSlip.from_presliding(measured.path(), measured.force, grid, n,
                                       viscous=viscous)


def identify_gms(data, slip_distances=None, n=24, *, model=None) -> GMS:
    """A GMS starting model: element stiffnesses and weights from :func:`identify_maxwell_slip`.

    GMS with ``Fs = Fc`` and a large attraction ``C`` is the Maxwell-slip
    model with ``W_i = alpha_i Fc`` (:ref:`guide-gms`), so the NNLS element set
    gives ``alpha_i = W_i / sum W`` and ``k_i``; the Coulomb force is
    ``sum W`` (the sliding force of the record).  The data are checked as
    :func:`identify_maxwell_slip` checks them; the fit is
    :meth:`polind.models.GMS.from_presliding`.

    Parameters
    ----------
    data, slip_distances, n
        As :func:`identify_maxwell_slip`.
    model : FrictionModel, optional
        A ``gms`` model whose ``attraction`` [N/s], Stribeck velocity [m/s],
        exponent, shape and ``viscous_coefficient`` [N s/m] are kept, and
        whose ratio ``static_force / coulomb_force`` is applied.  Without it:
        ``Fs = Fc = sum W``, ``stribeck_velocity`` the median speed of the
        moving samples, and ``C = 10 v max_i k_i`` with ``v`` that speed (a
        slip relaxation length ``alpha_i g / C`` well below every slip
        distance, i.e. close to Maxwell-slip).

    Returns
    -------
    FrictionModel
        A ``gms`` model.

    Raises
    ------
    InputError
        As :func:`identify_maxwell_slip`, or a ``model`` that is not a
        ``gms`` model.
    """
    measured = measured_data(data, normal_load_ok=False)
    grid = _slip_distances(slip_distances)
    return GMS.from_presliding(measured.path(), measured.force, grid, n, model=model)


def identify_stribeck(v, F, *, model=None, free=None, bounds=None, stribeck_shape="exponential",
                      **options) -> FitResult:
    """The Stribeck curve ``F = g(v) sgn(v) + sigma2 v`` from steady-state points.

    The start is :meth:`polind.models.Stribeck.from_steady_points` (or the
    ``model`` given), refined by :func:`identify` on the points.

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
    start = Stribeck.from_steady_points(v, force, stribeck_shape=stribeck_shape, model=model)
    if free is None:
        free = ["coulomb_force", "static_force", "stribeck_velocity", "stribeck_exponent"]
    # A memoryless model's force at sample k depends on v[k] only: the points form a "path".
    points = {"t": np.arange(v.shape[0], dtype=np.float64), "v": v, "F": force}
    return identify(start, points, free=free, bounds=bounds, **options)
