"""The iterative method: separation under a normal load (MODELS.md 7.4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from polind.contact.materials import effective_moduli
from polind.contact.separation import RELATIVE_TOLERANCE, solve_separation, solve_separation_series
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.errors import InputError

ETA, A0, R, SIGMA = 1e10, 1e-4, 50e-6, 0.5e-6
E_STAR, G_STAR = effective_moduli(210e9, 0.3, 210e9, 0.3)


@pytest.fixture(scope="module")
def statistical():
    return StatisticalSurface(ETA, A0, R, SIGMA, E_STAR, G_STAR)


@pytest.fixture(scope="module")
def direct():
    # 100 000 summits: a tenth of the default area.
    return DirectSurface.from_seed(ETA, 1e-5, SIGMA, R, E_STAR, G_STAR, seed=0)


def plain_direct_load(surface, d):
    delta = np.maximum(surface.heights - d, 0.0)
    return float(np.sum(surface.counts * 4.0 / 3.0 * E_STAR * math.sqrt(R) * delta**1.5))


LOADS = [1e-9, 1e-6, 1e-3, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5, 1e6]


@pytest.mark.parametrize("load", LOADS)
def test_statistical_converges_to_1e_10(statistical, load):
    d, evaluations = solve_separation(statistical, load, full_output=True)
    assert abs(float(statistical.normal_load(d)) - load) <= RELATIVE_TOLERANCE * load
    assert evaluations <= 6
    assert SIGMA * -5 <= d <= SIGMA * 10


@pytest.mark.parametrize("load", [1e-3, 0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5])
def test_direct_converges_to_1e_10(direct, load):
    d, evaluations = solve_separation(direct, load, full_output=True)
    assert abs(plain_direct_load(direct, d) - load) <= RELATIVE_TOLERANCE * load
    assert evaluations <= 12


def test_only_the_top_summit_touching_gives_the_hertz_separation():
    surface = DirectSurface([1e-6, 0.0], R, E_STAR, G_STAR)
    load = 0.37
    expected = 1e-6 - (load / (4.0 / 3.0 * E_STAR * math.sqrt(R))) ** (2.0 / 3.0)
    assert expected > 0.0
    d, evaluations = solve_separation(surface, load, full_output=True)
    assert d == pytest.approx(expected, rel=1e-12)
    assert evaluations <= 8


def test_any_starting_point_converges(statistical, direct):
    for start in SIGMA * np.array([-40.0, -5.0, 0.0, 7.0, 100.0]):
        for surface in (statistical, direct):
            d = solve_separation(surface, 50.0, initial=start)
            assert float(surface.normal_load(d)) == pytest.approx(50.0, rel=RELATIVE_TOLERANCE)


def test_series_warm_start(statistical, direct):
    t = np.linspace(0.0, 1.0, 2000)
    loads = 100.0 * (1.0 + 0.5 * np.sin(2 * np.pi * 3 * t))
    loads[1000:1010] = loads[1000]          # a held load reuses the previous d
    for surface in (statistical, direct):
        d, evaluations = solve_separation_series(surface, loads, full_output=True)
        N = np.array([float(surface.normal_load(x)) for x in d])
        assert np.all(np.abs(N - loads) <= RELATIVE_TOLERANCE * loads)
        # Warm started from the previous sample: two evaluations or fewer
        # (a cold start takes three; sample 1010 follows a jump of ten samples).
        assert np.delete(evaluations, [0, 1010]).max() <= 2
        assert np.all(evaluations[1001:1010] == 0)
        np.testing.assert_array_equal(d[1000:1010], d[1000])
        assert d[0] == solve_separation(surface, loads[0])


@pytest.mark.parametrize("load", [0.0, -3.0, math.nan, math.inf, "100", None, True])
def test_bad_loads(statistical, direct, load):
    for surface in (statistical, direct):
        with pytest.raises(InputError, match="'normal_load' of pol-ind must be a positive finite number"):
            solve_separation(surface, load)


def test_load_too_large_or_small_for_the_statistical_surface(statistical):
    smallest, largest = statistical.load_range
    assert largest == pytest.approx(float(statistical.normal_load(-5 * SIGMA)))
    assert smallest == pytest.approx(float(statistical.normal_load(10 * SIGMA)))
    with pytest.raises(InputError, match="too large .* below -5"):
        solve_separation(statistical, 1.01 * largest)
    with pytest.raises(InputError, match="too small .* above 10"):
        solve_separation(statistical, 0.99 * smallest)
    # The ends themselves are reachable.
    assert solve_separation(statistical, largest) == pytest.approx(-5 * SIGMA, rel=1e-9)
    assert solve_separation(statistical, smallest) == pytest.approx(10 * SIGMA, rel=1e-9)


def test_direct_accepts_loads_that_put_every_summit_in_contact(direct):
    """Below the lowest summit all summits touch and N keeps growing (documented choice)."""
    assert direct.load_range == (direct.smallest_load, math.inf) and direct.smallest_load < 1e-20
    all_touching = plain_direct_load(direct, direct.heights[0])
    for factor in (0.999, 1.5, 100.0):
        load = factor * all_touching
        d = solve_separation(direct, load)
        assert (d < direct.heights[0]) == (factor > 1.0)
        assert abs(plain_direct_load(direct, d) - load) <= RELATIVE_TOLERANCE * load


def test_a_single_summit_carries_any_load():
    surface = DirectSurface([1e-6], R, E_STAR, G_STAR)
    for load in (1e-6, 0.37, 1e3):
        expected = 1e-6 - (load / (4.0 / 3.0 * E_STAR * math.sqrt(R))) ** (2.0 / 3.0)
        d, evaluations = solve_separation(surface, load, full_output=True)
        assert d == pytest.approx(expected, rel=1e-12)
        assert evaluations == 1


def test_bad_initial_separation(statistical):
    for initial in (math.nan, "0", math.inf):
        with pytest.raises(InputError, match="'initial' separation"):
            solve_separation(statistical, 1.0, initial=initial)


def test_series_errors_name_the_sample(statistical):
    with pytest.raises(InputError, match="Got nan at index 2"):
        solve_separation_series(statistical, [1.0, 2.0, math.nan, 4.0])
    with pytest.raises(InputError, match="at index 1"):
        solve_separation_series(statistical, [1.0, 1e12])
    with pytest.raises(InputError, match="1-D"):
        solve_separation_series(statistical, [[1.0]])
