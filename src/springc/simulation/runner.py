"""Simulation: CompiledModel + SimulationOptions -> SimulationResult.

Options, the output grid ``t0, t0 + dt, ..., stop``, the start state, and the run:
the step loop (:mod:`.steps`), ``auto``'s race (:mod:`.race`), the fixed-step
solvers (:mod:`.solvers`), the switching driver (:mod:`.switching`), then the outputs.

Defaults: start 0 s, stop 10 s, 500 output intervals, unless the model's
``experiment`` annotation says otherwise (its Interval applies even when the start or
stop time is given); rtol 1e-6 (or the experiment's Tolerance),
atol = rtol / 1000; solver :data:`DEFAULT_SOLVER`; at most
:data:`~springc.simulation.limits.DEFAULT_MAX_STEPS` steps and
:data:`~springc.simulation.limits.DEFAULT_TIME_LIMIT` seconds (:mod:`.limits`).

(The module is not named ``simulate``: ``springc.simulate`` is the API function, and a
submodule of that name would replace it on the package once imported.)
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, TextIO

import numpy as np

from ..errors import SimulationError, describe_failure
from ..pipeline import CompiledModel, split_values
from . import error_control, solvers
from .compiled import (
    COMPILED,
    SCIPY,
    advance_compiled,
    choose_engine,
    engine_reason,
    explained,
    jitted,
    run_fixed_compiled,
)
from .failures import Stop, code_location, state_notes
from .limits import (
    DEFAULT_MAX_STEPS,
    DEFAULT_TIME_LIMIT,
    Limits,
    OverLimit,
    check_outputs,
    check_parameters,
    over_limit,
)
from .observed_rows import observed_on_rows
from .race import auto
from .results import SimulationResult, SimulationStats
from .solver_names import (
    ALL_SOLVERS,
    AUTO,
    DEFAULT_ENGINE,
    DEFAULT_SOLVER,
    EXPLICIT,
    FIXED_STEP,
)
from .steps import Problem, Progress, StepLoop, integrate
from .values import MAX_INTERVALS

DEFAULT_START, DEFAULT_STOP, DEFAULT_INTERVALS = 0.0, 10.0, 500
DEFAULT_RTOL = 1e-6
MAX_OUTPUT_BYTES = 4_000_000_000
LSODA_LIMIT = 2000


@dataclass(frozen=True)
class SimulationOptions:
    """``None`` means: from the experiment annotation, else the documented default."""

    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    solver: str = DEFAULT_SOLVER
    rtol: float | None = None
    atol: float | None = None
    parameters: Mapping[str, float] = field(default_factory=dict)  # and start values
    progress: TextIO | None = None
    step: float | None = None  # fixed-step solvers only
    max_steps: int = DEFAULT_MAX_STEPS
    time_limit: float = DEFAULT_TIME_LIMIT  # seconds of wall clock
    engine: str = DEFAULT_ENGINE  # auto, compiled (springc.integrate) or scipy
    event_rows: bool = False  # add rows with the left and right limits at each event
    error_control: str = error_control.DEFAULT_MODE  # tighten, warn or off (.error_control)


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


def resolve(model: CompiledModel, options: SimulationOptions) -> tuple[float, float, float,
                                                                        float, float]:
    """start, stop, interval, rtol, atol from options, experiment and defaults."""
    exp = model.module.EXPERIMENT
    start = _first(options.start, exp.get("start"), DEFAULT_START)
    stop = _first(options.stop, exp.get("stop"), DEFAULT_STOP)
    if options.interval is not None:
        interval = options.interval
    elif exp.get("interval") is not None:
        interval = exp["interval"]
    else:
        interval = (stop - start) / DEFAULT_INTERVALS
    rtol = _first(options.rtol, exp.get("tolerance"), DEFAULT_RTOL)
    atol = _first(options.atol, None, rtol / 1000)
    return start, stop, interval, rtol, atol


def _first(*values: float | None) -> float:
    for v in values:
        if v is not None:
            return float(v)
    raise AssertionError("no default")


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


def simulate_model(model: CompiledModel, options: SimulationOptions = SimulationOptions()
                   ) -> SimulationResult:
    """Integrate ``model`` and return the selected outputs on the output grid (with the
    model's description strings), with the estimated error and tightened as
    ``options.error_control`` says (:mod:`.error_control`)."""
    mode = error_control.check_mode(options.error_control, "error_control")
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
    options: SimulationOptions

    def __call__(self, points: int) -> SimulationResult:
        start, stop = resolve(self.model, self.options)[:2]
        return simulate_once(self.model, replace(
            self.options, interval=(stop - start) / (points - 1), event_rows=True))


def simulate_once(model: CompiledModel, options: SimulationOptions) -> SimulationResult:
    """One run of ``model`` with ``options`` (no error estimate)."""
    began = time.perf_counter()
    solver = options.solver.lower()
    if solver not in ALL_SOLVERS:
        raise SimulationError(f"unknown solver '{options.solver}'",
                              hint=f"choose one of {', '.join(ALL_SOLVERS)}")
    limits = Limits(options.max_steps, options.time_limit)
    limits.validate()
    engine = choose_engine(options.engine, solver, model.module.BACKEND, "engine", "backend")
    start, stop, interval, rtol, atol = resolve(model, options)
    grid = output_grid(start, stop, interval)
    parameters, starts = split_values(model, options.parameters)
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
    if size > MAX_OUTPUT_BYTES:
        raise SimulationError(
            f"{len(grid)} output times x {len(model.outputs)} variables need "
            f"{size / 1e9:.1f} GB", hint="select variables with --vars (outputs=[...]) or "
            "use a larger --interval")
    note = ""
    step = 0.0  # fixed-step solvers only
    if solver in FIXED_STEP:
        step, note = solvers.check_step(solver, options.step, grid, limits.max_steps)
    p = parameter_vector(model, parameters)
    if getattr(model.module, "DELAYS", 0):  # the history of delay(...) (delays.py)
        from .delays import simulate_delayed

        x0 = initial_state(model, p, start, starts)
        return simulate_delayed(model, options, solver, grid, x0, p, rtol, atol, limits, began)
    if getattr(model.module, "EVENTS", False):  # the states chosen at compile time
        from .hybrid import simulate_hybrid

        x0 = initial_state(model, p, start, starts)
        return simulate_hybrid(model, options, solver, grid, x0, p, rtol, atol, limits,
                               step if solver in FIXED_STEP else None, note, began, engine)
    if getattr(model.module, "SWITCHABLE", False) and solver not in FIXED_STEP:
        from .switching import simulate_switching_model

        if options.engine == COMPILED:
            raise SimulationError(f"{model.name} may switch its states during the run "
                                  "(dynamic state selection), which only the scipy engine "
                                  "does", hint="use --engine scipy (or auto)")

        if starts:
            raise SimulationError(f"{model.name} may switch its states during the run "
                                  f"(dynamic state selection): the start of "
                                  f"'{min(starts)}' cannot be set from outside",
                                  hint="set it in the model (start = ...)")
        result = simulate_switching_model(model, solver, grid, rtol, atol,
                                          parameters, limits)
        if options.engine.lower() == AUTO:
            result.stats = replace(result.stats, engine_reason=(
                f"{result.stats.solver} ran in scipy's loop, the only one that switches "
                "states"))
        return result
    x0 = initial_state(model, p, start, starts)
    progress = Progress(options.progress, start, stop)
    problem = Problem(model, p, solver, progress, limits)
    try:
        with np.errstate(all="ignore"):
            if not np.isfinite(x0).all():
                raise Stop(SimulationError(
                    f"the start values are not finite at time {start}",
                    notes=state_notes(problem.names, x0, None)))
            if problem.asserts:
                problem.asserts.start(start, x0, problem.z)
            reason = ""
            # a large model's generated functions may be plain Python: scipy's loop then
            compiled = engine == COMPILED and jitted(model.module)
            finish = advance_compiled if compiled else None
            loop_time = 0.0
            if solver in FIXED_STEP and compiled:
                states, steps, loop_time = run_fixed_compiled(problem, grid, x0, step)
            elif solver in FIXED_STEP:
                states, steps = solvers.run_fixed(problem, grid, x0, step)
            elif solver == AUTO and len(x0):
                run = StepLoop(problem, grid, x0, rtol, atol, finish)
                solver, reason = auto(run, start, x0, stop, lambda t, x: solvers.choose(
                    problem.jac(t, x), stop - start))
                states, steps, loop_time = run.states, run.steps, run.loop_time
                compiled = run.compiled_steps > 0
            else:
                if solver == AUTO:
                    solver, reason = EXPLICIT, "no states to integrate"
                problem.solver = solver
                run = integrate(problem, grid, x0, rtol, atol, finish)
                states, steps, loop_time = run.states, run.steps, run.loop_time
                compiled = compiled and len(x0) > 0
            if problem.asserts and (compiled or not len(x0)):
                problem.asserts.grid(grid, states, problem.z, _locate(
                    problem, grid, states, solver, rtol, atol, step) if len(x0) else None)
            outputs = _outputs(model, problem, grid, states)
    except Stop as stop_:
        raise stop_.error from None
    except OverLimit as over:
        raise over_limit(over, start, stop, problem.jacobian) from None
    finally:
        progress.close()
    stats = SimulationStats(solver, steps, problem.nfev, problem.njev,
                            time.perf_counter() - began, problem.model_time,
                            model.compile_time, model.cached, reason, note,
                            COMPILED if compiled else SCIPY, loop_time,
                            engine_reason=engine_reason(options.engine.lower(), solver,
                                                        model.module, compiled, len(x0))
                            if explained(options.engine, reason, compiled) else "")
    units = model.units
    names = model.outputs
    return SimulationResult(model.name, grid, names, outputs,
                            tuple(units.get(n, "") for n in names), stats,
                            dict(zip(model.parameter_names, p.tolist())))


def _locate(problem: Problem, grid: np.ndarray, states: np.ndarray, solver: str,
            rtol: float, atol: float, step: float) -> Callable[[int], None]:
    """Run the output interval ``grid[k - 1], grid[k]`` of a compiled run again on
    scipy's loop (or the Python fixed-step integrator, the same steps), from the state
    at ``grid[k - 1]``: its assertion checks after every step locate a failure inside
    the interval and raise it. A run that fails otherwise is left to the caller."""
    def locate(k: int) -> None:
        span = grid[k - 1:k + 1]
        problem.solver = solver
        try:
            if solver in FIXED_STEP:
                solvers.run_fixed(problem, span, states[k - 1], step)
            else:
                integrate(problem, span, states[k - 1], rtol, atol)
        except (Stop, OverLimit):
            pass
    return locate


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


def _outputs(model: CompiledModel, problem: Problem, grid: np.ndarray,
             states: np.ndarray) -> np.ndarray:
    """The output columns (``model.outputs``) at the grid's rows: one array, the
    observed rows written into it directly where the outputs are the states then the
    observed variables in order (every output: a large scene holds one copy)."""
    names = model.outputs
    n = len(model.states)
    columns = [*model.states, *model.observed]
    selected = set(names)
    wanted = [o for o in model.observed if o in selected]
    in_order = tuple(columns) == tuple(names)
    out = np.empty((len(grid), len(names)))
    obs = out[:, n:] if in_order else np.empty((len(grid), len(model.observed)))
    if wanted:
        z = np.asarray(model.module.guesses(problem.p), dtype=float)
        try:
            observed_on_rows(model.module, grid, states, problem.p, z, obs)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise _first_failure(model, problem, grid, states, err) from err
        if z[-1] != 0.0:
            row = int(np.flatnonzero(np.isnan(obs).all(axis=1))[0])
            problem.z[-1] = z[-1]
            raise problem.newton_failure(float(grid[row]), states[row])
        if not np.isfinite(obs).all():
            _locate_observed(model, problem, grid, states, obs)
    if in_order:
        out[:, :n] = states
    else:
        sources = {s: i for i, s in enumerate(columns)}  # columns of [states | observed]
        index = np.array([sources[name] for name in names], dtype=np.intp)
        from_states = index < n
        out[:, from_states] = states[:, index[from_states]]
        out[:, ~from_states] = obs[:, index[~from_states] - n]
    check_outputs(names, grid, out)
    return out


def _first_failure(model: CompiledModel, problem: Problem, grid: np.ndarray,
                   states: np.ndarray, err: BaseException) -> Stop:
    """The failure of the observed variables at the first output time where it occurs
    (``observed_grid`` raised for the whole grid)."""
    z = np.asarray(model.module.guesses(problem.p), dtype=float)
    for row in range(len(grid)):
        try:
            model.module.observed(float(grid[row]), states[row], problem.p, z)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as first:
            return problem.fail(first, float(grid[row]), states[row], "an observed variable")
    return problem.fail(err, float(grid[-1]), states[-1], "an observed variable")


def _locate_observed(model: CompiledModel, problem: Problem, grid: np.ndarray,
                     states: np.ndarray, obs: np.ndarray) -> None:
    """Raise the located error of a numba module's observed variables that are not
    finite: the first output time up to the first non-finite row where the Python
    semantics of the same code raise (as the python backend does)."""
    last = int(np.flatnonzero(~np.isfinite(obs).all(axis=1))[0])
    for row in range(last + 1):
        located = problem.locate(model.module.observed, float(grid[row]), states[row],
                                 "an observed variable")
        if located is not None:
            raise located
