"""``--solver auto`` for hybrid models: probes of the event loop, decided by counts and
the cost model of :mod:`springc.simulation.step_cost`, never by the clock.

The event loop restarts its integrator at every event, so it cannot hand a run from one
method to another as :mod:`springc.simulation.race` does; instead each probe is a run
from the start with a step cap, and the winner runs afresh from the start (a capped run
takes exactly the first steps of the full one, so ``auto -> X`` gives ``X``'s result):

1. ``dop853`` runs :data:`~springc.simulation.race.CHEAP_STEPS` steps. If it finishes,
   that is the run (a short run costs no estimate: the reason is the old one).
2. Its projection: the span left at its average rate so far (steps per second of model
   time, events included), times its work per step in the cost model. At most
   ``CHEAP_STEPS`` more steps, or a small stiffness estimate ``rho * T`` at the state
   reached (:func:`springc.simulation.solvers.choose`, the continuous race's threshold),
   and ``dop853`` runs.
3. Else ``radau`` runs :data:`IMPLICIT_PROBE` steps (a run that ends there is the run)
   and is projected alike; where its projection is :data:`~springc.simulation.race.SURE`
   times below ``dop853``'s, ``radau`` runs. Else its probe may have spent its steps
   on the start's transient (a stiff start after the initial events: Translational.
   PreLoad's radau takes 300 steps for its first 5 ms, then 22 for the next 2 s), so
   ``radau`` runs again from the start in stretches :data:`GROWTH` times longer, each
   projected at the rate of the steps it added to the one before (its marginal rate,
   the step size it settled on), while each stretch lowers the projection below
   :data:`~springc.simulation.race.STALL` of the last and the probes' work stays within
   :data:`~springc.simulation.race.BUDGET` of ``dop853``'s projection (the continuous
   race's rules). ``radau`` runs where a projection wins by ``SURE``, else ``dop853``.
   Where a ``radau`` stretch has reached further in model time than ``dop853``'s probe,
   ``dop853`` first runs again from the start, ``GROWTH`` times longer, and is
   projected at the rate of the steps it added (:func:`_explicit_ahead`): the two
   projections then come from the same part of the run (Analog.CauerLowPassSC's
   ``dop853`` probe ends 5 ms after its input steps at 1 s, and projected from the
   quiet second before it ~3e4 steps, where the run takes ~4e6).
   The reason gives both projections (steps to go x RHS evaluations per step = work).

The probes cost at most ``CHEAP_STEPS`` steps of ``dop853`` and a fifth of its projected
work in ``radau``'s probes more than the run. A failure in ``dop853``'s probe is the
run's own (as with ``--solver dop853``); one in ``radau``'s hands the run to ``dop853``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .failures import Stop
from .limits import OverLimit
from .race import BUDGET, CHEAP_STEPS, STALL, SURE, Projection, counted
from .solver_names import EXPLICIT, RACE, RACE_IMPLICIT
from .solvers import choose as estimate
from .step_cost import Work, step_costs

IMPLICIT_PROBE = 100
"""``radau``'s probe: enough steps past its first growth from a tiny step that its
average rate is its rate (each event restarts it from a small step again)."""

GROWTH = 4
"""Each of ``radau``'s further probes takes this many times the steps of the one before."""

OLD_REASON = "a hybrid model: dop853 with event location"


class Attempt(NamedTuple):
    """A run of the event loop: its problem (``steps.Problem``), loop
    (``events.EventLoop``), whether it ran compiled and the seconds in the kernels."""

    problem: Any
    loop: Any
    compiled: bool
    loop_time: float
    capped: OverLimit | None = None
    """Where a probe reached its step cap (``None``: the run finished)."""


def choose(attempt: Callable[[str, int | None], Attempt], x0: np.ndarray, start: float,
           stop: float, max_steps: int) -> tuple[Attempt, str]:
    """The run ``auto`` chose (see the module text) and why."""
    if not len(x0) or max_steps <= CHEAP_STEPS:
        return attempt(EXPLICIT, None), OLD_REASON
    first = attempt(EXPLICIT, CHEAP_STEPS)
    if first.capped is None:
        return first, OLD_REASON
    ahead = _projection(first, False, start, stop)
    if ahead.steps <= CHEAP_STEPS:
        return attempt(EXPLICIT, None), f"non-stiff: {EXPLICIT} needs ~{ahead.steps:.2g} more steps"
    over = first.capped
    choice = estimate(first.problem.jac(over.t, np.asarray(over.y, dtype=float)), stop - start)
    if choice.solver != RACE:
        return attempt(choice.solver, None), choice.reason
    cap, before, spent = IMPLICIT_PROBE, None, 0.0
    while True:
        try:
            second = attempt(RACE_IMPLICIT, cap)
        except Stop as failure:
            return attempt(EXPLICIT, None), (f"{choice.reason}, but {RACE_IMPLICIT} failed "
                                             f"in its trial steps ({failure})")
        if second.capped is None:
            return second, (f"{choice.reason}; counted: {RACE_IMPLICIT} finished the run "
                            f"in its {cap} trial steps, {EXPLICIT} {ahead.text()} to go")
        behind = _projection(second, True, start, stop, before)
        first, ahead = _explicit_ahead(attempt, first, ahead, second, start, stop)
        text = counted(behind, ahead)
        if SURE * behind.work <= ahead.work:
            return attempt(RACE_IMPLICIT, None), f"{choice.reason}; {text}"
        work = _work(second, True)
        spent += work
        last = _projection(before, True, start, stop) if before is not None else None
        if (last is not None and not behind.work < STALL * last.work) or \
                spent + GROWTH * work > BUDGET * ahead.work:
            return attempt(EXPLICIT, None), (f"{choice.reason}, but the fast modes must be "
                                             f"resolved anyway; {text}")
        before, cap = second, cap * GROWTH


def _explicit_ahead(attempt: Callable[[str, int | None], Attempt], first: Attempt,
                    ahead: Projection, second: Attempt, start: float, stop: float
                    ) -> tuple[Attempt, Projection]:
    """``dop853``'s probe and projection to compare with ``radau``'s probe ``second``:
    ``first`` and ``ahead`` where ``first`` reached at least as far in model time, else
    a probe :data:`GROWTH` times longer projected at the rate of the steps it added to
    ``first`` (a failure there keeps ``first``'s, and a probe that finishes is
    projected at no steps to go: it is then the cheaper run)."""
    assert first.capped is not None and second.capped is not None
    if float(second.capped.t) <= float(first.capped.t):
        return first, ahead
    try:
        longer = attempt(EXPLICIT, GROWTH * first.loop.steps)
    except Stop:
        return first, ahead
    if longer.capped is None:
        return first, Projection(0.0, ahead.per_step)
    return longer, _projection(longer, False, start, stop, first)


def _projection(probe: Attempt, implicit: bool, start: float, stop: float,
                before: Attempt | None = None) -> Projection:
    """A capped probe's work to go: the span left at its rate, each step at its work per
    step in the cost model (attempts counted as accepted steps: the event loops count no
    rejections). The rate is the probe's average, or with ``before`` (a shorter probe of
    the same method: the first steps of this one) that of the steps it added."""
    assert probe.capped is not None
    reached, taken = float(probe.capped.t), probe.loop.steps
    covered, work = reached - start, _work(probe, implicit)
    if before is not None:
        assert before.capped is not None
        covered = reached - float(before.capped.t)
        taken, work = taken - before.loop.steps, work - _work(before, implicit)
    steps = (stop - reached) * taken / covered if covered > 0 else math.inf
    return Projection(steps, work / max(taken, 1))


def _work(probe: Attempt, implicit: bool) -> float:
    """A probe's work in equivalent right-hand side evaluations (the cost model)."""
    problem, taken = probe.problem, probe.loop.steps
    costs = step_costs(problem.mod, probe.compiled)
    return costs.evaluations(implicit, Work(taken, taken, problem.nfev, problem.njev))
