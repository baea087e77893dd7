"""The plan of a run: CompiledModel + RunSettings -> :class:`RunPlan`, resolved once.

(The module is not named ``plan``: the package exports the function :func:`plan`, which
a submodule of that name would replace once imported.)

:func:`plan` resolves what every driver needs, in this order, each refusal naming the
option at fault: the solver (a name of the registry), the limits, the engine
(:func:`.compiled.choose_engine`), the times and tolerances (settings, then the
model's ``experiment`` annotation, then the defaults of :mod:`.settings`), the output
grid, the parameter vector and the start values (run-time data: a structural
parameter needs a new compilation), the size of the outputs, a fixed-step solver's
step, the driver (the kind the generated module declares, ``KIND``) and the start
state, solved on the system the compiled model captured when it was compiled, never
on the files as they are now. The drivers (:data:`.runner.DRIVERS`) take
``(model, plan)``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SimulationError, describe_failure
from ..pipeline import CompiledModel, ModuleKind, split_values
from . import solvers
from .compiled import choose_engine
from .failures import code_location
from .limits import Limits, check_parameters
from .settings import DEFAULT_INTERVALS, DEFAULT_RTOL, DEFAULT_START, DEFAULT_STOP, RunSettings
from .solver_names import ALL_SOLVERS, FIXED_STEP
from .values import MAX_INTERVALS

MAX_OUTPUT_BYTES = 4_000_000_000
LSODA_LIMIT = 2000


@dataclass(frozen=True)
class RunPlan:
    """A run, resolved (see the module docstring): what the drivers read."""

    settings: RunSettings  # as asked (progress, event rows, the engine asked for)
    solver: str  # a name of the registry, lower case (auto included)
    grid: np.ndarray
    rtol: float
    atol: float
    step: float | None  # fixed-step solvers only, validated
    note: str  # a fixed step shortened to land on the output times
    parameters: dict[str, float]  # the parameter values set (not structural)
    starts: dict[str, float]  # the start values set
    p: np.ndarray
    x0: np.ndarray | None  # None for the switching driver: it solves its own start
    limits: Limits
    engine: str  # compiled or scipy (.compiled.choose_engine)
    driver: str  # a ModuleKind: the driver that runs it
    began: float  # perf_counter() when planning began: the run's wall time counts it

    @property
    def start(self) -> float:
        return float(self.grid[0])

    @property
    def stop(self) -> float:
        return float(self.grid[-1])

    @property
    def fixed(self) -> bool:
        """A fixed-step solver."""
        return self.solver in FIXED_STEP


def plan(model: CompiledModel, settings: RunSettings,
         max_output_bytes: float = MAX_OUTPUT_BYTES) -> RunPlan:
    """Resolve ``settings`` for ``model`` (see the module docstring)."""
    began = time.perf_counter()
    solver = settings.solver.lower()
    if solver not in ALL_SOLVERS:
        raise SimulationError(f"unknown solver '{settings.solver}'",
                              hint=f"choose one of {', '.join(ALL_SOLVERS)}")
    limits = Limits(settings.step_limit, settings.seconds_limit, settings.budget)
    limits.validate()
    engine = choose_engine(settings.engine, solver, model.module.BACKEND, "engine", "backend")
    start, stop, interval, rtol, atol = resolve(model, settings)
    grid = output_grid(start, stop, interval)
    parameters, starts = split_values(model, settings.parameters)
    structural = [n for n in parameters if n in model.structural]
    if structural:
        raise SimulationError(f"'{structural[0]}' is a structural parameter: changing it "
                              "needs a new compilation",
                              hint="pass it to compile_model(parameters=...) or use "
                              "springc.simulate(files, parameters=...)")
    n = len(model.states)
    if solver == "lsoda" and n > LSODA_LIMIT:
        raise SimulationError(f"lsoda uses dense Jacobians, too large for {n} states",
                              hint="use --solver bdf or radau (sparse Jacobians)")
    size = len(grid) * (len(model.outputs) + n) * 8
    if size > max_output_bytes:
        raise SimulationError(
            f"{len(grid)} output times x {len(model.outputs)} variables need "
            f"{size / 1e9:.1f} GB", hint="select variables with --vars (outputs=[...]) or "
            "use a larger --interval")
    step, note = None, ""
    if solver in FIXED_STEP:
        step, note = solvers.check_step(solver, settings.step, grid, limits.max_steps)
    p = parameter_vector(model, parameters)
    driver = model.kind
    if driver == ModuleKind.SWITCHING and solver in FIXED_STEP:
        driver = ModuleKind.CONTINUOUS  # states chosen at compile time, never switched
    x0 = None if driver == ModuleKind.SWITCHING else initial_state(model, p, start, starts)
    return RunPlan(settings, solver, grid, rtol, atol, step, note, parameters, starts, p,
                   x0, limits, engine, driver, began)


def output_grid(start: float, stop: float, interval: float) -> np.ndarray:
    """``start, start + interval, ..., stop``; the last point is ``stop`` exactly."""
    if not (math.isfinite(start) and math.isfinite(stop)) or stop <= start:
        raise SimulationError(f"the stop time {stop:g} must be after the start time "
                              f"{start:g}")
    if not math.isfinite(stop - start):
        raise SimulationError(f"the span from {start:g} to {stop:g} is too large for a "
                              "floating-point number")
    if not interval > 0:
        raise SimulationError(f"the output interval must be positive, not {interval:g}")
    count = (stop - start) / interval
    n = max(1, round(count)) if abs(count - round(count)) < 1e-9 * max(1.0, count) \
        else math.ceil(count)
    if n > MAX_INTERVALS:
        raise SimulationError(f"{n} output intervals are too many",
                              hint="use a larger --interval")
    grid = start + interval * np.arange(n + 1, dtype=float)
    grid[-1] = stop
    return grid


def resolve(model: CompiledModel, settings: RunSettings) -> tuple[float, float, float,
                                                                  float, float]:
    """start, stop, interval, rtol, atol from settings, experiment and defaults."""
    exp = model.module.EXPERIMENT
    start = _first(settings.start, exp.get("start"), DEFAULT_START)
    stop = _first(settings.stop, exp.get("stop"), DEFAULT_STOP)
    if settings.interval is not None:
        interval = settings.interval
    elif exp.get("interval") is not None:
        interval = exp["interval"]
    else:
        interval = (stop - start) / DEFAULT_INTERVALS
    rtol = _first(settings.rtol, exp.get("tolerance"), DEFAULT_RTOL)
    atol = _first(settings.atol, None, rtol / 1000)
    return start, stop, interval, rtol, atol


def _first(*values: float | None) -> float:
    for v in values:
        if v is not None:
            return float(v)
    raise AssertionError("no default")


def parameter_vector(model: CompiledModel, values: Mapping[str, float]) -> np.ndarray:
    """The generated module's parameter vector with ``values``; every entry finite."""
    try:
        p = np.asarray(model.module.parameters(dict(values)), dtype=float)
    except (ArithmeticError, ValueError) as err:
        where = code_location(err, str(model.path))
        raise SimulationError(f"{describe_failure(err)} while computing the parameter "
                              f"{where or 'values'}",
                              hint="check the parameters its binding uses (--set)") from None
    check_parameters(model.parameter_names, p)
    return p


def initial_state(model: CompiledModel, p: np.ndarray, t0: float = 0.0,
                  starts: Mapping[str, float] | None = None) -> np.ndarray:
    """The states at the start time.

    States start at their ``start`` values, as Modelica tools do when nothing else
    fixes them; ``starts`` replaces the start values it names (run-time data, never a
    new compilation: a fixed start is then the initial value, a free one a guess of
    the initial problem). A model with ``initial equation``s or fixed start values on variables
    that are not states has an initial problem: it is solved by
    :func:`springc.simplify.initial_state` on the simplified system the compiled model
    captured when it was compiled (:meth:`CompiledModel.closed_system`; the generated
    module holds only the ODE's functions), never on the files as they are now.
    """
    if not getattr(model.module, "INITIAL_CONDITIONS", 0):
        try:
            x0 = np.array(model.module.start(p), dtype=float)
            index = {name: i for i, name in enumerate(model.states)}
            for name, value in (starts or {}).items():
                x0[index[name]] = value
            return x0
        except (ArithmeticError, ValueError) as err:
            where = code_location(err, str(model.path))
            raise SimulationError(
                f"{describe_failure(err)} while computing the start value of {where or 'a state'}",
                hint="check the parameters the start values use (--set)") from None
    from ..simplify import initial_state as solve_initial

    system = model.closed_system().system
    values = dict(zip(model.parameter_names, (float(v) for v in p)))
    if getattr(model.module, "EVENTS", False):  # discrete variables at their start
        mod: Any = model.module
        z = mod.guesses(p)
        values.update((name, float(z[slot])) for name, slot in zip(mod.DISCRETE, mod.Z_DISCRETE))
    x0, _info = solve_initial(system, values, t0, starts=starts)
    order = {s.name: i for i, s in enumerate(system.states)}
    return np.array([x0[order[name]] for name in model.states], dtype=float)
