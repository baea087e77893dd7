"""Simulation: ``CompiledModel`` -> ``SimulationResult`` (solvers, auto's race, output).

The package is ``simulation``, not ``simulate``: ``springc.simulate`` is the API function.
"""

from .results import (
    PLOT_FORMATS,
    RESULT_FORMATS,
    SimulationResult,
    file_format,
    save_outputs,
    write_csv,
)
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

__all__ = ["DEFAULT_SOLVER", "FIXED_STEP", "LSODA_LIMIT", "PLOT_FORMATS", "RESULT_FORMATS",
           "SOLVERS", "SimulationOptions", "SimulationResult", "file_format", "initial_state",
           "output_grid", "resolve", "save_outputs", "simulate_model", "write_csv"]
