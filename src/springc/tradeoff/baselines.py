"""The scipy baselines of a study -> their runs (:func:`baseline_runs`).

- **scipy's default call** ``solve_ivp(rhs, span, x0, t_eval=grid)`` (RK45, rtol 1e-3,
  atol 1e-6) on the same generated right-hand side, outputs included; every
  recommendation is compared with it, so it is always timed ``repeats`` times.
- **scipy's RK45 tightened**: ``solve_ivp`` RK45 at the study's tolerances below 1e-3
  (atol = rtol/1000), loosest first, until it meets the smallest target; the
  recommendation quotes the first rtol that does. springc's compiled ``rk45`` takes
  the same steps as scipy's RK45 (same method, same controller: the same errors), in
  milliseconds, so it is run first at each rtol as a probe: scipy's RK45 is then run
  at the first rtol the probe says meets the target (or the last, if none does), and
  the looser rtols are listed as skipped with the probe's error. Should scipy's error
  there differ from the probe's (other steps: a hybrid model, say), the sweep starts
  again from the loosest rtol as without a probe.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import SimulationError
from .model import PROBE_SKIP, SCIPY_DEFAULT, SCIPY_RK45, Reference, Run
from .runs import (
    Measured,
    energy_drift,
    log_line,
    retimed,
    springc_once,
    timed_once,
    warm_up_solver,
    with_errors,
)
from .setup import Deadline, StudySetup, relative_errors, scipy_outputs

PROBE = "rk45"
"""springc's compiled method taking scipy RK45's steps."""
PROBE_AGREEMENT = 1e-3
"""Relative difference of scipy's error and the probe's at the same rtol above which
they did not take the same steps: the probe's word is then not taken."""


def _counting_rhs(setup: StudySetup, budget: float) -> tuple[Callable[..., Any], list[int]]:
    mod, p = setup.model.module, setup.p
    z = np.asarray(mod.guesses(p), dtype=float)
    deadline = Deadline(budget)
    count = [0]

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        count[0] += 1
        if count[0] % 64 == 0:
            deadline.check()
        dx: np.ndarray = mod.rhs(t, x, p, z)
        return dx

    return rhs, count


def scipy_once(setup: StudySetup, rtol: float | None) -> Callable[[float], Measured]:
    """``solve_ivp`` RK45 with the generated RHS: scipy's defaults when ``rtol`` is None."""
    from scipy.integrate import solve_ivp

    grid = setup.grid

    def once(budget: float) -> Measured:
        rhs, count = _counting_rhs(setup, budget)
        kwargs = {} if rtol is None else {"rtol": rtol, "atol": rtol * setup.atol_ratio}
        began = time.perf_counter()
        with np.errstate(all="ignore"):
            sol = solve_ivp(rhs, (grid[0], grid[-1]), setup.x0, t_eval=grid, **kwargs)
            if not sol.success or sol.y.shape[1] != len(grid):
                raise SimulationError(f"solve_ivp: {sol.message}")
            values = scipy_outputs(setup.model, setup.p, grid, sol.y.T)
        return time.perf_counter() - began, (-1, count[0], 0), values, "scipy"

    return once


def probe_errors(setup: StudySetup, ref: Reference, scales: np.ndarray,
                 rtols: list[float], goal: float) -> list[float] | None:
    """The max errors of springc's compiled :data:`PROBE` at ``rtols`` (loosest first),
    up to the first that meets ``goal``; None if it does not run compiled (as a short
    run over the first output interval says first) or fails."""
    if warm_up_solver(setup, PROBE, rtols[0], None)[1] != "compiled":
        return None
    errors: list[float] = []
    for rtol in rtols:
        try:
            with np.errstate(all="ignore"):
                _, _, values, engine = springc_once(setup, PROBE, rtol, None)(math.inf)
        except SimulationError:
            return None
        if engine != "compiled":
            return None
        worst, _ = relative_errors(values, ref.values, scales)
        if not math.isfinite(worst):
            return None
        errors.append(worst)
        if worst <= goal:
            break
    return errors


def baseline_runs(setup: StudySetup, ref: Reference, scales: np.ndarray,
                  energy: str | None, log: Callable[[str], None] | None = None
                  ) -> list[Run]:
    """scipy's default call, then RK45 tightened (see the module text)."""
    options = setup.options
    add_drift = energy_drift(setup, energy, ref)

    def measured(name: str, rtol: float | None) -> Run:
        once = scipy_once(setup, rtol)
        run, values = timed_once(setup, name, "rtol", 1e-3 if rtol is None else rtol, once)
        run = add_drift(with_errors(run, values, ref, scales), values)
        if log is not None:
            log(log_line(run))
        return retimed([(run, once)], options.repeats)[0] if rtol is None else run

    default = measured(SCIPY_DEFAULT, None)
    goal = min(options.targets)
    if default.ok and default.max_error <= goal:
        return [default]
    rtols = sorted((t for t in options.tolerances if t < 1e-3), reverse=True)
    probes = probe_errors(setup, ref, scales, rtols, goal) if rtols else None
    done: dict[int, Run] = {}

    def run_at(i: int) -> Run:
        if i not in done:
            done[i] = measured(SCIPY_RK45, rtols[i])
        return done[i]

    start = 0
    if probes is not None:
        start = len(probes) - 1  # the first rtol the probe meets the goal at, or the last
        run = run_at(start)
        if run.ok and abs(run.max_error - probes[start]) > PROBE_AGREEMENT * probes[start]:
            probes, start = None, 0  # not the same steps after all: sweep them all
    i = start
    while i < len(rtols) and run_at(i).ok and not (run_at(i).max_error <= goal):
        i += 1
    first = min(done) if done else len(rtols)
    rows = [default]
    for k in range(first):
        assert probes is not None, "rtols are skipped only on the probe's word"
        rows.append(Run(SCIPY_RK45, "rtol", rtols[k], math.nan, 0, -1, -1, -1, math.nan,
                        math.nan, f"{PROBE_SKIP} ({PROBE} reaches {probes[k]:.1e} > "
                        f"{goal:.0e})"))
    return rows + [done[k] for k in sorted(done)]
