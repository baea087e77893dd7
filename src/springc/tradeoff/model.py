"""The data of a tradeoff study: options in, runs and reference out, and the constants
every other tradeoff module shares. Nothing here computes; :mod:`.study` does.

The order of the package is ``model <- setup <- {reference, timing}``,
``timing <- {chains, baselines}``, ``model <- report``, ``model <- plot``, then
``{reference, energy, chains, baselines} <- study``: no module imports one that
imports it back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TextIO

import numpy as np

from ..errors import SimulationError, UsageError
from ..simulation import OverBudget as OverBudget  # raised by a run past its budget
from ..simulation import check_run_values

DEFAULT_TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
DEFAULT_STEP_DIVISIONS = (2, 4, 8, 16, 32, 64, 128, 256)
"""Default fixed steps: the output interval divided by these."""
DEFAULT_TARGETS = (1e-4,)
REFERENCE_RTOL = 1e-12
SCALE_FLOOR = 1e-6
REPEAT_LIMIT = 2.0
"""Runs longer than this (seconds) are timed once, contenders or not."""
REPEAT_MARGIN = 5.0
"""A run is a contender, timed ``repeats`` times, when it meets a target within this
factor of the fastest time known for it (see :mod:`.timing`)."""
COST_LIMIT = 10.0
"""Default factor of the cost limit: a solver's tighter settings are skipped once one
of its runs takes this many times the pilot's fastest run meeting the targets."""
DEFAULT_BUDGET = 30.0
SCIPY_DEFAULT, SCIPY_RK45 = "scipy-default", "scipy-rk45"
BUDGET_SKIP = "skipped (a looser setting was over budget)"
COST_SKIP = "skipped: cost limit"
"""How the status of a setting skipped by the cost limit starts (:mod:`.chains`)."""
PROBE_SKIP = "skipped: probe"
"""How the status of an rtol of scipy's RK45 skipped on the probe's word starts
(:mod:`.baselines`)."""
CSV_COLUMNS = ("solver", "setting", "value", "wall_time_s", "repeats", "steps",
               "rhs_evaluations", "jacobian_evaluations", "max_error", "rms_error",
               "status", "energy_drift", "engine")


class TradeoffError(SimulationError):
    """The reference is unusable (a CSV that does not match, methods that disagree)."""


def _check_positive(name: str, values: tuple[float, ...] | None, below_one: bool) -> None:
    if values is None:
        return
    if not values:
        raise UsageError(f"{name} is empty", option=name)
    for v in values:
        top = 1.0 if below_one else math.inf
        if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 < v < top):
            kind = "finite numbers in (0, 1)" if below_one else "positive finite numbers"
            raise UsageError(f"{name} must be {kind}, not {v!r}", option=name)


@dataclass(frozen=True)
class TradeoffOptions:
    """What to measure; ``None`` solvers or steps mean the defaults.

    The values are checked here (a :class:`~springc.errors.UsageError` naming the
    field), so a study never starts with settings it cannot run.
    """

    solvers: tuple[str, ...] | None = None
    tolerances: tuple[float, ...] = DEFAULT_TOLERANCES
    steps: tuple[float, ...] | None = None
    targets: tuple[float, ...] = DEFAULT_TARGETS
    reference: str | None = None
    repeats: int = 3
    budget: float = DEFAULT_BUDGET
    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    parameters: Mapping[str, float] = field(default_factory=dict)
    log: TextIO | None = None
    energy: str | None = None  # None: the only variable in J, if any
    cost_limit: float = COST_LIMIT  # math.inf: every setting of every solver is run

    def __post_init__(self) -> None:
        _check_positive("tolerances", self.tolerances, below_one=True)
        _check_positive("steps", self.steps, below_one=False)
        _check_positive("targets", self.targets, below_one=False)
        if isinstance(self.repeats, bool) or not isinstance(self.repeats, int) \
                or self.repeats < 1:
            raise UsageError(f"repeats must be an integer >= 1, not {self.repeats!r}",
                             option="repeats")
        if not (isinstance(self.budget, (int, float)) and self.budget > 0
                and not math.isnan(self.budget)):
            raise UsageError(f"budget must be a positive number of seconds, not "
                             f"{self.budget!r}", option="budget")
        if not (isinstance(self.cost_limit, (int, float)) and self.cost_limit >= 1):
            raise UsageError(f"cost_limit must be a factor of at least 1 (inf: no limit), "
                             f"not {self.cost_limit!r}", option="cost_limit")
        check_run_values(self.start, self.stop, self.interval)


@dataclass(frozen=True)
class Run:
    """One solver at one setting (``rtol`` or ``step``); errors are NaN unless ok."""

    solver: str
    setting: str
    value: float
    wall_time: float
    repeats: int
    steps: int  # -1: not known (scipy's solve_ivp does not report it)
    rhs_evaluations: int
    jacobian_evaluations: int
    max_error: float
    rms_error: float
    status: str = "ok"
    energy_drift: float = math.nan  # see springc.tradeoff.energy
    engine: str = ""  # the step loop that ran it: "compiled" or "scipy" ("": not run)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def label(self) -> str:
        """``rtol 1e-06`` or ``step 0.005``."""
        return f"rtol {self.value:.0e}" if self.setting == "rtol" else f"step {self.value:.3g}"


@dataclass(frozen=True)
class Reference:
    """The trajectory the runs are measured against (on the study's output grid)."""

    time: np.ndarray
    names: tuple[str, ...]
    values: np.ndarray
    description: str
    agreement: float  # max relative difference of the two methods (NaN: a user file)


@dataclass(frozen=True)
class Tradeoff:
    """The result of a study; :func:`springc.tradeoff.report.recommendations` reads it."""

    model: str
    states: int
    reference: Reference
    scales: np.ndarray
    runs: tuple[Run, ...]
    baselines: tuple[Run, ...]
    targets: tuple[float, ...]
    energy: str | None = None
    cost_limit: str = ""  # "10x the fastest dop853 run meeting ...": what it measures
    pilot: str = ""  # the solver run first (:mod:`.chains`)
