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
    for _round in range(MAX_ROUNDS):
        try:
            companion, estimate, tight = _estimate(options, result, rtol, atol, run, began)
        except SpringcError as failed:
            why = f"its companion run failed ({failed.message})"
            return _finish(result, rtol, atol, None, f"error not estimated: {why}",
                           f"the error could not be estimated: {why}", began)
        if result.stats.solver in FIXED_STEP:
            return _finish(result, rtol, atol, estimate, _words(estimate, "", "fixed"), "",
                           began)
        estimate = replace(estimate, tolerance=np.array(allowed_errors(
            estimate.scales.tolist(), asked.rtol, asked.atol)))
        if (estimate.met or asked.mode == "warn" or tight[0] < TIGHTEST_RUN_RTOL * 0.999
                or _round == MAX_ROUNDS - 1):
            break
        # the first run let go before the companion's outputs are computed: a large
        # scene holds one array of every output at a time
        result, first = companion, result.stats
        result, (rtol, atol) = _tightened(first, result), tight
    return _verdict(result, estimate, asked, rtol, atol, began)


def _estimate(options: RunSettings, result: SimulationResult, rtol: float,
              atol: float, run: Run, began: float
              ) -> tuple[SimulationResult, ErrorEstimate, tuple[float, float]]:
    """The companion of ``result`` (run at ``rtol``), the estimate, the companion's
    tolerances; the companion gets what is left of the time limit."""
    solver = result.stats.solver
    left = options.seconds_limit - (time.perf_counter() - began)
    if left <= 0:
        raise SpringcError(f"the time limit of {options.seconds_limit:g} s is reached")
    base = replace(options, progress=None, event_rows=False, time_limit=left,
                   error_control="off", deferred_outputs=True)
    started = time.perf_counter()
    if solver in FIXED_STEP:
        step = float(options.step or 0.0) / 2
        companion = _quiet(run, replace(base, solver=solver, rtol=rtol, atol=atol, step=step))
        gain = 2.0 ** registered(solver).order
        return companion, compare(result, companion, companion.time,
                                  f"Richardson against {solver} at step {step:.3g} s",
                                  gain / (gain - 1), started), (rtol, atol)
    tight = companion_tolerances(rtol, atol)
    chosen = companion_solver(solver)
    companion = _quiet(run, replace(base, solver=chosen, rtol=tight[0], atol=tight[1]))
    return companion, compare(result, companion, companion.time,
                              f"companion {chosen} at rtol {short(tight[0])}", 1.0,
                              started), tight


def _quiet(run: Run, options: RunSettings) -> SimulationResult:
    """A companion run, its stderr (the warnings of ``assert(..., level = warning)``,
    which the run has printed once already) discarded."""
    with contextlib.redirect_stderr(io.StringIO()):
        return run(options)


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
             atol: float, began: float) -> SimulationResult:
    """``result`` with its estimate, the summary's words and, if broken, the warning."""
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
