"""The default trajectory of a large scene is not written: a CSV or MAT file (or the CSV
on stdout) of every output of a model whose output times x variables exceed
:data:`LARGE_TRAJECTORY` is refused before the run, with the size and how to ask for
variables (``--vars``). Variables asked for are always written.

Ten million values are about 200 MB of CSV (some 20 characters per number) and most
of a minute of writing; the 50x50 cloth's default output is 60 million (1.2 GB).
"""

from __future__ import annotations

import re

from ..errors import UsageError
from ..pipeline import CompiledModel
from .planning import output_grid, resolve
from .settings import RunSettings

LARGE_TRAJECTORY = 10_000_000
"""Output times x variables above which the default trajectory is not written."""
CSV_BYTES_PER_VALUE = 20
"""About how many characters a number takes in the CSV (``repr`` and a comma)."""


def check_trajectory_size(model: CompiledModel, options: RunSettings,
                          target: str) -> None:
    """Refuse (a UsageError naming ``--vars``) to write every output of ``model`` to
    ``target`` when that is more than :data:`LARGE_TRAJECTORY` values."""
    start, stop, interval, _, _ = resolve(model, options)
    times = len(output_grid(start, stop, interval))
    variables = len(model.outputs)
    if times * variables <= LARGE_TRAJECTORY:
        return
    size = times * variables * CSV_BYTES_PER_VALUE
    example = re.sub(r"\[[^\[\]]*\]", "[*]", model.states[0]) if model.states else "x"
    raise UsageError(
        f"{target}: the default output of {model.name} is {variables:,} variables x "
        f"{times:,} times ({times * variables / 1e6:.0f} million values, about "
        f"{size / 1e9:.1f} GB of CSV); a trajectory above {LARGE_TRAJECTORY:,} values is "
        "written only for the variables asked for", option="--vars",
        hint=f"select them with --vars (e.g. --vars '{example}'; --vars '*' writes every "
        "variable), use a larger --interval, or draw them with --plot alone")
