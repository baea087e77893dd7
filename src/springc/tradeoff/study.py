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
- **Time.** Wall time of ``simulate_model`` (integration and outputs, not compilation:
  each solver's loop is warmed up untimed), timed once; the contenders for a
  recommendation are timed ``repeats`` times (the fastest), see :mod:`.runs`. A run
  longer than ``budget`` seconds is stopped, and the solver's tighter settings are
  skipped.
- **Order and cost limit.** The pilot solver (``dop853``) runs first, in this process,
  right after the reference; the other solvers' tighter settings are skipped once a run
  costs ``cost_limit`` times the pilot's fastest run meeting the targets
  (:mod:`.chains`); skipped rows say why.
- **Baselines.** scipy's default call ``solve_ivp(rhs, span, x0, t_eval=grid)`` (RK45,
  rtol 1e-3, atol 1e-6) on the same generated right-hand side, and ``solve_ivp`` RK45
  tightened until it reaches the smallest target (:mod:`.baselines`).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..pipeline import CompiledModel
from ..simulation import FIXED_STEP, SOLVERS
from .baselines import baseline_runs
from .chains import Chain, Pilot, cost_ceiling, pilot_solver, solver_runs
from .energy import energy_variable
from .model import (
    DEFAULT_STEP_DIVISIONS,
    SCIPY_DEFAULT,
    Reference,
    Run,
    Tradeoff,
    TradeoffError,
    TradeoffOptions,
)
from .reference import read_reference, tight_reference
from .runs import log_line
from .setup import StudySetup, study_setup, variable_scales, warm_up

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


SPREAD_ABOVE = 2.0
"""Seconds of the pilot's runs below which ``springc tradeoff`` keeps the other solvers
in its own process unless told otherwise: starting a worker process (a fresh
interpreter importing springc, numba and scipy, then loading the model and the
compiled loops) costs seconds, more than such a study's remaining runs."""


def run_tradeoff(model: CompiledModel, options: TradeoffOptions,
                 executor: Executor | None = None, spread_above: float = 0.0) -> Tradeoff:
    """Measure every solver at every setting against the reference (see module text).

    The reference and the pilot solver's runs are computed here; each other solver's
    settings (and the scipy baselines) are one task (:class:`Chain`), run in this
    process or, with ``executor`` (the studies executor: local processes or Dask), in
    its workers, when the pilot's runs took ``spread_above`` seconds or more in all;
    the table is the same.
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
    # Step 2: the pilot, then every other solver, loosest setting first, until one is
    # over budget or over the cost limit; step 3: the scipy baselines.
    interval = float(setup.grid[1] - setup.grid[0]) if len(setup.grid) > 1 else 1.0
    steps = options.steps or tuple(interval / d for d in DEFAULT_STEP_DIVISIONS)
    chains = [Chain(solver, tuple(sorted(steps if solver in FIXED_STEP else options.tolerances,
                                         reverse=True))) for solver in solvers]
    chains.append(Chain(SCIPY_DEFAULT, ()))
    first = solvers.index(pilot_solver(solvers))
    done: list[list[Run]] = [[] for _ in chains]
    done[first] = solver_runs(setup, ref, scales, energy, chains[first], None, setup.log)
    pilot = Pilot(chains[first].solver, tuple(done[first]))
    rest = [i for i in range(len(chains)) if i != first]
    pilot_seconds = sum(r.wall_time for r in pilot.runs if r.ok)
    if executor is not None and pilot_seconds < spread_above:
        setup.log(f"the other solvers run in this process: {pilot.solver}'s runs took "
                  f"{pilot_seconds:.2g} s, less than starting worker processes costs")
        executor = None
    if executor is None:
        for i in rest:
            done[i] = chain_runs(setup, ref, scales, energy, chains[i], pilot, setup.log)
    else:
        job = ChainJob(model, dataclasses.replace(options, log=None),
                       ref, scales, energy, pilot)
        for k, runs in executor.map(functools.partial(run_chain, job),
                                    [chains[i] for i in rest]):
            done[rest[k]] = runs
            for run in runs:
                setup.log(log_line(run))
    return Tradeoff(model.name, len(model.states), ref, scales,
                    tuple(run for runs in done[:-1] for run in runs), tuple(done[-1]),
                    tuple(options.targets), energy,
                    cost_ceiling(pilot, options.targets, options.cost_limit)[1], pilot.solver)


class Executor(Protocol):
    """Runs independent tasks, yielding (task index, result) as each completes
    (:class:`springc.studies.Executor`: local processes or Dask)."""

    def map(self, function: Callable[[Any], Any], items: Sequence[Any]
            ) -> Iterable[tuple[int, Any]]: ...


@dataclass(frozen=True)
class ChainJob:
    """What a worker needs for any chain: the compiled model with the compared outputs
    (pickled: closed, it never reads its files, see :mod:`springc.pipeline.closed`),
    the options (no log stream), the reference, the scales, the energy variable and the
    pilot's runs."""

    model: CompiledModel
    options: TradeoffOptions
    reference: Reference
    scales: np.ndarray
    energy: str | None
    pilot: Pilot | None = None


def run_chain(job: ChainJob, chain: Chain) -> list[Run]:
    """One chain in a worker process: the job's model, warmed up, then runs."""
    model = job.model
    setup = study_setup(model, job.options)
    with np.errstate(all="ignore"):
        warm_up(model, setup.p, setup.x0)
    return chain_runs(setup, job.reference, job.scales, job.energy, chain, job.pilot)


def chain_runs(setup: StudySetup, ref: Reference, scales: np.ndarray, energy: str | None,
               chain: Chain, pilot: Pilot | None = None,
               log: Callable[[str], None] | None = None) -> list[Run]:
    """The runs of ``chain``: a solver's (:func:`.chains.solver_runs`) or the scipy
    baselines (:func:`.baselines.baseline_runs`), each logged with ``log`` when done."""
    if chain.solver == SCIPY_DEFAULT:
        return baseline_runs(setup, ref, scales, energy, log)
    return solver_runs(setup, ref, scales, energy, chain, pilot, log)
