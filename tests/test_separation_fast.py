"""The fast Greenwood–Williamson pair (polind.kernels.greenwood) and the statistical start (polind.kernels.separation).

:func:`gw_half_integer_pair_fast` is an approximation (piecewise polynomials
on [-5.5, 10.5)); these tests measure its error against three independent
references: values of the parabolic-cylinder form computed with 40-digit
``mpmath`` (a table below), adaptive quadrature of the defining integral,
and the exact Bessel pair of :mod:`polind.contact.greenwood` (to that pair's
own documented accuracy).  :func:`statistical_start` must land close enough
to the root that one evaluation meets the tolerance for every load a
statistical surface can carry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from polind.contact.greenwood import half_integer_pair
from polind.contact.surface import StatisticalSurface
from polind.kernels import greenwood as kernels
from polind.kernels.greenwood import FAST_RANGE, gw_half_integer_pair, gw_half_integer_pair_fast
from polind.kernels.separation import (
    RELATIVE_TOLERANCE,
    STATISTICAL,
    STATISTICAL_STOP,
    newton_separation_counted,
    statistical_load_and_slope,
    statistical_separation,
    statistical_separation_at,
    statistical_separation_only,
    statistical_start,
)
from polind.kernels.special import special_addresses

ADDRESSES = special_addresses()
SIGMA = 0.5e-6
NO_SUMMITS = np.empty(0)
#: The documented bound of the approximation (measured: 2.6e-15).
BOUND = 5e-15

# (s, F_{1/2}(s), F_{3/2}(s)): F_m(s) = Γ(m+1) phi(s) e^{s²/4} D_{-m-1}(s) with
# mpmath 1.3 at 40 digits (mp.pcfd), each rounded once to the nearest double.
# The points: every piece boundary of FAST_RANGE and the double just below
# it, the bracket ends -5 and 10, the exact pair's Taylor cut-off ±1e-8, the
# exact pair's worst cancellation (s = 2.8) and the default model's range.
GW_REFERENCE = [
    (-5.5, 2.3351855094400142, 13.059588709844942),
    (-5.000000000000001, 2.2244131828051352, 11.349387798006598),
    (-5.0, 2.2244131828051352, 11.349387798006594),
    (-4.9, 2.2015575661373, 11.017436888285992),
    (-4.500000000000001, 2.1075129767380383, 9.724498175837672),
    (-4.5, 2.1075129767380383, 9.72449817583767),
    (-4.000000000000001, 1.9832298897597238, 8.189959426789367),
    (-4.0, 1.9832298897597236, 8.189959426789363),
    (-3.6, 1.8772834077891327, 7.031481440234312),
    (-3.5000000000000004, 1.8497274045163647, 6.7519498264350135),
    (-3.5, 1.8497274045163647, 6.751949826435012),
    (-3.0000000000000004, 1.7041320019204507, 5.418377276511697),
    (-3.0, 1.7041320019204507, 5.418377276511696),
    (-2.5000000000000004, 1.541890499543151, 4.199895952398185),
    (-2.5, 1.5418904995431508, 4.199895952398184),
    (-2.2, 1.4339435519096015, 3.529994025866407),
    (-2.0000000000000004, 1.3566405981393808, 3.1112928856876),
    (-2.0, 1.3566405981393808, 3.111292885687599),
    (-1.5000000000000002, 1.142514886340674, 2.172209400507064),
    (-1.5, 1.142514886340674, 2.1722094005070636),
    (-1.0000000000000002, 0.9006029312703164, 1.4045974704739528),
    (-1.0, 0.9006029312703163, 1.4045974704739523),
    (-0.7, 0.7479692607911284, 1.033599756747324),
    (-0.5000000000000001, 0.6466694535032851, 0.8244484201857113),
    (-0.5, 0.6466694535032851, 0.8244484201857112),
    (-1e-08, 0.4110894836314292, 0.430019999828602),
    (-3e-09, 0.41108948062128925, 0.4300199955121624),
    (-1e-300, 0.4110894793312293, 0.4300199936622598),
    (-5e-324, 0.4110894793312293, 0.4300199936622598),
    (0.0, 0.4110894793312293, 0.4300199936622598),
    (1e-300, 0.4110894793312293, 0.4300199936622598),
    (1e-08, 0.4110894750310293, 0.43001998749591763),
    (2e-08, 0.41108947073082946, 0.43001998132957553),
    (0.3, 0.2921867847250675, 0.2725699076055834),
    (0.49999999999999994, 0.22533558169731163, 0.19520360374379064),
    (0.5, 0.2253355816973116, 0.19520360374379064),
    (0.9999999999999999, 0.10415367530785771, 0.07566817739097509),
    (1.0, 0.1041536753078577, 0.07566817739097507),
    (1.4999999999999998, 0.03988151765469582, 0.02463948030748375),
    (1.5, 0.039881517654695796, 0.024639480307483735),
    (1.7, 0.025688916454683425, 0.014933149226724125),
    (1.9999999999999998, 0.012480040296439074, 0.006648177623587098),
    (2.0, 0.012480040296439067, 0.006648177623587093),
    (2.4999999999999996, 0.003159023032652176, 0.0014699382395379937),
    (2.5, 0.0031590230326521717, 0.0014699382395379915),
    (2.8, 0.001247134848200571, 0.000538151407506009),
    (2.85, 0.0010598785487720929, 0.0004518126310574919),
    (2.9999999999999996, 0.0006418504393485518, 0.0002639675542694677),
    (3.0, 0.0006418504393485508, 0.0002639675542694673),
    (3.0041502046751, 0.0006328225881874028, 0.0002599999999999904),
    (3.18992188924169, 0.00033035023534817284, 0.00013000000000000018),
    (3.4999999999999996, 0.00010407145290773253, 3.822707776096117e-05),
    (3.5, 0.00010407145290773235, 3.8227077760961094e-05),
    (3.9999999999999996, 1.3406669924496435e-05, 4.4391559585392605e-06),
    (4.0, 1.340666992449641e-05, 4.439155958539252e-06),
    (4.4, 2.199732135934381e-06, 6.743191537855498e-07),
    (4.499999999999999, 1.3674721507435395e-06, 4.11499863850753e-07),
    (4.5, 1.3674721507435336e-06, 4.1149986385075114e-07),
    (4.999999999999999, 1.1014563207789332e-07, 3.033850561878499e-08),
    (5.0, 1.1014563207789281e-07, 3.033850561878485e-08),
    (5.499999999999999, 6.9912241453897956e-09, 1.7737354783161354e-09),
    (5.5, 6.99122414538976e-09, 1.773735478316126e-09),
    (5.999999999999999, 3.490963471387411e-10, 8.203580589815212e-11),
    (6.0, 3.490963471387392e-10, 8.203580589815166e-11),
    (6.25, 7.126548989016162e-11, 1.6147923056562598e-11),
    (6.499999999999999, 1.3694682819660332e-11, 2.9955222865024624e-12),
    (6.5, 1.369468281966025e-11, 2.9955222865024443e-12),
    (6.999999999999999, 4.2158901308053434e-13, 8.621388970723307e-14),
    (7.0, 4.2158901308053166e-13, 8.621388970723251e-14),
    (7.499999999999999, 1.0175533466238869e-14, 1.953059702859627e-15),
    (7.5, 1.01755334662388e-14, 1.9530597028596136e-15),
    (7.9, 4.3389369892328805e-16, 7.936450997716005e-17),
    (7.999999999999999, 1.9240743960372916e-16, 3.478399792218717e-17),
    (8.0, 1.9240743960372775e-16, 3.4783997922186915e-17),
    (8.499999999999998, 2.8484084673504244e-18, 4.865612847538172e-19),
    (8.5, 2.8484084673503805e-18, 4.865612847538096e-19),
    (8.999999999999998, 3.2995892741946387e-20, 5.3409728284092645e-21),
    (9.0, 3.299589274194585e-20, 5.3409728284091764e-21),
    (9.3, 2.020958603221136e-21, 3.1713471898892775e-22),
    (9.499999999999998, 2.989446130953177e-22, 4.597374931388759e-23),
    (9.5, 2.9894461309531257e-22, 4.5973749313886797e-23),
    (9.999999999999998, 2.117479299141649e-24, 3.1012065086732254e-25),
    (10.0, 2.117479299141611e-24, 3.101206508673169e-25),
    (10.499999999999998, 1.1721764414987621e-26, 1.6384854911613598e-27),
]

PIECE_BOUNDARIES = [FAST_RANGE[0] + 0.5 * k for k in range(33)]


def fast(s):
    return gw_half_integer_pair_fast(float(s), ADDRESSES)


def test_reference_table_covers_every_piece_boundary():
    points = {s for s, _, _ in GW_REFERENCE}
    for boundary in PIECE_BOUNDARIES[:-1]:
        assert boundary in points
    for boundary in PIECE_BOUNDARIES[1:]:
        assert float(np.nextafter(boundary, -np.inf)) in points


@pytest.mark.parametrize("s, f_half, f_three_halves", GW_REFERENCE)
def test_fast_pair_against_40_digit_values(s, f_half, f_three_halves):
    got_half, got_three_halves = fast(s)
    assert abs(got_half - f_half) <= BOUND * f_half
    assert abs(got_three_halves - f_three_halves) <= BOUND * f_three_halves


def quadrature(m, s):
    """``F_m(s)`` by adaptive quadrature of its definition (``t - s = v²``, ``phi(s)`` factored out).

    Measured against the 40-digit table: relative error below 3.5e-15.
    """
    value, _ = integrate.quad(lambda v: 2.0 * v ** (2 * m + 1) * math.exp(-0.5 * v**4 - s * v * v),
                              0.0, math.inf, epsabs=0.0, epsrel=1e-13, limit=400)
    return value * math.exp(-0.5 * s * s) / math.sqrt(2.0 * math.pi)


def test_fast_pair_against_quadrature():
    for s in np.linspace(-5.5, 10.49, 151).tolist():
        f_half, f_three_halves = fast(s)
        assert f_half == pytest.approx(quadrature(0.5, s), rel=1e-14, abs=0), s
        assert f_three_halves == pytest.approx(quadrature(1.5, s), rel=1e-14, abs=0), s


def test_fast_pair_against_the_exact_bessel_pair():
    """Within the exact pair's own error: 3e-12 and 4e-13 (greenwood.py), 1.5e-14 where it does not cancel."""
    rng = np.random.default_rng(3)
    grid = np.concatenate([np.linspace(-5.5, 10.5, 4001)[:-1], rng.uniform(-5.5, 10.5, 2000),
                           [-1e-8, 1e-8, 3e-9, -3e-9, 0.0, 1e-300]])
    worst = {True: [0.0, 0.0], False: [0.0, 0.0]}
    for s in grid.tolist():
        got = fast(s)
        for index, (g, exact, python) in enumerate(zip(got, gw_half_integer_pair(s, ADDRESSES),
                                                       half_integer_pair(s))):
            assert exact == python
            error = abs(g - exact) / exact
            accurate = s <= 1.0           # no cancellation in the Bessel forms
            worst[accurate][index] = max(worst[accurate][index], error)
    assert worst[True][0] <= 1.5e-14 and worst[True][1] <= 1.5e-14, worst
    assert worst[False][0] <= 4e-13 and worst[False][1] <= 3e-12, worst


def test_fast_pair_is_continuous_across_its_pieces():
    for boundary in PIECE_BOUNDARIES[1:-1]:
        step = boundary - float(np.nextafter(boundary, -np.inf))
        below, above = fast(boundary - step), fast(boundary)
        for b, a in zip(below, above):
            # Both within BOUND of F_m, which itself moves by |dlog F_m/ds| < 20 per unit s.
            assert abs(a - b) <= (2 * BOUND + 20 * step) * a, boundary


def test_fast_pair_is_smooth_and_decreasing():
    h = 1e-3
    s = np.linspace(-5.5, 10.5, 16001)[:-1]
    f_half, f_three_halves = np.array([fast(x) for x in s]).T
    assert np.all(np.diff(f_three_halves) < 0) and np.all(np.diff(f_half) < 0)
    # dF_{3/2}/ds = -(3/2) F_{1/2}: the two polynomial families are one
    # consistent function (fourth-order differences: error below 1e-7 here).
    slope = (f_three_halves[:-4] - 8.0 * f_three_halves[1:-3] + 8.0 * f_three_halves[3:-1]
             - f_three_halves[4:]) / (12.0 * h)
    np.testing.assert_allclose(slope, -1.5 * f_half[2:-2], rtol=1e-6)


def test_outside_its_range_the_fast_pair_is_the_exact_pair():
    for s in (-1e3, -6.0, float(np.nextafter(-5.5, -np.inf)), 10.5, 11.0, 40.0, 1e3):
        assert fast(s) == gw_half_integer_pair(s, ADDRESSES)
    assert fast(math.inf) == (0.0, 0.0)
    assert fast(-math.inf) == (math.inf, math.inf)
    assert all(math.isnan(v) for v in fast(math.nan))


def test_the_tables_are_built_from_a_converged_quadrature():
    """Halving the trapezoidal step changes the build's values by rounding only."""
    s = np.linspace(-5.5, 10.5, 97)
    scaled = s >= 0.0
    coarse = kernels._quadrature_pair(s, scaled)
    step = kernels._TRAPEZOID_STEP
    try:
        kernels._TRAPEZOID_STEP = step / 2.0
        fine = kernels._quadrature_pair(s, scaled)
    finally:
        kernels._TRAPEZOID_STEP = step
    for c, f in zip(coarse, fine):
        np.testing.assert_allclose(c, f, rtol=1e-15, atol=0)
    tables = kernels._build_tables()
    np.testing.assert_array_equal(tables[0], kernels._FORWARD)
    np.testing.assert_array_equal(tables[1], kernels._INVERSE)


# --------------------------------------------------------------------------- statistical start


@pytest.fixture(scope="module")
def surface():
    return StatisticalSurface(1e10, 1e-4, 50e-6, SIGMA, 1.15e11, 2.4e10)


def test_statistical_start_inverts_the_fast_load():
    scale = 3.7e5
    s = np.concatenate([np.linspace(-5.5, 10.5, 12001)[:-1], [-5.0, 10.0]])
    for x in s.tolist():
        load = scale * fast(x)[1]
        start = statistical_start(load, scale, SIGMA) / SIGMA
        assert abs(start - x) <= 2e-12, x
        assert abs(scale * fast(start)[1] - load) <= 3e-11 * load, x


@pytest.mark.parametrize("where", ["inside", "ends"])
def test_one_evaluation_for_every_load_the_surface_carries(surface, where):
    lo, hi = surface.separation_range
    smallest, largest = surface.load_range
    if where == "inside":
        loads = np.geomspace(smallest, largest, 2001)[1:-1]
    else:
        loads = np.array([smallest, largest, smallest * (1 + 1e-12), largest * (1 - 1e-12)])
    for load in loads.tolist():
        d, value, slope, evaluations = statistical_separation(load, lo, hi, surface._load_scale, SIGMA,
                                                              ADDRESSES)
        assert evaluations == 1, load
        assert lo <= d <= hi
        # The balance holds to 1e-10 measured with the exact Bessel pair too.
        assert abs(float(surface.normal_load(d)) - load) <= RELATIVE_TOLERANCE * load
        assert abs(value - load) <= STATISTICAL_STOP * load
        assert (value, slope) == statistical_load_and_slope(d, surface._load_scale, SIGMA, ADDRESSES)
        start = statistical_start(load, surface._load_scale, SIGMA)
        assert (d, value, slope, 1) == newton_separation_counted(
            load, start, lo, hi, STATISTICAL, surface._load_scale, SIGMA, NO_SUMMITS, NO_SUMMITS, 0.0,
            ADDRESSES)


def test_statistical_separation_falls_back_to_newton(surface):
    """Loads outside the bracket's range: Newton from the same start (which repeats the first evaluation)."""
    lo, hi = surface.separation_range
    smallest, largest = surface.load_range
    for load in (largest * 1.5, smallest / 3.0, largest * (1 + 1e-6)):
        got = statistical_separation(load, lo, hi, surface._load_scale, SIGMA, ADDRESSES)
        start = min(max(statistical_start(load, surface._load_scale, SIGMA), lo), hi)
        want = newton_separation_counted(load, start, lo, hi, STATISTICAL, surface._load_scale, SIGMA,
                                         NO_SUMMITS, NO_SUMMITS, 0.0, ADDRESSES)
        assert got[:3] == want[:3]
        assert got[3] == 1 + want[3]
        assert got[0] in (lo, hi)


def test_the_model_kernels_entry_takes_the_addresses_as_numbers(surface):
    """``statistical_separation_at`` (a model kernel's call) is ``statistical_separation``, fallback too."""
    lo, hi = surface.separation_range
    smallest, largest = surface.load_range
    for load in np.geomspace(smallest, largest, 41).tolist() + [largest * 1.5, smallest / 3.0]:
        want = statistical_separation(load, lo, hi, surface._load_scale, SIGMA, ADDRESSES)
        for kve_address, ive_address in (ADDRESSES.tolist(), ADDRESSES.astype(float).tolist()):
            assert statistical_separation_at(load, lo, hi, surface._load_scale, SIGMA, kve_address,
                                             ive_address) == want


def test_the_separation_alone_is_the_checked_one(surface):
    """``statistical_separation_only`` skips the check of the start inside the bracket, nothing else.

    Bit for bit the separation of ``statistical_separation_at`` at loads
    across the surface's range (where that check always passes), at its
    ends, beyond them (the Newton fallback) and for NaN (which a caller refuses first).
    """
    lo, hi = surface.separation_range
    smallest, largest = surface.load_range
    kve_address, ive_address = ADDRESSES.tolist()
    loads = (np.geomspace(smallest, largest, 4001).tolist()
             + [smallest * (1 + 1e-12), largest * (1 - 1e-12), largest * 1.5, smallest / 3.0,
                largest * (1 + 1e-6), 1e-300, 1e300, math.nan])
    for load in loads:
        want = statistical_separation_at(load, lo, hi, surface._load_scale, SIGMA, kve_address,
                                         ive_address)
        got = statistical_separation_only(load, lo, hi, surface._load_scale, SIGMA, kve_address,
                                          ive_address)
        assert got == want[0] or (math.isnan(got) and math.isnan(want[0])), load
