"""polind: dynamic friction modelling, the Pol-Ind model and its classical peers.

The public API (the user guide, :ref:`guide-simulate`)::

    import polind
    model = polind.load_model("model.toml")      # or polind.model_from_dict({...})
    res = polind.simulate(model, t, x=x)         # or v=v
    res.t, res.x, res.v, res.force

A model as a discrete-time python-control system (optional extra
``polind[control]``; not imported by ``import polind``)::

    from polind.control import friction_system, initial_state
    sys = friction_system(model, dt=1e-3)        # input "x" (or "v"), output "F"
"""

from polind.errors import InputError, ValidityWarning

__all__ = ["InputError", "ValidityWarning", "MODEL_TYPES", "FrictionModel", "State", "SimulationResult",
           "StepFunctions", "StepKernel", "register_model", "unregister_model", "Param", "Table", "Stepper", "Body",
           "BodyBatch", "load_model", "model_from_dict", "save_model", "simulate", "System", "SystemResult",
           "load_system", "simulate_system", "identify", "FitResult",
           "identify_maxwell_slip", "identify_gms", "identify_stribeck", "compare", "Comparison",
           "sweep", "SweepSummary", "Structure", "StructureResult", "simulate_structure", "load_structure",
           "hysteresis_loop", "HysteresisLoop", "harmonic_balance", "HarmonicBalanceResult",
           "frequency_response", "FrequencyResponse", "ContinuationError", "backbone", "Backbone"]
__version__ = "0.1.0"

# Every export but InputError is imported on first use (PEP 562), so that
# `import polind` (and with it `polind --help`) imports neither NumPy nor the
# numba kernels, SciPy or matplotlib.
_LAZY = {"MODEL_TYPES": "polind.models", "FrictionModel": "polind.models",
         "State": "polind.models", "StepFunctions": "polind.models",
         "StepKernel": "polind.models", "load_model": "polind.models",
         "model_from_dict": "polind.models", "register_model": "polind.models",
         "unregister_model": "polind.models",
         "save_model": "polind.io",
         "Param": "polind.models.params", "Table": "polind.models.params",
         "SimulationResult": "polind.simulation", "simulate": "polind.simulation",
         "identify": "polind.identification", "FitResult": "polind.identification",
         "identify_maxwell_slip": "polind.identification",
         "identify_gms": "polind.identification",
         "identify_stribeck": "polind.identification",
         "compare": "polind.identification", "Comparison": "polind.identification",
         "Stepper": "polind.stepper", "Body": "polind.stepper", "BodyBatch": "polind.batch",
         "System": "polind.dynamics", "SystemResult": "polind.dynamics",
         "load_system": "polind.dynamics", "simulate_system": "polind.dynamics",
         "sweep": "polind.sweeps", "SweepSummary": "polind.sweeps",
         "Structure": "polind.structures", "StructureResult": "polind.structures",
         "simulate_structure": "polind.structures", "load_structure": "polind.structures",
         "hysteresis_loop": "polind.structures", "HysteresisLoop": "polind.structures",
         "harmonic_balance": "polind.structures", "HarmonicBalanceResult": "polind.structures",
         "frequency_response": "polind.structures", "FrequencyResponse": "polind.structures",
         "ContinuationError": "polind.structures", "backbone": "polind.structures",
         "Backbone": "polind.structures"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    if name in ("sweeps", "datasets"):
        # The package of polind.sweep (polind.sweeps.Sweep, ...) and the shipped data
        # (polind.datasets.tribometer(), ...), imported on first use too.
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'polind' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
