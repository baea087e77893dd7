"""Ensembles: CompiledModel + EnsembleOptions -> a Parquet table, one row per run.

The compiled ensemble engine (:func:`springc.integrate.ensemble`) integrates a chunk of
runs in one call, in parallel over the runs on every core, with no Python per run
inside the loop; the runs' parameter vectors, start states and work arrays are built
in Python per chunk, and each chunk's rows are written to the table as one Parquet
row group, so memory is bounded by the chunk size, never by the number of runs.

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

The message of a failed run is the single-run path's own (``springc.simulate`` with
``solver="dop853"`` on the run's values, run again for that run only) for the first
``explain`` failed runs of each chunk; later ones get the words of the failure's kind
and its time. The file carries the key ``springc`` in its metadata (JSON: the model,
the parameters, the variables, the options, ``"format": "springc ensemble 1"``).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SimulationError, SpringcError, UsageError
from ..fileio import atomic_write
from ..pipeline import CompiledModel
from ..simulation import (
    DEFAULT_MAX_STEPS,
    RunSettings,
    initial_state,
    output_grid,
    resolve,
    simulate_model,
)
from .job import StudyOptions
from .params import ParameterSpec
from .study import check_names, parameter_table

SOLVER = "dop853"
STATISTICS = {"final": "final", "min": "min", "max": "max", "mean": "mean",
              "argmax": "time_of_max"}
"""The kernel's statistic -> its column suffix."""
DEFAULT_CHUNK = 10_000
FAILED_PREPARATION = -1  # a run whose parameters or start values could not be computed
NON_FINITE_OUTPUT = 3  # Status.NON_FINITE_STATE: a chosen variable NaN or inf on the grid


@dataclass(frozen=True)
class EnsembleOptions:
    """What to vary and how to run. The runs: a ``table`` (names and a matrix, one row
    per run) if given, else a grid of the ``parameters`` or ``samples`` draws of them
    (as :class:`~springc.studies.StudyOptions`). ``fixed`` values apply to every run;
    times and tolerances as for ``simulate`` (``None``: the model's defaults);
    ``variables``: the outputs to summarise (``None``: every output of the model)."""

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
    chunk: int = DEFAULT_CHUNK
    explain: int = 100


@dataclass(frozen=True)
class EnsembleSummary:
    """What a finished ensemble wrote: ``runs`` rows, ``failed`` of them failed."""

    path: str
    runs: int
    failed: int

    def summary_line(self) -> str:
        return (f"{self.runs} runs, {self.runs - self.failed} ok, {self.failed} failed "
                f"-> {self.path}")


def run_table(options: EnsembleOptions) -> tuple[tuple[str, ...], np.ndarray]:
    """The varied parameters' names and values (one row per run)."""
    if options.table is not None:
        if options.parameters:
            raise UsageError("--table and --param exclude each other (the table gives "
                             "every run's values)", option="--table")
        return options.table
    study = StudyOptions(options.parameters, options.samples, options.method, options.seed)
    return tuple(s.name for s in options.parameters), parameter_table(study)


def check_model(model: CompiledModel) -> None:
    """The ensemble engine runs continuous models with compiled (numba) functions."""
    module = model.module
    for flag, what in (("EVENTS", "events (when, if on a state, sample...)"),
                       ("DELAYS", "delay(...)"), ("SWITCHABLE", "states that switch")):
        if getattr(module, flag, False):
            raise SimulationError(f"{model.name} has {what}, which the ensemble engine does "
                                  "not run yet", hint="use springc sweep (one run at a time)")
    if getattr(module, "BACKEND", "") != "numba":
        raise SimulationError(f"the ensemble engine needs the numba backend, not "
                              f"{module.BACKEND}", hint="compile with --backend numba")


def columns_of(model: CompiledModel, variables: Sequence[str] | None) -> tuple[list[str],
                                                                               list[int]]:
    """The summarised variables and their indices into ``[states | observed]``."""
    names = list(model.outputs if variables is None else variables)
    index = {n: i for i, n in enumerate((*model.states, *model.observed))}
    for name in names:
        if name not in index:
            raise UsageError(f"--vars {name}: not a variable of {model.name}",
                             option="--vars")
    return names, [index[n] for n in names]


def prepare(model: CompiledModel, names: Sequence[str], values: np.ndarray,
            fixed: Mapping[str, float], t0: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, str]]:
    """Parameter vectors, start states and work arrays of a chunk's runs (Python per
    run: the generated module's ``parameters``, ``start`` and ``guesses``), and the
    message of each run whose values could not be computed."""
    module = model.module
    n_p, n = len(model.parameter_names), len(model.states)
    P = np.zeros((len(values), n_p))
    X0 = np.zeros((len(values), n))
    Z = np.zeros((len(values), np.asarray(module.guesses(module.parameters(dict(fixed)))).size))
    failed: dict[int, str] = {}
    for r, row in enumerate(values):
        settings = dict(fixed)
        settings.update(zip(names, (float(v) for v in row)))
        try:
            P[r] = module.parameters(settings)
            if not np.isfinite(P[r]).all():
                raise SimulationError("a parameter value is not finite")
            X0[r] = initial_state(model, P[r], t0)
            Z[r] = module.guesses(P[r])
        except (ArithmeticError, ValueError, SpringcError) as err:
            failed[r] = str(err)
            P[r], X0[r] = np.nan, np.nan
    return P, X0, Z, failed


def settings_of(model: CompiledModel, options: EnsembleOptions
                ) -> tuple[np.ndarray, float, float, int]:
    """The output grid, rtol, atol and step limit of the runs."""
    timing = RunSettings(start=options.start, stop=options.stop,
                         interval=options.interval, solver=SOLVER, rtol=options.rtol,
                         atol=options.atol)
    start, stop, interval, rtol, atol = resolve(model, timing)
    max_steps = DEFAULT_MAX_STEPS if options.max_steps is None else options.max_steps
    return output_grid(start, stop, interval), rtol, atol, max_steps


WORDS = {1: "Required step size is less than spacing between numbers.",
         2: "the derivatives are not finite",
         3: "a variable is not finite",
         4: "the run reached the step limit (--max-steps {limit})",
         5: "a nonlinear system did not converge"}
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
             values: np.ndarray, result: Any, prepared: Mapping[int, str],
             max_steps: int) -> list[str | None]:
    """The error message of every run of a chunk (``None`` for a run that succeeded)."""
    out: list[str | None] = [None] * len(values)
    explained = 0
    for r in np.flatnonzero(result.status != 0).tolist():
        if r in prepared:
            out[r] = prepared[r]
            continue
        text = None
        if explained < options.explain:
            explained += 1
            settings = dict(options.fixed)
            settings.update(zip(names, (float(v) for v in values[r])))
            text = explain(model, options, settings, max_steps)
        out[r] = text or failure_words(int(result.status[r]), float(result.failure_time[r]),
                                       max_steps)
    return out


def schema_of(model: CompiledModel, names: Sequence[str], variables: Sequence[str],
              metadata: Mapping[str, Any]) -> Any:
    """The ensemble table's Arrow schema (see the module text)."""
    import pyarrow as pa

    units = model.units
    fields = [pa.field("run", pa.int64()),
              *(pa.field(n, pa.float64()) for n in names),
              pa.field("status", pa.string()), pa.field("error", pa.string()),
              pa.field("solver", pa.string()), pa.field("steps", pa.int64()),
              pa.field("rhs_evaluations", pa.int64())]
    for v in variables:
        unit = units.get(v, "")
        for suffix in STATISTICS.values():
            fields.append(pa.field(f"{v}.{suffix}", pa.float64(),
                                   metadata={"unit": unit} if unit else None))
    return pa.schema(fields, metadata={"springc": json.dumps(dict(metadata))})


def chunk_table(schema: Any, first: int, values: np.ndarray, result: Any,
                errors: Sequence[str | None]) -> Any:
    """The rows of a chunk (runs ``first``, ``first + 1``, ...)."""
    import pyarrow as pa

    runs = len(values)
    ok = result.status == 0
    failed = ~ok
    columns: list[Any] = [np.arange(first, first + runs, dtype=np.int64),
                          *(values[:, j] for j in range(values.shape[1])),
                          pa.array(["ok" if good else "failed" for good in ok.tolist()]),
                          pa.array(list(errors), type=pa.string()),
                          pa.array([SOLVER] * runs), result.steps, result.rhs_evaluations]
    for c in range(result.summary.shape[1]):
        for s in range(len(STATISTICS)):
            columns.append(pa.array(result.summary[:, c, s], mask=failed))
    return pa.Table.from_arrays(columns, schema=schema)


def run_ensemble(model: CompiledModel, options: EnsembleOptions, output: str,
                 protected: Sequence[str] = ()) -> EnsembleSummary:
    """Run every run of ``options`` on ``model`` in chunks and write the ensemble table
    to ``output`` (through a temporary file, renamed when complete)."""
    import pyarrow.parquet as pq

    from ..integrate import ensemble

    check_model(model)
    names, values = run_table(options)
    check_names(model, names)
    if options.chunk < 1:
        raise UsageError(f"--chunk must be at least 1, not {options.chunk}", option="--chunk")
    variables, columns = columns_of(model, options.variables)
    grid, rtol, atol, max_steps = settings_of(model, options)
    fixed = dict(options.fixed)
    metadata = {"format": "springc ensemble 1", "model": model.name,
                "parameters": list(names), "variables": variables,
                "method": "table" if options.table else
                "grid" if options.samples is None else options.method,
                "samples": options.samples, "seed": options.seed, "fixed": fixed,
                "start": float(grid[0]), "stop": float(grid[-1]), "points": len(grid),
                "solver": SOLVER, "rtol": rtol, "atol": atol, "max_steps": max_steps,
                "runs": len(values), "statistics": list(STATISTICS.values())}
    schema = schema_of(model, names, variables, metadata)
    failed = 0
    with atomic_write(output, "wb", protected) as f, pq.ParquetWriter(f, schema) as writer:
        for first in range(0, len(values), options.chunk):
            chunk = values[first:first + options.chunk]
            P, X0, Z, prepared = prepare(model, names, chunk, fixed, float(grid[0]))
            result = ensemble(model.module.rhs, grid, X0, P, Z, rtol=rtol, atol=atol,
                              observed=model.module.observed, columns=columns,
                              max_steps=max_steps)
            status = result.status.copy()
            finite = np.isfinite(result.summary).all(axis=(1, 2))
            status[(status == 0) & ~finite] = NON_FINITE_OUTPUT
            status[list(prepared)] = FAILED_PREPARATION
            result = _with_status(result, status)
            errors = messages(model, options, names, chunk, result, prepared, max_steps)
            failed += int((status != 0).sum())
            writer.write_table(chunk_table(schema, first, chunk, result, errors))
    return EnsembleSummary(output, len(values), failed)


def _with_status(result: Any, status: np.ndarray) -> Any:
    from dataclasses import replace

    return replace(result, status=status)
