"""``--solver auto``: explicit first, and a short race where the run proves long.

1. ``dop853`` takes :data:`EXPLICIT_PROBE` steps. If it finishes, or its current step
   size leaves at most :data:`CHEAP_STEPS` steps to go, it finishes the run: a short
   run costs no stiffness estimate at all.
2. Otherwise the stiffness estimate of :func:`springc.simulation.solvers.choose` (``rho * T``
   from the analytic Jacobian at the current state) decides whether ``radau`` could
   be cheaper. If not, ``dop853`` goes on.
3. If it could, the estimate alone cannot tell: a very stiff spring whose fast mode
   stays at rest costs ``dop853`` nothing, an excited one must be resolved by every
   method, and a ``radau`` step costs several ``dop853`` steps. So ``radau`` takes
   :data:`IMPLICIT_PROBE` steps from the start (fewer if they cost over
   :data:`PROBE_BUDGET` of ``dop853``'s projected time), each method's remaining cost is
   projected from its last step sizes and its measured time per step, and the
   cheaper one finishes the run from where its probe left off. (``radau`` starts
   afresh rather than from ``dop853``'s state: a state reached at the stability
   limit carries fast-mode noise that would hold ``radau``'s first steps small.)

On the compiled engine steps are cheap and each call of a compiled loop has a fixed
cost (some 50 microseconds, tens of steps of a small model): the explicit probe is
:data:`COMPILED_PROBE` steps (:data:`CHEAP_STEPS` more for a model of over
:data:`SPRINT_STATES` states, whose estimate is dearer than compiled steps), and the
race is :func:`_compiled_race`: step counts far apart decide alone, each method's time
per step is the difference of two calls (the fixed cost cancels), and ``radau`` may
run up to :data:`COMPILED_BUDGET` of ``dop853``'s projected time, since its early
projection can be far too dear.

The probes are steps of the real run (the grid points they pass are kept), so
deciding costs at most the two probes. On scipy's loop the projection is taken early,
so it sees ``radau`` at its worst when a fast mode is excited above the tolerance (it
must resolve the first oscillations before its damping removes them): the race then
keeps ``dop853``, which resolves that vibration instead of damping it away. A failure
inside the explicit probe (an overflow from an unstable step) hands the run to
``radau``; if ``radau`` fails too, the explicit probe's error is reported (where the
trouble began) with ``radau``'s as a note. Failures after the decision are the run's
own.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from .solver_names import EXPLICIT, RACE, RACE_IMPLICIT
from .solvers import AutoChoice

EXPLICIT_PROBE = 40
IMPLICIT_PROBE = 20
PROBE_BUDGET = 0.05
"""The implicit probe stops early once it has cost this fraction of the explicit
method's projected remaining time (a large scene's radau steps are dear)."""
CHEAP_STEPS = 500
"""Explicit steps to go below which no estimate or implicit probe is worth its cost
(about what ``rho * T <= 2000`` allows a stability-limited explicit method)."""
COMPILED_PROBE = 10
SPRINT_STATES = 32
"""On the compiled engine, models of more states take :data:`CHEAP_STEPS` more explicit
steps before an estimate (dense eigenvalues of 32 states take about 0.1 ms, of 400
some 40 ms: as long as hundreds of compiled steps)."""
STEP_COST = 20.0
"""A ``radau`` step of a model of at most :data:`SPRINT_STATES` states costs under this
many ``dop853`` steps (a few Newton iterations of 3 evaluations of the model and a
dense LU of at most 32 unknowns, against 12 evaluations): where ``dop853`` projects
more times ``radau``'s steps, the counts decide the compiled race alone."""
COMPILED_STRETCHES: dict[str, tuple[int, int]] = {EXPLICIT: (20, 200),
                                                 RACE_IMPLICIT: (16, 64)}
"""The steps of each method's first two timed calls in a compiled race (a call right
after other work runs cold and is not compared with later ones: neither probe is
timed); ``radau``'s later stretches are four times longer each."""
COMPILED_BUDGET = 0.2
"""The compiled race lets ``radau`` run up to this fraction of ``dop853``'s projected
time (stretches four times longer each): an excited fast mode holds ``radau``'s first
steps small until its damping removes it, so its early projection can be far too
dear (the uneven pair at k = 1e8 over 10 s: 0.5 s projected, 11 ms taken), and
``dop853``'s, from its first steps, is too (0.29 s projected, 0.107 s taken). A
``radau`` run costing under a fifth of ``dop853``'s projection is found; where
``dop853`` wins, the race costs it at most a fifth more (over 1 s, where ``dop853``
takes 10 ms and ``radau`` 12 ms, auto takes 15 ms)."""


class Stretch(Protocol):
    """What one stretch of steps measured (``springc.simulation.steps.Stretch``)."""

    @property
    def steps(self) -> int: ...

    @property
    def seconds(self) -> float: ...

    @property
    def sizes(self) -> tuple[float, ...]: ...


class Run(Protocol):
    """The simulation's step loop (``springc.simulation.steps.StepLoop``)."""

    @property
    def failure(self) -> type[Exception]: ...

    @property
    def done(self) -> bool: ...

    @property
    def compiled(self) -> bool: ...

    def start(self, solver: str, t: float, y: np.ndarray,
              first_step: float | None = None) -> Any: ...

    def advance(self, integrator: Any, max_steps: int | None = None) -> Stretch: ...

    def both_failed(self, first: Any, second: Any) -> Exception: ...

    def factorization_seconds(self) -> float: ...


@dataclass(frozen=True)
class Probe:
    """What a probe measured: the step size its method settled on (0 where it accepted
    none) and the seconds per step of stepping."""

    step: float
    per_step: float

    def cost(self, span: float) -> float:
        """Projected seconds for ``span`` at that step size and time per step."""
        return _steps(span, self.step) * self.per_step


def auto(run: Run, t0: float, x0: np.ndarray, stop: float,
         estimate: Callable[[float, np.ndarray], AutoChoice]) -> tuple[str, str]:
    """Integrate ``run`` to the end; the solver that finished and why.

    ``estimate(t, x)`` is the stiffness estimate at a state (only called for long runs).
    """
    explicit = run.start(EXPLICIT, t0, x0)
    first = EXPLICIT_PROBE
    if run.compiled:
        first = COMPILED_PROBE + (CHEAP_STEPS if len(x0) > SPRINT_STATES else 0)
    try:
        probe = run.advance(explicit, first)
    except run.failure as failure:
        implicit = run.start(RACE_IMPLICIT, float(explicit.t), np.array(explicit.y))
        try:
            run.advance(implicit)
        except run.failure as again:
            raise run.both_failed(failure, again) from None
        return RACE_IMPLICIT, f"{EXPLICIT} failed in its first steps ({failure})"
    if run.done:
        return EXPLICIT, f"non-stiff: {EXPLICIT} finished in {probe.steps} steps"
    left = _steps(stop - explicit.t, _step(probe))
    if left <= CHEAP_STEPS:
        run.advance(explicit)
        return EXPLICIT, f"non-stiff: {EXPLICIT} needs ~{left:.2g} more steps"
    choice = estimate(float(explicit.t), np.array(explicit.y))
    if choice.solver == RACE:
        return _race(run, explicit, probe, t0, x0, stop, choice.reason)
    if choice.solver == RACE_IMPLICIT:
        explicit = run.start(RACE_IMPLICIT, float(explicit.t), np.array(explicit.y))
    run.advance(explicit)
    return choice.solver, choice.reason


def _race(run: Run, explicit: Any, first: Stretch, t0: float, x0: np.ndarray, stop: float,
          stiffness: str) -> tuple[str, str]:
    if run.compiled:
        return _compiled_race(run, explicit, first, t0, x0, stop, stiffness)
    explicit_cost = Probe(_step(first), _mean(first)).cost(stop - explicit.t)
    implicit = run.start(RACE_IMPLICIT, t0, x0)
    trial = _scipy_implicit_probe(run, implicit, explicit_cost)
    if run.done:
        return RACE_IMPLICIT, f"{stiffness}; {RACE_IMPLICIT} finished the run in its trial steps"
    implicit_cost = trial.cost(stop - implicit.t)
    return _finish(run, explicit, implicit, implicit_cost <= explicit_cost, stiffness,
                   f"~{implicit_cost:.2g} s to go, {EXPLICIT} ~{explicit_cost:.2g} s")


def _compiled_race(run: Run, explicit: Any, first: Stretch, t0: float, x0: np.ndarray,
                   stop: float, stiffness: str) -> tuple[str, str]:
    """The race on the compiled engine. Where one factorization of ``radau``'s Newton
    matrices (predicted from their band) would cost over :data:`COMPILED_BUDGET` of
    ``dop853``'s projected time, ``dop853`` goes on. Else ``radau`` takes
    :data:`IMPLICIT_PROBE` steps from the start (4 for a model of over
    :data:`SPRINT_STATES` states, whose steps are dear); where the step counts alone
    decide (:data:`STEP_COST`) nothing is timed.
    Otherwise ``dop853`` is timed, and ``radau`` runs stretches (16, 64, then four times
    longer each, within what is left of :data:`COMPILED_BUDGET` of ``dop853``'s
    projected time) until its projection beats ``dop853``'s or the budget is spent."""
    small = len(x0) <= SPRINT_STATES
    explicit_steps = _steps(stop - explicit.t, _step(first))
    # (an upper bound: the first call's fixed cost counted as stepping)
    explicit_cost = explicit_steps * _mean(first)
    factorization = run.factorization_seconds()
    if factorization > COMPILED_BUDGET * explicit_cost:
        run.advance(explicit)
        return EXPLICIT, (f"{stiffness}, but one factorization of {RACE_IMPLICIT}'s Newton "
                          f"matrices takes over {factorization:.2g} s, {EXPLICIT} "
                          f"~{explicit_cost:.2g} s to go")
    implicit = run.start(RACE_IMPLICIT, t0, x0)
    done = [run.advance(implicit, IMPLICIT_PROBE if small else 4)]  # (untimed: cold)
    if run.done:
        return RACE_IMPLICIT, f"{stiffness}; {RACE_IMPLICIT} finished the run in its trial steps"
    implicit_steps = _steps(stop - implicit.t, _step(done[-1]))
    if small and explicit_steps >= STEP_COST * implicit_steps:
        return _finish(run, explicit, implicit, True, stiffness,
                       f"~{implicit_steps:.2g} steps to go, {EXPLICIT} ~{explicit_steps:.2g}")
    probe = _timed(run, explicit, COMPILED_STRETCHES[EXPLICIT])
    if run.done:
        return EXPLICIT, f"{stiffness}; {EXPLICIT} finished the run in its trial steps"
    explicit_cost = probe.cost(stop - explicit.t)
    steps = float(COMPILED_STRETCHES[RACE_IMPLICIT][0])
    while True:
        last = done[-1]
        # (two timed stretches: their difference; before, the last one's mean, an upper
        # bound with the call's fixed cost in it)
        per_step = _per_step(done[-2], last) if len(done) >= 3 else _mean(last)
        implicit_cost = Probe(_step(last), per_step).cost(stop - implicit.t)
        steps = min(steps, (COMPILED_BUDGET * explicit_cost - sum(s.seconds for s in done))
                    / per_step)
        if implicit_cost <= explicit_cost or steps < 1:
            return _finish(run, explicit, implicit, implicit_cost <= explicit_cost, stiffness,
                           f"~{implicit_cost:.2g} s to go, {EXPLICIT} ~{explicit_cost:.2g} s")
        done.append(run.advance(implicit, int(steps)))
        if run.done:
            return RACE_IMPLICIT, (f"{stiffness}; {RACE_IMPLICIT} finished the run in its "
                                   "trial steps")
        steps = 4.0 * done[-1].steps


def _finish(run: Run, explicit: Any, implicit: Any, implicit_wins: bool, stiffness: str,
            measured: str) -> tuple[str, str]:
    """The race's winner runs to the end; the reason names what was measured."""
    measured = f"measured: {RACE_IMPLICIT} {measured}"
    if implicit_wins:
        run.advance(implicit)
        return RACE_IMPLICIT, f"{stiffness}; {measured}"
    run.advance(explicit)
    return EXPLICIT, f"{stiffness}, but the fast modes must be resolved anyway; {measured}"


def _timed(run: Run, integrator: Any, stretches: tuple[int, int]) -> Probe:
    """Two compiled stretches of ``stretches`` steps (fewer if the run ends): the time
    per step from their difference (see :func:`_per_step`), the step size the second
    settled on."""
    done = [run.advance(integrator, stretches[0])]
    if not run.done:
        done.append(run.advance(integrator, stretches[1]))
    return Probe(_step(done[-1]), _per_step(done[0], done[-1]))


def _per_step(before: Stretch, last: Stretch) -> float:
    """Seconds per step: the difference of two stretches of a method over their
    difference in steps (each call's fixed cost cancels), or the last one's mean where
    that is not positive (or the two are one)."""
    if last is not before and last.steps != before.steps:
        difference = (last.seconds - before.seconds) / (last.steps - before.steps)
        if difference > 0:
            return difference
    return _mean(last)


def _scipy_implicit_probe(run: Run, implicit: Any, explicit_cost: float) -> Probe:
    """The implicit probe on scipy's loop: a step at a time, up to :data:`IMPLICIT_PROBE`
    or :data:`PROBE_BUDGET` of the explicit method's projected cost."""
    steps, seconds = 0, 0.0
    sizes: list[float] = []
    while steps < IMPLICIT_PROBE and seconds <= PROBE_BUDGET * explicit_cost:
        trial = run.advance(implicit, 1)
        steps, seconds = steps + trial.steps, seconds + trial.seconds
        sizes += trial.sizes
        if run.done:
            break
    return Probe(float(statistics.median(sizes[-5:])) if sizes else 0.0,
                 seconds / max(steps, 1))


def _step(stretch: Stretch) -> float:
    """The step size a method has settled on: the median of its last steps (0 where it
    accepted none)."""
    return float(statistics.median(stretch.sizes[-5:])) if stretch.sizes else 0.0


def _steps(span: float, step: float) -> float:
    """Steps of ``step`` over ``span`` (infinitely many where the step is 0)."""
    return span / step if step > 0 else math.inf


def _mean(stretch: Stretch) -> float:
    """A stretch's seconds per step, with its call's fixed cost in them."""
    return stretch.seconds / max(stretch.steps, 1)
