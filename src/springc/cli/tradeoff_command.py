"""``springc tradeoff``: accuracy against cost of the solvers on one model."""

from __future__ import annotations

import sys

import click

from ..errors import UsageError
from ..simulation import RunSettings
from .app import guard, main
from .options import (
    TIMES,
    NumberRange,
    check_output_options,
    compile_options,
    model_options,
    run_settings_options,
    single_threaded_blas,
    values_named_by,
    verbosity,
    verbosity_options,
)


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
    from ..tradeoff import available_solvers

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
@model_options
@compile_options
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
              help="Timed runs of a contender, at least (the fastest kept; a short one "
              "until 0.2 s of timings): a run meeting a --max-error within 5x of the fastest "
              "one known, and scipy's default call; other runs, and runs over 2 s, are "
              "timed once.")
@click.option("--cost-limit", type=NumberRange(min=1), default=10.0, show_default=True,
              metavar="FACTOR", help="Skip a solver's tighter settings once one of its runs "
              "takes FACTOR times dop853's fastest run meeting every --max-error (the "
              "table says which); inf runs them all.")
@click.option("--budget", type=NumberRange(min=0, min_open=True), default=30.0,
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
@verbosity_options("No line per run on stderr.")
@guard
@run_settings_options(*TIMES)
def tradeoff(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool, settings: RunSettings,
             solvers: tuple[str, ...] | None, tolerances: tuple[float, ...] | None,
             steps: tuple[float, ...] | None, targets: tuple[float, ...] | None,
             reference: str | None, save_reference: str | None, repeats: int,
             cost_limit: float, budget: float, output: str | None, plot: str | None,
             energy: str | None,
             workers: int | None, scheduler: str | None) -> None:
    """Accuracy vs cost of the solvers: a table, a work-precision plot, a recommendation.

    The error of each run is measured on the output grid against REFERENCE, or against
    a tight dop853 solve checked by a second method (VODE Adams). By default the states
    are compared; --vars selects other variables. dop853 runs first, then each other
    solver's runs are one task of the studies executor (local processes, or Dask with
    --scheduler), its tighter settings skipped past --cost-limit. Every run is at the
    setting its row names: no --error-control (simulate's companion runs and
    tightening): the table measures each run's error itself.
    """
    from ..simulation import PLOT_FORMATS

    quiet = verbosity() < 0
    if workers is not None and scheduler is not None:
        raise UsageError("--workers and --scheduler exclude each other (a Dask cluster "
                         "has its own workers)", option="--workers")

    values = settings.parameters
    inputs = (*files, *([reference] if reference else []))
    check_output_options([("-o", output, {".csv": "csv"}), ("--plot", plot, PLOT_FORMATS),
                    ("--save-reference", save_reference, {".csv": "csv"})], inputs)
    single_threaded_blas()
    from ..api import compile_model, default_choice
    from ..tradeoff import (
        DEFAULT_TARGETS,
        DEFAULT_TOLERANCES,
        SPREAD_ABOVE,
        TradeoffOptions,
        compare_states,
        run_tradeoff,
        save_study,
        summary,
    )

    # numba by default: the runs of solvers with a compiled loop run there (many runs
    # share one compilation)
    with values_named_by("--set"):
        compiled = compile_model(files, model, libraries=libraries,
                                 backend=default_choice(backend),
                                 outputs=patterns or None, parameters=values,
                                 cache=not no_cache)
    if not patterns:
        compiled = compare_states(compiled)
    rest = {k: v for k, v in values.items() if k not in compiled.structural}
    options = TradeoffOptions(
        solvers=solvers, tolerances=tolerances or DEFAULT_TOLERANCES, steps=steps,
        targets=targets or DEFAULT_TARGETS, reference=reference, repeats=repeats,
        budget=budget, cost_limit=cost_limit, start=settings.start, stop=settings.stop,
        interval=settings.interval, parameters=rest,
        log=None if quiet else sys.stderr, energy=energy)
    from ..studies import Executor

    # a small study stays in this process unless workers or a scheduler are asked for
    spread = 0.0 if workers is not None or scheduler is not None else SPREAD_ABOVE
    study = run_tradeoff(compiled, options, Executor(workers, scheduler), spread)
    click.echo(summary(study), nl=False)
    save_study(study, table=output, plot=plot, reference=save_reference, protected=inputs)
