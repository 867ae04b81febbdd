"""The separation kernels (MODELS.md 7.3–7.4): SciPy's Bessel functions in numba, the
Greenwood–Williamson pair, the surfaces' loads and the safeguarded Newton iteration.

The fast pair the statistical load is computed with has its own tests
(``tests/test_separation_fast.py``)."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numba
import numpy as np
import pytest
from scipy import integrate, special

from polind.contact import greenwood
from polind.contact.greenwood import half_integer_pair
from polind.contact.separation import RELATIVE_TOLERANCE, solve_separation, solve_separation_series
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.kernels import greenwood as gw_kernels
from polind.kernels import separation as kernels
from polind.kernels.greenwood import gw_half_integer_pair, gw_half_integer_pair_fast
from polind.kernels.separation import (
    DIRECT,
    STATISTICAL,
    STATISTICAL_STOP,
    direct_load_and_slope,
    direct_lower_bound,
    newton_separation,
    newton_separation_counted,
    newton_separation_series,
    predicted_start,
    statistical_load_and_slope,
    statistical_separation,
)
from polind.kernels.special import ive, kve, special_addresses

ETA, A0, R, SIGMA = 1e10, 1e-4, 50e-6, 0.5e-6
E_STAR, G_STAR = 1.15e11, 2.4e10
ADDRESSES = special_addresses()
NO_SUMMITS = np.empty(0)
LOADS = np.geomspace(1e-3, 1e3, 61)


@pytest.fixture(scope="module")
def statistical():
    return StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR)


@pytest.fixture(scope="module")
def direct():
    # 100 000 summits: a tenth of the default area.
    return DirectSurface.from_seed(ETA, 1e-5, SIGMA, R, E_STAR, G_STAR, seed=0)


def kernel_arguments(surface):
    """The surface as the kernels' (kind, load_scale, height_std, heights, counts, hertz, addresses)."""
    if surface.kind == "statistical":
        return STATISTICAL, surface._load_scale, surface.height_std, NO_SUMMITS, NO_SUMMITS, 0.0, ADDRESSES
    return DIRECT, 0.0, 1.0, surface.heights, surface.counts, surface._hertz_scale(), ADDRESSES


def bracket(surface, load):
    """The bracket of polind.contact.separation: sigma_a (-5, 10), or the direct lower bound."""
    if surface.kind == "statistical":
        return surface.separation_range
    lo = direct_lower_bound(load, surface.heights, surface.counts, surface._hertz_scale())
    return lo, surface.heights[-1]


def kernel_load_and_slope(surface):
    """The ``N(d), dN/dd`` the kernel balances: the fast pair's (statistical surface) or the sum (direct)."""
    if surface.kind == "statistical":
        return lambda d: statistical_load_and_slope(d, surface._load_scale, surface.height_std, ADDRESSES)
    return surface.load_and_slope


def python_newton(surface, load, start, lo, hi):
    """The iteration of MODELS.md 7.4 written out in Python, on the load the kernel balances.

    Stops at ``|N(d) - N_app| <= 1e-10 N_app`` for a direct surface and at
    ``0.9e-10 N_app`` (``STATISTICAL_STOP``) for the statistical one, whose
    ``N`` is the fast pair's.
    """
    load_and_slope = kernel_load_and_slope(surface)
    tolerance = (STATISTICAL_STOP if surface.kind == "statistical" else RELATIVE_TOLERANCE) * load
    log_load = math.log(load)
    d = min(max(start, lo), hi)
    best = (d, math.inf, math.nan, math.nan)
    for iteration in range(1, kernels.MAX_ITERATIONS + 1):
        value, slope = load_and_slope(d)
        error = abs(value - load)
        if error < best[1]:
            best = (d, error, value, slope)
        if error <= tolerance:
            return d, value, slope, iteration
        if value > load:
            lo = d
        else:
            hi = d
        if value > 0.0 and slope < 0.0:
            candidate = d - (math.log(value) - log_load) * value / slope
        else:
            candidate = math.nan
        if not lo < candidate < hi:
            candidate = 0.5 * (lo + hi)
        if candidate == d or not lo < candidate < hi:
            break
        d = candidate
    return best[0], best[2], best[3], iteration


# --------------------------------------------------------------------------- special functions


def test_kve_and_ive_are_scipys_to_the_bit():
    rng = np.random.default_rng(5)
    x = np.concatenate([rng.uniform(0.0, 30.0, 300), np.geomspace(1e-12, 1e3, 60)])
    for order in (0.25, 0.75, 1.0, 2.5):
        assert [kve(order, v, ADDRESSES) for v in x] == special.kve(order, x).tolist()
    for order in (0.25, -0.25, 0.75, -0.75, 3.0):
        assert [ive(order, v, ADDRESSES) for v in x] == special.ive(order, x).tolist()


def test_addresses_may_be_float64_and_are_computed_once():
    assert special_addresses() is ADDRESSES
    assert not ADDRESSES.flags.writeable
    as_floats = ADDRESSES.astype(np.float64)
    np.testing.assert_array_equal(as_floats.astype(np.int64), ADDRESSES)
    assert kve(0.25, 1.7, as_floats) == special.kve(0.25, 1.7)
    assert ive(-0.75, 1.7, as_floats) == special.ive(-0.75, 1.7)


def test_kernels_do_not_import_the_layers_above():
    for module in ("special.py", "greenwood.py", "separation.py"):
        tree = ast.parse((Path(kernels.__file__).parent / module).read_text())
        imported = [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
                    for alias in node.names]
        imported += [node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
        assert [name for name in imported if name.startswith("polind")] == [
            name for name in imported if name.startswith("polind.kernels")
        ], (module, imported)


# --------------------------------------------------------------------------- F_{1/2}, F_{3/2}

S_GRID = np.concatenate([np.linspace(-5.0, 10.0, 1501), [0.0, 1e-8, -1e-8, 2e-8, -2e-8, 3e-9, -7e-9, 1e-300]])


def test_constants_are_greenwoods():
    """One copy of the pair's constants: the kernels', which contact.greenwood calls, equal to F_m(0)."""
    for name in ("_F_MINUS_HALF_0", "_F_HALF_0", "_F_THREE_HALVES_0", "_TAYLOR_BELOW", "_SQRT_PI"):
        assert not hasattr(greenwood, name), name
    for name, m in (("_F_MINUS_HALF_0", -0.5), ("_F_HALF_0", 0.5), ("_F_THREE_HALVES_0", 1.5)):
        assert getattr(gw_kernels, name) == pytest.approx(quadrature(m, 0.0), rel=1e-13, abs=0), name
    assert (gw_kernels._SQRT_PI, gw_kernels._SQRT_2) == (math.sqrt(math.pi), math.sqrt(2.0))


def test_pair_matches_half_integer_pair():
    for s in S_GRID.tolist():
        want = half_integer_pair(s)
        got = gw_half_integer_pair(s, ADDRESSES)
        for g, w in zip(got, want):
            assert abs(g - w) <= 1e-15 * abs(w), (s, got, want)


def test_pair_special_values():
    assert gw_half_integer_pair(math.inf, ADDRESSES) == (0.0, 0.0)
    assert gw_half_integer_pair(-math.inf, ADDRESSES) == (math.inf, math.inf)
    assert all(math.isnan(v) for v in gw_half_integer_pair(math.nan, ADDRESSES))


def quadrature(m, s):
    """``F_m(s)`` by quadrature of its definition.

    With ``t - s = v²`` the integrand is smooth at the lower end, and
    ``phi(s)`` is factored out so that nothing underflows at ``s = 10``.
    """
    value, _ = integrate.quad(lambda v: 2.0 * v ** (2 * m + 1) * math.exp(-0.5 * v**4 - s * v * v),
                              0.0, math.inf, epsabs=0.0, epsrel=1e-13, limit=400)
    return value * math.exp(-0.5 * s * s) / math.sqrt(2.0 * math.pi)


@pytest.mark.parametrize("s", np.concatenate([np.linspace(-5.0, 10.0, 61), [1e-9, -1e-9, 1e-7, -1e-7]]).tolist())
def test_pair_matches_the_defining_integral(s):
    f_half, f_three_halves = gw_half_integer_pair(s, ADDRESSES)
    # greenwood.py documents 4e-13 (F_{1/2}) and 3e-12 (F_{3/2}) against
    # arbitrary-precision quadrature.
    assert f_half == pytest.approx(quadrature(0.5, s), rel=1e-11, abs=0)
    assert f_three_halves == pytest.approx(quadrature(1.5, s), rel=1e-11, abs=0)


# --------------------------------------------------------------------------- loads and slopes


def test_load_and_slope_are_the_surfaces(statistical, direct):
    for x in SIGMA * np.linspace(-5.0, 10.0, 301):
        value, slope = statistical_load_and_slope(x, statistical._load_scale, SIGMA, ADDRESSES)
        # The fast pair (tests/test_separation_fast.py), in the surface's formulas ...
        f_half, f_three_halves = gw_half_integer_pair_fast(x / SIGMA, ADDRESSES)
        assert (value, slope) == (statistical._load_scale * f_three_halves,
                                  -1.5 * statistical._load_scale / SIGMA * f_half)
        # ... so the surface's own (exact Bessel) values to that pair's error: 3e-12, 4e-13.
        want_value, want_slope = statistical.load_and_slope(x)
        assert value == pytest.approx(want_value, rel=3e-12, abs=0)
        assert slope == pytest.approx(want_slope, rel=4e-13, abs=0)
    for x in (SIGMA * np.linspace(-6.0, 5.0, 301)).tolist() + [float(direct.heights[-1]), 1.0]:
        assert direct_load_and_slope(x, direct.heights, direct.counts, direct._hertz_scale()) == (
            direct.load_and_slope(x))


def test_direct_lower_bound_carries_the_load(direct):
    hertz = direct._hertz_scale()
    for load in LOADS:
        lo = direct_lower_bound(load, direct.heights, direct.counts, hertz)
        # Exact when the top summit alone carries the load: allow its rounding.
        assert float(direct.normal_load(lo)) >= load * (1.0 - 1e-13)
    single = DirectSurface([1e-6], R, E_STAR, G_STAR)
    lo = direct_lower_bound(0.37, single.heights, single.counts, single._hertz_scale())
    assert lo == pytest.approx(1e-6 - (0.37 / (4.0 / 3.0 * E_STAR * math.sqrt(R))) ** (2.0 / 3.0), rel=1e-15)


# --------------------------------------------------------------------------- Newton


@pytest.mark.parametrize("kind", ["statistical", "direct"])
def test_newton_meets_the_tolerance_and_is_the_python_iteration(statistical, direct, kind):
    surface = statistical if kind == "statistical" else direct
    arguments = kernel_arguments(surface)
    for load in LOADS.tolist():
        lo, hi = bracket(surface, load)
        for start in (0.0, -3.0 * SIGMA, 6.0 * SIGMA, solve_separation(surface, load * 1.01)):
            d, value, slope, evaluations = newton_separation_counted(load, start, lo, hi, *arguments)
            # The balance holds with the surface's own (exact) load.
            assert abs(float(surface.normal_load(d)) - load) <= RELATIVE_TOLERANCE * load
            assert (value, slope) == kernel_load_and_slope(surface)(d)
            # Step for step the iteration written out in Python.
            assert (d, value, slope, evaluations) == python_newton(surface, load, start, lo, hi)
            assert newton_separation(load, start, lo, hi, *arguments) == (d, value, slope)
            # The one kind's solver (what solve_separation runs) is the same, to the bit.
            own = kernels.statistical_newton_counted if kind == "statistical" else \
                kernels.direct_newton_counted
            assert own(load, start, lo, hi, *arguments) == (d, value, slope, evaluations)
            # The Python API runs the same kernel.
            assert solve_separation(surface, load, start, full_output=True) == (d, evaluations)


@numba.njit
def warm_loop(loads, lo, hi, kind, load_scale, height_std, heights, counts, hertz, addresses, out):
    """A model's step kernel, per changed load: the statistical start, or Newton from the predicted one."""
    d, value, slope = newton_separation(loads[0], 0.0, lo, hi, kind, load_scale, height_std, heights, counts,
                                        hertz, addresses)
    out[0] = d
    for k in range(1, loads.size):
        if loads[k] != loads[k - 1]:
            if kind == STATISTICAL:
                d, value, slope, _ = statistical_separation(loads[k], lo, hi, load_scale, height_std,
                                                            addresses)
            else:
                start = predicted_start(d, value, slope, loads[k])
                lo = direct_lower_bound(loads[k], heights, counts, hertz)
                d, value, slope = newton_separation(loads[k], start, lo, hi, kind, load_scale, height_std,
                                                    heights, counts, hertz, addresses)
        out[k] = d


@pytest.mark.parametrize("kind", ["statistical", "direct"])
def test_warm_started_series_equals_cold_solves(statistical, direct, kind):
    surface = statistical if kind == "statistical" else direct
    arguments = kernel_arguments(surface)
    t = np.linspace(0.0, 1.0, 1500)
    loads = np.exp(np.log(1e-3) + np.log(1e6) * (0.5 - 0.5 * np.cos(2 * np.pi * t)))   # 1e-3 .. 1e3 N
    loads[700:720] = loads[700]
    lo, hi = bracket(surface, float(loads[0]))
    warm = np.empty(loads.size)
    warm_loop(loads, lo, hi, *arguments, warm)
    series = np.empty(loads.size)
    evaluations = np.empty(loads.size, dtype=np.int64)
    newton_separation_series(loads, 0.0, surface.separation_range[0], hi, *arguments, series, evaluations)
    cold = np.array([solve_separation(surface, load) for load in loads.tolist()])
    # Warm and cold solutions both meet |N(d) - N| <= 1e-10 N, so they may
    # differ by up to 2e-10 N / |dN/dd| in d: about 1e-11 of d at s = 3,
    # where d |dlog N/dd| is near 10.  Measured: up to 1.4e-11 relative.
    allowed = 2.0 * RELATIVE_TOLERANCE * loads / np.abs(surface.normal_load_slope(cold)) * (1.0 + 1e-6)
    assert np.all(np.abs(warm - cold) <= allowed + 4.0 * np.spacing(np.abs(cold)))
    np.testing.assert_allclose(warm, cold, rtol=5e-11, atol=0)
    # The kernel series is the kernel building blocks' loop, and the Python series.
    np.testing.assert_array_equal(series, warm)
    np.testing.assert_array_equal(series, solve_separation_series(surface, loads, initial=0.0))
    assert np.all(evaluations[701:720] == 0)
    if kind == "statistical":
        # The statistical start: one evaluation per changed load.  (A direct
        # surface near 1e-3 N has a handful of summits in contact, and N(d)
        # kinks where one enters: up to 13 evaluations there.)
        assert np.all(np.delete(evaluations, [0]) <= 1)
    N = np.array([float(surface.normal_load(x)) for x in series])
    assert np.all(np.abs(N - loads) <= RELATIVE_TOLERANCE * loads)
