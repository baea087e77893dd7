"""Command-line interface: click options -> checked values and frozen options objects ->
library calls -> text on stdout.

Exit codes: 0 success, 1 model errors (diagnostics on stderr), 2 usage errors (a bad
option value, an output file springc refuses to write), 3 internal errors (traceback
only with ``--debug``); 130 after Ctrl-C, 143 after SIGTERM, 141 when stdout is a pipe
closed early (``springc simulate m.mdl | head -1``), quietly. Unfinished output files
are removed in every case (:mod:`springc.fileio`).
"""

from __future__ import annotations

import functools
import importlib.util
import json
import os
import signal
import sys
import traceback
from collections.abc import Callable, Sequence
from types import FrameType
from typing import Any

import click

from .errors import ErrorGroup, OutputError, SpringcError, UsageError, render_all
from .ir.expr import recursion_room
from .simulation import ALL_SOLVERS, DEFAULT_ENGINE, DEFAULT_SOLVER, ENGINES, FIXED_STEP

EXIT_MODEL_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE
EXIT_INTERRUPTED = 128 + signal.SIGINT

CLI_NAMES = {"start": "--start", "stop": "--stop", "interval": "--interval",
             "rtol": "--rtol", "atol": "--atol", "step": "--step", "parameters": "--set"}
"""How the checks of :func:`springc.simulation.check_run_values` name the options."""


def _terminate(signum: int, frame: FrameType | None) -> None:
    """SIGTERM ends the run as an exception, so that unfinished outputs are removed."""
    raise SystemExit(128 + signum)


def _silence_stdout() -> None:
    """After a closed pipe: send what is left in stdout's buffer nowhere."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass  # stdout is not a real file (a test runner's buffer)
    finally:
        os.close(devnull)


def _guard(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn springc errors into diagnostics and crashes into exit code 3."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        debug = click.get_current_context().find_root().params.get("debug", False)
        try:
            with recursion_room():  # expressions up to ir.expr.MAX_DEPTH deep
                return func(*args, **kwargs)
        except UsageError as err:
            click.echo(str(err), err=True)
            sys.exit(EXIT_USAGE)
        except (SpringcError, ErrorGroup) as err:
            click.echo(render_all(err), err=True)
            sys.exit(EXIT_MODEL_ERROR)
        except KeyboardInterrupt:
            click.echo("interrupted", err=True)
            sys.exit(EXIT_INTERRUPTED)
        except BrokenPipeError:
            _silence_stdout()
            sys.exit(EXIT_BROKEN_PIPE)
        except (click.exceptions.Exit, click.ClickException):
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
                        "then SPRINGC_PATH and MODELICAPATH.")(func)
    func = click.option("--model", "model", default=None,
                        help="Dotted name of the model (default: the last model of the "
                        "last file).")(func)
    return click.argument("files", nargs=-1, required=True,
                          type=click.Path(exists=True, dir_okay=False))(func)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
@click.option("--max-size", type=click.IntRange(min=1), default=None, metavar="N",
              help="Cap on the flat model's scalars and on loop iterations while "
                   "flattening (default 2,000,000; the same as $SPRINGC_MAX_SIZE).")
@click.version_option(package_name="springc")
def main(debug: bool, max_size: int | None) -> None:
    """springc: compile and simulate spring-mass models written in a Modelica subset."""
    if max_size is not None:  # read by flatten (and inherited by sweep's workers)
        os.environ["SPRINGC_MAX_SIZE"] = str(max_size)
    try:
        if signal.getsignal(signal.SIGTERM) == signal.SIG_DFL:
            signal.signal(signal.SIGTERM, _terminate)
    except ValueError:
        pass  # not the main thread: leave signals alone


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


def _check_outputs(outputs: Sequence[tuple[str, str | None, dict[str, str] | None]],
                   protected: Sequence[str]) -> None:
    """Refuse, before any work, outputs that cannot be written: ``(option, path,
    formats by suffix or None)``; a UsageError names the option."""
    from .fileio import check_distinct, check_target
    from .simulation import file_format

    given = [(option, path, formats) for option, path, formats in outputs if path]
    try:
        for option, path, formats in given:
            if formats is not None:
                file_format(path, formats, option)
            try:
                check_target(path, protected)
            except OutputError as err:
                raise UsageError(f"{option}: {err.message}", option=option,
                                 hint=err.hint) from None
        check_distinct((option, path) for option, path, _ in given)
    except OutputError as err:
        raise UsageError(err.message, hint=err.hint) from None


def _run_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """The options of a run shared by ``simulate`` and ``tradeoff``."""
    func = click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE",
                        help="Set a parameter (repeatable); array sizes re-flatten the "
                        "model.")(func)
    func = click.option("--interval", type=float,
                        help="Output interval [s] (default: experiment, else "
                        "(stop-start)/500).")(func)
    func = click.option("--stop", type=float,
                        help="Stop time [s] (default: experiment, else 10).")(func)
    return click.option("--start", type=float,
                        help="Start time [s] (default: experiment, else 0).")(func)


def _compile_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("--no-cache", is_flag=True,
                        help="Regenerate the code instead of using the on-disk cache.")(func)
    func = click.option("--vars", "patterns", multiple=True, metavar="PATTERN",
                        help="Output only these variables: flat names, * and ? as "
                        "wildcards (repeatable). Default: all states and observed.")(func)
    return click.option("--backend", type=click.Choice(["python", "numba"]),
                        default=None,
                        help="Generated code: plain Python/numpy, or numba-compiled "
                        "(default: numba for simulate's compiled engine, else "
                        "python).")(func)


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
@_run_options
@click.option("--solver", type=click.Choice(ALL_SOLVERS, case_sensitive=False),
              default=DEFAULT_SOLVER, show_default=True,
              help="auto: dop853 or radau from a stiffness estimate at the start (the "
              "summary says why); a scipy solve_ivp method; or a fixed-step one "
              "(verlet, symplectic-euler, rk4) with --step.")
@click.option("--engine", type=click.Choice(ENGINES, case_sensitive=False),
              default=DEFAULT_ENGINE, show_default=True,
              help="compiled: numba loops (springc.integrate) for dop853, auto's dop853 "
              "and the fixed-step solvers; scipy: scipy's solvers stepped from Python; "
              "auto: compiled for the numba backend (--backend numba), else scipy.")
@click.option("--error-estimate", type=click.Choice(("off", "on", "auto"),
                                                   case_sensitive=False),
              default="auto", show_default=True,
              help="Estimate the global error reached on the output grid (a companion "
              "run at a 1000x tighter tolerance, or half the step for fixed-step "
              "solvers): in the summary line and in the side file NAME.error.csv next to "
              "-o NAME.csv; auto: where it costs at most about 30 % of the run.")
@click.option("--step", type=float, help="Step size [s] of the fixed-step solvers "
              "(required for them).")
@click.option("--rtol", type=float, help="Relative tolerance (default: experiment "
              "Tolerance, else 1e-6).")
@click.option("--atol", type=float, help="Absolute tolerance (default: rtol/1000).")
@click.option("--max-steps", type=click.IntRange(min=1), default=None,
              help="Stop with an error after this many integrator steps (default "
              "20,000,000).")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Stop with an error after this many seconds of wall clock (default "
              "3600).")
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the trajectory: .csv, or .mat (the MATLAB v4 result layout of "
              "OpenModelica and Dymola); default: CSV on stdout unless --plot.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write a plot: .png, .svg or .pdf.")
@click.option("--event-rows", is_flag=True, help="For a model with events: add two rows at "
              "each event, its left and right limits (default: one row per output time).")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar and no summary line.")
@_guard
def simulate(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, solver: str, engine: str,
             error_estimate: str, rtol: float | None, step: float | None,
             atol: float | None,
             assignments: tuple[str, ...], max_steps: int | None,
             time_limit: float | None, output: str | None, plot: str | None,
             event_rows: bool, quiet: bool) -> None:
    """Simulate a model and write its trajectory (CSV or MAT) and/or a plot."""
    from .simulation import PLOT_FORMATS, RESULT_FORMATS, check_run_values, choose_engine

    values = _parse_set(assignments)
    if solver.lower() in FIXED_STEP and step is None:
        raise click.UsageError(f"--solver {solver.lower()} is a fixed-step solver and "
                               "needs --step H (e.g. --step 1e-3)")
    chosen = choose_engine(engine.lower(), solver.lower(), backend)
    check_run_values(start, stop, interval, rtol, atol, step, values, CLI_NAMES)
    _check_outputs([("-o", output, RESULT_FORMATS), ("--plot", plot, PLOT_FORMATS)],
                   files)
    _single_threaded_blas()
    from .api import compile_model
    from .api import simulate as run
    from .simulation import (
        SimulationOptions,
        check_trajectory_size,
        save_outputs,
        write_csv,
    )

    compiled = compile_model(files, model, libraries=libraries, backend=backend or (
        "numba" if chosen == "compiled" else "python"), outputs=patterns or None,
        parameters=values, cache=not no_cache)
    if not patterns and (output or not plot):  # the default trajectory of every output
        check_trajectory_size(compiled, SimulationOptions(start, stop, interval),
                              f"-o {output}" if output else "the CSV on stdout")
    progress = None if quiet or not sys.stderr.isatty() else sys.stderr
    result = run(compiled, start=start, stop=stop, interval=interval,
                 solver=solver.lower(), rtol=rtol, atol=atol,
                 parameters={k: v for k, v in values.items() if k not in compiled.structural},
                 progress=progress, step=step, max_steps=max_steps, time_limit=time_limit,
                 engine=engine.lower(), error_estimate=error_estimate.lower(),
                 event_rows=event_rows)
    if output or plot:
        note = save_outputs(result, output, plot, files)
        if note and not quiet:
            click.echo(f"note: plot {plot}: {note}", err=True)
    else:
        write_csv(result, sys.stdout)
        sys.stdout.flush()
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

    _check_outputs([("-o", output, None)], files)
    compiled = compile_files(CompileOptions(files, model, libraries, backend or "python",
                                            patterns or None, (), not no_cache))
    if output:
        from .fileio import atomic_write

        with atomic_write(output, "w", files) as f:
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
@_run_options
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
              help="Write the table as CSV (.csv).")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write the work-precision plot: .png, .svg or .pdf.")
@click.option("--energy", metavar="NAME",
              help="Variable whose drift is reported per run (default: the only "
              "variable in J, if any).")
@click.option("--workers", type=click.IntRange(min=1),
              help="Local worker processes running the solvers (default: one per core).")
@click.option("--scheduler", metavar="ADDRESS", help="Run the solvers on the Dask "
              "scheduler at ADDRESS instead of local processes (as for sweep).")
@click.option("--quiet", "-q", is_flag=True, help="No line per run on stderr.")
@_guard
def tradeoff(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
             stop: float | None, interval: float | None, assignments: tuple[str, ...],
             solvers: tuple[str, ...] | None, tolerances: tuple[float, ...] | None,
             steps: tuple[float, ...] | None, targets: tuple[float, ...] | None,
             reference: str | None, save_reference: str | None, repeats: int,
             budget: float, output: str | None, plot: str | None, energy: str | None,
             workers: int | None, scheduler: str | None, quiet: bool) -> None:
    """Accuracy vs cost of the solvers: a table, a work-precision plot, a recommendation.

    The error of each run is measured on the output grid against REFERENCE, or against
    a tight dop853 solve checked by a second method (VODE Adams). By default the states
    are compared; --vars selects other variables. Each solver's runs are one task of
    the studies executor (local processes, or Dask with --scheduler).
    """
    from .simulation import PLOT_FORMATS, check_run_values

    if workers is not None and scheduler is not None:
        raise UsageError("--workers and --scheduler exclude each other (a Dask cluster "
                         "has its own workers)", option="--workers")

    values = _parse_set(assignments)
    check_run_values(start, stop, interval, parameters=values, names=CLI_NAMES)
    inputs = (*files, *([reference] if reference else []))
    _check_outputs([("-o", output, {".csv": "csv"}), ("--plot", plot, PLOT_FORMATS),
                    ("--save-reference", save_reference, {".csv": "csv"})], inputs)
    _single_threaded_blas()
    from .api import compile_model
    from .tradeoff import (
        DEFAULT_TARGETS,
        DEFAULT_TOLERANCES,
        TradeoffOptions,
        compare_states,
        run_tradeoff,
        save_study,
        summary,
    )

    # numba by default: the runs of solvers with a compiled loop run there (many runs
    # share one compilation)
    numba = importlib.util.find_spec("numba") is not None
    compiled = compile_model(files, model, libraries=libraries,
                             backend=backend or ("numba" if numba else "python"),
                             outputs=patterns or None, parameters=values,
                             cache=not no_cache)
    if not patterns:
        compiled = compare_states(compiled)
    rest = {k: v for k, v in values.items() if k not in compiled.structural}
    options = TradeoffOptions(
        solvers=solvers, tolerances=tolerances or DEFAULT_TOLERANCES, steps=steps,
        targets=targets or DEFAULT_TARGETS, reference=reference, repeats=repeats,
        budget=budget, start=start, stop=stop, interval=interval, parameters=rest,
        log=None if quiet else sys.stderr, energy=energy)
    from .studies import Executor

    study = run_tradeoff(compiled, options, Executor(workers, scheduler))
    click.echo(summary(study), nl=False)
    save_study(study, table=output, plot=plot, reference=save_reference, protected=inputs)


# ------------------------------------------------------------------ sweep

@main.command()
@_model_options
@_compile_options
@_run_options
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=VALUES",
              help="A parameter to vary (repeatable): a list 0.5,1,2; a range "
              "START:STOP[:lin|log]:COUNT; with --samples, a range START:STOP[:log] or a "
              "distribution uniform(a,b), loguniform(a,b), normal(mean,std), "
              "lognormal(mu,sigma), triangular(a,mode,b). Grid: every combination.")
@click.option("--samples", type=click.IntRange(min=1), help="Draw this many runs from "
              "the --param ranges/distributions instead of a grid.")
@click.option("--method", type=click.Choice(["lhs", "mc"]), default="lhs",
              show_default=True, help="With --samples: Latin hypercube or Monte Carlo.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of --samples (the same seed gives the same runs).")
@click.option("--workers", type=click.IntRange(min=1),
              help="Local worker processes (default: one per core).")
@click.option("--scheduler", metavar="ADDRESS", help="Run on the Dask scheduler at "
              "ADDRESS (tcp://host:8786) instead of local processes.")
@click.option("--solver", type=click.Choice(ALL_SOLVERS, case_sensitive=False),
              default=DEFAULT_SOLVER, show_default=True, help="As for simulate.")
@click.option("--step", type=float, help="Step size [s] of the fixed-step solvers.")
@click.option("--rtol", type=float, help="Relative tolerance (default: experiment "
              "Tolerance, else 1e-6).")
@click.option("--atol", type=float, help="Absolute tolerance (default: rtol/1000).")
@click.option("--max-steps", type=click.IntRange(min=1), default=None,
              help="Integrator steps per run before it fails (as for simulate).")
@click.option("--time-limit", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Seconds of wall clock per run before it fails (as for simulate).")
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
@click.option("--quiet", "-q", is_flag=True, help="No progress and no summary line.")
@_guard
def sweep(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
          backend: str, patterns: tuple[str, ...], no_cache: bool, start: float | None,
          stop: float | None, interval: float | None, assignments: tuple[str, ...],
          params: tuple[str, ...], samples: int | None, method: str, seed: int,
          workers: int | None, scheduler: str | None, solver: str, step: float | None,
          rtol: float | None, atol: float | None, max_steps: int | None,
          time_limit: float | None, energy: str | None, output: str,
          summary_file: str | None, resume: bool, plot: str | None,
          plot_var: str | None, quiet: bool) -> None:
    """Run a model over a grid or samples of parameter values, in parallel, into Parquet.

    The model is compiled once; runs go to local processes (or a Dask scheduler); each
    run's parameters, status, solver statistics and trajectories are written to OUTPUT,
    one row per run and output time, and a summary per run (final, min, max of each
    variable) next to it. A failing run is recorded with its error; an interrupted
    study continues with --resume.
    """
    from .simulation import check_run_values
    from .studies import check_outputs, parse_parameter, summary_path

    values = _parse_set(assignments)
    if solver.lower() in FIXED_STEP and step is None:
        raise click.UsageError(f"--solver {solver.lower()} is a fixed-step solver and "
                               "needs --step H (e.g. --step 1e-3)")
    if workers is not None and scheduler is not None:
        raise UsageError("--workers and --scheduler exclude each other (a Dask cluster "
                         "has its own workers)", option="--workers")
    check_run_values(start, stop, interval, rtol, atol, step, values, CLI_NAMES)
    specs = tuple(parse_parameter(item) for item in params)
    summary_file = summary_file or summary_path(output)
    check_outputs(output, summary_file, files)
    from .simulation import PLOT_FORMATS

    _check_outputs([("-o", output, None), ("--summary", summary_file, None),
                    ("--plot", plot, PLOT_FORMATS)], files)
    _single_threaded_blas()
    from .api import compile_model
    from .studies import StudyOptions, parameter_table, run_study

    options = StudyOptions(specs, samples, method, seed, (), start, stop, interval,
                           solver.lower(), rtol, atol, step, workers, scheduler, energy,
                           max_steps, time_limit)
    parameter_table(options)  # refuse bad specifications before compiling
    compiled = compile_model(files, model, libraries=libraries, backend=backend or "python",
                             outputs=patterns or None, parameters=values,
                             cache=not no_cache)
    fixed = tuple((k, v) for k, v in values.items() if k not in compiled.structural)
    from dataclasses import replace

    from .studies import plot_variable

    plotted = plot_variable(compiled.outputs, plot_var) if plot else None

    try:
        study = run_study(compiled, replace(options, fixed=fixed), output, summary_file,
                          resume, files, None if quiet else sys.stderr)
    except (KeyboardInterrupt, SystemExit):
        from .studies import partial_folder

        if partial_folder(output).is_dir():
            click.echo(f"note: finished runs are kept in {partial_folder(output)}; run "
                       "the same command with --resume to continue", err=True)
        raise
    if plot and plotted:
        from .fileio import atomic_write
        from .simulation import file_format
        from .studies import render_fan

        picture, note = render_fan(study, plotted, file_format(plot, PLOT_FORMATS, "--plot"))
        with atomic_write(plot, "wb", files) as f:
            f.write(picture)
        if not quiet:
            click.echo(f"note: plot {plot}: {note}", err=True)
    if not quiet:
        click.echo(study.summary_line(), err=True)
