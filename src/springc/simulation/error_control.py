"""``--error-control tighten|warn|off``: every run estimates its global error and meets
its tolerance, or says so. One run -> the run, its estimate and the verdict.

**The rule.** The estimated error of each output variable ``v`` (:mod:`.error_estimate`:
the largest difference from a companion run over the output grid) must be at most
``FACTOR * (rtol * scale_v + atol)``, where ``scale_v`` is the largest ``|v|`` over the
run and ``rtol``, ``atol`` are the tolerances asked for (:data:`FACTOR` is 10): each
variable is judged on its own scale, as the solver's own error test judges each state.

**The modes.** ``tighten`` (the default): a run whose estimate breaks the rule is run
again :data:`~.error_rules.COMPANION_FACTOR` times tighter (rtol and atol alike) -
its companion already is that run, so it becomes the answer and a new companion
estimates its error - until the rule holds, the run's rtol would pass
:data:`TIGHTEST_RUN_RTOL`, or a companion fails or meets the step or time limit
(``--max-steps`` per run, ``--time-limit`` for all runs together); the summary says
``tightened rtol 1e-6 -> 1e-9: est. error 7.6e-6 <= tolerance 2.9e-4 (...)``, and a
rule still broken is a warning (``SimulationStats.warning``). ``warn``: the estimate
and, where the rule is broken, the warning; no second run. ``off``: no companion, no
estimate (the fast path). A fixed-step run is estimated (Richardson) but has no
tolerance to meet: its step is what was asked.

**What it may cost.** The companions of one run take together at most
:data:`STEP_BUDGET` times the steps of the first run (at least :data:`BUDGET_FLOOR`
steps), counted, never timed: a companion past what is left stops there, and the
answer is the last run estimated or, where a tightened run lost its companion, that
run with the words of the estimate before it (``error not estimated``, a warning). A
tightened run whose estimated error did not fall at least :data:`SHRINK` times below
the estimate of the run before it is not tightened again: its error does not follow
the tolerance (events, kinks), and a tighter run would cost more for little (a
warning says so).

``--error-estimate off|on|auto`` (the option before this one) still works, deprecated:
``off`` is ``off``, ``on`` is ``warn``, ``auto`` is the default ``tighten``.
"""

from __future__ import annotations

import contextlib
import io
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import SpringcError
from .error_estimate import ErrorEstimate, compare
from .error_rules import FACTOR, allowed_errors, companion_tolerances, short
from .settings import (
    RunSettings,
)
from .solver_names import (
    DEFAULT_ERROR_CONTROL,
    ERROR_CONTROLS,
    FIXED_STEP,
    companion_solver,
    registered,
)

if TYPE_CHECKING:
    from .results import SimulationResult, SimulationStats

MODES = ERROR_CONTROLS
DEFAULT_MODE = DEFAULT_ERROR_CONTROL
TIGHTEST_RUN_RTOL = 1e-12
"""``tighten`` runs at no tighter rtol (its companion is then at the solvers' limit)."""
MAX_ROUNDS = 4
"""At most this many estimates (from rtol 1e-3: runs at 1e-6, 1e-9, 1e-12)."""
STEP_BUDGET = 20
"""The companions of one run take at most this many times the first run's steps
(a companion 1000x tighter takes 2.4x the steps of dop853's run on a smooth model, 3-4x
radau's: the ladder 1e-6 -> 1e-9 -> 1e-12 fits on dop853)."""
BUDGET_FLOOR = 20_000
"""... and at least this many steps (a short run's companions are cheap anyway)."""
SHRINK = 10.0
"""A run 1000x tighter whose estimated error (over its tolerance) fell less than this
many times is not tightened again."""


@dataclass
class Budget:
    """The steps error control's companions may still take (:data:`STEP_BUDGET`)."""

    first: int  # the steps of the first run
    left: int

    @classmethod
    def of(cls, steps: int) -> Budget:
        """The budget of a first run of ``steps`` steps."""
        return cls(steps, max(BUDGET_FLOOR, STEP_BUDGET * steps))


@dataclass(frozen=True)
class Asked:
    """What the user asked: the mode and the resolved tolerances the rule uses."""

    mode: str
    rtol: float
    atol: float


Run = Callable[[RunSettings], "SimulationResult"]


def controlled(options: RunSettings, asked: Asked, run: Run) -> SimulationResult:
    """``run(options)``, estimated and tightened as ``asked.mode`` says (module docstring)."""
    began = time.perf_counter()
    rtol, atol = asked.rtol, asked.atol
    result = run(replace(options, rtol=rtol, atol=atol))
    if asked.mode == "off" or not len(result.names):
        return _finish(result, rtol, atol, None, "", "", began)
    budget = Budget.of(result.stats.steps)
    before: tuple[float, ErrorEstimate] | None = None  # the run let go: rtol, estimate
    stalled = False
    for _round in range(MAX_ROUNDS):
        try:
            companion, estimate, tight = _estimate(options, result, rtol, atol, run, began,
                                                   budget)
        except SpringcError as failed:
            return _unestimated(result, asked, rtol, atol, failed.message, before, began)
        if result.stats.solver in FIXED_STEP:
            return _finish(result, rtol, atol, estimate, _words(estimate, "", "fixed"), "",
                           began)
        estimate = replace(estimate, tolerance=np.array(allowed_errors(
            estimate.scales.tolist(), asked.rtol, asked.atol)))
        last = tight[0] < TIGHTEST_RUN_RTOL * 0.999 or _round == MAX_ROUNDS - 1
        stalled = before is not None and not estimate.met and not last and \
            _excess(estimate) > _excess(before[1]) / SHRINK
        if estimate.met or asked.mode == "warn" or last or stalled:
            break
        before = (rtol, estimate)
        # the first run let go before the companion's outputs are computed: a large
        # scene holds one array of every output at a time
        result, first = companion, result.stats
        result, (rtol, atol) = _tightened(first, result), tight
    return _verdict(result, estimate, asked, rtol, atol, began,
                    before if stalled else None)


def _excess(estimate: ErrorEstimate) -> float:
    """How many times its tolerance the worst variable's estimated error is."""
    assert estimate.tolerance is not None
    i = estimate.worst
    return float(estimate.absolute[i] / estimate.tolerance[i])


def _unestimated(result: SimulationResult, asked: Asked, rtol: float, atol: float,
                 why: str, before: tuple[float, ErrorEstimate] | None,
                 began: float) -> SimulationResult:
    """``result`` whose companion failed (``why``): no estimate; where it is a
    tightened run, the words say so and give the estimate of the run before it."""
    why = f"its companion run failed ({why})"
    if before is None:
        return _finish(result, rtol, atol, None, f"error not estimated: {why}",
                       f"the error could not be estimated: {why}", began)
    rtol_before, estimate = before
    i = estimate.worst
    assert estimate.tolerance is not None
    earlier = (f"at rtol {short(rtol_before)} it was {short(estimate.absolute[i])} > "
               f"tolerance {short(estimate.tolerance[i])} ({estimate.names[i]} at t = "
               f"{estimate.times[i]:.4g} s)")
    return _finish(result, rtol, atol, None,
                   f"tightened rtol {short(asked.rtol)} -> {short(rtol)}: error not "
                   f"estimated: {why}; {earlier}",
                   f"the error of the run at rtol {short(rtol)} could not be estimated: "
                   f"{why}; {earlier}", began)


def _estimate(options: RunSettings, result: SimulationResult, rtol: float,
              atol: float, run: Run, began: float, budget: Budget
              ) -> tuple[SimulationResult, ErrorEstimate, tuple[float, float]]:
    """The companion of ``result`` (run at ``rtol``), the estimate, the companion's
    tolerances; the companion gets what is left of the time limit and of ``budget``."""
    solver = result.stats.solver
    left = options.seconds_limit - (time.perf_counter() - began)
    if left <= 0:
        raise SpringcError(f"the time limit of {options.seconds_limit:g} s is reached")
    base = replace(options, progress=None, event_rows=False, time_limit=left,
                   error_control="off", deferred_outputs=True)
    started = time.perf_counter()
    if solver in FIXED_STEP:
        step = float(options.step or 0.0) / 2
        companion = _quiet(run, replace(base, solver=solver, rtol=rtol, atol=atol, step=step),
                           budget)
        gain = 2.0 ** registered(solver).order
        return companion, compare(result, companion, companion.time,
                                  f"Richardson against {solver} at step {step:.3g} s",
                                  gain / (gain - 1), started), (rtol, atol)
    tight = companion_tolerances(rtol, atol)
    chosen = companion_solver(solver)
    companion = _quiet(run, replace(base, solver=chosen, rtol=tight[0], atol=tight[1]),
                       budget)
    return companion, compare(result, companion, companion.time,
                              f"companion {chosen} at rtol {short(tight[0])}", 1.0,
                              started), tight


def _quiet(run: Run, options: RunSettings, budget: Budget) -> SimulationResult:
    """A companion run, its stderr (the warnings of ``assert(..., level = warning)``,
    which the run has printed once already) discarded, within the steps ``budget`` has
    left (which it takes from there)."""
    if budget.left <= 0:
        raise SpringcError(_spent(budget))
    capped = budget.left < options.step_limit
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            companion = run(replace(options, max_steps=min(budget.left, options.step_limit)))
    except SpringcError as failed:
        if capped and "reached the step limit" in failed.message:
            raise SpringcError(_spent(budget)) from failed
        raise
    budget.left -= companion.stats.steps
    return companion


def _spent(budget: Budget) -> str:
    """Why a companion stopped at error control's step budget, in words."""
    return (f"error control's step budget is spent: the companions may take "
            f"{max(BUDGET_FLOOR, STEP_BUDGET * budget.first):,} steps, {STEP_BUDGET:g} x "
            f"the run's {budget.first:,} (at least {BUDGET_FLOOR:,})")


def _tightened(first: SimulationStats, companion: SimulationResult) -> SimulationResult:
    """The companion as the answer, its outputs computed (where they were deferred),
    with the first run's words on why its solver and engine (``auto``'s choice) where
    it ran the same solver."""
    if companion.deferred is not None:
        companion = replace(companion, values=companion.deferred.values(), deferred=None)
    if companion.stats.solver != first.solver:
        return companion
    return replace(companion, stats=replace(companion.stats, reason=first.reason,
                                            engine_reason=first.engine_reason))


def _verdict(result: SimulationResult, estimate: ErrorEstimate, asked: Asked, rtol: float,
             atol: float, began: float, stalled: tuple[float, ErrorEstimate] | None
             ) -> SimulationResult:
    """``result`` with its estimate, the summary's words and, if broken, the warning
    (``stalled``: the rtol and estimate of the run before it, whose error this one's
    did not undercut :data:`SHRINK` times)."""
    tightened = f"tightened rtol {short(asked.rtol)} -> {short(rtol)}: " \
        if rtol != asked.rtol else ""
    words = _words(estimate, tightened, "met" if estimate.met else "broken")
    warning = ""
    if not estimate.met:
        i = estimate.worst
        assert estimate.tolerance is not None
        warning = (f"the estimated error {short(estimate.absolute[i])} of "
                   f"{estimate.names[i]} (at t = {estimate.times[i]:.4g} s) exceeds its "
                   f"tolerance {short(estimate.tolerance[i])} ({FACTOR:g} x (rtol "
                   f"{short(asked.rtol)} x its largest magnitude + atol "
                   f"{short(asked.atol)}))")
        if stalled is not None:
            j = stalled[1].worst
            warning += (f", also at rtol {short(rtol)}; it hardly falls with the "
                        f"tolerance ({short(stalled[1].absolute[j])} of "
                        f"{stalled[1].names[j]} at rtol {short(stalled[0])}): not "
                        f"tightened further")
        else:
            warning += (f", also at rtol {short(rtol)}, the tightest springc tries"
                        if tightened else
                        "; use --error-control tighten (error_control='tighten') or a "
                        "smaller --rtol")
    return _finish(result, rtol, atol, estimate, words, warning, began)


def _words(estimate: ErrorEstimate, tightened: str, verdict: str) -> str:
    """The summary's words: ``est. error 2e-7 <= tolerance 3e-4 (x at t = 1 s; how)``."""
    i = estimate.worst
    where = f"{estimate.names[i]} at t = {estimate.times[i]:.4g} s; {estimate.method}, " \
        f"{estimate.seconds:.3f} s"
    error = f"est. error {short(estimate.absolute[i])}"
    if verdict == "fixed":
        return f"{error} ({where}; a fixed step: no tolerance to meet)"
    assert estimate.tolerance is not None
    sign = "<=" if verdict == "met" else ">"
    return f"{tightened}{error} {sign} tolerance {short(estimate.tolerance[i])} ({where})"


def _finish(result: SimulationResult, rtol: float, atol: float,
            estimate: ErrorEstimate | None, words: str, warning: str,
            began: float) -> SimulationResult:
    """``result`` whose stats record the tolerances used, the estimate and the warning,
    and the wall time of every run."""
    i = estimate.worst if estimate is not None else -1
    stats = replace(result.stats, rtol=rtol, atol=atol, error=words, warning=warning,
                    estimated_error=None if i < 0 or estimate is None
                    else float(estimate.absolute[i]),
                    error_tolerance=None if i < 0 or estimate is None or
                    estimate.tolerance is None else float(estimate.tolerance[i]),
                    wall_time=max(result.stats.wall_time, time.perf_counter() - began))
    return replace(result, stats=stats, error_estimate=estimate)
