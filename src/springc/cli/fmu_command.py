"""``springc fmu``: export a model as an FMU (FMI 3.0 or 2.0; Model Exchange and
Co-Simulation in one file)."""

from __future__ import annotations

import click

from ..errors import printable
from .app import guard, main
from .options import check_output_options, model_options, verbosity, verbosity_options

FMU_SUFFIX = {".fmu": "fmu"}


@main.command()
@model_options
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False),
              help="Write the FMU here (NAME.fmu).")
@click.option("--fmi", "fmi_version", type=click.Choice(["3", "2"]), default="3",
              show_default=True, help="The FMI version of the FMU.")
@verbosity_options("Nothing on stderr but warnings and errors.")
@guard
def fmu(files: tuple[str, ...], model: str | None, libraries: tuple[str, ...],
        output: str, fmi_version: str) -> None:
    """Export a model of FILES as an FMU with Model Exchange and Co-Simulation: its C
    sources, and a linux64 binary compiled with the system C compiler."""
    from ..fmu import export_fmu
    from ..pipeline import CompileOptions

    check_output_options([("-o", output, FMU_SUFFIX)], files)
    done = export_fmu(CompileOptions(files, model, libraries, "python", None, (), False),
                      output, int(fmi_version))
    for warning in (done.note, *done.warnings) if done.note else done.warnings:
        click.echo(printable(f"warning: {warning}"), err=True)
    if verbosity() >= 0:
        click.echo(printable(
            f"{done.path}: FMI {done.fmi_version}.0 FMU of {done.model} (Model Exchange "
            f"and Co-Simulation; {done.states} states, {done.variables} variables, "
            f"{done.event_indicators} event indicators; "
            f"{'sources and linux64 binary' if done.binary else 'sources only'})"), err=True)
