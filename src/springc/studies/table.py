"""A user's table of runs: a CSV file -> parameter names and a matrix (one row per run).

The first line names the parameters (flat names, as ``--param``), every further line
is one run; every cell must be a finite number. Blank lines are skipped.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import UsageError
from .params import MAX_RUNS

OPTION = "--table"


def read_table(path: str | Path) -> tuple[tuple[str, ...], np.ndarray]:
    """The parameter names of the header and the values, one row per run."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = [row for row in csv.reader(f) if any(cell.strip() for cell in row)]
    except OSError as err:
        raise UsageError(f"{OPTION} {path}: {err.strerror}", option=OPTION) from None
    if not rows:
        raise UsageError(f"{OPTION} {path}: the file is empty (expected a header line of "
                         "parameter names)", option=OPTION)
    names = tuple(cell.strip() for cell in rows[0])
    if any(not name for name in names) or len(set(names)) != len(names):
        raise UsageError(f"{OPTION} {path}:1: the header must name each parameter once, "
                         f"got {', '.join(names)}", option=OPTION)
    if not 1 <= len(rows) - 1 <= MAX_RUNS:
        raise UsageError(f"{OPTION} {path}: the table must have between 1 and {MAX_RUNS} "
                         f"runs, not {len(rows) - 1}", option=OPTION)
    values = np.empty((len(rows) - 1, len(names)))
    for i, row in enumerate(rows[1:]):
        if len(row) != len(names):
            raise UsageError(f"{OPTION} {path}: run {i} has {len(row)} values for "
                             f"{len(names)} parameters", option=OPTION)
        for j, cell in enumerate(row):
            try:
                value = float(cell)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise UsageError(f"{OPTION} {path}: run {i}, {names[j]}: '{cell.strip()}' "
                                 "is not a finite number", option=OPTION)
            values[i, j] = value
    return names, values
