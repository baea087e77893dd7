"""One batch of runs in a worker: RunJob + (run, values) pairs -> RunRecords; the
study's options (:class:`StudyOptions`), which the job carries to the workers.

This is the code that executes in the worker processes (local or Dask). A worker gets
the compiled model itself, pickled with the job: a compiled model is closed (it never
reads its source files again, see :mod:`springc.pipeline.closed`), so every run of a
study runs the model the parent compiled, even if its files change or vanish meanwhile,
and a worker imports its module once per process (from the verified cache entry when
there is one). A run that fails (a
:class:`~springc.errors.SpringcError`: the solver gave up, a division by zero...) is
recorded with its message and the batch continues; anything else propagates and stops
the study.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import SpringcError
from ..pipeline import CompiledModel
from ..simulation import DEFAULT_ERROR_CONTROL, RunSettings, run_settings, simulate_model
from .params import ParameterSpec


@dataclass(frozen=True)
class StudyOptions:
    """What to vary and how to run. ``samples`` ``None``: a grid of the parameters'
    lists; else that many draws (``method`` ``lhs`` or ``mc``, from ``seed``). Times,
    solver and tolerances as for ``simulate`` (``None``: the model's defaults);
    ``fixed`` parameter values apply to every run. ``scheduler``: the address of a Dask
    scheduler, else ``workers`` local processes (default: one per core)."""

    parameters: tuple[ParameterSpec, ...]
    samples: int | None = None
    method: str = "lhs"
    seed: int = 0
    fixed: tuple[tuple[str, float], ...] = ()
    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    solver: str = "auto"
    rtol: float | None = None
    atol: float | None = None
    step: float | None = None
    workers: int | None = None
    scheduler: str | None = None
    energy: str | None = None
    max_steps: int | None = None
    time_limit: float | None = None
    error_control: str = DEFAULT_ERROR_CONTROL  # tighten, warn or off, as for simulate

    def running(self, settings: RunSettings) -> StudyOptions:
        """These options with the run settings of ``settings`` (``springc sweep``'s
        shared options, :func:`springc.sweep`'s keywords; ``None``: the default)."""
        return replace(self, start=settings.start, stop=settings.stop,
                       interval=settings.interval, solver=settings.solver,
                       rtol=settings.rtol, atol=settings.atol, step=settings.step,
                       max_steps=settings.max_steps, time_limit=settings.time_limit,
                       error_control=settings.error_control)

    @property
    def run(self) -> RunSettings:
        """The settings every run shares, built by the one function the API and the
        command line build theirs with."""
        return run_settings(start=self.start, stop=self.stop, interval=self.interval,
                            solver=self.solver, rtol=self.rtol, atol=self.atol,
                            step=self.step, parameters=dict(self.fixed),
                            max_steps=self.max_steps, time_limit=self.time_limit,
                            error_control=self.error_control)


@dataclass(frozen=True)
class RunJob:
    """What every run of a study shares: the compiled model (pickled to the workers) and
    the study's options (swept names, fixed values, simulation settings; ``None``: the
    model's defaults, and simulate's limits of steps and seconds)."""

    model: CompiledModel
    study: StudyOptions

    @property
    def solver(self) -> str:
        return self.study.solver

    def options(self, values: Sequence[float]) -> RunSettings:
        """The settings of the run with the swept ``values``."""
        o = self.study
        base = o.run
        parameters = dict(base.parameters)
        parameters.update(zip((s.name for s in o.parameters), (float(v) for v in values)))
        return replace(base, parameters=parameters)


@dataclass(frozen=True)
class RunRecord:
    """The outcome of one run: ``values[i, j]`` is output ``j`` at output time ``i``
    (``None`` if the run failed: ``error`` holds the message)."""

    run: int
    error: str | None
    solver: str
    steps: int
    rhs_evaluations: int
    jacobian_evaluations: int
    values: np.ndarray | None
    rtol: float = math.nan  # --error-control: the rtol of the run kept
    estimated_error: float = math.nan  # of the variable furthest from its tolerance
    warning: str | None = None  # the tolerance still missed (SimulationStats.warning)


def run_one(model: CompiledModel, job: RunJob, run: int, values: Sequence[float]
            ) -> RunRecord:
    """Simulate one run; a :class:`SpringcError` becomes a failed record."""
    try:
        result = simulate_model(model, job.options(values))
    except SpringcError as err:
        return RunRecord(run, str(err), job.solver, 0, 0, 0, None)
    stats = result.stats
    return RunRecord(run, None, stats.solver, stats.steps, stats.rhs_evaluations,
                     stats.jacobian_evaluations, result.values,
                     math.nan if stats.rtol is None else stats.rtol,
                     math.nan if stats.estimated_error is None else stats.estimated_error,
                     stats.warning or None)


def run_batch(job: RunJob, runs: Sequence[tuple[int, tuple[float, ...]]]
              ) -> list[RunRecord]:
    """Simulate ``runs`` (run number, swept values) in order."""
    model = job.model
    return [run_one(model, job, run, values) for run, values in runs]
