"""The library entry points shared by the CLI and Python users.

``flatten_files`` runs load -> flatten; later stages build on it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from ..flatten import flatten
from ..ir.flat import FlatModel
from ..parse import load


def flatten_files(files: Sequence[str | Path], model: str | None = None,
                  libraries: Iterable[str | Path] = ()) -> FlatModel:
    """Load ``files`` (plus library folders) and flatten ``model`` (dotted name)."""
    return flatten(load(files, libraries), model)
