"""``springc ensemble``: many runs in the compiled ensemble engine, one row per run."""

from __future__ import annotations

import click

from ..status_line import silenced
from .app import guard, main
from .options import (
    CLI_NAMES,
    check_output_options,
    compile_options,
    model_options,
    parse_set,
    run_options,
    sampling_options,
    verbosity,
    verbosity_options,
)


@main.command()
@model_options
@compile_options
@run_options
@click.option("--param", "params", multiple=True, metavar="NAME=VALUES",
              help="A parameter to vary (repeatable), as for sweep: a list, a range "
              "START:STOP[:lin|log]:COUNT (grid), or with --samples a range or a "
              "distribution.")
@click.option("--table", "table_file", type=click.Path(dir_okay=False),
              help="A CSV file of runs instead of --param: a header line of parameter "
              "names, then one line of values per run.")
@sampling_options
@click.option("--rtol", type=float, help="Relative tolerance (default: experiment "
              "Tolerance, else 1e-6).")
@click.option("--atol", type=float, help="Absolute tolerance (default: rtol/1000).")
@click.option("--max-steps", type=click.IntRange(min=1), default=None,
              help="Integrator steps per run before it fails (as for simulate).")
@click.option("--chunk", type=click.IntRange(min=1), default=None,
              help="Runs per compiled call and per Parquet row group (memory grows "
              "with it, not with the number of runs; default: 100,000 for the C engine, "
              "10,000 for numba, 1,000,000 on a GPU, fewer with trajectories).")
@click.option("--stats", "stats", default=None, metavar="LIST",
              help="The statistics of each variable, comma-separated, of final, min, max, "
              "mean, time_of_max (default: all five).")
@click.option("--trajectories", "traj_file", type=click.Path(dir_okay=False),
              help="Also write the trajectories of the --traj-vars variables (.parquet, "
              "the layout of sweep's study table: one row per run and output time).")
@click.option("--traj-vars", "traj_patterns", multiple=True, metavar="PATTERN",
              help="A variable whose trajectory goes to --trajectories (repeatable; * and "
              "? match; among the states and the --vars variables).")
@click.option("--every", type=click.IntRange(min=1), default=1, show_default=True,
              help="Keep every k-th output time of the trajectories (and the last).")
@click.option("--engine", type=click.Choice(["c", "numba"]), default=None,
              help="The CPU engine: c (the batched C kernel, the default where a C "
              "compiler is found) or numba.")
@click.option("--device", type=click.Choice(["cpu", "gpu"]), default="cpu",
              show_default=True, help="gpu: the C kernel on an NVIDIA GPU through CuPy, "
              "one thread per run.")
@click.option("--threads", type=click.IntRange(min=1), default=None,
              help="CPU threads (default: every core; with --scheduler, per task: 1; the "
              "results do not depend on it).")
@click.option("--scheduler", metavar="ADDRESS", help="Run each chunk as a task on the Dask "
              "scheduler at ADDRESS (tcp://host:8786), as sweep does; the same results. "
              "--chunk default: about four tasks per worker thread.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True,
              help="The ensemble table (.parquet): one row per run.")
@verbosity_options("No summary line and no status line (\"springc: compiling ...\").")
@guard
def ensemble(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, assignments: tuple[str, ...],
             params: tuple[str, ...], table_file: str | None, samples: int | None,
             method: str, seed: int, rtol: float | None, atol: float | None,
             max_steps: int | None, chunk: int | None, stats: str | None,
             traj_file: str | None, traj_patterns: tuple[str, ...], every: int,
             engine: str | None, device: str, threads: int | None, scheduler: str | None,
             output: str) -> None:
    """Run a model over many parameter sets in compiled code, into Parquet.

    Every run is integrated with compiled DOP853 in a loop over the runs on every core
    (or one GPU thread per run with --device gpu; no Python per run); each run has its
    own steps, its own events (hybrid models: the C engine) and its own status, and a
    failed run is recorded with its error. OUTPUT
    gets one row per run: its parameters, status, error, step counts, and the final
    value, min, max, time-weighted mean and time of the max of each variable (--vars;
    default: all; --stats picks among them). Use --interval to set the grid the
    statistics are taken on (one interval = final values only, the fastest).
    --trajectories writes the --traj-vars variables on that grid (--every k: every
    k-th time), chunk by chunk. Values outside a parameter's declared min/max are
    refused before any run.
    """
    from ..simulation import check_run_values
    from ..studies import EnsembleOptions, parse_parameter, read_table

    values = parse_set(assignments)
    check_run_values(start, stop, interval, rtol, atol, None, values, CLI_NAMES)
    if table_file is not None and params:
        raise click.UsageError("--table and --param exclude each other (the table gives "
                               "every run's values)")
    if table_file is None and not params:
        raise click.UsageError("give --param NAME=VALUES (repeatable) or --table FILE.csv")
    if bool(traj_patterns) != (traj_file is not None):
        raise click.UsageError("--trajectories FILE and --traj-vars PATTERN go together")
    specs = tuple(parse_parameter(item) for item in params)
    table = read_table(table_file) if table_file is not None else None
    statistics = tuple(s.strip() for s in stats.split(",") if s.strip()) \
        if stats is not None else None
    check_output_options([("-o", output, None), ("--trajectories", traj_file, None)], files)
    from ..api import compile_model
    from ..studies import run_ensemble

    quiet = verbosity() < 0
    with silenced(quiet):  # the status lines of a model or kernel that compiles
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=backend or "numba", outputs=patterns or None,
                                 parameters=values, cache=not no_cache)
        fixed = tuple((k, v) for k, v in values.items() if k not in compiled.structural)
        options = EnsembleOptions(specs, samples, method, seed, table, fixed, start, stop,
                                  interval, rtol, atol, max_steps, chunk=chunk,
                                  statistics=statistics,
                                  trajectories=trajectory_names(compiled, traj_patterns),
                                  every=every, engine=engine, device=device,
                                  threads=threads, scheduler=scheduler)
        summary = run_ensemble(compiled, options, output, files, traj_file)
    if not quiet:
        click.echo(f"{compiled.name}: {summary.summary_line()}", err=True)


def trajectory_names(compiled: object, patterns: tuple[str, ...]) -> tuple[str, ...]:
    """The variables ``--traj-vars`` selects among the states and observed variables."""
    from ..errors import SimulationError, UsageError
    from ..pipeline import CompiledModel, select_names

    assert isinstance(compiled, CompiledModel)
    if not patterns:
        return ()
    try:
        return tuple(select_names(compiled.states + compiled.observed, patterns))
    except SimulationError as err:
        raise UsageError(err.message.replace("--vars", "--traj-vars", 1),
                         option="--traj-vars", hint=err.hint) from None
