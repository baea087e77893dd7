"""Energy drift of the tradeoff runs: an energy variable on the output grid -> its drift.

springc cannot know a scene's energy in general, so the study follows a variable of
the model: the one named by ``--energy NAME``, or else the only variable whose unit
is ``J`` (``Real E(unit = "J") = 0.5*m*v^2 + 0.5*k*x^2``). Its drift in a run is
``max_t |E(t) - E(t0)| / max_t |E_ref(t)|``: what the fixed-step scene integrators
keep bounded and adaptive solvers let grow over long runs.
"""

from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel
from ..simulation import observed_on_grid

ENERGY_UNIT = "J"


def energy_variable(model: CompiledModel, requested: str | None) -> str | None:
    """The energy variable of the study, checked; ``None`` if there is none."""
    units = model.units
    if requested is None:
        joules = [name for name, unit in units.items() if unit == ENERGY_UNIT]
        return joules[0] if len(joules) == 1 else None
    if requested not in units:
        raise SimulationError(f"'{requested}' is not a variable of {model.name}",
                              hint="name a state or observed variable of the model, "
                              "e.g. one declared as Real E = 0.5*m*v^2 + 0.5*k*x^2")
    if requested not in model.outputs and not set(model.states) <= set(model.outputs):
        raise SimulationError(f"the energy variable '{requested}' is not among the "
                              "compared variables", hint=f"add '{requested}' to --vars")
    return requested


def energy_series(model: CompiledModel, p: np.ndarray, grid: np.ndarray,
                  values: np.ndarray, name: str) -> np.ndarray:
    """``name`` on ``grid`` from a run's compared outputs ``values``."""
    if name in model.outputs:
        return values[:, model.outputs.index(name)]
    states = np.column_stack([values[:, model.outputs.index(s)] for s in model.states])
    if name in model.states:
        return states[:, model.states.index(name)]
    z = np.asarray(model.module.guesses(p), dtype=float)
    with np.errstate(all="ignore"):
        observed = observed_on_grid(model.module, grid, np.ascontiguousarray(states),
                                    p, z)
    return np.asarray(observed)[:, model.observed.index(name)]


def drift(series: np.ndarray, scale: float) -> float:
    """``max |E(t) - E(t0)| / scale`` (``scale`` <= 0: absolute)."""
    change = float(np.max(np.abs(series - series[0]))) if len(series) else 0.0
    return change / scale if scale > 0 else change
