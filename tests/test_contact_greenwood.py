"""Greenwood–Williamson integrals F_m (MODELS.md 7.3) against quadrature and standard values."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from polind.contact.greenwood import VALID_RANGE, gw_integral, half_integer_pair, three_halves_inverse
from polind.errors import InputError

ORDERS = (0.0, 0.5, 1.0, 1.5)


def reference_F(m: float, s: float) -> float:
    """F_m(s) by adaptive quadrature in the normalised variable.

    With t = s + v^2 the integrand 2 v^(2m+1) phi(s + v^2) is smooth at the
    contact edge; phi(s) is taken out analytically so that values near
    1e-23 (s = 10) keep their relative accuracy.
    """
    def integrand(v):
        return 2.0 * v ** (2.0 * m + 1.0) * math.exp(-s * v * v - 0.5 * v**4)

    # The integrand peaks at v^2 = max(-s, 0) + O(1) and is below e^-60 of
    # its peak beyond v^2 = max(-s, 0) + 12.
    peak = math.sqrt(max(-s, 0.0) + 1.0)
    end = math.sqrt(max(-s, 0.0) + 12.0)
    total = 0.0
    for a, b in ((0.0, peak), (peak, end), (end, end + 5.0)):
        part, _ = integrate.quad(integrand, a, b, epsabs=0.0, epsrel=1e-13, limit=200)
        total += part
    return math.exp(-0.5 * s * s) / math.sqrt(2.0 * math.pi) * total


@pytest.mark.parametrize(
    "m, s, printed",
    [
        (0.0, 0.0, "0.5"),
        (1.0, 0.0, "0.398942"),
        (1.5, 0.0, "0.430020"),
        (1.5, 1.0, "0.0756682"),
        (1.5, 2.0, "0.00664818"),
    ],
)
def test_standard_values_to_their_printed_digits(m, s, printed):
    decimals = len(printed.split(".")[1])
    assert f"{gw_integral(m, s):.{decimals}f}" == printed


@pytest.mark.parametrize("m", ORDERS)
def test_matches_quadrature_to_1e_10_over_the_valid_range(m):
    s = np.concatenate([np.linspace(*VALID_RANGE, 61), [-1e-9, 1e-9, 1e-7, -1e-7, 2.8, 9.99]])
    expected = np.array([reference_F(m, x) for x in s])
    got = gw_integral(m, s)
    rel = np.abs(got / expected - 1.0)
    assert rel.max() <= 1e-10, f"worst at s = {s[rel.argmax()]}: {rel.max():.2e}"


def test_quadrature_reference_itself_matches_the_closed_forms():
    # The reference must be right for the test above to mean anything.
    for s in (-4.0, 0.0, 3.0, 9.0):
        q = 0.5 * math.erfc(s / math.sqrt(2.0))
        phi = math.exp(-0.5 * s * s) / math.sqrt(2.0 * math.pi)
        assert reference_F(0.0, s) == pytest.approx(q, rel=1e-12)
        assert reference_F(1.0, s) == pytest.approx(phi - s * q, rel=1e-10)


@pytest.mark.parametrize("m, lower", [(1.5, 0.5), (1.0, 0.0), (0.5, None)])
def test_derivative_identity(m, lower):
    """dF_m/ds = -m F_{m-1}, by central differences (truncation ~h^2)."""
    if lower is None:
        # F_{-1/2} is not offered; check F_{1/2}' against quadrature of it.
        def lower_values(s):
            return np.array(
                [integrate.quad(lambda v: 2.0 * math.exp(-0.5 * (x + v * v) ** 2), 0, 12, epsabs=0.0, epsrel=1e-13)[0]
                 / math.sqrt(2.0 * math.pi) for x in s]
            )
    else:
        def lower_values(s):
            return gw_integral(lower, s)
    s = np.linspace(-4.5, 9.5, 29)
    h = 1e-4
    derivative = (gw_integral(m, s + h) - gw_integral(m, s - h)) / (2.0 * h)
    expected = -m * lower_values(s)
    np.testing.assert_allclose(derivative, expected, rtol=2e-6)


def test_derivative_identity_integrated():
    """F_{3/2}(a) - F_{3/2}(b) = 1.5 ∫_a^b F_{1/2}(s) ds, to quadrature accuracy."""
    for a, b in ((-5.0, -2.0), (-1.0, 1.5), (2.0, 6.0), (6.0, 10.0)):
        area, _ = integrate.quad(lambda x: gw_integral(0.5, x), a, b, epsabs=0.0, epsrel=1e-13)
        assert gw_integral(1.5, a) - gw_integral(1.5, b) == pytest.approx(1.5 * area, rel=1e-11)


def test_scalar_fast_path_matches_the_array_path():
    s = np.linspace(-6.0, 12.0, 181)
    pairs = np.array([half_integer_pair(x) for x in s])
    np.testing.assert_allclose(pairs[:, 0], gw_integral(0.5, s), rtol=1e-13)
    np.testing.assert_allclose(pairs[:, 1], gw_integral(1.5, s), rtol=1e-13)
    # A scalar s runs the scalar pair: the array path's values, to the bit.
    for m in (0.5, 1.5):
        assert [gw_integral(m, x) for x in s] == gw_integral(m, s).tolist()
        assert [gw_integral(m, np.float64(x)) for x in s[::30]] == gw_integral(m, s[::30]).tolist()


def test_shapes_scalars_and_infinities():
    assert isinstance(gw_integral(1.5, 0.3), float)
    grid = np.zeros((2, 3))
    assert gw_integral(0.5, grid).shape == (2, 3)
    assert gw_integral(1.5, np.array([np.inf]))[0] == 0.0
    assert gw_integral(1, np.array([np.inf]))[0] == 0.0
    assert gw_integral(0, np.array([-np.inf]))[0] == 1.0


def test_monotone_decreasing_in_s():
    s = np.linspace(-5.0, 10.0, 3001)
    for m in ORDERS:
        assert np.all(np.diff(gw_integral(m, s)) < 0.0)


def test_inverse_guess_is_close():
    for s in np.linspace(-5.0, 10.0, 77):
        assert abs(three_halves_inverse(gw_integral(1.5, s)) - s) < 2e-3


@pytest.mark.parametrize("m", [2, -0.5, "1.5", None])
def test_unknown_order_is_an_input_error(m):
    with pytest.raises(InputError, match="'m' of gw_integral"):
        gw_integral(m, 0.0)
