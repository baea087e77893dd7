"""Guards of a simulation run: parameters, step count, wall clock, output values.

- :func:`check_parameters`: every parameter value is finite before the run starts
  (``--set g=nan`` names ``g`` instead of failing somewhere inside the solver).
- :class:`Limits`: at most ``max_steps`` integrator steps (``--max-steps``, default
  :data:`DEFAULT_MAX_STEPS`) and ``time_limit`` seconds of wall clock
  (``--time-limit``, default :data:`DEFAULT_TIME_LIMIT`), both owned by
  :class:`~.settings.RunSettings` and resolved into the run's plan; and a ``budget``
  (tradeoff's ``--budget``): past it a run raises :class:`OverBudget`, which is not an
  error but a verdict its caller records. A run whose current step
  size projects more than :data:`HOPELESS` times ``max_steps`` stops at once (k = 1e29
  on the seed: 1e15 steps to go) rather than after the full budget.
  :func:`over_limit` writes the error: the time reached, the stiffness seen (the
  spectral radius of the Jacobian there) and a suggested solver.
- :func:`check_outputs`: no NaN or infinity reaches the output; the first is reported
  with its variable and time.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import Note, SimulationError
from .settings import DEFAULT_MAX_STEPS, DEFAULT_TIME_LIMIT
from .solver_names import IMPLICIT_SOLVERS
from .stiffness import STIFF_THRESHOLD, spectral_radius

__all__ = ["CHECK_EVERY", "DEFAULT_MAX_STEPS", "DEFAULT_TIME_LIMIT", "HOPELESS", "Limits",
           "OverBudget", "OverLimit", "check_outputs", "check_parameters", "over_limit",
           "projected_steps"]
HOPELESS = 100
"""A run stops early when its current step size needs this many times ``max_steps``."""
CHECK_EVERY = 1000
"""Steps between two projections of the steps still needed."""


@dataclass(frozen=True)
class Limits:
    """What a run may cost; :meth:`check` is called by the step loops."""

    max_steps: int = DEFAULT_MAX_STEPS
    time_limit: float = DEFAULT_TIME_LIMIT
    budget: float = math.inf  # seconds; checked with the progress updates (steps.Progress)

    def validate(self) -> None:
        """Errors name the option."""
        if not (isinstance(self.max_steps, int) and self.max_steps > 0):
            raise SimulationError(f"--max-steps must be a positive integer, not "
                                  f"{self.max_steps!r}")
        if not (self.time_limit > 0):
            raise SimulationError(f"--time-limit must be a positive number of seconds, "
                                  f"not {self.time_limit!r}")


class OverBudget(Exception):
    """Raised from inside a run that has taken longer than its :attr:`Limits.budget`
    (checked where the progress bar is updated: from the run's first second on, ten
    times a second); not an error: the caller (tradeoff) records the run as over budget."""


class OverLimit(Exception):
    """Raised inside the step loop when a run exceeds its :class:`Limits`."""

    def __init__(self, reason: str, t: float, y: np.ndarray, solver: str) -> None:
        super().__init__(reason)
        self.reason, self.t, self.y, self.solver = reason, t, y, solver


def projected_steps(taken: int, t: float, stop: float, sizes: Sequence[float]) -> float:
    """``taken`` plus the steps to ``stop`` at the median of the recent step ``sizes``."""
    if not sizes:
        return float(taken)
    h = float(np.median(sizes))
    return math.inf if h <= 0 else taken + (stop - t) / h


def over_limit(error: OverLimit, start: float, stop: float,
               jacobian: Callable[[float, np.ndarray], Any] | None) -> SimulationError:
    """The error of a run stopped by its limits: time, stiffness, a suggested solver."""
    rho = None
    if jacobian is not None:
        try:
            with np.errstate(all="ignore"):
                rho = spectral_radius(jacobian(error.t, error.y))
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):
            rho = None
    notes = [Note(f"reached time {error.t:.9g} of {stop:g} "
                  f"({100 * (error.t - start) / (stop - start):.3g} % of the span)")]
    remaining = stop - error.t
    stiff = rho is not None and math.isfinite(rho) and rho * remaining > STIFF_THRESHOLD
    if rho is not None:
        scale = f"fastest time scale 1/rho = {1 / rho:.3g} s" if rho > 0 else "no dynamics"
        notes.append(Note(f"stiffness there: spectral radius of the Jacobian rho = "
                          f"{rho:.3g} 1/s ({scale}; rho*T = {rho * remaining:.3g} over the "
                          f"remaining {remaining:g} s)"))
    if stiff and error.solver not in IMPLICIT_SOLVERS:
        hint = "the system is stiff: use --solver radau (or bdf)"
    elif stiff:
        hint = (f"the fast dynamics are excited, so even {error.solver} must resolve them: "
                "check the parameters (a stiffness or mass off by orders of magnitude?), "
                "loosen --rtol, or raise --max-steps / --time-limit")
    else:
        hint = ("the run is long rather than stiff: raise --max-steps / --time-limit, "
                "loosen --rtol, or use --solver dop853")
    return SimulationError(f"the simulation stopped at time {error.t:.9g}: {error.reason}",
                           notes=notes, hint=hint)


def check_parameters(names: Sequence[str], values: np.ndarray) -> None:
    """Raise unless every parameter value is finite, naming the first ones that are not."""
    bad = [i for i in range(len(values)) if not math.isfinite(values[i])]
    if not bad:
        return
    shown = ", ".join(f"'{names[i]}' = {_word(values[i])}" for i in bad[:4])
    more = f" and {len(bad) - 4} more" if len(bad) > 4 else ""
    raise SimulationError(f"parameter {shown}{more}: parameters must be finite numbers",
                          hint=f"give {names[bad[0]]} a finite value (--set "
                          f"{names[bad[0]]}=...), or fix the binding it follows")


def check_outputs(names: Sequence[str], grid: np.ndarray, values: np.ndarray) -> None:
    """Raise at the first output time where a value is NaN or infinite (the rows
    checked :data:`CHECKED_ROWS` at a time: no mask as large as a large scene's result)."""
    for begin in range(0, len(values), CHECKED_ROWS):
        finite = np.isfinite(values[begin:begin + CHECKED_ROWS])
        if not finite.all():
            _not_finite(names, grid[begin:], values[begin:], finite)


CHECKED_ROWS = 16
"""Rows of a result checked for NaN and infinities at a time."""


def _not_finite(names: Sequence[str], grid: np.ndarray, values: np.ndarray,
                finite: np.ndarray) -> None:
    """Raise at the first row of ``finite`` (the mask of the first rows of ``values``)
    with a value that is not finite."""
    row = int(np.flatnonzero(~finite.all(axis=1))[0])
    columns = np.flatnonzero(~finite[row])
    shown = ", ".join(f"{names[j]} = {_word(values[row, j])}" for j in columns[:4])
    raise SimulationError(
        f"{names[columns[0]]} is {_word(values[row, columns[0]])} at time "
        f"{grid[row]:.9g}", notes=[Note(f"non-finite at that time: {shown}")],
        hint="the model leaves the domain of an operation there (or overflows); check "
             "the parameters (--set) and start values, or guard the expression")


def _word(value: float) -> str:
    return "NaN" if math.isnan(value) else ("infinite" if math.isinf(value) else f"{value:g}")
