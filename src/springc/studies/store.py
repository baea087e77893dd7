"""Study results as Parquet: RunRecords -> the study table and the summary table.

**Study table** (``-o study.parquet``; long layout, one row per run and output time,
sorted by run then time; every run has the same output times, so a failed run has
its rows with null values):

| column | type | meaning |
| --- | --- | --- |
| ``run`` | int64 | run number, 0-based (the row of the parameter table) |
| ``time`` | float64 | output time [s] |
| each swept parameter (``spring.k``) | float64 | its value in the run |
| each output variable (``mass.pos[1]``) | float64 | its value (null: the run failed) |
| ``status`` | string | ``ok`` or ``failed`` |
| ``error`` | string | the error message of a failed run (null if ok) |
| ``solver`` | string | the solver used (``auto``'s choice) |
| ``steps``, ``rhs_evaluations``, ``jacobian_evaluations`` | int64 | solver statistics |
| ``rtol`` | float64 | the rtol of the run kept (tighter than asked if tightened) |
| ``estimated_error`` | float64 | the error of the variable furthest from its tolerance |
| ``warning`` | string | the tolerance missed, or the error not estimated (else null) |

``rtol``, ``estimated_error`` and ``warning`` come from ``--error-control``
(:mod:`springc.simulation.error_control`); ``estimated_error`` is NaN where the run was
not estimated (``off``, a failed companion). No column holds a time measured by the
clock: the same study writes the same bytes on every run, with any number of workers
(the study's duration is in its summary line,
:meth:`springc.studies.Study.summary_line`).

Variable columns carry their unit as field metadata (``unit``). A parameter or
variable whose flat name is one of the fixed columns above (a top-level
``Real error;``) is stored under its quoted name (``'error'``).

**Summary table** (``study.summary.parquet`` next to it, one row per run): ``run``, the
parameters, ``status`` to ``warning`` as above, then for each output variable
``NAME.final``, ``NAME.min`` and ``NAME.max`` (null if the run failed), and, when an
energy variable is selected (``--energy NAME``, else the only output in J),
``NAME.drift`` = max_t |E(t) - E(t0)| / max_t |E(t)|.

Both files carry the key ``springc`` in their metadata: JSON with the model, the
parameter and variable names, the units, the options and the sampling settings.

Resuming: while a study runs, each finished batch is written to a shard
(``shard-NNNNNN.parquet``, the study-table layout) in the folder ``OUTPUT.partial``,
with ``study.json`` describing the study. ``--resume`` checks that description and
skips every run found in the shards; when the study is complete both tables are
written and the folder is removed.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import OutputError, UsageError
from ..fileio import OutputSet, atomic_write, check_distinct, check_target
from .job import RunRecord

FIXED_COLUMNS = ("run", "time", "status", "error", "solver", "steps", "rhs_evaluations",
                 "jacobian_evaluations", "rtol", "estimated_error", "warning")
ACCURACY = ("rtol", "estimated_error")
"""Per run (``--error-control``): the rtol of the run kept (tighter than asked where it
was tightened) and the estimated error of the variable furthest from its tolerance
(NaN: not estimated); ``warning``: the rule still broken, or null."""
STATS = ("solver", "steps", "rhs_evaluations", "jacobian_evaluations")
SUFFIX = ".parquet"
MANIFEST = "study.json"
FORMAT_VERSION = 2
"""2: no ``wall_time`` column; ``rtol``, ``estimated_error`` and ``warning`` (shards of version 1
are another study's to ``--resume``)."""


def column_name(name: str) -> str:
    """The column of a parameter or variable: its flat name, quoted if it is one of
    :data:`FIXED_COLUMNS`."""
    return f"'{name}'" if name in FIXED_COLUMNS else name


@dataclass(frozen=True)
class Layout:
    """The columns of a study: swept parameters, output variables and their units,
    the output times, and the metadata stored in the files."""

    parameters: tuple[str, ...]
    variables: tuple[str, ...]
    units: tuple[str, ...]
    time: np.ndarray
    energy: str | None
    metadata: Mapping[str, Any]

    def schema(self) -> Any:
        """The pyarrow schema of the study table."""
        import pyarrow as pa

        fields = [pa.field("run", pa.int64()), pa.field("time", pa.float64())]
        fields += [pa.field(column_name(p), pa.float64()) for p in self.parameters]
        fields += [pa.field(column_name(v), pa.float64(), metadata={"unit": u})
                   for v, u in zip(self.variables, self.units)]
        fields += [pa.field("status", pa.string()), pa.field("error", pa.string()),
                   pa.field("solver", pa.string())]
        fields += [pa.field(n, pa.int64()) for n in STATS[1:]]
        fields += [pa.field(n, pa.float64()) for n in ACCURACY]
        fields.append(pa.field("warning", pa.string()))
        meta = {"springc": json.dumps(dict(self.metadata), sort_keys=True)}
        return pa.schema(fields, metadata=meta)


def records_table(layout: Layout, records: Sequence[RunRecord],
                  values: Mapping[int, Sequence[float]]) -> Any:
    """The study-table rows of ``records``; ``values[run]`` are the swept values."""
    import pyarrow as pa

    count, nt = len(records), len(layout.time)
    runs = np.array([r.run for r in records], dtype=np.int64)
    data: dict[str, Any] = {"run": np.repeat(runs, nt), "time": np.tile(layout.time, count)}
    swept = np.array([values[r.run] for r in records], dtype=float).reshape(
        count, len(layout.parameters))
    for j, name in enumerate(layout.parameters):
        data[column_name(name)] = np.repeat(swept[:, j], nt)
    block = np.full((count * nt, len(layout.variables)), np.nan)
    failed = np.zeros(count * nt, dtype=bool)
    for i, record in enumerate(records):
        if record.values is None:
            failed[i * nt:(i + 1) * nt] = True
        else:
            block[i * nt:(i + 1) * nt] = record.values
    for j, name in enumerate(layout.variables):
        data[column_name(name)] = pa.array(block[:, j], mask=failed)
    data["status"] = np.repeat(["ok" if r.error is None else "failed" for r in records], nt)
    data["error"] = pa.array([r.error for r in records for _ in range(nt)], pa.string())
    for name in STATS + ACCURACY:
        data[name] = np.repeat([getattr(r, name) for r in records], nt)
    data["warning"] = pa.array([r.warning for r in records for _ in range(nt)], pa.string())
    return pa.Table.from_pydict(data, schema=layout.schema())


def summary_table(layout: Layout, table: Any) -> Any:
    """One row per run of the (sorted) study ``table``: parameters, status, statistics
    and the final, min and max of each variable (and the energy drift)."""
    import pyarrow as pa

    nt = len(layout.time)
    first = table.take(np.arange(0, table.num_rows, nt))
    names = ["run", *map(column_name, layout.parameters), *FIXED_COLUMNS[2:]]
    out = first.select(names)
    fields = []
    for name, unit in zip(layout.variables, layout.units):
        series = table.column(column_name(name)).to_numpy(zero_copy_only=False)
        series = np.asarray(series, dtype=float).reshape(-1, nt)
        metrics = {"final": series[:, -1], "min": series.min(axis=1),
                   "max": series.max(axis=1)}
        if name == layout.energy:
            with np.errstate(all="ignore"):
                scale = np.abs(series).max(axis=1)
                change = np.abs(series - series[:, :1]).max(axis=1)
                metrics["drift"] = np.where(scale > 0, change / np.where(
                    scale > 0, scale, 1.0), change)
        for metric, column in metrics.items():
            fields.append((pa.field(f"{name}.{metric}", pa.float64(),
                                    metadata={"unit": "" if metric == "drift" else unit}),
                           pa.array(column, mask=np.isnan(column))))
    for field, column in fields:
        out = out.append_column(field, column)
    return out.replace_schema_metadata(layout.schema().metadata)


def summary_path(output: str | os.PathLike[str]) -> str:
    """``study.summary.parquet`` for ``study.parquet``."""
    path = os.fspath(output)
    stem = path[:-len(SUFFIX)] if path.lower().endswith(SUFFIX) else path
    return stem + ".summary" + SUFFIX


def partial_folder(output: str | os.PathLike[str]) -> Path:
    """The folder of a study's shards: ``OUTPUT.partial``."""
    return Path(os.fspath(output) + ".partial")


def check_outputs(output: str, summary: str, protected: Iterable[str],
                  names: tuple[str, str] = ("-o", "--summary")) -> None:
    """Refuse outputs that cannot be written (a UsageError naming the option)."""
    for option, path in zip(names, (output, summary)):
        if not path.lower().endswith(SUFFIX):
            raise UsageError(f"{option} {path}: the study is written as Parquet: the "
                             f"file name must end in {SUFFIX}", option=option)
        try:
            check_target(path, protected)
        except OutputError as err:
            raise UsageError(f"{option}: {err.message}", option=option,
                             hint=err.hint) from None
    try:
        check_distinct(zip(names, (output, summary)))
    except OutputError as err:
        raise UsageError(err.message, hint=err.hint) from None


def describe(layout: Layout, values: np.ndarray, model_source: str) -> dict[str, Any]:
    """What identifies a study for ``--resume``: its metadata, the digests of the
    generated model and of the parameter table."""
    return {"version": FORMAT_VERSION, "metadata": dict(layout.metadata),
            "model_sha256": hashlib.sha256(model_source.encode()).hexdigest(),
            "runs_sha256": hashlib.sha256(np.ascontiguousarray(values).tobytes()).hexdigest(),
            "runs": len(values)}


class Shards:
    """The shard folder of a study being written (see the module text)."""

    def __init__(self, folder: Path, description: dict[str, Any], resume: bool) -> None:
        self.folder = folder
        self.count = 0
        manifest = folder / MANIFEST
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            raise UsageError(f"{folder} is in the way: it should be the folder of "
                             "partial results; remove it", option="--resume")
        if folder.exists() and not resume:
            raise UsageError(f"partial results of an earlier study are in {folder}",
                             option="--resume",
                             hint="add --resume to continue that study, or remove the "
                             "folder to start again")
        if folder.exists():
            try:
                found = json.loads(manifest.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                found = None
            if found != json.loads(json.dumps(description)):
                raise UsageError(f"the partial results in {folder} are of another study "
                                 "(model, parameters or options differ)", option="--resume",
                                 hint="rerun the command that started it, or remove the "
                                 "folder to start again")
            self.count = len(self.paths())
        else:
            folder.mkdir(mode=0o700)
            with atomic_write(manifest, "w") as f:
                json.dump(description, f, indent=1, sort_keys=True)

    def paths(self) -> list[Path]:
        return sorted(self.folder.glob("shard-*" + SUFFIX))

    def read(self, columns: list[str] | None = None) -> list[Any]:
        """The tables of the shards written so far (only ``columns`` if given)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        tables = []
        for path in self.paths():
            try:
                tables.append(pq.read_table(path, columns=columns))
            except (OSError, pa.ArrowException) as err:
                raise UsageError(f"the partial result {path} is damaged ({err})",
                                 option="--resume", hint="remove that file (its runs are "
                                 "run again) and resume") from None
        return tables

    def done(self) -> set[int]:
        """The runs already in the shards."""
        return {int(r) for table in self.read(["run"])
                for r in np.unique(table.column("run"))}

    def write(self, table: Any) -> None:
        """Add ``table`` as a new shard (written to a temporary file, then renamed)."""
        import pyarrow.parquet as pq

        path = self.folder / f"shard-{self.count:06d}{SUFFIX}"
        with atomic_write(path, "wb") as f:
            pq.write_table(table, f)
        self.count += 1

    def remove(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)


def write_tables(table: Any, summary: Any, output: str, summary_file: str,
                 protected: Iterable[str]) -> None:
    """Write both tables, all or nothing."""
    import pyarrow.parquet as pq

    with OutputSet(protected) as outputs:
        with outputs.open(output, "wb") as f:
            pq.write_table(table, f)
        with outputs.open(summary_file, "wb") as f:
            pq.write_table(summary, f)
