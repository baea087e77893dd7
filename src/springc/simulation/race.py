"""``--solver auto``: explicit first, and a short race where the run proves long,
decided by counts and a cost model fixed in the code, never by the clock.

1. ``dop853`` takes :data:`EXPLICIT_PROBE` steps on scipy's loop, :data:`COMPILED_PROBE`
   on the compiled engine (:data:`CHEAP_STEPS` more for a model of over
   :data:`SPRINT_STATES` states, whose stiffness estimate is dearer than compiled
   steps). If it finishes, or its current step size leaves at most
   :data:`CHEAP_STEPS` steps to go, it finishes the run: a short run costs no
   stiffness estimate at all.
2. Otherwise the stiffness estimate of :func:`springc.simulation.solvers.choose`
   (``rho * T`` from the analytic Jacobian at the current state) decides whether
   ``radau`` could be cheaper. If not, ``dop853`` goes on.
3. If it could, the estimate alone cannot tell: a very stiff spring whose fast mode
   stays at rest costs ``dop853`` nothing, an excited one must be resolved by every
   method, and a ``radau`` step costs several ``dop853`` steps. Each method's remaining
   work is projected as its steps to go (the span left over its settled step size)
   times its work per accepted step, in equivalent right-hand side evaluations of the
   cost model of :mod:`springc.simulation.step_cost` (evaluations, Jacobians,
   factorizations and solves the stretches counted, priced from the model's size and
   the band of its Newton matrices). So:

   - where one factorization of ``radau``'s Newton matrices alone costs over
     :data:`BUDGET` of ``dop853``'s projection (a large scene's band), ``dop853`` goes on;
   - else ``radau`` takes :data:`IMPLICIT_PROBE` steps from the start (4 for a large
     model); where its projection is :data:`SURE` times below ``dop853``'s, it finishes
     the run;
   - else ``dop853`` takes :data:`SETTLE` more steps (its step size settles at the
     stability limit), and ``radau`` goes on in stretches of 16 steps, then four times
     longer each, while its projection is the dearer, each stretch lowers it (by
     :data:`STALL`) and its work so far stays within :data:`BUDGET` of ``dop853``'s
     projection: an excited fast mode holds ``radau``'s first steps small until its
     damping removes it, so its early projection can be far too dear, while a
     projection that stays put is a mode ``radau`` must resolve as well. The cheaper
     projection finishes the run from where its method stopped.

   (``radau`` starts afresh rather than from ``dop853``'s state: a state reached at the
   stability limit carries fast-mode noise that would hold ``radau``'s first steps
   small.) The summary line's reason gives the figures: steps to go, work per step
   and the product, for both methods.

The probes are steps of the real run (the grid points they pass are kept), so deciding
costs at most the probes. The same files and options take the same steps and so the
same decision in every run and process. A failure inside the explicit probe (an
overflow from an unstable step) hands the run to ``radau``; if ``radau`` fails too, the
explicit probe's error is reported (where the trouble began) with ``radau``'s as a
note. Failures after the decision are the run's own.
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
from .step_cost import StepCosts, Work

EXPLICIT_PROBE = 40
COMPILED_PROBE = 10
IMPLICIT_PROBE = 20
CHEAP_STEPS = 500
"""Explicit steps to go below which no estimate or implicit probe is worth its cost
(about what ``rho * T <= 2000`` allows a stability-limited explicit method)."""
SPRINT_STATES = 32
"""On the compiled engine, models of more states take :data:`CHEAP_STEPS` more explicit
steps before an estimate (dense eigenvalues of 32 states take about 0.1 ms, of 400
some 40 ms: as long as hundreds of compiled steps); their implicit probe is 4 steps."""
SURE = 4.0
"""``radau``'s projection from its probe wins at once where it is this many times below
``dop853``'s from its probe (whose early steps, still growing, make it too dear)."""
SETTLE = 200
"""``dop853``'s further steps before a close race is run on: its step size at the end
is the one it keeps."""
STALL = 0.98
"""``radau``'s stretches go on only while each lowers its projection below this
fraction of the last one's: on the uneven pair at k = 1e8 (its damping at work) each
stretch lowers it by 6-33 %, on the oscillator over 1000 periods (a mode to resolve)
by about 1 %, and radau stops there after 100 steps instead of 1,000."""
BUDGET = 0.2
"""``radau`` may work up to this fraction of ``dop853``'s projected work in its probe and
stretches (the uneven pair at k = 1e8 over 10 s: radau's probe projects ~8 times dop853's
work, it finishes the run for under a tenth of it). Where ``dop853`` wins, the race
costs it at most a fifth more."""


class Stretch(Protocol):
    """What one stretch of steps counted (``springc.simulation.steps.Stretch``)."""

    @property
    def work(self) -> Work: ...

    @property
    def steps(self) -> int: ...

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

    def costs(self) -> StepCosts: ...


@dataclass(frozen=True)
class Projection:
    """A method's projected remaining work: ``steps`` to go at its settled step size,
    ``per_step`` equivalent right-hand side evaluations each."""

    steps: float
    per_step: float

    @property
    def work(self) -> float:
        """The product (infinite where no step size settled)."""
        return self.steps * self.per_step if math.isfinite(self.steps) else math.inf

    def text(self) -> str:
        return f"~{self.steps:.2g} steps x {self.per_step:.3g} = ~{self.work:.2g}"


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
    """The race (see the module text): every comparison is of two :class:`Projection`
    objects, from the counts of the stretches run so far."""
    costs = run.costs()
    ahead = _projection(costs, False, first, stop - explicit.t)
    factorization = costs.factorization_evaluations()
    if factorization > BUDGET * ahead.work:
        run.advance(explicit)
        return EXPLICIT, (f"{stiffness}, but one factorization of {RACE_IMPLICIT}'s Newton "
                          f"matrices costs ~{factorization:.2g} RHS evaluations, {EXPLICIT} "
                          f"{ahead.text()} to go")
    implicit = run.start(RACE_IMPLICIT, t0, x0)
    last = run.advance(implicit, IMPLICIT_PROBE if len(x0) <= SPRINT_STATES else 4)
    spent = costs.evaluations(True, last.work)
    if run.done:
        return RACE_IMPLICIT, _trial(stiffness, spent, ahead)
    behind = _projection(costs, True, last, stop - implicit.t)
    if SURE * behind.work <= ahead.work:
        return _finish(run, explicit, implicit, True, stiffness, behind, ahead)
    settled = run.advance(explicit, SETTLE)
    if run.done:
        return EXPLICIT, (f"{stiffness}; counted: {EXPLICIT} finished the run in its "
                          f"{SETTLE} further steps, {RACE_IMPLICIT} {behind.text()} RHS "
                          "evaluations to go")
    ahead = _projection(costs, False, settled, stop - explicit.t)
    steps, before = 16.0, math.inf
    while True:
        behind = _projection(costs, True, last, stop - implicit.t)
        room = BUDGET * ahead.work - spent
        steps = min(steps, room / behind.per_step) if behind.per_step > 0 else 0.0
        if behind.work <= ahead.work or not steps >= 1 or behind.work > STALL * before:
            return _finish(run, explicit, implicit, behind.work <= ahead.work, stiffness,
                           behind, ahead)
        last = run.advance(implicit, int(steps))
        spent += costs.evaluations(True, last.work)
        if run.done:
            return RACE_IMPLICIT, _trial(stiffness, spent, ahead)
        steps, before = 4.0 * last.steps, behind.work


def _trial(stiffness: str, spent: float, ahead: Projection) -> str:
    """The reason of a ``radau`` run that ended within its trial steps."""
    return (f"{stiffness}; counted: {RACE_IMPLICIT} finished the run in its trial steps, "
            f"~{spent:.2g} RHS evaluations, {EXPLICIT} {ahead.text()} to go")


def _finish(run: Run, explicit: Any, implicit: Any, implicit_wins: bool, stiffness: str,
            behind: Projection, ahead: Projection) -> tuple[str, str]:
    """The race's winner runs to the end; the reason gives both projections (steps to go
    x RHS evaluations per step = work)."""
    text = counted(behind, ahead)
    if implicit_wins:
        run.advance(implicit)
        return RACE_IMPLICIT, f"{stiffness}; {text}"
    run.advance(explicit)
    return EXPLICIT, f"{stiffness}, but the fast modes must be resolved anyway; {text}"


def counted(behind: Projection, ahead: Projection) -> str:
    """The reason's figures: ``radau``'s projection (``behind``), then ``dop853``'s."""
    return (f"counted: {RACE_IMPLICIT} {behind.text()} RHS evaluations to go, {EXPLICIT} "
            f"{ahead.text()}")


def _projection(costs: StepCosts, implicit: bool, stretch: Stretch, span: float
                ) -> Projection:
    """A method's work to go over ``span`` from its last ``stretch``: steps at the step
    size it settled on, each at the stretch's work per accepted step."""
    steps = _steps(span, _step(stretch))
    per_step = costs.evaluations(implicit, stretch.work) / max(stretch.steps, 1)
    return Projection(steps, per_step)


def _step(stretch: Stretch) -> float:
    """The step size a method has settled on: the median of its last steps (0 where it
    accepted none)."""
    return float(statistics.median(stretch.sizes[-5:])) if stretch.sizes else 0.0


def _steps(span: float, step: float) -> float:
    """Steps of ``step`` over ``span`` (infinitely many where the step is 0)."""
    return span / step if step > 0 else math.inf
