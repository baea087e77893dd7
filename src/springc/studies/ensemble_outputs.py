"""The files of an ensemble, written a chunk at a time, and read back as a :class:`Study`.

**Ensemble table** (one row per run): see :mod:`.ensemble`. **Trajectories**
(``--trajectories FILE.parquet``): the study-table layout of :mod:`.store` (long: one
row per run and kept output time, sorted by run then time; a failed run's values null),
for the variables asked for, on the output grid or every k-th time of it (and the
last); one Parquet row group per chunk. :func:`read_trajectories` reads it back as a
:class:`Study`, so :func:`to_dataset` (xarray) and the fan plot take it as they take a
sweep's.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import UsageError
from ..pipeline import CompiledModel
from .store import Layout, column_name, summary_table
from .study import Study

STATISTICS = {"final": "final", "min": "min", "max": "max", "mean": "mean",
              "argmax": "time_of_max"}
"""The kernel's statistic (its order in the summary axis) -> its column suffix."""
SUFFIXES = tuple(STATISTICS.values())
TRAJECTORY_FORMAT = "springc ensemble trajectories 1"


def statistics_of(chosen: Sequence[str] | None) -> tuple[int, ...]:
    """The positions (in :data:`STATISTICS`) of the chosen column suffixes (None: all)."""
    if chosen is None:
        return tuple(range(len(SUFFIXES)))
    for name in chosen:
        if name not in SUFFIXES:
            raise UsageError(f"--stats {name}: not one of {', '.join(SUFFIXES)}",
                             option="--stats")
    return tuple(i for i, s in enumerate(SUFFIXES) if s in chosen)


def schema_of(model: CompiledModel, names: Sequence[str], variables: Sequence[str],
              statistics: Sequence[int], metadata: Mapping[str, Any]) -> Any:
    """The ensemble table's Arrow schema (see :mod:`.ensemble`)."""
    import pyarrow as pa

    units = model.units
    fields = [pa.field("run", pa.int64()),
              *(pa.field(n, pa.float64()) for n in names),
              pa.field("status", pa.string()), pa.field("error", pa.string()),
              pa.field("solver", pa.string()), pa.field("steps", pa.int64()),
              pa.field("rhs_evaluations", pa.int64())]
    for v in variables:
        unit = units.get(v, "")
        for s in statistics:
            fields.append(pa.field(f"{v}.{SUFFIXES[s]}", pa.float64(),
                                   metadata={"unit": unit} if unit else None))
    return pa.schema(fields, metadata={"springc": json.dumps(dict(metadata))})


def chunk_table(schema: Any, first: int, values: np.ndarray, result: Any,
                statistics: Sequence[int], errors: Sequence[str | None],
                solver: str) -> Any:
    """The ensemble-table rows of a chunk (runs ``first``, ``first + 1``, ...)."""
    import pyarrow as pa

    runs = len(values)
    failed = result.status != 0
    status = np.where(failed, "failed", "ok")
    columns: list[Any] = [np.arange(first, first + runs, dtype=np.int64),
                          *(values[:, j] for j in range(values.shape[1])),
                          pa.array(status), pa.array(list(errors), type=pa.string()),
                          pa.array(np.full(runs, solver)), result.steps,
                          result.rhs_evaluations]
    for c in range(result.summary.shape[1]):
        for s in statistics:
            columns.append(pa.array(result.summary[:, c, s], mask=failed))
    return pa.Table.from_arrays(columns, schema=schema)


def trajectory_layout(model: CompiledModel, names: Sequence[str], variables: Sequence[str],
                      time: np.ndarray, metadata: Mapping[str, Any]) -> Layout:
    """The study-table layout of an ensemble's trajectories."""
    units = model.units
    return Layout(tuple(names), tuple(variables), tuple(units.get(v, "") for v in variables),
                  np.asarray(time, dtype=float), None,
                  {**metadata, "format": TRAJECTORY_FORMAT, "variables": list(variables),
                   "units": {v: units.get(v, "") for v in variables}})


def trajectory_table(layout: Layout, first: int, values: np.ndarray, result: Any,
                     errors: Sequence[str | None], solver: str, rtol: float) -> Any:
    """The trajectory rows of a chunk: run x kept time, the study-table columns."""
    import pyarrow as pa

    runs, nt = len(values), len(layout.time)
    failed = np.repeat(result.status != 0, nt)
    data: dict[str, Any] = {
        "run": np.repeat(np.arange(first, first + runs, dtype=np.int64), nt),
        "time": np.tile(layout.time, runs)}
    for j, name in enumerate(layout.parameters):
        data[column_name(name)] = np.repeat(values[:, j], nt)
    for c, name in enumerate(layout.variables):
        data[column_name(name)] = pa.array(result.trajectories[:, :, c].reshape(-1),
                                           mask=failed)
    data["status"] = pa.array(np.where(failed, "failed", "ok"))
    data["error"] = pa.array([e for e in errors for _ in range(nt)], pa.string())
    data["solver"] = pa.array(np.full(runs * nt, solver))
    data["steps"] = np.repeat(result.steps, nt)
    data["rhs_evaluations"] = np.repeat(result.rhs_evaluations, nt)
    data["jacobian_evaluations"] = np.zeros(runs * nt, dtype=np.int64)
    data["rtol"] = np.full(runs * nt, rtol)
    data["estimated_error"] = np.full(runs * nt, np.nan)
    data["warning"] = pa.nulls(runs * nt, pa.string())
    return pa.Table.from_pydict(data, schema=layout.schema())


def read_trajectories(path: str) -> Study:
    """An ensemble's trajectory file as a :class:`Study` (its table, and the summary
    the study layout derives from it: ``to_dataset``, ``render_fan`` take it)."""
    import pyarrow.parquet as pq

    table = pq.read_table(path)
    raw = (table.schema.metadata or {}).get(b"springc", b"{}")
    metadata = json.loads(raw)
    if metadata.get("format") != TRAJECTORY_FORMAT:
        raise UsageError(f"{path}: not the trajectories of a springc ensemble",
                         hint="write them with springc ensemble --trajectories FILE")
    variables = tuple(metadata["variables"])
    units = tuple(metadata["units"].get(v, "") for v in variables)
    runs = np.unique(table.column("run").to_numpy())
    nt = table.num_rows // max(len(runs), 1)
    time = table.column("time").to_numpy()[:nt]
    layout = Layout(tuple(metadata["parameters"]), variables, units, time, None, metadata)
    values = np.column_stack([table.column(column_name(p)).to_numpy()[::nt]
                              for p in layout.parameters]) if layout.parameters else \
        np.zeros((len(runs), 0))
    return Study(metadata["model"], layout, values, table, summary_table(layout, table),
                 tuple(int(r) for r in runs), 1, str(metadata.get("engine", "")), 0.0,
                 (path,))
