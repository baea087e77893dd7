"""The decisions of ``--solver auto`` (springc.simulation.race) on a scripted step loop: which
method finishes the run, after how many probe steps, and the reason given."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

from springc.simulation import race
from springc.simulation.solvers import AutoChoice


@dataclass
class Stretch:
    steps: int
    seconds: float
    sizes: tuple[float, ...]


@dataclass
class Integrator:
    solver: str
    t: float
    y: np.ndarray = field(default_factory=lambda: np.zeros(1))


class Run:
    """Each solver steps by a fixed size at a fixed cost per step, up to ``stop``."""

    failure = RuntimeError

    def __init__(self, step: dict[str, float], cost: dict[str, float], stop: float = 10.0,
                 compiled: bool = False, call: float = 0.0) -> None:
        self.step, self.cost, self.stop = step, cost, stop
        self.compiled, self.call = compiled, call  # call: each advance's fixed cost
        self.factorization = 0.0  # the predicted cost of radau's Newton matrices
        self.done = False
        self.taken: dict[str, int] = {}

    def start(self, solver: str, t: float, y: np.ndarray,
              first_step: float | None = None) -> Integrator:
        return Integrator(solver, t, y)

    def advance(self, integrator: Integrator, max_steps: int | None = None) -> Stretch:
        h = self.step[integrator.solver]
        if h == 0:  # every step rejected: the attempts cost, no step is accepted
            assert max_steps is not None, "a method that never steps is run to the end"
            self.taken[integrator.solver] = self.taken.get(integrator.solver, 0) + max_steps
            return Stretch(0, self.call + max_steps * self.cost[integrator.solver], ())
        left = int(np.ceil((self.stop - integrator.t) / h - 1e-9))
        steps = left if max_steps is None else min(max_steps, left)
        integrator.t = min(self.stop, integrator.t + steps * h)
        self.done = self.done or integrator.t >= self.stop
        self.taken[integrator.solver] = self.taken.get(integrator.solver, 0) + steps
        return Stretch(steps, self.call + steps * self.cost[integrator.solver],
                       (h,) * min(steps, 10))

    def both_failed(self, first: Exception, second: Exception) -> Exception:
        return first

    def factorization_seconds(self) -> float:
        return self.factorization


def estimate(solver: str) -> object:
    return lambda t, x: AutoChoice(solver, f"{solver} estimate", 1.0, 10.0)


def _auto(run: Run, choice: str = race.RACE) -> tuple[str, str]:
    return race.auto(run, 0.0, np.zeros(1), 10.0, estimate(choice))  # type: ignore[arg-type]


def test_a_short_run_needs_no_estimate() -> None:
    run = Run({"dop853": 0.5}, {"dop853": 1e-4})
    assert _auto(run, "unused") == ("dop853", "non-stiff: dop853 finished in 20 steps")
    run = Run({"dop853": 0.1}, {"dop853": 1e-4})  # 100 steps: 60 left after the probe
    assert _auto(run, "unused") == ("dop853", "non-stiff: dop853 needs ~60 more steps")
    assert run.taken == {"dop853": 100}


@pytest.mark.parametrize("choice", ["dop853", "radau"])
def test_a_long_run_follows_a_clear_estimate(choice: str) -> None:
    run = Run({"dop853": 1e-3, "radau": 0.1}, {"dop853": 1e-4, "radau": 1e-3})
    assert _auto(run, choice) == (choice, f"{choice} estimate")
    assert run.done and set(run.taken) == ({"dop853"} | {choice})


def test_the_race_picks_the_cheaper_projection() -> None:
    # dop853 held to 1e-4 s steps (1e5 steps, 10 s); radau 0.05 s steps (200, 0.4 s).
    run = Run({"dop853": 1e-4, "radau": 0.05}, {"dop853": 1e-4, "radau": 2e-3})
    solver, reason = _auto(run)
    assert solver == "radau" and run.taken["dop853"] == race.EXPLICIT_PROBE
    assert reason == "race estimate; measured: radau ~0.36 s to go, dop853 ~10 s"
    # radau held to small steps too, each dearer: dop853 goes on after radau's probe.
    run = Run({"dop853": 1e-3, "radau": 1e-3}, {"dop853": 1e-4, "radau": 1e-3})
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken["radau"] == race.IMPLICIT_PROBE
    assert reason == ("race estimate, but the fast modes must be resolved anyway; "
                      "measured: radau ~10 s to go, dop853 ~1 s")


def test_the_implicit_probe_stops_at_its_budget() -> None:
    # dop853 projects ~1 s; each radau step costs 0.02 s, over the 0.05 s budget by 3.
    run = Run({"dop853": 1e-3, "radau": 1e-3}, {"dop853": 1e-4, "radau": 0.02})
    assert _auto(run)[0] == "dop853"
    assert run.taken["radau"] == 3


def test_compiled_probes_time_by_differences() -> None:
    # a small model: 10 compiled steps, and with 490 to go no estimate
    run = Run({"dop853": 0.02}, {"dop853": 1e-6}, compiled=True)
    assert _auto(run, "unused") == ("dop853", "non-stiff: dop853 needs ~4.9e+02 more steps")
    # radau's probe (20 steps) leaves ~2,000 steps, dop853's ~10,000: the counts cannot
    # tell, so dop853 is timed on 20 and 200 more steps; each call's fixed cost (10 us,
    # as much as 10 steps) cancels in the difference: ~0.0098 s to go. radau's cost,
    # the probe's mean with the call's cost in it, is an upper bound: ~0.0049 s.
    run = Run({"dop853": 1e-3, "radau": 5e-3}, {"dop853": 1e-6, "radau": 2e-6},
              compiled=True, call=1e-5)
    solver, reason = _auto(run)
    assert solver == "radau" and run.taken == {"dop853": 10 + 20 + 200, "radau": 2000}
    assert reason == "race estimate; measured: radau ~0.0049 s to go, dop853 ~0.0098 s"


def test_step_counts_alone_decide_a_compiled_race_far_apart() -> None:
    # ~180 radau steps against ~1e5 dop853 steps: no radau step of one state costs 20
    run = Run({"dop853": 1e-4, "radau": 0.05}, {"dop853": 1e-6, "radau": 2e-5},
              compiled=True)
    solver, reason = _auto(run)
    assert solver == "radau" and run.taken == {"dop853": 10, "radau": 200}
    assert reason == "race estimate; measured: radau ~1.8e+02 steps to go, dop853 ~1e+05"



def test_the_compiled_race_lets_radau_run_up_to_a_fifth_of_dop853s_time() -> None:
    """radau held to 10x smaller steps (each 2x dearer) runs stretches four times longer
    each (its 20 probe steps, then 16, 64, 256, and what the budget leaves) until it has
    cost a fifth of dop853's ~0.01 s: 977 steps of 2 us."""
    run = Run({"dop853": 1e-3, "radau": 1e-4}, {"dop853": 1e-6, "radau": 2e-6},
              compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken == {"dop853": 10_000, "radau": 977}
    assert reason == ("race estimate, but the fast modes must be resolved anyway; measured: "
                      "radau ~0.2 s to go, dop853 ~0.0098 s")


def test_a_large_compiled_model_sprints_before_its_estimate() -> None:
    """Over SPRINT_STATES states, 510 explicit steps come before a (dear) estimate."""
    run = Run({"dop853": 0.02}, {"dop853": 1e-6}, compiled=True)
    x0 = np.zeros(race.SPRINT_STATES + 1)
    assert race.auto(run, 0.0, x0, 10.0, estimate("unused")) == (  # type: ignore[arg-type]
        "dop853", "non-stiff: dop853 finished in 500 steps")


def test_the_compiled_implicit_probe_stops_at_its_budget() -> None:
    # dop853 projects ~10 s (1e5 steps of 1e-4 s): radau's 20 probe steps of 0.25 s
    # (5 s) spend more than the 2 s budget, and no further stretch is run
    run = Run({"dop853": 1e-4, "radau": 1e-3}, {"dop853": 1e-4, "radau": 0.25},
              compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken["radau"] == 20
    assert reason.endswith("measured: radau ~2.5e+03 s to go, dop853 ~10 s")


def test_a_compiled_race_skips_radau_whose_factorization_alone_is_over_budget() -> None:
    """A large scene: one factorization of radau's Newton matrices predicted at 1.6 s
    (the 50x50 cloth's band), over a fifth of dop853's ~0.1 s: radau takes no step."""
    run = Run({"dop853": 1e-3}, {"dop853": 1e-5}, compiled=True)
    run.factorization = 1.6
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken == {"dop853": 10_000}
    assert reason == ("race estimate, but one factorization of radau's Newton matrices "
                      "takes over 1.6 s, dop853 ~0.1 s to go")


def test_a_compiled_stretch_that_accepts_no_step_projects_no_end() -> None:
    """radau's probe rejecting every step (no step size settled): its projection is
    infinite and the race keeps dop853, with no error on the empty stretch."""
    run = Run({"dop853": 1e-3, "radau": 0.0}, {"dop853": 1e-6, "radau": 2e-6},
              compiled=True)
    solver, reason = _auto(run)
    assert solver == "dop853" and run.taken["dop853"] == 10_000
    assert reason.endswith("measured: radau ~inf s to go, dop853 ~0.0098 s")
