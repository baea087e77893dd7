"""Ensembles: CompiledModel + EnsembleOptions -> a Parquet table, one row per run.

An ensemble engine (:mod:`.ensemble_engines`: the batched C kernel on every core by
default, the numba kernel, or the C kernel on a GPU) integrates a chunk of runs in one
call with no Python per run; each chunk's rows are written to the table as one Parquet
row group (and its trajectories, when asked, to the trajectory file), so memory is
bounded by the chunk size, never by the number of runs.

**Ensemble table** (``-o ensemble.parquet``, one row per run, in run order):

| column | type | meaning |
| --- | --- | --- |
| ``run`` | int64 | run number, 0-based (the row of the parameter table) |
| each varied parameter | float64 | its value in the run |
| ``status`` | string | ``ok`` or ``failed`` |
| ``error`` | string | the message of a failed run (null if ok) |
| ``solver`` | string | ``dop853`` |
| ``steps``, ``rhs_evaluations`` | int64 | accepted + rejected steps, evaluations |
| ``NAME.final`` | float64 | a chosen variable's value at the stop time (null: failed) |
| ``NAME.min``, ``NAME.max`` | float64 | its least and greatest value on the output grid |
| ``NAME.mean`` | float64 | its time-weighted mean: the trapezoidal rule on the grid / span |
| ``NAME.time_of_max`` | float64 | the first output time where it takes its maximum |

Only the statistics chosen (``statistics``, default all five) get columns. The message
of a failed run is the single-run path's own (``springc.simulate`` with
``solver="dop853"`` on the run's values, run again for that run only) for the first
``explain`` failed runs of the ensemble (in run order, so the same whatever the chunk
size); later ones get the words of the failure's kind and its time. The file carries
the key ``springc`` in its metadata (JSON: the model, the parameters, the variables, the
options, the engine, ``"format": "springc ensemble 1"``). Trajectories:
:mod:`.ensemble_outputs`. Chunks as Dask tasks (``scheduler``): :mod:`.ensemble_tasks`.

Parameter values outside a parameter's declared ``min``/``max`` are refused before any
run (:func:`check_bounds`), naming the parameter and the run.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SimulationError, SpringcError, UsageError
from ..fileio import OutputSet
from ..pipeline import CompiledModel
from ..simulation import (
    DEFAULT_MAX_STEPS,
    RunSettings,
    output_grid,
    resolve,
    simulate_model,
)
from .engines import connect, dask_workers
from .ensemble_engines import (
    FAILED_PREPARATION,
    Chunk,
    Plan,
    event_constructs,
    open_engine,
    resolve_engine,
)
from .ensemble_outputs import (
    SUFFIXES,
    chunk_table,
    schema_of,
    statistics_of,
    trajectory_layout,
    trajectory_table,
)
from .ensemble_tasks import (
    Chunks,
    ChunkTask,
    dask_chunk_size,
    dask_chunks,
    fixed_items,
    local_chunks,
    task_threads,
)
from .job import StudyOptions
from .params import ParameterSpec
from .study import check_names, parameter_table

SOLVER = "dop853"
CHUNKS = {"c": 100_000, "numba": 10_000, "gpu": 1_000_000}
"""The default runs per chunk of each engine (a chunk is one kernel call and one Parquet
row group: memory grows with it)."""
TRAJECTORY_VALUES = 2_000_000
"""With trajectories, a chunk holds at most this many values (runs x times x variables)."""


@dataclass(frozen=True)
class EnsembleOptions:
    """What to vary and how to run. The runs: a ``table`` (names and a matrix, one row
    per run) if given, else a grid of the ``parameters`` or ``samples`` draws of them
    (as :class:`~springc.studies.StudyOptions`). ``fixed`` values apply to every run;
    times and tolerances as for ``simulate`` (``None``: the model's defaults);
    ``variables``: the outputs to summarise (``None``: every output of the model), with
    the ``statistics`` chosen (column suffixes, ``None``: all); ``trajectories``: the
    variables whose values on the output grid (every ``every``-th time, and the last)
    go to the trajectory file. ``engine``: ``c`` or ``numba`` (``None``: ``c`` where a
    C compiler is found); ``device``: ``cpu`` or ``gpu``; ``chunk``: runs per kernel
    call (``None``: the engine's default); ``threads``: the CPU threads (``None``: every
    core; the results are the same bytes whatever the number); ``scheduler``: the
    address of a Dask scheduler, each chunk one task there (``chunk`` default: about
    four tasks per worker thread; ``threads`` default 1 per task), the same bytes."""

    parameters: tuple[ParameterSpec, ...] = ()
    samples: int | None = None
    method: str = "lhs"
    seed: int = 0
    table: tuple[tuple[str, ...], np.ndarray] | None = None
    fixed: tuple[tuple[str, float], ...] = ()
    start: float | None = None
    stop: float | None = None
    interval: float | None = None
    rtol: float | None = None
    atol: float | None = None
    max_steps: int | None = None
    variables: tuple[str, ...] | None = None
    chunk: int | None = None
    explain: int = 100
    statistics: tuple[str, ...] | None = None
    trajectories: tuple[str, ...] = ()
    every: int = 1
    engine: str | None = None
    device: str = "cpu"
    threads: int | None = None
    scheduler: str | None = None


@dataclass(frozen=True)
class EnsembleSummary:
    """What a finished ensemble wrote: ``runs`` rows, ``failed`` of them failed, on
    ``engine``; ``files``: the ensemble table (and the trajectories)."""

    path: str
    runs: int
    failed: int
    engine: str = ""
    files: tuple[str, ...] = ()

    def summary_line(self) -> str:
        return (f"{self.runs} runs, {self.runs - self.failed} ok, {self.failed} failed "
                f"-> {' and '.join(self.files or (self.path,))}")


def run_table(options: EnsembleOptions) -> tuple[tuple[str, ...], np.ndarray]:
    """The varied parameters' names and values (one row per run)."""
    if options.table is not None:
        if options.parameters:
            raise UsageError("--table and --param exclude each other (the table gives "
                             "every run's values)", option="--table")
        return options.table
    study = StudyOptions(options.parameters, options.samples, options.method, options.seed)
    return tuple(s.name for s in options.parameters), parameter_table(study)


def check_model(model: CompiledModel, device: str = "cpu") -> None:
    """The ensemble engines run continuous and hybrid models (events in the C kernel);
    delays and states that switch are refused by name, as are events without states."""
    module = model.module
    for flag, what in (("DELAYS", "delay(...)"), ("SWITCHABLE", "states that switch "
                                                  "(dynamic state selection)")):
        if getattr(module, flag, False):
            raise SimulationError(f"{model.name} has {what}, which the ensemble engine "
                                  "does not run yet",
                                  hint="use springc sweep (one run at a time)")
    if getattr(module, "EVENTS", False) and not model.states:
        raise SimulationError(f"{model.name} has events ({event_constructs(model)}) but no "
                              "states, which the ensemble engine does not run yet",
                              hint="use springc sweep (one run at a time)")


def check_bounds(model: CompiledModel, names: Sequence[str], values: np.ndarray,
                 fixed: Mapping[str, float]) -> None:
    """Refuse, before any run, a value outside its parameter's declared ``min``/``max``
    (the generated module's ``PARAMETER_BOUNDS``), naming the parameter (and the first
    run that has it)."""
    bounds = dict(zip(model.parameter_names, model.module.PARAMETER_BOUNDS))
    checks = [(f"--param {n}", n, values[:, j], True) for j, n in enumerate(names)]
    checks += [(f"--set {n}", n, np.array([v]), False) for n, v in fixed.items()]
    for option, name, column, per_run in checks:
        low, high = bounds.get(name, (None, None))
        below = column < low if low is not None else np.zeros(column.shape, dtype=bool)
        above = column > high if high is not None else np.zeros(column.shape, dtype=bool)
        outside = np.flatnonzero(below | above)
        if outside.size:
            r = int(outside[0])
            limit = f"min = {low:g}" if below[r] else f"max = {high:g}"
            where = f" (run {r})" if per_run else ""
            raise UsageError(f"{option}: {name} = {float(column[r]):g}{where} is outside "
                             f"its declared range ({limit})",
                             option=option.split()[0],
                             hint="the model declares " + ", ".join(
                                 f"{k} = {v:g}" for k, v in (("min", low), ("max", high))
                                 if v is not None) + f" for {name}")


def columns_of(model: CompiledModel, variables: Sequence[str] | None, option: str = "--vars"
               ) -> tuple[list[str], list[int]]:
    """The chosen variables and their indices into ``[states | observed]``."""
    names = list(model.outputs if variables is None else variables)
    index = {n: i for i, n in enumerate((*model.states, *model.observed))}
    for name in names:
        if name not in index:
            raise UsageError(f"{option} {name}: not a variable of {model.name}",
                             option=option)
    return names, [index[n] for n in names]


def settings_of(model: CompiledModel, options: EnsembleOptions
                ) -> tuple[np.ndarray, float, float, int]:
    """The output grid, rtol, atol and step limit of the runs."""
    timing = RunSettings(start=options.start, stop=options.stop,
                         interval=options.interval, solver=SOLVER, rtol=options.rtol,
                         atol=options.atol)
    start, stop, interval, rtol, atol = resolve(model, timing)
    max_steps = DEFAULT_MAX_STEPS if options.max_steps is None else options.max_steps
    return output_grid(start, stop, interval), rtol, atol, max_steps


UNSETTLED, CHATTERING = 8, 9  # springc.integrate.native_ensemble's hybrid statuses
WORDS = {FAILED_PREPARATION: "the parameters or start values are not finite",
         1: "Required step size is less than spacing between numbers.",
         2: "the derivatives are not finite",
         3: "a variable is not finite",
         4: "the run reached the step limit (--max-steps {limit})",
         5: "a nonlinear system did not converge",
         UNSETTLED: "the event iteration did not settle",
         CHATTERING: "chattering (more than 100 events within 1e-6 of the simulated span)"}
"""The words of a failure's kind (:class:`springc.integrate.Status`), when the run is
not run again to locate it."""


def failure_words(status: int, t: float, limit: int) -> str:
    """The message of a failed run from its status code and time alone."""
    words = WORDS.get(status, f"the run stopped (status {status})").format(limit=limit)
    return f"{SOLVER} failed at time {t:g}: {words}"


def explain(model: CompiledModel, options: EnsembleOptions, settings: Mapping[str, float],
            max_steps: int) -> str | None:
    """The single-run path's message for a run (``None`` if it does not fail there)."""
    single = RunSettings(start=options.start, stop=options.stop,
                         interval=options.interval, solver=SOLVER, rtol=options.rtol,
                         atol=options.atol, parameters=dict(settings), max_steps=max_steps,
                         engine="compiled", error_control="off")
    try:
        simulate_model(model, single)
    except SpringcError as err:
        return str(err)
    return None


def messages(model: CompiledModel, options: EnsembleOptions, names: Sequence[str],
             values: np.ndarray, result: Chunk, max_steps: int, explained: int = 0
             ) -> tuple[list[str | None], int]:
    """The error message of every run of a chunk (``None`` for a run that succeeded),
    and the runs explained by the single-run path so far (``explained`` before it)."""
    out: list[str | None] = [None] * len(values)
    for r in np.flatnonzero(result.status != 0).tolist():
        if r in result.prepared:
            out[r] = result.prepared[r]
            continue
        text = None
        if explained < options.explain:
            explained += 1
            settings = dict(options.fixed)
            settings.update(zip(names, (float(v) for v in values[r])))
            text = explain(model, options, settings, max_steps)
        out[r] = text or failure_words(int(result.status[r]), float(result.failure_time[r]),
                                       max_steps)
    return out, explained


def chunk_size(options: EnsembleOptions, engine: str, values_per_run: int) -> int:
    """Runs per chunk: as asked, else the engine's default, capped so that a chunk's
    trajectories hold at most :data:`TRAJECTORY_VALUES` values."""
    if options.chunk is not None:
        if options.chunk < 1:
            raise UsageError(f"--chunk must be at least 1, not {options.chunk}",
                             option="--chunk")
        return options.chunk
    size = CHUNKS[engine]
    if values_per_run:
        size = min(size, max(1, TRAJECTORY_VALUES // values_per_run))
    return size


def run_ensemble(model: CompiledModel, options: EnsembleOptions, output: str,
                 protected: Sequence[str] = (), trajectories: str | None = None
                 ) -> EnsembleSummary:
    """Run every run of ``options`` on ``model`` in chunks (in this process, or as Dask
    tasks with ``options.scheduler``) and write the ensemble table to ``output`` (and
    the trajectories of ``options.trajectories`` to ``trajectories``), all or nothing
    (temporary files, renamed when complete)."""
    check_model(model, options.device)
    names, values = run_table(options)
    check_names(model, names)
    fixed = dict(options.fixed)
    check_bounds(model, names, values, fixed)
    if options.every < 1:
        raise UsageError(f"--every must be at least 1, not {options.every}", option="--every")
    if bool(options.trajectories) != (trajectories is not None):
        raise UsageError("--traj-vars and --trajectories go together (the variables and "
                         "their file)", option="--trajectories")
    variables, columns = columns_of(model, options.variables)
    traj_names, traj_columns = columns_of(model, options.trajectories, "--traj-vars")
    statistics = statistics_of(options.statistics)
    grid, rtol, atol, max_steps = settings_of(model, options)
    kept = np.arange(0, grid.size, options.every)
    kept = kept if kept[-1] == grid.size - 1 else np.append(kept, grid.size - 1)
    plan = Plan(grid, rtol, atol, max_steps, tuple(columns), tuple(traj_columns),
                options.every, task_threads(options.threads, options.scheduler))
    engine = resolve_engine(options.engine, options.device)
    chunk = chunk_size(options, engine, len(kept) * len(traj_names))
    if options.scheduler is None:
        engine, run = open_engine(model, options.engine, options.device, names, fixed, plan)
        chunks = local_chunks(run, values, chunk)
        client = None
    else:  # connect first: a scheduler that cannot be reached leaves nothing behind
        client = connect(options.scheduler)
        threads = dask_workers(client)
        if options.chunk is None:
            chunk = dask_chunk_size(len(values), threads, chunk)
        task = ChunkTask(model, engine, tuple(names), fixed_items(fixed), plan)
        chunks = dask_chunks(client, task, values, chunk, threads)
    metadata = {"format": "springc ensemble 1", "model": model.name,
                "parameters": list(names), "variables": variables,
                "method": "table" if options.table else
                "grid" if options.samples is None else options.method,
                "samples": options.samples, "seed": options.seed, "fixed": fixed,
                "start": float(grid[0]), "stop": float(grid[-1]), "points": len(grid),
                "solver": SOLVER, "rtol": rtol, "atol": atol, "max_steps": max_steps,
                "runs": len(values), "statistics": [SUFFIXES[s] for s in statistics],
                "engine": engine}
    schema = schema_of(model, names, variables, statistics, metadata)
    layout = trajectory_layout(model, names, traj_names, grid[kept], metadata)
    try:
        failed = _write(model, options, names, chunks, (schema, layout, statistics),
                        (output, trajectories), protected, (rtol, max_steps))
    finally:
        if client is not None:
            client.close()
    files = (output,) if trajectories is None else (output, trajectories)
    return EnsembleSummary(output, len(values), failed, engine, files)


def _write(model: CompiledModel, options: EnsembleOptions, names: Sequence[str],
           chunks: Chunks, layouts: tuple[Any, Any, Any], paths: tuple[str, str | None],
           protected: Sequence[str], settings: tuple[float, int]) -> int:
    """The chunks, in run order, each into the table (and the trajectory file) as a
    row group; the number of failed runs. The first ``options.explain`` failed runs of
    the ensemble get the single-run path's message."""
    import pyarrow.parquet as pq

    schema, layout, statistics = layouts
    output, trajectories = paths
    rtol, max_steps = settings
    failed = explained = 0
    with OutputSet(protected) as outputs, contextlib.ExitStack() as stack:
        writer = stack.enter_context(pq.ParquetWriter(
            stack.enter_context(outputs.open(output, "wb")), schema))
        traj_writer = None if trajectories is None else stack.enter_context(
            pq.ParquetWriter(stack.enter_context(outputs.open(trajectories, "wb")),
                             layout.schema()))
        for first, part, result in chunks:
            errors, explained = messages(model, options, names, part, result, max_steps,
                                         explained)
            failed += int((result.status != 0).sum())
            writer.write_table(chunk_table(schema, first, part, result, statistics, errors,
                                           SOLVER))
            if traj_writer is not None:
                traj_writer.write_table(trajectory_table(layout, first, part, result,
                                                         errors, SOLVER, rtol))
    return failed
