"""The Pol-Ind model: GMS elements built from asperity mechanics (:ref:`guide-pol-ind`).

Approach I (single asperities, Hertz and elastic slip) and the
Greenwood–Williamson statistics live in :mod:`polind.contact`; approach III
(the iterative separation solver) too.  This module assembles them into the
modified Maxwell-slip structure of approach II and runs it with the GMS
rate-state law (:ref:`guide-pol-ind-law`) on the project's one element machinery
(:mod:`polind.kernels.elements`).

**Choices** where the model leaves room (:ref:`guide-pol-ind-varying-load`
gives the rules for a time-varying load):

* The element table (bin or asperity heights ``h_j`` and counts ``n_j``) is
  built once per run at the separation of the run's *largest* normal load,
  so every asperity that touches during the run has an element; the table
  is fixed in ``h`` and carried in the state.  ``(k_j, W_j)`` follow
  ``d(t)``; elements out of contact carry nothing and restart from zero.
* Capacities are normalised at every sample so that ``sum W_j = mu_s N(t)``
  exactly (Amontons' law), ``alpha_j = W_j / sum W``.
* A continuation (``state=``) reuses the state's table; a load above the
  load the table was built for is an error (start the first chunk with the
  largest load, or pass the whole record at once).
* A ball on a flat (``surface.ball_radius``): the ball's Hertz area is the
  nominal area at every load, ``A0(N) = pi (3 N R_b / (4 E*))^(2/3)``, and the
  summit counts scale with it (:ref:`guide-measured-surfaces-ball`): at a
  load ``N`` the kernel solves the table load's surface at ``N / r`` and
  scales every element row by ``r = A0(N) / A0(N_t)``; a sampled direct
  surface keeps the summits drawn at the table load, each standing for ``r``.
* The separation ``d(t)`` is solved on the continuous surface
  (:ref:`guide-pol-ind-separation`).  Statistical bins are placed for the largest load, so far below it
  the table is coarser: with 64 bins built at 100 N the presliding
  stiffness is 0.03 % low at 50 N, 0.15 % at 5 N and 26 % at 1 N (one bin
  left in contact).  For loads that vary over decades, use more elements.
"""

from __future__ import annotations

import functools
import math
import warnings

import numpy as np

from polind.errors import InputError, ValidityWarning
from polind.models import pol_ind_fit
from polind.models.base import FrictionModel, StepFunctions, register
from polind.models.gms import GMS, gms_arrays, gms_scales
from polind.models.maxwell_slip import MaxwellSlip
from polind.models.params import Param, VISCOUS
from polind.models.pol_ind_tables import (DISCRETISATION_TABLE, MAP_KEYS, MAPPED_SURFACE_KEYS,
                                         MATERIALS_TABLE, SAMPLED_SURFACE_KEYS, SURFACE_TABLE,
                                         plastic_arrays, surface_of)


def default_table() -> dict:
    """The default Pol-Ind ``[model]`` table, ``type`` included (:meth:`PolInd.example_parameters`)."""
    return {"type": PolInd.type, **PolInd.example_parameters()}


@register
class PolInd(FrictionModel):
    """The Pol-Ind friction model (the user guide, :ref:`guide-pol-ind-law`).

    Each element ``j`` carries ``n_j`` asperities at interference
    ``delta_j``: stiffness ``k_j = n_j 8 G* sqrt(R delta_j)``, share of the
    load ``alpha_j = n_j P(delta_j) / N``; it sticks with ``dF_j/dt = k_j v``
    until ``|F_j| >= alpha_j |s(v)|`` and slips with
    ``dF_j/dt = sgn(v) C (1 - F_j/(alpha_j s(v)))``, where
    ``s(v) = sgn(v) N [mu_k + (mu_s - mu_k) exp(-|v/vs|^delta)]``.
    ``F = sum F_j + sigma2 v``.

    The parameters are the keys of the ``[model]`` table of a model file
    (:ref:`formats-model-files`), in SI units.

    Parameters
    ----------
    normal_load : float
        N [N]; a ``normal_load`` array given to :func:`polind.simulate`
        replaces it sample by sample.
    static_coefficient, kinetic_coefficient : float
        mu_s and mu_k.
    stribeck_velocity : float
        vs [m/s].
    stribeck_exponent : float, default 2
        delta.
    stribeck_shape : {"exponential", "rational"}
    attraction : float
        C [N/s].
    viscous_coefficient : float, default 0
        sigma2 [N s/m].
    surface : table
        ``asperity_density`` eta [1/m^2], ``nominal_area`` A0 [m^2],
        ``asperity_radius`` R [m], ``height_std`` sigma_a [m]; or a measured
        height map: ``topography`` (a file, relative to the model file),
        ``pixel_size`` [dx, dy] [m] (``.npy``/``.csv`` grids only),
        ``short_cutoff`` [m] (optional low-pass) and optionally
        ``nominal_area`` (default the map's area; each measured summit
        stands for ``A0 / A_map`` summits).  The map gives eta, R and
        sigma_a (every summit has its own height and radius) and implies
        direct summation; :meth:`statistical_equivalent` is the
        Greenwood–Williamson model of the same map.
    materials : table
        ``youngs_modulus`` [E1, E2] [Pa], ``poisson_ratio`` [nu1, nu2], and
        optionally the rough body's ``hardness`` H [Pa] or ``yield_strength``
        Y [Pa] (``H = 2.8 Y``): elastic-plastic asperities (Kogut–Etsion,
        :ref:`guide-pol-ind-plasticity`); without either they are Hertzian.
    discretisation : table
        ``summation`` "statistical" (``elements`` height bins) or "direct"
        (``seed`` for Gaussian summit heights, or ``heights_file``: a CSV
        with a column ``h`` of measured summit heights [m]); ``tangential``
        "elastic-slip" (default) or "mindlin" with ``microslip_elements``
        (default 32): Cattaneo–Mindlin sub-elements, :ref:`guide-pol-ind-microslip`.

    Examples
    --------
    >>> import numpy as np, polind
    >>> from polind.models.pol_ind import default_table
    >>> model = polind.model_from_dict({"model": default_table()})
    >>> t = np.linspace(0.0, 1.0, 2001)
    >>> res = polind.simulate(model, t, v=np.full_like(t, 0.01))
    >>> round(float(res.force[-1]), 9)       # mu_k N on the Stribeck curve at v = 10 vs
    10.0
    """

    type = "pol-ind"
    title = "Pol-Ind"
    form = "GMS elements derived from asperity mechanics"
    purpose = ("friction from surface roughness and materials: parameters a tribologist can "
               "measure")
    guide = "guide-pol-ind"
    #: When to use it (the guide's 'Which one to use').
    advice = ('GMS elements derived from the asperity mechanics of a rough surface: the element '
              'stiffnesses and capacities follow from a summit-height distribution (or a '
              'measured height map), summit radius and the elastic constants of the two bodies, '
              'and change with the normal load.  Its parameters are the ones a tribologist '
              'measures.')
    has_elements = True
    has_contact = True
    takes_normal_load = True
    phenomena = frozenset({"presliding_memory", "frictional_lag", "non_drifting"})
    fit_defaults = ("static_coefficient", "kinetic_coefficient", "stribeck_velocity",
                    "attraction", "surface.height_std")
    state_keys = ("element_force", "slip_direction", "element_height", "element_count",
                  "table_load")
    parameters = (
        Param("normal_load", unit="N",
          description=("Normal load :math:`N` pressing the surfaces together; a "
                       "``normal_load`` signal replaces it sample by sample."), symbol="N"),
        Param("static_coefficient",
          description=(r"Static friction coefficient :math:`\mu_s`: break-away at "
                       r":math:`\mu_s N`."), symbol=r"\mu_s"),
        Param("kinetic_coefficient",
          description=(r"Kinetic friction coefficient :math:`\mu_k`: sliding at :math:`\mu_k "
                       r"N` well above :math:`v_s`."), symbol=r"\mu_k"),
        Param("stribeck_velocity", unit="m/s",
          description=("Stribeck velocity :math:`v_s`: the speed over which the force falls "
                       "from the static to the kinetic level."), symbol="v_s"),
        Param("stribeck_exponent", default=2.0,
          description=r"Stribeck exponent :math:`\delta` of the curve's shape.", symbol=r"\delta"),
        Param("stribeck_shape", kind="str", default="exponential",
              choices=("exponential", "rational"),
          description=('Shape of the Stribeck curve: ``"exponential"`` '
                       ':math:`e^{-|v/v_s|^\\delta}` or ``"rational"`` :math:`1/(1 + '
                       '|v/v_s|^\\delta)` (:ref:`guide-stribeck-curve`).')),
        Param("attraction", unit="N/s",
          description=("Attraction parameter :math:`C`: how fast a slipping element's force "
                       "approaches its share of the Stribeck curve."), symbol="C"),
        VISCOUS,
        SURFACE_TABLE,
        MATERIALS_TABLE,
        DISCRETISATION_TABLE,
    )

    @classmethod
    def _check(cls, params):
        from polind.contact.elements import MAX_ELEMENTS
        from polind.contact.microslip import microslip_of

        surface = params["surface"]
        discretisation = params["discretisation"]
        mapped = surface.get("topography") is not None
        if "summation" not in discretisation:
            discretisation["summation"] = "direct" if mapped else "statistical"
        if mapped:
            for key in MAPPED_SURFACE_KEYS:
                if key in surface:
                    raise InputError(f"The 'surface.{key}' parameter of pol-ind is not used with a "
                                     f"'surface.topography': the height map gives every summit's "
                                     f"height and radius. Remove it.")
            if discretisation["summation"] != "direct":
                raise InputError("The 'surface.topography' of pol-ind sums over the measured "
                                 "summits: it needs summation = \"direct\". Got \"statistical\" "
                                 "instead; remove 'discretisation.summation' or use "
                                 "statistical_equivalent() for the statistical model.")
            if discretisation.get("heights_file"):
                raise InputError("A pol-ind model takes its summits from a 'surface.topography' "
                                 "or a 'discretisation.heights_file', not both. Remove one.")
        if "ball_radius" in surface and "nominal_area" in surface:
            raise InputError("A pol-ind surface takes its nominal area from 'surface.nominal_area' "
                             "or 'surface.ball_radius' (the Hertz contact of the ball), not both. "
                             "Remove one.")
        if not mapped:
            for key in MAP_KEYS:
                if key in surface:
                    raise InputError(f"The 'surface.{key}' parameter of pol-ind only goes with a "
                                     f"'surface.topography' (a height map). Remove it or add "
                                     f"the map.")
            if "asperity_radius" not in surface:
                raise InputError("Missing key 'surface.asperity_radius' for a pol-ind model "
                                 "(needed without a 'surface.topography').")
        materials = params["materials"]
        if materials.get("hardness") is not None and materials.get("yield_strength") is not None:
            raise InputError("The 'materials.hardness' and 'materials.yield_strength' of pol-ind are "
                             "two ways of giving one number (H = 2.8 Y): give one of them. Got both.")
        microslip_of(discretisation)
        if surface.get("bulk_compliance") is not None and "ball_radius" not in surface:
            raise InputError("The 'surface.bulk_compliance' parameter of pol-ind is the compliance "
                             "of a ball's Hertz contact: it needs a 'surface.ball_radius'. Got "
                             f"{surface['bulk_compliance']!r} on a flat; remove it (a flat's "
                             "bulk is a [model.compliance] of its own).")
        count = discretisation["elements"]
        if not 1 <= count <= MAX_ELEMENTS:
            raise InputError(f"The 'discretisation.elements' parameter of pol-ind must be in the "
                             f"range [1, {MAX_ELEMENTS}]. Got {count} instead.")
        if mapped:                  # the map replaced the sampled keys (refused above)
            return
        heights_file = discretisation.get("heights_file")
        if heights_file and discretisation["summation"] != "direct":
            raise InputError("The 'discretisation.heights_file' parameter of pol-ind needs "
                             "summation = \"direct\". Got \"statistical\" instead.")
        ball = "ball_radius" in surface
        for key in SAMPLED_SURFACE_KEYS + ("ball_radius",):
            if heights_file and key in surface:
                raise InputError(f"The 'surface.{key}' parameter of pol-ind is not used with "
                                 f"a 'discretisation.heights_file': the file gives the "
                                 f"summits themselves. Remove it.")
            if key == "ball_radius" or (key == "nominal_area" and ball):
                continue
            if not heights_file and key not in surface:
                raise InputError(f"Missing key 'surface.{key}' for a pol-ind model (needed "
                                 f"without a 'discretisation.heights_file').")

    # --- contact mechanics (computed on first use, then cached) -----------------------

    @functools.cached_property
    def _contacts(self):
        return {}

    def contact(self, normal_load=None):
        """The contact at a normal load [N] (default: the model's): surface, separation, table.

        Built on first use and kept (the model is immutable), one per load.
        """
        from polind.contact import build_contact

        load = self._params["normal_load"] if normal_load is None else float(normal_load)
        if load not in self._contacts:
            if len(self._contacts) >= 8:
                self._contacts.pop(next(iter(self._contacts)))
            loaded = {**self._params, "normal_load": load}
            # With a ball radius the nominal area (so the surface) depends on the load.
            surface = surface_of(loaded if self._params["surface"].get("ball_radius")
                                 else self._params)
            contact = build_contact(loaded, surface=surface)
            table = contact.elements
            for name, values in (("stiffness", table.stiffness), ("weight", table.weight)):
                if not np.all(np.isfinite(values)):
                    raise InputError(f"The pol-ind parameters give non-finite element {name}s at "
                                     f"{load!r} N (a value too large for double precision, such "
                                     f"as static_coefficient = "
                                     f"{self._params['static_coefficient']!r}?); expected "
                                     f"parameters of a physical size.")
            self._contacts[load] = contact
            message = contact.validity_warning()
            if message is not None:
                warnings.warn(message, ValidityWarning, stacklevel=2)
        return self._contacts[load]

    @property
    def plastic(self) -> bool:
        """Whether the model runs the elastic-plastic step (:ref:`guide-pol-ind-plasticity`).

        A hardness (or yield strength) is given and an asperity can pass yield
        on the surface; a hardness so large that none can (``H -> inf``) gives
        exactly the Hertzian model, which runs the Hertzian step.
        """
        return surface_of(self._params).yields

    def element_table(self, normal_load=None):
        """The modified Maxwell-slip element table at a normal load (:ref:`guide-pol-ind-elements`)."""
        return self.contact(normal_load).elements

    def statistical_equivalent(self) -> "PolInd":
        """The same model on the Greenwood–Williamson surface of its height map.

        For a model with a ``surface.topography``: a statistical-summation
        Pol-Ind model whose surface has the map's summit density ``eta``,
        radius ``1 / mean(kappa)`` and summit-height standard deviation, over
        the same nominal area; every other key is the same.  Comparing the
        two shows what the measured distribution of heights and radii does
        that the Gaussian, one-radius idealisation does not.

        Raises
        ------
        polind.InputError
            If the model has no ``surface.topography``.
        """
        if self._params["surface"].get("topography") is None:
            raise InputError("statistical_equivalent() needs a pol-ind model with a "
                             "'surface.topography' (a measured height map). Got none.")
        gw = dict(surface_of(self._params).greenwood_williamson)
        params = self.params
        ball_radius = params["surface"].get("ball_radius")
        if ball_radius is not None:        # the same ball: the area follows the load
            gw.pop("nominal_area")
            gw["ball_radius"] = ball_radius
        params["surface"] = gw
        discretisation = params["discretisation"]
        discretisation["summation"] = "statistical"
        discretisation.pop("heights_file", None)
        return type(self)(**params)

    def gms_parameters(self, normal_load=None) -> dict:
        """The GMS parameters (:ref:`guide-gms`) this model is at a constant normal load.

        ``stiffness`` and ``weight`` (arrays) of the element table at the load,
        ``coulomb_force = mu_k N``, ``static_force = mu_s N``, and the model's
        own Stribeck velocity, exponent, shape, attraction and viscous term
        (:ref:`guide-pol-ind-law`).
        """
        p = self._params
        load = p["normal_load"] if normal_load is None else float(normal_load)
        table = self.element_table(load)
        return {"stiffness": table.stiffness, "weight": table.weight,
                "attraction": p["attraction"],
                "coulomb_force": p["kinetic_coefficient"] * load,
                "static_force": p["static_coefficient"] * load,
                "stribeck_velocity": p["stribeck_velocity"],
                "stribeck_exponent": p["stribeck_exponent"],
                "stribeck_shape": p["stribeck_shape"],
                "viscous_coefficient": p["viscous_coefficient"]}

    @classmethod
    def example_parameters(cls, elements=None):
        """The default Pol-Ind parameter set: a steel pair under 100 N (:ref:`formats-model-files`).

        mu_s = 0.15, mu_k = 0.10, vs = 1 mm/s, delta = 2, C = 1e4 N/s, sigma2 = 0;
        eta = 1e10 /m^2, A0 = 1e-4 m^2, R = 50 um, sigma_a = 0.5 um; E = 210 GPa and
        nu = 0.3 for both bodies, no hardness (Hertzian asperities: peak asperity
        pressure 9.25 GPa, under the 10 GPa at which a Hertzian contact warns,
        :ref:`guide-pol-ind-validity`); 64 statistical elements (or ``elements``).
        """
        return {
            "normal_load": 100.0,
            "static_coefficient": 0.15,
            "kinetic_coefficient": 0.10,
            "stribeck_velocity": 1e-3,
            "stribeck_exponent": 2.0,
            "attraction": 1e4,
            "viscous_coefficient": 0.0,
            "surface": {"asperity_density": 1e10, "nominal_area": 1e-4,
                        "asperity_radius": 50e-6, "height_std": 0.5e-6},
            "materials": {"youngs_modulus": [210e9, 210e9], "poisson_ratio": [0.3, 0.3]},
            "discretisation": {"summation": "statistical",
                               "elements": 64 if elements is None else int(elements),
                               "seed": 0},
        }

    def equivalent_gms(self, normal_load=None) -> "GMS":
        """The GMS model this model is at a constant normal load [N] (:ref:`guide-pol-ind-law`):
        its element table and levels (:meth:`gms_parameters`)."""
        equivalent = self.gms_parameters(normal_load)
        equivalent["stiffness"] = [float(k) for k in equivalent["stiffness"]]
        equivalent["weight"] = [float(a) for a in equivalent["weight"]]
        return GMS(**equivalent)

    def equivalent_maxwell_slip(self, normal_load=None) -> "MaxwellSlip":
        """The rate-independent limit (C -> inf, Fs = Fc) of the same contact: Maxwell-slip with
        the element stiffnesses ``k_j`` and break-away forces ``W_j = mu_s N alpha_j`` (summing
        to ``mu_s N``), no viscous term."""
        equivalent = self.gms_parameters(normal_load)
        static = equivalent["static_force"]
        return MaxwellSlip(stiffness=[float(k) for k in equivalent["stiffness"]],
                           breakaway_force=[static * float(a) for a in equivalent["weight"]])

    def phenomenological_gms(self, count=8, span=30.0) -> "GMS":
        """A GMS as an engineer would set it up without the asperity mechanics.

        ``count`` elements of equal weight whose slip distances are log-spaced over
        the model's presliding range (from ``1/span`` of its largest element slip
        distance to that distance, ``k_i = alpha_i Fs / D_i``), with this model's
        Stribeck curve, attraction and viscous term: the same levels with a
        different element set.
        """
        equivalent = self.gms_parameters()
        static = equivalent["static_force"]
        slips = [static * a / k for a, k in zip(equivalent["weight"], equivalent["stiffness"])
                 if k > 0.0]
        shortest = max(slips) / span
        ratio = (max(slips) / shortest) ** (1.0 / (count - 1))
        levels = {key: equivalent[key] for key in (
            "attraction", "coulomb_force", "static_force", "stribeck_velocity",
            "stribeck_exponent", "stribeck_shape", "viscous_coefficient")}
        return GMS(stiffness=[static / count / (shortest * ratio ** i) for i in range(count)],
                   weight=[1.0 / count] * count, **levels)

    def peers(self) -> dict:
        """LuGre with the parameters of 1995, a phenomenological GMS and the Maxwell-slip limit
        of this contact (:meth:`phenomenological_gms`, :meth:`equivalent_maxwell_slip`)."""
        from polind.models.lugre import LuGre

        return {
            "LuGre": (LuGre.example(), "The LuGre model (the user guide, 'LuGre') with the "
                      "parameters of Canudas de Wit et al. (1995)."),
            "GMS": (self.phenomenological_gms(),
                    "GMS (the user guide, 'Generalized Maxwell-slip (GMS)') with eight "
                    "equal-weight elements whose slip distances are log-spaced from 1/30 of "
                    "Pol-Ind's largest slip distance to it, and Pol-Ind's Stribeck curve and "
                    "attraction: the same levels with a phenomenological element set."),
            "Maxwell-slip": (self.equivalent_maxwell_slip(),
                             "Maxwell-slip (the user guide, 'Maxwell-slip') with Pol-Ind's "
                             "element stiffnesses and W_j = mu_s N alpha_j (summing to mu_s N): "
                             "the rate-independent limit of the same contact."),
        }

    # --- where a fit starts (polind.models.pol_ind_fit) -------------------------------

    def structured_starts(self, path, force, free):
        """The record's force level and presliding range on this model's own elements
        (:func:`polind.models.pol_ind_fit.structured_starts`)."""
        return pol_ind_fit.structured_starts(self, path, force, free)

    @classmethod
    def contains(cls):
        """Pol-Ind itself: its Maxwell-slip limit, ``mu_k = mu_s`` (the elements of its
        surface, which a Maxwell-slip model of free elements does not stand for)."""
        return cls

    def special_case(self, free, path):
        """The Maxwell-slip limit (:func:`polind.models.pol_ind_fit.special_case`)."""
        return pol_ind_fit.special_case(self, free, path)

    # --- the stepping contract --------------------------------------------------------

    def initial_variables(self, normal_load=None):
        build_load = self._params["normal_load"] if normal_load is None \
            else float(np.max(normal_load))
        table = self.element_table(build_load)
        n = table.stiffness.shape[0]
        return {"element_force": np.zeros(n), "slip_direction": np.zeros(n),
                "element_height": np.array(table.heights, dtype=np.float64),
                # Hertz weights n_j sqrt(R_j / R): the counts, unless summits have own radii.
                "element_count": np.array(table.contact_weights, dtype=np.float64),
                "table_load": np.array([build_load])}

    def check_state(self, state):
        if state.model_type != self.type:
            super().check_state(state)
        keys = ("element_force", "slip_direction", "element_height", "element_count",
                "table_load")
        for key in keys:
            if key not in state.variables:
                raise InputError(f"The state lacks its '{key}' entry for a pol-ind model.")
        n = state.variables["element_force"].shape[0]
        for key in keys[1:4]:
            if state.variables[key].shape[0] != n:
                raise InputError(f"The state's '{key}' has {state.variables[key].shape[0]} "
                                 f"entries; its 'element_force' has {n}.")
        table_load = state.variables["table_load"]
        if table_load.shape != (1,) or not (math.isfinite(table_load[0]) and table_load[0] > 0.0):
            raise InputError(f"The state's 'table_load' must be one positive finite load [N]. "
                             f"Got {table_load.tolist()} instead.")
        counts = state.variables["element_count"]
        if np.any(counts < 0.0):
            index = int(np.flatnonzero(counts < 0.0)[0])
            raise InputError(f"The state's 'element_count' must be non-negative. Got "
                             f"{float(counts[index])!r} at index {index} instead.")
        directions = state.variables["slip_direction"]
        if not np.all(np.isin(directions, (-1.0, 0.0, 1.0))):
            raise InputError("The state's 'slip_direction' entries must be -1, 0 or 1.")
        expected = self.element_table(float(table_load[0])).stiffness.shape[0]
        if n != expected:
            raise InputError(f"The state has {n} elements but this pol-ind model has {expected} "
                             f"(at the state's table load {float(table_load[0])!r} N): a state "
                             f"continues the model that produced it.")

    def step_functions(self):
        # Kernels load numba: imported on first use so `import polind` stays fast.
        from polind.kernels import pol_ind
        if self.plastic:
            # Elastic-plastic asperities: a path of their own (the Hertzian one stays as it is).
            from polind.kernels import pol_ind_plastic as plastic
            return StepFunctions(plastic.plastic_step, plastic.plastic_force,
                                 pol_ind.pol_ind_tangent, runners="pol_ind_plastic")
        return StepFunctions(pol_ind.pol_ind_step, pol_ind.pol_ind_force,
                             pol_ind.pol_ind_tangent, runners="pol_ind")

    def fixed_load_step_functions(self, state):
        """The step of a run that stays at the load its element table was built for.

        The GMS law of the table (:mod:`polind.kernels.pol_ind_fixed`),
        without the separation solver and the table's update at a new load, for
        the Hertzian and the elastic-plastic contact alike; None when the
        state's table was built at another load (the first step must bring it).
        """
        if float(state.variables["table_load"][0]) != float(self.constant_load):
            return None
        from polind.kernels import pol_ind, pol_ind_fixed
        return StepFunctions(pol_ind_fixed.fixed_load_step, pol_ind_fixed.fixed_load_force,
                             pol_ind.pol_ind_tangent, runners="pol_ind_fixed_load")

    def kernel_arrays(self, state):
        from polind.kernels import pol_ind as slots
        from polind.kernels.separation import DIRECT, STATISTICAL
        from polind.kernels.special import special_addresses

        table_load = float(state.variables["table_load"][0])
        contact = self.contact(table_load)
        surface = contact.surface
        gms_scalars, gms_table = gms_arrays(self.gms_parameters(table_load))
        scalars = np.zeros(slots.N_SCALARS)
        scalars[:gms_scalars.shape[0]] = gms_scalars
        p = self._params
        scalars[slots.KINETIC_COEFFICIENT] = p["kinetic_coefficient"]
        scalars[slots.STATIC_COEFFICIENT] = p["static_coefficient"]
        scalars[slots.RADIUS] = surface.asperity_radius
        scalars[slots.E_STAR] = surface.E_star
        scalars[slots.G_STAR] = surface.G_star
        scalars[slots.CURRENT_LOAD] = table_load
        scalars[slots.SEPARATION] = contact.separation
        # No warm-start information yet: the first solve starts at the table's d.
        scalars[slots.LOAD_VALUE] = 0.0
        scalars[slots.LOAD_SLOPE] = 0.0
        if surface.kind == "statistical":
            scalars[slots.SURFACE_KIND] = STATISTICAL
            scalars[slots.LOAD_SCALE] = surface._load_scale
            scalars[slots.HEIGHT_STD] = surface.height_std
            scalars[slots.LOWER], scalars[slots.UPPER] = surface.separation_range
        else:
            scalars[slots.SURFACE_KIND] = DIRECT
            scalars[slots.UPPER] = float(np.max(state.variables["element_height"]))
        scalars[slots.HERTZ] = (4.0 / 3.0) * surface.E_star * np.sqrt(surface.asperity_radius)
        scalars[slots.ADDRESSES:slots.ADDRESSES + 2] = special_addresses()
        if p["surface"].get("ball_radius"):
            # A ball's nominal area follows the load: the kernel scales this surface's.
            scalars[slots.BALL_LOAD] = table_load
        table = np.zeros((slots.N_ROWS, gms_table.shape[1]))
        table[:gms_table.shape[0]] = gms_table
        if surface.yields:
            return plastic_arrays(scalars, table, contact)
        return scalars, table

    def characteristic_scales(self):
        # At its constant load Pol-Ind is a GMS (the user guide, 'The rate-state law'):
        # its scales are that GMS's.
        return gms_scales(self.gms_parameters())

    def force_scale(self):
        p = self._params
        return max(p["kinetic_coefficient"], p["static_coefficient"]) * p["normal_load"]

    @property
    def constant_load(self):
        return self._params["normal_load"]

    def load_bounds(self, state):
        table_load = float(state.variables["table_load"][0])
        if self.microslip_elements is not None:
            return table_load, table_load
        return self._smallest_load(table_load), table_load

    @property
    def microslip_elements(self) -> int | None:
        """Sub-elements per element with ``tangential = "mindlin"``, else ``None``
        (:ref:`guide-pol-ind-microslip`)."""
        from polind.contact.microslip import microslip_of
        return microslip_of(self._params["discretisation"])

    @property
    def bulk_stiffness(self) -> float:
        """``8 G* a`` [N/m] of a ball's bulk (:ref:`guide-pol-ind-bulk`), ``inf`` without one.

        A ``surface.ball_radius`` contact carries the smooth ball's Mindlin
        compliance ``1 / (8 G* a)``, ``a = (3 N R_b / (4 E*))^(1/3)`` its Hertz
        contact radius at the model's ``normal_load``, in series with the
        asperities unless ``surface.bulk_compliance = false``.
        """
        from polind.contact.ball import bulk_stiffness
        return bulk_stiffness(self._params)

    @property
    def series_stiffness(self) -> float:
        """k_s [N/m]: ``[model.compliance]`` in series with a ball's bulk (:attr:`bulk_stiffness`).

        ``1 / (1 / k_compliance + 1 / (8 G* a))``; either alone where the other
        is absent, ``inf`` with neither (:ref:`guide-pol-ind-bulk`).
        """
        given = super().series_stiffness
        bulk = self.bulk_stiffness
        if bulk == math.inf:
            return given
        if given == math.inf:
            return bulk
        return 1.0 / (1.0 / given + 1.0 / bulk)

    def _smallest_load(self, table_load):
        """The smallest load [N] a run on the table built at ``table_load`` [N] may use.

        The surface's own smallest load (a statistical surface's separation
        range), or 0.  With a ball the surface of a load ``N`` is the table
        load's with its area times ``r = (N / N_t)^(2/3)``, solved at
        ``N / r = N^(1/3) N_t^(2/3)``: that must reach the smallest load
        ``L`` of the table load's surface, so ``N >= L^3 / N_t^2``.
        """
        smallest = max(self.contact(table_load).surface.load_range[0], 0.0)
        if self._params["surface"].get("ball_radius"):
            smallest = smallest ** 3 / table_load ** 2
        return smallest

    def check_loads(self, loads, state):
        """Loads the run may use: at most the state's table load, within the surface's range.

        With a ball the nominal area follows each load
        (:ref:`guide-measured-surfaces-ball`): the smallest load is then
        ``L^3 / N_t^2``, ``L`` the smallest of the table load ``N_t``'s surface.
        """
        table_load = float(state.variables["table_load"][0])
        peak = float(np.max(loads))
        if self.microslip_elements is not None:
            from polind.contact.microslip import check_constant_load
            check_constant_load(loads, table_load)
        if peak > table_load * (1.0 + 1e-12):
            raise InputError(f"The 'normal_load' reaches {peak!r} N but the state's element "
                             f"table was built for at most {table_load!r} N; start the first "
                             f"chunk with the largest load or simulate the record at once.")
        smallest = self._smallest_load(table_load)
        low = float(np.min(loads))
        if low < smallest:
            index = int(np.argmin(loads))
            raise InputError(f"The 'normal_load' of pol-ind is too small for its surface: "
                             f"no asperity would be in contact. Got {low!r} N at index {index}; "
                             f"expected at least {smallest:.6g} N.")

