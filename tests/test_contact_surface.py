"""Statistical and direct surfaces (MODELS.md 7.1, 7.3)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from polind.contact.materials import effective_moduli
from polind.contact.surface import DirectSurface, StatisticalSurface, read_summit_heights
from polind.errors import InputError

ETA, A0, R, SIGMA = 1e10, 1e-4, 50e-6, 0.5e-6
E_STAR, G_STAR = effective_moduli(210e9, 0.3, 210e9, 0.3)


@pytest.fixture(scope="module")
def statistical():
    return StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR)


def hertz(delta):
    return 4.0 / 3.0 * E_STAR * math.sqrt(R) * delta**1.5


def reference_totals(d):
    """N, n, A by quadrature of the Gaussian in metres' worth of sigma units.

    eta A0 ∫_d^∞ f(h - d) Phi(h) dh with h = sigma t, written from MODELS.md
    7.1 and 7.3 without the F_m.
    """
    s = d / SIGMA
    phi = lambda t: math.exp(-0.5 * t * t) / math.sqrt(2 * math.pi)  # noqa: E731
    parts = {
        "N": lambda t: hertz(SIGMA * (t - s)) * phi(t),
        "n": lambda t: phi(t),
        "A": lambda t: math.pi * R * SIGMA * (t - s) * phi(t),
    }
    out = {}
    for key, f in parts.items():
        value = 0.0
        for a, b in ((s, s + 1.0), (s + 1.0, max(s, 0.0) + 14.0)):
            value += integrate.quad(f, a, b, epsabs=0.0, epsrel=1e-12, limit=200)[0]
        out[key] = ETA * A0 * value
    return out


@pytest.mark.parametrize("s", [-4.0, -1.0, 0.0, 1.5, 3.0, 6.0])
def test_statistical_totals_match_quadrature(statistical, s):
    d = s * SIGMA
    ref = reference_totals(d)
    assert float(statistical.normal_load(d)) == pytest.approx(ref["N"], rel=1e-9)
    assert float(statistical.contacts(d)) == pytest.approx(ref["n"], rel=1e-9)
    assert float(statistical.real_area(d)) == pytest.approx(ref["A"], rel=1e-9)


def test_statistical_slope_is_the_derivative(statistical):
    d = SIGMA * np.linspace(-4.5, 9.0, 40)
    h = 1e-5 * SIGMA
    numeric = (statistical.normal_load(d + h) - statistical.normal_load(d - h)) / (2 * h)
    np.testing.assert_allclose(statistical.normal_load_slope(d), numeric, rtol=1e-7)
    for x in d[::7]:
        N, slope = statistical.load_and_slope(float(x))
        assert N == pytest.approx(float(statistical.normal_load(x)), rel=1e-13)
        assert slope == pytest.approx(float(statistical.normal_load_slope(x)), rel=1e-13)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.floats(-5.0, 9.9), st.floats(1e-6, 0.1))
def test_statistical_load_decreasing_and_continuous(statistical, s, step):
    d1, d2 = s * SIGMA, (s + step) * SIGMA
    N1, N2 = float(statistical.normal_load(d1)), float(statistical.normal_load(d2))
    assert N2 < N1
    # Continuity with the slope bound: N1 - N2 <= |N'(d1)| (d2 - d1) (N
    # convex), up to the rounding of N itself.
    assert N1 - N2 <= -float(statistical.normal_load_slope(d1)) * (d2 - d1) * (1 + 1e-9) + 1e-12 * N1


def _plain_sums(heights, d):
    """Reference direct sums: a Python loop over the summits."""
    N = slope = n = area = 0.0
    for h in heights:
        if h > d:
            delta = h - d
            N += hertz(delta)
            slope -= 2.0 * E_STAR * math.sqrt(R) * math.sqrt(delta)
            n += 1
            area += math.pi * R * delta
    return N, slope, n, area


def test_direct_sums_match_a_plain_loop():
    rng = np.random.default_rng(11)
    heights = SIGMA * rng.standard_normal(500)
    surface = DirectSurface(heights, R, E_STAR, G_STAR)
    for d in SIGMA * np.array([-3.5, -0.7, 0.0, 1.1, 2.4, 5.0]):
        N, slope, n, area = _plain_sums(heights, d)
        assert float(surface.normal_load(d)) == pytest.approx(N, rel=1e-12, abs=0)
        assert float(surface.normal_load_slope(d)) == pytest.approx(slope, rel=1e-12, abs=0)
        assert float(surface.contacts(d)) == n
        assert float(surface.real_area(d)) == pytest.approx(area, rel=1e-12, abs=0)
        assert surface.load_and_slope(d) == pytest.approx((N, slope), rel=1e-12)
    grid = SIGMA * np.array([[0.0, 1.0], [2.0, 3.0]])
    assert surface.normal_load(grid).shape == (2, 2)


@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.floats(-3.0, 3.0), st.floats(1e-9, 0.5))
def test_direct_load_decreasing_and_continuous(s, step):
    surface = _small_sample()
    d1, d2 = s * SIGMA, (s + step) * SIGMA
    N1, N2 = float(surface.normal_load(d1)), float(surface.normal_load(d2))
    assert N2 < N1
    assert N1 - N2 <= -float(surface.normal_load_slope(d1)) * (d2 - d1) * (1 + 1e-9) + 1e-12 * N1


_SAMPLE = {}


def _small_sample():
    if "surface" not in _SAMPLE:
        heights = SIGMA * np.random.default_rng(5).standard_normal(2000)
        _SAMPLE["surface"] = DirectSurface(heights, R, E_STAR, G_STAR)
    return _SAMPLE["surface"]


def test_seeded_sample_converges_on_the_statistical_totals(statistical):
    """200 000 seeded summits: N, n, A within 4 standard errors of GW."""
    area = 2e-5
    sample = DirectSurface.from_seed(ETA, area, SIGMA, R, E_STAR, G_STAR, seed=7)
    assert sample.asperity_count == round(ETA * area)
    ratio = area / A0
    heights = sample.heights
    for s in (-1.0, 0.0, 1.0, 2.0, 2.5):
        d = s * SIGMA
        delta = np.maximum(heights - d, 0.0)
        per_summit = {
            "N": hertz(delta),
            "n": (delta > 0).astype(float),
            "A": math.pi * R * delta,
        }
        expected = {
            "N": ratio * float(statistical.normal_load(d)),
            "n": ratio * float(statistical.contacts(d)),
            "A": ratio * float(statistical.real_area(d)),
        }
        got = {
            "N": float(sample.normal_load(d)),
            "n": float(sample.contacts(d)),
            "A": float(sample.real_area(d)),
        }
        for key in per_summit:
            standard_error = math.sqrt(heights.size) * per_summit[key].std()
            assert abs(got[key] - expected[key]) < 4.0 * standard_error, (s, key)
            # and the sample's own sums are those of its summits
            assert got[key] == pytest.approx(per_summit[key].sum(), rel=1e-10)


def test_from_seed_draws_default_rng_heights():
    sample = DirectSurface.from_seed(1e10, 1.23456e-7, SIGMA, R, E_STAR, G_STAR, seed=42)
    expected = np.sort(SIGMA * np.random.default_rng(42).standard_normal(1235))
    np.testing.assert_array_equal(sample.heights, expected)
    np.testing.assert_array_equal(sample.counts, np.ones(1235))


def test_equal_heights_are_grouped():
    surface = DirectSurface([3e-7, 1e-7, 3e-7, 2e-7], R, E_STAR, G_STAR)
    np.testing.assert_array_equal(surface.heights, [1e-7, 2e-7, 3e-7])
    np.testing.assert_array_equal(surface.counts, [1, 1, 2])
    assert float(surface.normal_load(0.0)) == pytest.approx(hertz(1e-7) + hertz(2e-7) + 2 * hertz(3e-7))
    weighted = DirectSurface([2e-7, 1e-7], R, E_STAR, G_STAR, counts=[0.5, 4.0])
    assert float(weighted.normal_load(0.0)) == pytest.approx(0.5 * hertz(2e-7) + 4 * hertz(1e-7))


@pytest.mark.parametrize(
    "heights, counts, match",
    [
        ([], None, "non-empty"),
        ([[1e-7]], None, "1-D"),
        ([1e-7, math.nan], None, "finite"),
        ([1e-7, 2e-7], [1.0], "match the heights"),
        ([1e-7, 2e-7], [1.0, -1.0], "positive"),
    ],
)
def test_bad_direct_surfaces(heights, counts, match):
    with pytest.raises(InputError, match=match):
        DirectSurface(heights, R, E_STAR, G_STAR, counts=counts)


@pytest.mark.parametrize(
    "args, name",
    [
        ((0.0, A0, R, SIGMA), "surface.asperity_density"),
        ((ETA, -A0, R, SIGMA), "surface.nominal_area"),
        ((ETA, A0, math.nan, SIGMA), "surface.asperity_radius"),
        ((ETA, A0, R, "0.5e-6"), "surface.height_std"),
    ],
)
def test_bad_statistical_surfaces(args, name):
    with pytest.raises(InputError, match=name):
        StatisticalSurface(*args, E_STAR, G_STAR)


def test_bad_seeded_samples():
    with pytest.raises(InputError, match="asperity count"):
        DirectSurface.from_seed(1e10, 1e-11, SIGMA, R, E_STAR, G_STAR)
    with pytest.raises(InputError, match="asperity count"):
        DirectSurface.from_seed(1e12, 1.0, SIGMA, R, E_STAR, G_STAR)
    with pytest.raises(InputError, match="discretisation.seed"):
        DirectSurface.from_seed(1e10, 1e-7, SIGMA, R, E_STAR, G_STAR, seed=-1)


def test_read_summit_heights(tmp_path):
    path = tmp_path / "summits.csv"
    path.write_text("x,h\n0,1e-7\n1,-2.5e-7\n\n2,3e-7\n")
    np.testing.assert_array_equal(read_summit_heights(path), [1e-7, -2.5e-7, 3e-7])
    surface = DirectSurface.from_csv(path, R, E_STAR, G_STAR)
    assert surface.asperity_count == 3


@pytest.mark.parametrize(
    "text, match",
    [
        ("", "is empty"),
        ("height\n1e-7\n", "column 'h'"),
        ("h\n", "no data rows"),
        ("h\n1e-7\nabc\n", "row 2 \\(line 3\\)"),
        ("h\n1e-7\ninf\n", "row 2 \\(line 3\\)"),
        ("x,h\n1,1e-7\n2\n", "row 2 \\(line 3\\)"),
    ],
)
def test_bad_heights_files(tmp_path, text, match):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=match) as error:
        read_summit_heights(path)
    assert "bad.csv" in str(error.value)
    assert "\n" not in str(error.value)


def test_missing_heights_file(tmp_path):
    with pytest.raises(InputError, match="cannot be read"):
        read_summit_heights(tmp_path / "nowhere.csv")
