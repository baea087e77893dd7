"""``springc simulate``: one run, its trajectory (CSV or MAT) and/or a plot."""

from __future__ import annotations

import sys
import warnings

import click

from ..simulation import (
    ALL_SOLVERS,
    DEFAULT_ENGINE,
    DEFAULT_ERROR_CONTROL,
    DEFAULT_SOLVER,
    ENGINES,
    ERROR_CONTROLS,
    FIXED_STEP,
)
from ..status_line import silenced
from .app import guard, main
from .options import (
    CLI_NAMES,
    NumberRange,
    check_output_options,
    compile_options,
    model_options,
    parse_set,
    report_units,
    run_options,
    single_threaded_blas,
    units_option,
    verbosity,
    verbosity_options,
)


@main.command()
@model_options
@compile_options
@run_options
@click.option("--solver", type=click.Choice(ALL_SOLVERS, case_sensitive=False),
              default=DEFAULT_SOLVER, show_default=True,
              help="auto: dop853 or radau from a stiffness estimate at the start (the "
              "summary says why); a scipy solve_ivp method; or a fixed-step one "
              "(verlet, symplectic-euler, rk4) with --step.")
@click.option("--engine", type=click.Choice(ENGINES, case_sensitive=False),
              default=DEFAULT_ENGINE, show_default=True,
              help="compiled: numba loops (springc.integrate) for auto, dop853, rk45, "
              "radau, bdf and the fixed-step solvers; scipy: scipy's solvers stepped from "
              "Python; auto: compiled where it can run (numba installed, a solver with a "
              "compiled loop, not --backend python), else scipy, and the summary says "
              "why.")
@click.option("--error-control", type=click.Choice(ERROR_CONTROLS, case_sensitive=False),
              default=None, help="Estimate the global error on the output grid (a "
              "companion run 1000x tighter, or half the step for fixed-step solvers: in "
              "the summary line, in a .mat trajectory and in --error-output) and hold every "
              "output variable v to 10 * (rtol * max|v| + atol). tighten: run 1000x "
              "tighter until it holds (at most rtol 1e-12, within --max-steps and "
              "--time-limit), else warn; warn: only warn; off: no estimate (fastest). "
              f"[default: {DEFAULT_ERROR_CONTROL}]")
@click.option("--error-estimate", type=click.Choice(("off", "on", "auto"),
                                                   case_sensitive=False),
              default=None, help="Deprecated: off is --error-control off, on is warn, "
              "auto is tighten.")
@click.option("--error-output", type=click.Path(dir_okay=False),
              help="Write the error estimate per state (CSV: variable, max_abs_error, "
              "relative_error, at_time, method) here.")
@click.option("--step", type=float, help="Step size [s] of the fixed-step solvers "
              "(required for them).")
@click.option("--rtol", type=float, help="Relative tolerance (default: experiment "
              "Tolerance, else 1e-6).")
@click.option("--atol", type=float, help="Absolute tolerance (default: rtol/1000).")
@click.option("--max-steps", type=click.IntRange(min=1), default=None,
              help="Stop with an error after this many integrator steps (default "
              "20,000,000).")
@click.option("--time-limit", type=NumberRange(min=0, min_open=True), default=None,
              help="Stop with an error after this many seconds of wall clock (default "
              "3600).")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the trajectory: .csv, or .mat (the MATLAB v4 result layout of "
              "OpenModelica and Dymola); default: CSV on stdout unless --plot.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write a plot: .png, .svg or .pdf.")
@click.option("--event-rows", is_flag=True, help="For a model with events: add two rows at "
              "each event, its left and right limits (default: one row per output time).")
@verbosity_options("No progress bar, no summary line and no status lines (\"springc: "
                   "compiling ...\" before a step that compiles, once).")
@units_option
@guard
def simulate(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, solver: str, engine: str,
             error_control: str | None, error_estimate: str | None,
             error_output: str | None, rtol: float | None, step: float | None,
             atol: float | None,
             assignments: tuple[str, ...], max_steps: int | None,
             time_limit: float | None, output: str | None, plot: str | None,
             event_rows: bool, strict_units: bool) -> None:
    """Simulate a model and write its trajectory (CSV or MAT) and/or a plot."""
    from ..simulation import (
        PLOT_FORMATS,
        RESULT_FORMATS,
        check_run_values,
        choose_engine,
        error_control_mode,
        estimate_deprecation,
    )

    values = parse_set(assignments)
    if solver.lower() in FIXED_STEP and step is None:
        raise click.UsageError(f"--solver {solver.lower()} is a fixed-step solver and "
                               "needs --step H (e.g. --step 1e-3)")
    choose_engine(engine.lower(), solver.lower(), backend)
    check_run_values(start, stop, interval, rtol, atol, step, values, CLI_NAMES)
    check_output_options([("-o", output, RESULT_FORMATS), ("--plot", plot, PLOT_FORMATS),
                          ("--error-output", error_output, {".csv": "csv"})], files)
    mode = error_control_mode(error_control, error_estimate)
    if error_output and mode == "off":  # the table asked for needs the estimate
        option = "--error-control" if error_control else "--error-estimate"
        raise click.UsageError(f"--error-output needs an error estimate, which {option} off "
                               "turns off")
    if error_estimate is not None:
        click.echo(f"warning: {estimate_deprecation(error_estimate)}", err=True)
    single_threaded_blas()
    from ..api import AccuracyWarning, compile_model, default_choice
    from ..api import simulate as run
    from ..simulation import (
        SimulationOptions,
        check_trajectory_size,
        save_outputs,
        write_csv,
    )

    level = verbosity()
    quiet = level < 0
    with silenced(quiet):  # the status lines of long steps (compiling)
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=default_choice(backend, engine, solver),
                                 outputs=patterns or None, parameters=values,
                                 cache=not no_cache)
        report_units(compiled.warnings, strict_units)
        if not patterns and (output or not plot):  # the default trajectory of every output
            check_trajectory_size(compiled, SimulationOptions(start, stop, interval),
                                  f"-o {output}" if output else "the CSV on stdout")
        progress = None if quiet or not sys.stderr.isatty() else sys.stderr
        with warnings.catch_warnings():  # said below as the command's own warning
            warnings.simplefilter("ignore", AccuracyWarning)
            result = run(compiled, start=start, stop=stop, interval=interval,
                         solver=solver.lower(), rtol=rtol, atol=atol,
                         parameters={k: v for k, v in values.items()
                                     if k not in compiled.structural},
                         progress=progress, step=step, max_steps=max_steps,
                         time_limit=time_limit, engine=engine.lower(), error_control=mode,
                         event_rows=event_rows)
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
