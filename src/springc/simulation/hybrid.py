"""Simulation of a hybrid model: CompiledModel with events -> SimulationResult.

Runs :class:`.events.EventLoop` with the chosen solver (scipy's adaptive ones, the
fixed-step scene integrators, or ``auto``: capped probes of dop853 and radau decide,
:mod:`.hybrid_auto`; on the compiled engine, chosen as for continuous models, the solvers with a
compiled loop run in the kernels of ``springc.integrate``: :mod:`.hybrid_compiled`),
then computes the outputs row by row with the discrete values in force at each row,
and checks the model's assertions there. By default the result has one row per output
time (the value after an event at that very time); ``event_rows`` adds two rows at each
event, its left and right limits, as OpenModelica's result files do.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any, cast

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel
from .compiled import COMPILED, SCIPY, engine_reason, explained, jitted
from .events import EventLoop
from .events_fixed import run_fixed_events
from .failures import Stop, state_notes
from .hybrid_auto import Attempt, choose
from .hybrid_compiled import c_events, run_compiled_events
from .limits import OverLimit, check_outputs, over_limit
from .observed_rows import observed_at_rows
from .planning import RunPlan
from .results import SimulationResult, SimulationStats
from .solver_names import AUTO, EXPLICIT, FIXED_STEP
from .steps import Problem, Progress, warm_slots


def simulate_hybrid(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    """Integrate the hybrid ``model`` as ``plan`` says (see the module docstring), on
    its engine (:data:`.compiled.COMPILED`: :mod:`.hybrid_compiled`)."""
    solver, grid, x0, p, limits = plan.solver, plan.grid, plan.x0, plan.p, plan.limits
    assert x0 is not None
    rtol, atol, step, note, engine = plan.rtol, plan.atol, plan.step, plan.note, plan.engine
    options = plan.settings
    start, stop = plan.start, plan.stop
    reason = ""
    progress = Progress(options.progress, start, stop, limits.budget)
    event_rows = options.event_rows

    def attempt(solver: str, cap: int | None = None) -> Attempt:
        """A run of ``solver`` from the start, of at most ``cap`` steps."""
        capped = limits if cap is None else replace(limits, max_steps=cap)
        problem = Problem(model, p, solver, progress, capped)
        loop = EventLoop(problem, grid, keep_events=event_rows)
        compiled = engine == COMPILED and len(x0) > 0 and (
            jitted(model.module) or c_events(problem, solver))
        loop_time = 0.0
        try:
            if compiled:
                loop_time = run_compiled_events(loop, solver, x0, rtol, atol, step)
            elif solver in FIXED_STEP:
                assert step is not None
                run_fixed_events(loop, solver, x0, step)
            else:
                loop.run_adaptive(solver, x0, rtol, atol, capped.max_steps)
        except OverLimit as over:
            if cap is None:
                raise
            return Attempt(problem, loop, compiled, loop_time, over)
        return Attempt(problem, loop, compiled, loop_time)

    problem = Problem(model, p, EXPLICIT if solver == AUTO else solver, progress, limits)
    try:
        with np.errstate(all="ignore"):
            if not np.isfinite(x0).all():
                raise Stop(SimulationError(
                    f"the start values are not finite at time {start}",
                    notes=state_notes(problem.names, x0, None)))
            if solver == AUTO:
                run, reason = choose(attempt, x0, start, stop, limits.max_steps)
            else:
                run = attempt(solver)
            problem, loop, compiled, loop_time, _ = run
            solver = problem.solver
            loop.terminal()
            times, states, zs = rows(loop, event_rows)
            try:
                obs = _observed(model, problem, times, states, zs)
            except Stop:  # an assertion that fails at an earlier row is reported first
                check_assertions(problem, times, states, zs)
                raise
            check_assertions(problem, times, states, zs)
            outputs = _outputs(model, times, states, obs)
    except Stop as stop_:
        raise stop_.error from None
    except OverLimit as over:
        raise over_limit(over, start, stop, problem.jacobian) from None
    finally:
        progress.close()
    if loop.stopped is not None:
        when, message = loop.stopped
        shown = "".join(c if c.isprintable() else repr(c)[1:-1] for c in message)
        note = "; ".join(filter(None, (note, f"terminate() at time {when:.9g}: {shown}")))
    state_events, time_events = loop.counts.get("state", 0), loop.counts.get("time", 0)
    stats = SimulationStats(solver, loop.steps, problem.nfev, problem.njev,
                            time.perf_counter() - plan.began, problem.model_time,
                            model.compile_time, model.cached, reason, note,
                            COMPILED if compiled else SCIPY, loop_time, state_events,
                            time_events, engine_reason=engine_reason(
                                options.engine.lower(), solver, model.module, compiled,
                                len(x0)) if explained(options.engine, reason, compiled)
                            else "")
    units = model.units
    names = model.outputs
    return SimulationResult(model.name, times, names, outputs,
                            tuple(units.get(n, "") for n in names), stats,
                            dict(zip(model.parameter_names, p.tolist())),
                            tuple(loop.events), tuple(loop.step_times))


def rows(loop: EventLoop, event_rows: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times, states and ``z`` of the result rows: the grid rows reached (a run ended
    by terminate() stops at its time), and with ``event_rows`` the left and right
    limits at each event after the start, before the grid row at the same time."""
    k = loop.k
    times, states, zs = loop.grid[:k], loop.states[:k], loop.zs[:k]
    if loop.stopped is not None and (k == 0 or times[-1] < loop.stopped[0]):
        last = loop.last_event
        assert last is not None  # terminate() acts in an event
        times = np.append(times, last.time)
        states = np.vstack([states, last.x_right])
        zs = np.vstack([zs, last.z_right])
    if not event_rows:
        return times, states, zs
    extra_t, extra_x, extra_z, order = [], [], [], []
    for e in loop.events:
        if e.kind not in ("state", "time"):
            continue
        extra_t += [e.time, e.time]
        extra_x += [e.x_left, e.x_right]
        extra_z += [e.z_left, e.z_right]
        order += [0, 1]
    if not extra_t:
        return times, states, zs
    all_t = np.concatenate([np.asarray(extra_t), times])
    rank = np.concatenate([np.asarray(order), np.full(len(times), 2)])
    sort = np.lexsort((rank, all_t))
    return (all_t[sort], np.vstack([np.asarray(extra_x), states])[sort],
            np.vstack([np.asarray(extra_z), zs])[sort])


def check_assertions(problem: Problem, times: np.ndarray, states: np.ndarray,
                     zs: np.ndarray) -> None:
    """``assert(...)`` of a hybrid model, checked at every result row with the discrete
    values in force there (the event loop does not check after each step: a failure is
    reported at the first output time where the condition is false)."""
    if not problem.asserts:
        return
    for k, (t, x, z) in enumerate(zip(times, states, zs)):
        if k == 0:  # the first row is the initialization: initial() holds there
            z = np.array(z)
            z[int(cast(Any, problem.mod).Z_INITIAL)] = 1.0  # a HybridModule
            problem.asserts.start(float(t), x, z)
        else:
            problem.asserts.step(float(t), x, z)


def _observed(model: CompiledModel, problem: Problem, times: np.ndarray,
              states: np.ndarray, zs: np.ndarray) -> np.ndarray | None:
    """The observed variables at every row, each with its own discrete values, where
    an output or an assertion needs them (None where none does). Each row's Newton
    warm starts in ``zs`` become its solution, solved from the row before
    (:func:`.observed_rows.observed_at_rows`): the assertions are then evaluated from
    them. A run on the compiled engine gives all the rows of one kernel run the ``z``
    of its end, whose warm starts may be far from a row's solution
    (HeatingNPN_NORGate: from those at 140 s, the assertion's Newton block at 135.08 s
    found a negative temperature)."""
    selected = set(model.outputs)
    wanted = any(o in selected for o in model.observed)
    if not (wanted or (problem.asserts and warm_slots(model.module))):
        return None
    return observed_at_rows(model.module, problem, times, states, zs, keep=True)


def _outputs(model: CompiledModel, times: np.ndarray, states: np.ndarray,
             obs: np.ndarray | None) -> np.ndarray:
    """The selected outputs at every row (``obs``: the observed variables there)."""
    names = model.outputs
    columns: dict[str, np.ndarray] = {s: states[:, i] for i, s in enumerate(model.states)}
    if obs is not None:
        columns.update({o: obs[:, i] for i, o in enumerate(model.observed)})
    out = np.empty((len(times), len(names)))
    for i, name in enumerate(names):
        out[:, i] = columns[name]
    check_outputs(names, times, out)
    return out
