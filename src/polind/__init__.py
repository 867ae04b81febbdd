"""polind: dynamic friction modelling, the Pol-Ind model and its classical peers.

The public API (INTERFACE.md)::

    import polind
    model = polind.load_model("model.toml")      # or polind.model_from_dict({...})
    res = polind.simulate(model, t, x=x)         # or v=v
    res.t, res.x, res.v, res.force

A model as a discrete-time python-control system (optional extra
``polind[control]``; not imported by ``import polind``)::

    from polind.control import friction_system, initial_state
    sys = friction_system(model, dt=1e-3)        # input "x" (or "v"), output "F"
"""

from polind.errors import InputError
from polind.models import (MODEL_TYPES, FrictionModel, State, StepFunctions, StepKernel,
                           load_model, model_from_dict, register_model)
from polind.models.params import Param, Table
from polind.simulate import SimulationResult, simulate

__all__ = ["InputError", "MODEL_TYPES", "FrictionModel", "State", "SimulationResult",
           "StepFunctions", "StepKernel", "register_model", "Param", "Table", "Stepper", "Body",
           "load_model", "model_from_dict", "simulate", "System", "SystemResult",
           "load_system", "simulate_system", "identify", "FitResult",
           "identify_maxwell_slip", "identify_gms", "identify_stribeck", "compare", "sweep"]
__version__ = "0.1.0"

# The one-degree-of-freedom and identification APIs load numba kernels and
# SciPy: import them on first use
# (PEP 562) so `import polind` stays fast.
_LAZY = {"identify": "polind.identification", "FitResult": "polind.identification",
         "identify_maxwell_slip": "polind.identification",
         "identify_gms": "polind.identification",
         "identify_stribeck": "polind.identification",
         "compare": "polind.comparison",
         "Stepper": "polind.stepper", "Body": "polind.stepper",
         "System": "polind.dynamics", "SystemResult": "polind.dynamics",
         "load_system": "polind.dynamics", "simulate_system": "polind.dynamics",
         "sweep": "polind.sweep"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        module = importlib.import_module(_LAZY[name])
        # polind.sweep is its module, made callable (polind.sweep(...) runs a sweep), so that
        # it is the same object whether `import polind.sweep` or this came first.
        value = module if module.__name__ == f"{__name__}.{name}" else getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'polind' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))
