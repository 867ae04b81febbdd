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

import sys
import types

from polind.errors import InputError

__all__ = ["InputError", "MODEL_TYPES", "FrictionModel", "State", "SimulationResult",
           "StepFunctions", "StepKernel", "register_model", "Param", "Table", "Stepper", "Body",
           "load_model", "model_from_dict", "save_model", "simulate", "System", "SystemResult",
           "load_system", "simulate_system", "identify", "FitResult",
           "identify_maxwell_slip", "identify_gms", "identify_stribeck", "compare", "Comparison",
           "sweep"]
__version__ = "0.1.0"

# Every export but InputError is imported on first use (PEP 562), so that
# `import polind` (and with it `polind --help`) imports neither NumPy nor the
# numba kernels, SciPy or matplotlib.
_LAZY = {"MODEL_TYPES": "polind.models", "FrictionModel": "polind.models",
         "State": "polind.models", "StepFunctions": "polind.models",
         "StepKernel": "polind.models", "load_model": "polind.models",
         "model_from_dict": "polind.models", "register_model": "polind.models",
         "save_model": "polind.io",
         "Param": "polind.models.params", "Table": "polind.models.params",
         "SimulationResult": "polind.simulate", "simulate": "polind.simulate",
         "identify": "polind.identification", "FitResult": "polind.identification",
         "identify_maxwell_slip": "polind.identification",
         "identify_gms": "polind.identification",
         "identify_stribeck": "polind.identification",
         "compare": "polind.identification", "Comparison": "polind.identification",
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
        value = module if module.__name__ == f"{__name__}.{name}" and callable(module) \
            else getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'polind' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))


class _Package(types.ModuleType):
    """``polind``, whose ``simulate`` stays the function when the module ``polind.simulate``
    is imported: the import system binds a submodule on its package, which would
    otherwise replace the function ``polind.simulate`` by the module of that name."""

    def __setattr__(self, name, value):
        if name == "simulate" and isinstance(value, types.ModuleType) \
                and value.__name__ == f"{__name__}.simulate":
            value = value.simulate
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
