"""Simulation: CompiledModel + RunSettings -> SimulationResult.

:func:`simulate_model` holds a run to its tolerance (:mod:`.error_control`); each run
is planned once (:func:`.planning.plan`: grid, tolerances, parameters, start state, limits,
engine, driver) and run by the driver of the kind the generated module declares
(:data:`DRIVERS`): continuous (:mod:`.continuous`), hybrid (:mod:`.hybrid`), delay
(:mod:`.delays`) or switching (:mod:`.switching`). The options and their defaults are
:class:`~.settings.RunSettings`.

(The module is not named ``simulate``: ``springc.simulate`` is the API function, and a
submodule of that name would replace it on the package once imported.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from ..pipeline import CompiledModel, ModuleKind
from . import error_control
from .continuous import simulate_continuous
from .planning import (
    LSODA_LIMIT,
    MAX_OUTPUT_BYTES,
    RunPlan,
    initial_state,
    output_grid,
    parameter_vector,
    plan,
    resolve,
)
from .results import SimulationResult
from .settings import RunSettings, SimulationOptions, check_mode

__all__ = ["DRIVERS", "LSODA_LIMIT", "MAX_OUTPUT_BYTES", "Rerun", "RunPlan", "RunSettings",
           "SimulationOptions", "initial_state", "output_grid", "parameter_vector", "plan",
           "resolve", "run_plan", "simulate_model", "simulate_once"]


def _hybrid(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    from .hybrid import simulate_hybrid  # the event loop loads with its first model

    return simulate_hybrid(model, plan)


def _delay(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    from .delays import simulate_delayed  # the history of delay(...)

    return simulate_delayed(model, plan)


def _switching(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    from .switching import simulate_switching_model  # states chosen during the run

    return simulate_switching_model(model, plan)


DRIVERS: dict[str, Callable[[CompiledModel, RunPlan], SimulationResult]] = {
    ModuleKind.CONTINUOUS: simulate_continuous, ModuleKind.HYBRID: _hybrid,
    ModuleKind.DELAY: _delay, ModuleKind.SWITCHING: _switching}
"""The driver of each kind of generated module (``KIND``), taking ``(model, plan)``."""


DEFAULTS = RunSettings()
"""The settings of a run given none: every default."""


def simulate_model(model: CompiledModel, options: RunSettings = DEFAULTS) -> SimulationResult:
    """Integrate ``model`` and return the selected outputs on the output grid (with the
    model's description strings), with the estimated error and tightened as
    ``options.error_control`` says (:mod:`.error_control`)."""
    mode = check_mode(options.error_control, "error_control")
    rtol, atol = resolve(model, options)[3:]
    result = error_control.controlled(options, error_control.Asked(mode, rtol, atol),
                                      lambda run: simulate_once(model, run))
    result.descriptions = model.descriptions
    result.discrete = tuple(getattr(model.module, "DISCRETE", ()))
    result.rerun = Rerun(model, replace(
        options, progress=None, error_control="off",
        rtol=result.stats.rtol if result.stats.rtol is not None else options.rtol,
        atol=result.stats.atol if result.stats.atol is not None else options.atol))
    return result


@dataclass(frozen=True)
class Rerun:
    """The run of a result again on a grid of other ``points`` (a plot's finer grid:
    :func:`.plot_layout.plot_points`), at the tolerances the result was run at, without
    error control, with the rows at both sides of each event: the result itself and
    its grid stay as they are."""

    model: CompiledModel
    options: RunSettings

    def __call__(self, points: int) -> SimulationResult:
        start, stop = resolve(self.model, self.options)[:2]
        return simulate_once(self.model, replace(
            self.options, interval=(stop - start) / (points - 1), event_rows=True))


def simulate_once(model: CompiledModel, options: RunSettings) -> SimulationResult:
    """One run of ``model`` with ``options`` (no error estimate): planned, then run."""
    return run_plan(model, plan(model, options, MAX_OUTPUT_BYTES))


def run_plan(model: CompiledModel, planned: RunPlan) -> SimulationResult:
    """The run of ``planned`` by its driver."""
    return DRIVERS[planned.driver](model, planned)
