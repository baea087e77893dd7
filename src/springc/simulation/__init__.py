"""Simulation: ``CompiledModel`` -> ``SimulationResult`` (solvers, auto's race, output).

The package is ``simulation``, not ``simulate``: ``springc.simulate`` is the API function.

The solver names (:mod:`.solver_names`) and the standard-library pieces of the
command line's warm path (:mod:`.csv_rows`, :mod:`.error_rules`, :mod:`.summary`) load
with the package; everything else loads
on first use (PEP 562), so that the CLI can offer the solver names without importing
numpy and scipy (a third of a second on every ``springc check``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .csv_rows import write_rows  # light: the stdlib pieces of the warm path
from .error_rules import allowed_errors, companion_tolerances, largest_differences, worst_column
from .settings import (  # light: the run options, no numpy
    DEFAULT_MAX_STEPS,
    DEFAULT_TIME_LIMIT,
    OPTION_NAMES,
    RunSettings,
    SimulationOptions,
    error_control_mode,
    estimate_deprecation,
    run_settings,
)
from .solver_names import (
    ALL_SOLVERS,
    AUTO,
    COMPILED_SOLVERS,
    DEFAULT_ENGINE,
    DEFAULT_ERROR_CONTROL,
    DEFAULT_SOLVER,
    ENGINES,
    ERROR_CONTROLS,
    EXPLICIT,
    FIXED_STEP,
    IMPLICIT_SOLVERS,
    ORDERS,
    RACE_IMPLICIT,
    REGISTRY,
    SOLVERS,
    Solver,
    companion_solver,
    registered,
)
from .summary import brief_line
from .values import check_run_values  # light: only math and errors

if TYPE_CHECKING:
    from .compiled import (
        c_loop_available,
        c_loop_runs,
        choose_engine,
        default_backend,
        numba_available,
        observed_on_grid,
    )
    from .limits import OverBudget
    from .output_size import LARGE_TRAJECTORY, check_trajectory_size
    from .results import (
        PLOT_FORMATS,
        RESULT_FORMATS,
        SimulationResult,
        file_format,
        save_outputs,
        write_csv,
    )
    from .runner import (
        LSODA_LIMIT,
        RunPlan,
        initial_state,
        output_grid,
        plan,
        resolve,
        run_plan,
        simulate_model,
    )

__all__ = [
    "ALL_SOLVERS",
    "AUTO",
    "COMPILED_SOLVERS",
    "DEFAULT_ENGINE",
    "DEFAULT_ERROR_CONTROL",
    "DEFAULT_MAX_STEPS",
    "DEFAULT_SOLVER",
    "DEFAULT_TIME_LIMIT",
    "ENGINES",
    "ERROR_CONTROLS",
    "EXPLICIT",
    "FIXED_STEP",
    "IMPLICIT_SOLVERS",
    "LARGE_TRAJECTORY",
    "LSODA_LIMIT",
    "OPTION_NAMES",
    "ORDERS",
    "PLOT_FORMATS",
    "RACE_IMPLICIT",
    "REGISTRY",
    "RESULT_FORMATS",
    "SOLVERS",
    "OverBudget",
    "RunPlan",
    "RunSettings",
    "SimulationOptions",
    "SimulationResult",
    "Solver",
    "allowed_errors",
    "brief_line",
    "c_loop_available",
    "c_loop_runs",
    "check_run_values",
    "check_trajectory_size",
    "choose_engine",
    "companion_solver",
    "companion_tolerances",
    "default_backend",
    "error_control_mode",
    "estimate_deprecation",
    "file_format",
    "initial_state",
    "largest_differences",
    "numba_available",
    "observed_on_grid",
    "output_grid",
    "plan",
    "registered",
    "resolve",
    "run_plan",
    "run_settings",
    "save_outputs",
    "simulate_model",
    "worst_column",
    "write_csv",
    "write_rows",
]

_LIMITS = frozenset({"OverBudget"})
_RESULTS = frozenset({"PLOT_FORMATS", "RESULT_FORMATS", "SimulationResult", "file_format",
                      "save_outputs", "write_csv"})
_RUNNER = frozenset({"LSODA_LIMIT", "RunPlan", "initial_state", "output_grid", "plan",
                     "resolve", "run_plan", "simulate_model"})


def __getattr__(name: str) -> Any:
    # Lazy (see the docstring): numpy and scipy load with the first simulation name.
    if name in ("c_loop_available", "c_loop_runs", "choose_engine", "default_backend",
                "numba_available", "observed_on_grid"):
        from . import compiled

        return getattr(compiled, name)
    if name in ("LARGE_TRAJECTORY", "check_trajectory_size"):
        from . import output_size

        return getattr(output_size, name)
    if name in _LIMITS:
        from . import limits

        return getattr(limits, name)
    if name in _RESULTS:
        from . import results

        return getattr(results, name)
    if name in _RUNNER:
        from . import runner

        return getattr(runner, name)
    raise AttributeError(f"module 'springc.simulation' has no attribute {name!r}")
