"""The continuous driver: CompiledModel + RunPlan -> SimulationResult for a model
without events, delays or switching states (``KIND`` ``continuous``).

The step loop (:mod:`.steps`) on scipy's integrators or the compiled loops
(:mod:`.compiled`), ``auto``'s race (:mod:`.race`), the fixed-step solvers
(:mod:`.solvers`), the model's assertions after every step, then the outputs on the
grid (:func:`.observed_rows.observed_on_rows`), or, for error control's companion
(``RunSettings.deferred_outputs``), the states with :class:`DeferredOutputs`: the
output rows computed when read, a few rows at a time.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel
from . import solvers
from .compiled import (
    COMPILED,
    SCIPY,
    advance_compiled,
    c_loop_runs,
    engine_reason,
    explained,
    jitted,
    observed_on_grid,
    run_fixed_compiled,
)
from .failures import Stop, state_notes
from .limits import CHECKED_ROWS, OverLimit, check_outputs, over_limit
from .native import advance_native, loop_ready, native_observed
from .observed_rows import observed_on_rows
from .planning import RunPlan
from .race import auto
from .results import SimulationResult, SimulationStats
from .solver_names import AUTO, EXPLICIT, FIXED_STEP
from .steps import Problem, Progress, StepLoop, integrate


def simulate_continuous(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    """Integrate ``model`` as ``plan`` says (see the module docstring)."""
    solver, grid, x0, p = plan.solver, plan.grid, plan.x0, plan.p
    assert x0 is not None
    start, stop, rtol, atol = plan.start, plan.stop, plan.rtol, plan.atol
    step, note, engine, began = plan.step or 0.0, plan.note, plan.engine, plan.began
    options = plan.settings
    progress = Progress(options.progress, start, stop, plan.limits.budget)
    problem = Problem(model, p, solver, progress, plan.limits)
    try:
        with np.errstate(all="ignore"):
            if not np.isfinite(x0).all():
                raise Stop(SimulationError(
                    f"the start values are not finite at time {start}",
                    notes=state_notes(problem.names, x0, None)))
            if problem.asserts:
                problem.asserts.start(start, x0, problem.z)
            reason = ""
            # the C loop runs a python module's model (choose_engine allowed it); a large
            # model's generated functions may be plain Python otherwise: scipy's loop then
            native = engine == COMPILED and not jitted(model.module) \
                and c_loop_runs(solver, model.module.BACKEND) and loop_ready(problem)
            compiled = engine == COMPILED and (native or jitted(model.module))
            finish = (advance_native if native else advance_compiled) if compiled else None
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
            # a C loop run's outputs come from the C model at once; others may be
            # deferred for error control
            deferred = DeferredOutputs(model, problem, grid, states) \
                if options.deferred_outputs and not native and _in_order(model) else None
            outputs = _outputs(model, problem, grid, states, native) if deferred is None \
                else np.empty((len(grid), 0))
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
                            if explained(options.engine, reason, compiled) or native
                            else "")
    units = model.units
    names = model.outputs
    return SimulationResult(model.name, grid, names, outputs,
                            tuple(units.get(n, "") for n in names), stats,
                            dict(zip(model.parameter_names, p.tolist())), deferred=deferred)


BLOCK_ROWS = 8
"""Output rows per block of :meth:`DeferredOutputs.blocks` (the 50x50 cloth: 8 MB)."""


def _in_order(model: CompiledModel) -> bool:
    """Whether the outputs are every state then every observed variable, in order."""
    return tuple(model.outputs) == (*model.states, *model.observed)


@dataclass(frozen=True)
class DeferredOutputs:
    """A continuous run's outputs (every state, then every observed variable) not yet
    computed: its states on the grid. Error control compares its companion run with
    the answer block by block (:func:`.error_estimate.compare`), so a large scene never
    holds a second array of every output; :meth:`values` computes them all when the
    companion becomes the answer."""

    model: CompiledModel
    problem: Problem
    grid: np.ndarray
    states: np.ndarray

    def values(self) -> np.ndarray:
        """Every output row (as a run that is not deferred computes them, its errors)."""
        return _outputs(self.model, self.problem, self.grid, self.states)

    def blocks(self) -> Iterator[np.ndarray]:
        """The output rows in order, :data:`BLOCK_ROWS` at a time: the same rows as
        :meth:`values` (the grid loop carries ``z`` from block to block as from row to
        row). From a block with a row that fails or is not finite on, the rest come
        from :meth:`values`, in one block (its continuation, or its error)."""
        module, p, n = self.model.module, self.problem.p, len(self.model.states)
        width = n + len(self.model.observed)
        z = np.asarray(module.guesses(p), dtype=float) if width > n else np.zeros(1)
        for begin in range(0, len(self.grid), BLOCK_ROWS):
            end = min(begin + BLOCK_ROWS, len(self.grid))
            block = np.empty((end - begin, width))
            block[:, :n] = self.states[begin:end]
            try:
                if width > n:
                    block[:, n:] = observed_on_grid(module, self.grid[begin:end],
                                                    self.states[begin:end], p, z)
            except (ArithmeticError, ValueError, np.linalg.LinAlgError):
                z[-1] = 1.0
            if (width > n and z[-1] != 0.0) or not np.isfinite(block).all():
                yield self.values()[begin:]
                return
            yield block



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


def _outputs(model: CompiledModel, problem: Problem, grid: np.ndarray,
             states: np.ndarray, native: bool = False) -> np.ndarray:
    """The output columns (``model.outputs``) at the grid's rows: one array, the
    observed rows written into it directly where the outputs are the states then the
    observed variables in order (every output: a large scene holds one copy); on the
    C loop (``native``) by the C model first."""
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
        if native and native_observed(problem, grid, states, z.copy(), obs):
            wanted = []
    if wanted:
        try:
            observed_on_rows(model.module, grid, states, problem.p, z, obs)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as err:
            raise _first_failure(model, problem, grid, states, err) from err
        if z[-1] != 0.0:
            row = int(np.flatnonzero(np.isnan(obs).all(axis=1))[0])
            problem.z[-1] = z[-1]
            raise problem.newton_failure(float(grid[row]), states[row])
        if not all(np.isfinite(obs[k:k + CHECKED_ROWS]).all()
                   for k in range(0, len(obs), CHECKED_ROWS)):
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
