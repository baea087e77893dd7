"""Simulate a model whose states must change during the run: CompiledModel -> result.

Index reduction may leave a choice of states that becomes singular somewhere (a rod
passing vertical, see :mod:`springc.simplify.state_choice`). Such models are marked
``SWITCHABLE`` when generated; :func:`simulate_switching_model` runs them through
:func:`simulate_switching`, a reference driver on scipy's ``solve_ivp`` that
evaluates the simplified system with the reference evaluator (slower than generated
code, but these index-3 scenes are small) and reports each switch in the summary:

- a terminal event on ``conditioning - threshold`` (:func:`conditioning_event`)
  stops the integration before the singularity;
- the states are reselected there (:func:`springc.simplify.switch`) and the run
  restarts at the same time from the values there, which satisfy every constraint.

Where every block that may turn singular carries its run-time check
(:func:`springc.simplify.pivot_checks`: one-equation blocks, a free body's quaternion
constraint), :func:`simulate_switching_model` first runs the generated code with the
states chosen at compile time, as the continuous driver does; the result stands when
no check fails (no switch was needed), else the run starts again here.

The ODE's functions come from a callback (``make_functions``), by default the
reference evaluator (:class:`EvaluatorFunctions`), so that generated code can be
used instead.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Protocol

import numpy as np

from ..errors import SimulationError
from ..ir import flat
from ..pipeline import CompiledModel, ModuleKind
from ..simplify import (
    CHECK_DETAIL,
    CHECK_MESSAGE,
    THRESHOLD,
    OdeEvaluator,
    StateChoice,
    conditioning,
    initial_state,
    needs_switch,
    parameter_values,
    select_states,
    state_vector,
    switch,
)
from .assertions import check_trajectory
from .compiled import COMPILED
from .limits import Limits, OverLimit, check_outputs, over_limit
from .planning import RunPlan
from .results import SimulationResult, SimulationStats
from .solver_names import AUTO, EXPLICIT, SOLVERS
from .stiffness import numerical_jacobian

MAX_SWITCHES = 10_000


class Functions(Protocol):
    """What the driver needs of a compiled ODE."""

    def rhs(self, t: float, states: np.ndarray) -> np.ndarray:
        """The state derivatives."""
        ...

    def values(self, t: float, states: np.ndarray) -> dict[str, float]:
        """Every parameter, state, computed variable and alias, by name."""
        ...


MakeFunctions = Callable[[StateChoice, Mapping[str, float], Mapping[str, float]], Functions]
"""``make_functions(choice, parameters, guess)``: the functions of ``choice.ode``;
``guess`` (current values, by name) seeds the Newton iterations of torn blocks."""


class EvaluatorFunctions:
    """:class:`Functions` by the reference evaluator (:class:`springc.simplify.OdeEvaluator`)."""

    def __init__(self, choice: StateChoice, parameters: Mapping[str, float],
                 guess: Mapping[str, float]) -> None:
        self.evaluator = OdeEvaluator(choice.ode, parameters, guess=guess)

    def rhs(self, t: float, states: np.ndarray) -> np.ndarray:
        return self.evaluator.rhs(t, states)

    def values(self, t: float, states: np.ndarray) -> dict[str, float]:
        env = self.evaluator.values(t, states)
        env.update(self.evaluator.observed(env, t))
        return env


@dataclass(frozen=True)
class Switch:
    """At ``time`` the states changed from ``old_states`` to ``new_states``;
    ``conditioning`` is that of the old choice there."""

    time: float
    old_states: tuple[str, ...]
    new_states: tuple[str, ...]
    conditioning: float


@dataclass(frozen=True)
class SwitchingResult:
    """``values[name][k]``: every continuous and discrete variable of the flat model at
    ``t[k]``; the integrator's accepted steps and its RHS and Jacobian evaluations, over all
    segments."""

    t: np.ndarray
    values: dict[str, np.ndarray]
    switches: tuple[Switch, ...]
    steps: int = 0
    rhs_evaluations: int = 0
    jacobian_evaluations: int = 0


@dataclass
class _Counts:
    """The steps of every solver of a run, and the solvers (their ``nfev``, ``njev``)."""

    steps: int = 0
    solvers: list[object] = field(default_factory=list)

    def evaluations(self) -> tuple[int, int]:
        return (sum(int(getattr(s, "nfev", 0)) for s in self.solvers),
                sum(int(getattr(s, "njev", 0)) for s in self.solvers))


def _counted(method: str, counts: _Counts) -> type:
    """``scipy.integrate``'s solver class ``method``, counting its accepted steps and
    keeping its instances in ``counts`` (``solve_ivp`` reports no step count)."""
    import scipy.integrate

    base = getattr(scipy.integrate, method)

    class Counted(base):  # type: ignore[misc, valid-type]
        def __init__(self, *args: object, **kwargs: object) -> None:
            super().__init__(*args, **kwargs)
            counts.solvers.append(self)

        def step(self) -> str | None:
            before = self.t
            message: str | None = super().step()
            if self.status != "failed" and self.n and self.t != before:
                counts.steps += 1
            return message

    return Counted


def simulate_switching(model: flat.FlatModel, t_span: tuple[float, float],
                       t_eval: Sequence[float] | np.ndarray | None = None,
                       rtol: float = 1e-6, atol: float = 1e-8, method: str = "DOP853",
                       parameters: Mapping[str, float] | None = None,
                       make_functions: MakeFunctions = EvaluatorFunctions,
                       threshold: float = THRESHOLD, time_limit: float = math.inf
                       ) -> SwitchingResult:
    """Simulate ``model`` over ``t_span`` with dynamic state selection.

    Starts with the default choice of states and consistent initial values
    (:func:`springc.simplify.initial_state`; reselected at once if that choice is
    badly conditioned there), integrates with ``solve_ivp(method=...)`` until the
    conditioning event, switches (:func:`switch`), and restarts at the event time from
    the values there. Output at ``t_eval`` (default: every accepted step).
    Raises :class:`SimulationError` when the integrator fails, a switch does not
    improve the conditioning, or the run takes over ``time_limit`` seconds (the error
    names the time reached and the stiffness there, from a difference Jacobian).
    """
    from scipy.integrate import solve_ivp

    deadline = time.perf_counter() + time_limit
    counts = _Counts()
    name = method
    method = _counted(method, counts)  # type: ignore[assignment]

    t0, t1 = float(t_span[0]), float(t_span[1])
    choice = select_states(model)
    params = parameter_values(choice.ode.parameters, parameters)
    x0, info = initial_state(choice.ode, parameters, t0)
    values: dict[str, float] = {**info.values, **info.observed}
    switches: list[Switch] = []
    if needs_switch(choice, values, threshold, t0):
        choice = _switch(model, choice, values, t0, threshold, switches)
        x0 = state_vector(choice, values)
    # The flat model's unknowns, then every choice's states that are no flat variable:
    # a derivative that index reduction made a state (``der(x)`` where ``v = der(x)``
    # has ``v`` avoided), computed by every choice (a state, or a dummy derivative).
    names = [v.name for v in model.variables if v.is_unknown]
    times: list[float] = []
    rows: list[dict[str, float]] = []
    requested = None if t_eval is None else np.asarray(t_eval, dtype=float)
    t, state = t0, x0
    while True:
        names += [s.name for s in choice.ode.states if s.name not in names]
        functions = make_functions(choice, params, values)
        event = conditioning_event(choice, functions, threshold)
        segment = None
        if requested is not None:
            later = (requested >= t) & (requested > times[-1] if times else True)
            segment = requested[later & (requested <= t1)]
        rhs = _RejectingRhs(functions, deadline, time_limit, name.lower())
        try:
            with np.errstate(all="ignore"):  # a run that overflows fails with a message
                sol = solve_ivp(rhs, (t, t1), state, method=method, t_eval=segment, rtol=rtol,
                                atol=atol, events=event if choice.blocks else None)
        except OverLimit as over:
            raise over_limit(over, t0, t1, partial(numerical_jacobian, functions.rhs)
                             ) from None
        if sol.status == -1:
            cause = f" (last failure: {rhs.failure})" if rhs.failure else ""
            reached = sol.t[-1] if len(sol.t) else rhs.time  # no output time reached
            raise SimulationError(f"the integration failed at t = {reached:g}: "
                                  f"{sol.message}{cause}")
        # Outputs in time order from the segment's start values: each Newton guess is
        # the previous output's solution, never one from the segment's end.
        output = make_functions(choice, params, values)
        skip_first = requested is None and bool(times)
        for k, tk in enumerate(sol.t):
            if skip_first and k == 0:
                continue
            times.append(float(tk))
            rows.append(output.values(float(tk), sol.y[:, k]))
        if sol.status == 0:
            break
        t = float(sol.t_events[0][0])
        values = functions.values(t, sol.y_events[0][0])
        if len(switches) >= MAX_SWITCHES:
            raise SimulationError(f"more than {MAX_SWITCHES} switches of states by "
                                  f"t = {t:g}")
        choice = _switch(model, choice, values, t, threshold, switches)
        state = state_vector(choice, values)
    out = {n: np.array([r.get(n, np.nan) for r in rows]) for n in names}
    return SwitchingResult(np.array(times), out, tuple(switches), counts.steps,
                           *counts.evaluations())


class _RejectingRhs:
    """``functions.rhs`` returning NaN where the steps fail (e.g. Newton diverges on a
    trial stage that went past a singularity): solve_ivp's methods then reject the
    step and retry a smaller one, so the conditioning event gets its chance."""

    def __init__(self, functions: Functions, deadline: float = math.inf,
                 time_limit: float = math.inf, solver: str = "") -> None:
        self.functions = functions
        self.failure: SimulationError | None = None
        self.deadline, self.time_limit, self.solver = deadline, time_limit, solver
        self.time = -math.inf  # the last time the right-hand side was asked for

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        self.time = t
        if time.perf_counter() > self.deadline:
            raise OverLimit(f"{self.time_limit:g} s of wall clock reached the time limit "
                            "(--time-limit)", t, np.array(y), self.solver)
        try:
            return self.functions.rhs(t, y)
        except SimulationError as err:
            self.failure = err
            return np.full(len(y), np.nan)


def conditioning_event(choice: StateChoice, functions: Functions,
                       threshold: float = THRESHOLD) -> Callable[[float, np.ndarray], float]:
    """A terminal ``solve_ivp`` event: ``conditioning - threshold`` crossing downwards."""

    def event(time: float, y: np.ndarray) -> float:
        return conditioning(choice, functions.values(time, y), time) - threshold

    event.terminal = True  # type: ignore[attr-defined]
    event.direction = -1  # type: ignore[attr-defined]
    return event


def _switch(model: flat.FlatModel, old: StateChoice, values: Mapping[str, float],
            t: float, threshold: float, switches: list[Switch]) -> StateChoice:
    """Reselect at ``values``; the new choice must be better conditioned there."""
    before = conditioning(old, values, t)
    new = switch(model, values)
    if new.states == old.states or conditioning(new, values, t) < threshold:
        raise SimulationError(
            f"dynamic state selection found no well-conditioned choice of states at "
            f"t = {t:g} (states {', '.join(old.states)}; conditioning {before:.3g})")
    switches.append(Switch(t, old.states, new.states, before))
    return new


def _column(run: SwitchingResult, name: str) -> np.ndarray:
    """The trajectory of the output ``name`` (a variable the run did not compute is a
    bug of springc, named, not a ``KeyError``)."""
    if name in run.values:
        return run.values[name]
    raise RuntimeError(f"the run with dynamic state selection computed no value of the "
                       f"output '{name}' (a bug in springc)")


def simulate_switching_model(model: CompiledModel, plan: RunPlan) -> SimulationResult:
    """Run ``model`` as ``plan`` says with dynamic state selection (adaptive solvers
    only; on scipy's loop, the only one that switches states)."""
    settings = plan.settings
    checked = _checked_run(model, plan)
    if checked is not None:
        return checked
    if settings.engine == COMPILED:
        raise SimulationError(f"{model.name} may switch its states during the run "
                              "(dynamic state selection), which only the scipy engine "
                              "does", hint="use --engine scipy (or auto)")
    if plan.starts:
        raise SimulationError(f"{model.name} may switch its states during the run "
                              f"(dynamic state selection): the start of "
                              f"'{min(plan.starts)}' cannot be set from outside",
                              hint="set it in the model (start = ...)")
    began = time.perf_counter()
    result = _switching_run(model, plan.solver, plan.grid, plan.rtol, plan.atol,
                            plan.parameters, plan.limits, began)
    if settings.engine.lower() == AUTO:
        result.stats = replace(result.stats, engine_reason=(
            f"{result.stats.solver} ran in scipy's loop, the only one that switches "
            "states"))
    return result


def _checked_run(model: CompiledModel, plan: RunPlan) -> SimulationResult | None:
    """The run of the states chosen at compile time on the generated code, where every
    block that may turn singular has its run-time check
    (:func:`springc.simplify.pivot_checks`) and no check fails; None otherwise (a
    check failed: the run must switch states)."""
    system = model.closed_system().system
    if not any(a.origin.detail == CHECK_DETAIL for a in system.assertions):
        return None
    from .continuous import simulate_continuous  # the continuous driver's module
    from .planning import initial_state

    x0 = initial_state(model, plan.p, plan.start, plan.starts)
    try:
        result = simulate_continuous(model, replace(plan, x0=x0,
                                                    driver=ModuleKind.CONTINUOUS))
    except SimulationError as err:
        if CHECK_MESSAGE in str(err):
            return None
        raise
    result.stats = replace(result.stats, engine_reason=(
        f"{result.stats.engine_reason + '; ' if result.stats.engine_reason else ''}"
        "the states chosen at compile time stayed well conditioned (checked at every "
        "step): no switch of states"))
    return result


def _switching_run(model: CompiledModel, solver: str, grid: np.ndarray, rtol: float,
                   atol: float, parameters: dict[str, float], limits: Limits,
                   began: float) -> SimulationResult:
    method = solver if solver in SOLVERS else EXPLICIT
    closed = model.closed_system()  # captured at compile time: never the files again
    flat_model = closed.flat_model
    if flat_model is None:
        raise RuntimeError(f"the compiled model {model.name} holds no flat model for its "
                           "state selection (a bug in springc)")
    run = simulate_switching(flat_model, (float(grid[0]), float(grid[-1])), t_eval=grid,
                             rtol=rtol, atol=atol, method=SOLVERS[method],
                             parameters=parameters,
                             time_limit=limits.time_limit)
    if flat_model.assertions:
        known = parameter_values(closed.system.parameters, parameters)
        check_trajectory(flat_model.assertions, np.asarray(grid, dtype=float), run.values,
                         known)
    values = np.column_stack([_column(run, name) for name in model.outputs])
    check_outputs(model.outputs, np.asarray(grid, dtype=float), values)
    units = tuple(str(u) for u in getattr(model.module, "OBSERVED_UNITS", ()))
    unit_of = dict(zip(model.states, getattr(model.module, "STATE_UNITS", ())))
    unit_of.update(zip(model.observed, units))
    switches = ", ".join(f"t = {s.time:.6g}" for s in run.switches)
    reason = (f"dynamic state selection, {len(run.switches)} switch"
              f"{'es' if len(run.switches) != 1 else ''} ({switches})" if switches else
              "dynamic state selection, no switch in this run")
    stats = SimulationStats(method, run.steps, run.rhs_evaluations, run.jacobian_evaluations,
                            time.perf_counter() - began, 0.0, model.compile_time,
                            model.cached, reason)
    return SimulationResult(model.name, np.asarray(grid, dtype=float), model.outputs,
                            values, tuple(unit_of.get(n, "") for n in model.outputs),
                            stats, dict(parameters))
