"""Dynamic state selection: flat.FlatModel + current values -> a new ODE and its states.

Index reduction (:mod:`springc.reduce`) turns some derivatives into algebraic *dummy*
derivatives; the choice is valid while the Jacobian blocks it solves stay regular.
For a rod between two masses the coordinate solved from ``|p2 - p1| = l`` can be
``p2.x`` only while the rod is not vertical: any static choice fails somewhere.
Modelica tools then switch states during the simulation; this module does it:

1. :func:`select_states` simplifies the model, by default as ``simplify`` does, or
   with ``at=values`` for the best-conditioned choice at those values, and wraps the
   ODE with what the monitor needs (:class:`StateChoice`).
2. :func:`conditioning` measures the current choice at given values: for each
   dummy-derivative block with alternatives, the smallest singular value of the
   Jacobian block of the current dummies divided by that of the best choice at these
   values (:func:`springc.reduce.pivoted_choice`); the minimum over blocks. It is
   about 1 right after a (re)selection and falls to 0 at the singularity.
   :func:`needs_switch` compares it with a threshold (:data:`THRESHOLD`).
3. :func:`switch` reselects at the current values and :func:`state_vector` maps the
   values (which satisfy all constraints, since the old ODE solved them) onto the new
   states: the restart is consistent without any projection.
4. :func:`simulate_switching` is a reference driver on scipy's ``solve_ivp``: a
   terminal event on ``conditioning - threshold`` stops the integration before the
   singularity; it switches and restarts at the same time. The ODE's functions come
   from a callback (``make_functions``), by default the reference evaluator, so that
   generated code can be used instead.

Hysteresis: the new choice has conditioning about 1 (it is the best one) and the
threshold is well below the ratio at which :func:`~springc.reduce.pivoted_choice`
prefers another choice, so a switch never triggers another at once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import SimulationError
from ..ir import expr as x
from ..ir import flat, ode
from .index_reduction import DummyBlock, pivoted_choice
from .initialize import initial_state
from .isolate import free_variables, partial
from .ode_eval import Evaluator, parameter_values
from .passes import simplify

THRESHOLD = 0.2
"""Switch when the current choice is this much worse conditioned than the best one."""
MAX_SWITCHES = 10_000


@dataclass(frozen=True)
class MonitoredBlock:
    """A dummy-derivative block prepared for :func:`conditioning`: ``entries`` are
    the non-zero ``(row, candidate, d(equation)/d(candidate))``; ``chosen`` the
    candidate positions of the current dummies."""

    size: int
    candidates: tuple[str, ...]
    tiers: tuple[int, ...]
    entries: tuple[tuple[int, int, x.Expr], ...]
    chosen: tuple[int, ...]


@dataclass(frozen=True)
class StateChoice:
    """An ODE together with the blocks its choice of states relies on."""

    ode: ode.ODE
    blocks: tuple[MonitoredBlock, ...]

    @property
    def states(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.ode.states)


def select_states(model: flat.FlatModel, at: Mapping[str, float] | None = None
                  ) -> StateChoice:
    """``simplify(model, at)`` with the monitor data of its dummy-derivative blocks."""
    simplified = simplify(model, at)
    return StateChoice(simplified.ode, tuple(_monitored(b) for b in simplified.blocks
                                             if len(b.candidates) > len(b.dummies)))


def _monitored(block: DummyBlock) -> MonitoredBlock:
    entries = []
    for i, e in enumerate(block.equations):
        present = free_variables(e)
        for j, name in enumerate(block.candidates):
            if name in present:
                d = partial(e, name)
                if d != x.ZERO:
                    entries.append((i, j, d))
    position = {name: j for j, name in enumerate(block.candidates)}
    return MonitoredBlock(len(block.equations), block.candidates, block.tiers,
                          tuple(entries), tuple(position[d] for d in block.dummies))


def conditioning(choice: StateChoice, values: Mapping[str, float], time: float = 0.0
                 ) -> float:
    """How well the current states suit ``values`` (see step 2 of the module
    docstring): 1 for the best choice, towards 0 near its singularity; 1 when there is
    nothing to choose. ``values`` must hold the variables the ODE's steps compute
    (e.g. :meth:`Evaluator.values`); names missing from it count as 0."""
    worst = 1.0
    for block in choice.blocks:
        jac = np.zeros((block.size, len(block.candidates)))
        for i, j, e in block.entries:
            jac[i, j] = _evaluate(e, values, time)
        if not np.all(np.isfinite(jac)):
            return 0.0
        best = pivoted_choice(jac, block.tiers)
        if best is None:
            return 0.0
        reference = _smallest_singular_value(jac[:, best])
        if reference > 0.0:
            current = _smallest_singular_value(jac[:, list(block.chosen)])
            worst = min(worst, current / reference)
    return worst


def needs_switch(choice: StateChoice, values: Mapping[str, float],
                 threshold: float = THRESHOLD, time: float = 0.0) -> bool:
    """Is the current choice of states too badly conditioned at ``values``?"""
    return conditioning(choice, values, time) < threshold


def switch(model: flat.FlatModel, values: Mapping[str, float]) -> StateChoice:
    """The best-conditioned choice of states at ``values`` (use with :func:`state_vector`)."""
    return select_states(model, at=values)


def state_vector(choice: StateChoice, values: Mapping[str, float]) -> np.ndarray:
    """The values of ``choice``'s states, in the order of ``choice.ode.states``."""
    return np.array([float(values[s.name]) for s in choice.ode.states])


def _evaluate(e: x.Expr, values: Mapping[str, float], time: float) -> float:
    try:
        return float(x.evaluate(e, values, time))  # type: ignore[arg-type]
    except KeyError:
        return float(x.evaluate(e, _Defaulting(values), time))  # type: ignore[arg-type]


class _Defaulting(dict):  # type: ignore[type-arg]
    def __missing__(self, key: str) -> float:
        return 0.0


def _smallest_singular_value(a: np.ndarray) -> float:
    if a.shape == (1, 1):
        return abs(float(a[0, 0]))
    return float(np.linalg.svd(a, compute_uv=False)[-1])


# The reference driver.


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
    """:class:`Functions` by the reference evaluator (:mod:`springc.evaluate_ode`)."""

    def __init__(self, choice: StateChoice, parameters: Mapping[str, float],
                 guess: Mapping[str, float]) -> None:
        self.evaluator = Evaluator(choice.ode, parameters, guess=guess)

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
    """``values[name][k]``: every continuous variable of the flat model at ``t[k]``."""

    t: np.ndarray
    values: dict[str, np.ndarray]
    switches: tuple[Switch, ...]


def simulate_switching(model: flat.FlatModel, t_span: tuple[float, float],
                       t_eval: Sequence[float] | np.ndarray | None = None,
                       rtol: float = 1e-6, atol: float = 1e-8, method: str = "DOP853",
                       parameters: Mapping[str, float] | None = None,
                       make_functions: MakeFunctions = EvaluatorFunctions,
                       threshold: float = THRESHOLD) -> SwitchingResult:
    """Simulate ``model`` over ``t_span`` with dynamic state selection.

    Starts with the default choice of states and consistent initial values
    (:func:`springc.initialize.initial_state`; reselected at once if that choice is
    badly conditioned there), integrates with ``solve_ivp(method=...)`` until the
    conditioning event, switches (:func:`switch`), and restarts at the event time from
    the values there. Output at ``t_eval`` (default: every accepted step).
    Raises :class:`SimulationError` when the integrator fails or a switch does not
    improve the conditioning.
    """
    from scipy.integrate import solve_ivp

    t0, t1 = float(t_span[0]), float(t_span[1])
    choice = select_states(model)
    params = parameter_values(choice.ode.parameters, parameters)
    x0, info = initial_state(choice.ode, parameters, t0)
    values: dict[str, float] = {**info.values, **info.observed}
    switches: list[Switch] = []
    if needs_switch(choice, values, threshold, t0):
        choice = _switch(model, choice, values, t0, threshold, switches)
        x0 = state_vector(choice, values)
    names = [v.name for v in model.variables if v.variability == "continuous"]
    times: list[float] = []
    rows: list[dict[str, float]] = []
    requested = None if t_eval is None else np.asarray(t_eval, dtype=float)
    t, state = t0, x0
    while True:
        functions = make_functions(choice, params, values)
        event = conditioning_event(choice, functions, threshold)
        segment = None
        if requested is not None:
            later = (requested >= t) & (requested > times[-1] if times else True)
            segment = requested[later & (requested <= t1)]
        rhs = _RejectingRhs(functions)
        sol = solve_ivp(rhs, (t, t1), state, method=method, t_eval=segment,
                        rtol=rtol, atol=atol, events=event if choice.blocks else None)
        if sol.status == -1:
            cause = f" (last failure: {rhs.failure})" if rhs.failure else ""
            raise SimulationError(f"the integration failed at t = {sol.t[-1]:g}: "
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
    return SwitchingResult(np.array(times), out, tuple(switches))


class _RejectingRhs:
    """``functions.rhs`` returning NaN where the steps fail (e.g. Newton diverges on a
    trial stage that went past a singularity): solve_ivp's methods then reject the
    step and retry a smaller one, so the conditioning event gets its chance."""

    def __init__(self, functions: Functions) -> None:
        self.functions = functions
        self.failure: SimulationError | None = None

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
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
