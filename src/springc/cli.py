"""Command-line interface: click options -> library calls -> text on stdout.

Exit codes: 0 success, 1 model errors (diagnostics on stderr), 2 usage errors,
3 internal errors (traceback only with ``--debug``).
"""

from __future__ import annotations

import functools
import json
import sys
import traceback
from collections.abc import Callable
from typing import Any

import click

from .errors import ErrorGroup, SpringcError, render_all
from .ir.expr import recursion_room

EXIT_MODEL_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3


def _guard(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn springc errors into diagnostics and crashes into exit code 3."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        debug = click.get_current_context().find_root().params.get("debug", False)
        try:
            with recursion_room():  # expressions up to ir.expr.MAX_DEPTH deep
                return func(*args, **kwargs)
        except (SpringcError, ErrorGroup) as err:
            click.echo(render_all(err), err=True)
            sys.exit(EXIT_MODEL_ERROR)
        except (click.exceptions.Exit, click.ClickException, KeyboardInterrupt):
            raise
        except Exception as err:
            if debug:
                traceback.print_exc()
            else:
                click.echo(f"internal error: {type(err).__name__}: {err}\n"
                           "this is a bug in springc; rerun with --debug for the traceback "
                           "and report it", err=True)
            sys.exit(EXIT_INTERNAL)

    return wrapper


def _model_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("-L", "--library", "libraries", multiple=True,
                        type=click.Path(exists=True, file_okay=False),
                        help="Library folder to search for classes (repeatable); "
                        "SPRINGC_PATH is searched too.")(func)
    func = click.option("--model", "model", default=None,
                        help="Dotted name of the model (default: the last model of the "
                        "last file).")(func)
    return click.argument("files", nargs=-1, required=True,
                          type=click.Path(exists=True, dir_okay=False))(func)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
@click.version_option(package_name="springc")
def main(debug: bool) -> None:
    """springc: compile and simulate spring-mass models written in a Modelica subset."""


@main.command()
@_model_options
@click.option("--origins", is_flag=True, help="Show where each equation comes from.")
@click.option("--json", "as_json", is_flag=True, help="Print the flat model as JSON.")
@click.option("--simplify", "simplified", is_flag=True,
              help="Print the simplified system: states, evaluation order, observed.")
@click.option("--latex", "as_latex", is_flag=True,
              help="Print the equations (with --simplify: the evaluation order) as LaTeX.")
@_guard
def flatten(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
            origins: bool, as_json: bool, simplified: bool, as_latex: bool) -> None:
    """Print the flat model of FILES as Modelica text (or JSON, or LaTeX)."""
    from .ir.flat import format_flat, format_flat_latex, to_json_dict
    from .pipeline import flatten_files

    if as_latex and as_json:
        raise click.UsageError("--latex and --json cannot be combined")
    flat_model = flatten_files(files, model, libraries)
    if simplified:
        from .ir.ode import format_ode, format_ode_latex
        from .simplify import simplify

        result = simplify(flat_model)
        click.echo((format_ode_latex if as_latex else format_ode)(result.ode), nl=False)
        for note in result.warnings:
            click.echo(f"{note.span}: warning: {note.message}" if note.span
                       else f"warning: {note.message}", err=True)
    elif as_json:
        click.echo(json.dumps(to_json_dict(flat_model), indent=1))
    elif as_latex:
        click.echo(format_flat_latex(flat_model), nl=False)
    else:
        click.echo(format_flat(flat_model, origins), nl=False)


@main.command()
@_model_options
@_guard
def check(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...]) -> None:
    """Check that a model flattens and is balanced; print a one-line summary."""
    from .pipeline import flatten_files
    from .simplify import check_balance

    click.echo(check_balance(flatten_files(files, model, libraries)).summary())


# ------------------------------------------------------------------ simulate, compile

SOLVER_CHOICES = ("auto", "rk45", "dop853", "radau", "bdf", "lsoda",  # simulation.SOLVERS
                  "verlet", "symplectic-euler", "rk4")  # simulation.FIXED_STEP


def _parse_set(values: tuple[str, ...]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in values:
        name, sep, text = item.partition("=")
        if not sep or not name.strip():
            raise click.BadParameter(f"expected NAME=VALUE, got '{item}'", param_hint="--set")
        word = text.strip().lower()
        if word in ("true", "false"):
            out[name.strip()] = 1.0 if word == "true" else 0.0
            continue
        try:
            out[name.strip()] = float(text)
        except ValueError:
            raise click.BadParameter(f"'{text}' is not a number (in '{item}')",
                                     param_hint="--set") from None
    return out


def _compile_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("--no-cache", is_flag=True,
                        help="Regenerate the code instead of using the on-disk cache.")(func)
    func = click.option("--vars", "patterns", multiple=True, metavar="PATTERN",
                        help="Output only these variables: flat names, * and ? as "
                        "wildcards (repeatable). Default: all states and observed.")(func)
    return click.option("--backend", type=click.Choice(["python", "numba"]),
                        default="python", show_default=True,
                        help="Generated code: plain Python/numpy, or numba-compiled.")(func)


def _single_threaded_blas() -> None:
    """Run BLAS on one thread unless the user chose otherwise: the solvers' vector
    operations are too small to gain from threads, and on a busy machine threaded
    OpenBLAS made a 20,000-state BDF run eight times slower."""
    import os

    if "numpy" not in sys.modules:
        for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(var, "1")


@main.command()
@_model_options
@_compile_options
@click.option("--start", type=float, help="Start time [s] (default: experiment, else 0).")
@click.option("--stop", type=float, help="Stop time [s] (default: experiment, else 10).")
@click.option("--interval", type=float,
              help="Output interval [s] (default: experiment, else (stop-start)/500).")
@click.option("--solver", type=click.Choice(SOLVER_CHOICES, case_sensitive=False),
              default="auto", show_default=True,
              help="auto: dop853 or radau from a stiffness estimate at the start (the "
              "summary says why); a scipy solve_ivp method; or a fixed-step one "
              "(verlet, symplectic-euler, rk4) with --step.")
@click.option("--step", type=float, help="Step size [s] of the fixed-step solvers "
              "(required for them).")
@click.option("--rtol", type=float, help="Relative tolerance (default: experiment "
              "Tolerance, else 1e-6).")
@click.option("--atol", type=float, help="Absolute tolerance (default: rtol/1000).")
@click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE",
              help="Set a parameter (repeatable); array sizes re-flatten the model.")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the trajectory as CSV (default: stdout unless --plot).")
@click.option("--plot", type=click.Path(dir_okay=False), help="Write a PNG plot.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary line.")
@_guard
def simulate(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, solver: str, rtol: float | None,
             step: float | None, atol: float | None, assignments: tuple[str, ...],
             output: str | None, plot: str | None, quiet: bool) -> None:
    """Simulate a model and write its trajectory (CSV) and/or a plot (PNG)."""
    values = _parse_set(assignments)
    if solver.lower() in SOLVER_CHOICES[-3:] and step is None:
        raise click.UsageError(f"--solver {solver.lower()} is a fixed-step solver and "
                               "needs --step H (e.g. --step 1e-3)")
    if step is not None and not step > 0:
        raise click.BadParameter(f"{step:g} is not positive", param_hint="--step")
    _single_threaded_blas()
    from .api import simulate as run

    progress = None if quiet or not sys.stderr.isatty() else sys.stderr
    result = run(files, model_name=model, libraries=libraries, backend=backend,
                 outputs=patterns or None, cache=not no_cache, start=start, stop=stop,
                 interval=interval, solver=solver.lower(), rtol=rtol, atol=atol,
                 parameters=values, progress=progress, step=step)
    if output:
        result.to_csv(output)
    elif not plot:
        from .simulation import write_csv

        write_csv(result, sys.stdout)
    if plot:
        result.plot(plot)
    if not quiet:
        click.echo(result.stats.summary(result.model), err=True)


@main.command(name="compile")
@_model_options
@_compile_options
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the generated Python module here (default: stdout).")
@_guard
def compile_(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool,
             output: str | None) -> None:
    """Generate a standalone Python module (numpy/scipy, or numba) for a model."""
    from .pipeline import CompileOptions, compile_files

    compiled = compile_files(CompileOptions(files, model, libraries, backend,
                                            patterns or None, (), not no_cache))
    if output:
        from pathlib import Path

        from .fileio import atomic_write

        with atomic_write(Path(output), "w") as f:
            f.write(compiled.source)
    else:
        click.echo(compiled.source, nl=False)


# ------------------------------------------------------------------ tradeoff

def _split(value: str | None) -> list[str]:
    return [] if value is None else [w for w in value.replace(",", " ").split() if w]


def _positive_list(ctx: click.Context, param: click.Parameter, value: str | None
                   ) -> tuple[float, ...] | None:
    if value is None:
        return None
    out = []
    for word in _split(value):
        try:
            number = float(word)
        except ValueError:
            raise click.BadParameter(f"'{word}' is not a number") from None
        if not 0 < number < float("inf"):
            raise click.BadParameter(f"{word} is not positive")
        out.append(number)
    if not out:
        raise click.BadParameter("the list is empty")
    return tuple(out)


def _solver_list(ctx: click.Context, param: click.Parameter, value: str | None
                 ) -> tuple[str, ...] | None:
    if value is None:
        return None
    from .tradeoff import available_solvers

    names = tuple(w.lower() for w in _split(value))
    known = available_solvers()
    for name in names:
        if name not in known:
            raise click.BadParameter(f"unknown solver '{name}' (choose from "
                                     f"{', '.join(known)})")
    if not names:
        raise click.BadParameter("the list is empty")
    return names


@main.command()
@_model_options
@_compile_options
@click.option("--start", type=float, help="Start time [s] (default: experiment, else 0).")
@click.option("--stop", type=float, help="Stop time [s] (default: experiment, else 10).")
@click.option("--interval", type=float,
              help="Output interval [s] (default: experiment, else (stop-start)/500).")
@click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE",
              help="Set a parameter (repeatable); array sizes re-flatten the model.")
@click.option("--solvers", callback=_solver_list, metavar="LIST",
              help="Solvers to compare, e.g. 'dop853,radau' (default: rk45 dop853 radau "
              "bdf lsoda and the fixed-step ones).")
@click.option("--tolerances", callback=_positive_list, metavar="LIST",
              help="rtol values of the adaptive solvers (atol = rtol/1000; default "
              "1e-3 ... 1e-10).")
@click.option("--steps", callback=_positive_list, metavar="LIST",
              help="Step sizes [s] of the fixed-step solvers (default: the output "
              "interval divided by 2, 4, ..., 256).")
@click.option("--max-error", "targets", callback=_positive_list, metavar="LIST",
              help="Errors to recommend a setting for (default 1e-4).")
@click.option("--reference", type=click.Path(exists=True, dir_okay=False),
              help="Reference trajectory CSV (as written by simulate -o) instead of a "
              "tight solve.")
@click.option("--save-reference", type=click.Path(dir_okay=False),
              help="Write the reference trajectory as CSV (reusable with --reference).")
@click.option("--repeats", type=click.IntRange(min=1), default=3, show_default=True,
              help="Timed runs per setting (median); runs over 2 s are timed once.")
@click.option("--budget", type=click.FloatRange(min=0, min_open=True), default=30.0,
              show_default=True, help="Seconds per run: a longer run is stopped and the "
              "solver's tighter settings are skipped.")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the table as CSV.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write the work-precision plot (PNG).")
@click.option("--energy", metavar="NAME",
              help="Variable whose drift is reported per run (default: the only "
              "variable in J, if any).")
@click.option("--quiet", "-q", is_flag=True, help="No line per run on stderr.")
@_guard
def tradeoff(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, assignments: tuple[str, ...],
             solvers: tuple[str, ...] | None, tolerances: tuple[float, ...] | None,
             steps: tuple[float, ...] | None, targets: tuple[float, ...] | None,
             reference: str | None, save_reference: str | None, repeats: int,
             budget: float, output: str | None, plot: str | None, energy: str | None,
             quiet: bool) -> None:
    """Accuracy vs cost of the solvers: a table, a work-precision plot, a recommendation.

    The error of each run is measured on the output grid against REFERENCE, or against
    a tight dop853 solve checked by a second method (VODE Adams). By default the states
    are compared; --vars selects other variables.
    """
    values = _parse_set(assignments)
    _single_threaded_blas()
    from .api import compile_model
    from .tradeoff import (
        DEFAULT_TARGETS,
        DEFAULT_TOLERANCES,
        TradeoffOptions,
        compare_states,
        run_tradeoff,
        summary,
        write_table_csv,
    )

    compiled = compile_model(files, model, libraries=libraries, backend=backend,
                             outputs=patterns or None, parameters=values,
                             cache=not no_cache)
    if not patterns:
        compiled = compare_states(compiled)
    rest = {k: v for k, v in values.items() if k not in compiled.structural}
    options = TradeoffOptions(solvers, tolerances or DEFAULT_TOLERANCES, steps,
                              targets or DEFAULT_TARGETS, reference, repeats, budget,
                              start, stop, interval, rest, None if quiet else sys.stderr,
                              energy)
    study = run_tradeoff(compiled, options)
    click.echo(summary(study), nl=False)
    if save_reference:
        from .tradeoff import write_reference

        write_reference(study.reference, save_reference)
    if output:
        write_table_csv(study, output)
    if plot:
        from .tradeoff import write_work_precision

        write_work_precision(study, plot)
