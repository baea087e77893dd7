"""``--solver auto`` on a large stiffness estimate: a short race decides the solver.

``rho * T`` large says an explicit method *could* be held to steps of ``1/rho`` for
stability; whether it is depends on the run. A very stiff spring whose fast mode stays
at rest (a symmetric pair, an equilibrium) costs ``dop853`` nothing; one whose fast
mode is excited must be resolved by every method; and a ``radau`` step costs several
``dop853`` steps. So both are measured on the model itself:

1. ``dop853`` takes :data:`EXPLICIT_PROBE` steps. If it finishes, or its current step
   size leaves fewer than :data:`CHEAP_STEPS` steps to go, it finishes the run.
2. Otherwise ``radau`` takes :data:`IMPLICIT_PROBE` steps from the start, and each
   method's remaining cost is projected from its last step sizes and its measured
   time per step. The cheaper one finishes the run from where its probe left off.
   (``radau`` starts afresh rather than from ``dop853``'s state: a state reached at
   the stability limit carries fast-mode noise that would hold ``radau``'s first
   steps small and spoil its projection.)

The probes are steps of the real run (the grid points they pass are kept), so the
cost of deciding is bounded by the two probes: a few percent of any run long enough
to matter. The projection is taken early, so it sees ``radau`` at its worst when a
fast mode is excited above the tolerance (it must resolve the first oscillations
before its damping removes them): the race then keeps ``dop853``, which resolves
that vibration faithfully instead of damping it away. A failure inside the explicit probe
(an overflow from an unstable step) hands the run to ``radau``; failures after the
decision are the run's own.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from .solvers import EXPLICIT, IMPLICIT

EXPLICIT_PROBE = 40
IMPLICIT_PROBE = 20
CHEAP_STEPS = 2000
"""Explicit steps to go below which the implicit probe is not worth its cost."""


class Stretch(Protocol):
    steps: int
    seconds: float
    sizes: tuple[float, ...]


class Run(Protocol):
    """The simulation's step loop (``springc.simulation._Run``)."""

    failure: type[Exception]
    done: bool

    def start(self, solver: str, t: float, y: np.ndarray,
              first_step: float | None = None) -> Any: ...

    def advance(self, integrator: Any, max_steps: int | None = None) -> Stretch: ...


def race(run: Run, t0: float, x0: np.ndarray, stop: float, stiffness: str
         ) -> tuple[str, str]:
    """Integrate ``run`` to the end; the solver that finished and why.

    ``stiffness`` is the estimate's own reason (``stiff: fastest time scale ...``).
    """
    explicit = run.start(EXPLICIT, t0, x0)
    try:
        probe = run.advance(explicit, EXPLICIT_PROBE)
    except run.failure:
        implicit = run.start(IMPLICIT, float(explicit.t), np.array(explicit.y))
        run.advance(implicit)
        return IMPLICIT, f"{stiffness}; {EXPLICIT} failed in its first steps"
    if run.done:
        return EXPLICIT, (f"{stiffness}, but {EXPLICIT} finished in {probe.steps} steps: "
                          "the fast modes stay at rest")
    h_explicit = _step(probe)
    left = (stop - explicit.t) / h_explicit
    if left <= CHEAP_STEPS:
        run.advance(explicit)
        return EXPLICIT, (f"{stiffness}, but {EXPLICIT}'s steps are not held to it "
                          f"(~{left:.2g} steps to go): the fast modes stay at rest")
    per_explicit = probe.seconds / probe.steps
    implicit = run.start(IMPLICIT, t0, x0)
    trial = run.advance(implicit, IMPLICIT_PROBE)
    if run.done:
        return IMPLICIT, f"{stiffness}; {IMPLICIT} finished the run in its trial steps"
    explicit_cost = (stop - explicit.t) / h_explicit * per_explicit
    implicit_cost = (stop - implicit.t) / _step(trial) * trial.seconds / trial.steps
    measured = (f"measured: {IMPLICIT} ~{implicit_cost:.2g} s to go, {EXPLICIT} "
                f"~{explicit_cost:.2g} s")
    if implicit_cost <= explicit_cost:
        run.advance(implicit)
        return IMPLICIT, f"{stiffness}; {measured}"
    run.advance(explicit)
    return EXPLICIT, (f"{stiffness}, but the fast modes must be resolved anyway; "
                      f"{measured}")


def _step(stretch: Stretch) -> float:
    """The step size a method has settled on: the median of its last steps."""
    return float(np.median(stretch.sizes[-5:]))
