"""Simulate a model whose states must change during the run: CompiledModel -> result.

Index reduction may leave a choice of states that becomes singular somewhere (a rod
passing vertical, see :mod:`springc.switching`). Such models are marked
``SWITCHABLE`` when generated; :func:`simulate_switching_model` runs them through the
dynamic-state-selection driver of :mod:`springc.switching`, which evaluates the
simplified system with the reference evaluator (slower than generated code, but
these index-3 scenes are small) and reports each switch in the summary.
"""

from __future__ import annotations

import time

import numpy as np

from ..pipeline import CompiledModel, derive_system
from ..simplify import simulate_switching
from .results import SimulationResult, SimulationStats

EXPLICIT_DEFAULT = "dop853"
SCIPY_NAMES = {"rk45": "RK45", "dop853": "DOP853", "radau": "Radau", "bdf": "BDF",
               "lsoda": "LSODA"}


def simulate_switching_model(model: CompiledModel, solver: str, grid: np.ndarray,
                             rtol: float, atol: float, parameters: dict[str, float]
                             ) -> SimulationResult:
    """Run ``model`` on ``grid`` with dynamic state selection (adaptive solvers only)."""
    began = time.perf_counter()
    method = solver if solver in SCIPY_NAMES else EXPLICIT_DEFAULT
    flat_model = derive_system(model.options).flat_model
    run = simulate_switching(flat_model, (float(grid[0]), float(grid[-1])), t_eval=grid,
                             rtol=rtol, atol=atol, method=SCIPY_NAMES[method],
                             parameters=parameters)
    values = np.column_stack([run.values[name] for name in model.outputs])
    units = tuple(str(u) for u in getattr(model.module, "OBSERVED_UNITS", ()))
    unit_of = dict(zip(model.states, getattr(model.module, "STATE_UNITS", ())))
    unit_of.update(zip(model.observed, units))
    switches = ", ".join(f"t = {s.time:.6g}" for s in run.switches) or "none"
    reason = (f"dynamic state selection, {len(run.switches)} switch"
              f"{'es' if len(run.switches) != 1 else ''} ({switches})")
    stats = SimulationStats(method, len(run.t), 0, 0, time.perf_counter() - began, 0.0,
                            model.compile_time, model.cached, reason)
    return SimulationResult(model.name, np.asarray(grid, dtype=float), model.outputs,
                            values, tuple(unit_of.get(n, "") for n in model.outputs),
                            stats, dict(parameters))
