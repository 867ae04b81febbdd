"""Structures: many coordinates, friction contacts between them (:ref:`guide-structures`).

:class:`Structure` holds the mass, damping and stiffness matrices and the
contacts; :func:`simulate_structure` integrates it in time with the
structure driver of :mod:`polind.kernels.structure`.
"""

from polind.structures.core import Structure, StructureResult, simulate_structure

__all__ = ["Structure", "StructureResult", "simulate_structure"]
