"""polind: dynamic friction modelling, the Pol-Ind model and its classical peers.

The public API (INTERFACE.md)::

    import polind
    model = polind.load_model("model.toml")      # or polind.model_from_dict({...})
    res = polind.simulate(model, t, x=x)         # or v=v
    res.t, res.x, res.v, res.force
"""

from polind.errors import InputError
from polind.models import MODEL_TYPES, FrictionModel, State, load_model, model_from_dict
from polind.simulate import SimulationResult, simulate
from polind.dynamics import System, SystemResult, load_system, simulate_system

__all__ = ["InputError", "MODEL_TYPES", "FrictionModel", "State", "SimulationResult",
           "load_model", "model_from_dict", "simulate", "System", "SystemResult",
           "load_system", "simulate_system"]
__version__ = "0.1.0"
