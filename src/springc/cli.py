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

EXIT_MODEL_ERROR = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3


def _guard(func: Callable[..., Any]) -> Callable[..., Any]:
    """Turn springc errors into diagnostics and crashes into exit code 3."""

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        debug = click.get_current_context().find_root().params.get("debug", False)
        try:
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
@_guard
def flatten(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
            origins: bool, as_json: bool, simplified: bool) -> None:
    """Print the flat model of FILES as Modelica text (or JSON)."""
    from .flat import format_flat, to_json_dict
    from .pipeline import flatten_files

    flat_model = flatten_files(files, model, libraries)
    if simplified:
        from .ode import format_ode
        from .simplify import simplify

        result = simplify(flat_model)
        click.echo(format_ode(result.ode), nl=False)
        for note in result.warnings:
            click.echo(f"{note.span}: warning: {note.message}" if note.span
                       else f"warning: {note.message}", err=True)
    elif as_json:
        click.echo(json.dumps(to_json_dict(flat_model), indent=1))
    else:
        click.echo(format_flat(flat_model, origins), nl=False)


@main.command()
@_model_options
@_guard
def check(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...]) -> None:
    """Check that a model flattens and is balanced; print a one-line summary."""
    from .balance import check_balance
    from .pipeline import flatten_files

    click.echo(check_balance(flatten_files(files, model, libraries)).summary())
