"""Runs of models with ``delay(expr, delayTime[, delayMax])`` (Modelica 3.6, 3.7.4.1).

The generated module reads the value of its k-th delay call from ``z[Z_DELAYS + k]``
and computes the delayed expressions and the delay times with ``delay_inputs``
(codegen/delays.py). This run keeps the history of each delayed expression: after
every accepted step of a scipy integrator, at :data:`SAMPLES` points of the step's
dense output. Before each evaluation at time ``t`` the slots get the history at
``t - delayTime`` by cubic interpolation on the four nearest points (the value at the
start time while ``t - delayTime`` lies before it; a delay time of 0 is the
expression now). The step size is at most the smallest positive delay time at the
start, so that every stage of a step looks back into the recorded history (a delay
time that later becomes shorter than the step is extrapolated from the last four
points).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel
from .failures import Stop, state_notes
from .limits import OverLimit
from .observed_rows import observed_at_rows
from .planning import RunPlan
from .results import SimulationResult, SimulationStats
from .solver_names import AUTO, EXPLICIT, FIXED_STEP, IMPLICIT_SOLVERS, SOLVERS
from .steps import Problem, Progress

#: Points of the dense output recorded per accepted step.
SAMPLES = 8


class DelayHistory:
    """The recorded values of the delayed expressions, growing with the run."""

    def __init__(self, mod: Any, p: np.ndarray) -> None:
        self.mod, self.p = mod, p
        self.n = int(mod.DELAYS)
        self.base = int(mod.Z_DELAYS)
        self.size = 0
        self.times = np.empty(256)
        self.values = np.empty((256, self.n))

    def inputs(self, t: float, x: np.ndarray, z: np.ndarray) -> np.ndarray:
        return np.asarray(self.mod.delay_inputs(t, x, self.p, z), dtype=float)

    def record(self, t: float, x: np.ndarray, z: np.ndarray) -> None:
        if self.size and t <= self.times[self.size - 1]:
            return
        if self.size == len(self.times):
            self.times = np.concatenate([self.times, np.empty(self.size)])
            self.values = np.concatenate([self.values, np.empty((self.size, self.n))])
        self.times[self.size] = t
        self.values[self.size] = self.inputs(t, x, z)[:self.n]
        self.size += 1

    def fill(self, t: float, x: np.ndarray, z: np.ndarray) -> None:
        """Set the delay slots of ``z`` for an evaluation at ``(t, x)``."""
        di = self.inputs(t, x, z)
        for k in range(self.n):
            lag = di[self.n + k]
            if not lag >= 0:
                raise Stop(SimulationError(
                    f"the delay time of {self.mod.DELAY_CALLS[k]} is {lag:g} at time {t:g}",
                    notes=state_notes(tuple(self.mod.STATES), x, None),
                    hint="a delay time must not be negative (Modelica 3.6, 3.7.4.1)"))
            z[self.base + k] = di[k] if lag == 0 else self.at(k, t - lag)

    def at(self, k: int, tq: float) -> float:
        """The history of expression ``k`` at ``tq`` (cubic through 4 points)."""
        m = self.size
        times, values = self.times[:m], self.values[:m, k]
        if tq <= times[0] or m == 1:
            return float(values[0])
        # past the last point (a delay time shorter than the step): extrapolated
        i = min(int(np.searchsorted(times, tq)), m)  # times[i-1] < tq <= times[i]
        lo = min(max(i - 2, 0), max(m - 4, 0))
        ts, vs = times[lo:lo + 4], values[lo:lo + 4]
        out = 0.0
        for j in range(len(ts)):
            w = 1.0
            for q in range(len(ts)):
                if q != j:
                    w *= (tq - ts[q]) / (ts[j] - ts[q])
            out += w * vs[j]
        return out


def simulate_delayed(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    """Integrate ``model`` (it has delay calls) as ``plan`` says, on scipy's integrators."""
    import scipy.integrate

    solver, grid, x0, p, limits = plan.solver, plan.grid, plan.x0, plan.p, plan.limits
    assert x0 is not None
    rtol, atol = plan.rtol, plan.atol
    mod = model.module
    if getattr(mod, "EVENTS", False):
        raise SimulationError("delay() in a model with events is not supported yet",
                              hint="springc supports a subset of Modelica; see \"Not "
                              "supported yet\" in docs/language.md")
    if solver in FIXED_STEP:
        raise SimulationError(f"delay() needs an adaptive solver, not {solver}",
                              hint="use --solver dop853, rk45, radau or bdf")
    reason = ""
    if solver == AUTO:
        solver, reason = EXPLICIT, "a model with delay(): dop853 with the delayed history"
    start, stop = float(grid[0]), float(grid[-1])
    progress = Progress(plan.settings.progress, start, stop, limits.budget)
    problem = Problem(model, p, solver, progress, limits)
    history = DelayHistory(mod, p)
    z = problem.z
    states = np.empty((len(grid), len(x0)))
    zs = np.empty((len(grid), len(z)))
    steps = 0
    try:
        with np.errstate(all="ignore"):
            history.record(start, x0, z)
            history.fill(start, x0, z)
            lags = history.inputs(start, x0, z)[history.n:]
            positive = lags[lags > 0]
            states[0], zs[0] = x0, z
            k = 1
            if len(x0):
                def rhs(t: float, x: np.ndarray) -> np.ndarray:
                    history.fill(t, x, z)
                    return problem.rhs(t, x)

                kwargs: dict[str, Any] = {"jac": problem.jac} \
                    if solver in IMPLICIT_SOLVERS else {}
                if len(positive):
                    kwargs["max_step"] = float(positive.min())
                integrator = getattr(scipy.integrate, SOLVERS[solver])(
                    rhs, start, x0, stop, rtol=rtol, atol=atol, **kwargs)
                while k < len(grid):
                    before = integrator.t
                    message = integrator.step()
                    steps += 1
                    if integrator.status == "failed":
                        raise Stop(SimulationError(
                            f"the {solver} solver failed at time {integrator.t:g}: {message}",
                            notes=state_notes(problem.names, np.asarray(integrator.y), None),
                            hint="try --solver radau"))
                    if steps >= limits.max_steps and integrator.t < stop:
                        raise OverLimit(f"{steps} steps of {solver} reached the step limit "
                                        f"(--max-steps {limits.max_steps})", integrator.t,
                                        np.array(integrator.y), solver)
                    dense = integrator.dense_output()
                    for t in np.linspace(before, integrator.t, SAMPLES + 1)[1:]:
                        history.record(float(t), np.asarray(dense(t)), z)
                    while k < len(grid) and grid[k] <= integrator.t:
                        x = np.asarray(dense(grid[k])) if grid[k] < integrator.t \
                            else np.asarray(integrator.y)
                        history.fill(float(grid[k]), x, z)
                        states[k], zs[k] = x, z
                        k += 1
                    if integrator.status == "finished":
                        break
            for j in range(k, len(grid)):  # no states: the history is the start value
                history.fill(float(grid[j]), x0, z)
                states[j], zs[j] = x0, z
            if problem.asserts:
                for j, t in enumerate(grid):
                    if j == 0:
                        problem.asserts.start(float(t), states[j], zs[j])
                    else:
                        problem.asserts.step(float(t), states[j], zs[j])
            outputs = _outputs(model, problem, grid, states, zs)
    except Stop as stop_:
        raise stop_.error from None
    finally:
        progress.close()
    stats = SimulationStats(solver, steps, problem.nfev, problem.njev,
                            time.perf_counter() - plan.began, problem.model_time,
                            model.compile_time, model.cached, reason)
    names = model.outputs
    units = model.units
    return SimulationResult(model.name, grid, names, outputs,
                            tuple(units.get(n, "") for n in names), stats,
                            dict(zip(model.parameter_names, p.tolist())))


def _outputs(model: CompiledModel, problem: Problem, grid: np.ndarray, states: np.ndarray,
             zs: np.ndarray) -> np.ndarray:
    """The selected outputs at every row, each with its delayed values."""
    columns: dict[str, np.ndarray] = {s: states[:, i] for i, s in enumerate(model.states)}
    if model.observed:
        obs = observed_at_rows(model.module, problem, grid, states, zs)
        columns.update({o: obs[:, i] for i, o in enumerate(model.observed)})
    return np.column_stack([columns[name] for name in model.outputs]) if model.outputs \
        else np.empty((len(grid), 0))
