"""Options and checks shared by the commands: the model's files, the compile and run
options, ``--set`` values, output paths refused before any work."""

from __future__ import annotations

import contextlib
import functools
import math
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import click

from ..errors import (
    ErrorGroup,
    OutputError,
    Span,
    SpringcError,
    UnitError,
    UnknownParameterError,
    UsageError,
    render,
)
from ..simulation import (
    ALL_SOLVERS,
    DEFAULT_ENGINE,
    DEFAULT_ERROR_CONTROL,
    DEFAULT_SOLVER,
    ENGINES,
    ERROR_CONTROLS,
    FIXED_STEP,
    OPTION_NAMES,
    RunSettings,
    run_settings,
)


class NumberRange(click.FloatRange):
    """``click.FloatRange`` that also refuses ``nan`` (no comparison with a bound fails
    for it, so ``FloatRange`` lets it through)."""

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        number = super().convert(value, param, ctx)
        if math.isnan(number):
            self.fail(f"{value!r} is not a number", param, ctx)
        return number


class FolderPath(click.Path):
    """``click.Path`` for an existing folder that also refuses a FIFO, device or socket
    (``click.Path(file_okay=False)`` lets them through: they are no regular files)."""

    def __init__(self) -> None:
        super().__init__(exists=True, file_okay=False)

    def convert(self, value: Any, param: click.Parameter | None,
                ctx: click.Context | None) -> Any:
        path = super().convert(value, param, ctx)
        if not os.path.isdir(path):
            self.fail(f"{value!r} is not a folder.", param, ctx)
        return path


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


@contextlib.contextmanager
def values_named_by(option: str) -> Iterator[None]:
    """A value for a name the model lacks, given by ``option`` (``--set``), is a
    misuse of that option: exit 2 naming it, with the did-you-mean hint."""
    try:
        yield
    except UnknownParameterError as err:
        raise err.given_as(option) from None


def verbosity() -> int:
    """The level of the running command: -1 ``--quiet``, 0 the default (a short summary),
    1 ``-v``, 2 ``-vv`` and more; ``--quiet`` wins over ``-v``."""
    ctx = click.get_current_context(silent=True)
    return int(ctx.meta.get(LEVEL_KEY, 0)) if ctx is not None else 0


CLI_NAMES = OPTION_NAMES
"""How :func:`springc.simulation.check_run_values` names the options."""


def model_options(func: Callable[..., Any]) -> Callable[..., Any]:
    func = click.option("-L", "--library", "libraries", multiple=True,
                        type=FolderPath(),
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


@contextlib.contextmanager
def initial_warnings() -> Iterator[list[str]]:
    """Say the redundant initial conditions a run left out as located warnings (each
    once, after the run: the companion error run initializes again), and list them in
    what it yields; other Python warnings pass on as they came."""
    left_out: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.filterwarnings("always", r".*redundant initial condition", UserWarning)
        yield left_out
    # the class from springc.simplify where a run imported it (it initialized): a warm
    # run imports no compile path
    face = sys.modules.get("springc.simplify")
    redundant = getattr(face, "RedundantInitialWarning", ())
    said: dict[tuple[str, Span | None], None] = {}
    for item in caught:
        if not isinstance(item.message, redundant):
            warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
            continue
        said.update(((c.text, c.span), None) for c in item.message.conditions)
    left_out.extend(text for text, _ in said)
    for text, span in said:
        warning = SpringcError(f"initial condition '{text}' left out: the other initial "
                               "conditions determine it and it holds", span)
        click.echo(render(warning, kind="warning"), err=True)


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
    try:  # two names of one file first: a link to the other output's new file
        check_distinct((option, path) for option, path, _ in given)
    except OutputError as err:
        raise UsageError(err.message, hint=err.hint) from None
    for option, path, formats in given:
        if formats is not None:
            file_format(path, formats, option)
        try:
            check_target(path, protected)
        except OutputError as err:
            raise UsageError(f"{option}: {err.message}", option=option,
                             hint=err.hint) from None


RUN_OPTIONS: dict[str, Callable[[Callable[..., Any]], Callable[..., Any]]] = {
    "start": click.option("--start", type=float,
                          help="Start time [s] (default: experiment, else 0)."),
    "stop": click.option("--stop", type=float,
                         help="Stop time [s] (default: experiment, else 10)."),
    "interval": click.option("--interval", type=float,
                             help="Output interval [s] (default: experiment, else "
                             "(stop-start)/500)."),
    "parameters": click.option(
        "--set", "assignments", multiple=True, metavar="NAME=VALUE",
        help="Set a parameter or the start value of a state (repeatable; as "
        "OpenModelica's -override). A fixed start (fixed=true) is the initial value; a "
        "free one is the guess of the initial equations. Array sizes re-flatten the "
        "model; start values never recompile it."),
    "solver": click.option(
        "--solver", type=click.Choice(ALL_SOLVERS, case_sensitive=False),
        default=DEFAULT_SOLVER, show_default=True,
        help="auto: dop853 or radau from a stiffness estimate at the start (the summary "
        "says why); a scipy solve_ivp method; or a fixed-step one (verlet, "
        "symplectic-euler, rk4) with --step."),
    "engine": click.option(
        "--engine", type=click.Choice(ENGINES, case_sensitive=False),
        default=DEFAULT_ENGINE, show_default=True,
        help="compiled: numba loops (springc.integrate) for auto, dop853, rk45, radau, bdf "
        "and the fixed-step solvers; scipy: scipy's solvers stepped from Python; auto: "
        "compiled where it can run (numba installed, a solver with a compiled loop, not "
        "--backend python), else scipy, and the summary says why."),
    "error_control": click.option(
        "--error-control", type=click.Choice(ERROR_CONTROLS, case_sensitive=False),
        default=None, help="Estimate the global error on the output grid (a companion run "
        "1000x tighter, or half the step for fixed-step solvers: in the summary line, in "
        "a .mat trajectory and in --error-output) and hold every output variable v to 10 "
        "* (rtol * max|v| + atol). tighten: run 1000x tighter until it holds (at most "
        "rtol 1e-12, within --max-steps, --time-limit and, for the companions together, "
        "20x the run's steps; not again where the error stops falling), else warn; "
        "warn: only warn; "
        f"off: no estimate (fastest). [default: {DEFAULT_ERROR_CONTROL}]"),
    "error_estimate": click.option(
        "--error-estimate", type=click.Choice(("off", "on", "auto"), case_sensitive=False),
        default=None, help="Deprecated: off is --error-control off, on is warn, auto is "
        "tighten."),
    "step": click.option("--step", type=float, help="Step size [s] of the fixed-step "
                         "solvers (required for them)."),
    "rtol": click.option("--rtol", type=float, help="Relative tolerance (default: "
                         "experiment Tolerance, else 1e-6)."),
    "atol": click.option("--atol", type=float,
                         help="Absolute tolerance (default: rtol/1000)."),
    "max_steps": click.option(
        "--max-steps", type=click.IntRange(min=1), default=None,
        help="Stop a run with an error after this many integrator steps (default "
        "20,000,000)."),
    "time_limit": click.option(
        "--time-limit", type=NumberRange(min=0, min_open=True), default=None,
        help="Stop a run with an error after this many seconds of wall clock (default "
        "3600)."),
    "event_rows": click.option(
        "--event-rows", is_flag=True, help="For a model with events: add two rows at each "
        "event, its left and right limits (default: one row per output time)."),
}
"""Every run option of the command line, once: the field of
:class:`springc.simulation.RunSettings` it sets -> its click option. A new run option
is a field there, a keyword of :func:`springc.simulation.run_settings`, and a row here."""

PARAMETER_NAMES = {"parameters": "assignments"}
"""The click parameter of a setting where it is not the setting's own name."""
PASSED_ON = frozenset({"error_estimate"})
"""Options the command also receives as given (the deprecated ``--error-estimate``:
the command words its warning)."""
TIMES = ("start", "stop", "interval", "parameters")
"""The times and values of a run: every command that runs the model."""
SOLVING = ("solver", "step", "rtol", "atol", "max_steps", "time_limit", "error_control")
"""How a single setting runs: the commands that run one (``simulate``, ``sweep``)."""


def run_options(func: Callable[..., Any]) -> Callable[..., Any]:
    """The options of :data:`TIMES` as plain parameters (``ensemble``, which builds its
    own options)."""
    for name in reversed(TIMES):
        func = RUN_OPTIONS[name](func)
    return func


def run_settings_options(*names: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """The shared option group of ``simulate``, ``sweep`` and ``tradeoff``: the options
    ``names`` of :data:`RUN_OPTIONS`, given to the command as one ``settings``
    (:class:`springc.simulation.RunSettings`, built by :func:`cli_settings`). Apply it
    below ``guard``, which words its errors."""
    def decorate(func: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            given = {name: (kwargs[PARAMETER_NAMES.get(name, name)] if name in PASSED_ON
                            else kwargs.pop(PARAMETER_NAMES.get(name, name)))
                     for name in names}
            return func(*args, settings=cli_settings(given), **kwargs)

        command: Callable[..., Any] = wrapper
        for name in reversed(names):
            command = RUN_OPTIONS[name](command)
        return command
    return decorate


def cli_settings(given: dict[str, Any]) -> RunSettings:
    """The settings of a command's run options ``given`` (by setting name): ``--set``
    parsed, a fixed-step solver refused without ``--step``, then the checks of
    :func:`springc.simulation.run_settings`, which name the options."""
    values = dict(given)
    values["parameters"] = parse_set(values.get("parameters", ()))
    solver = str(values.get("solver", DEFAULT_SOLVER)).lower()
    if solver in FIXED_STEP and values.get("step") is None:
        raise click.UsageError(f"--solver {solver} is a fixed-step solver and needs "
                               "--step H (e.g. --step 1e-3)")
    values["solver"] = solver
    if "engine" in values:
        values["engine"] = str(values["engine"]).lower()
    return run_settings(**values, cli=True)


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


MMAP_THRESHOLD = 1 << 20
"""Bytes from which glibc's ``malloc`` maps each allocation apart and unmaps it when
it is freed (:func:`unmapped_large_buffers`)."""


def unmapped_large_buffers() -> None:
    """With glibc, allocations of :data:`MMAP_THRESHOLD` bytes or more are mapped apart
    and returned to the system when freed, unless the user set
    ``MALLOC_MMAP_THRESHOLD_``. By default glibc raises that threshold (up to 32 MB)
    once such a buffer is freed; a large scene's blocks of rows (the observed rows, the
    error estimate's, 8 to 16 MB each) then come from the heap, where freed space
    stays resident between the live arrays: the 50x50 cloth's warm run held about 75
    MB more at its result. A no-op elsewhere (no glibc ``mallopt``)."""
    import ctypes
    import os

    if not sys.platform.startswith("linux") or "MALLOC_MMAP_THRESHOLD_" in os.environ:
        return
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt(-3, MMAP_THRESHOLD)  # M_MMAP_THRESHOLD


def release_compile_memory() -> None:
    """After a model compiled in this process: its collected objects freed and, with
    glibc, the free pages of the heap returned to the system (``malloc_trim``). A 50x50
    cloth compiled cold keeps 740 MB of RSS after ``compile_model``, 567 MB after
    this, the run then starting from there (flattening's million expression nodes
    leave most of the rest in Python's partly used arenas)."""
    import ctypes
    import gc

    gc.collect()
    if sys.platform.startswith("linux"):
        try:
            trim = ctypes.CDLL(None).malloc_trim
        except (OSError, AttributeError):
            return
        trim.argtypes = [ctypes.c_size_t]
        trim(0)


def single_threaded_blas() -> None:
    """Run BLAS on one thread unless the user chose otherwise: the solvers' vector
    operations are too small to gain from threads, and on a busy machine threaded
    OpenBLAS made a 20,000-state BDF run eight times slower."""
    import os

    if "numpy" not in sys.modules:
        for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
            os.environ.setdefault(var, "1")
