"""The setting of a study: CompiledModel + TradeoffOptions -> StudySetup (the output
grid, parameters, start state, units: the plan of the simulator, resolved once), and the
measures shared by the runs and the reference: the per-variable scales, the relative
errors, the compared outputs of a scipy solve, and the deadline of the scipy baselines
(springc's own runs carry the budget in their settings: ``RunSettings.budget``).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..pipeline import CompiledModel
from ..simulation import LSODA_LIMIT, RunSettings, initial_state, observed_on_grid, plan
from .model import SCALE_FLOOR, OverBudget, TradeoffOptions

# ------------------------------------------------------------------ errors

def variable_scales(values: np.ndarray, units: Sequence[str]) -> np.ndarray:
    """``max |value|`` over time per column, floored per unit at
    :data:`SCALE_FLOOR` times the largest peak of that unit (see :mod:`.study`)."""
    peak = np.max(np.abs(values), axis=0) if len(values) else np.zeros(len(units))
    scales = peak.copy()
    for unit in set(units):
        cols = np.array([u == unit for u in units])
        floor = SCALE_FLOOR * float(np.max(peak[cols]))
        scales[cols] = np.maximum(peak[cols], floor)
    scales[~(scales > 0)] = 1.0  # all zero (or NaN): compare absolutely
    return scales


def relative_errors(values: np.ndarray, reference: np.ndarray,
                    scales: np.ndarray) -> tuple[float, float]:
    """(max, RMS) of ``|values - reference| / scales`` over times and variables."""
    err = np.abs(values - reference) / scales
    if err.size == 0:
        return 0.0, 0.0
    if not np.isfinite(err).all():
        return math.inf, math.inf
    return float(err.max()), float(np.sqrt(np.mean(err * err)))


# ------------------------------------------------------------------ budget

class Deadline:
    """The budget of a scipy baseline (:mod:`.baselines`, which calls ``solve_ivp``
    itself): :meth:`check` raises :class:`OverBudget` past it. (springc's runs stop
    themselves: their settings carry the budget.)"""

    def __init__(self, seconds: float) -> None:
        self.end = time.perf_counter() + seconds

    def check(self) -> None:
        if time.perf_counter() > self.end:
            raise OverBudget

    def write(self, text: str) -> int:
        """:meth:`check`, as a stream's write (the check of a progress update)."""
        self.check()
        return len(text)


# ------------------------------------------------------------------ the study

@dataclass(frozen=True)
class StudySetup:
    """What every run of a study shares: the model, the options, the output grid, the
    parameter vector ``p``, the start state ``x0`` and the units of the compared outputs."""

    model: CompiledModel
    options: TradeoffOptions
    grid: np.ndarray
    atol_ratio: float
    p: np.ndarray
    x0: np.ndarray
    units: tuple[str, ...]

    def sim_options(self, solver: str, rtol: float | None = None, step: float | None = None,
                    budget: float = math.inf) -> RunSettings:
        """The simulator's settings for one run (atol in the study's ratio to rtol; the
        engine is the simulator's default: the compiled loop for a numba module and a
        solver that has one); past ``budget`` seconds the run raises ``OverBudget``.
        ``error_control`` is off: the study measures each run's error itself against
        its reference, and a run tightened behind its back would no longer be the
        setting its row names."""
        o = self.options
        return RunSettings(start=o.start, stop=o.stop, interval=o.interval, solver=solver,
                           rtol=rtol, atol=None if rtol is None else rtol * self.atol_ratio,
                           parameters=dict(o.parameters), step=step, budget=budget,
                           error_control="off")

    def log(self, text: str) -> None:
        """A line on the study's log stream, if any."""
        if self.options.log is not None:
            self.options.log.write(text + "\n")
            self.options.log.flush()


def study_setup(model: CompiledModel, options: TradeoffOptions) -> StudySetup:
    """The setup of a study of ``model``: times and tolerances resolved as the simulator
    resolves them (options, then the experiment annotation, then the defaults)."""
    planned = plan(model, RunSettings(start=options.start, stop=options.stop,
                                      interval=options.interval,
                                      parameters=dict(options.parameters)))
    x0 = planned.x0  # the switching driver solves its own start: the module's here
    if x0 is None:
        x0 = initial_state(model, planned.p, planned.start, planned.starts)
    units = model.units
    return StudySetup(model, options, planned.grid, planned.atol / planned.rtol, planned.p,
                      x0, tuple(units.get(n, "") for n in model.outputs))


def warm_up(model: CompiledModel, p: np.ndarray, x0: np.ndarray) -> None:
    """Call the generated functions once, so that just-in-time compilation (numba)
    is not timed as part of the first run that needs them."""
    mod = model.module
    z = np.asarray(mod.guesses(p), dtype=float)
    for name in ("rhs", "jacobian", "jacobian_dense"):
        if name == "jacobian_dense" and len(x0) > LSODA_LIMIT:
            continue
        func = getattr(mod, name, None)
        if func is not None:
            func(0.0, x0, p, z)
    if model.observed:
        observed_on_grid(mod, np.zeros(1), np.ascontiguousarray(x0[None, :]), p, z)


def scipy_outputs(model: CompiledModel, p: np.ndarray, grid: np.ndarray,
                  states: np.ndarray) -> np.ndarray:
    """The compared outputs (``model.outputs``) from states on the grid."""
    columns = {s: states[:, i] for i, s in enumerate(model.states)}
    observed = set(model.observed)
    if any(n in observed for n in model.outputs):
        z = np.asarray(model.module.guesses(p), dtype=float)
        obs = observed_on_grid(model.module, grid, np.ascontiguousarray(states), p, z)
        columns.update({o: obs[:, i] for i, o in enumerate(model.observed)})
    return np.column_stack([columns[n] for n in model.outputs]) if model.outputs \
        else np.empty((len(grid), 0))
