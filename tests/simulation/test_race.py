"""The decisions of ``--solver auto`` (springc.simulation.race) on a scripted step loop: which
method finishes the run, after how many probe steps, and the reason given, from counts
alone (the scripted loop has no clock)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

from springc.simulation import race
from springc.simulation.solvers import AutoChoice
from springc.simulation.step_cost import Overheads, StepCosts, Work

EVALUATIONS = {"dop853": 12, "radau": 7}
"""Right-hand side evaluations per step of the scripted methods: with :func:`costs` a
dop853 step is 12 evaluations' work, a radau step 11 (7 evaluations, one
factorization of 2, two Newton iterations' solves of 1 each)."""


def costs(factorization: float = 2.0) -> StepCosts:
    """Prices in thousands of operations: a call-free loop, no per-state work."""
    return StepCosts(0, 1000.0, 1000.0, 1000.0 * factorization, 1000.0,
                     Overheads(0.0, 0.0, 0.0))


@dataclass
class Stretch:
    work: Work
    sizes: tuple[float, ...]

    @property
    def steps(self) -> int:
        return self.work.steps


@dataclass
class Integrator:
    solver: str
    t: float
    y: np.ndarray = field(default_factory=lambda: np.zeros(1))
    taken: int = 0


class Run:
    """Each solver steps by its step size (``step[solver]``, or a schedule of (steps,
    size) phases whose last size goes on), up to ``stop``."""

    failure = RuntimeError

    def __init__(self, step: dict[str, float | list[tuple[int, float]]], stop: float = 10.0,
                 compiled: bool = False, factorization: float = 2.0) -> None:
        self.step, self.stop, self.compiled = step, stop, compiled
        self.prices = costs(factorization)
        self.done = False
        self.taken: dict[str, int] = {}

    def start(self, solver: str, t: float, y: np.ndarray,
              first_step: float | None = None) -> Integrator:
        return Integrator(solver, t, y)

    def size(self, integrator: Integrator) -> float:
        schedule = self.step[integrator.solver]
        if isinstance(schedule, float):
            return schedule
        count = 0
        for steps, h in schedule:
            count += steps
            if integrator.taken < count:
                return h
        return schedule[-1][1]

    def advance(self, integrator: Integrator, max_steps: int | None = None) -> Stretch:
        solver, steps, sizes = integrator.solver, 0, []
        while self.stop - integrator.t > 1e-9 and steps != max_steps:  # (sums round)
            h = self.size(integrator)
            if h == 0:  # every attempt rejected: the attempts cost, no step is accepted
                assert max_steps is not None, "a method that never steps is run to the end"
                work = Work(0, max_steps, EVALUATIONS[solver] * max_steps)
                self.taken[solver] = self.taken.get(solver, 0) + max_steps
                return Stretch(work, ())
            integrator.t = min(self.stop, integrator.t + h)
            if self.stop - integrator.t <= 1e-9:
                integrator.t = self.stop
            integrator.taken += 1
            steps += 1
            sizes.append(h)
        self.done = self.done or integrator.t >= self.stop
        self.taken[solver] = self.taken.get(solver, 0) + steps
        return Stretch(Work(steps, steps, EVALUATIONS[solver] * steps), tuple(sizes[-10:]))

    def both_failed(self, first: Exception, second: Exception) -> Exception:
        return first

    def costs(self) -> StepCosts:
        return self.prices


def estimate(solver: str) -> object:
    return lambda t, x: AutoChoice(solver, f"{solver} estimate", 1.0, 10.0)


def _auto(run: Run, choice: str = race.RACE, states: int = 1) -> tuple[str, str]:
    return race.auto(run, 0.0, np.zeros(states), 10.0, estimate(choice))  # type: ignore[arg-type]


def test_the_scripted_prices() -> None:
    prices = costs()
    assert prices.evaluations(False, Work(1, 1, 12)) == 12.0
    assert prices.evaluations(True, Work(1, 1, 7)) == 11.0
    assert prices.factorizations(Work(5, 7, 40, 2)) == 9  # attempts + Jacobian updates
    assert prices.factorizations(Work(5, 7, 40, 2, 3)) == 3  # counted by the loop


def test_a_short_run_needs_no_estimate() -> None:
    run = Run({"dop853": 0.5})
    assert _auto(run, "unused") == ("dop853", "non-stiff: dop853 finished in 20 steps")
    run = Run({"dop853": 0.1})  # 100 steps: 60 left after the probe
    assert _auto(run, "unused") == ("dop853", "non-stiff: dop853 needs ~60 more steps")
    assert run.taken == {"dop853": 100}


@pytest.mark.parametrize("choice", ["dop853", "radau"])
def test_a_long_run_follows_a_clear_estimate(choice: str) -> None:
    run = Run({"dop853": 1e-3, "radau": 0.1})
    assert _auto(run, choice) == (choice, f"{choice} estimate")
    assert run.done and set(run.taken) == ({"dop853"} | {choice})


@pytest.mark.parametrize("compiled", [False, True])
def test_far_apart_projections_decide_after_the_probes(compiled: bool) -> None:
    # dop853 held to 1e-4 s steps (~1e5 to go x 12); radau 0.05 s steps: after its 20
    # probe steps 180 to go x 11, far below a quarter of dop853's work.
    run = Run({"dop853": 1e-4, "radau": 0.05}, compiled=compiled)
    assert _auto(run) == ("radau", "race estimate; counted: radau ~1.8e+02 steps x 11 = "
                                   "~2e+03 RHS evaluations to go, dop853 ~1e+05 steps x 12 = "
                                   "~1.2e+06")
    probe = race.COMPILED_PROBE if compiled else race.EXPLICIT_PROBE
    assert run.taken == {"dop853": probe, "radau": 200}


def test_a_radau_projection_that_stays_put_ends_the_race() -> None:
    """radau held to half dop853's steps: its probe projects ~2e4 steps x 11 against
    ~1e4 x 12, not four times below; dop853 takes 200 more steps, radau a stretch of
    16 that leaves its projection where it was (a mode it must resolve too): dop853."""
    run = Run({"dop853": 1e-3, "radau": 5e-4}, compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853"
    assert run.taken == {"dop853": 10_000, "radau": 20 + 16}
    assert reason == ("race estimate, but the fast modes must be resolved anyway; counted: "
                      "radau ~2e+04 steps x 11 = ~2.2e+05 RHS evaluations to go, dop853 "
                      "~9.8e+03 steps x 12 = ~1.2e+05")


def test_a_slowly_gaining_radau_spends_its_budget() -> None:
    """radau's steps grow 5 % a stretch (16, 64, 256, 1024 steps, then what is left of
    a fifth of dop853's 117,480 to go after its 210 steps: 755, rounded down): its
    projection falls, but not to dop853's before the budget is spent."""
    growing = [(20, 5e-4), (16, 5.25e-4), (64, 5.5e-4), (256, 5.8e-4), (1024, 6.1e-4),
               (1, 6.4e-4)]
    run = Run({"dop853": 1e-3, "radau": growing}, compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853"
    assert run.taken == {"dop853": 10_000, "radau": 20 + 16 + 64 + 256 + 1024 + 755}
    assert reason == ("race estimate, but the fast modes must be resolved anyway; counted: "
                      "radau ~1.4e+04 steps x 11 = ~1.5e+05 RHS evaluations to go, dop853 "
                      "~9.8e+03 steps x 12 = ~1.2e+05")


def test_radau_damping_its_fast_mode_wins_within_its_budget() -> None:
    """The excited stiff mode: radau's first steps are small (its probe projects ~2e5
    steps), each stretch lowers its projection as the damping lets its steps grow,
    and after its stretch of 256 steps at 0.005 s it is below dop853's."""
    damping = [(20, 5e-5), (16, 7e-5), (64, 8e-5), (1, 0.005)]
    run = Run({"dop853": 1e-4, "radau": damping}, compiled=True)
    solver, reason = _auto(run)
    assert solver == "radau"
    assert run.taken == {"dop853": 10 + 200, "radau": 100 + 1999}
    assert reason == ("race estimate; counted: radau ~1.7e+03 steps x 11 = ~1.9e+04 RHS "
                      "evaluations to go, dop853 ~1e+05 steps x 12 = ~1.2e+06")


def test_a_large_compiled_model_sprints_before_its_estimate() -> None:
    """Over SPRINT_STATES states, 510 explicit steps come before a (dear) estimate."""
    run = Run({"dop853": 0.02}, compiled=True)
    assert _auto(run, "unused", race.SPRINT_STATES + 1) == (
        "dop853", "non-stiff: dop853 finished in 500 steps")


def test_the_race_skips_radau_whose_factorization_alone_is_over_budget() -> None:
    """A large scene: one factorization of radau's Newton matrices prices at 3e5
    evaluations, over a fifth of dop853's ~1.2e5 to go: radau takes no step."""
    run = Run({"dop853": 1e-4}, compiled=True, factorization=3e5)
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken == {"dop853": 100_000}
    assert reason == ("race estimate, but one factorization of radau's Newton matrices "
                      "costs ~3e+05 RHS evaluations, dop853 ~1e+05 steps x 12 = ~1.2e+06 "
                      "to go")


def test_a_stretch_that_accepts_no_step_projects_no_end() -> None:
    """radau's probe rejecting every step (no step size settled): its projection is
    infinite and the race keeps dop853, with no error on the empty stretch."""
    run = Run({"dop853": 1e-3, "radau": 0.0}, compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken["dop853"] == 10_000
    assert reason.endswith("counted: radau ~inf steps x 176 = ~inf RHS evaluations to go, "
                           "dop853 ~9.8e+03 steps x 12 = ~1.2e+05")


def test_radau_finishing_within_its_probe_states_its_work() -> None:
    run = Run({"dop853": 1e-4, "radau": 0.5}, compiled=True)
    assert _auto(run) == ("radau", "race estimate; counted: radau finished the run in its "
                                   "trial steps, ~2.2e+02 RHS evaluations, dop853 ~1e+05 "
                                   "steps x 12 = ~1.2e+06 to go")


def test_the_decision_is_the_same_every_time() -> None:
    """No clock: the same scripted run decides alike, to the text."""
    runs = [_auto(Run({"dop853": 1e-3, "radau": [(36, 5e-4), (1, 6e-4)]}, compiled=True))
            for _ in range(3)]
    assert runs[0] == runs[1] == runs[2]
