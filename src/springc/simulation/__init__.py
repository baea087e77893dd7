"""Simulation: ``CompiledModel`` -> ``SimulationResult`` (solvers, auto's race, output).

The package is ``simulation``, not ``simulate``: ``springc.simulate`` is the API function.
"""

from .results import SimulationResult, write_csv
from .runner import (
    DEFAULT_SOLVER,
    FIXED_STEP,
    LSODA_LIMIT,
    SOLVERS,
    SimulationOptions,
    initial_state,
    output_grid,
    resolve,
    simulate_model,
)

__all__ = ["DEFAULT_SOLVER", "FIXED_STEP", "LSODA_LIMIT", "SOLVERS", "SimulationOptions",
           "SimulationResult", "initial_state", "output_grid", "resolve", "simulate_model",
           "write_csv"]
