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
@click.option("--chunk", type=click.IntRange(min=1), default=10_000, show_default=True,
              help="Runs per compiled call and per Parquet row group (memory grows "
              "with it, not with the number of runs).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True,
              help="The ensemble table (.parquet): one row per run.")
@verbosity_options("No summary line and no status line (\"springc: compiling ...\").")
@guard
def ensemble(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, assignments: tuple[str, ...],
             params: tuple[str, ...], table_file: str | None, samples: int | None,
             method: str, seed: int, rtol: float | None, atol: float | None,
             max_steps: int | None, chunk: int, output: str) -> None:
    """Run a continuous model over many parameter sets in compiled code, into Parquet.

    Every run is integrated with compiled DOP853 in a loop over the runs on every core
    (no Python per run); each run has its own steps and its own status, and a failed
    run is recorded with its error. OUTPUT gets one row per run: its parameters,
    status, error, step counts, and the final value, min, max, time-weighted mean and
    time of the max of each variable (--vars; default: all). Use --interval to set the
    grid the statistics are taken on (one interval = final values only, the fastest).
    Unlike sweep, no trajectories are written.
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
    specs = tuple(parse_parameter(item) for item in params)
    table = read_table(table_file) if table_file is not None else None
    check_output_options([("-o", output, None)], files)
    from ..api import compile_model
    from ..studies import run_ensemble

    quiet = verbosity() < 0
    with silenced(quiet):  # the status lines of a model or kernel that compiles
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=backend or "numba", outputs=patterns or None,
                                 parameters=values, cache=not no_cache)
        fixed = tuple((k, v) for k, v in values.items() if k not in compiled.structural)
        options = EnsembleOptions(specs, samples, method, seed, table, fixed, start, stop,
                                  interval, rtol, atol, max_steps, chunk=chunk)
        summary = run_ensemble(compiled, options, output, files)
    if not quiet:
        click.echo(f"{compiled.name}: {summary.summary_line()}", err=True)
