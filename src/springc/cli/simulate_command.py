"""``springc simulate``: one run, its trajectory (CSV or MAT) and/or a plot."""

from __future__ import annotations

import sys
import warnings
from dataclasses import replace

import click

from ..simulation import RunSettings
from ..status_line import silenced
from .app import guard, main
from .options import (
    SOLVING,
    TIMES,
    check_output_options,
    compile_options,
    initial_warnings,
    model_options,
    release_compile_memory,
    report_units,
    run_settings_options,
    single_threaded_blas,
    units_option,
    unmapped_large_buffers,
    values_named_by,
    verbosity,
    verbosity_options,
)
from .run_records import remember_run


@main.command()
@model_options
@compile_options
@click.option("--error-output", type=click.Path(dir_okay=False),
              help="Write the error estimate per state (CSV: variable, max_abs_error, "
              "relative_error, at_time, method) here.")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the trajectory: .csv, or .mat (the MATLAB v4 result layout of "
              "OpenModelica and Dymola); default: CSV on stdout unless --plot.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write a plot: .png, .svg or .pdf.")
@verbosity_options("No progress bar, no summary line and no status lines (\"springc: "
                   "compiling ...\" before a step that compiles, once).")
@units_option
@guard
@run_settings_options(*TIMES, *SOLVING, "engine", "error_estimate", "event_rows")
def simulate(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool,
             settings: RunSettings, error_estimate: str | None, error_output: str | None,
             output: str | None, plot: str | None, strict_units: bool) -> None:
    """Simulate a model and write its trajectory (CSV or MAT) and/or a plot."""
    from ..simulation import (
        PLOT_FORMATS,
        RESULT_FORMATS,
        choose_engine,
        estimate_deprecation,
    )

    choose_engine(settings.engine, settings.solver, backend)
    check_output_options([("-o", output, RESULT_FORMATS), ("--plot", plot, PLOT_FORMATS),
                          ("--error-output", error_output, {".csv": "csv"})], files)
    if error_output and settings.error_control == "off":  # the table needs the estimate
        option = "--error-estimate" if error_estimate is not None else "--error-control"
        raise click.UsageError(f"--error-output needs an error estimate, which {option} off "
                               "turns off")
    if error_estimate is not None:
        click.echo(f"warning: {estimate_deprecation(error_estimate)}", err=True)
    single_threaded_blas()
    unmapped_large_buffers()
    from ..api import AccuracyWarning, compile_model, default_choice
    from ..api import simulate as run
    from ..pipeline import CompiledModel, collector_paused, compiled_apart, functions_apart
    from ..simulation import check_trajectory_size, save_outputs, write_csv

    level = verbosity()
    quiet = level < 0
    with silenced(quiet):  # the status lines of long steps (compiling)
        def compiled_here() -> CompiledModel:
            return compile_model(files, model, libraries=libraries,
                                 backend=default_choice(backend, settings.engine,
                                                        settings.solver),
                                 outputs=patterns or None, parameters=settings.parameters,
                                 cache=not no_cache)

        with collector_paused():  # until its one collection, release_compile_memory's
            # a model not in the cache: compiled in a child process that exits before
            # the run
            with values_named_by("--set"):
                compiled = compiled_here() if no_cache else compiled_apart(compiled_here)
            report_units(compiled.warnings, strict_units)
            if not compiled.cached:
                release_compile_memory()
        if compiled.cached:  # its numba functions compiled (LLVM) in a child too
            functions_apart(compiled.module, compiled.path)
        if not patterns and (output or not plot):  # the default trajectory of every output
            check_trajectory_size(compiled, settings,
                                  f"-o {output}" if output else "the CSV on stdout")
        progress = None if quiet or not sys.stderr.isatty() else sys.stderr
        with initial_warnings() as left_out, warnings.catch_warnings():  # accuracy: below
            warnings.simplefilter("ignore", AccuracyWarning)
            run_as = replace(settings, parameters={
                k: v for k, v in settings.parameters.items() if k not in compiled.structural})
            result = run(compiled, settings=replace(run_as, progress=progress))
        if error_output and result.error_estimate is None:
            raise click.UsageError(f"--error-output {error_output}: this run made no error "
                                   "estimate (--error-control off, or a model without states)")
        if output or plot or error_output:
            note = save_outputs(result, output, plot, files, error_output)
            if note and not quiet:
                click.echo(f"note: plot {plot}: {note}", err=True)
        else:
            write_csv(result, sys.stdout)
            sys.stdout.flush()
        if level == 0:
            click.echo(result.stats.brief(result.model), err=True)
        elif level > 0:
            click.echo(result.stats.summary(result.model), err=True)
        if level > 1:
            click.echo(f"note: generated module {compiled.path}", err=True)
        if result.stats.warning:  # even with --quiet: the answer missed its tolerance
            click.echo(f"warning: {result.model}: {result.stats.warning}", err=True)
        if not (plot or error_output or no_cache or error_estimate or level > 0
                or left_out) and \
                (output is None or output.lower().endswith(".csv")):
            remember_run(compiled, run_as, result, files, libraries, output, quiet)
