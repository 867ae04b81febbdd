"""The six friction phenomena (:ref:`guide-phenomena`): the experiments, their metrics and their checks.

Each experiment runs one friction model through a prescribed motion
(:func:`polind.simulate`) or a one-degree-of-freedom system (:ref:`guide-systems`)
(:func:`polind.dynamics.simulate_system`) and returns a
:class:`PhenomenonResult`: the arrays its figure shows (``data``), the
numbers that measure the phenomenon (``metrics``), the inputs used
(``settings``) and ``passed`` -- whether the phenomenon *appears* in this
run, decided by a check that can fail.  ``expected`` says whether the user
guide credits the model with the phenomenon (:ref:`guide-choosing-table`); a model behaves as documented when
the two agree (:attr:`PhenomenonResult.as_expected`).  So LuGre's
non-drifting result has ``passed = False`` (it drifts: Dupont et al. 2002)
and ``expected = False``; Maxwell-slip, being rate independent, shows no
Stribeck effect and no frictional lag.

Every length, time and force of an experiment is scaled by the model's own
levels (:func:`friction_levels`): its static and Coulomb forces, Stribeck
velocity, presliding range and lag time.  The same experiment then fits the
1 N LuGre model of 1995 and a 15 N Pol-Ind contact whose presliding range is
a few tens of nanometres.

When ``passed`` is true (the phenomenon appears):

* :func:`stribeck_effect`: the steady force at ``1e-3 vs`` exceeds the
  curve's minimum by more than 1 % (the dip) and every steady force matches
  the analytic curve within 1e-6;
* :func:`presliding_memory`: every inner loop closes on its starting
  reversal point and the path then follows the branch it would have
  followed without the loop, within 1e-6 of the loop's force span
  (wipe-out: non-local memory);
* :func:`frictional_lag`: every loop circulates in the lag direction (the
  force is higher while v rises), with an area above 1e-6 of the box
  ``2 va Fs``, and the area grows with the frequency;
* :func:`non_drifting`: the advance per cycle of the force-driven body dies
  away: the last cycle's is below 1e-3 of the first's (or below 1e-6 of the
  presliding range);
* :func:`stick_slip`: at the low drive velocity the body sticks and slips
  periodically, at the high one it slides steadily;
* :func:`breakaway`: at the slowest force ramp the break-away force is
  within 2 % of the static level Fs.

The package holds one module per experiment and one for what they share:

* :mod:`polind.phenomena.common`: :class:`FrictionLevels`,
  :func:`friction_levels`, :class:`PhenomenonResult`, :data:`PHENOMENA
  <polind.phenomena.common.PHENOMENA>`, :func:`velocity_scale`,
  :func:`cycle_area` and the one-degree-of-freedom body of the last three
  experiments;
* :mod:`polind.phenomena.steady`: :func:`stribeck_effect`;
* :mod:`polind.phenomena.presliding`: :func:`presliding_memory`;
* :mod:`polind.phenomena.lag`: :func:`frictional_lag`;
* :mod:`polind.phenomena.drift`: :func:`non_drifting`;
* :mod:`polind.phenomena.stickslip_runs`: :func:`stick_slip`;
* :mod:`polind.phenomena.breakaway_ramps`: :func:`breakaway`.

Every public name is importable from :mod:`polind.phenomena` itself.
"""

from polind.phenomena.breakaway_ramps import breakaway
from polind.phenomena.common import (
    PHENOMENA,
    FrictionLevels,
    PhenomenonResult,
    cycle_area,
    friction_levels,
    velocity_scale,
)
from polind.phenomena.drift import non_drifting
from polind.phenomena.lag import frictional_lag
from polind.phenomena.presliding import (
    MEMORY_BRANCHES,
    MEMORY_CLOSURES,
    MEMORY_PATH,
    MEMORY_TOLERANCE,
    presliding_memory,
)
from polind.phenomena.steady import stribeck_effect
from polind.phenomena.stickslip_runs import stick_slip

__all__ = [
    "PHENOMENA",
    "FrictionLevels",
    "PhenomenonResult",
    "friction_levels",
    "velocity_scale",
    "cycle_area",
    "MEMORY_PATH",
    "MEMORY_CLOSURES",
    "MEMORY_BRANCHES",
    "MEMORY_TOLERANCE",
    "stribeck_effect",
    "presliding_memory",
    "frictional_lag",
    "non_drifting",
    "stick_slip",
    "breakaway",
]
