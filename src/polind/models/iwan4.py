"""Segalman's four-parameter Iwan model (the user guide, :ref:`guide-iwan4`), as a
Maxwell-slip element table.

The model is a density of slip displacements, ``rho(phi) = R phi^chi`` on
``(0, phi_max)`` plus a point mass ``S`` at ``phi_max``; polind steps it as the
Maxwell-slip elements of a quadrature of that density (:func:`element_table`),
with the Maxwell-slip kernels and runners: nothing of the element machinery is
its own.
"""

from __future__ import annotations

import math

import numpy as np

from polind.errors import InputError, describe
from polind.models.base import FrictionModel, StepFunctions, register, scales
from polind.models.params import Param

__all__ = ["Iwan4", "density", "element_table", "innermost_edge"]

#: The smallest amplitude (a fraction of ``phi_max``) the element table is graded for:
#: the energy per cycle is within 1 % of the density's from ``phi_max / 20`` up with the
#: default 64 elements.
SMALLEST_AMPLITUDE = 0.05


def density(slip_force, stiffness, chi, beta) -> tuple:
    """``(phi_max [m], R, S [N/m])`` of the Iwan density of :ref:`guide-iwan4`.

    With ``r = (chi + 1)/(chi + 2)``: ``phi_max = F_S (1 + beta)/(K_T (beta + r))``,
    ``R = F_S (chi + 1)/(phi_max^(chi + 2) (beta + r))`` and
    ``S = (F_S / phi_max) beta/(beta + r)``, so that the density integrates to
    ``K_T`` and its first moment to ``F_S``.
    """
    r = (chi + 1.0) / (chi + 2.0)
    phi_max = slip_force * (1.0 + beta) / (stiffness * (beta + r))
    coefficient = slip_force * (chi + 1.0) / (phi_max ** (chi + 2.0) * (beta + r))
    point = slip_force / phi_max * beta / (beta + r)
    return phi_max, coefficient, point


def innermost_edge(chi, cells) -> float:
    """The upper edge ``s_1`` (a fraction of ``phi_max``) of the innermost cell ``(0, s_1)``.

    Two errors of the energy per cycle are balanced at the smallest amplitude
    ``u = phi_max / 20`` (:data:`SMALLEST_AMPLITUDE`): the innermost cell's,
    exactly ``(s_1/u)^(chi + 3)/(chi + 2)`` relative (one element for all of
    ``(0, s_1)``), and that of the ``cells - 1`` geometric cells above it,
    about ``(ln(1/s_1)/(cells - 1))^2 / 10`` (a cell of ratio ``q`` errs by
    ``O((q - 1)^2)`` relative, mostly in the cell that holds the amplitude).
    The fixed point of the balance is found by iteration (it contracts: the
    log varies slowly).  For 64 elements ``s_1`` is 0.0016 (chi near -1) to
    0.0056 (chi = 0).
    """
    if cells <= 1:
        return 1.0
    edge = SMALLEST_AMPLITUDE / 10.0
    for _ in range(60):
        geometric = (math.log(1.0 / edge) / (cells - 1)) ** 2 / 10.0
        edge = min(SMALLEST_AMPLITUDE * ((chi + 2.0) * geometric) ** (1.0 / (chi + 3.0)), 0.5)
    return edge


def _power_difference(upper, lower, exponent):
    """``upper^exponent - lower^exponent`` (``0 <= lower < upper``), accurate as exponent -> 0."""
    with np.errstate(divide="ignore"):
        ratio = np.where(lower > 0.0, np.log(lower / upper), -np.inf)
    return upper ** exponent * -np.expm1(exponent * ratio)


def element_table(slip_force, stiffness, chi, beta, elements=64) -> tuple:
    """``(k [N/m], W [N])``: the Maxwell-slip elements of the Iwan density, by slip displacement.

    The density's continuous part ``R phi^chi`` on ``(0, phi_max)`` is cut into
    cells: ``(0, s_1 phi_max)`` and above it cells of equal ratio up to
    ``phi_max`` (``s_1``: :func:`innermost_edge`).  Each cell becomes one
    element whose stiffness is the cell's integral of ``rho`` and whose
    break-away force is the cell's integral of ``rho phi`` (its slip
    displacement ``W/k`` is the cell's mean ``phi``, inside the cell): the
    one-point quadrature with the weight ``phi^chi`` exact for the two moments
    of each cell.  With ``beta > 0`` the point mass is one more element,
    ``k = S`` and ``W = S phi_max``.  Therefore ``sum k = K_T`` and
    ``sum W = F_S``, exactly but for rounding (the table is scaled onto them).

    Why graded: the energy per cycle of amplitude ``u0`` is
    ``sum 4 W (u0 - W/k)`` over the elements with ``W/k < u0``, set by the
    slip displacements below ``u0``.  A cell errs relative to the energy by
    about the square of its width over ``u0``, so equal widths would lose the
    small amplitudes (10 % at ``phi_max / 20`` with 64 elements); equal
    ratios give every amplitude the same relative resolution.  Measured with
    64 elements, for ``u0`` in ``[0.05, 0.9] phi_max``: within 0.41 %
    (``chi = 0``) to 0.19 % (``chi`` near -1) of ``4 R u0^(chi+3)/((chi+2)(chi+3))``.
    """
    phi_max, _, point = density(slip_force, stiffness, chi, beta)
    cells = elements - 1 if beta > 0.0 else elements
    edge = innermost_edge(chi, cells)
    edges = np.concatenate([[0.0], np.geomspace(edge, 1.0, cells)]) if cells > 1 \
        else np.array([0.0, 1.0])
    edges[-1] = 1.0
    lower, upper = edges[:-1], edges[1:]
    # Shares of the continuous part's stiffness and first moment (each sums to 1).
    share_k = _power_difference(upper, lower, chi + 1.0)
    share_w = _power_difference(upper, lower, chi + 2.0)
    r = (chi + 1.0) / (chi + 2.0)
    # The continuous part holds K_T - S = F_S/(phi_max (beta + r)) and F_S r/(beta + r).
    k = slip_force / (phi_max * (beta + r)) * share_k / math.fsum(share_k)
    w = slip_force * r / (beta + r) * share_w / math.fsum(share_w)
    if beta > 0.0:
        k = np.append(k, point)
        w = np.append(w, point * phi_max)
    k *= stiffness / math.fsum(k)
    w *= slip_force / math.fsum(w)
    return k, w


@register
class Iwan4(FrictionModel):
    """Segalman's four-parameter Iwan model: ``rho(phi) = R phi^chi + S delta(phi - phi_max)``.

    The force of a density of Jenkins elements (a spring in series with a
    slider) by their slip displacement ``phi``: virgin curve
    ``F(u) = integral rho(phi) min(u, phi) dphi``, Masing unloading, energy per
    cycle ``D = 4 R u0^(chi+3)/((chi+2)(chi+3))`` below ``phi_max`` (so
    ``D ∝ F^(3+chi)`` at small force).  Built as a Maxwell-slip element table
    (:func:`element_table`) with ``sum k = K_T`` and ``sum W = F_S``, stepped
    exactly as Maxwell-slip is; the table is derived, so :func:`polind.identify`
    fits the four parameters.

    Parameters
    ----------
    slip_force : float
        F_S [N], the force of macroslip (every element slipping).
    stiffness : float
        K_T [N/m], the joint's stiffness at rest.
    chi : float
        The exponent of the density, -1 < chi <= 0.
    beta : float
        The point mass's share, >= 0 (0: none).
    elements : int, default 64
        The number of Maxwell-slip elements, >= 2.

    Examples
    --------
    >>> import numpy as np, polind
    >>> joint = polind.model_from_dict({"model": {"type": "iwan4", "slip_force": 1000.0,
    ...     "stiffness": 1e8, "chi": -0.5, "beta": 0.2}})
    >>> k, W = joint.element_table()
    >>> len(k), round(float(k.sum()) / 1e8, 12), round(float(W.sum()), 9)
    (64, 1.0, 1000.0)
    """

    type = "iwan4"
    title = "Segalman's four-parameter Iwan model"
    form = "an Iwan density R phi^chi plus a point mass, as Maxwell-slip elements"
    purpose = "bolted joints: microslip damping D ∝ F^(3+chi) from four parameters"
    guide = "guide-iwan4"
    #: When to use it (the guide's 'Which one to use').
    advice = ("A jointed structure's bolted joint: four parameters (slip force, stiffness, the "
              "exponent of the energy per cycle and the share of macroslip) give the power law "
              r"of microslip damping, :math:`D \propto F^{3+\chi}`, that joint experiments "
              "measure; Masing and rate independent, stepped as Maxwell-slip elements.")

    @classmethod
    def example_parameters(cls, elements=None):
        """A single-bolt lap joint: F_S = 1 kN (friction coefficient 0.2 under a 5 kN bolt
        load), K_T = 1e8 N/m, chi = -0.5, beta = 0.2 (so phi_max = 22.5 um)."""
        return {"slip_force": 1000.0, "stiffness": 1e8, "chi": -0.5, "beta": 0.2}

    parameters = (
        Param("slip_force", unit="N",
          description=("Slip force :math:`F_S`: the force at which the whole joint slips "
                       r"(macroslip); :math:`\sum_i W_i = F_S`."), symbol="F_S"),
        Param("stiffness", unit="N/m",
          description=("Joint stiffness :math:`K_T` at rest, the slope of the virgin curve at "
                       r"zero; :math:`\sum_i k_i = K_T`."), symbol="K_T"),
        Param("chi", bound="iwan_exponent",
          description=(r"Exponent :math:`\chi` of the density :math:`R\varphi^\chi`: the "
                       r"energy per cycle grows as :math:`F^{3+\chi}` at small force."),
          symbol=r"\chi"),
        Param("beta", bound="nonnegative",
          description=(r"Point-mass share :math:`\beta`: the density's mass at "
                       r":math:`\varphi_\max` relative to its continuous part (0: none)."),
          symbol=r"\beta"),
        Param("elements", kind="int", default=64, fittable=False,
          description=("Number of Maxwell-slip elements of the table, at least 2 "
                       "(:ref:`guide-iwan4`)."), symbol="n"),
    )
    phenomena = frozenset({"presliding_memory", "non_drifting"})
    fit_defaults = ("slip_force", "stiffness", "chi", "beta")

    @classmethod
    def _check(cls, params):
        elements = params["elements"]
        if elements < 2:
            raise InputError(f"The 'elements' parameter of {cls.type} must be an integer of at "
                             f"least 2 (a quadrature of the density and its point mass). Got "
                             f"{describe(elements)} instead.")

    def _table(self):
        """The element table, built once per model (the parameters never change)."""
        table = self.__dict__.get("_element_table")
        if table is None:
            p = self._params
            table = element_table(p["slip_force"], p["stiffness"], p["chi"], p["beta"],
                                  p["elements"])
            self._element_table = table
        return table

    def density(self) -> tuple:
        """``(phi_max [m], R, S [N/m])`` of this model (:func:`density`)."""
        p = self._params
        return density(p["slip_force"], p["stiffness"], p["chi"], p["beta"])

    def element_table(self) -> tuple:
        """``(k [N/m], W [N])``: copies of the Maxwell-slip elements the model steps."""
        k, w = self._table()
        return k.copy(), w.copy()

    def to_maxwell_slip(self):
        """The ``maxwell-slip`` model of the same elements (equal forces on any motion)."""
        from polind.models.maxwell_slip import MaxwellSlip

        k, w = self._table()
        extra = {key: self._params[key] for key in ("reference_load", "compliance")
                 if key in self._params}
        return MaxwellSlip(stiffness=k.tolist(), breakaway_force=w.tolist(), **extra)

    def characteristic_scales(self):
        p = self._params
        phi_max = self.density()[0]
        return scales(p["slip_force"], p["slip_force"], 0.0, presliding_range=phi_max,
                      presliding_stiffness=p["stiffness"])

    def initial_variables(self, normal_load=None):
        return {"element_force": np.zeros(self._params["elements"])}

    def step_functions(self):
        # The Maxwell-slip functions and runners: the one element machinery of the family.
        from polind.kernels import elements
        return StepFunctions(elements.maxwell_slip_step, elements.maxwell_slip_force,
                             elements.maxwell_slip_tangent, runners="maxwell_slip")

    def kernel_arrays(self, state):
        k, w = self._table()
        return np.array([0.0]), np.vstack([k, w])

    def force_scale(self):
        return float(self._params["slip_force"])
