"""The ``springc`` command group and :func:`guard`, which turns errors into exit codes.

Exit codes: 0 success, 1 model errors (diagnostics on stderr), 2 usage errors (a bad
option value, an output file springc refuses to write), 3 internal errors (traceback
only with ``--debug``); 130 after Ctrl-C, 143 after SIGTERM, 141 when stdout is a pipe
closed early (``springc simulate m.mdl | head -1``), quietly. Unfinished output files
are removed in every case (:mod:`springc.fileio`).
"""

from __future__ import annotations

import functools
import os
import signal
import sys
import traceback
from collections.abc import Callable
from types import FrameType
from typing import Any

import click

from ..errors import ErrorGroup, SpringcError, UsageError, render_all
from ..ir.expr import recursion_room
from .options import LEVEL_KEY

EXIT_MODEL_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE
EXIT_INTERRUPTED = 128 + signal.SIGINT


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


def guard(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn springc errors into diagnostics and crashes into exit code 3."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        ctx = click.get_current_context()
        debug = ctx.find_root().params.get("debug", False) or ctx.meta.get(LEVEL_KEY, 0) >= 2
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
                           "this is a bug in springc; rerun with -vv for the traceback "
                           "and report it", err=True)
            sys.exit(EXIT_INTERNAL)

    return wrapper


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
