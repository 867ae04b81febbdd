"""From the pol-ind model table to the loaded contact.

:func:`build_contact` reads the keys of the ``[model]`` table of a
``pol-ind`` model file that the contact mechanics needs (``normal_load``,
``static_coefficient``, ``surface``, ``materials``, ``discretisation``),
builds the surface, solves the separation and builds the element table;
:meth:`Contact.summary` is what ``polind surface --json`` prints.

See the user guide, :ref:`guide-pol-ind` (the surface, the separation and the
elements), and the keys in :ref:`formats-model-files`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass

from polind.contact._checks import positive_number
from polind.contact.ball import ball_contact_area
from polind.contact.elements import ElementTable, element_table
from polind.contact.materials import effective_moduli
from polind.contact.microslip import microslip_of, microslip_table
from polind.contact.plasticity import HARDNESS_PER_YIELD_STRENGTH, Plasticity
from polind.contact.separation import RELATIVE_TOLERANCE, solve_separation
from polind.contact.surface import DirectSurface, StatisticalSurface
from polind.contact.validity import validity_figures, validity_warning
from polind.errors import InputError, describe

__all__ = ["Contact", "build_contact", "build_surface", "measured_surface", "plasticity_of",
           "PLASTIC_KEYS"]

#: The keys of ``[model.materials]`` that make the asperities elastic-plastic.
PLASTIC_KEYS = ("hardness", "yield_strength")

class _Keys(dict):
    """A sub-table of the model table: a missing key is an InputError naming it."""

    table = ""

    def __missing__(self, key):
        raise InputError(f"Missing key '{self.table}.{key}' for a pol-ind contact; the formats "
                         f"page lists the keys of [model.{self.table}].")


@dataclass(frozen=True, eq=False)
class Contact:
    """A surface pressed by its normal load: separation and Maxwell-slip elements.

    Attributes
    ----------
    surface : StatisticalSurface or DirectSurface
        The rough surface with its materials.
    normal_load : float
        Applied normal load ``N_app`` [N].
    separation : float
        Separation ``d`` [m] with ``N(d) = N_app`` (to 1e-10 relative).
    elements : ElementTable
        The modified Maxwell-slip elements at ``d``: with
        ``tangential = "mindlin"`` their microslip sub-elements, the elements
        themselves the table's ``parent`` (:ref:`guide-pol-ind-microslip`).
    unmatched_load : float
        ``N_app - N(d)`` [N] where the separation cannot meet the load
        balance (a direct sum of elastic-plastic summits whose load jumps
        across ``N_app``, :ref:`guide-pol-ind-plasticity`); 0 where it does.
    """

    surface: StatisticalSurface | DirectSurface
    normal_load: float
    separation: float
    elements: ElementTable
    unmatched_load: float = 0.0

    @property
    def contacts(self) -> float:
        """Asperities in contact at the separation (expected number if statistical)."""
        return float(self.surface.contacts(self.separation))

    @property
    def real_area(self) -> float:
        """Real contact area at the separation [m^2]."""
        return float(self.surface.real_area(self.separation))

    def validity(self) -> dict:
        """The validity figures of the contact (:ref:`guide-pol-ind-validity`).

        ``plasticity_index`` (``None`` without a hardness),
        ``plastic_contact_share``, ``plastic_load_share``, ``mean_real_pressure``
        [Pa], ``peak_asperity_pressure`` [Pa] and ``unmatched_load`` [N]
        (:func:`polind.contact.validity.validity_figures`).
        """
        return validity_figures(self)

    def validity_warning(self) -> str | None:
        """The warning of a Hertzian contact beyond its validity (peak pressure above 10 GPa), or ``None``."""
        return validity_warning(self)

    def summary(self) -> dict:
        """Plain-float summary, the JSON object of ``polind surface --json``.

        Keys ``separation`` [m], ``contacts`` [-], ``real_area`` [m^2],
        ``normal_load`` [N], ``elements``, a list of
        ``{stiffness [N/m], breakaway_force [N], asperities [-], interference [m]}``,
        and ``validity`` (:meth:`validity`).  With microslip sub-elements
        (:ref:`guide-pol-ind-microslip`) also ``tangential`` (``"mindlin"``)
        and ``microslip_elements`` (sub-elements per element), and each
        element's ``slip_displacement`` ``u*`` [m]; ``elements`` lists the
        elements, not their sub-elements.
        """
        table = self.elements
        summary = {
            "separation": float(self.separation),
            "contacts": self.contacts,
            "real_area": self.real_area,
            "normal_load": float(self.normal_load),
            "elements": (table if table.parent is None else table.parent).records(),
            "validity": self.validity(),
        }
        if table.parent is not None:
            summary["tangential"] = "mindlin"
            summary["microslip_elements"] = table.microslip_elements
            for record, slip in zip(summary["elements"], table.slip_displacement.tolist()):
                record["slip_displacement"] = slip
        return summary


def _table(params: Mapping, key: str) -> dict:
    """A sub-table of the model table (a missing key is an InputError naming it)."""
    given = params.get(key)
    if given is None:
        given = {}
    if not isinstance(given, Mapping):
        raise InputError(f"The '{key}' of pol-ind must be a table. Got {describe(given)}.")
    keys = _Keys(given)
    keys.table = key
    return keys


def _number(params: Mapping, key: str) -> float:
    if key not in params:
        raise InputError(f"Missing key '{key}' for a pol-ind contact.")
    return positive_number(params[key], key)


def _pair(table: Mapping, key: str) -> tuple:
    """A two-entry list ``[body 1, body 2]`` of the materials table."""
    value = table[key]
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 2:
        raise InputError(
            f"The 'materials.{key}' of pol-ind must be a list of two numbers (body 1, body 2). "
            f"Got {describe(value)}."
        )
    return tuple(value)


def build_contact(params: Mapping, base_dir=None, *, surface=None) -> Contact:
    """Build the loaded contact of a pol-ind model table.

    Parameters
    ----------
    params : mapping
        The ``[model]`` table as nested dicts, with the keys
        ``normal_load`` [N], ``static_coefficient`` [-],
        ``surface`` = {``asperity_density`` [1/m^2], ``nominal_area`` [m^2],
        ``asperity_radius`` [m], ``height_std`` [m]},
        ``materials`` = {``youngs_modulus`` [Pa, Pa], ``poisson_ratio`` [-, -],
        optionally ``hardness`` [Pa] or ``yield_strength`` [Pa]},
        ``discretisation`` = {``summation`` ("statistical" or "direct"),
        ``elements`` (bins, statistical), ``seed`` (direct, sampled),
        ``heights_file`` (direct, measured), optionally ``tangential``
        ("elastic-slip" or "mindlin") and ``microslip_elements``}, as a validated pol-ind model
        has them (``PolInd(...).params``; :ref:`formats-model-files`).  A
        missing key is an error naming it; other keys of the model table are
        ignored (they are not the contact's).
    base_dir : str or os.PathLike, optional
        Directory a relative ``heights_file`` is read from (the model file's);
        default: the current directory.
    surface : StatisticalSurface or DirectSurface, optional
        The table's surface, already built (:func:`build_surface`); default:
        built here.

    Returns
    -------
    Contact

    Raises
    ------
    polind.InputError
        If a value used here is of the wrong type or out of range, the
        heights file is bad, or the surface cannot carry the load: also a
        load so small that no summit would be in contact (below a direct
        surface's :attr:`~polind.contact.surface.DirectSurface.smallest_load`;
        a contact carrying no asperity has no friction element and rests on
        nothing, so it is refused, not run).

    Examples
    --------
    >>> from polind.models import PolInd
    >>> contact = build_contact(PolInd.example_parameters())
    >>> summary = contact.summary()
    >>> len(summary["elements"]), round(summary["separation"] / 0.5e-6, 4)
    (64, 3.0042)
    """
    if not isinstance(params, Mapping):
        raise InputError(f"The model table of pol-ind must be a table. Got {describe(params)}.")
    normal_load = _number(params, "normal_load")
    static_coefficient = _number(params, "static_coefficient")
    if surface is None:
        surface = build_surface(params, base_dir)
    discretisation = _table(params, "discretisation")
    microslip = microslip_of(discretisation)
    separation = solve_separation(surface, normal_load)
    elements = element_table(
        surface, separation, static_coefficient, discretisation["elements"], normal_load=normal_load
    )
    if len(elements) == 0:
        # The separation solve refuses such loads (DirectSurface.smallest_load): a contact
        # resting on no asperity has no element to carry mu_s N and is no contact.
        raise InputError(f"The 'normal_load' of pol-ind leaves no summit in contact at the "
                         f"separation {separation!r} m. Got {normal_load!r} N; expected a load "
                         f"that some asperity carries.")
    if microslip is not None:
        # Cattaneo-Mindlin asperities: each element becomes its microslip sub-elements.
        elements = microslip_table(elements, microslip)
    unmatched = normal_load - float(surface.normal_load(separation))
    if abs(unmatched) <= RELATIVE_TOLERANCE * normal_load:
        unmatched = 0.0
    return Contact(surface=surface, normal_load=normal_load, separation=separation, elements=elements,
                   unmatched_load=unmatched)


def _file_name(value, key, base_dir):
    """A file the model table names, relative to ``base_dir`` (the model file's folder)."""
    if not isinstance(value, (str, os.PathLike)) or not os.fspath(value):
        raise InputError(f"The '{key}' of pol-ind must be a file name. Got {describe(value)}.")
    path = os.fspath(value)
    if base_dir is not None and not os.path.isabs(path):
        path = os.path.join(os.fspath(base_dir), path)
    return path


def measured_surface(surface_keys: Mapping, E_star, G_star, base_dir=None):
    """The direct surface of a ``[model.surface]`` table with a ``topography`` (a height map).

    Reads the map (:func:`polind.topography.load_measured_surface`, with the
    table's ``pixel_size``, ``short_cutoff``, ``remove_outliers``,
    ``levelling`` and ``channel``), and sums over its summits with their own
    radii, each standing for ``nominal_area / A_map`` summits
    (:meth:`~polind.contact.surface.DirectSurface.from_topography`).
    """
    from polind.topography import load_measured_surface

    path = _file_name(surface_keys["topography"], "surface.topography", base_dir)
    measured = load_measured_surface(path, surface_keys.get("pixel_size"),
                                     surface_keys.get("short_cutoff"),
                                     remove_outliers=surface_keys.get("remove_outliers", False),
                                     levelling=surface_keys.get("levelling", "plane"),
                                     channel=surface_keys.get("channel"))
    return DirectSurface.from_topography(measured, E_star, G_star,
                                         nominal_area=surface_keys.get("nominal_area"))


def build_surface(params: Mapping, base_dir=None):
    """The surface of a pol-ind model table (statistical or direct), before any load.

    The part of :func:`build_contact` that depends only on the ``surface``,
    ``materials`` and ``discretisation`` tables (for a direct surface the
    sampled or measured summits, sorted): what a fit may reuse while only
    friction keys move.
    """
    if not isinstance(params, Mapping):
        raise InputError(f"The model table of pol-ind must be a table. Got {describe(params)}.")
    surface_keys = _table(params, "surface")
    materials = _table(params, "materials")
    discretisation = _table(params, "discretisation")

    E1, E2 = _pair(materials, "youngs_modulus")
    nu1, nu2 = _pair(materials, "poisson_ratio")
    E_star, G_star = effective_moduli(E1, nu1, E2, nu2)
    if surface_keys.get("ball_radius") is not None:
        # Ball on flat: the nominal area is the ball's Hertz contact at the normal load.
        if surface_keys.get("nominal_area") is not None:
            raise InputError("A pol-ind surface takes its nominal area from 'surface.nominal_area' "
                             "or 'surface.ball_radius' (the Hertz contact of the ball), not both. "
                             "Remove one.")
        surface_keys["nominal_area"] = ball_contact_area(_number(params, "normal_load"),
                                                         surface_keys["ball_radius"], E_star)

    surface = _hertzian_surface(params, surface_keys, discretisation, E_star, G_star, base_dir)
    plasticity = plasticity_of(materials, nu1)
    return surface if plasticity is None else surface.with_plasticity(plasticity)


def plasticity_of(materials: Mapping, poisson) -> Plasticity | None:
    """The :class:`~polind.contact.plasticity.Plasticity` of a ``[model.materials]`` table, or ``None``.

    ``hardness = H`` [Pa] or ``yield_strength = Y`` [Pa] (then ``H = 2.8 Y``),
    not both; ``poisson`` is the rough body's Poisson ratio ``nu1``.
    """
    given = [key for key in PLASTIC_KEYS if materials.get(key) is not None]
    if len(given) == 2:
        raise InputError("The 'materials.hardness' and 'materials.yield_strength' of pol-ind are two "
                         "ways of giving one number (H = 2.8 Y): give one of them. Got both.")
    if not given:
        return None
    if given[0] == "hardness":
        return Plasticity(materials["hardness"], poisson)
    strength = positive_number(materials["yield_strength"], "materials.yield_strength")
    return Plasticity(HARDNESS_PER_YIELD_STRENGTH * strength, poisson)


def _hertzian_surface(params, surface_keys, discretisation, E_star, G_star, base_dir):
    """The surface of :func:`build_surface` with Hertzian asperities."""
    topography = surface_keys.get("topography")
    summation = discretisation.get("summation") or ("direct" if topography else "statistical")
    if topography is not None:
        if summation != "direct":
            raise InputError("The 'surface.topography' of pol-ind needs summation = \"direct\". "
                             "Got \"statistical\".")
        return measured_surface(surface_keys, E_star, G_star, base_dir)
    heights_file = discretisation.get("heights_file")
    if summation == "statistical":
        if heights_file is not None:
            raise InputError(
                "The 'discretisation.heights_file' of pol-ind is only read with "
                f"summation = \"direct\". Got {describe(heights_file)} with summation = \"statistical\"."
            )
        surface = StatisticalSurface(
            surface_keys["asperity_density"],
            surface_keys["nominal_area"],
            surface_keys["asperity_radius"],
            surface_keys["height_std"],
            E_star,
            G_star,
        )
    elif summation == "direct":
        if heights_file is not None:
            path = _file_name(heights_file, "discretisation.heights_file", base_dir)
            surface = DirectSurface.from_csv(path, surface_keys["asperity_radius"], E_star, G_star)
        else:
            surface = DirectSurface.from_seed(
                surface_keys["asperity_density"],
                surface_keys["nominal_area"],
                surface_keys["height_std"],
                surface_keys["asperity_radius"],
                E_star,
                G_star,
                seed=discretisation["seed"],
            )
    else:
        raise InputError(
            "The 'discretisation.summation' of pol-ind must be \"statistical\" or \"direct\". "
            f"Got {describe(summation)}."
        )
    return surface
