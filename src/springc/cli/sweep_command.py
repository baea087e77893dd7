"""``springc sweep``: a model over a grid or samples of parameter values, into Parquet."""

from __future__ import annotations

import sys

import click

from ..errors import UsageError
from ..simulation import RunSettings
from ..status_line import silenced
from .app import guard, main
from .options import (
    SOLVING,
    TIMES,
    check_output_options,
    compile_options,
    model_options,
    run_settings_options,
    sampling_options,
    single_threaded_blas,
    values_named_by,
    verbosity,
    verbosity_options,
)


@main.command()
@model_options
@compile_options
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=VALUES",
              help="A parameter to vary (repeatable): a list 0.5,1,2; a range "
              "START:STOP[:lin|log]:COUNT; with --samples, a range START:STOP[:log] or a "
              "distribution uniform(a,b), loguniform(a,b), normal(mean,std), "
              "lognormal(mu,sigma), triangular(a,mode,b). Grid: every combination.")
@sampling_options
@click.option("--workers", type=click.IntRange(min=1),
              help="Local worker processes (default: one per core).")
@click.option("--scheduler", metavar="ADDRESS", help="Run on the Dask scheduler at "
              "ADDRESS (tcp://host:8786) instead of local processes.")
@click.option("--energy", metavar="NAME", help="Variable whose drift the summary "
              "reports (default: the only selected variable in J, if any).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), required=True,
              help="The study table (.parquet); the summary goes to "
              "NAME.summary.parquet.")
@click.option("--summary", "summary_file", type=click.Path(dir_okay=False),
              help="The summary table (.parquet), instead of NAME.summary.parquet.")
@click.option("--resume", is_flag=True, help="Continue an interrupted study: runs "
              "already in OUTPUT.partial are kept, not run again.")
@click.option("--plot", type=click.Path(dir_okay=False), help="Plot one variable across "
              "the runs (.png, .svg or .pdf): lines up to 12 runs, else a fan chart "
              "(median, percentile bands).")
@click.option("--plot-var", metavar="NAME", help="The variable of --plot (default: the "
              "study's first variable).")
@verbosity_options("No progress, no summary line and no status line (\"springc: "
                   "compiling ...\").")
@guard
@run_settings_options(*TIMES, *SOLVING)
def sweep(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
          backend: str, patterns: tuple[str, ...], no_cache: bool, settings: RunSettings,
          params: tuple[str, ...], samples: int | None, method: str, seed: int,
          workers: int | None, scheduler: str | None, energy: str | None, output: str,
          summary_file: str | None, resume: bool, plot: str | None,
          plot_var: str | None) -> None:
    """Run a model over a grid or samples of parameter values, in parallel, into Parquet.

    The model is compiled once; runs go to local processes (or a Dask scheduler); each
    run's parameters, status, solver statistics and trajectories are written to OUTPUT,
    one row per run and output time, and a summary per run (final, min, max of each
    variable) next to it. A failing run is recorded with its error; an interrupted
    study continues with --resume.
    """
    from ..studies import check_outputs, parse_parameter, summary_path

    quiet = verbosity() < 0
    if workers is not None and scheduler is not None:
        raise UsageError("--workers and --scheduler exclude each other (a Dask cluster "
                         "has its own workers)", option="--workers")
    specs = tuple(parse_parameter(item) for item in params)
    summary_file = summary_file or summary_path(output)
    check_outputs(output, summary_file, files)
    from ..simulation import PLOT_FORMATS

    check_output_options([("-o", output, None), ("--summary", summary_file, None),
                    ("--plot", plot, PLOT_FORMATS)], files)
    single_threaded_blas()
    from ..api import compile_model, default_choice
    from ..studies import StudyOptions, parameter_table, run_study

    options = StudyOptions(specs, samples, method, seed, workers=workers,
                           scheduler=scheduler, energy=energy).running(settings)
    parameter_table(options)  # refuse bad specifications before compiling

    with silenced(quiet), values_named_by("--set"):  # the status line of a compile
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=default_choice(backend, solver=settings.solver),
                                 outputs=patterns or None, parameters=settings.parameters,
                                 cache=not no_cache)
    fixed = tuple((k, v) for k, v in settings.parameters.items()
                  if k not in compiled.structural)
    from dataclasses import replace

    from ..studies import plot_variable

    plotted = plot_variable(compiled.outputs, plot_var) if plot else None

    try:
        study = run_study(compiled, replace(options, fixed=fixed), output, summary_file,
                          resume, files, None if quiet else sys.stderr)
    except (KeyboardInterrupt, SystemExit):
        from ..studies import partial_folder

        if partial_folder(output).is_dir():
            click.echo(f"note: finished runs are kept in {partial_folder(output)}; run "
                       "the same command with --resume to continue", err=True)
        raise
    if plot and plotted:
        from ..fileio import atomic_write
        from ..simulation import file_format
        from ..studies import render_fan

        picture, note = render_fan(study, plotted, file_format(plot, PLOT_FORMATS, "--plot"))
        with atomic_write(plot, "wb", files) as f:
            f.write(picture)
        if not quiet:
            click.echo(f"note: plot {plot}: {note}", err=True)
    if not quiet:
        click.echo(study.summary_line(), err=True)
