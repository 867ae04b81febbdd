"""The nominal area of a ball on a flat, its macroscopic Hertz contact.

See :ref:`guide-measured-surfaces-ball`.

On a ball-on-flat tribometer the rough contact is not the whole sample: it
is the patch the ball flattens.  Hertz's solution for a sphere of radius
``R_b`` pressed on a flat by ``N`` gives the contact radius

    a = (3 N R_b / (4 E*))^(1/3)

and the nominal area ``A0 = pi a^2`` over which the asperities meet
(``E*`` of the same material pair as the asperities).  ``[model.surface]
ball_radius`` puts this ``A0`` in place of ``nominal_area``
(:func:`polind.contact.build_surface`).  **Choice**: it is the nominal area at
every load, ``A0(N) = pi (3 N R_b / (4 E*))^(2/3)``, and the summit counts
scale with it; under a varying load the Pol-Ind step scales the surface of
its table load by ``A0(N) / A0(N_t)``
(:func:`polind.kernels.pol_ind.area_ratio`).

The bulk under the contact is no rigid backing: the smooth ball's own
tangential stiffness is Mindlin's ``8 G* a`` of its Hertz contact, in series
with the asperities (:func:`bulk_stiffness`, :ref:`guide-pol-ind-bulk`).
"""

from __future__ import annotations

import math

from polind.contact._checks import positive_number

__all__ = ["hertz_contact_radius", "ball_contact_area", "bulk_stiffness"]


def hertz_contact_radius(normal_load, ball_radius, E_star) -> float:
    """``a = (3 N R_b / (4 E*))^(1/3)`` [m]: Hertz's contact radius of a ball on a flat.

    Parameters
    ----------
    normal_load : float
        ``N`` [N].
    ball_radius : float
        ``R_b`` [m].
    E_star : float
        Effective modulus ``E*`` [Pa].

    Examples
    --------
    >>> round(hertz_contact_radius(5.0, 3e-3, 1.15e11) * 1e6, 2)   # a 6 mm steel ball at 5 N
    46.08
    """
    N = positive_number(normal_load, "normal_load")
    R = positive_number(ball_radius, "surface.ball_radius")
    E = positive_number(E_star, "E_star")
    return (3.0 * N * R / (4.0 * E)) ** (1.0 / 3.0)


def ball_contact_area(normal_load, ball_radius, E_star) -> float:
    """``A0 = pi a^2`` [m^2] with ``a`` of :func:`hertz_contact_radius`.

    Examples
    --------
    >>> a = hertz_contact_radius(5.0, 3e-3, 1.15e11)
    >>> ball_contact_area(5.0, 3e-3, 1.15e11) == math.pi * a * a
    True
    """
    radius = hertz_contact_radius(normal_load, ball_radius, E_star)
    return math.pi * radius * radius


def bulk_stiffness(params) -> float:
    """``8 G* a`` [N/m]: the smooth ball's Mindlin stiffness, in series with its asperities.

    ``a`` is :func:`hertz_contact_radius` at the model's ``normal_load`` and
    ``G*`` the effective shear modulus of the pair.  ``inf`` (no spring) for
    a flat (no ``surface.ball_radius``) or with ``surface.bulk_compliance =
    false`` (:ref:`guide-pol-ind-bulk`).

    Parameters
    ----------
    params : mapping
        A validated pol-ind ``[model]`` table (``normal_load``, ``surface``,
        ``materials``).

    Examples
    --------
    >>> table = {"normal_load": 5.0, "surface": {"ball_radius": 3e-3},
    ...          "materials": {"youngs_modulus": [210e9, 210e9], "poisson_ratio": [0.3, 0.3]}}
    >>> round(bulk_stiffness(table) / 1e6, 1)        # 8 G* a, a = 46 um, G* = 23.7 GPa
    8.7
    """
    from polind.contact.materials import effective_moduli

    surface = params["surface"]
    if surface.get("ball_radius") is None or surface.get("bulk_compliance") is False:
        return math.inf
    (E1, E2), (nu1, nu2) = params["materials"]["youngs_modulus"], params["materials"]["poisson_ratio"]
    E_star, G_star = effective_moduli(E1, nu1, E2, nu2)
    return 8.0 * G_star * hertz_contact_radius(params["normal_load"], surface["ball_radius"], E_star)
