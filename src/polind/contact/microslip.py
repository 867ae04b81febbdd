"""Microslip asperities: the Cattaneo–Mindlin law as Maxwell-slip sub-elements.

See :ref:`guide-pol-ind-microslip`.

A Hertzian sphere of contact radius ``a`` under the normal load ``P`` obeys
Cattaneo–Mindlin, whose loops follow Masing's rule; at constant ``P`` that law
*is* an Iwan (Maxwell-slip) model: a continuum of elastic-slip elements of slip
displacement ``phi`` in ``(0, u*)``, ``u* = 3 mu P / (16 G* a)``, with the
stiffness density

    k(phi) = (3 mu P / (4 u*^2)) (1 - phi / u*)^(-1/2),

whose total stiffness is ``8 G* a`` and total capacity ``mu P``.  With
``s = phi / u*`` the density is ``4 G* a (1 - s)^(-1/2)``, its virgin curve
``Q(u) = mu P [1 - (1 - u / u*)^(3/2)]`` (Cattaneo) and its loop energy at the
amplitude ``Q = q mu P`` (Mindlin–Deresiewicz)::

    D(q) = (9 mu^2 P^2 / (10 a G*)) f(q),
    f(q) = 1 - (1 - q)^(5/3) - (5 q / 6) (1 + (1 - q)^(2/3))
         = q^3 (1 + 3 p + p^2) / (6 (1 + p + p^2)^3),  p = (1 - q)^(1/3)

(the second form has no cancellation at small ``q``; ``f ~ 5 q^3 / 162``,
Goodman's cubic law ``D ~ Q^3 / (36 a G* mu P)``).

:func:`microslip_table` replaces each element ``j`` of a Pol-Ind table (a bin,
a summit, an elastic-plastic summit with its own contact radius) by ``m``
sub-elements: sub-element ``i`` has the stiffness ``c_i k_j``, the slip
displacement ``s_i u*_j`` and the capacity ``w_i W_j``, ``w_i = (3/2) c_i s_i``,
where ``u*_j = (3/2) W_j / k_j`` is the element's ``3 mu P_j / (16 G* a_j)``
(``k_j = 8 G* a_j``, ``W_j = mu_s P_j``, times ``n_j``).  ``sum c_i = 1`` and
``sum w_i = 1`` to rounding, so ``sum k = 8 G* a_j`` and ``sum W = mu_s P_j``
and every limit of the Pol-Ind law holds unchanged.

**The placement rule** (:func:`microslip_fractions`).
An m-element Iwan model's loop energy, against the force amplitude, is a
polyline: linear between the amplitudes at which its elements start to slip,
with a vertex at each.  Conversely every polyline that starts on ``D = 0``,
ends at ``q = 1`` and has increasing slopes is the loop energy of one Iwan
model, whose total stiffness and capacity are the continuum's (the recursion
in ``_iwan_of_polyline``).  So the sub-elements are placed for the
energy, not by a polynomial quadrature of the density (16 Gauss–Jacobi nodes
err by 22 % at ``q = 0.1``):

* the vertices ``q_2 < ... < q_m = 1`` lie on ``D``, evenly spaced in
  ``z(q) = int sqrt(f'' / (8 f)) dq``, which makes the relative error of the
  chords the same on every interval (``(dz)^2`` each); at small ``q`` this
  is evenly in ``log q`` (``z ~ (sqrt(3)/2) log q``), and near full slip it
  packs the vertices where ``f'' ~ (1 - q)^(-4/3)`` bends the curve;
* nine intervals in ten span the range where the loop energy must be right,
  ``q`` in [0.05, 1]; the rest, ``ceil((m - 2) / 10)`` of them, span the
  decade below it, [0.005, 0.05], which a rough surface's small amplitudes
  reach through its tallest summits;
* the first vertex, where the first sub-element slips at zero energy, is at
  ``2 q_2 / 3``: the tangent of the cubic law at ``q_2`` (so the slopes
  increase and every stiffness is positive; that one sub-element carries
  3/4 of the continuum's stiffness below ``q_2``, which leaves the other
  slip displacements 0.04 % short);
* every vertex energy is lowered by half the largest relative excess of the
  chords over ``D`` on [0.05, 1], so the error there alternates between
  ``+e`` and ``-e``;
* with fewer than 12 sub-elements (no decade below 0.05) the vertices are
  instead the edges of bins of the density, one sub-element at each bin's
  centroid (``_binned``): a polyline of so few vertices would need slip
  displacements beyond ``u*``.

Measured against ``D(q)`` (``q`` in [0.05, 0.95]): 0.90 % at the default
``m = 32``, 0.22 % at 64, 0.051 % at 128 and 0.0008 % at 1024 (16
sub-elements: 4.7 %; below 16 the energy is coarse); the log-log slope on
[0.05, 0.1] is 3.074 at 32 and 3.052 at 128 (the law's own: 3.051).  The
virgin curve is Cattaneo's within 0.12 % of ``mu P`` at 32 and 0.02 % at
128 or more.

Under a varying normal load the element machinery re-evaluates each row as
an elastic-slip element (one slip distance per element), so a model with
microslip sub-elements runs at its constant normal load
(:ref:`guide-pol-ind-microslip`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np

__all__ = ["MICROSLIP_ELEMENTS", "MICROSLIP_RANGE", "TANGENTIAL_LAWS", "mindlin_energy_ratio",
           "mindlin_loop_energy", "check_constant_load", "microslip_fractions", "microslip_of", "microslip_table"]

#: Sub-elements per element by default (``discretisation.microslip_elements``).
MICROSLIP_ELEMENTS = 32
#: The allowed range of ``discretisation.microslip_elements``.
MICROSLIP_RANGE = (2, 1024)

# The range of q the loop energy must follow (even error), the decade below it, and
# one interval in _COARSE_SHARE spent there.
_FINE_START = 0.05
_COARSE_START = 0.005
_COARSE_SHARE = 10
# Units: stiffness in 8 G* a, displacement in u*, so Q in 8 G* a u* (q = 1.5 Q) and D
# in 8 G* a u*^2, where the Mindlin-Deresiewicz factor 9 mu^2 P^2 / (10 a G*) is 3.2.
_Q_PER_FORCE = 2.0 / 3.0
_D_PER_ENERGY = 3.2


def mindlin_energy_ratio(q):
    """``f(q)``: Mindlin–Deresiewicz's loop energy over ``9 mu^2 P^2 / (10 a G*)`` (vectorised).

    ``q = Q / (mu P)`` in [0, 1], the force amplitude over the slip force;
    computed as ``q^3 (1 + 3 p + p^2) / (6 (1 + p + p^2)^3)``,
    ``p = (1 - q)^(1/3)``, without cancellation at small ``q``.

    Examples
    --------
    >>> round(float(mindlin_energy_ratio(1.0)), 12)       # full slip: 1/6
    0.166666666667
    >>> round(float(mindlin_energy_ratio(1e-3) / (5 * 1e-9 / 162)), 4)   # Goodman's cubic law
    1.0007
    """
    q = np.asarray(q, dtype=float)
    p = np.cbrt(1.0 - q)
    return q ** 3 * (1.0 + 3.0 * p + p * p) / (6.0 * (1.0 + p + p * p) ** 3)


def mindlin_loop_energy(amplitude, P, a, mu, G_star):
    """Energy [J] one Cattaneo–Mindlin sphere dissipates per cycle of tangential amplitude ``Q`` [N].

    ``D = (9 mu^2 P^2 / (10 a G*)) f(Q / (mu P))`` (:func:`polind.contact.microslip.mindlin_energy_ratio`),
    for ``|Q| <= mu P`` at the constant normal load ``P`` [N], contact radius
    ``a`` [m] and effective shear modulus ``G*`` [Pa].
    """
    q = np.abs(np.asarray(amplitude, dtype=float)) / (mu * P)
    return 9.0 * mu * mu * P * P / (10.0 * a * G_star) * mindlin_energy_ratio(np.minimum(q, 1.0))


def _energy_curvature(q):
    """``sqrt(f'' / (8 f))`` (``f'' = (5/27) q (1 - q)^(-4/3)``), the density of ``z``."""
    p = np.cbrt(1.0 - q)
    s = 1.0 + p + p * p
    return np.sqrt(5.0 / 36.0 * s ** 3 / (p ** 4 * (1.0 + 3.0 * p + p * p))) / q


@functools.lru_cache(maxsize=1)
def _z_grid():
    """``(q, z)`` tabulated from ``q = 1e-4`` to 1: ``z`` in ``log q`` below 1/2, in ``p`` above."""
    t = np.linspace(math.log(1e-4), math.log(0.5), 4001)
    q_low = np.exp(t)
    integrand_low = _energy_curvature(q_low) * q_low
    p = np.linspace(0.5 ** (1.0 / 3.0), 0.0, 4001)
    q_high = 1.0 - p ** 3
    # dq = -3 p^2 dp: f'' ~ p^-4 near full slip, so the integrand in p stays finite.
    with np.errstate(divide="ignore", invalid="ignore"):
        integrand_high = np.where(p > 0.0, _energy_curvature(q_high) * 3.0 * p * p,
                                  math.sqrt(5.0) / 2.0)
    z_low = np.concatenate(([0.0], np.cumsum(0.5 * (integrand_low[1:] + integrand_low[:-1])
                                             * np.diff(t))))
    z_high = z_low[-1] + np.concatenate(([0.0], np.cumsum(
        0.5 * (integrand_high[1:] + integrand_high[:-1]) * -np.diff(p))))
    return np.concatenate((q_low, q_high[1:])), np.concatenate((z_low, z_high[1:]))


def _even_in_z(start, end, intervals):
    """``intervals + 1`` values of ``q`` from ``start`` to ``end``, evenly spaced in ``z``."""
    q_grid, z_grid = _z_grid()
    z = np.linspace(np.interp(start, q_grid, z_grid), np.interp(end, q_grid, z_grid),
                    intervals + 1)
    q = np.interp(z, z_grid, q_grid)
    q[0], q[-1] = start, end
    return q


def _vertices(m):
    """The loop-energy vertices ``q_1 .. q_m`` of the placement rule (module notes)."""
    intervals = m - 2
    coarse = math.ceil(intervals / _COARSE_SHARE) if intervals >= _COARSE_SHARE else 0
    fine = intervals - coarse
    if fine == 0:
        curve = np.array([1.0])
    else:
        curve = _even_in_z(_FINE_START, 1.0, fine)
        if coarse:
            curve = np.concatenate((_even_in_z(_COARSE_START, _FINE_START, coarse)[:-1], curve))
    return np.concatenate(([2.0 * curve[0] / 3.0], curve))


def _chord_excess(vertices):
    """Largest relative excess of the chords of ``f`` between vertices over ``f``, on [0.05, 1]."""
    low, high = vertices[1:-1], vertices[2:]
    keep = low >= _FINE_START * (1.0 - 1e-12)
    if not np.any(keep):
        return 0.0
    low, high = low[keep], high[keep]
    fraction = np.linspace(0.0, 1.0, 65)[1:-1]
    q = low[:, None] + (high - low)[:, None] * fraction
    f_low, f_high = mindlin_energy_ratio(low)[:, None], mindlin_energy_ratio(high)[:, None]
    chord = f_low + (f_high - f_low) * fraction
    return float(np.max(chord / mindlin_energy_ratio(q) - 1.0))


def _iwan_of_polyline(force, energy):
    """Stiffness shares ``c`` and slip fractions ``s`` of the Iwan model with this loop energy.

    ``force`` (``Q_1 < ... < Q_m``, in ``8 G* a u*``) and ``energy`` (``D_1 = 0``,
    in ``8 G* a u*^2``): the vertices of the polyline.  Before the first
    vertex every element sticks (``Q = s_0``, total stiffness 1); beyond
    vertex ``j`` elements ``1..j`` slip, so the slope there is
    ``sigma_j = 4 sum_{i<=j} c_i s_i / sum_{i>j} c_i``, which gives
    ``c_j = C_j (sigma_j - sigma_{j-1}) / (sigma_j + 4 s_j)`` (``C_j`` the
    stiffness not yet slipping) and the next slip amplitude from the force
    step; the last element takes the stiffness left, and the last vertex's
    force is ``sum c_i s_i``.
    """
    m = force.size
    c = np.zeros(m)
    s = np.zeros(m)
    s[0] = force[0]
    remaining = 1.0
    previous = 0.0
    for j in range(m - 1):
        slope = (energy[j + 1] - energy[j]) / (force[j + 1] - force[j])
        c[j] = remaining * (slope - previous) / (slope + 4.0 * s[j])
        remaining -= c[j]
        s[j + 1] = s[j] + (force[j + 1] - force[j]) / remaining
        previous = slope
    c[-1] = remaining
    return c, s


def _binned(vertices):
    """``(c, s)`` of bins of the density, edged at the vertices below full slip.

    Few sub-elements (fewer than 12): the density in ``s`` split at the
    ``s`` of ``0, q_1, ..., q_(m-1), 1``; each bin one sub-element with the
    bin's stiffness ``c = sqrt(1 - s_a) - sqrt(1 - s_b)`` at the bin's
    centroid (its capacity the bin's).  Every slip displacement then lies
    inside ``(0, u*)``, which the polyline of so few vertices does not keep.
    """
    edges = np.concatenate(([0.0], 1.0 - (1.0 - vertices[:-1]) ** (2.0 / 3.0), [1.0]))
    root = np.sqrt(1.0 - edges)
    stiffness = root[:-1] - root[1:]
    # int s (1 - s)^(-1/2) / 2 ds = -(1/3) sqrt(1 - s) (2 + s)
    moment = root[:-1] * (2.0 + edges[:-1]) / 3.0 - root[1:] * (2.0 + edges[1:]) / 3.0
    return stiffness, moment / stiffness


@functools.lru_cache(maxsize=16)
def microslip_fractions(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(c, s, w)`` of ``m`` sub-elements: stiffness shares, slip fractions, capacity shares.

    Sub-element ``i`` of an element of stiffness ``k`` and capacity ``W``
    (slip displacement ``u* = 1.5 W / k``) has the stiffness ``c_i k``, the
    slip displacement ``s_i u*`` and the capacity ``w_i W``,
    ``w_i = 1.5 c_i s_i``; ``sum c = sum w = 1`` to rounding.  Placed by the
    rule of the module notes.  Read-only arrays, ascending in ``s``.

    Examples
    --------
    >>> c, s, w = microslip_fractions(32)
    >>> round(float(c.sum()), 15), round(float(w.sum()), 15), bool(np.all(np.diff(s) > 0))
    (1.0, 1.0, True)
    """
    q = _vertices(int(m))
    if m - 2 < _COARSE_SHARE:
        c, s = _binned(q)
    else:
        shift = 0.5 * _chord_excess(q)
        energy = _D_PER_ENERGY * mindlin_energy_ratio(q) * (1.0 - shift)
        energy[0] = 0.0
        c, s = _iwan_of_polyline(_Q_PER_FORCE * q, energy)
    c = c / c.sum()
    w = 1.5 * c * s
    w = w / w.sum()
    s = w / (1.5 * c)
    for array in (c, s, w):
        array.setflags(write=False)
    return c, s, w


def microslip_table(table, m: int):
    """The element table with each element replaced by its ``m`` microslip sub-elements.

    Parameters
    ----------
    table : polind.contact.ElementTable
        Elastic-slip elements (a bin, a summit or an elastic-plastic summit
        each, :ref:`guide-pol-ind-elements`).
    m : int
        Sub-elements per element (:func:`polind.contact.microslip.microslip_fractions`).

    Returns
    -------
    polind.contact.ElementTable
        ``len(table) * m`` rows, element ``j``'s ``m`` sub-elements together
        (element-major): each row keeps its element's height, count,
        interference and radius; its stiffness and capacity are the
        element's times ``c_i`` and ``w_i``, its slip displacement
        ``s_i u*_j``.  ``parent`` is ``table``.
    """
    c, _, w = microslip_fractions(int(m))
    n = len(table)

    def rows(values):
        return None if values is None else np.repeat(values, m)

    stiffness_share = np.tile(c, n)
    capacity_share = np.tile(w, n)
    return replace(table,
                   heights=rows(table.heights), asperities=rows(table.asperities),
                   interference=rows(table.interference),
                   stiffness=rows(table.stiffness) * stiffness_share,
                   breakaway_force=rows(table.breakaway_force) * capacity_share,
                   weights=rows(table.weights), radii=rows(table.radii),
                   stiffness_share=stiffness_share, capacity_share=capacity_share, parent=table)


#: The values of ``discretisation.tangential``.
TANGENTIAL_LAWS = ("elastic-slip", "mindlin")


def microslip_of(discretisation) -> int | None:
    """Sub-elements per element of a ``[model.discretisation]`` table, or ``None`` (elastic slip).

    ``tangential = "mindlin"`` with ``microslip_elements`` (default
    :data:`MICROSLIP_ELEMENTS`, an integer in :data:`MICROSLIP_RANGE`);
    ``microslip_elements`` without ``tangential = "mindlin"`` is refused
    (it would do nothing).

    Raises
    ------
    polind.InputError
        Naming the key.
    """
    from polind.errors import InputError, describe

    law = discretisation.get("tangential")
    law = "elastic-slip" if law is None else law
    if law not in TANGENTIAL_LAWS:
        raise InputError(f"The 'discretisation.tangential' parameter of pol-ind must be "
                         f"\"elastic-slip\" or \"mindlin\". Got {describe(law)} instead.")
    count = discretisation.get("microslip_elements")
    if law == "elastic-slip":
        if count is not None:
            raise InputError("The 'discretisation.microslip_elements' parameter of pol-ind is "
                             "only used with tangential = \"mindlin\". Got "
                             f"{describe(count)} with tangential = \"elastic-slip\"; remove it "
                             "or set tangential = \"mindlin\".")
        return None
    if count is None:
        return MICROSLIP_ELEMENTS
    low, high = MICROSLIP_RANGE
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) \
            or not low <= count <= high:
        raise InputError(f"The 'discretisation.microslip_elements' parameter of pol-ind must be "
                         f"an integer in the range [{low}, {high}]. Got {describe(count)} "
                         f"instead.")
    return int(count)


def check_constant_load(loads, table_load) -> None:
    """Refuse a normal load other than the table's for microslip sub-elements (an InputError).

    The element machinery re-evaluates each row at a new load as an
    elastic-slip element of its own (one slip distance per row), so the
    sub-elements would no longer be Cattaneo–Mindlin's: a model with
    ``tangential = "mindlin"`` runs at its constant load
    (:ref:`guide-pol-ind-microslip`).
    """
    from polind.errors import InputError

    loads = np.asarray(loads, dtype=float)
    other = np.flatnonzero(loads != table_load)
    if other.size:
        index = int(other[0])
        raise InputError(
            f"A pol-ind model with tangential = \"mindlin\" runs at one constant normal load "
            f"(its microslip sub-elements are placed for their element's load; at another load "
            f"each would slip as an elastic-slip element of its own). Got 'normal_load' "
            f"{float(loads[index])!r} N at index {index}, the table's load being "
            f"{float(table_load)!r} N; give a constant load or tangential = \"elastic-slip\".")
