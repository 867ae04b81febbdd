"""Effective elastic moduli of a contacting pair (the user guide, :ref:`guide-pol-ind-surface`).

Hertz (normal) and Cattaneo–Mindlin (tangential) contact of two elastic
bodies behave like a rigid body pressed on one body with effective moduli
``E*`` and ``G*``; every asperity law of :mod:`polind.contact.asperity` takes
these two numbers.
"""

from __future__ import annotations

from polind.contact._checks import poisson_ratio, positive_number

__all__ = ["effective_moduli", "shear_modulus"]


def shear_modulus(youngs_modulus: float, poisson: float) -> float:
    """Shear modulus of an isotropic solid, ``G = E / (2 (1 + nu))``.

    Parameters
    ----------
    youngs_modulus : float
        Young's modulus ``E`` [Pa].
    poisson : float
        Poisson's ratio ``nu`` [-].

    Returns
    -------
    float
        Shear modulus ``G`` [Pa].
    """
    return youngs_modulus / (2.0 * (1.0 + poisson))


def effective_moduli(E1: float, nu1: float, E2: float, nu2: float) -> tuple[float, float]:
    """Effective normal and tangential moduli of a pair of solids (:ref:`guide-pol-ind-surface`).

    ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`` and
    ``1/G* = (2 - nu1)/G1 + (2 - nu2)/G2`` with ``G = E / (2 (1 + nu))``.

    Parameters
    ----------
    E1, E2 : float
        Young's moduli of the two bodies [Pa], positive.
    nu1, nu2 : float
        Poisson's ratios of the two bodies [-], in (-1, 0.5].

    Returns
    -------
    E_star : float
        Effective (contact) modulus ``E*`` [Pa].
    G_star : float
        Effective tangential modulus ``G*`` [Pa].

    Raises
    ------
    polind.InputError
        If a modulus is not a positive finite number or a Poisson ratio lies
        outside (-1, 0.5].

    Examples
    --------
    >>> E_star, G_star = effective_moduli(210e9, 0.3, 210e9, 0.3)
    >>> round(E_star / 1e9, 3), round(G_star / 1e9, 3)
    (115.385, 23.756)
    """
    E1 = positive_number(E1, "materials.youngs_modulus[0]")
    E2 = positive_number(E2, "materials.youngs_modulus[1]")
    nu1 = poisson_ratio(nu1, "materials.poisson_ratio[0]")
    nu2 = poisson_ratio(nu2, "materials.poisson_ratio[1]")
    E_star = 1.0 / ((1.0 - nu1 * nu1) / E1 + (1.0 - nu2 * nu2) / E2)
    G1 = shear_modulus(E1, nu1)
    G2 = shear_modulus(E2, nu2)
    G_star = 1.0 / ((2.0 - nu1) / G1 + (2.0 - nu2) / G2)
    return E_star, G_star
