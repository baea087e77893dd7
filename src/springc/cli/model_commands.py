"""``springc check``, ``flatten`` and ``compile``: the commands that stop before a run."""

from __future__ import annotations

import json

import click

from ..errors import printable
from .app import guard, main
from .options import (
    check_output_options,
    compile_options,
    model_options,
    report_units,
    units_option,
    verbosity,
    verbosity_options,
)


@main.command()
@model_options
@verbosity_options("Nothing on stderr but warnings and errors.")
@click.option("--origins", is_flag=True, help="Show where each equation comes from.")
@click.option("--json", "as_json", is_flag=True, help="Print the flat model as JSON.")
@click.option("--simplify", "simplified", is_flag=True,
              help="Print the simplified system: states, evaluation order, observed.")
@click.option("--latex", "as_latex", is_flag=True,
              help="Print the equations (with --simplify: the evaluation order) as LaTeX.")
@guard
def flatten(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
            origins: bool, as_json: bool, simplified: bool, as_latex: bool) -> None:
    """Print the flat model of FILES as Modelica text (or JSON, or LaTeX)."""
    from ..ir.flat import format_flat, format_flat_latex, to_json_dict
    from ..pipeline import flatten_files

    if as_latex and as_json:
        raise click.UsageError("--latex and --json cannot be combined")
    flat_model = flatten_files(files, model, libraries)
    if simplified:
        from ..ir.ode import format_ode, format_ode_latex
        from ..simplify import simplify

        result = simplify(flat_model)
        click.echo((format_ode_latex if as_latex else format_ode)(result.ode), nl=False)
        for note in result.warnings:
            message = printable(note.message)
            click.echo(f"{printable(str(note.span))}: warning: {message}" if note.span
                       else f"warning: {message}", err=True)
    elif as_json:
        click.echo(json.dumps(to_json_dict(flat_model), indent=1))
    elif as_latex:
        click.echo(format_flat_latex(flat_model), nl=False)
    else:
        click.echo(format_flat(flat_model, origins), nl=False)


@main.command()
@model_options
@units_option
@verbosity_options("No notes on stderr (warnings and errors still).")
@guard
def check(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
          strict_units: bool) -> None:
    """Check that a model flattens, its units agree and it is balanced; print a
    one-line summary."""
    from ..pipeline import flatten_files
    from ..simplify import check_balance
    from ..units import check_units

    flat = flatten_files(files, model, libraries)
    for note in flat.notes if verbosity() >= 0 else ():  # diagnostics, not errors
        click.echo("\n".join(printable(line) for line in str(note).split("\n")), err=True)
    report_units(check_units(flat), strict_units)
    click.echo(printable(check_balance(flat).summary()))


@main.command(name="compile")
@model_options
@compile_options
@click.option("-o", "--output", type=click.Path(dir_okay=False),
              help="Write the generated Python module here (default: stdout).")
@verbosity_options("Nothing on stderr but warnings and errors.")
@guard
def compile_(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
             backend: str, patterns: tuple[str, ...], no_cache: bool,
             output: str | None) -> None:
    """Generate a standalone Python module (numpy/scipy, or numba) for a model."""
    from ..pipeline import CompileOptions, compile_files
    from ..simulation import default_backend

    check_output_options([("-o", output, None)], files)
    compiled = compile_files(CompileOptions(files, model, libraries,
                                            backend or default_backend(),
                                            patterns or None, (), not no_cache))
    if output:
        from ..fileio import atomic_write

        with atomic_write(output, "w", files) as f:
            f.write(compiled.source)
    else:
        click.echo(compiled.source, nl=False)
    if verbosity() > 0:
        click.echo(f"{compiled.name}: {len(compiled.states)} states, "
                   f"{len(compiled.observed)} observed, {compiled.module.BACKEND} module "
                   f"{'from the cache' if compiled.cached else 'generated'} in "
                   f"{compiled.compile_time:.2f} s", err=True)
    if verbosity() > 1:
        click.echo(f"note: generated module {compiled.path}", err=True)
