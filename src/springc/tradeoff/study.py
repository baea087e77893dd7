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
import functools
import math
import os
import statistics
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..errors import SimulationError
from ..pipeline import CompiledModel, CompileOptions, compile_files
from ..simulation import FIXED_STEP, SOLVERS, simulate_model
from .energy import drift, energy_series, energy_variable
from .model import (
    DEFAULT_STEP_DIVISIONS,
    REPEAT_LIMIT,
    SCIPY_DEFAULT,
    SCIPY_RK45,
    OverBudget,
    Reference,
    Run,
    Tradeoff,
    TradeoffError,
    TradeoffOptions,
)
from .reference import read_reference, tight_reference
from .setup import (
    Deadline,
    StudySetup,
    relative_errors,
    scipy_outputs,
    study_setup,
    variable_scales,
    warm_up,
)

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


Measured = tuple[float, tuple[int, int, int], np.ndarray]
"""What one timed run returns: seconds, (steps, RHS, Jacobian evaluations), outputs."""


def _timed(setup: StudySetup, solver: str, setting: str, value: float,
           once: Callable[[float], Measured]) -> tuple[Run, np.ndarray | None]:
    """Run ``once(budget)`` (it returns (seconds, stats, values)), repeat if short."""
    try:
        seconds, (steps, rhs, jacobians), values = once(setup.options.budget)
    except OverBudget:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"over budget (> {setup.options.budget:g} s)"), None
    except SimulationError as err:
        return Run(solver, setting, value, math.nan, 1, -1, -1, -1, math.nan, math.nan,
                   f"failed: {err.message}"), None
    times = [seconds]
    while seconds < REPEAT_LIMIT and len(times) < setup.options.repeats:
        times.append(once(math.inf)[0])
    return Run(solver, setting, value, statistics.median(times), len(times), steps, rhs,
               jacobians, math.nan, math.nan), values


def _springc_run(setup: StudySetup, solver: str, rtol: float | None,
                 step: float | None) -> tuple[Run, np.ndarray | None]:
    def once(budget: float) -> Measured:
        deadline = Deadline(budget) if math.isfinite(budget) else None
        result = simulate_model(setup.model, setup.sim_options(solver, rtol, step, deadline))
        s = result.stats
        return s.wall_time, (s.steps, s.rhs_evaluations, s.jacobian_evaluations), result.values

    if step is not None:
        return _timed(setup, solver, "step", step, once)
    assert rtol is not None, "an adaptive run needs rtol"
    return _timed(setup, solver, "rtol", rtol, once)


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


def _scipy_run(setup: StudySetup, rtol: float | None) -> tuple[Run, np.ndarray | None]:
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


def run_tradeoff(model: CompiledModel, options: TradeoffOptions,
                 executor: Executor | None = None) -> Tradeoff:
    """Measure every solver at every setting against the reference (see module text).

    The reference is computed here; each solver's settings (and the scipy baselines)
    are one task (:class:`Chain`), run in this process or, with ``executor`` (the
    studies executor: local processes or Dask), in its workers; the table is the same.
    """
    setup = study_setup(model, options)
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
    # Step 2: every solver, loosest setting first, until one is over budget; step 3:
    # scipy's default call, then RK45 tightened until it reaches the targets.
    fixed = set(fixed_step_solvers())
    interval = float(setup.grid[1] - setup.grid[0]) if len(setup.grid) > 1 else 1.0
    steps = options.steps or tuple(interval / d for d in DEFAULT_STEP_DIVISIONS)
    chains = [Chain(solver, tuple(sorted(steps if solver in fixed else options.tolerances,
                                         reverse=True))) for solver in solvers]
    chains.append(Chain(SCIPY_DEFAULT, ()))
    done: list[list[Run]] = [[] for _ in chains]
    if executor is None:
        for i, chain in enumerate(chains):
            done[i] = chain_runs(setup, ref, scales, energy, chain, setup.log)
    else:
        job = ChainJob(model.options, model.outputs, dataclasses.replace(options, log=None),
                       ref, scales, energy)
        for i, runs in executor.map(functools.partial(run_chain, job), chains):
            done[i] = runs
            for run in runs:
                setup.log(_log_line(run))
    return Tradeoff(model.name, len(model.states), ref, scales,
                    tuple(run for runs in done[:-1] for run in runs), tuple(done[-1]),
                    tuple(options.targets), energy)


class Executor(Protocol):
    """Runs independent tasks, yielding (task index, result) as each completes
    (:class:`springc.studies.Executor`: local processes or Dask)."""

    def map(self, function: Callable[[Any], Any], items: Sequence[Any]
            ) -> Iterable[tuple[int, Any]]: ...


@dataclass(frozen=True)
class Chain:
    """One task: a solver's settings, loosest first (a run over budget skips the
    tighter ones), or the scipy baselines (``solver`` :data:`SCIPY_DEFAULT`)."""

    solver: str
    settings: tuple[float, ...]


@dataclass(frozen=True)
class ChainJob:
    """What a worker needs for any chain: the model (compile options with absolute
    file names, and the compared outputs), the options (no log stream), the reference,
    the scales and the energy variable."""

    compile: CompileOptions
    outputs: tuple[str, ...]
    options: TradeoffOptions
    reference: Reference
    scales: np.ndarray
    energy: str | None

    def __post_init__(self) -> None:
        absolute = dataclasses.replace(
            self.compile, files=tuple(os.path.abspath(f) for f in self.compile.files),
            libraries=tuple(os.path.abspath(f) for f in self.compile.libraries))
        object.__setattr__(self, "compile", absolute)


@functools.lru_cache(maxsize=4)
def worker_model(options: CompileOptions) -> CompiledModel:
    """The compiled model of ``options`` in a worker (loaded from the cache once)."""
    return compile_files(options)


def run_chain(job: ChainJob, chain: Chain) -> list[Run]:
    """One chain in a worker process: the model from the cache, warmed up, then runs."""
    model = dataclasses.replace(worker_model(job.compile), outputs=job.outputs)
    setup = study_setup(model, job.options)
    with np.errstate(all="ignore"):
        warm_up(model, setup.p, setup.x0)
    return chain_runs(setup, job.reference, job.scales, job.energy, chain)


def chain_runs(setup: StudySetup, ref: Reference, scales: np.ndarray, energy: str | None,
               chain: Chain, log: Callable[[str], None] | None = None) -> list[Run]:
    """The runs of ``chain``, each logged with ``log`` when done."""
    with_energy = _energy_drift(setup, energy, ref)
    runs: list[Run] = []

    def done(run: Run) -> None:
        runs.append(run)
        if log is not None:
            log(_log_line(run))

    if chain.solver == SCIPY_DEFAULT:
        base, values = _scipy_run(setup, None)
        done(with_energy(_with_errors(base, values, ref, scales), values))
        goal = min(setup.options.targets)
        if not (runs[0].ok and runs[0].max_error <= goal):
            for rtol in sorted((t for t in setup.options.tolerances if t < 1e-3),
                               reverse=True):
                run, values = _scipy_run(setup, rtol)
                done(with_energy(_with_errors(run, values, ref, scales), values))
                if not runs[-1].ok or runs[-1].max_error <= goal:
                    break
        return runs
    fixed = chain.solver in fixed_step_solvers()
    skip = False
    for value in chain.settings:
        if skip:
            runs.append(Run(chain.solver, "step" if fixed else "rtol", value, math.nan, 0,
                            -1, -1, -1, math.nan, math.nan,
                            "skipped (a looser setting was over budget)"))
            continue
        run, values = _springc_run(setup, chain.solver, None if fixed else value,
                                   value if fixed else None)
        done(with_energy(_with_errors(run, values, ref, scales), values))
        skip = runs[-1].status.startswith("over budget")
    return runs


def _energy_drift(setup: StudySetup, energy: str | None, ref: Reference
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
