"""Parameter identification: fit a friction model to measured force.

The user guide, :ref:`guide-identification`; the ``[fit]`` table, :ref:`formats-fit`.

Three tools, from general to structured:

* :func:`identify` -- bounded nonlinear least squares on the simulated force
  (``scipy.optimize.least_squares``, trust-region-reflective) for any model
  of polind: the model's current values are the starting point, ``free``
  names the keys to identify and ``bounds`` limits them.  Standard errors come
  from the Jacobian at the solution.  This is ``polind fit``.
* :func:`identify_maxwell_slip` and :func:`identify_gms` -- the element set
  of a Maxwell-slip structure (:ref:`guide-maxwell-slip`, :ref:`guide-gms`) from a
  presliding record by
  non-negative least squares, a good starting point for :func:`identify`.
  Once the slip distances ``D_i`` are fixed, element ``i`` of a Maxwell-slip
  model has the deflection ``z_i`` of a spring whose deflection is clipped to
  ``[-D_i, D_i]``; that deflection depends on the path and on ``D_i`` alone,
  and the element force is ``k_i z_i = W_i (z_i / D_i)``.  The total force is
  therefore *linear* in the break-away forces: ``F = A W`` with
  ``A[k, i] = z_i(x_k) / D_i`` in ``[-1, 1]``, and ``W >= 0`` is an NNLS
  problem over a grid of slip distances.
* :func:`identify_stribeck` -- the static Stribeck curve (:ref:`guide-stribeck-curve`)
  from steady-state ``(v, F)`` points.

:func:`plot_fit` draws measured against fitted force (``polind fit --plot``), and
:func:`compare` fits several models to one record and ranks them (``polind compare``,
:ref:`guide-compare`).

Parametrisation
---------------
The optimiser works on internal variables that all start at 0:

* a parameter declared positive (stiffnesses, forces, velocities, the
  attraction ``C``, ...) is fitted on a log scale, ``p = p0 exp(u)``: it
  stays strictly positive (the default lower bound 0 is exclusive), and a
  step means the same *relative* change whether ``p`` is 1e-6 or 1e6;
* any other number (non-negative ones such as ``viscous_coefficient`` and
  ``bristle_damping``, which may start at and reach 0) is fitted on a linear
  scale ``p = p0 + s u``, ``s = |p0|`` or, for a start of 0, a scale set by
  the parameter's unit and the data (e.g. RMS force / RMS velocity for
  N s/m);
* a list (``stiffness``) is free as a whole vector, each entry mapped as
  above; a weight vector that must sum to 1 (``weight`` of GMS) is mapped
  through ``w = softmax(u_1 .. u_{n-1}, 0)`` so it stays positive and sums
  to 1 (it takes no bounds);
* the Leuven ``breakaway_force`` list must sum to ``static_force``: when
  ``breakaway_force`` is free, ``static_force`` follows its sum; when only
  ``static_force`` is free, ``breakaway_force`` is scaled with it.

The Jacobian is taken by forward differences of a fixed step in these
variables.  A trial point whose parameters the model rejects (a load its
surface cannot carry, say) or where its force is not finite costs a large
constant residual, so the solver backs off instead of stopping.

Standard errors are ``sqrt(diag(cov))`` with ``cov = s^2 (J^T J)^-1``,
``s^2 = RSS / (n - p)``, ``J`` the Jacobian of the force residuals at the
solution, carried to the physical parameters by the derivative of the
mapping (the delta method).  A direction the data cannot determine (``J``
rank-deficient) gives an infinite standard error to every parameter it
involves.

Several starts (:ref:`guide-fit-starts`)
----------------------------------------
:func:`identify` fits from the model's values, from the fit of the special case
the model contains (:meth:`polind.FrictionModel.special_case`), from the model's
structured starts (:meth:`polind.FrictionModel.structured_starts`) and from
:data:`DEFAULT_SPREAD_STARTS` Latin-hypercube points in the bounds, and keeps the
fit with the smallest sum of squares in sample (``starts=N`` sets the number).
A free value whose Jacobian column is zero at a start cannot move the force
there: it is fixed at that start, not iterated on, and reported.

Safe fits (:ref:`guide-fit-warnings`)
-------------------------------------
A free key without ``[fit.bounds]`` gets default bounds derived from the
fitted data by its unit (:func:`default_bounds`; the table is there and on the
documentation's file formats page), never an unbounded range.  Every fit lists its ``warnings``: a
parameter that ended at a bound, one the data do not determine (standard
error larger than its value, or not finite), a data column or signal the
model does not use, a start outside the default bounds, a solver that
stopped early; and whether the fit as a whole is credible: an RMS error above
the record's noise, estimated from its high-frequency part (:func:`noise_level`),
a force level beyond the largest measured force that a free value set,
residuals with structure (a runs test), a held-out error far above the
in-sample one.  ``holdout=F`` fits the first
``1 - F`` of the record and scores the prediction of the rest.  The columns of
the finite-difference Jacobian run on threads (the numba kernels release the
GIL).

Comparing models
----------------
:func:`compare` fits every model on the same samples and tabulates, per model, the
free values, the RMS error in sample and held out, and the Akaike and Bayesian
criteria of the fitted part, ``AIC = n ln(RSS / n) + 2 k`` and
``BIC = n ln(RSS / n) + k ln n`` (:attr:`polind.FitResult.aic`), with ``n``
fitted samples, ``RSS`` the sum of their squared residuals and ``k`` the free
values; only differences between rows mean anything (lower is better).

Modules
-------
One idea each; everything public is imported here:

* ``data`` -- the measured data, their checks and the hold-out split;
* ``parameters`` -- free keys, bounds (default ones from the data) and the
  optimiser's variables;
* ``starts`` -- where the fits start (:ref:`guide-fit-starts`): the model's
  values, the fit of the special case it contains, its structured starts,
  Latin-hypercube points (:func:`spread_points`);
* ``solver`` -- :func:`identify`: the least-squares solve from every start, a
  free value that cannot move the force fixed (:data:`STILL_COLUMN`), a start stopped
  once it gains less than the noise (:data:`NOISE_SHARE`) or its step moves the force
  by less than the noise can show (:data:`STEP_SHARE`), the noise's variance taken
  with the residuals' correlation (:func:`autocorrelation_time`), its threads;
* ``threads`` -- the fit's threads, and one BLAS thread for its matrix products;
* ``results`` -- :class:`polind.FitResult`, its standard errors and warnings;
* ``credibility`` -- the warnings on a fit as a whole (:ref:`guide-fit-warnings`):
  an error above the record's noise (:func:`noise_level`), a force level beyond the
  data, residuals with structure (:func:`runs_test`), a held-out error far above the
  in-sample one;
* ``memory`` -- the memory a fit holds per sample;
* ``structure`` -- the structured fits :func:`identify_maxwell_slip`,
  :func:`identify_gms` and :func:`identify_stribeck`, which check the data and call
  the models' own constructors (:meth:`polind.models.MaxwellSlip.from_presliding`,
  :meth:`polind.models.GMS.from_presliding`,
  :meth:`polind.models.Stribeck.from_steady_points`);
* ``comparison`` -- :func:`compare` and :class:`polind.Comparison`;
* ``plot`` -- :func:`plot_fit`.
"""

from polind.identification.comparison import COLOURS, COLUMNS, Comparison, compare
from polind.identification.credibility import (BREAKAWAY_LEVEL, CORRELATION_WINDOW, HOLDOUT_RATIO,
                                               NOISE_CLIP, NOISE_ORDER, NOISE_RATIO, RUNS_Z,
                                               SLIDING_LEVEL, STRUCTURE_TIME,
                                               autocorrelation_time, noise_level, runs_test)
from polind.identification.data import MeasuredData, holdout_split, measured_data
from polind.identification.memory import fit_bytes_per_sample
from polind.identification.parameters import (DEFAULT_RANGES, UNSCALED_RANGE, default_bounds,
                                              fittable_keys, parse_fit)
from polind.identification.plot import plot_fit
from polind.identification.results import FitResult
from polind.identification.solver import NOISE_SHARE, STEP_SHARE, STILL_COLUMN, identify
from polind.identification.starts import DEFAULT_SPREAD_STARTS, SPREAD_SPAN, spread_points
from polind.identification.structure import (identify_gms, identify_maxwell_slip,
                                              identify_stribeck)

__all__ = ["FitResult", "identify", "parse_fit", "default_bounds", "identify_maxwell_slip",
           "identify_gms", "identify_stribeck", "plot_fit", "fit_bytes_per_sample",
           "fittable_keys", "measured_data", "MeasuredData", "holdout_split", "DEFAULT_RANGES",
           "UNSCALED_RANGE", "COLUMNS", "COLOURS", "Comparison", "compare",
           "DEFAULT_SPREAD_STARTS", "SPREAD_SPAN", "spread_points", "STILL_COLUMN",
           "NOISE_SHARE", "STEP_SHARE",
           "SLIDING_LEVEL", "BREAKAWAY_LEVEL", "RUNS_Z", "STRUCTURE_TIME", "HOLDOUT_RATIO",
           "NOISE_RATIO", "NOISE_ORDER", "NOISE_CLIP", "noise_level",
           "runs_test", "autocorrelation_time", "CORRELATION_WINDOW"]
