"""Options and checks shared by the commands: the model's files, the compile and run
options, ``--set`` values, output paths refused before any work."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Sequence
from typing import Any

import click

from ..errors import ErrorGroup, OutputError, UnitError, UsageError, render


class NumberRange(click.FloatRange):
    """``click.FloatRange`` that also refuses ``nan`` (no comparison with a bound fails
    for it, so ``FloatRange`` lets it through)."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)
        if math.isnan(number):
            self.fail(f"{value!r} is not a number", param, ctx)
        return number


LEVEL_KEY = "springc.verbosity"
"""Where the ``-v``/``-q`` level of a command is kept (``click.Context.meta``)."""


def _remember(level: int) -> Callable[[click.Context, click.Parameter, Any], Any]:
    def callback(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
        if value and (level < 0 or ctx.meta.get(LEVEL_KEY, 0) >= 0):
            ctx.meta[LEVEL_KEY] = -1 if level < 0 else int(value)
        return value
    return callback


def verbosity_options(quiet_help: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``-v``/``-vv``/``-q``, the same levels for every command (:func:`verbosity`)."""
    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        func = click.option("-q", "--quiet", is_flag=True, expose_value=False,
                            callback=_remember(-1), help=quiet_help)(func)
        return click.option("-v", "--verbose", count=True, expose_value=False,
                            callback=_remember(1),
                            help="More on stderr: -v the full detail (a run's solver "
                            "choice, engine, evaluations, timings), -vv also what helps "
                            "debugging (tracebacks of internal errors, the generated "
                            "module's path).")(func)
    return decorate


def verbosity() -> int:
    """The level of the running command: -1 ``--quiet``, 0 the default (a short summary),
    1 ``-v``, 2 ``-vv`` and more; ``--quiet`` wins over ``-v``."""
    ctx = click.get_current_context(silent=True)
    return int(ctx.meta.get(LEVEL_KEY, 0)) if ctx is not None else 0


CLI_NAMES = {"start": "--start", "stop": "--stop", "interval": "--interval",
             "rtol": "--rtol", "atol": "--atol", "step": "--step", "parameters": "--set"}
"""How the checks of :func:`springc.simulation.check_run_values` name the options."""


def model_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("-L", "--library", "libraries", multiple=True,
                        type=click.Path(exists=True, file_okay=False),
                        help="Library folder to search for classes (repeatable); "
                        "then SPRINGC_PATH and MODELICAPATH.")(func)
    func = click.option("--model", "model", default=None,
                        help="Dotted name of the model (default: the last model of the "
                        "last file).")(func)
    return click.argument("files", nargs=-1, required=True,
                          type=click.Path(exists=True, dir_okay=False))(func)


def units_option(func: Callable[..., Any]) -> Callable[..., Any]:
    return click.option("--strict-units", is_flag=True,
                        help="Unit mismatches are errors (exit 1), not warnings.")(func)


def report_units(warnings: Sequence[UnitError], strict: bool) -> None:
    """Print the unit mismatches of a model as warnings, or raise them with
    ``--strict-units``."""
    if strict and warnings:
        raise warnings[0] if len(warnings) == 1 else ErrorGroup(warnings)
    if warnings:  # separated as errors are
        click.echo("\n\n".join(render(w, kind="warning") for w in warnings), err=True)


def parse_set(values: tuple[str, ...]) -> dict[str, float]:
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


def check_output_options(outputs: Sequence[tuple[str, str | None, dict[str, str] | None]],
                   protected: Sequence[str]) -> None:
    """Refuse, before any work, outputs that cannot be written: ``(option, path,
    formats by suffix or None)``; a UsageError names the option."""
    from ..fileio import check_distinct, check_target
    from ..simulation import file_format

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


def run_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """The options of a run shared by ``simulate`` and ``tradeoff``."""
    func = click.option("--set", "assignments", multiple=True, metavar="NAME=VALUE",
                        help="Set a parameter or the start value of a state "
                        "(repeatable; as OpenModelica's -override). A fixed start "
                        "(fixed=true) is the initial value; a free one is the guess of "
                        "the initial equations. Array sizes re-flatten the model; start "
                        "values never recompile it.")(func)
    func = click.option("--interval", type=float,
                        help="Output interval [s] (default: experiment, else "
                        "(stop-start)/500).")(func)
    func = click.option("--stop", type=float,
                        help="Stop time [s] (default: experiment, else 10).")(func)
    return click.option("--start", type=float,
                        help="Start time [s] (default: experiment, else 0).")(func)


def sampling_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """``--samples``, ``--method``, ``--seed``: the runs drawn from ``--param`` ranges,
    shared by ``sweep`` and ``ensemble``."""
    func = click.option("--seed", type=click.IntRange(min=0), default=0,
                        show_default=True,
                        help="Seed of --samples (the same seed gives the same runs).")(func)
    func = click.option("--method", type=click.Choice(["lhs", "mc"]), default="lhs",
                        show_default=True,
                        help="With --samples: Latin hypercube or Monte Carlo.")(func)
    return click.option("--samples", type=click.IntRange(min=1), help="Draw this many "
                        "runs from the --param ranges/distributions instead of a "
                        "grid.")(func)


def compile_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("--no-cache", is_flag=True,
                        help="Regenerate the code instead of using the on-disk cache.")(func)
    func = click.option("--vars", "patterns", multiple=True, metavar="PATTERN",
                        help="Output only these variables: flat names, * and ? as "
                        "wildcards (repeatable). Default: all states and observed.")(func)
    return click.option("--backend", type=click.Choice(["python", "numba"]),
                        default=None,
                        help="Generated code: numba-compiled, or plain Python/numpy "
                        "(default: numba where numba is installed, which the compiled "
                        "engine runs; python for --engine scipy and solvers without a "
                        "compiled loop).")(func)


def single_threaded_blas() -> None:
    """Run BLAS on one thread unless the user chose otherwise: the solvers' vector
    operations are too small to gain from threads, and on a busy machine threaded
    OpenBLAS made a 20,000-state BDF run eight times slower."""
    import os

    if "numpy" not in sys.modules:
        for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(var, "1")
