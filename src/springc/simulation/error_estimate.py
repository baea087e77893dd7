"""``--error-estimate off|on|auto``: the global error a run reached on its output grid.

An adaptive run is compared with a companion run of the same start at a tolerance
:data:`COMPANION_FACTOR` times tighter (``dop853``, compiled where the module is numba's;
an implicit run's own solver on scipy otherwise): the companion's error is then about a
thousandth of the run's, so ``|x_run - x_companion|`` is the run's error. A fixed-step
run of order ``q`` is compared with the same method at half the step (Richardson):
``error ~ (x_h - x_h/2) 2^q / (2^q - 1)``.

``auto`` estimates where it costs at most :data:`AUTO_BUDGET` of the run so far (the
companion's time predicted from the run's compiled loop: a DOP853 run at a 1000x
tighter tolerance takes ``1000^(1/8)`` ~ 2.4x the steps, a half-step run 2x), so a
warm run whose loop is most of its time is not doubled; ``on`` always estimates.

The estimate is per state: the largest ``|error|`` over the grid, where it occurs,
and that divided by the state's largest magnitude (the relative error, comparable
with ``rtol``); the summary names the state with the largest relative error.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import UsageError
from .solver_names import EXPLICIT, FIXED_STEP, IMPLICIT_SOLVERS, RACE_IMPLICIT

if TYPE_CHECKING:
    from .steps import Problem

MODES = ("off", "on", "auto")
DEFAULT_MODE = "auto"
COMPANION_FACTOR = 1000.0
TIGHTEST_RTOL = 1e-13
AUTO_BUDGET = 0.3
ORDERS = {"symplectic-euler": 1, "verlet": 2, "rk4": 4, "dop853": 8, "radau": 4}
"""Fixed-step methods: the order; adaptive ones: how steps grow with tighter tolerances
(``steps ~ rtol^(-1/q)``: DOP853's error estimator is of order 7, Radau's of order 3)."""


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated global error of each state over the output grid."""

    names: tuple[str, ...]
    absolute: np.ndarray  # largest |error| over the grid, per state
    relative: np.ndarray  # absolute / the state's largest |value| (1 where that is 0)
    times: np.ndarray  # where the largest |error| occurs, per state
    method: str  # how it was estimated, in words
    seconds: float  # what estimating cost

    @property
    def worst(self) -> int:
        """The state with the largest relative error."""
        return int(np.argmax(self.relative)) if len(self.relative) else -1

    @property
    def error(self) -> float:
        """The largest relative error of any state (0 without states)."""
        return float(self.relative.max()) if len(self.relative) else 0.0

    def summary(self) -> str:
        """``estimated error 3.1e-06 (relative; 2.4e-05 in mass.v[1] at t = 3.2 s; ...)``."""
        if not len(self.names):
            return "estimated error 0 (no states)"
        i = self.worst
        return (f"estimated error {self.relative[i]:.2g} (relative; {self.absolute[i]:.2g} "
                f"in {self.names[i]} at t = {self.times[i]:.4g} s; {self.method}, "
                f"{self.seconds:.3f} s)")

    def rows(self) -> list[list[str]]:
        """The side file's table: a header, then one row per state."""
        return [["variable", "max_abs_error", "relative_error", "at_time", "method"],
                *([name, repr(float(a)), repr(float(r)), repr(float(t)), self.method]
                  for name, a, r, t in zip(self.names, self.absolute, self.relative,
                                           self.times))]


def check_mode(mode: str, option: str = "--error-estimate") -> str:
    """``mode`` lowered, or a usage error naming ``option``."""
    name = mode.lower() if isinstance(mode, str) else mode
    if name not in MODES:
        raise UsageError(f"{option} must be one of {', '.join(MODES)}, not {mode!r}",
                         option=option)
    return str(name)


def predicted_cost(solver: str, compiled: bool, loop_time: float) -> float | None:
    """The seconds an estimate should cost, from the run's compiled loop; None where the
    run gives no measure (the estimate would run on scipy: auto leaves it off)."""
    if not compiled or loop_time <= 0:
        return None
    if solver in FIXED_STEP:
        return 2.0 * loop_time
    if solver in (EXPLICIT, RACE_IMPLICIT):
        return float(COMPANION_FACTOR ** (1 / ORDERS[solver]) * loop_time)
    return None


def wanted(mode: str, solver: str, compiled: bool, loop_time: float, elapsed: float) -> bool:
    """Whether to estimate: ``on``, or ``auto`` within :data:`AUTO_BUDGET` of ``elapsed``."""
    if mode == "on":
        return True
    cost = predicted_cost(solver, compiled, loop_time) if mode == "auto" else None
    return cost is not None and cost <= AUTO_BUDGET * elapsed


def estimate(problem: Problem, grid: np.ndarray, x0: np.ndarray, states: np.ndarray,
             solver: str, rtol: float, atol: float, step: float | None,
             compiled: bool) -> ErrorEstimate:
    """The error estimate of a run that produced ``states`` on ``grid`` from ``x0``."""
    began = time.perf_counter()
    if solver in FIXED_STEP:
        assert step is not None
        finer = _fixed_companion(problem, grid, x0, solver, step / 2, compiled)
        gain = 2.0 ** ORDERS[solver]
        error = (states - finer) * gain / (gain - 1)
        method = f"Richardson against {solver} at step {step / 2:.3g} s"
    else:
        tight_rtol, tight_atol = companion_tolerances(rtol, atol)
        companion_solver = solver if solver in IMPLICIT_SOLVERS else EXPLICIT
        reference = _adaptive_companion(problem, grid, x0, companion_solver, tight_rtol,
                                        tight_atol, compiled)
        error = states - reference
        method = f"companion {companion_solver} run at rtol {tight_rtol:.3g}"
    return measured(tuple(problem.names), grid, states, error, method, began)


def companion_tolerances(rtol: float, atol: float) -> tuple[float, float]:
    """The companion run's rtol and atol: :data:`COMPANION_FACTOR` times tighter."""
    tight_rtol = max(rtol / COMPANION_FACTOR, TIGHTEST_RTOL)
    return tight_rtol, atol * tight_rtol / rtol


def measured(names: tuple[str, ...], grid: np.ndarray, values: np.ndarray,
             error: np.ndarray, method: str, began: float) -> ErrorEstimate:
    """The estimate from the ``error`` of each column of ``values`` on ``grid``."""
    magnitude = np.abs(values).max(axis=0)
    absolute = np.abs(error).max(axis=0)
    where = grid[np.abs(error).argmax(axis=0)]
    relative = absolute / np.where(magnitude > 0, magnitude, 1.0)
    return ErrorEstimate(names, absolute, relative, where, method,
                         time.perf_counter() - began)


def _companion_problem(problem: Problem, solver: str) -> Problem:
    from .steps import Problem as StepProblem
    from .steps import Progress

    return StepProblem(problem.model, problem.p, solver, Progress(None, 0.0, 1.0),
                       problem.limits)


def _fixed_companion(problem: Problem, grid: np.ndarray, x0: np.ndarray, solver: str,
                     step: float, compiled: bool) -> np.ndarray:
    from .compiled import run_fixed_compiled
    from .solvers import run_fixed

    companion = _companion_problem(problem, solver)
    if compiled:
        return run_fixed_compiled(companion, grid, x0, step)[0]
    return run_fixed(companion, grid, x0, step)[0]


def _adaptive_companion(problem: Problem, grid: np.ndarray, x0: np.ndarray, solver: str,
                        rtol: float, atol: float, compiled: bool) -> np.ndarray:
    from .compiled import advance_compiled
    from .steps import integrate

    companion = _companion_problem(problem, solver)
    finish = advance_compiled if compiled and solver in (EXPLICIT, RACE_IMPLICIT) else None
    return integrate(companion, grid, x0, rtol, atol, finish).states
