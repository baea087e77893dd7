"""A parameter study: CompiledModel + StudyOptions -> Study (tables, written as Parquet).

The model is compiled once by the caller; the runs (a grid or samples, see
:mod:`.params`) are cut into batches and run by an engine (:mod:`.engines`); each
finished batch becomes rows of the study table (:mod:`.store`), written to a shard when
there is an output file so that an interrupted study can resume.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, TextIO

import numpy as np

from ..errors import SimulationError, UnknownParameterError, UsageError, printable
from ..pipeline import CompiledModel, check_parameter_names
from ..simulation import output_grid, resolve
from .engines import (
    Batch,
    batches,
    connect,
    dask_batches,
    dask_workers,
    default_workers,
    local_batches,
)
from .job import RunJob, StudyOptions
from .params import grid, sample
from .progress import StudyProgress, duration
from .store import (
    Layout,
    Shards,
    column_name,
    describe,
    partial_folder,
    records_table,
    summary_path,
    summary_table,
    write_tables,
)

ENERGY_UNIT = "J"


@dataclass
class Study:
    """The outcome of a study: ``table`` and ``summary`` are pyarrow Tables in the
    layouts of :mod:`springc.studies.store`; ``values[run]`` are the swept values;
    ``computed`` lists the runs simulated by this call (the others were resumed)."""

    model: str
    layout: Layout
    values: np.ndarray
    table: Any
    summary: Any
    computed: tuple[int, ...]
    workers: int
    engine: str
    wall_time: float
    files: tuple[str, ...] = field(default=())

    @property
    def failed(self) -> int:
        return sum(1 for s in self.summary.column("status").to_pylist() if s != "ok")

    def summary_line(self) -> str:
        """One line: runs, failures, engine, time, files written."""
        runs = len(self.values)
        text = (f"{printable(self.model)}: {runs} runs ({runs - self.failed} ok, {self.failed} "
                f"failed), {len(self.computed)} simulated on {self.engine} in "
                f"{duration(self.wall_time)}")
        return text + (f"; wrote {' and '.join(self.files)}" if self.files else "")


def parameter_table(options: StudyOptions) -> np.ndarray:
    """The swept values: one row per run, one column per parameter."""
    if options.samples is None:
        return grid(options.parameters)
    return sample(options.parameters, options.samples, options.method, options.seed)


def check_names(model: CompiledModel, names: Sequence[str]) -> None:
    """Swept parameters must be parameters of ``model`` and not structural (Integer and
    Boolean parameters, array sizes: they change the equations). A start value is
    set for every run (``--set``), not swept: its column would be its variable's."""
    try:
        check_parameter_names(model, dict.fromkeys(names, 0.0))
    except UnknownParameterError as err:
        raise err.given_as("--param") from None
    for name in names:
        if name not in model.parameter_names:
            raise UsageError(f"--param {name}: '{name}' is a start value, not a parameter; "
                             "a study sweeps parameters", option="--param",
                             hint=f"set it for every run with --set {name}=VALUE, or bind "
                             "its start to a parameter in the model (start = p)")
        if name in model.structural:
            raise UsageError(f"--param {name}: '{name}' is a structural parameter (it "
                             "changes the equations); a study varies the others",
                             option="--param",
                             hint="run one study per value, with --set NAME=VALUE")


def energy_variable(model: CompiledModel, requested: str | None) -> str | None:
    """The output whose drift the summary reports: ``requested``, else the only output
    in J."""
    units = model.units
    if requested is not None:
        if requested not in model.outputs:
            raise UsageError(f"--energy {requested}: not among the study's variables",
                             option="--energy", hint="add it to --vars")
        return requested
    joules = [n for n in model.outputs if units.get(n) == ENERGY_UNIT]
    return joules[0] if len(joules) == 1 else None


def layout_of(model: CompiledModel, options: StudyOptions, values: np.ndarray) -> Layout:
    """The columns and metadata of the study of ``model``."""
    start, stop, interval, rtol, atol = resolve(model, options.run)
    units = model.units
    names = tuple(s.name for s in options.parameters)
    energy = energy_variable(model, options.energy)
    metadata = {
        "format": "springc study 1", "model": model.name, "parameters": list(names),
        "specs": [s.text for s in options.parameters],
        "variables": list(model.outputs), "units": {n: units.get(n, "") for n in
                                                    model.outputs},
        "method": "grid" if options.samples is None else options.method,
        "samples": options.samples, "seed": options.seed if options.samples else None,
        "fixed": dict(options.fixed), "start": start, "stop": stop, "interval": interval,
        "solver": options.solver, "rtol": rtol, "atol": atol, "step": options.step,
        "energy": energy, "runs": len(values), "max_steps": options.max_steps,
        "time_limit": options.time_limit, "error_control": options.error_control}
    return Layout(names, model.outputs, tuple(units.get(n, "") for n in model.outputs),
                  output_grid(start, stop, interval), energy, metadata)


def job_of(model: CompiledModel, options: StudyOptions) -> RunJob:
    """The job the workers run: the compiled model itself (closed: the workers never
    read its files) and the study's options."""
    return RunJob(model, options)


Pending = Sequence[tuple[int, tuple[float, ...]]]


def _engine(options: StudyOptions, job: RunJob, pending: Pending, client: Any
            ) -> tuple[Iterator[list[Any]], int, str, Callable[[], None]]:
    """The batches' results as they complete, the worker count, the engine's name,
    and what to call at the end (``client``: the connected Dask client, if any)."""
    if client is not None:
        workers = dask_workers(client)
        work: list[Batch] = batches(pending, workers)
        return (dask_batches(client, job, work), workers,
                f"Dask at {options.scheduler} ({workers} threads)",
                client.close)
    workers = options.workers or default_workers()
    if workers < 1:
        raise UsageError(f"--workers must be at least 1, not {workers}", option="--workers")
    work = batches(pending, workers)
    return (local_batches(job, work, workers), workers,
            f"{workers} local process{'es' if workers > 1 else ''}", lambda: None)


def run_study(model: CompiledModel, options: StudyOptions, output: str | None = None,
              summary: str | None = None, resume: bool = False,
              protected: Sequence[str] = (), progress: TextIO | None = None,
              callback: Callable[[int, int], None] | None = None) -> Study:
    """Run every run of the study (those not already in the shards of ``output`` with
    ``resume``) and return the tables; with ``output``, write them there (and to
    ``summary``, default ``OUTPUT`` with ``.summary.parquet``). ``callback(done,
    total)`` is called after each batch (after its shard is written)."""
    began = time.perf_counter()
    values = parameter_table(options)
    names = tuple(s.name for s in options.parameters)
    check_names(model, names)
    for name, _ in options.fixed:
        if name in names:
            raise UsageError(f"'{name}' is both swept (--param) and fixed (--set)",
                             option="--set")
    layout = layout_of(model, options, values)
    job = job_of(model, options)
    if options.workers is not None and options.workers < 1:
        raise UsageError(f"--workers must be at least 1, not {options.workers}",
                         option="--workers")
    # Connect first: a scheduler that cannot be reached leaves no partial results.
    client = connect(options.scheduler) if options.scheduler is not None else None
    fresh = output is not None and not os.path.lexists(partial_folder(output))
    shards = None
    if output is not None:
        description = describe(layout, values, model.source)
        try:
            shards = Shards(partial_folder(output), description, resume)
        except BaseException:
            if client is not None:
                client.close()
            raise
    done = shards.done() if shards is not None else set()
    pending = [(i, tuple(float(v) for v in values[i])) for i in range(len(values))
               if i not in done]
    by_run = {run: swept for run, swept in pending}
    tables: list[Any] = []
    computed: list[int] = []
    meter = StudyProgress(progress, len(values), len(done))
    try:
        results, workers, engine, close = _engine(options, job, pending, client)
    except BaseException:
        _drop_empty(shards, fresh, client)
        raise
    try:
        for records in results:
            table = records_table(layout, records, by_run)
            if shards is not None:
                shards.write(table)
            else:
                tables.append(table)
            computed += [r.run for r in records]
            failed = sum(1 for r in records if r.error is not None)
            meter.update(len(records) - failed, failed)
            if callback is not None:
                callback(meter.done, len(values))
    except BaseException:
        _drop_empty(shards, fresh, None)
        raise
    finally:
        meter.close()
        close()
    return _finish(model, layout, values, shards, tables, computed, workers, engine,
                   began, output, summary, protected)


def _drop_empty(shards: Shards | None, fresh: bool, client: Any) -> None:
    """After a failure: close ``client``; remove the shard folder if this run created it
    and wrote no shard (a study that never ran leaves nothing behind)."""
    if client is not None:
        client.close()
    if shards is not None and fresh and shards.count == 0:
        shards.remove()


def _finish(model: CompiledModel, layout: Layout, values: np.ndarray,
            shards: Shards | None, tables: list[Any], computed: list[int], workers: int,
            engine: str, began: float, output: str | None, summary: str | None,
            protected: Sequence[str]) -> Study:
    import pyarrow as pa

    if shards is not None:
        tables = shards.read()
    schema = layout.schema()
    table = pa.concat_tables([t.cast(schema) for t in tables]) if tables else \
        schema.empty_table()
    table = table.sort_by([("run", "ascending"), ("time", "ascending")])
    if table.num_rows != len(values) * len(layout.time):
        raise SimulationError(f"the study has {table.num_rows} rows, expected "
                              f"{len(values)} runs x {len(layout.time)} times",
                              hint="remove the partial results and run it again")
    table = table.replace_schema_metadata(schema.metadata)
    brief = summary_table(layout, table)
    files: tuple[str, ...] = ()
    if output is not None and shards is not None:
        summary = summary or summary_path(output)
        write_tables(table, brief, output, summary, protected)
        shards.remove()
        files = (output, summary)
    return Study(model.name, layout, values, table, brief, tuple(computed), workers,
                 engine, time.perf_counter() - began, files)


def to_dataset(study: Study) -> Any:
    """The study as an ``xarray.Dataset``: each output variable over ``run`` x ``time``
    (attribute ``units``), the swept parameters as coordinates on ``run``, and
    ``status``, ``error`` and the solver statistics as variables over ``run``."""
    import xarray as xr

    layout, table = study.layout, study.table
    runs, nt = len(study.values), len(layout.time)
    coords: dict[str, Any] = {"run": np.arange(runs), "time": ("time", layout.time,
                                                               {"units": "s"})}
    for j, name in enumerate(layout.parameters):
        coords[column_name(name)] = ("run", study.values[:, j])
    data: dict[str, Any] = {}
    for name, unit in zip(layout.variables, layout.units):
        column = np.asarray(table.column(column_name(name)).to_numpy(
            zero_copy_only=False), dtype=float)
        data[name] = (("run", "time"), column.reshape(runs, nt), {"units": unit} if unit
                      else {})
    for name in ("status", "error", "solver", "steps", "rhs_evaluations",
                 "jacobian_evaluations", "rtol", "estimated_error", "warning"):
        data[name] = ("run", np.asarray(study.summary.column(name).to_pylist(),
                                        dtype=object if name in ("status", "error", "solver",
                                                                 "warning") else None))
    return xr.Dataset(data, coords=coords, attrs={"model": study.model,
                                                  "method": layout.metadata["method"]})
