"""Accuracy versus cost: CompiledModel + TradeoffOptions -> Tradeoff (a table of runs,
the reference they are measured against, scipy baselines, recommendations).

For each solver and tolerance (step size for the fixed-step methods) the model is
simulated by :func:`springc.simulation.simulate_model` and the table records the wall
time, the steps, the RHS and Jacobian evaluations, and the error on the output grid:

- **Error.** Variable ``j`` at output time ``t_i`` is off by
  ``|y_j(t_i) - ref_j(t_i)| / scale_j``, where ``scale_j = max_i |ref_j(t_i)|`` floored
  at :data:`SCALE_FLOOR` (1e-6) times the largest scale among the compared variables
  of the same unit (so a variable that stays near zero, such as a velocity at rest,
  does not turn round-off into a large relative error). *max error* is the largest
  over times and variables, *RMS error* the root mean square over both.
- **Reference.** A CSV with the same times and (at least) the compared names, or a
  tight solve: springc's ``dop853`` at rtol :data:`REFERENCE_RTOL`, verified by a
  different method (scipy's VODE in Adams mode, a variable-order multistep method with
  no Jacobian, so it suits any size) at the same tolerance. Their difference, in the
  error measure above, is reported; if it exceeds the smallest target error the
  reference is refused.
- **Time.** Wall time of ``simulate_model`` (integration and outputs, not compilation),
  the median of ``repeats`` runs; runs longer than :data:`REPEAT_LIMIT` are timed once.
  A run longer than ``budget`` seconds is stopped, and the solver's tighter settings
  are skipped.
- **Baselines.** scipy's default call ``solve_ivp(rhs, span, x0, t_eval=grid)`` (RK45,
  rtol 1e-3, atol 1e-6) on the same generated right-hand side, timed the same way
  (observed outputs included), and ``solve_ivp`` RK45 at the requested tolerances
  (atol = rtol/1000), loosest first, until it reaches the smallest target.
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, TextIO

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel
from ..simulation import (
    FIXED_STEP,
    LSODA_LIMIT,
    SOLVERS,
    SimulationOptions,
    initial_state,
    output_grid,
    resolve,
    simulate_model,
)
from .energy import drift, energy_series, energy_variable

DEFAULT_TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
DEFAULT_STEP_DIVISIONS = (2, 4, 8, 16, 32, 64, 128, 256)
"""Default fixed steps: the output interval divided by these."""
DEFAULT_TARGETS = (1e-4,)
REFERENCE_RTOL = 1e-12
SCALE_FLOOR = 1e-6
REPEAT_LIMIT = 2.0
DEFAULT_BUDGET = 30.0
SCIPY_DEFAULT, SCIPY_RK45 = "scipy-default", "scipy-rk45"
CSV_COLUMNS = ("solver", "setting", "value", "wall_time_s", "repeats", "steps",
               "rhs_evaluations", "jacobian_evaluations", "max_error", "rms_error",
               "status", "energy_drift")


class TradeoffError(SimulationError):
    """The reference is unusable (a CSV that does not match, methods that disagree)."""


@dataclass(frozen=True)
class TradeoffOptions:
    """What to measure; ``None`` solvers or steps mean the defaults."""

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
    energy_drift: float = math.nan  # see springc.tradeoff_energy

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def label(self) -> str:
        """``rtol 1e-06`` or ``step 0.005``."""
        return f"rtol {self.value:.0e}" if self.setting == "rtol" else f"step {self.value:.3g}"


@dataclass(frozen=True)
class Reference:
    time: np.ndarray
    names: tuple[str, ...]
    values: np.ndarray
    description: str
    agreement: float  # max relative difference of the two methods (NaN: a user file)


@dataclass(frozen=True)
class Tradeoff:
    model: str
    states: int
    reference: Reference
    scales: np.ndarray
    runs: tuple[Run, ...]
    baselines: tuple[Run, ...]
    targets: tuple[float, ...]
    energy: str | None = None

    def recommendations(self) -> list[str]:
        """One line per target (:func:`springc.tradeoff_table.recommend`)."""
        from .report import recommend

        return [recommend(self.runs, self.baselines, t) for t in self.targets]


# ------------------------------------------------------------------ solvers

def compare_states(model: CompiledModel) -> CompiledModel:
    """``model`` with its states as the compared outputs (the default of the study)."""
    return dataclasses.replace(model, outputs=model.states)


def fixed_step_solvers() -> tuple[str, ...]:
    """The fixed-step methods (they need ``SimulationOptions.step``)."""
    return FIXED_STEP


def available_solvers() -> tuple[str, ...]:
    """Every solver the study can run: the adaptive ones, then the fixed-step ones."""
    return (*SOLVERS, *FIXED_STEP)


def check_solvers(names: Sequence[str]) -> tuple[str, ...]:
    known = available_solvers()
    for name in names:
        if name not in known:
            raise TradeoffError(f"unknown solver '{name}'",
                                hint=f"choose from {', '.join(known)}")
    return tuple(names)


# ------------------------------------------------------------------ errors

def variable_scales(values: np.ndarray, units: Sequence[str]) -> np.ndarray:
    """``max |value|`` over time per column, floored per unit (see the module text)."""
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

class OverBudget(Exception):
    """Raised from inside a run that has taken longer than its budget."""


class _Deadline:
    """A progress stream that ends the run: ``simulate_model`` writes progress to it
    about ten times a second once a run has taken a second, and past the deadline the
    write raises :class:`OverBudget` (a time limit in SimulationOptions would be
    cleaner)."""

    def __init__(self, seconds: float) -> None:
        self.end = time.perf_counter() + seconds

    def check(self) -> None:
        if time.perf_counter() > self.end:
            raise OverBudget

    def write(self, text: str) -> int:
        self.check()
        return len(text)

    def flush(self) -> None:
        pass


# ------------------------------------------------------------------ the study

@dataclass
class _Setup:
    model: CompiledModel
    options: TradeoffOptions
    grid: np.ndarray
    atol_ratio: float
    p: np.ndarray
    x0: np.ndarray
    units: tuple[str, ...]

    def sim_options(self, solver: str, rtol: float | None = None, step: float | None = None,
                    progress: Any = None) -> SimulationOptions:
        o = self.options
        return SimulationOptions(o.start, o.stop, o.interval, solver, rtol,
                                 None if rtol is None else rtol * self.atol_ratio,
                                 dict(o.parameters), progress, step)

    def log(self, text: str) -> None:
        if self.options.log is not None:
            self.options.log.write(text + "\n")
            self.options.log.flush()


def _setup(model: CompiledModel, options: TradeoffOptions) -> _Setup:
    base = SimulationOptions(options.start, options.stop, options.interval,
                             parameters=dict(options.parameters))
    start, stop, interval, rtol, atol = resolve(model, base)
    p = np.asarray(model.module.parameters(dict(options.parameters)), dtype=float)
    units = dict(zip(model.states, model.module.STATE_UNITS))
    units.update(zip(model.observed, model.module.OBSERVED_UNITS))
    return _Setup(model, options, output_grid(start, stop, interval), atol / rtol, p,
                  initial_state(model, p, start),
                  tuple(units.get(n, "") for n in model.outputs))


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
        mod.observed_grid(np.zeros(1), np.ascontiguousarray(x0[None, :]), p, z)


def _timed(setup: _Setup, solver: str, setting: str, value: float,
           once: Callable[[float], Any]) -> tuple[Run, Any]:
    """Run ``once(budget)`` (it returns (seconds, stats, values)), repeat if short."""
    try:
        seconds, stats, values = once(setup.options.budget)
    except OverBudget:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"over budget (> {setup.options.budget:g} s)"), None
    except SimulationError as err:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"failed: {err.message}"), None
    times = [seconds]
    while seconds < REPEAT_LIMIT and len(times) < setup.options.repeats:
        times.append(once(math.inf)[0])
    return Run(solver, setting, value, statistics.median(times), len(times), *stats,
               math.nan, math.nan), values


def _springc_run(setup: _Setup, solver: str, rtol: float | None,
                 step: float | None) -> tuple[Run, np.ndarray | None]:
    def once(budget: float) -> tuple[float, tuple[int, int, int], np.ndarray]:
        deadline = _Deadline(budget) if math.isfinite(budget) else None
        result = simulate_model(setup.model, setup.sim_options(solver, rtol, step, deadline))
        s = result.stats
        return s.wall_time, (s.steps, s.rhs_evaluations, s.jacobian_evaluations), result.values

    setting, value = ("rtol", rtol) if step is None else ("step", step)
    return _timed(setup, solver, setting, float(value), once)  # type: ignore[arg-type]


def scipy_outputs(model: CompiledModel, p: np.ndarray, grid: np.ndarray,
                  states: np.ndarray) -> np.ndarray:
    """The compared outputs (``model.outputs``) from states on the grid."""
    columns = {s: states[:, i] for i, s in enumerate(model.states)}
    observed = set(model.observed)
    if any(n in observed for n in model.outputs):
        z = np.asarray(model.module.guesses(p), dtype=float)
        obs = model.module.observed_grid(grid, np.ascontiguousarray(states), p, z)
        columns.update({o: obs[:, i] for i, o in enumerate(model.observed)})
    return np.column_stack([columns[n] for n in model.outputs]) if model.outputs \
        else np.empty((len(grid), 0))


def _counting_rhs(setup: _Setup, budget: float) -> tuple[Callable[..., Any], list[int]]:
    mod, p = setup.model.module, setup.p
    z = np.asarray(mod.guesses(p), dtype=float)
    deadline = _Deadline(budget)
    count = [0]

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        count[0] += 1
        if count[0] % 64 == 0:
            deadline.check()
        return mod.rhs(t, x, p, z)

    return rhs, count


def _scipy_run(setup: _Setup, rtol: float | None) -> tuple[Run, np.ndarray | None]:
    """``solve_ivp`` RK45 with the generated RHS: scipy's defaults when ``rtol`` is None."""
    from scipy.integrate import solve_ivp

    grid = setup.grid

    def once(budget: float) -> tuple[float, tuple[int, int, int], np.ndarray]:
        rhs, count = _counting_rhs(setup, budget)
        kwargs = {} if rtol is None else {"rtol": rtol, "atol": rtol * setup.atol_ratio}
        began = time.perf_counter()
        with np.errstate(all="ignore"):
            sol = solve_ivp(rhs, (grid[0], grid[-1]), setup.x0, t_eval=grid, **kwargs)
            if not sol.success or sol.y.shape[1] != len(grid):
                raise SimulationError(f"solve_ivp: {sol.message}")
            values = scipy_outputs(setup.model, setup.p, grid, sol.y.T)
        return time.perf_counter() - began, (-1, count[0], 0), values

    if rtol is None:
        return _timed(setup, SCIPY_DEFAULT, "rtol", 1e-3, once)
    return _timed(setup, SCIPY_RK45, "rtol", rtol, once)


def _with_errors(run: Run, values: np.ndarray | None, ref: Reference,
                 scales: np.ndarray) -> Run:
    if values is None:
        return run
    worst, rms = relative_errors(values, ref.values, scales)
    if not math.isfinite(worst):
        return dataclasses.replace(run, status="failed: non-finite outputs")
    return dataclasses.replace(run, max_error=worst, rms_error=rms)


def run_tradeoff(model: CompiledModel, options: TradeoffOptions) -> Tradeoff:
    """Measure every solver at every setting against the reference (see module text)."""
    from .reference import read_reference, tight_reference

    setup = _setup(model, options)
    solvers = check_solvers(options.solvers if options.solvers is not None
                            else available_solvers())
    with np.errstate(all="ignore"):
        warm_up(model, setup.p, setup.x0)
    # Step 1: the reference and the scales of the compared variables.
    if options.reference:
        ref = read_reference(options.reference, setup.grid, model.outputs)
    else:
        ref = tight_reference(setup, min(options.targets))
    scales = variable_scales(ref.values, setup.units)
    setup.log(f"reference: {ref.description}")
    energy = energy_variable(model, options.energy)
    with_energy = _energy_drift(setup, energy, ref)
    # Step 2: every solver, loosest setting first, until one is over budget.
    runs: list[Run] = []
    fixed = set(fixed_step_solvers())
    interval = float(setup.grid[1] - setup.grid[0]) if len(setup.grid) > 1 else 1.0
    steps = options.steps or tuple(interval / d for d in DEFAULT_STEP_DIVISIONS)
    for solver in solvers:
        settings = sorted(steps if solver in fixed else options.tolerances, reverse=True)
        skip = False
        for value in settings:
            if skip:
                runs.append(Run(solver, "step" if solver in fixed else "rtol", value,
                                math.nan, 0, -1, -1, -1, math.nan, math.nan,
                                "skipped (a looser setting was over budget)"))
                continue
            run, values = _springc_run(setup, solver, None if solver in fixed else value,
                                       value if solver in fixed else None)
            run = with_energy(_with_errors(run, values, ref, scales), values)
            runs.append(run)
            setup.log(_log_line(run))
            skip = run.status.startswith("over budget")
    # Step 3: scipy's default call, then RK45 tightened until it reaches the targets.
    base, values = _scipy_run(setup, None)
    baselines = [with_energy(_with_errors(base, values, ref, scales), values)]
    setup.log(_log_line(baselines[0]))
    goal = min(options.targets)
    if not (baselines[0].ok and baselines[0].max_error <= goal):
        for rtol in sorted((t for t in options.tolerances if t < 1e-3), reverse=True):
            run, values = _scipy_run(setup, rtol)
            run = with_energy(_with_errors(run, values, ref, scales), values)
            baselines.append(run)
            setup.log(_log_line(run))
            if not run.ok or run.max_error <= goal:
                break
    return Tradeoff(model.name, len(model.states), ref, scales, tuple(runs),
                    tuple(baselines), tuple(options.targets), energy)


def _energy_drift(setup: _Setup, energy: str | None, ref: Reference
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


def _log_line(run: Run) -> str:
    if not run.ok:
        return f"{run.solver} {run.label()}: {run.status}"
    return (f"{run.solver} {run.label()}: {run.wall_time:.3g} s, max error "
            f"{run.max_error:.1e}")
