"""A solver's settings, loosest first -> its runs (:func:`solver_runs`), with the
cost limit that skips the tighter settings a solver cannot win with.

- **Pilot.** One solver (``dop853`` when compared, else the first listed) is run
  first, in the calling process; the others are measured against its fastest runs.
- **Cost limit.** Tighter settings cost more (more steps), so once a run of a solver
  takes over ``cost_limit`` times the pilot's fastest run meeting every target, none of
  the solver's tighter settings can be the fastest for a target: they are skipped, and
  each skipped row says why. Without a pilot run meeting every target (a target only
  another solver may reach), or with ``cost_limit`` infinite, every setting is run.
- **Budget.** A run over the budget is stopped and the tighter settings are skipped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..simulation import EXPLICIT, registered
from .model import BUDGET_SKIP, COST_SKIP, Reference, Run
from .runs import (
    contender,
    energy_drift,
    fastest,
    log_line,
    retimed,
    springc_once,
    timed_once,
    warm_up_solver,
    with_errors,
)
from .setup import StudySetup

PILOT = EXPLICIT
"""The pilot when compared: fast on most models, and the method of the reference (the
registry's explicit method)."""


@dataclass(frozen=True)
class Chain:
    """One task: a solver's settings, loosest first, or the scipy baselines (``solver``
    :data:`~.model.SCIPY_DEFAULT`)."""

    solver: str
    settings: tuple[float, ...]


@dataclass(frozen=True)
class Pilot:
    """The runs of the solver measured first; the others' cost limit and contenders
    are measured against its fastest runs."""

    solver: str
    runs: tuple[Run, ...]


def pilot_solver(solvers: tuple[str, ...]) -> str:
    """:data:`PILOT` if among ``solvers``, else the first of them."""
    return PILOT if PILOT in solvers else solvers[0]


def cost_ceiling(pilot: Pilot | None, targets: tuple[float, ...], factor: float
                 ) -> tuple[float, str]:
    """Seconds past which a solver's tighter settings are skipped, and what they are
    measured against in words (``math.inf`` and "" when no limit applies): ``10x the
    fastest dop853 run meeting 1e-04 (rtol 1e-07, 0.025 s)``."""
    if pilot is None or not math.isfinite(factor):
        return math.inf, ""
    best = [fastest(pilot.runs, t) for t in targets]
    if any(b is None for b in best):
        return math.inf, ""
    slowest = max((b for b in best if b is not None), key=lambda r: r.wall_time)
    target = min(t for t, b in zip(targets, best) if b is slowest)
    return factor * slowest.wall_time, (
        f"{factor:g}x the fastest {pilot.solver} run meeting {target:.0e} "
        f"({slowest.label()}, {slowest.wall_time:.3g} s)")


def skipped(solver: str, value: float, status: str) -> Run:
    """The row of a setting not run, with the reason as status."""
    return Run(solver, registered(solver).setting, value, math.nan, 0, -1, -1, -1,
               math.nan, math.nan, status)


def solver_runs(setup: StudySetup, ref: Reference, scales: np.ndarray, energy: str | None,
                chain: Chain, pilot: Pilot | None = None,
                log: Callable[[str], None] | None = None) -> list[Run]:
    """The runs of ``chain`` (see the module text), each logged with ``log`` when done;
    contenders are timed again at the end (:mod:`.runs`)."""
    options = setup.options
    facts = registered(chain.solver)
    fixed = facts.fixed
    add_drift = energy_drift(setup, energy, ref)
    ceiling, _ = cost_ceiling(pilot, options.targets, options.cost_limit)

    def arguments(value: float) -> tuple[float | None, float | None]:
        return (None, value) if fixed else (value, None)

    if chain.settings:
        seconds, _ = warm_up_solver(setup, chain.solver, *arguments(chain.settings[0]))
        if log is not None and seconds > 1.0:
            log(f"{chain.solver}: its loop loaded or compiled in {seconds:.1f} s (not timed)")
    runs: list[Run] = []
    onces = []
    stop = ""
    for value in chain.settings:
        if stop:
            runs.append(skipped(chain.solver, value, stop))
            continue
        once = springc_once(setup, chain.solver, *arguments(value))
        run, values = timed_once(setup, chain.solver, facts.setting, value, once)
        run = add_drift(with_errors(run, values, ref, scales), values)
        runs.append(run)
        onces.append((len(runs) - 1, once))
        if log is not None:
            log(log_line(run))
        if run.status.startswith("over budget"):
            stop = BUDGET_SKIP
        elif run.ok and run.wall_time > ceiling:
            stop = (f"{COST_SKIP} ({run.label()} took {run.wall_time:.3g} s > "
                    f"{options.cost_limit:g} x {ceiling / options.cost_limit:.3g} s)")
    known = [*(pilot.runs if pilot is not None else ()), *runs]
    again = [(i, once) for i, once in onces if contender(runs[i], options.targets, known)]
    for (i, _), run in zip(again, retimed([(runs[i], once) for i, once in again],
                                          options.repeats)):
        runs[i] = run
    return runs
