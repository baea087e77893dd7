"""``--solver auto``: explicit first, and a short race where the run proves long.

1. ``dop853`` takes :data:`EXPLICIT_PROBE` steps. If it finishes, or its current step
   size leaves at most :data:`CHEAP_STEPS` steps to go, it finishes the run: a short
   run costs no stiffness estimate at all. On the compiled engine, where a whole short
   run costs less than those probe steps on scipy, ``dop853`` first tries the run
   compiled within ``EXPLICIT_PROBE + CHEAP_STEPS`` steps; if it does not finish there
   (or fails), that work is dropped and the run goes on as here from the start.
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

The probes are steps of the real run (the grid points they pass are kept), so
deciding costs at most the two probes: a few percent of any run long enough to
matter. The projection is taken early, so it sees ``radau`` at its worst when a fast
mode is excited above the tolerance (it must resolve the first oscillations before
its damping removes them): the race then keeps ``dop853``, which resolves that
vibration instead of damping it away. A failure inside the explicit probe (an
overflow from an unstable step) hands the run to ``radau``; if ``radau`` fails too,
the explicit probe's error is reported (where the trouble began) with ``radau``'s as
a note. Failures after the decision are the run's own.
"""

from __future__ import annotations

from collections.abc import Callable
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

    def start(self, solver: str, t: float, y: np.ndarray,
              first_step: float | None = None) -> Any: ...

    def advance(self, integrator: Any, max_steps: int | None = None) -> Stretch: ...

    def both_failed(self, first: Any, second: Any) -> Exception: ...

    def sprint(self, integrator: Any, steps: int) -> Stretch | None: ...


def auto(run: Run, t0: float, x0: np.ndarray, stop: float,
         estimate: Callable[[float, np.ndarray], AutoChoice]) -> tuple[str, str]:
    """Integrate ``run`` to the end; the solver that finished and why.

    ``estimate(t, x)`` is the stiffness estimate at a state (only called for long runs).
    """
    explicit = run.start(EXPLICIT, t0, x0)
    sprint = run.sprint(explicit, EXPLICIT_PROBE + CHEAP_STEPS)
    if sprint is not None:
        return EXPLICIT, f"non-stiff: {EXPLICIT} finished in {sprint.steps} steps"
    try:
        probe = run.advance(explicit, EXPLICIT_PROBE)
    except run.failure as failure:
        implicit = run.start(RACE_IMPLICIT, float(explicit.t), np.array(explicit.y))
        try:
            run.advance(implicit)
        except run.failure as again:
            raise run.both_failed(failure, again) from None
        return RACE_IMPLICIT, f"{EXPLICIT} failed in its first steps ({failure})"
    if run.done:
        return EXPLICIT, f"non-stiff: {EXPLICIT} finished in {probe.steps} steps"
    h_explicit = _step(probe)
    left = (stop - explicit.t) / h_explicit
    if left <= CHEAP_STEPS:
        run.advance(explicit)
        return EXPLICIT, f"non-stiff: {EXPLICIT} needs ~{left:.2g} more steps"
    choice = estimate(float(explicit.t), np.array(explicit.y))
    if choice.solver == RACE:
        return _race(run, explicit, probe, h_explicit, t0, x0, stop, choice.reason)
    if choice.solver == RACE_IMPLICIT:
        explicit = run.start(RACE_IMPLICIT, float(explicit.t), np.array(explicit.y))
    run.advance(explicit)
    return choice.solver, choice.reason


def _race(run: Run, explicit: Any, probe: Stretch, h_explicit: float, t0: float,
          x0: np.ndarray, stop: float, stiffness: str) -> tuple[str, str]:
    explicit_cost = (stop - explicit.t) / h_explicit * probe.seconds / probe.steps
    implicit = run.start(RACE_IMPLICIT, t0, x0)
    steps, seconds = 0, 0.0
    sizes: list[float] = []
    while steps < IMPLICIT_PROBE and seconds <= PROBE_BUDGET * explicit_cost:
        trial = run.advance(implicit, 1)
        steps, seconds = steps + trial.steps, seconds + trial.seconds
        sizes += trial.sizes
        if run.done:
            return RACE_IMPLICIT, (f"{stiffness}; {RACE_IMPLICIT} finished the run in its "
                                   "trial steps")
    implicit_cost = (stop - implicit.t) / float(np.median(sizes[-5:])) * seconds / steps
    measured = (f"measured: {RACE_IMPLICIT} ~{implicit_cost:.2g} s to go, {EXPLICIT} "
                f"~{explicit_cost:.2g} s")
    if implicit_cost <= explicit_cost:
        run.advance(implicit)
        return RACE_IMPLICIT, f"{stiffness}; {measured}"
    run.advance(explicit)
    return EXPLICIT, (f"{stiffness}, but the fast modes must be resolved anyway; "
                      f"{measured}")


def _step(stretch: Stretch) -> float:
    """The step size a method has settled on: the median of its last steps."""
    return float(np.median(stretch.sizes[-5:]))
