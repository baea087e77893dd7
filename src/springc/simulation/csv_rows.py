"""The text of a trajectory's CSV (no numpy): a header ``time,<names>`` (quoted as RFC
4180 says when a name holds a comma, a quote or a line break), then one line per row,
every number written with ``repr`` (the shortest text that reads back as the same float).

The one writer of the format: :func:`.results.write_csv` and the command line's warm
path (:mod:`springc.launcher`) both call :func:`write_rows`, so both write the same bytes.
"""

from __future__ import annotations

import csv
from collections.abc import Iterable, Sequence
from typing import IO


def write_rows(f: IO[str], names: Sequence[str], rows: Iterable[Sequence[float]]) -> None:
    """Write the header and ``rows`` (each: the time, then one value per name)."""
    write_header(f, names)
    write_lines(f, rows)


def write_header(f: IO[str], names: Sequence[str]) -> None:
    """The header line: ``time``, then the names."""
    csv.writer(f, lineterminator="\n").writerow(["time", *names])


def write_lines(f: IO[str], rows: Iterable[Sequence[float]]) -> None:
    """One line per row (the time, then one value per name), each number its ``repr``."""
    f.writelines(",".join(map(repr, row)) + "\n" for row in rows)
