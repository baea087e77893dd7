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
   times below ``dop853``'s, ``radau`` runs, else ``dop853``. The reason gives both
   projections (steps to go x RHS evaluations per step = work).

The probes cost at most ``CHEAP_STEPS + IMPLICIT_PROBE`` steps more than the run. A
failure in ``dop853``'s probe is the run's own (as with ``--solver dop853``); one in
``radau``'s hands the run to ``dop853``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .failures import Stop
from .limits import OverLimit
from .race import CHEAP_STEPS, SURE, Projection, counted
from .solver_names import EXPLICIT, RACE, RACE_IMPLICIT
from .solvers import choose as estimate
from .step_cost import Work, step_costs

IMPLICIT_PROBE = 100
"""``radau``'s probe: enough steps past its first growth from a tiny step that its
average rate is its rate (each event restarts it from a small step again)."""

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
    try:
        second = attempt(RACE_IMPLICIT, IMPLICIT_PROBE)
    except Stop as failure:
        return attempt(EXPLICIT, None), (f"{choice.reason}, but {RACE_IMPLICIT} failed in "
                                         f"its trial steps ({failure})")
    if second.capped is None:
        return second, (f"{choice.reason}; counted: {RACE_IMPLICIT} finished the run in "
                        f"its {IMPLICIT_PROBE} trial steps, {EXPLICIT} {ahead.text()} to go")
    behind = _projection(second, True, start, stop)
    text = counted(behind, ahead)
    if SURE * behind.work <= ahead.work:
        return attempt(RACE_IMPLICIT, None), f"{choice.reason}; {text}"
    return attempt(EXPLICIT, None), (f"{choice.reason}, but the fast modes must be "
                                     f"resolved anyway; {text}")


def _projection(probe: Attempt, implicit: bool, start: float, stop: float) -> Projection:
    """A capped probe's work to go: the span left at its average rate, each step at its
    work per step in the cost model (attempts counted as accepted steps: the event
    loops count no rejections)."""
    assert probe.capped is not None
    problem, reached, taken = probe.problem, float(probe.capped.t), probe.loop.steps
    covered = reached - start
    steps = (stop - reached) * taken / covered if covered > 0 else math.inf
    work = Work(taken, taken, problem.nfev, problem.njev)
    costs = step_costs(problem.mod, probe.compiled)
    return Projection(steps, costs.evaluations(implicit, work) / max(taken, 1))
