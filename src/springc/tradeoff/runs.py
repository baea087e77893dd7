"""One run of a study -> Run: its timing, the warm-up that keeps compilation out of it,
its errors and energy drift, and whether it is timed again.

- **Timed once.** Every setting is run once, timed: the wall time of
  ``simulate_model`` (integration and outputs). A run over the budget is stopped.
- **Warm-up.** Before a solver's first timed run, an untimed run over the first output
  interval loads its compiled loop from numba's cache (or compiles it, on a machine
  where it never ran): loading or compiling the loop is not the cost of a run.
- **Contenders are timed again.** A run that meets a target within
  :data:`~.model.REPEAT_MARGIN` times the fastest time known to meet it (the pilot's
  runs and the solver's own) is a contender for the recommendation: it is timed
  ``repeats`` times, short ones more (:func:`retimed`), and the fastest of its
  timings kept (a run computes the same thing each time: the load of a shared machine
  only adds time to it), unless it took over :data:`~.model.REPEAT_LIMIT`. Other runs
  cannot be recommended, so a second timing would change no conclusion of the study.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from ..errors import SimulationError
from ..simulation import simulate_model
from .energy import drift, energy_series
from .model import REPEAT_LIMIT, REPEAT_MARGIN, OverBudget, Reference, Run
from .setup import StudySetup, relative_errors

STABLE_SECONDS = 0.2
"""A contender is timed until its timings add up to this (at least ``repeats`` times,
at most :data:`MAX_REPEATS`): a run of a few milliseconds on a loaded machine needs
more than three timings for its fastest to be its cost."""
MAX_REPEATS = 15

Measured = tuple[float, tuple[int, int, int], np.ndarray, str]
"""What one timed run returns: seconds, (steps, RHS, Jacobian evaluations), outputs,
engine ("compiled" or "scipy")."""
Once = Callable[[float], Measured]
"""One run with a budget in seconds (``math.inf``: none)."""


def timed_once(setup: StudySetup, solver: str, setting: str, value: float, once: Once
               ) -> tuple[Run, np.ndarray | None]:
    """``once`` run with the study's budget: its Run (timed once) and outputs."""
    try:
        seconds, (steps, rhs, jacobians), values, engine = once(setup.options.budget)
    except OverBudget:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"over budget (> {setup.options.budget:g} s)"), None
    except SimulationError as err:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"failed: {err.message}"), None
    return Run(solver, setting, value, seconds, 1, steps, rhs, jacobians, math.nan,
               math.nan, engine=engine), values


def retimed(runs: Sequence[tuple[Run, Once]], repeats: int) -> list[Run]:
    """The ``runs`` (each with its ``once``) timed again in rounds, each round timing
    every run once (a change of the machine's load falls on all of them alike): an ok
    run under :data:`REPEAT_LIMIT` is timed ``repeats`` times in all, and a short one
    more, up to :data:`STABLE_SECONDS` of timings or :data:`MAX_REPEATS`; the fastest
    of its times is kept."""
    def wanted(run: Run) -> int:
        if not run.ok or run.wall_time >= REPEAT_LIMIT or repeats <= 1:
            return 1  # the timing it has
        short = math.ceil(STABLE_SECONDS / max(run.wall_time, 1e-9))
        return max(repeats, min(MAX_REPEATS, short))

    times = [[run.wall_time] for run, _ in runs]
    counts = [wanted(run) for run, _ in runs]
    for _ in range(max(counts, default=1) - 1):
        for (_, once), timed, count in zip(runs, times, counts):
            if len(timed) < count:
                timed.append(once(math.inf)[0])
    return [dataclasses.replace(run, wall_time=min(timed), repeats=len(timed))
            if len(timed) > 1 else run for (run, _), timed in zip(runs, times)]


def springc_once(setup: StudySetup, solver: str, rtol: float | None, step: float | None
                 ) -> Once:
    """One run of springc's ``solver`` at ``rtol`` (adaptive) or ``step`` (fixed)."""
    def once(budget: float) -> Measured:
        result = simulate_model(setup.model, setup.sim_options(solver, rtol, step, budget))
        s = result.stats
        return (s.wall_time, (s.steps, s.rhs_evaluations, s.jacobian_evaluations),
                result.values, s.engine)

    return once


def warm_up_solver(setup: StudySetup, solver: str, rtol: float | None,
                   step: float | None) -> tuple[float, str]:
    """Run ``solver`` untimed over the first output interval, so that loading (or
    compiling) its compiled loop is not timed: its seconds and engine ("" if it
    failed: a failure is left to the timed runs to report)."""
    grid = setup.grid
    options = dataclasses.replace(setup.sim_options(solver, rtol, step),
                                  start=float(grid[0]), stop=float(grid[1]),
                                  interval=float(grid[1] - grid[0]))
    began = time.perf_counter()
    try:
        with np.errstate(all="ignore"):
            engine = simulate_model(setup.model, options).stats.engine
    except SimulationError:
        engine = ""
    return time.perf_counter() - began, engine


# ------------------------------------------------------------------ measures

def with_errors(run: Run, values: np.ndarray | None, ref: Reference,
                scales: np.ndarray) -> Run:
    """``run`` with its max and RMS errors against ``ref``."""
    if values is None:
        return run
    worst, rms = relative_errors(values, ref.values, scales)
    if not math.isfinite(worst):
        return dataclasses.replace(run, status="failed: non-finite outputs")
    return dataclasses.replace(run, max_error=worst, rms_error=rms)


def energy_drift(setup: StudySetup, energy: str | None, ref: Reference
                 ) -> Callable[[Run, np.ndarray | None], Run]:
    """A function adding the energy drift to a run (the identity without energy)."""
    if energy is None:
        return lambda run, values: run
    model, p, grid = setup.model, setup.p, setup.grid
    scale = float(np.max(np.abs(energy_series(model, p, grid, ref.values, energy))))

    def add(run: Run, values: np.ndarray | None) -> Run:
        if values is None or not run.ok:
            return run
        series = energy_series(model, p, grid, values, energy)
        return dataclasses.replace(run, energy_drift=drift(series, scale))

    return add


# ------------------------------------------------------------------ contenders

def fastest(runs: Iterable[Run], target: float) -> Run | None:
    """The fastest ok run of ``runs`` meeting ``target`` (max error), if any."""
    good = [r for r in runs if r.ok and r.max_error <= target]
    return min(good, key=lambda r: r.wall_time) if good else None


def contender(run: Run, targets: Sequence[float], known: Sequence[Run]) -> bool:
    """Whether ``run`` meets a target within :data:`REPEAT_MARGIN` times the fastest
    of ``known`` meeting it (see the module text)."""
    for target in targets:
        if run.ok and run.max_error <= target:
            best = fastest(known, target)
            if best is None or run.wall_time <= REPEAT_MARGIN * best.wall_time:
                return True
    return False


def log_line(run: Run) -> str:
    """``dop853 rtol 1e-06: 0.024 s, max error 2.6e-04`` or the run's status."""
    if not run.ok:
        return f"{run.solver} {run.label()}: {run.status}"
    return (f"{run.solver} {run.label()}: {run.wall_time:.3g} s, max error "
            f"{run.max_error:.1e}")
