"""Structures: many coordinates, friction contacts between them (:ref:`guide-structures`).

:class:`polind.Structure` holds the mass, damping and stiffness matrices and
the contacts; :func:`polind.simulate_structure` integrates it in time with the
structure driver of :mod:`polind.kernels.structure`; :func:`polind.load_structure`
reads a structure file (:ref:`formats-structure`) into a structure and its
run (:class:`polind.structures.StructureRun` in time,
:class:`polind.structures.FrequencyResponseRun` or :class:`polind.structures.BackboneRun`
by harmonic balance); :func:`polind.structures.plot_structure`,
:func:`polind.structures.plot_frequency_response` and
:func:`polind.structures.plot_backbone` draw their results; :func:`polind.structures.contact_period` is a contact's periodic
steady state along one period of a motion (the periodic evaluation harmonic
balance builds on, :mod:`polind.kernels.periodic`); :func:`polind.hysteresis_loop`
gives the energy per cycle, secant stiffness and damping ratio of a record's last
closed loop.  In the frequency domain (:ref:`guide-frequency-domain`):
:func:`polind.harmonic_balance` finds one periodic steady state,
:func:`polind.frequency_response` follows it over a frequency range by continuation
(through turning points), and :func:`polind.backbone` gives a mode's frequency and
damping ratio against its amplitude (the extended periodic motion concept).
"""

from polind.structures.core import Structure, StructureResult, simulate_structure
from polind.structures.harmonic import HarmonicBalanceResult, harmonic_balance
from polind.structures.continuation import ContinuationError, FrequencyResponse, frequency_response
from polind.structures.modes import Backbone, backbone
from polind.structures.periodic import ContactPeriod, contact_period
from polind.structures.files import StructureRun, load_structure, structure_from_dict
from polind.structures.frequency_files import BackboneRun, FrequencyResponseRun
from polind.structures.loops import HysteresisLoop, hysteresis_loop
from polind.structures.plot import plot_backbone, plot_frequency_response, plot_structure

__all__ = ["Backbone", "backbone", "ContinuationError", "FrequencyResponse", "frequency_response",
           "HarmonicBalanceResult", "harmonic_balance", "ContactPeriod", "contact_period", "HysteresisLoop", "hysteresis_loop", "Structure", "StructureResult", "StructureRun", "load_structure", "plot_structure",
           "simulate_structure", "structure_from_dict", "FrequencyResponseRun", "BackboneRun",
           "plot_frequency_response", "plot_backbone"]
