"""The library entry points shared by the CLI and Python users.

``flatten_files`` runs load -> flatten; later stages build on it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

from ..ir.flat import FlatModel


def flatten_files(files: Sequence[str | Path], model: str | None = None,
                  libraries: Iterable[str | Path] = ()) -> FlatModel:
    """Load ``files`` (plus library folders) and flatten ``model`` (dotted name)."""
    from ..flatten import flatten
    from ..parse import load

    return flatten(load(files, libraries), model)
