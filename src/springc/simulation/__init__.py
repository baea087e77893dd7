"""Simulation: ``CompiledModel`` -> ``SimulationResult`` (solvers, auto's race, output).

The package is ``simulation``, not ``simulate``: ``springc.simulate`` is the API function.
"""

from .results import SimulationResult, atomic_write, write_csv
from .runner import (
    DEFAULT_SOLVER,
    SimulationOptions,
    initial_state,
    output_grid,
    resolve,
    simulate_model,
)

__all__ = ["DEFAULT_SOLVER", "SimulationOptions", "SimulationResult", "atomic_write",
           "initial_state", "output_grid", "resolve", "simulate_model", "write_csv"]
